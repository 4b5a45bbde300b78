"""--method windows on the command lines: the C commands that solve
(distance, allpairs, landmarks, voronoi, path) write the Python API's
windows values bit for bit; the Python commands (isolines, render) take
it too, with a cost too; the usage errors (--exact with --method, an
unknown or repeated method) exit 2 and write nothing."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from conftest import MESHES, mesh
from test_cli import run

NAME = "spot.obj"
PATH = MESHES / NAME


def refused(cli, *args):
    proc = subprocess.run([cli, *map(str, args)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    return proc.stderr


@pytest.mark.parametrize("args,sources,kw", [
    (["--source", 77], 77, {}),
    (["--source", 77, "--source", 2001], [77, 2001], {}),
    (["--face-source", 100, 0.2, 0.3, 0.5], "face", {}),
    (["--source", 77, "--max-distance", 0.5], 77, {"max_distance": 0.5}),
])
def test_distance(cli, tmp_path, args, sources, kw):
    from meshfmm import SurfacePoint

    if sources == "face":
        sources = SurfacePoint(100, (0.2, 0.3, 0.5))
    out = tmp_path / "d.npy"
    run(cli, "distance", PATH, *args, "--method", "windows", "-o", out)
    want = mesh(NAME).distance(sources, method="windows", **kw)
    assert np.load(out).tobytes() == want.tobytes()
    run(cli, "distance", PATH, *args, "--method", "fmm", "-o", out)
    assert np.load(out).tobytes() == mesh(NAME).distance(sources, **kw).tobytes()


def test_allpairs_opencl(cli, tmp_path):
    """--backend opencl runs the window method's kernel: the serial rows, bit for bit."""
    m = mesh(NAME)
    src = np.array([0, 17, 905, 2929], dtype=np.int32)
    tgt = np.array([5, 905, 17, 5], dtype=np.int32)
    np.save(tmp_path / "s.npy", src)
    np.save(tmp_path / "t.npy", tgt)
    common = ["--sources", tmp_path / "s.npy", "--dtype", "float64", "--backend", "opencl",
              "--method", "windows", "--quiet"]
    proc = subprocess.run([cli, "allpairs", PATH, *map(str, common), "-o", str(tmp_path / "D.npy")],
                          capture_output=True, text=True, timeout=300)
    if proc.returncode != 0 and "OpenCL" in proc.stderr:
        pytest.skip("no OpenCL device: " + proc.stderr.strip())
    assert proc.returncode == 0, proc.stderr
    want = m.distance_matrix(src, backend="serial", dtype="float64", method="windows")
    assert np.load(tmp_path / "D.npy").tobytes() == want.tobytes()
    run(cli, "allpairs", PATH, *common, "--targets", tmp_path / "t.npy", "-o", tmp_path / "T.npy")
    assert np.load(tmp_path / "T.npy").tobytes() == want[:, tgt].tobytes()


@pytest.mark.parametrize("backend", ["serial", "threads", "auto"])
def test_allpairs_dense_sparse_and_targets(cli, tmp_path, backend):
    scipy_sparse = pytest.importorskip("scipy.sparse")
    m = mesh(NAME)
    src = np.array([0, 17, 905, 2929], dtype=np.int32)
    tgt = np.array([5, 905, 17, 5], dtype=np.int32)
    np.save(tmp_path / "s.npy", src)
    np.save(tmp_path / "t.npy", tgt)
    common = ["--sources", tmp_path / "s.npy", "--dtype", "float64", "--backend", backend,
              "--method", "windows", "--quiet"]
    run(cli, "allpairs", PATH, *common, "-o", tmp_path / "D.npy")
    want = m.distance_matrix(src, backend="serial", dtype="float64", method="windows")
    assert np.load(tmp_path / "D.npy").tobytes() == want.tobytes()
    run(cli, "allpairs", PATH, *common, "--targets", tmp_path / "t.npy", "-o", tmp_path / "T.npy")
    assert np.load(tmp_path / "T.npy").tobytes() == want[:, tgt].tobytes()
    r = 0.4
    run(cli, "allpairs", PATH, *common, "--max-distance", r, "-o", tmp_path / "S.npz")
    S = scipy_sparse.load_npz(tmp_path / "S.npz")
    W = m.distance_matrix(src, backend="serial", dtype="float64", method="windows",
                          max_distance=r, sparse=True)
    assert np.array_equal(S.indptr, W.indptr) and np.array_equal(S.indices, W.indices)
    assert S.data.tobytes() == W.data.tobytes()


