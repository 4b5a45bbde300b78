"""Distance matrices: Mesh.distance_matrix on every backend equals
Mesh.distance rows (float64 bit for bit, float32 = float64 rounded), and
equals `meshfmm allpairs` from the command line; out= takes a numpy.memmap;
backend "opencl" without a device raises OpenCLError and "auto" falls back.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import meshfmm
from conftest import MESHES, mesh, need_data
from conftest import find_cli

SOURCES = [0, 17, 400, 809, 3, 17]


def rows_of(m, sources, **kw):
    return np.stack([m.distance(int(s), **kw) for s in sources])


def matrix_or_skip(m, *args, **kw):
    try:
        return m.distance_matrix(*args, **kw)
    except meshfmm.OpenCLError as exc:
        if kw.get("backend") == "opencl":
            pytest.skip(f"no OpenCL device: {exc}")
        raise


@pytest.mark.parametrize("backend", ["serial", "threads", "opencl", "auto"])
@pytest.mark.parametrize("name", ["hand_lowres.obj", "wingnut.obj"])
def test_rows_equal_distance(name, backend):
    need_data()
    m = mesh(name)
    src = SOURCES if name == "hand_lowres.obj" else [5, 80, 2593, 1000]
    ref = rows_of(m, src)
    D, info = matrix_or_skip(m, src, backend=backend, dtype="float64", n_threads=2,
                             return_info=True)
    assert D.shape == (len(src), m.n_vertices) and D.dtype == np.float64
    assert np.array_equal(D.view(np.uint64), ref.view(np.uint64))
    assert isinstance(info, meshfmm.MatrixInfo)
    if backend != "auto":
        assert info.backend == backend and info.reason == ""
    D32 = matrix_or_skip(m, src, backend=backend, n_threads=2)
    assert D32.dtype == np.float32
    assert np.array_equal(D32.view(np.uint32), ref.astype(np.float32).view(np.uint32))


@pytest.mark.parametrize("backend", ["threads", "opencl"])
def test_costs_and_max_distance(backend):
    need_data()
    m = mesh("hand_lowres.obj")
    rng = np.random.default_rng(4)
    cost = rng.uniform(0.5, 3.0, m.n_faces)
    for kw in ({"cost": cost, "cost_location": "face"}, {"max_distance": 0.05}):
        ref = rows_of(m, SOURCES, **kw)
        D = matrix_or_skip(m, SOURCES, backend=backend, dtype="float64", **kw)
        assert np.array_equal(D.view(np.uint64), ref.view(np.uint64))
    assert np.isinf(D).any() and np.isfinite(D).any()


def test_memmap_out_all_vertices(tmp_path):
    need_data()
    m = mesh("hand_lowres.obj")
    n = m.n_vertices
    path = tmp_path / "all.npy"
    mm = np.lib.format.open_memmap(path, mode="w+", dtype=np.float32, shape=(n, n))
    out = m.distance_matrix(out=mm, backend="auto", memory_limit=1 << 20)
    assert out is mm
    mm.flush()
    del mm, out
    back = np.load(path, mmap_mode="r")
    assert back.shape == (n, n) and back.dtype == np.float32
    for s in (0, 333, n - 1):
        assert np.array_equal(back[s], m.distance(s).astype(np.float32))
    # each source is at distance 0 from itself
    assert np.all(np.diag(back) == 0)


def test_cli_agrees(tmp_path):
    need_data()
    cli = find_cli()
    if cli is None:
        pytest.skip("no meshfmm command line found (set MESHFMM_CLI or build with CMake)")
    m = mesh("hand_lowres.obj")
    (tmp_path / "src.txt").write_text(" ".join(map(str, SOURCES)) + "\n")
    out = tmp_path / "D.npy"
    proc = subprocess.run(
        [cli, "allpairs", str(MESHES / "hand_lowres.obj"), "-o", str(out), "--dtype", "float64",
         "--sources", str(tmp_path / "src.txt"), "--backend", "threads"],
        capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    D = np.load(out, mmap_mode="r")
    P = m.distance_matrix(SOURCES, backend="serial", dtype="float64")
    assert D.shape == P.shape and D.dtype == P.dtype
    assert np.array_equal(np.asarray(D).view(np.uint64), P.view(np.uint64))


def test_no_opencl_device(tmp_path):
    """In a process whose OpenCL loader finds no platform."""
    empty = tmp_path / "no_icd"
    empty.mkdir()
    code = textwrap.dedent(
        """
        import numpy as np, meshfmm
        V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.]])
        m = meshfmm.Mesh(V, [[0, 1, 2], [1, 3, 2]])
        D, info = m.distance_matrix(backend="auto", dtype="float64", return_info=True)
        assert info.backend == "threads", info
        assert info.reason, info
        assert np.array_equal(D[2], m.distance(2))
        try:
            m.distance_matrix(backend="opencl")
        except meshfmm.OpenCLError as exc:
            print("OpenCLError", exc)
        else:
            raise SystemExit("no OpenCLError")
        """
    )
    env = dict(os.environ, OCL_ICD_VENDORS=str(empty))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "OpenCLError" in proc.stdout and "platform" in proc.stdout


def test_opencl_context_made_once_per_process():
    """Every OpenCL call reuses one context (the program is built once per
    process); rows from repeated calls stay equal to the serial core's."""
    need_data()
    from meshfmm import _rows

    m = mesh("hand_lowres.obj")
    ref = rows_of(m, SOURCES)
    first = None
    for _ in range(3):
        D = matrix_or_skip(m, SOURCES, backend="opencl", dtype="float64")
        assert np.array_equal(D.view(np.uint64), ref.view(np.uint64))
        ctx = _rows.shared_opencl_context()
        assert ctx is not None
        first = first or ctx.value
        assert ctx.value == first
