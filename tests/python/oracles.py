"""Meshes with known geodesic distances, and the bounds every distance must meet.

Shared by tests/python/test_oracles.py and bench/studies/oracle_sweep.py (which puts
tests/python on sys.path). Nothing here calls meshfmm except the checks at
the end, which take the distances as arrays.

Generators (each returns a :class:`Case`):

- :func:`random_flat`: the Delaunay triangulation (scipy.spatial.Delaunay) of
  random points in a convex region (square, disk, random convex polygon), with
  points injected 0 to 1e-9 off the segments between other points
  (near-collinear triples, slivers) and optionally near-coincident pairs (gaps
  1e-16 to 1e-9), rotated into 3D by a random rotation and scaled by
  10^U(-6, 6). The triangulation covers the convex hull of its points, so the
  geodesic distance between two points of the surface is their Euclidean
  distance, whenever the mesh is a planar embedding (no zero-area face, no
  fold); ``case.known`` says whether it is (see :func:`_classify_flat`).
- :func:`random_slit`: a flat triangulation with one interior vertex split
  into two 1e-16..1e-9 apart, the slit between them closed by two slivers
  (the defect class of a needle shortcut).
- :func:`random_book`: two or more flat convex pages sharing one spine edge
  at random dihedral angles. Intrinsically each page is a convex planar
  polygon with the spine on its boundary, and a path between two pages
  crosses the spine once, so the geodesic distance between a point a of one
  page and b of another is min over q on the spine of |a - q| + |q - b| in
  page coordinates (x along the spine, h >= 0 the distance from it): with b
  unfolded to (x_b, -h_b), the straight segment if it crosses the spine
  within its extent, else the path through the nearer spine end (the sum is
  convex in q, so the minimum over the spine is at the clamped crossing).
  Within one page it is the Euclidean distance (the page is convex).

Bounds for any mesh (:func:`edge_graph`, :func:`euclid`): a path on the
surface is at least as long as the straight segment (Euclidean lower bound,
from the 3D source point), and the shortest path along edges of faces of
nonzero area is a path on the surface (edge-graph upper bound; from a point
source inside a face, through one of the face's corners).
"""

from __future__ import annotations

import dataclasses
from fractions import Fraction
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

EPS = np.finfo(np.float64).eps

# ----------------------------------------------------------------- tolerances
# Exact solver where the distance is known (flat: Euclidean; book: unfolding):
#   |e - ref| <= EXACT_REL * ref + EXACT_ABS * diag.
# Double-precision unfolding places each vertex with an error of a few ulps
# of the coordinates per face crossed, so on a well-conditioned mesh a correct
# solver is within ~1e-13 relative: measured on 4,570 sources of random flat
# and slit meshes (seed 11), at most 1.8e-13 where every edge is longer than
# 1e-6 of the diagonal. A window on a short edge l places its source only to
# ~eps d / l, so near-coincident vertices cost more: at most 8.5e-12
# relative there (seed 11), and over 20,000 meshes of bench/studies/oracle_sweep.py
# (seeds 0, 1) the worst error was 8.9e-11 of the diagonal (a flat mesh with
# two vertices 8e-12 of the diagonal apart; 1.7e-7 relative at the distance
# between those two). EXACT_REL = 1e-9 catches any wrong window (the defects
# found were 1e-7..2x off) and the floor, 1e-9 of the bounding-box diagonal,
# leaves a factor 11 over that worst rounding. The bounds below still hold
# to 1e-12 on every mesh.
EXACT_REL = 1e-9
EXACT_ABS = 1e-9
# Bounds on any mesh, for every method:
#   eu * (1 - BOUND_REL) - BOUND_ABS * diag <= d <= graph * (1 + BOUND_REL) + BOUND_ABS * diag
# (eu the Euclidean distance from the source's 3D point, graph the edge-graph
# path). They hold for any path on the surface whatever the rounding, and a
# solver can meet them by construction (clamping to |x_v - p|, relaxing edges),
# so only rounding is allowed: Dijkstra and the solvers sum the same lengths
# in other orders (k ulps for k edges, k < 400 here); the floor covers
# distances of a few ulps of the coordinates.
BOUND_REL = 1e-12
BOUND_ABS = 1e-13
# The march from one source: in exact arithmetic an upwind update of a real
# face (the characteristic crossing the opposite edge within it) from values
# >= the Euclidean distance is >= it too (along the edge the values
# interpolate linearly above a convex function, then a straight leg), so what
# undershoots comes from rounding in ill-conditioned updates (slivers) and
# from virtual edges, whose unfolded triangle may leave the surface. Measured
# by bench/studies/oracle_sweep.py (seeds 0 and 1: 20,000 meshes, 60,000 sources):
# min (d - eu) / eu was -9.3e-10 for the default march (from its exact start,
# which covers much of these small meshes; vertex sources: -1.5e-13), and for
# the plain start (exact_start=False) -7.5e-8 at the 1e-4 quantile, with an
# outlier or two per 10,000 meshes down to -1.3e-2 (defects of the march with
# virtual edges). The tolerances leave a factor 10 over the default's worst
# and 13 over the plain start's bulk.
FMM_UNDER_REL = 1e-8
PLAIN_UNDER_REL = 1e-6