def test_landmarks_voronoi_and_path(cli, tmp_path):
    m = mesh(NAME)
    run(cli, "landmarks", PATH, "-k", 9, "--start", 5, "--method", "windows",
        "-o", tmp_path / "L.npy")
    L = np.load(tmp_path / "L.npy")
    assert L.tolist() == m.farthest_point_sampling(9, start=5, method="windows").tolist()
    run(cli, "voronoi", PATH, "--sources", tmp_path / "L.npy", "--method", "windows",
        "--distances", tmp_path / "vd.npy", "-o", tmp_path / "V.npy")
    d = m.distance(L.tolist(), method="windows")
    assert np.load(tmp_path / "vd.npy").tobytes() == d.tobytes()
    assert np.array_equal(np.load(tmp_path / "V.npy"), m.voronoi_labels(L.tolist(), d))
    proc = run(cli, "path", PATH, "--source", 77, "--target", 1500, "--method", "windows",
               "-o", tmp_path / "p.csv")
    p = m.path(77, 1500, method="windows")
    xyz = np.loadtxt(tmp_path / "p.csv", delimiter=",", skiprows=1)[:, 4:7]
    assert np.array_equal(xyz, p.points)
    assert float(proc.stdout.split()[0]) == pytest.approx(p.length, rel=1e-12)


def test_usage_errors(cli, tmp_path):
    out = tmp_path / "o.npy"
    cost = tmp_path / "c.txt"
    cost.write_text("1\n" * mesh(NAME).n_vertices)
    for sub in ("distance", "voronoi"):
        for method in ("windows", "fmm"):
            err = refused(cli, sub, PATH, "--source", 0, "--exact", "--method", method,
                          "-o", out)
            assert "--exact and --method are two methods" in err
    for sub in ("distance", "landmarks", "allpairs"):
        args = ["-k", 3] if sub == "landmarks" else ["--source", 0] if sub == "distance" else []
        err = refused(cli, sub, PATH, *args, "--method", "exact", "-o", out)
        assert "--method is fmm or windows, not 'exact'" in err
        err = refused(cli, sub, PATH, *args, "--method", "fmm", "--method", "windows", "-o", out)
        assert "--method given twice" in err
    assert list(tmp_path.iterdir()) == [cost]


@pytest.mark.parametrize("where", ["vertex", "face"])
def test_cost(cli, tmp_path, where):
    """--method windows --cost: the Python API's values bit for bit
    (distance, allpairs)."""
    m = mesh(NAME)
    n = m.n_vertices if where == "vertex" else m.n_faces
    c = 1.0 + (np.arange(n) % 5 == 0)
    cost = tmp_path / "c.npy"
    np.save(cost, c)
    flag = ["--cost-per-face"] if where == "face" else []
    out = tmp_path / "d.npy"
    run(cli, "distance", PATH, "--source", 77, "--method", "windows", "--cost", cost, *flag,
        "-o", out)
    want = m.distance(77, c, cost_location=where, method="windows")
    assert np.load(out).tobytes() == want.tobytes()
    src = np.array([0, 77], dtype=np.int32)
    np.save(tmp_path / "s.npy", src)
    run(cli, "allpairs", PATH, "--sources", tmp_path / "s.npy", "--dtype", "float64",
        "--backend", "serial", "--method", "windows", "--cost", cost, *flag, "--quiet",
        "-o", tmp_path / "D.npy")
    assert np.load(tmp_path / "D.npy")[1].tobytes() == want.tobytes()


def test_python_isolines_and_render_take_the_method(tmp_path):
    m = mesh(NAME)
    d = m.distance([77, 2001], method="windows")
    np.save(tmp_path / "f.npy", d)

    def py(*args):
        return subprocess.run([sys.executable, "-m", "meshfmm", *map(str, args)],
                              capture_output=True, text=True, timeout=300)

    a = py("isolines", PATH, "--source", 77, "--source", 2001, "--method", "windows",
           "--values", "0.2,0.5", "-o", tmp_path / "a.csv")
    assert a.returncode == 0, a.stderr
    b = py("isolines", PATH, "--field", tmp_path / "f.npy", "--values", "0.2,0.5",
           "-o", tmp_path / "b.csv")
    assert b.returncode == 0, b.stderr
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()
    np.save(tmp_path / "c.npy", np.full(m.n_vertices, 2.0))
    c = py("isolines", PATH, "--source", 77, "--method", "windows", "--cost",
           tmp_path / "c.npy", "--values", "0.4", "-o", tmp_path / "c.csv")
    assert c.returncode == 0, c.stderr
    d = py("isolines", PATH, "--source", 77, "--method", "windows", "--values", "0.2",
           "-o", tmp_path / "d.csv")
    assert d.returncode == 0, d.stderr
    # cost 2: the 0.4 isoline is the 0.2 one without a cost, but for its value
    lines = [(tmp_path / n).read_text().count("\n") for n in ("c.csv", "d.csv")]
    assert lines[0] == lines[1]
    assert "windows" in py("render", "--help").stdout
