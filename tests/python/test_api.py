"""The Python API: input conversion, bad inputs and their exceptions (run in
a subprocess, so that an interpreter crash would show), lifetimes, load_mesh."""

from __future__ import annotations

import gc
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import meshfmm
from conftest import load, need_data


def grid(n: int = 8):
    """A flat (n+1)^2-vertex grid on [0,1]^2, two triangles per square."""
    xs = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(xs, xs, indexing="xy")
    V = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], axis=1)
    F = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 1, a + n + 2
            F += [(a, b, d), (a, d, c)]
    return V, np.array(F, dtype=np.int32)


# ------------------------------------------------------------- conversion
def test_inputs_numpy_accepts_give_identical_results():
    V, F = grid(6)
    ref = meshfmm.Mesh(V, F).distance(0)
    variants = [
        (V.tolist(), F.tolist()),
        (V, F.astype(np.int64)),
        (np.asfortranarray(V), np.asfortranarray(F)),
        (np.hstack([V, V])[:, :3], np.hstack([F, F])[:, :3]),  # non-contiguous views
        (V[::-1][::-1], F.astype(np.uint32)),
        (tuple(map(tuple, V)), F.astype(np.int16)),
    ]
    for Vx, Fx in variants:
        m = meshfmm.Mesh(Vx, Fx)
        np.testing.assert_array_equal(m.distance(0), ref)
    # float32 input is converted (values change by rounding only)
    m32 = meshfmm.Mesh(V.astype(np.float32), F)
    assert m32.vertices.dtype == np.float64
    np.testing.assert_allclose(m32.distance(0), ref, rtol=1e-6, atol=1e-7)


def test_properties_and_info():
    V, F = grid(4)
    m = meshfmm.Mesh(V, F)
    assert (m.n_vertices, m.n_faces) == (25, 32)
    assert m.vertices.dtype == np.float64 and m.faces.dtype == np.int32
    np.testing.assert_array_equal(m.vertices, V)
    np.testing.assert_array_equal(m.faces, F)
    with pytest.raises(ValueError):
        m.vertices[0, 0] = 1.0  # read-only
    # a private copy: changing the caller's array changes nothing
    V2 = V.copy()
    m2 = meshfmm.Mesh(V2, F)
    V2[:] = 7.0
    assert m2.vertices[0, 0] == 0.0
    info = m.info
    assert info.n_vertices == 25 and info.n_faces == 32
    assert info.n_edges == 25 + 32 - 1  # Euler: V - E + F = 1 for a disk
    assert info.n_boundary_edges == 16
    assert info.n_components == 1
    assert info.n_unreferenced_vertices == 0
    assert info.n_obtuse_corners == 0
    assert abs(info.bbox_diagonal - np.sqrt(2)) < 1e-15
    assert abs(info.min_edge_length - 0.25) < 1e-15
    assert set(info.as_dict()) >= {"n_virtual_edges", "n_unfold_failures", "mean_edge_length"}


def test_memory_report():
    """Mesh.memory(): the C report (mfmm_mesh_memory), sizes that follow from
    the counts alone; the exact tables count from the first solve, the
    spokes (only with spokes=True) from the solve after 8 full marches."""
    V, F = grid(6)
    for spokes in (True, False):
        m = meshfmm.Mesh(V, F, spokes=spokes)
        mem = m.memory()
        nv, nf = m.n_vertices, m.n_faces
        assert mem["xyz"] == 24 * nv
        assert mem["to_internal/to_external"] == 8 * nv
        assert mem["face_to_internal/external"] == 8 * nf
        assert mem["face_neighbor"] == 12 * nf
        assert mem["spokes (once built)"] == 0 and mem["exact tables (once built)"] == 0
        assert all(isinstance(b, int) and b >= 0 for b in mem.values())
        m.distance(0)
        after = m.memory()
        assert after["spokes (once built)"] == 0
        assert after["exact tables (once built)"] > 0
        for _ in range(8):
            m.distance(0)
        after = m.memory()
        assert (after["spokes (once built)"] > 0) == spokes
        assert sum(after.values()) > sum(mem.values())
        m.close()
        with pytest.raises(ValueError, match="closed"):
            m.memory()


