"""method="windows" (MFMM_METHOD_WINDOWS, docs/windows.md) through every
Python entry that solves: Mesh.distance, distance_matrix (serial and
threads, dense and sparse, vertex and surface-point targets),
iter_distance_rows, farthest_point_sampling, voronoi_labels and path.

- never below the exact geodesic distance (the stored igl.exact_geodesic
  rows of tests/data/reference, and our exact solver on random meshes) by
  more than 1e-9 relative: each value is the length of a path on the
  surface, straight within the faces it crosses;
- its mean relative error per mesh under a bound a little above the one
  measured, and below the march's from the same source;
- exact on surfaces that unfold into the plane (cylinders, folded pages);
- matrix rows, landmarks and labels equal those of windows solves, float64
  bit for bit;
- the refusals: "exact" in the matrix calls.
- a cost: a constant one scales the values; matrix rows (serial, threads,
  OpenCL) equal the solves' bit for bit; farthest points and paths take it.
"""

from __future__ import annotations

import numpy as np
import pytest

import meshfmm
from meshfmm import SurfacePoint
from conftest import mesh, reference
from meshfmm_testing import mean_rel_error

# Relative allowance below the exact distance: rounding only (the least
# (d - e) / e measured over the stored sources is -1.8e-15).
BELOW = 1e-9

# Mean relative error in percent, the largest of the three stored sources
# (measured: hand 0.050, spot 0.133, wingnut 0.136, fertility 0.141,
# decimated-max 0.151, camelhead 0.119, nefertiti 0.098, bunny 0.097;
# the march's from the same sources: 0.36-0.81).
MEAN_ERROR_PCT = {
    "hand_lowres.obj": 0.06,
    "spot.obj": 0.15,
    "wingnut.obj": 0.15,
    "fertility_FE_10k.off": 0.16,
    "decimated-max.obj": 0.17,
    "camelhead.off": 0.13,
    "nefertiti-lowres.obj": 0.11,
    "stanford-bunny.obj": 0.11,
}

# Max error in percent of the bounding-box diagonal, the largest of the
# three stored sources (measured: hand 0.350, spot 0.411, wingnut 0.772,
# fertility 0.614, decimated-max 0.453, camelhead 0.332, nefertiti 0.287,
# bunny 0.204; the march's: 0.49-1.79, and above the windows' from every
# source).
MAX_ERROR_PCT = {
    "hand_lowres.obj": 0.36,
    "spot.obj": 0.42,
    "wingnut.obj": 0.78,
    "fertility_FE_10k.off": 0.63,
    "decimated-max.obj": 0.46,
    "camelhead.off": 0.34,
    "nefertiti-lowres.obj": 0.30,
    "stanford-bunny.obj": 0.21,
}


@pytest.mark.parametrize("name", sorted(MEAN_ERROR_PCT))
def test_never_below_the_exact_distance_and_mean_error(name):
    m = mesh(name)
    sources, exact = reference(name)
    for s, e in zip(sources, exact):
        d = m.distance(int(s), method="windows")
        fin = np.isfinite(e)
        assert np.array_equal(np.isfinite(d), fin)
        pos = fin & (e > 0)
        low = float(np.min((d[pos] - e[pos]) / e[pos]))
        assert low >= -BELOW, f"{name} from {s}: {low:.3e} below the exact distance"
        mre = mean_rel_error(d, e)
        assert mre <= MEAN_ERROR_PCT[name], f"{name} from {s}: {mre:.4f} %"
        march = m.distance(int(s))
        assert mre < mean_rel_error(march, e)
        diag = float(np.linalg.norm(np.ptp(m.vertices, axis=0)))
        mx = 100.0 * float(np.max(np.abs(d[fin] - e[fin]))) / diag
        assert mx <= MAX_ERROR_PCT[name], f"{name} from {s}: max {mx:.4f} % of the diagonal"
        assert mx <= 100.0 * float(np.max(np.abs(march[fin] - e[fin]))) / diag


def cylinder(n, m):
    """An open cylinder of radius 1 and height 2, n vertices around, m
    rows of quads each cut in two."""
    th = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    z = np.linspace(0.0, 2.0, m + 1)
    V = np.array([[np.cos(t), np.sin(t), h] for h in z for t in th])
    F = []
    for j in range(m):
        for i in range(n):
            a, b = j * n + i, j * n + (i + 1) % n
            F += [(a, b, b + n), (a, b + n, a + n)]
    return V, np.array(F, dtype=np.int32)


