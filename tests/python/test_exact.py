"""mfmm_solve_exact through the C ABI (meshfmm._lib): live against
igl.exact_geodesic (Kirsanov's MMP) on the smallest test mesh, from
vertices and from face centroids (igl's face sources), and the refusal of a
cost. The stored references of all meshes are checked by bench/suite/bench_exact.py
and tests/c/test_exact.c."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from conftest import MESHES, need_data
from meshfmm import _lib


def _solve_exact(V, F, source, options=None):
    err = _lib.mfmm_error()
    mesh, solver = ctypes.c_void_p(), ctypes.c_void_p()
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int32)
    assert _lib.mfmm_mesh_create(V.ctypes.data, len(V), F.ctypes.data, len(F), None,
                                 ctypes.byref(mesh), ctypes.byref(err)) == 0, err.message
    try:
        assert _lib.mfmm_exact_solver_create(mesh, ctypes.byref(solver)) == 0
        out = np.empty(len(V))
        info = _lib.mfmm_exact_info()
        st = _lib.mfmm_solve_exact(solver, ctypes.byref(source), 1,
                                   ctypes.byref(options) if options else None,
                                   out.ctypes.data, ctypes.byref(info), ctypes.byref(err))
        return st, out, info, err
    finally:
        _lib.mfmm_exact_solver_destroy(solver)
        _lib.mfmm_mesh_destroy(mesh)


def test_live_against_igl():
    igl = pytest.importorskip("igl")
    need_data()
    V, F = igl.read_triangle_mesh(str(MESHES / "hand_lowres.obj"))
    F = F.astype(np.int64)
    none = np.array([], dtype=np.int64)
    every = np.arange(len(V), dtype=np.int64)
    for v in (3, 400):
        ref = igl.exact_geodesic(V, F, np.array([v]), none, every, none)
        st, d, info, err = _solve_exact(V, F, _lib.mfmm_source(v, -1, (0.0, 0.0, 0.0), 0.0))
        assert st == 0, err.message
        np.testing.assert_allclose(d, ref, rtol=1e-12, atol=0)
        assert info.n_windows > 0 and info.peak_bytes > 0
    for f in (7, 1000):
        ref = igl.exact_geodesic(V, F, none, np.array([f]), every, none)
        third = 1.0 / 3.0
        st, d, _, err = _solve_exact(V, F, _lib.mfmm_source(0, f, (third, third, third), 0.0))
        assert st == 0, err.message
        np.testing.assert_allclose(d, ref, rtol=1e-12, atol=0)


def test_exact_options_take_no_cost():
    """Exact distances are for F = 1: the options have no cost to refuse."""
    names = [name for name, _ in _lib.mfmm_exact_options._fields_]
    assert "cost" not in names and "cost_location" not in names


@pytest.mark.parametrize("name", ["hand_lowres", "spot", "wingnut", "fertility_FE_10k",
                                  "decimated-max", "camelhead"])
def test_mesh_distance_method_exact_equals_stored_igl(name, reference_dir):
    """Mesh.distance(method="exact") against the stored igl.exact_geodesic rows
    (1e-9 relative; the larger meshes are checked by bench/suite/bench_exact.py)."""
    import meshfmm
    from conftest import load

    ext = {"fertility_FE_10k": ".off", "camelhead": ".off"}.get(name, ".obj")
    mesh = meshfmm.Mesh(*load(name + ext))
    ref = np.load(reference_dir / f"{name}.npz")
    for s, e in zip(ref["sources"], ref["distances"]):
        d = mesh.distance(int(s), method="exact")
        fin = np.isfinite(e)
        assert np.array_equal(np.isfinite(d), fin)
        pos = fin & (e > 0)
        assert np.max(np.abs(d[pos] - e[pos]) / e[pos]) < 1e-9
        assert d[int(s)] == 0.0


def test_mesh_distance_method_exact_refuses_what_it_cannot_do():
    import meshfmm
    from conftest import load

    mesh = meshfmm.Mesh(*load("hand_lowres.obj"))
    with pytest.raises(ValueError, match="no cost"):
        mesh.distance(0, cost=np.ones(mesh.n_vertices), method="exact")
    with pytest.raises(ValueError, match="method"):
        mesh.distance(0, method="mmp")
    with pytest.raises(ValueError, match="max_distance"):
        mesh.distance(0, method="exact", max_distance=-1.0)
    d = mesh.distance(0, method="exact", max_distance=0.05)
    full = mesh.distance(0, method="exact")
    near = full <= 0.05
    assert np.array_equal(d[near], full[near]) and np.all(np.isinf(d[~near]))


def test_cli_distance_exact(tmp_path, reference_dir):
    """`meshfmm distance --exact` equals the stored igl.exact_geodesic row;
    with --cost it is refused with a sentence and status 2."""
    import subprocess

    import meshfmm.__main__

    # the package's own binary, else $MESHFMM_CLI (a development build)
    cli = meshfmm.__main__.cli_path()
    if not cli:
        pytest.skip("no meshfmm command line in the package and MESHFMM_CLI is not set "
                    "(scripts/test.sh sets it to build/meshfmm)")
    ref = np.load(reference_dir / "spot.npz")
    out = tmp_path / "d.npy"
    r = subprocess.run([cli, "distance", str(MESHES / "spot.obj"), f"--source={ref['sources'][1]}",
                        "--exact", "-o", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    d, e = np.load(out), ref["distances"][1]
    pos = e > 0
    assert np.max(np.abs(d[pos] - e[pos]) / e[pos]) < 1e-9
    np.save(tmp_path / "c.npy", np.ones(len(d)))
    r = subprocess.run([cli, "distance", str(MESHES / "spot.obj"), "--source", "0", "--exact",
                        "--cost", str(tmp_path / "c.npy"), "-o", str(tmp_path / "x.npy")],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "--exact" in r.stderr


def _grid_with_t_junctions(n=10, splits=((3, 4), (5, 5), (6, 2), (2, 7)), resolved=False):
    """A flat n x n grid on [0,1]^2 whose diagonals at the given squares are
    split on one side only: the diagonal's other face is cut in two at the
    midpoint m, and a zero-area face (q, p, m) closes the T-junction, as
    exporters and mesh repair tools leave them. The surface is still the
    unit square, so distances are Euclidean. resolved: the same surface
    without the junctions, face (a, b, d) cut at m too (as the library
    splits it: (m, b, d) and (a, b, m)) and no cap."""
    xs = np.linspace(0.0, 1.0, n + 1)
    V = [(x, y, 0.0) for y in xs for x in xs]
    F = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 1, a + n + 2
            if (i, j) in splits:  # faces (a, b, d) and (d, c, a) share diagonal a-d
                m = len(V)
                V.append(((V[a][0] + V[d][0]) / 2, (V[a][1] + V[d][1]) / 2, 0.0))
                if resolved:
                    F += [(m, b, d), (a, b, m), (d, c, m), (m, c, a)]
                else:
                    F += [(a, b, d), (d, c, m), (m, c, a), (d, a, m)]  # (d, a, m): the cap
            else:
                F += [(a, b, d), (d, c, a)]
    return np.array(V), np.array(F, dtype=np.int32)


def test_zero_area_faces_closing_t_junctions_are_no_walls():
    """Zero-area faces were walls for the exact solver: across a T-junction
    closed by a needle cap a path went round through a vertex (the square
    split at (.5,.5), (.25,.25) gave 1.0607 for 0.7906), and on an
    all-degenerate strip nothing was reached. Now windows pass through the
    needle (ex_pass) and its edges are relaxed; the exact solver equals the
    Euclidean distance on the flat grid (analytic), as does the FMM within
    its exact start's radius."""
    import meshfmm

    V, F = _grid_with_t_junctions()
    m = meshfmm.Mesh(V, F)
    assert m.info.n_degenerate_faces == 4
    for s in (0, 37, 60, 120):
        ref = np.linalg.norm(V - V[s], axis=1)
        np.testing.assert_allclose(m.distance(s, method="exact"), ref, rtol=1e-12, atol=1e-14)
        near = ref < 0.3  # inside the exact start of every source here
        np.testing.assert_allclose(m.distance(s)[near], ref[near], rtol=1e-12, atol=1e-14)
    strip = meshfmm.Mesh([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0.0]], [[0, 1, 2], [1, 2, 3]])
    np.testing.assert_array_equal(strip.distance(0, method="exact"), [0.0, 1.0, 2.0, 3.0])


