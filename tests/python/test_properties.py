"""Properties of the solver on random small meshes (hypothesis).

Meshes: jittered grids with random heights and random diagonals (so obtuse
corners and virtual edges occur), some with a random per-face or per-vertex
cost. The properties hold for the discrete scheme exactly (up to rounding),
not only in the limit:

- T(source) = 0;
- across every edge uv, |T(u) - T(v)| <= |uv| F: every local update offers
  the edge's own 1-D update (Kimmel & Sethian section 3), with F the cost the
  core uses there: per face, the smallest of the edge's faces; per vertex, the
  cost of the later (larger T) vertex;
- adding a source never raises T (the scheme is monotone);
- distance_matrix rows equal single solves, bit for bit;
- a geodesic path is a polyline on the surface from the target to a source,
  so its length is at least the exact polyhedral distance (igl.exact_geodesic),
  which T(target) approximates.

Deterministic (derandomize=True, no example database) and small, so the whole
file runs in seconds.
"""

from __future__ import annotations

import numpy as np
import pytest

import meshfmm

hypothesis = pytest.importorskip("hypothesis", reason="property tests need hypothesis "
                                 "(pip install -r requirements-dev.txt)")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

SETTINGS = settings(max_examples=60, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow])

# Relative rounding allowance of the checks that are exact in real arithmetic.
EPS = 1e-12


def random_mesh(seed: int, nx: int, ny: int, jitter: float, height: float):
    """A (nx+1) x (ny+1) grid on [0,1]^2, vertices jittered in the plane by
    up to `jitter` of a cell, heights up to `height`, each square cut along a
    random diagonal. Every vertex is referenced, faces are never degenerate
    (jitter < 0.3 keeps each square convex)."""
    rng = np.random.default_rng(seed)
    xs = np.linspace(0.0, 1.0, nx + 1)
    ys = np.linspace(0.0, 1.0, ny + 1)
    X, Y = np.meshgrid(xs, ys, indexing="xy")
    V = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], axis=1)
    V[:, 0] += rng.uniform(-jitter, jitter, X.size) / nx
    V[:, 1] += rng.uniform(-jitter, jitter, X.size) / ny
    V[:, 2] = height * rng.uniform(-1.0, 1.0, X.size) / max(nx, ny)
    F = []
    flip = rng.integers(0, 2, nx * ny)
    for j in range(ny):
        for i in range(nx):
            a = j * (nx + 1) + i
            b, c, d = a + 1, a + nx + 1, a + nx + 2
            if flip[j * nx + i]:
                F += [(a, b, d), (a, d, c)]
            else:
                F += [(a, b, c), (b, d, c)]
    return V, np.array(F, dtype=np.int32)


@st.composite
def meshes(draw, cost=True):
    seed = draw(st.integers(0, 2**32 - 1))
    nx = draw(st.integers(2, 7))
    ny = draw(st.integers(2, 7))
    jitter = draw(st.sampled_from([0.0, 0.15, 0.28]))
    height = draw(st.sampled_from([0.0, 0.3, 1.5]))
    V, F = random_mesh(seed, nx, ny, jitter, height)
    where = draw(st.sampled_from(["none", "face", "vertex"])) if cost else "none"
    rng = np.random.default_rng(seed + 1)
    c = None
    if where == "face":
        c = rng.uniform(0.5, 4.0, len(F))
    elif where == "vertex":
        c = rng.uniform(0.5, 4.0, len(V))
    return V, F, c, where


def solve(m, sources, c, where, **kw):
    if c is None:
        return m.distance(sources, **kw)
    return m.distance(sources, cost=c, cost_location=where, **kw)


def edge_bound(V, F, T, c, where):
    """(u, v, |T(u) - T(v)|, |uv| F) over every edge."""
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    fid = np.tile(np.arange(len(F)), 3)
    e.sort(axis=1)
    length = np.linalg.norm(V[e[:, 0]] - V[e[:, 1]], axis=1)
    if where == "face":
        f = c[fid]
    elif where == "vertex":
        # F linear along the edge: the mean of its ends (march.h)
        f = 0.5 * (c[e[:, 0]] + c[e[:, 1]])
    else:
        f = np.ones(len(e))
    # per face cost: the cheapest of the edge's faces
    key = e[:, 0].astype(np.int64) * len(V) + e[:, 1]
    order = np.lexsort((f, key))
    key, e, f, length = key[order], e[order], f[order], length[order]
    first = np.ones(len(key), dtype=bool)
    first[1:] = key[1:] != key[:-1]
    e, f, length = e[first], f[first], length[first]
    return e[:, 0], e[:, 1], np.abs(T[e[:, 0]] - T[e[:, 1]]), length * f