def test_distance_results():
    V, F = grid(8)
    m = meshfmm.Mesh(V, F)
    d = m.distance(0)
    assert d.dtype == np.float64 and d.shape == (81,) and d.flags.c_contiguous
    assert d[0] == 0.0
    # along the grid axis FMM is exact
    np.testing.assert_allclose(d[:9], np.linspace(0, 1, 9), rtol=1e-12, atol=1e-15)
    # a new array each call
    assert m.distance(0) is not d
    # sources: a numpy integer, an int array, a list mixing ints and points
    np.testing.assert_array_equal(m.distance(np.int64(0)), d)
    both = m.distance(np.array([0, 80]))
    assert both[0] == 0.0 and both[80] == 0.0
    # the nearest source, to discretisation error (fronts meet along the diagonal)
    np.testing.assert_allclose(both, np.minimum(d, m.distance(80)), atol=0.05)
    np.testing.assert_array_equal(m.distance([0, 80]), both)
    # a point at corner 0 of face 0 (vertex 0): its face's corners start at
    # their exact in-plane distances, the rest is Euclidean to FMM accuracy
    sp = meshfmm.SurfacePoint(0, (1.0, 0.0, 0.0))
    ds = m.distance(sp)
    euclid = np.linalg.norm(V - V[0], axis=1)
    np.testing.assert_allclose(ds[F[0]], euclid[F[0]], rtol=1e-15, atol=0)
    np.testing.assert_allclose(ds, euclid, atol=0.03)
    mixed = m.distance([sp, 80])
    np.testing.assert_allclose(mixed, np.minimum(ds, m.distance(80)), atol=0.05)
    assert mixed[80] == 0.0
    # max_distance: beyond is +inf, within unchanged
    dm = m.distance(0, max_distance=0.5)
    assert np.isinf(dm[d > 0.5 + 1e-9]).all()
    np.testing.assert_array_equal(dm[d <= 0.5], d[d <= 0.5])
    # targets: the target is settled with its final value
    dt = m.distance(0, targets=[10])
    assert dt[10] == d[10]
    # unfolding off: same on a right-triangle grid (no obtuse corners)
    np.testing.assert_array_equal(m.distance(0, unfolding=False), d)


def test_unreferenced_vertex_is_inf():
    V, F = grid(2)
    V = np.vstack([V, [[5.0, 5.0, 5.0]]])
    m = meshfmm.Mesh(V, F)
    assert m.info.n_unreferenced_vertices == 1
    d = m.distance(0)
    assert np.isinf(d[-1]) and np.isfinite(d[:-1]).all()


