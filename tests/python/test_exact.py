"""mfmm_solve_exact through the C ABI (meshfmm._lib): live against
igl.exact_geodesic (Kirsanov's MMP) on the smallest test mesh, from
vertices and from face centroids (igl's face sources), and the refusal of a
cost. The stored references of all meshes are checked by bench/bench_exact.py
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


def test_cost_refused():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float64)
    F = np.array([[0, 1, 2]], dtype=np.int32)
    cost = np.ones(1)
    opt = _lib.mfmm_exact_options()
    _lib.mfmm_exact_options_init(ctypes.byref(opt))
    opt.cost = cost.ctypes.data
    opt.cost_location = _lib.MFMM_COST_PER_FACE
    st, d, _, err = _solve_exact(V, F, _lib.mfmm_source(0, -1, (0.0, 0.0, 0.0), 0.0), opt)
    assert st == _lib.MFMM_ERR_BAD_ARGUMENT
    assert b"cost" in err.message
    assert np.isinf(d).all()


@pytest.mark.parametrize("name", ["hand_lowres", "spot", "wingnut", "fertility_FE_10k",
                                  "decimated-max", "camelhead"])
def test_mesh_distance_method_exact_equals_stored_igl(name, reference_dir):
    """Mesh.distance(method="exact") against the stored igl.exact_geodesic rows
    (1e-9 relative; the larger meshes are checked by bench/bench_exact.py)."""
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
    import os
    import subprocess

    cli = os.environ.get("MESHFMM_CLI")
    if not cli:
        pytest.skip("MESHFMM_CLI is not set (scripts/test.sh sets it to build/meshfmm)")
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


def _grid_with_t_junctions(n=10, splits=((3, 4), (5, 5), (6, 2), (2, 7))):
    """A flat n x n grid on [0,1]^2 whose diagonals at the given squares are
    split on one side only: the diagonal's other face is cut in two at the
    midpoint m, and a zero-area face (q, p, m) closes the T-junction, as
    exporters and mesh repair tools leave them. The surface is still the
    unit square, so distances are Euclidean."""
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