@dataclasses.dataclass
class Case:
    """A generated mesh and what is known about it.

    kind: "flat", "slit" or "book"; V (nv, 3) float64, F (nf, 3) int32.
    known: True when :func:`reference` applies: a flat mesh that is a planar
        embedding of a convex region (every face of nonzero area in the
        library's sense with margin, no fold; geodesic distance == Euclidean
        distance), or a book whose pages are such embeddings.
    book: page coordinates for the book oracle (page id per vertex, -1 on
        the spine; xh (nv, 2)) and the spine's length.
    params: how it was made (for the debugging dumps).
    """

    kind: str
    V: np.ndarray
    F: np.ndarray
    known: bool = False
    page: Optional[np.ndarray] = None
    xh: Optional[np.ndarray] = None
    spine: float = 0.0
    params: dict = dataclasses.field(default_factory=dict)

    @property
    def diag(self) -> float:
        return float(np.linalg.norm(self.V.max(axis=0) - self.V.min(axis=0)))

    def exact_tolerance(self, ref: np.ndarray) -> np.ndarray:
        """The allowed |e - ref| of the exact solver (see EXACT_REL)."""
        return EXACT_REL * ref + EXACT_ABS * self.diag


# ------------------------------------------------------------- 2D primitives
def _orient_exact(a, b, c) -> int:
    """Sign of the orientation of three 2D float points, exactly."""
    det = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    bound = 3.3306690738754716e-16 * (abs((b[0] - a[0]) * (c[1] - a[1])) +
                                      abs((b[1] - a[1]) * (c[0] - a[0])))
    if abs(det) > bound:  # Shewchuk's orient2d filter
        return 1 if det > 0 else -1
    A = [Fraction(float(x)) for x in a]
    B = [Fraction(float(x)) for x in b]
    C = [Fraction(float(x)) for x in c]
    d = (B[0] - A[0]) * (C[1] - A[1]) - (B[1] - A[1]) * (C[0] - A[0])
    return (d > 0) - (d < 0)


def delaunay(P: np.ndarray) -> Tuple[np.ndarray, np.ndarray, bool]:
    """Delaunay triangulation of 2D points, each face counter-clockwise.

    Returns (P2, F, proper): unreferenced points (duplicates qhull dropped)
    removed, and whether the triangulation is a planar embedding in exact
    arithmetic on the float coordinates (every face of positive orientation,
    every directed edge once).
    """
    from scipy.spatial import Delaunay

    tri = Delaunay(P)
    F = np.array(tri.simplices, dtype=np.int64)
    proper = True
    for i, f in enumerate(F):
        s = _orient_exact(P[f[0]], P[f[1]], P[f[2]])
        if s < 0:
            F[i] = f[[0, 2, 1]]
        elif s == 0:
            proper = False
    if proper:
        d = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
        proper = len(np.unique(d, axis=0)) == len(d)
    used = np.zeros(len(P), dtype=bool)
    used[F.reshape(-1)] = True
    new = np.cumsum(used) - 1
    return P[used], new[F].astype(np.int32), proper