def book(n, angle):
    """A square grid folded along x = 0.5 by `angle` (two flat pages)."""
    xs = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(xs, xs)
    x, y = X.ravel(), Y.ravel()
    far = x > 0.5
    V = np.stack([np.where(far, 0.5 + (x - 0.5) * np.cos(angle), x), y,
                  np.where(far, (x - 0.5) * np.sin(angle), 0.0)], axis=1)
    F = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            F += [(a, a + 1, a + n + 2), (a, a + n + 2, a + n + 1)]
    return V, np.array(F, dtype=np.int32)


@pytest.mark.parametrize("V,F,sources", [
    (*cylinder(24, 8), [0, 99]),
    (*cylinder(48, 20), [0, 483]),
    (*book(20, 0.5), [0, 200]),
    (*book(20, 1.2), [0, 200]),
], ids=["cylinder24x8", "cylinder48x20", "book0.5", "book1.2"])
def test_exact_on_developable_surfaces(V, F, sources):
    """Surfaces that unfold into the plane: the values are the exact
    solver's to 1e-12 relative (measured: 3.1e-15)."""
    m = meshfmm.Mesh(V, F)
    for s in sources:
        w, e = m.distance(s, method="windows"), m.distance(s, method="exact")
        pos = e > 0
        assert np.max(np.abs(w - e)[pos] / e[pos]) <= 1e-12
        assert w[s] == 0.0


@pytest.mark.parametrize("pages", [2, 3, 4])
def test_books(pages):
    """Flat pages sharing one spine edge (tests/python/oracles.py's book
    oracle, clean pages), windows crossing the spine into every other page:
    never below the geodesic distance, and exact (1e-12 relative) but at
    a few vertices where a window of the source was dropped for two pieces
    of a spine end's that reached the edge by routes whose rays between
    were never traced (so they may not join): measured on 2 pages, 12
    books, 2 vertices at most 7.7e-6 over; 3 and 4 pages exact."""
    from oracles import random_book, reference

    rng = np.random.default_rng(100 + pages)
    for _ in range(12):
        case = random_book(rng, n_pages=pages, clean=True)
        if not case.known:
            continue
        m = meshfmm.Mesh(case.V, case.F)
        s = int(rng.integers(len(case.V)))
        ref, w = reference(case, s), m.distance(s, method="windows")
        pos = ref > 0
        rel = (w[pos] - ref[pos]) / ref[pos]
        assert np.all(np.isfinite(w)) and rel.min() >= -BELOW
        assert np.count_nonzero(rel > 1e-12) <= 2 and rel.max() <= 1e-5
        if pages > 2:
            assert rel.max() <= 1e-12


def test_beetle_non_manifold_never_below_the_exact_solver():
    """beetle has 47 non-manifold edges: windows stop there, the values
    are still paths' lengths (measured least (d - e)/e: -1.9e-15)."""
    m = mesh("beetle.obj")
    for s in (10, 500, 900):
        w, e = m.distance(s, method="windows"), m.distance(s, method="exact")
        pos = np.isfinite(e) & (e > 0)
        assert np.array_equal(np.isfinite(w), np.isfinite(e))
        assert np.min((w[pos] - e[pos]) / e[pos]) >= -BELOW


@pytest.fixture(scope="module")
def spot():
    return mesh("spot.obj")


SOURCES = np.array([0, 17, 905, 2929, 17], dtype=np.int32)  # a repeated row too


def windows_rows(m, sources, **kw):
    return np.stack([m.distance(int(s), method="windows", **kw) for s in sources])


@pytest.mark.parametrize("backend", ["serial", "threads", "auto"])
def test_matrix_rows_equal_windows_solves(spot, backend):
    want = windows_rows(spot, SOURCES)
    D, info = spot.distance_matrix(SOURCES, backend=backend, dtype="float64", method="windows",
                                   return_info=True)
    assert np.array_equal(D, want)
    assert info.backend == ("serial" if backend == "serial" else "threads")
    if backend == "auto":  # auto says why it ran threads
        assert info.reason == ("auto runs the window method on threads (backend opencl runs it "
                               "on an OpenCL device)")
    # float32: the float64 rows rounded
    assert np.array_equal(spot.distance_matrix(SOURCES, backend=backend, method="windows"),
                          want.astype(np.float32))
    # not the march's rows
    assert not np.array_equal(D, spot.distance_matrix(SOURCES, backend=backend,
                                                       dtype="float64"))


@pytest.mark.parametrize("backend", ["serial", "threads"])
def test_matrix_targets_and_max_distance(spot, backend):
    targets = np.array([2929, 3, 400, 3, 0], dtype=np.int32)
    full = windows_rows(spot, SOURCES)
    D = spot.distance_matrix(SOURCES, backend=backend, dtype="float64", method="windows",
                             targets=targets)
    assert np.array_equal(D, full[:, targets])
    r = 0.3 * float(np.max(full[np.isfinite(full)]))
    D = spot.distance_matrix(SOURCES, backend=backend, dtype="float64", method="windows",
                             max_distance=r)
    assert np.array_equal(D, windows_rows(spot, SOURCES, max_distance=r))
    assert np.array_equal(np.isfinite(D), full <= r)
    assert np.array_equal(D[np.isfinite(D)], full[full <= r])