def test_duplicate_faces_are_copies_not_walls():
    """Copies of faces (an export artifact: same vertices, any order, twice or
    three times) must not make every edge of the face non-manifold, hence a
    wall for the exact solver and the exact start: on the unit square
    f(0,1,2) f(1,3,2) f(1,3,2), vertex 3 would get 2 from vertex 0 instead
    of sqrt(2). Every result equals the mesh without the copies (the
    reference) to rounding, and info counts them."""
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.0]])
    sq = meshfmm.Mesh(V, [[0, 1, 2], [1, 3, 2], [1, 3, 2]])
    assert sq.info.n_duplicate_faces == 1 and sq.info.n_nonmanifold_edges == 0
    for kw in ({}, {"method": "exact"}):
        assert sq.distance(0, **kw)[3] == pytest.approx(np.sqrt(2.0), rel=1e-15)

    V, F = load("hand_lowres.obj")
    rng = np.random.default_rng(1)
    pick = rng.choice(len(F), 40, replace=False)
    copies = F[pick].copy()
    copies[::2] = copies[::2, ::-1]  # half of them the other way round
    G = np.vstack([F, copies, F[pick[:10]][:, [1, 2, 0]]])  # and 10 third copies
    perm = rng.permutation(len(G))
    G = G[perm]
    ref, m = meshfmm.Mesh(V, F), meshfmm.Mesh(V, G)
    assert m.info.n_duplicate_faces == 50
    for key in ("n_edges", "n_boundary_edges", "n_nonmanifold_edges", "n_unfold_failures"):
        assert getattr(m.info, key) == getattr(ref.info, key), key
    for s in (0, 100, 500):
        for kw in ({}, {"exact_start": False}, {"method": "exact"}):
            np.testing.assert_allclose(m.distance(s, **kw), ref.distance(s, **kw),
                                       rtol=1e-14, atol=1e-15, err_msg=f"{s} {kw}")
        p = m.geodesic_path(m.distance(s), 700, sources=[s])
        assert p.length == pytest.approx(ref.geodesic_path(ref.distance(s), 700,
                                                           sources=[s]).length, rel=1e-13)
    # a point of a copy is that point of its original (the copy is reversed)
    j = int(np.argsort(perm)[len(F)])
    b = np.array([0.2, 0.3, 0.5])
    for kw in ({}, {"method": "exact"}):
        np.testing.assert_allclose(
            m.distance(meshfmm.SurfacePoint(j, tuple(b)), **kw),
            ref.distance(meshfmm.SurfacePoint(int(pick[0]), tuple(b[::-1])), **kw),
            rtol=1e-14, atol=1e-15)