def region_points(rng: np.random.Generator, region: str, n: int) -> np.ndarray:
    """n random points in a convex region ("square", "disk", "polygon")."""
    if region == "square":
        return rng.uniform(-1.0, 1.0, (n, 2))
    if region == "disk":
        r = np.sqrt(rng.uniform(0.0, 1.0, n))
        t = rng.uniform(0.0, 2 * np.pi, n)
        return np.stack([r * np.cos(t), r * np.sin(t)], axis=1)
    if region == "polygon":
        k = int(rng.integers(3, 9))
        ang = np.sort(rng.uniform(0.0, 2 * np.pi, k))
        C = np.stack([np.cos(ang), np.sin(ang)], axis=1)  # convex position
        m = max(n - k, 0)
        # uniform in the fan of triangles (C0, Ci, Ci+1), by area
        u, w = C[1:-1] - C[0], C[2:] - C[0]
        a = np.abs(u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]) / 2
        tri = rng.choice(len(a), size=m, p=a / a.sum())
        u, v = rng.uniform(size=m), rng.uniform(size=m)
        flip = u + v > 1
        u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
        X = C[0] + u[:, None] * (C[1 + tri] - C[0]) + v[:, None] * (C[2 + tri] - C[0])
        return np.concatenate([C, X])[:n]
    raise ValueError(region)


def _log_uniform(rng, lo: float, hi: float) -> float:
    return float(10.0 ** rng.uniform(np.log10(lo), np.log10(hi)))


def inject_near_collinear(rng, P: np.ndarray, k: int, max_off: float = 1e-9) -> np.ndarray:
    """k points each on the segment between two points of P (t in (0.05,
    0.95)), moved off it by 0 (one in four) or 10^U(-16, log10 max_off)."""
    out = [P]
    for _ in range(k):
        i, j = rng.choice(len(P), 2, replace=False)
        p, q = P[i], P[j]
        t = rng.uniform(0.05, 0.95)
        d = q - p
        nrm = np.array([-d[1], d[0]]) / max(np.linalg.norm(d), 1e-300)
        off = 0.0 if rng.uniform() < 0.25 else _log_uniform(rng, 1e-16, max_off)
        out.append((p + t * d + rng.choice([-1.0, 1.0]) * off * nrm)[None])
    return np.concatenate(out)


def inject_near_coincident(rng, P: np.ndarray, k: int, lo: float = 1e-16,
                           hi: float = 1e-9) -> np.ndarray:
    """k copies of points of P moved by 10^U(log10 lo, log10 hi) in a random direction."""
    out = [P]
    for _ in range(k):
        p = P[rng.integers(len(P))]
        t = rng.uniform(0.0, 2 * np.pi)
        g = _log_uniform(rng, lo, hi)
        out.append((p + g * np.array([np.cos(t), np.sin(t)]))[None])
    return np.concatenate(out)


def random_rotation(rng) -> np.ndarray:
    """A uniformly random 3x3 rotation matrix (QR of a Gaussian matrix)."""
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    if np.linalg.det(Q) < 0:
        Q[:, 0] = -Q[:, 0]
    return Q


def _embed(rng, P3: np.ndarray, scale: Optional[float]) -> Tuple[np.ndarray, np.ndarray, float]:
    """Rotates points (n, 3) by a random rotation and scales them by
    10^U(-6, 6) (or `scale`), with a random offset of up to the mesh size.
    Returns (V, R, scale)."""
    R = random_rotation(rng)
    s = float(10.0 ** rng.uniform(-6.0, 6.0)) if scale is None else float(scale)
    off = rng.normal(size=3) * rng.uniform(0.0, 1.0)
    V = (P3 @ R.T + off) * s
    return np.ascontiguousarray(V, dtype=np.float64), R, s