@pytest.mark.parametrize("backend", ["serial", "threads", "auto"])
def test_sparse_rows(spot, backend):
    pytest.importorskip("scipy")
    full = windows_rows(spot, SOURCES)
    r = 0.25 * float(np.max(full))
    S, info = spot.distance_matrix(SOURCES, backend=backend, dtype="float64", method="windows",
                                   max_distance=r, sparse=True, return_info=True)
    got = np.full(full.shape, np.inf)  # the stored entries (explicit zeros at the sources)
    rows = np.repeat(np.arange(S.shape[0]), np.diff(S.indptr))
    got[rows, S.indices] = S.data
    assert np.array_equal(np.isfinite(got), full <= r)
    assert np.array_equal(got[np.isfinite(got)], full[full <= r])
    assert info.backend == ("serial" if backend == "serial" else "threads")
    targets = np.array([5, 905, 17], dtype=np.int32)
    St = spot.distance_matrix(SOURCES, backend=backend, dtype="float64", method="windows",
                              max_distance=r, sparse=True, targets=targets)
    sub = full[:, targets]
    got = np.full(sub.shape, np.inf)
    rows = np.repeat(np.arange(St.shape[0]), np.diff(St.indptr))
    got[rows, St.indices] = St.data
    assert np.array_equal(np.isfinite(got), sub <= r)
    assert np.array_equal(got[np.isfinite(got)], sub[sub <= r])


def test_surface_point_targets(spot):
    pts = [SurfacePoint(10, (0.2, 0.3, 0.5)), 77, SurfacePoint(5000, (1.0, 0.0, 0.0)),
           SurfacePoint(4321, (0.25, 0.25, 0.5))]
    for backend in ("serial", "threads"):
        D = spot.distance_matrix(SOURCES, backend=backend, dtype="float64", method="windows",
                                 targets=pts)
        for i, s in enumerate(SOURCES):
            assert np.array_equal(D[i], spot.distance(int(s), method="windows", at=pts))


def test_iter_distance_rows(spot):
    want = windows_rows(spot, SOURCES)
    got = np.concatenate([b for _, b in spot.iter_distance_rows(
        SOURCES, block_rows=2, dtype="float64", backend="threads", method="windows")])
    assert np.array_equal(got, want)


def test_matrix_refusals(spot):
    with pytest.raises(ValueError, match="not a method of distance_matrix"):
        spot.distance_matrix([0, 1], method="exact")
    with pytest.raises(ValueError, match="method must be one of"):
        spot.distance_matrix([0, 1], method="mmp")


@pytest.mark.parametrize("where", ["vertex", "face"])
def test_cost_scales_and_rows_equal_solves(spot, where):
    """A constant cost c: c times the values without one (1e-12 relative).
    A varying cost: matrix rows on every backend equal the solves."""
    n = spot.n_vertices if where == "vertex" else spot.n_faces
    for s in (0, 905):
        d1 = spot.distance(s, method="windows")
        dc = spot.distance(s, np.full(n, 2.5), cost_location=where, method="windows")
        np.testing.assert_allclose(dc, 2.5 * d1, rtol=1e-12, atol=0)
    cost = 1.0 + 0.5 * (np.arange(n) % 3 == 0)
    want = np.stack([spot.distance(int(s), cost, cost_location=where, method="windows")
                     for s in SOURCES])
    for backend in ("serial", "threads"):
        got = spot.distance_matrix(SOURCES, backend=backend, dtype="float64", method="windows",
                                   cost=cost, cost_location=where)
        assert np.array_equal(got, want), backend
    got = np.concatenate([b for _, b in spot.iter_distance_rows(
        SOURCES, block_rows=2, dtype="float64", backend="threads", method="windows",
        cost=cost, cost_location=where)])
    assert np.array_equal(got, want)


def test_face_cost_values_are_paths(spot):
    """Per face no face has mixed cost, so every value is a weighted path
    length: never below the least cost times the exact geodesic distance
    (1e-9 relative), and where no path shorter than the value leaves the
    cost-1 region the windows values without a cost."""
    F, V = spot.faces, spot.vertices
    cost = 1.0 + (V[F, 1].min(axis=1) > 0.0)  # cost 2: faces wholly above y = 0
    s = 7  # at y = -0.055
    d = spot.distance(s, cost, cost_location="face", method="windows")
    ex = spot.distance(s, method="exact")
    assert np.all(d >= ex * (1.0 - 1e-9))
    near = spot.distance(s, method="windows")
    inside = near < -V[s, 1]  # shorter than the way up to y = 0
    assert inside.sum() >= 5
    np.testing.assert_allclose(d[inside], near[inside], rtol=1e-12, atol=0)