# ---------------------------------------------------------- bad inputs
# (id, code, expected exception class name, words the message must contain)
# Each runs in one subprocess with V, F (a 3x3 grid), m = Mesh(V, F), and a
# tetrahedron T (4 vertices, 4 faces) in scope.
BAD = [
    ("V 2 columns", "meshfmm.Mesh(V[:, :2], F)", "MeshError", ["shape"]),
    ("V 1-D", "meshfmm.Mesh(V.ravel(), F)", "MeshError", ["shape"]),
    ("V strings", "meshfmm.Mesh([['a','b','c']], F)", "MeshError", ["vertices"]),
    ("V empty", "meshfmm.Mesh(np.zeros((0, 3)), F)", "MeshError", []),
    ("F 4 columns", "meshfmm.Mesh(V, np.hstack([F, F[:, :1]]))", "MeshError", ["shape"]),
    ("F floats", "meshfmm.Mesh(V, F.astype(float))", "MeshError", ["integer"]),
    ("F empty", "meshfmm.Mesh(V, np.zeros((0, 3), int))", "MeshError", []),
    ("V NaN", "W = V.copy(); W[3, 1] = np.nan; meshfmm.Mesh(W, F)", "MeshError", ["3"]),
    ("V inf", "W = V.copy(); W[5, 2] = np.inf; meshfmm.Mesh(W, F)", "MeshError", ["5"]),
    ("F index = nv", "G = F.copy(); G[2, 1] = len(V); meshfmm.Mesh(V, G)", "MeshError", ["2"]),
    ("F index -1", "G = F.copy(); G[4, 0] = -1; meshfmm.Mesh(V, G)", "MeshError", ["4"]),
    ("F int64 beyond int32", "G = F.astype(np.int64); G[1, 2] = 2**40; meshfmm.Mesh(V, G)",
     "MeshError", ["1099511627776"]),
    ("F int64 wraps to valid", "G = F.astype(np.int64); G[1, 2] = 2**32 + 1; meshfmm.Mesh(V, G)",
     "MeshError", ["4294967297"]),
    ("F repeated vertex", "G = F.copy(); G[6] = (1, 1, 2); meshfmm.Mesh(V, G)", "MeshError", ["6"]),
    ("max_unfold_steps 0", "meshfmm.Mesh(V, F, max_unfold_steps=0)", "MeshError", []),
    ("spokes 2", "meshfmm.Mesh(V, F, spokes=2)", "TypeError", ["spokes"]),
    ("source -1", "m.distance(-1)", "ValueError", ["-1"]),
    ("source nv", "m.distance(len(V))", "ValueError", [str(16)]),
    ("source 2**40", "m.distance(2**40)", "ValueError", ["1099511627776"]),
    ("source array out of range", "m.distance(np.array([0, 99]))", "ValueError", ["99"]),
    ("source str", "m.distance('0')", "TypeError", []),
    ("source float", "m.distance([0.0])", "TypeError", []),
    ("sources empty", "m.distance([])", "ValueError", ["source"]),
    ("face source out of range", "m.distance(meshfmm.SurfacePoint(18, (1/3, 1/3, 1/3)))",
     "ValueError", ["18"]),
    ("bary not summing to 1", "m.distance(meshfmm.SurfacePoint(0, (0.5, 0.5, 0.5)))",
     "ValueError", []),
    ("bary negative", "m.distance(meshfmm.SurfacePoint(0, (-0.1, 0.6, 0.5)))", "ValueError", []),
    ("bary NaN", "m.distance(meshfmm.SurfacePoint(0, (np.nan, 0.5, 0.5)))", "ValueError", []),
    ("bary 2 numbers", "m.distance(meshfmm.SurfacePoint(0, (0.5, 0.5)))", "ValueError", ["3"]),
    ("degenerate face source",
     "W = np.array([[0,0,0],[1,0,0],[2,0,0],[0,1,0.]]); "
     "meshfmm.Mesh(W, [[0,1,2],[0,1,3]]).distance(meshfmm.SurfacePoint(0, (1/3,1/3,1/3)))",
     "ValueError", ["0"]),
    ("cost 0", "c = np.ones(len(V)); c[7] = 0; m.distance(0, cost=c)", "ValueError", ["7"]),
    ("cost negative", "c = np.ones(len(F)); c[9] = -1; m.distance(0, cost=c)", "ValueError", ["9"]),
    ("cost NaN", "c = np.ones(len(V)); c[2] = np.nan; m.distance(0, cost=c)", "ValueError", ["2"]),
    ("cost inf", "c = np.ones(len(F)); c[3] = np.inf; m.distance(0, cost=c)", "ValueError", ["3"]),
    ("cost wrong length", "m.distance(0, cost=np.ones(5))", "ValueError", ["5"]),
    ("cost 2-D", "m.distance(0, cost=np.ones((len(V), 1)))", "ValueError", ["1-D"]),
    ("cost ambiguous", "T.distance(0, cost=np.ones(4))", "ValueError", ["cost_location"]),
    ("cost_location bad", "T.distance(0, cost=np.ones(4), cost_location='edge')", "ValueError",
     ["cost_location"]),
    ("cost_location length", "m.distance(0, cost=np.ones(len(V)), cost_location='face')",
     "ValueError", [str(18)]),
    ("max_distance NaN", "m.distance(0, max_distance=float('nan'))", "ValueError", ["NaN"]),
    ("max_distance str", "m.distance(0, max_distance='far')", "TypeError", []),
    ("target out of range", "m.distance(0, targets=[3, 16])", "ValueError", ["16"]),
    ("closed mesh", "k = meshfmm.Mesh(V, F); k.close(); k.distance(0)", "ValueError", ["closed"]),
    ("load missing file", "meshfmm.load_mesh('/nonexistent/x.obj')", "FileNotFoundError", []),
    ("load directory", "meshfmm.load_mesh('/')", "OSError", []),
    ("load garbage", "p = tmp + '/bad.off'; open(p, 'w').write('OFF\\n3 1 0\\n0 0\\n'); "
     "meshfmm.load_mesh(p)", "MeshError", []),
    ("load unknown extension", "p = tmp + '/x.xyz'; open(p, 'w').write('1 2 3\\n'); "
     "meshfmm.load_mesh(p)", "ValueError", []),
    ("path distances shape", "m.geodesic_path(np.zeros(3), 0)", "ValueError", ["shape"]),
    ("path target type", "m.geodesic_path(m.distance(0), 'a')", "TypeError", []),
    ("path unreached target", "d = m.distance(0, max_distance=0.1); m.geodesic_path(d, 15)",
     "ValueError", []),
    ("matrix dtype", "m.distance_matrix([0], dtype='int32')", "ValueError", ["dtype"]),
    ("matrix backend", "m.distance_matrix([0], backend='gpu')", "ValueError", ["backend"]),
    ("matrix out shape", "m.distance_matrix([0], out=np.empty((2, 16), np.float32))",
     "ValueError", ["shape"]),
    ("matrix out dtype", "m.distance_matrix([0], out=np.empty((1, 16)))", "ValueError", ["dtype"]),
    ("matrix out strided", "m.distance_matrix([0, 1], out=np.empty((2, 32), np.float32)[:, ::2])",
     "ValueError", ["contiguous"]),
    ("matrix source out of range", "m.distance_matrix([0, 16])", "ValueError", ["16"]),
    # yes/no options take bools only: 'no', 0 and None read as truth values
    # passed silently (unfolding='no' ran with unfolding)
    ("unfolding str", "m.distance(0, unfolding='no')", "TypeError", ["unfolding"]),
    ("matrix unfolding int", "m.distance_matrix([0], unfolding=0)", "TypeError", ["unfolding"]),
    ("matrix sparse str", "m.distance_matrix([0], sparse='no', max_distance=1)", "TypeError",
     ["sparse"]),
    ("path straighten str", "m.geodesic_path(m.distance(0), 15, straighten='no')", "TypeError",
     ["straighten"]),
    ("targets empty", "m.distance(0, targets=[])", "ValueError", ["targets"]),
    ("memory_limit wraps", "m.distance_matrix([0], memory_limit=2**70)", "ValueError",
     ["memory_limit"]),
    ("memory_limit float", "m.distance_matrix([0], memory_limit=1.5)", "TypeError",
     ["memory_limit"]),
    ("face source -1", "m.distance(meshfmm.SurfacePoint(-1, (1/3, 1/3, 1/3)))", "ValueError",
     ["face -1"]),
    ("path target face -1", "m.geodesic_path(m.distance(0), meshfmm.SurfacePoint(-1, (1, 0, 0)))",
     "ValueError", ["face -1"]),
    ("sources dict", "m.distance({0: 1})", "TypeError", ["dict"]),
    # distances that would overflow to +inf, which reads as "not reached"
    ("cost overflows", "m.distance(0, cost=np.full(len(V), 1e307))", "ValueError", ["overflow"]),
    ("matrix float32 range", "meshfmm.Mesh(V * 1e38, F).distance_matrix([0])", "ValueError",
     ["float32"]),
]