# -------------------------------------------------- library-like face tests
def sines(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Per face (sine of the corner between its first two edges, the
    library's zero-area threshold 64 eps (lmax/l0)(lmax/l1)) as (nf, 2)."""
    X = V[F]
    # e[k] runs from corner k+1 to corner k+2 (as mesh.c has it)
    e = np.stack([X[:, 2] - X[:, 1], X[:, 0] - X[:, 2], X[:, 1] - X[:, 0]], axis=1)
    L = np.linalg.norm(e, axis=2)
    lmax = L.max(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        u0 = e[:, 0] / L[:, 0, None]
        u1 = e[:, 1] / L[:, 1, None]
        s = np.linalg.norm(np.cross(u0, u1), axis=1)
        thr = 64 * EPS * (lmax / L[:, 0]) * (lmax / L[:, 1])
    s = np.where((L[:, 0] > 0) & (L[:, 1] > 0), s, 0.0)
    return np.stack([np.nan_to_num(s), np.nan_to_num(thr, nan=np.inf, posinf=np.inf)], axis=1)


def solid_faces(V: np.ndarray, F: np.ndarray, margin: float = 4.0) -> np.ndarray:
    """Faces of nonzero area with a margin over the library's threshold
    (those the library certainly keeps as triangles; the edge-graph bound
    uses their edges only, so a face the library drops as zero-area never
    makes the bound too small)."""
    st = sines(V, F)
    return st[:, 0] > margin * st[:, 1]


def _classify_flat(V: np.ndarray, F: np.ndarray, normal: np.ndarray, proper: bool) -> bool:
    """Whether the 3D mesh is a planar embedding: the 2D triangulation was
    proper, every face is of nonzero area with margin, and none is folded
    over (its normal within 60 degrees of the plane's)."""
    if not proper:
        return False
    if not solid_faces(V, F, margin=16.0).all():
        return False
    X = V[F]
    n = np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
    cosang = n @ normal / np.maximum(np.linalg.norm(n, axis=1), 1e-300)
    return bool((cosang > 0.5).all())


# ------------------------------------------------------------- generators
def random_flat(rng: np.random.Generator, n: Optional[int] = None, region: Optional[str] = None,
                n_collinear: Optional[int] = None, n_coincident: Optional[int] = None,
                scale: Optional[float] = None) -> Case:
    """A random flat triangulated convex region in 3D (module docstring).

    n: base points (default U{10..150}); n_collinear: injected near-collinear
    points (default U{0..n/3}); n_coincident: near-coincident copies
    (default 0 half the time, else U{1..5})."""
    n = int(rng.integers(10, 151)) if n is None else n
    region = str(rng.choice(["square", "disk", "polygon"])) if region is None else region
    if n_collinear is None:
        n_collinear = int(rng.integers(0, n // 3 + 1))
    if n_coincident is None:
        n_coincident = 0 if rng.uniform() < 0.5 else int(rng.integers(1, 6))
    P = region_points(rng, region, n)
    P = inject_near_collinear(rng, P, n_collinear)
    P = inject_near_coincident(rng, P, n_coincident)
    P, F, proper = delaunay(P)
    V, R, s = _embed(rng, np.concatenate([P, np.zeros((len(P), 1))], axis=1), scale)
    case = Case("flat", V, F, params=dict(region=region, n=n, n_collinear=n_collinear,
                                          n_coincident=n_coincident, scale=s))
    case.known = _classify_flat(V, F, R[:, 2], proper)
    return case


def random_slit(rng: np.random.Generator, n: Optional[int] = None,
                gap: Optional[float] = None, scale: Optional[float] = None) -> Case:
    """A flat triangulation of a square whose interior vertex v is split: the
    faces on one side of the polyline a-v-b (a, b neighbours of v) take a new
    vertex v' = v + gap * (the bisector of that side), and two slivers v-a-v',
    v-v'-b close the slit. gap: 10^U(-16, -9) by default (of a mesh of size
    2), or 0 (coincident vertices) one time in ten. Known (``case.known``:
    Euclidean) when the slivers have nonzero area in the library's sense; else
    the bounds only."""
    n = int(rng.integers(10, 120)) if n is None else n
    if gap is None:
        gap = 0.0 if rng.uniform() < 0.1 else _log_uniform(rng, 1e-16, 1e-9)
    for _ in range(100):
        P = region_points(rng, "square", n)
        P, F, proper = delaunay(P)
        if not proper:
            continue
        hull = np.zeros(len(P), dtype=bool)
        from scipy.spatial import ConvexHull

        hull[ConvexHull(P).vertices] = True
        inner = np.flatnonzero(~hull)
        # collinear points on the hull are not hull vertices: require no
        # boundary edge at v (every edge of v in two faces)
        rng.shuffle(inner)
        for v in inner:
            fan = np.flatnonzero((F == v).any(axis=1))
            # the ring of neighbours in counter-clockwise order
            nxt = {}
            for f in fan:
                k = int(np.flatnonzero(F[f] == v)[0])
                nxt[int(F[f][(k + 1) % 3])] = int(F[f][(k + 2) % 3])
            if len(nxt) != len(fan) or len(fan) < 4:
                continue
            ring = [next(iter(nxt))]
            while len(ring) < len(fan):
                ring.append(nxt[ring[-1]])
            if nxt[ring[-1]] != ring[0]:
                continue
            i = int(rng.integers(len(ring)))
            j = (i + int(rng.integers(2, len(ring) - 1))) % len(ring)
            a, b = ring[i], ring[j]
            # faces (v, r_k, r_k+1) for k from a's position up to b's: the
            # side of the fan turning counter-clockwise from a to b
            side = set()
            k = i
            while ring[k] != b:
                side.add((ring[k], ring[(k + 1) % len(ring)]))
                k = (k + 1) % len(ring)
            da = (P[a] - P[v]) / np.linalg.norm(P[a] - P[v])
            db = (P[b] - P[v]) / np.linalg.norm(P[b] - P[v])
            bis = da + db
            # the side from a to b counter-clockwise: the bisector points into
            # it when the angle a-v-b (ccw) is below pi, else away from it
            if da[0] * db[1] - da[1] * db[0] < 0:
                bis = -bis
            if np.linalg.norm(bis) < 1e-3:
                bis = np.array([-da[1], da[0]])
            bis /= np.linalg.norm(bis)
            w = len(P)
            P2 = np.concatenate([P, (P[v] + gap * bis)[None]])
            F2 = F.copy()
            for f in fan:
                k = int(np.flatnonzero(F[f] == v)[0])
                if (int(F[f][(k + 1) % 3]), int(F[f][(k + 2) % 3])) in side:
                    F2[f][k] = w
            # slivers between the polylines a-v-b and a-v'-b (v' inside the
            # wedge from a to b): v-a-v' and v-v'-b, counter-clockwise
            sl = np.array([[v, a, w], [v, w, b]], dtype=np.int32)
            F2 = np.concatenate([F2, sl]).astype(np.int32)
            V, R, s = _embed(rng, np.concatenate([P2, np.zeros((len(P2), 1))], axis=1), scale)
            case = Case("slit", V, F2, params=dict(n=n, gap=gap, v=int(v), a=int(a), b=int(b),
                                                  scale=s))
            ok = all(_orient_exact(P2[f[0]], P2[f[1]], P2[f[2]]) > 0 for f in F2)
            case.known = ok and _classify_flat(V, F2, R[:, 2], True)
            return case
    raise RuntimeError("no interior vertex to split")


def random_book(rng: np.random.Generator, n_pages: Optional[int] = None,
                n: Optional[int] = None, scale: Optional[float] = None,
                min_gap: float = 0.05, clean: bool = False) -> Case:
    """Pages (2 seven times in ten, else 3 or 4; n points each, default
    U{5..150/pages}) sharing the spine edge from (0,0) to
    (L,0) in page coordinates, each the Delaunay triangulation of the spine's
    ends and random points with h > 0 (a convex page with the spine as a hull
    edge), at random dihedral angles at least min_gap radians apart. Unless
    clean, one point in seven lies 1e-9..1e-3 from the spine and points are
    injected near the segments between others (slivers)."""
    if n_pages is None:
        n_pages = 2 if rng.uniform() < 0.7 else int(rng.integers(3, 5))
    L = float(rng.uniform(0.3, 2.0))
    while True:
        ang = np.sort(rng.uniform(0.0, 2 * np.pi, n_pages))
        gaps = np.diff(np.concatenate([ang, ang[:1] + 2 * np.pi]))
        if gaps.min() >= min_gap:
            break
    Vs = [np.zeros((2, 3))]
    Vs[0][1, 0] = L
    page = [-1, -1]
    xh = [[0.0, 0.0], [L, 0.0]]
    Fs = []
    proper_pages = []
    nv = 2
    for p in range(n_pages):
        m = int(rng.integers(5, max(6, 150 // n_pages))) if n is None else n
        Q = np.stack([rng.uniform(-0.5, L + 0.5, m), rng.uniform(0.0, 1.0, m)], axis=1)
        # some points close to the spine (slivers along it)
        if not clean:
            close = rng.uniform(size=m) < 0.15
            Q[close, 1] = [_log_uniform(rng, 1e-9, 1e-3) for _ in range(int(close.sum()))]
            Q = Q[Q[:, 1] > 0]
            Q = inject_near_collinear(rng, Q, int(rng.integers(0, max(1, m // 4))))
            Q = Q[Q[:, 1] > 0]
        else:
            Q[:, 1] = np.maximum(Q[:, 1], 0.05)
        P = np.concatenate([[[0.0, 0.0], [L, 0.0]], Q])
        P2, F, proper = delaunay(P)
        proper_pages.append(proper)
        # delaunay keeps point order: the spine ends stay 0 and 1 (both hull vertices)
        assert np.array_equal(P2[:2], P[:2])
        ids = np.concatenate([[0, 1], nv + np.arange(len(P2) - 2)])
        Fs.append(ids[F])
        c, s_ = np.cos(ang[p]), np.sin(ang[p])
        X = np.stack([P2[2:, 0], P2[2:, 1] * c, P2[2:, 1] * s_], axis=1)
        Vs.append(X)
        page += [p] * (len(P2) - 2)
        xh += P2[2:].tolist()
        nv += len(P2) - 2
    P3 = np.concatenate(Vs)
    V, R, s = _embed(rng, P3, scale)
    F = np.concatenate(Fs).astype(np.int32)
    page_faces = np.concatenate([np.full(len(f), p) for p, f in enumerate(Fs)])
    case = Case("book", V, F, page=np.array(page), xh=np.array(xh) * s, spine=L * s,
                params=dict(n_pages=n_pages, angles=ang.tolist(), L=L, scale=s))
    # the reference holds where every page is a planar embedding
    case.known = all(proper_pages) and all(
        _classify_flat(V, F[page_faces == p],
                       R @ np.array([0.0, -np.sin(ang[p]), np.cos(ang[p])]), True)
        for p in range(n_pages))
    return case


def random_case(rng: np.random.Generator, kinds: Sequence[str] = ("flat", "slit", "book"),
                p: Optional[Sequence[float]] = None) -> Case:
    kind = str(rng.choice(list(kinds), p=p))
    return {"flat": random_flat, "slit": random_slit, "book": random_book}[kind](rng)


# ------------------------------------------------------------ references
def source_point(V: np.ndarray, F: np.ndarray, source) -> np.ndarray:
    """3D point of a source: a vertex id, or (face, bary)."""
    if isinstance(source, (int, np.integer)):
        return V[int(source)]
    f, b = source
    return np.asarray(b, float) @ V[F[f]]


def euclid(V: np.ndarray, F: np.ndarray, source) -> np.ndarray:
    return np.linalg.norm(V - source_point(V, F, source), axis=1)


def edge_graph(V: np.ndarray, F: np.ndarray, source, faces: Optional[np.ndarray] = None) -> np.ndarray:
    """Shortest path along the edges of `faces` (a mask; default
    :func:`solid_faces`) from a vertex source, or from a point in a face
    through its corners (+inf where none reaches)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    nv = len(V)
    if faces is None:
        faces = solid_faces(V, F)
    G = F[faces]
    E = np.concatenate([G[:, [0, 1]], G[:, [1, 2]], G[:, [2, 0]]])
    E = np.unique(np.sort(E, axis=1), axis=0)
    if isinstance(source, (int, np.integer)):
        starts, init = [int(source)], [0.0]
    else:
        f, b = source
        p = source_point(V, F, source)
        starts = [int(x) for x in F[f]]
        init = [float(np.linalg.norm(V[x] - p)) for x in starts]
    w = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)
    w = np.maximum(w, 1e-300)  # explicit zeros would be read as no edge
    # a super-source nv joined to the start vertices by their initial values
    rows = np.concatenate([E[:, 0], E[:, 1], np.full(len(starts), nv)])
    cols = np.concatenate([E[:, 1], E[:, 0], starts])
    vals = np.concatenate([w, w, np.maximum(init, 1e-300)])
    M = coo_matrix((vals, (rows, cols)), shape=(nv + 1, nv + 1)).tocsr()
    M.sum_duplicates()  # duplicate (row, col) pairs only come from the super-source
    d = dijkstra(M, directed=True, indices=nv)[:nv]
    for s, d0 in zip(starts, init):
        d[s] = min(d[s], d0)
    return d


def book_distance(case: Case, source) -> np.ndarray:
    """Geodesic distance on a book (:func:`random_book`) from a vertex or a
    point in a face, in page coordinates (module docstring)."""
    page, xh, L = case.page, case.xh, case.spine
    if isinstance(source, (int, np.integer)):
        a, pa = xh[int(source)], int(page[int(source)])
    else:
        f, b = source
        vf = case.F[f]
        a = np.asarray(b, float) @ xh[vf]
        pg = page[vf]
        pa = int(pg.max())  # a face lies on one page; spine corners are -1
    out = np.empty(len(xh))
    for v in range(len(xh)):
        x, h = xh[v]
        pv = int(page[v])
        if pa == -1 or pv == -1 or pa == pv:
            out[v] = np.hypot(a[0] - x, a[1] - h)
            continue
        ha, hb = a[1], h
        t = a[0] + (x - a[0]) * ha / (ha + hb) if ha + hb > 0 else a[0]
        q = min(max(t, 0.0), L)
        out[v] = np.hypot(a[0] - q, ha) + np.hypot(x - q, hb)
    return out


def reference(case: Case, source) -> Optional[np.ndarray]:
    """The geodesic distance where the case knows it (flat, book), else None."""
    if case.kind == "book" and case.known:
        return book_distance(case, source)
    if case.known and case.kind != "book":
        return euclid(case.V, case.F, source)
    return None


# ----------------------------------------------------------------- checks
def check_exact(case: Case, source, e: np.ndarray, eu=None, gr=None) -> Dict[str, np.ndarray]:
    """Violations of the exact solver's bounds: {bound name: vertex ids}.
    Bounds: "below_euclid", "above_graph", "not_finite" (+inf or NaN where
    the edge graph reaches), "nan", and "reference" (flat: Euclidean; book:
    unfolding) where the case knows the distance."""
    V, F = case.V, case.F
    diag = case.diag
    eu = euclid(V, F, source) if eu is None else eu
    gr = edge_graph(V, F, source) if gr is None else gr
    out = {}
    out["nan"] = np.flatnonzero(np.isnan(e))
    out["below_euclid"] = np.flatnonzero(e < eu * (1 - BOUND_REL) - BOUND_ABS * diag)
    fin = np.isfinite(gr)
    out["not_finite"] = np.flatnonzero(fin & ~np.isfinite(e))
    out["above_graph"] = np.flatnonzero(fin & np.isfinite(e) &
                                        (e > gr * (1 + BOUND_REL) + BOUND_ABS * diag))
    ref = reference(case, source)
    if ref is not None:
        out["reference"] = np.flatnonzero(~(np.abs(e - ref) <= case.exact_tolerance(ref)))
    return out


def check_march(case: Case, source, d: np.ndarray, eu=None, gr=None,
                under_rel: float = FMM_UNDER_REL) -> Dict[str, np.ndarray]:
    """Violations of the march's bounds: {bound name: vertex ids}.
    "below_euclid" with the march's tolerance under_rel, "above_graph" with
    the rounding tolerance, "not_finite" where the edge graph reaches, "nan"."""
    V, F = case.V, case.F
    diag = case.diag
    eu = euclid(V, F, source) if eu is None else eu
    gr = edge_graph(V, F, source) if gr is None else gr
    fin = np.isfinite(gr)
    return {
        "nan": np.flatnonzero(np.isnan(d)),
        "below_euclid": np.flatnonzero(d < eu * (1 - under_rel) - BOUND_ABS * diag),
        "not_finite": np.flatnonzero(fin & ~np.isfinite(d)),
        "above_graph": np.flatnonzero(fin & np.isfinite(d) &
                                      (d > gr * (1 + BOUND_REL) + BOUND_ABS * diag)),
    }


def undershoot(case: Case, source, d: np.ndarray, eu=None) -> float:
    """min over vertices with eu > 1e-9 diag of (d - eu) / eu (0 if none)."""
    eu = euclid(case.V, case.F, source) if eu is None else eu
    m = eu > 1e-9 * case.diag
    if not m.any():
        return 0.0
    r = (d[m] - eu[m]) / eu[m]
    r = r[np.isfinite(r)]
    return float(r.min()) if r.size else 0.0


def pick_sources(rng: np.random.Generator, case: Case, n_vertex: int = 2,
                 n_face: int = 1) -> List:
    """Random vertex sources (ints) and points inside solid faces ((face, bary))."""
    nv = len(case.V)
    out: List = [int(v) for v in rng.choice(nv, size=min(n_vertex, nv), replace=False)]
    solid = np.flatnonzero(solid_faces(case.V, case.F, margin=1e6))
    for _ in range(n_face if len(solid) else 0):
        f = int(rng.choice(solid))
        b = rng.dirichlet([1.0, 1.0, 1.0])
        out.append((f, tuple(float(x) for x in b)))
    return out