@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_opencl_rows_equal_serial_rows(spot, dtype):
    """The OpenCL kernel runs the C core's own propagation (slots_core.h):
    dense rows, target columns and max_distance rows, with and without a
    cost, bit for bit."""
    tg = [3, 100, spot.n_vertices - 1]
    vcost = 1.0 + 0.5 * (np.arange(spot.n_vertices) % 3 == 0)
    fcost = 1.0 + 2.0 * (spot.vertices[spot.faces[:, 0], 2] > 0.0)
    kws = [dict(), dict(targets=tg), dict(max_distance=0.3),
           dict(cost=vcost, cost_location="vertex"), dict(cost=fcost, cost_location="face"),
           dict(cost=1.5 * vcost, cost_location="vertex", targets=tg, max_distance=0.6)]
    for kw in kws:
        want = spot.distance_matrix(SOURCES, backend="serial", dtype=dtype, method="windows",
                                    **kw)
        try:
            got = spot.distance_matrix(SOURCES, backend="opencl", dtype=dtype,
                                       method="windows", **kw)
        except meshfmm.OpenCLError:
            pytest.skip("no OpenCL device")
        assert np.array_equal(got, want), kw


def test_farthest_point_sampling_equals_a_loop_of_windows_solves(spot):
    k = 12
    pts, radii, dist = spot.farthest_point_sampling(k, start=5, method="windows",
                                                    return_radii=True, return_distances=True)
    chosen = [5]
    best = spot.distance(5, method="windows")
    want_radii = [np.inf]
    for _ in range(k - 1):
        v = int(np.argmax(best))  # ties to the lowest id, as the library
        want_radii.append(best[v])
        chosen.append(v)
        best = np.minimum(best, spot.distance(v, method="windows"))
    assert pts.tolist() == chosen
    assert np.array_equal(radii, want_radii)
    assert np.array_equal(dist, best)
    assert pts.tolist() != spot.farthest_point_sampling(k, start=5).tolist()
    with pytest.raises(ValueError, match="not a method of farthest_point_sampling"):
        spot.farthest_point_sampling(3, method="exact")
    c = 1.0 + (np.arange(spot.n_vertices) % 4 == 0)
    pts = spot.farthest_point_sampling(3, start=5, method="windows", cost=c)
    far = int(np.argmax(spot.distance(5, c, method="windows")))
    assert pts.tolist()[:2] == [5, far]


def test_voronoi_labels_and_path_take_the_method(spot):
    src = [0, 905, 2000]
    d = spot.distance(src, method="windows")
    assert np.array_equal(spot.voronoi_labels(src, method="windows"),
                          spot.voronoi_labels(src, d))
    p = spot.path(0, 2929, method="windows")
    back = spot.geodesic_path(spot.distance(0, method="windows"), 2929, sources=[0])
    assert np.array_equal(p.points, back.points[::-1])
    c = 1.0 + (np.arange(spot.n_vertices) % 4 == 0)
    p = spot.path(0, 2929, method="windows", cost=c)
    back = spot.geodesic_path(spot.distance(0, c, method="windows"), 2929, sources=[0], cost=c)
    assert np.array_equal(p.points, back.points[::-1])


# ----------------------------------------------------------- random meshes
hypothesis = pytest.importorskip("hypothesis", reason="property tests need hypothesis")
from hypothesis import given  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from test_properties import SETTINGS, meshes  # noqa: E402


@SETTINGS
@given(meshes(cost=False), st.data())
def test_random_meshes_never_below_the_exact_solver(mesh_case, data):
    """On jittered grids with random heights (saddles, boundaries), from
    one to three vertex sources and a point in a face: windows >= the exact
    solver's distance - 1e-9 relative, and the matrix rows equal the
    solves."""
    V, F, _, _ = mesh_case
    m = meshfmm.Mesh(V, F)
    nv = len(V)
    srcs = data.draw(st.lists(st.integers(0, nv - 1), min_size=1, max_size=3, unique=True))
    face = data.draw(st.integers(0, len(F) - 1))
    for sources in (srcs, [SurfacePoint(face, (0.2, 0.5, 0.3))]):
        d = m.distance(sources, method="windows")
        e = m.distance(sources, method="exact")
        assert np.all(d >= e - BELOW * np.abs(e)), (sources, np.min(d - e))
    D = m.distance_matrix(srcs, backend="serial", dtype="float64", method="windows")
    assert np.array_equal(D, windows_rows(m, srcs))