SCRIPT = textwrap.dedent(
    """
    import json, sys, tempfile, traceback
    import numpy as np
    import meshfmm
    sys.path.insert(0, {here!r})
    from test_api import grid, BAD
    V, F = grid(3)
    m = meshfmm.Mesh(V, F)
    T = meshfmm.Mesh([[0,0,0],[1,0,0],[0,1,0],[0,0,1.]], [[0,2,1],[0,1,3],[0,3,2],[1,2,3]])
    tmp = tempfile.mkdtemp()
    out = {{}}
    for name, code, _, _ in BAD:
        try:
            exec(code)
            out[name] = ["no exception", ""]
        except NotImplementedError as exc:
            out[name] = ["NotImplementedError", str(exc)]
        except BaseException as exc:
            out[name] = [[c.__name__ for c in type(exc).__mro__], str(exc)]
    print(json.dumps(out))
    """
)


@pytest.fixture(scope="module")
def bad_results():
    script = SCRIPT.format(here=str(Path(__file__).parent))
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, f"interpreter died ({proc.returncode}):\n{proc.stderr[-3000:]}"
    return json.loads(proc.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("name,code,expected,words", BAD, ids=[b[0] for b in BAD])
def test_bad_input(bad_results, name, code, expected, words):
    got, message = bad_results[name]
    if got == "NotImplementedError":
        pytest.skip(f"not in this build of the library: {message}")
    assert got != "no exception", f"{code!r} raised nothing"
    assert expected in got, f"{code!r} raised {got[0]}: {message}"
    assert message.strip(), f"{code!r}: {got[0]} without a message"
    for w in words:
        assert w in message, f"{code!r}: message {message!r} does not name {w!r}"


def test_large_values_within_range_are_kept():
    """The overflow checks refuse only what can overflow: float64 rows of a
    mesh 1e38 wide and costs of 1e300 on a unit grid give their values."""
    V, F = grid(3)
    big = meshfmm.Mesh(V * 1e38, F)
    np.testing.assert_allclose(big.distance_matrix([0], dtype="float64")[0],
                               big.distance(0), rtol=0)
    assert big.distance(0)[3] == pytest.approx(1e38, rel=1e-15)
    m = meshfmm.Mesh(V, F)
    np.testing.assert_allclose(m.distance(0, cost=np.full(len(V), 1e300)), 1e300 * m.distance(0),
                               rtol=1e-15)


def test_mesh_error_is_value_error():
    assert issubclass(meshfmm.MeshError, ValueError)
    assert issubclass(meshfmm.OpenCLError, RuntimeError)
    V, F = grid(2)
    G = F.copy()
    G[1] = (0, 0, 1)
    with pytest.raises(ValueError) as info:
        meshfmm.Mesh(V, G)
    assert info.value.status == "MFMM_ERR_REPEATED_VERTEX" and info.value.index == 1


# ------------------------------------------------------------- lifetimes
def test_close_and_context_manager():
    V, F = grid(3)
    with meshfmm.Mesh(V, F) as m:
        d = m.distance(0)
        assert not m.closed
    assert m.closed
    m.close()  # idempotent
    with pytest.raises(ValueError, match="closed"):
        m.distance(0)
    with pytest.raises(ValueError, match="closed"):
        m.geodesic_path(d, 3)
    assert "closed" in repr(m)
    # properties stay readable after close (they are Python copies)
    assert m.n_vertices == 16 and m.info.n_faces == 18


def test_many_meshes_are_freed():
    """Create and drop meshes (and their solvers) repeatedly; the process's
    resident memory must not grow with the count."""
    V, F = grid(30)

    def rss_kb() -> int:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
        return 0

    if not os.path.exists("/proc/self/status"):
        pytest.skip("needs /proc")
    for _ in range(20):
        meshfmm.Mesh(V, F).distance(0)
    gc.collect()
    before = rss_kb()
    for _ in range(300):
        m = meshfmm.Mesh(V, F)
        m.distance([0, 5])
        del m
    gc.collect()
    grown = rss_kb() - before
    # one mesh of 961 vertices with its solver is ~0.5 MB: 300 leaked ones would be >100 MB
    assert grown < 20_000, f"RSS grew by {grown} kB over 300 meshes"


# ------------------------------------------------------------- load_mesh
def test_load_mesh_matches_libigl(meshes_dir):
    igl = pytest.importorskip("igl")
    for name in ["hand_lowres.obj", "spot.obj", "camelhead.off", "fertility_FE_10k.off",
                 "beetle.obj"]:
        V, F = meshfmm.load_mesh(meshes_dir / name)
        assert V.dtype == np.float64 and F.dtype == np.int32
        assert V.flags.c_contiguous and F.flags.c_contiguous
        Vi, Fi = igl.read_triangle_mesh(str(meshes_dir / name))
        np.testing.assert_array_equal(V, Vi)
        np.testing.assert_array_equal(F, Fi)


def test_load_every_shared_mesh(meshes_dir):
    import json as _json

    stats = _json.loads((meshes_dir / "stats.json").read_text())
    for path in sorted(meshes_dir.iterdir()):
        if path.suffix not in (".obj", ".off", ".ply"):
            continue
        V, F = load(path.name)
        assert np.isfinite(V).all() and F.min() >= 0 and F.max() < V.shape[0]
        text = _json.dumps(stats)
        assert str(V.shape[0]) in text and str(F.shape[0]) in text, path.name


def test_load_mesh_accepts_pathlike_and_str(meshes_dir):
    p = meshes_dir / "hand_lowres.obj"
    V1, F1 = meshfmm.load_mesh(p)
    V2, F2 = meshfmm.load_mesh(str(p))
    np.testing.assert_array_equal(V1, V2)
    np.testing.assert_array_equal(F1, F2)


# ------------------------------------------------- paths and matrices (smoke)
def test_geodesic_path_smoke():
    V, F = grid(10)
    m = meshfmm.Mesh(V, F)
    d = m.distance(0)
    try:
        p = m.geodesic_path(d, 120, sources=[0])
    except NotImplementedError as exc:
        pytest.skip(str(exc))
    assert p.points.shape == (len(p), 3) and p.barycentric.shape == (len(p), 3)
    assert p.faces.shape == (len(p),) and p.faces.dtype == np.int32
    np.testing.assert_allclose(p.points[0], V[120], atol=1e-12)
    np.testing.assert_allclose(p.points[-1], V[0], atol=1e-9)
    seg = np.linalg.norm(np.diff(p.points, axis=0), axis=1).sum()
    assert abs(p.length - seg) < 1e-9 and p.weighted_length == pytest.approx(p.length)
    # straight segment on a flat grid
    assert abs(p.length - np.linalg.norm(V[120] - V[0])) < 0.005 * np.linalg.norm(V[120])


def test_distance_matrix_smoke(tmp_path):
    V, F = grid(10)
    m = meshfmm.Mesh(V, F)
    try:
        D, info = m.distance_matrix([0, 60], backend="serial", dtype="float64",
                                    return_info=True)
    except NotImplementedError as exc:
        pytest.skip(str(exc))
    assert D.shape == (2, 121) and D.dtype == np.float64
    np.testing.assert_array_equal(D[0], m.distance(0))
    np.testing.assert_array_equal(D[1], m.distance(60))
    assert info == meshfmm.MatrixInfo("serial", "", info.vertices_settled, 0)
    assert info.vertices_settled > 0
    assert not hasattr(m, "backend_used")
    mm = np.lib.format.open_memmap(tmp_path / "all.npy", mode="w+", dtype=np.float32,
                                   shape=(121, 121))
    seen = []
    out, info = m.distance_matrix(out=mm, backend="threads", n_threads=2, return_info=True,
                                  progress=lambda done, n: seen.append((done, n)))
    assert out is mm and info.backend == "threads"
    mm.flush()
    back = np.load(tmp_path / "all.npy", mmap_mode="r")
    np.testing.assert_array_equal(back[60], m.distance(60).astype(np.float32))
    assert seen and seen[-1] == (121, 121)

    def stop(done, n):
        raise KeyError("stop here")

    with pytest.raises(KeyError, match="stop here"):
        m.distance_matrix([0, 1, 2], backend="serial", progress=stop)


def test_opencl_errors_map_to_openclerror(tmp_path):
    """Without an OpenCL platform (no ICD vendors), backend='opencl' raises
    meshfmm.OpenCLError with the library's message and 'auto' falls back."""
    code = textwrap.dedent(
        """
        import numpy as np, meshfmm, sys
        sys.path.insert(0, %r)
        from test_api import grid
        m = meshfmm.Mesh(*grid(4))
        try:
            m.distance_matrix([0, 1], backend="opencl")
            print("no exception")
        except NotImplementedError:
            print("skip")
            raise SystemExit
        except meshfmm.OpenCLError as exc:
            assert isinstance(exc, RuntimeError) and str(exc), exc
            print("OpenCLError", exc)
        D, info = m.distance_matrix([0, 1], backend="auto", dtype="float64", return_info=True)
        assert info.backend in ("threads", "serial"), info
        assert (D[1] == m.distance(1)).all()
        print("fallback", info.backend)
        """
    ) % str(Path(__file__).parent)
    env = dict(os.environ, OCL_ICD_VENDORS=str(tmp_path), OPENCL_VENDOR_PATH=str(tmp_path))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr[-3000:]
    if proc.stdout.strip() == "skip":
        pytest.skip("no mfmm_distance_matrix in this library build")
    lines = proc.stdout.strip().splitlines()
    assert lines[0].startswith("OpenCLError"), proc.stdout
    assert lines[-1].startswith("fallback"), proc.stdout


def test_ctrl_c_stops_distance_matrix():
    """SIGINT during distance_matrix stops the library at the next block and
    raises KeyboardInterrupt; the interpreter and the mesh stay usable."""
    code = textwrap.dedent(
        """
        import os, signal, threading, time, numpy as np, meshfmm, sys
        sys.path.insert(0, %r)
        from test_api import grid
        m = meshfmm.Mesh(*grid(60))
        calls = []
        def progress(done, n):
            calls.append(done)
            if len(calls) == 1:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.05)
        try:
            m.distance_matrix(backend="serial", memory_limit=1 << 20, progress=progress)
            print("finished", len(calls))
        except KeyboardInterrupt:
            print("interrupted", len(calls))
        assert (m.distance(3) >= 0).all()
        """
    ) % str(Path(__file__).parent)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = proc.stdout.strip()
    if "NotImplementedError" in proc.stderr:
        pytest.skip("no mfmm_distance_matrix in this library build")
    assert out.startswith("interrupted"), out
    done = int(out.split()[1])
    assert done < 10, f"{done} blocks ran after Ctrl-C"


def test_ctrl_c_stops_exact_solve():
    """SIGINT during an exact solve stops the propagation within milliseconds
    and raises KeyboardInterrupt; the mesh's next exact solve gives the row
    it gave before."""
    code = textwrap.dedent(
        """
        import os, signal, threading, time, numpy as np, meshfmm, sys
        sys.path.insert(0, %r)
        from test_api import grid
        m = meshfmm.Mesh(*grid(240))
        t0 = time.perf_counter(); row = m.distance(0, method="exact")
        full = time.perf_counter() - t0
        threading.Timer(0.05, os.kill, (os.getpid(), signal.SIGINT)).start()
        t0 = time.perf_counter()
        try:
            m.distance(0, method="exact")
            print("finished", full)
        except KeyboardInterrupt:
            print("interrupted", time.perf_counter() - t0, full)
        assert np.array_equal(m.distance(0, method="exact"), row)
        """
    ) % str(Path(__file__).parent)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr[-3000:]
    words = proc.stdout.split()
    assert words[0] == "interrupted", proc.stdout
    stopped, full = float(words[1]), float(words[2])
    assert stopped < 0.5 * full, proc.stdout


def test_max_unfold_steps_reaches_the_core(meshes_dir):
    V, F = load("wingnut.obj")
    default = meshfmm.Mesh(V, F).info
    short = meshfmm.Mesh(V, F, max_unfold_steps=1).info
    assert default.n_obtuse_corners == short.n_obtuse_corners > 0
    assert default.n_virtual_edges + default.n_unfold_failures == default.n_obtuse_corners
    assert short.n_unfold_failures > default.n_unfold_failures


def test_options_rebuild_an_equal_mesh():
    V, F = grid(4)
    m = meshfmm.Mesh(V, F, max_unfold_steps=8, spokes=False)
    assert m.options == {"max_unfold_steps": 8, "spokes": False, "weld": False}
    m.options["spokes"] = True  # a copy: the mesh's options stay
    assert m.options["spokes"] is False
    again = meshfmm.Mesh(m.vertices, m.faces, **m.options)
    assert np.array_equal(again.distance(0), m.distance(0))
    assert meshfmm.Mesh(V, F).options == {"max_unfold_steps": None, "spokes": True,
                                             "weld": False}