def test_needle_on_a_non_manifold_edge():
    """A needle A-M-B whose long edge AB has two pages besides. Analytic:
    the plane z = 0, the source S below AM, crossing AB only on AM; page Q
    stands upright on AB; E is reached only by bending at M, at
    sqrt(5) + sqrt(4.5), through A it is sqrt(10) + sqrt(2.5).

    Closed (both pages split at M, as one face across is): the rows from
    every vertex, plain and exact start, equal the mesh given resolved; the
    march had C at 4.1985 for 3.2361 (no triangle update through the
    needle) and the path to E went through A, 4.7434.

    Left as it is (a page with a copy): the exact solver starts M's windows
    on AB with I on the edge, whose interval holds directions, not points;
    the windows that reached AB first, shorter at every point of AM, cut
    away M's whole left sector, and E took the path through A, 4.7434 (a
    fuzzed mesh found it, as a broken triangle inequality)."""
    import meshfmm

    V = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, -1, 0], [1, 1, 0], [-0.5, 1.5, 0],
                  [1, 0, 1]], dtype=np.float64)
    A, M, B, S, C, E, D = range(7)
    F = np.array([[A, S, M], [A, M, B], [A, B, C], [A, C, E], [A, D, B]], dtype=np.int32)
    dm = np.sqrt(5.0)  # S to M along their edge
    ref = np.array([np.sqrt(10.0), dm, dm + 1, 0.0, dm + 1, dm + np.sqrt(4.5), dm + 1])
    m = meshfmm.Mesh(V, F)
    assert (m.info.n_nonmanifold_edges, m.info.n_degenerate_faces) == (1, 1)
    resolved = meshfmm.Mesh(V, [[A, S, M], [A, M, C], [M, B, C], [A, C, E], [A, D, M],
                                [M, D, B]])
    for s in range(len(V)):
        for exact_start in (True, False):
            np.testing.assert_array_equal(m.distance(s, exact_start=exact_start),
                                          resolved.distance(s, exact_start=exact_start))
    np.testing.assert_allclose(m.distance(S, method="exact"), ref, rtol=1e-12, atol=1e-14)
    path = m.geodesic_path(m.distance(S), E)
    assert path.length == pytest.approx(ref[E], rel=1e-12)

    copied = meshfmm.Mesh(V, np.concatenate([F, F[-1:]]))
    assert copied.info.n_duplicate_faces == 1
    np.testing.assert_allclose(copied.distance(S, method="exact"), ref, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(copied.distance(S), ref, rtol=1e-12, atol=1e-14)  # exact start


def test_t_junctions_are_closed_for_the_march():
    """The march takes no triangle update through a zero-area face, so
    beyond its exact start it crossed a T-junction's needle only along
    edges, through the junction's ends (the square split at (.5, .5):
    1.0607 for 0.7906 from the plain start). The library now splits the
    face across the needle at its middle vertex and drops the needle: every
    row equals the same surface given resolved (reference: the serial core
    on that mesh) bit for bit, plain and exact start, and with a per-face
    cost given per input face on the serial, threads and OpenCL backends;
    the counts stay the input's."""
    import meshfmm

    V, F = _grid_with_t_junctions()
    Vr, Fr = _grid_with_t_junctions(resolved=True)
    m, r = meshfmm.Mesh(V, F), meshfmm.Mesh(Vr, Fr)
    assert m.info.n_faces == len(F) and m.n_faces == len(F)
    assert m.info.n_degenerate_faces == 4 and r.info.n_degenerate_faces == 0
    for start in (False, "auto"):
        np.testing.assert_array_equal(m.distance_matrix(np.arange(len(V)), exact_start=start,
                                                        dtype="float64"),
                                      r.distance_matrix(np.arange(len(V)), exact_start=start,
                                                        dtype="float64"))
    # a per-face cost of the input faces (the caps' entries unused): the
    # resolved mesh's pieces take their face's, on every backend; faces come
    # 2 per square, 4 where split ((a,b,d) first; resolved: its two pieces)
    rng = np.random.default_rng(3)
    cost = rng.uniform(1.0, 3.0, len(F))
    cost_r, i = [], 0
    for j in range(10):  # the generator's squares, in its order (n = 10)
        for k in range(10):
            split = (k, j) in ((3, 4), (5, 5), (6, 2), (2, 7))
            cost_r += [cost[i], cost[i], cost[i + 1], cost[i + 2]] if split else [cost[i], cost[i + 1]]
            i += 4 if split else 2
    assert len(cost_r) == len(Fr)
    src = np.arange(0, len(V), 7)
    want = r.distance_matrix(src, dtype="float64", cost=np.array(cost_r), cost_location="face",
                             backend="serial")
    for backend in ("serial", "threads", "opencl"):
        try:
            got = m.distance_matrix(src, dtype="float64", cost=cost, cost_location="face",
                                    backend=backend)
        except meshfmm.OpenCLError:
            continue  # no device here: the other backends still ran
        np.testing.assert_array_equal(got, want)


def _book(n, pages=((0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0.6, 0.8))):
    """Unit square pages, each an n x n grid, hinged on the segment [0,1] of
    the x axis and sharing its vertices: every hinge edge is non-manifold
    (one face per page). The surface is the pages joined at the hinge, so a
    shortest path from a point (x0, y0) of page 0 to the point at height z
    above the hinge on another page is straight once that page is unfolded
    across the hinge: length hypot(x - x0, y0 + z) (analytic)."""
    V, ids = [], {}

    def vertex(key, p):
        if key not in ids:
            ids[key] = len(V)
            V.append(p)
        return ids[key]

    F = []
    for j, d in enumerate(pages):
        for a in range(n + 1):
            for b in range(n + 1):
                key = ("hinge", a) if b == 0 else (j, a, b)
                vertex(key, (a / n, b / n * d[1], b / n * d[2]))
        at = lambda a, b: ids[("hinge", a) if b == 0 else (j, a, b)]  # noqa: E731
        for a in range(n):
            for b in range(n):
                F += [(at(a, b), at(a + 1, b), at(a + 1, b + 1)),
                      (at(a, b), at(a + 1, b + 1), at(a, b + 1))]
    V = np.array(V, dtype=np.float64)
    page = np.zeros(len(V), dtype=np.int64)
    for key, i in ids.items():  # -1: the hinge
        page[i] = -1 if key[0] == "hinge" else key[0]
    return V, np.array(F, dtype=np.int32), page


def test_non_manifold_edges_are_no_walls():
    """Non-manifold edges were walls for the exact solver: a path from one
    page of a book to another bent at a hinge vertex (n = 8, three pages:
    0.011 too long; beetle.obj's 47 such edges: up to 0.030 above the length
    of a real path, a Steiner-graph Dijkstra bound). Now a window reaching a
    non-manifold edge goes on into every other face on it (ex_fan_out), and
    the exact solver equals the unfolded distance (analytic), from vertices
    of a page and of the hinge; the FMM takes those values within its exact
    start."""
    import meshfmm

    # eight pages at 90, -90, 0, 37, 143, 10, 170 and -20 degrees: folded
    # fans, where windows are trimmed against the earlier ones of a hinge face
    folded = tuple((0.0, float(np.cos(a)), float(np.sin(a)))
                   for a in np.deg2rad([90, -90, 0, 37, 143, 10, 170, -20]))
    for pages in ((0, 1, 0), (0, -1, 0), (0, 0, 1)), \
            ((0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0.6, 0.8)), folded:
        V, F, page = _book(8, pages=pages)
        m = meshfmm.Mesh(V, F)
        assert m.info.n_nonmanifold_edges == 8
        for s in np.flatnonzero(page == 0)[[3, 20, 41]].tolist() + [int(np.flatnonzero(page == -1)[5])]:
            x0, y0 = V[s, 0], np.linalg.norm(V[s, 1:])
            height = np.linalg.norm(V[:, 1:], axis=1)
            same = (page == page[s]) | (page == -1) if page[s] >= 0 else np.ones(len(V), bool)
            ref = np.where(same & (page[s] >= 0),
                           np.linalg.norm(V - V[s], axis=1),
                           np.hypot(V[:, 0] - x0, y0 + height))
            np.testing.assert_allclose(m.distance(s, method="exact"), ref, rtol=1e-12,
                                       atol=1e-14)
            near = ref < 0.5  # inside the exact start (7 edges of 1/8)
            np.testing.assert_allclose(m.distance(s)[near], ref[near], rtol=1e-12, atol=1e-14)


def _steiner_bound(V, F, k, source):
    """Lengths of real paths from vertex source: Dijkstra on a Steiner graph
    (each edge cut in k, every two boundary points of a face joined by their
    segment), an upper bound on the geodesic distance of every vertex."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import dijkstra

    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    key = np.sort(E, axis=1)
    edges, inv = np.unique(key, axis=0, return_inverse=True)
    inv = inv.ravel()
    t = np.arange(1, k) / k
    P = np.concatenate([V, (V[edges[:, 0], None] * (1 - t)[:, None]
                            + V[edges[:, 1], None] * t[:, None]).reshape(-1, 3)])
    inner = len(V) + inv[:, None] * (k - 1) + np.arange(k - 1)  # from key[:, 0]
    inner = np.where((E[:, 0] == key[:, 0])[:, None], inner, inner[:, ::-1])
    nf = len(F)
    ring = np.concatenate([np.concatenate([E[j * nf:(j + 1) * nf, :1],
                                           inner[j * nf:(j + 1) * nf]], axis=1)
                           for j in range(3)], axis=1)  # (nf, 3k) points of a face
    r = np.repeat(ring, ring.shape[1], axis=1).ravel()
    c = np.tile(ring, (1, ring.shape[1])).ravel()
    w = np.linalg.norm(P[r] - P[c], axis=1)
    G = sp.csr_matrix((w, (r, c)), shape=(len(P), len(P)))  # duplicates: summed, so
    G.data = np.linalg.norm(P[G.indices] - P[np.repeat(np.arange(len(P)), np.diff(G.indptr))],
                            axis=1)  # the lengths again
    return dijkstra(G, indices=source)[:len(V)]


def test_beetle_nonmanifold_edges_crossed():
    """beetle.obj has 47 non-manifold edges. With them as walls the exact
    solver was up to 0.030 above the length of a real path across them;
    now it crosses them (its budget not reached: nonmanifold_walls 0) and no
    value lies above a real path's length (a Steiner-graph bound)."""
    import meshfmm

    need_data()
    V, F = meshfmm.load_mesh(MESHES / "beetle.obj")
    for s in (0, 100, 1147):
        st, d, info, err = _solve_exact(V, F, _lib.mfmm_source(s, -1, (0.0, 0.0, 0.0), 0.0))
        assert st == 0, err.message
        assert info.nonmanifold_walls == 0
        bound = _steiner_bound(V, F, 6, s)
        finite = np.isfinite(bound)
        np.testing.assert_array_equal(np.isfinite(d), finite)
        assert np.all(d[finite] <= bound[finite] + 1e-12)


def fuzz_exact_mesh(name):
    """The mesh of tests/fuzz/regressions/exact/NAME as tests/fuzz/fuzz_exact.c
    decodes it: V (nv, 3), F (nf, 3; faces may repeat a vertex), the input's
    bytes and the offset of its source bytes."""
    from pathlib import Path

    data = (Path(__file__).resolve().parents[1] / "fuzz" / "regressions" / "exact"
            / name).read_bytes() + bytes(4096)
    nv, nf = 3 + data[0] % 64, 1 + data[1] % 128
    V = np.frombuffer(data[4:4 + 3 * nv], dtype=np.int8).astype(np.float64).reshape(nv, 3) / 8
    F = (np.frombuffer(data[4 + 3 * nv:4 + 3 * nv + 3 * nf], dtype=np.uint8) % nv)
    return V, F.astype(np.int32).reshape(nf, 3), data, 4 + 3 * nv + 3 * nf


def test_degenerate_fans_finish_without_walls():
    """A fuzzed mesh (tests/fuzz/regressions/exact/
    nonmanifold-coincident-fans-window-cycle: coincident vertices, folded
    fans of non-manifold edges) where windows crossing those edges went
    round without getting farther, forever, and later passed its budget of
    windows (the solve redone with those edges as walls): copies of one
    window passed on through needles on those edges, now trimmed as windows
    into faces are, and the solve finishes crossing them. The fallback to
    walls itself: test_exact.c, test_nonmanifold_walls_past_budget."""
    V, F, data, at = fuzz_exact_mesh("nonmanifold-coincident-fans-window-cycle")
    nv, nf = len(V), len(F)
    at = 4 + 3 * nv + 3 * nf  # flags 8: two sources, the second with a value
    assert data[2] & 8
    sources = (_lib.mfmm_source * 2)(_lib.mfmm_source(data[at] % nv, -1, (0.0, 0.0, 0.0), 0.0),
                                     _lib.mfmm_source(data[at + 1] % nv, -1, (0.0, 0.0, 0.0),
                                                      (data[at + 2] % 8) / 8))
    err, info = _lib.mfmm_error(), _lib.mfmm_exact_info()
    mesh, solver = ctypes.c_void_p(), ctypes.c_void_p()
    assert _lib.mfmm_mesh_create(V.ctypes.data, nv, F.ctypes.data, nf, None, ctypes.byref(mesh),
                                 ctypes.byref(err)) == 0, err.message
    d = np.empty(nv)
    try:
        assert _lib.mfmm_exact_solver_create(mesh, ctypes.byref(solver)) == 0
        assert _lib.mfmm_solve_exact(solver, sources, 2, None, d.ctypes.data,
                                     ctypes.byref(info), ctypes.byref(err)) == 0, err.message
    finally:
        _lib.mfmm_exact_solver_destroy(solver)
        _lib.mfmm_mesh_destroy(mesh)
    assert info.nonmanifold_walls == 0
    source = sources[0].vertex
    assert d[source] == 0.0 and not np.any(np.isnan(d)) and np.all(d >= 0)


def test_face_source_on_a_needle_edge_crosses_the_tangle():
    """tests/fuzz/regressions/exact/face-source-on-a-needle-edge: the x axis
    is a tangle of 20 needles; p, a point on edge 8-2 of face 15, lies on
    edge 4-12 of face 8 too, through a strip of 9 needles (each sharing an
    edge with the next, all holding p), so the straight segment from p to
    vertex 27 of face 8 lies on the surface and d(27) is the Euclidean
    distance 5.0251 (5.7795 when a pass stopped after 8 needles); from
    vertex 3 of that line, likewise 5.0140 (6.1128). No value lies below
    the Euclidean distance."""
    V, F, data, at = fuzz_exact_mesh("face-source-on-a-needle-edge")
    bary = (0.0, 1.0 / 3.0, 2.0 / 3.0)
    p = bary[1] * V[F[15, 1]] + bary[2] * V[F[15, 2]]
    for source, x in ((_lib.mfmm_source(0, 15, bary, 0.0), p),
                      (_lib.mfmm_source(3, -1, (0.0, 0.0, 0.0), 0.0), V[3])):
        st, d, info, err = _solve_exact(V, F, source)
        assert st == 0, err.message
        assert info.nonmanifold_walls == 0
        euclid = np.linalg.norm(V - x, axis=1)
        np.testing.assert_allclose(d[27], euclid[27], rtol=1e-12, atol=0)
        assert np.all(d >= euclid * (1 - 1e-12))