@SETTINGS
@given(meshes(), st.data())
def test_source_zero_and_edge_triangle_inequality(mesh_case, data):
    V, F, c, where = mesh_case
    m = meshfmm.Mesh(V, F)
    k = data.draw(st.integers(1, 3))
    sources = data.draw(st.lists(st.integers(0, len(V) - 1), min_size=k, max_size=k))
    for unfolding in (True, False):
        T = solve(m, sources, c, where, unfolding=unfolding)
        assert np.isfinite(T).all()
        assert (T[sources] == 0).all(), T[sources]
        assert (T >= 0).all()
        u, v, diff, bound = edge_bound(V, F, T, c, where)
        bad = diff > bound * (1 + EPS) + EPS
        assert not bad.any(), (
            f"unfolding={unfolding}: |T(u)-T(v)| > |uv| F on {bad.sum()} edges, e.g. "
            f"u={u[bad][0]} v={v[bad][0]}: {diff[bad][0]!r} > {bound[bad][0]!r}")


@SETTINGS
@given(meshes(), st.data())
def test_adding_a_source_never_raises_T(mesh_case, data):
    V, F, c, where = mesh_case
    m = meshfmm.Mesh(V, F)
    ids = st.integers(0, len(V) - 1)
    fewer = data.draw(st.lists(ids, min_size=1, max_size=3))
    extra = data.draw(ids)
    T1 = solve(m, fewer, c, where)
    T2 = solve(m, fewer + [extra], c, where)
    assert T2[extra] == 0
    worse = T2 > T1 * (1 + EPS) + EPS
    assert not worse.any(), (
        f"{worse.sum()} vertices got farther when source {extra} was added to {fewer}: "
        f"e.g. vertex {np.flatnonzero(worse)[0]}: {T1[worse][0]!r} -> {T2[worse][0]!r}")


@SETTINGS
@given(meshes(), st.data())
def test_matrix_rows_equal_single_solves(mesh_case, data):
    V, F, c, where = mesh_case
    m = meshfmm.Mesh(V, F)
    sources = data.draw(st.lists(st.integers(0, len(V) - 1), min_size=1, max_size=8))
    backend = data.draw(st.sampled_from(["serial", "threads"]))
    kw = {} if c is None else {"cost": c, "cost_location": where}
    D = m.distance_matrix(sources, backend=backend, dtype="float64", n_threads=2, **kw)
    for i, s in enumerate(sources):
        np.testing.assert_array_equal(D[i], solve(m, s, c, where))
    D32 = m.distance_matrix(sources, backend=backend, dtype="float32", n_threads=2, **kw)
    np.testing.assert_array_equal(D32, D.astype(np.float32))


# Found by the path property (a jittered 4 x 4 grid): T(7) comes from source 3
# through a virtual edge (section 4.2), across faces that do not touch vertex
# 7's neighbours, so T has a local minimum at vertex 7 among its mesh
# neighbours, and backtracking along -grad T stalls there unless paths follow
# virtual edges through their strips.


@pytest.mark.parametrize("straighten", [True, False])
def test_regression_path_stalls_at_a_virtual_edge_minimum(straighten):
    V, F = random_mesh(0, 4, 4, 0.28, 0.3)
    m = meshfmm.Mesh(V, F)
    T = m.distance(3)
    assert T[7] == pytest.approx(0.2543890127883522, rel=1e-12)
    # plain stencils (no virtual edges): no local minimum, the path is traced
    p = m.geodesic_path(m.distance(3, unfolding=False), 7, sources=[3], straighten=straighten)
    np.testing.assert_allclose(p.points[-1], V[3], atol=1e-12)
    path = m.geodesic_path(T, 7, sources=[3], straighten=straighten)
    np.testing.assert_allclose(path.points[0], V[7], atol=1e-12)
    np.testing.assert_allclose(path.points[-1], V[3], atol=1e-12)
    assert path.length >= np.linalg.norm(V[7] - V[3]) - 1e-12


@SETTINGS
@given(meshes(cost=False), st.data())
def test_path_from_target_to_source_no_shorter_than_exact(mesh_case, data):
    igl = pytest.importorskip("igl")
    V, F, _, _ = mesh_case
    m = meshfmm.Mesh(V, F)
    n = len(V)
    s = data.draw(st.integers(0, n - 1), label="source")
    t = data.draw(st.integers(0, n - 1).filter(lambda x: x != s), label="target")
    straighten = data.draw(st.booleans(), label="straighten")
    T = m.distance(s)
    path = m.geodesic_path(T, t, sources=[s], straighten=straighten)
    exact = float(igl.exact_geodesic(V, F.astype(np.int64), VS=np.array([s], dtype=np.int64),
                                     VT=np.array([t], dtype=np.int64))[0])
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    tol = 1e-9 * diag
    # ends: the target first, the source last
    np.testing.assert_allclose(path.points[0], V[t], atol=tol, rtol=0)
    np.testing.assert_allclose(path.points[-1], V[s], atol=tol, rtol=0)
    # the length is the polyline's
    seg = np.linalg.norm(np.diff(path.points, axis=0), axis=1).sum()
    assert abs(seg - path.length) <= tol + 1e-12 * seg
    # every point lies in its face
    bary = path.barycentric
    assert (bary >= -1e-9).all() and np.allclose(bary.sum(1), 1.0)
    on = np.einsum("ki,kij->kj", bary, V[F[path.faces]])
    np.testing.assert_allclose(on, path.points, atol=tol, rtol=0)
    # a path on the surface is never shorter than the geodesic distance, and
    # T(target) approximates that distance
    assert path.length >= exact - tol, (path.length, exact, T[t])
