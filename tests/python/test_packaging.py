"""What `pip install .` gives besides the library: the
`meshfmm` command (console script and `python -m meshfmm`, the C command
line's commands), Mesh from any object with .vertices and .faces (trimesh),
Mesh.from_file.

The command tests need the C command line: inside the installed package
(meshfmm/_bin/meshfmm), or $MESHFMM_CLI for a development build; they skip
without one. Run the tests from the source tree (tests/data is not in the
sdist) against the installed package.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import meshfmm
import meshfmm.__main__ as cli_main
from conftest import MESHES, load, need_data
from test_api import grid


def run(args, **kw):
    return subprocess.run(args, capture_output=True, text=True, timeout=120, **kw)


@pytest.fixture(scope="module")
def binary():
    path = cli_main.cli_path()
    if path is None:
        pytest.skip("no meshfmm command line in the package and no $MESHFMM_CLI "
                    "(a development build: set MESHFMM_CLI=build/meshfmm)")
    return path


def console_script():
    """The `meshfmm` script pip put beside this interpreter, if any."""
    here = Path(sys.executable).parent / ("meshfmm.exe" if os.name == "nt" else "meshfmm")
    return str(here) if here.is_file() else None


# ------------------------------------------------------------ the command
def test_python_m_meshfmm_help_is_the_binary_help(binary):
    ours = run([sys.executable, "-m", "meshfmm", "--help"])
    theirs = run([binary, "--help"])
    assert ours.returncode == theirs.returncode == 0, ours.stderr
    assert ours.stdout == theirs.stdout
    for command in ("info", "distance", "path", "allpairs", "generate"):
        assert command in ours.stdout


def test_python_m_meshfmm_passes_exit_codes_and_output(binary, tmp_path):
    need_data()
    ours = run([sys.executable, "-m", "meshfmm", "no-such-command"])
    theirs = run([binary, "no-such-command"])
    assert ours.returncode == theirs.returncode != 0
    assert ours.stderr == theirs.stderr
    mesh = MESHES / "hand_lowres.obj"
    assert run([sys.executable, "-m", "meshfmm", "info", str(mesh)]).stdout == \
        run([binary, "info", str(mesh)]).stdout
    out = tmp_path / "d.npy"
    proc = run([sys.executable, "-m", "meshfmm", "distance", str(mesh), "--source", "5",
                "-o", str(out)])
    assert proc.returncode == 0, proc.stderr
    np.testing.assert_array_equal(np.load(out), meshfmm.Mesh(*load("hand_lowres.obj")).distance(5))


def test_python_m_meshfmm_sigint_reaches_the_binary(binary, tmp_path):
    """os.execv: the process is the binary, so Ctrl-C is its own (the
    binary removes its temporary file and exits; no Python traceback)."""
    src = tmp_path / "g.obj"
    assert run([binary, "generate", "grid", "120", "-o", str(src)]).returncode == 0
    out = tmp_path / "all.npy"
    proc = subprocess.Popen([sys.executable, "-m", "meshfmm", "allpairs", str(src), "-o", str(out),
                             "--backend", "serial"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.time() + 30
        # the binary writes a unique temporary file beside the target (all.npy.XXXXXX)
        while (not list(tmp_path.glob("all.npy.*")) and time.time() < deadline
               and proc.poll() is None):
            time.sleep(0.05)
        time.sleep(0.2)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode != 0
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    assert not out.exists()
    assert not list(tmp_path.glob("all.npy*"))


def test_allpairs_zarr_runs_the_dask_job(tmp_path):
    """`allpairs ... -o OUT.zarr` is Python's (meshfmm.distributed), not the
    binary's: a bad mesh is one sentence and status 2, a real one a Zarr array
    equal to the serial rows."""
    pytest.importorskip("distributed")
    zarr = pytest.importorskip("zarr")
    for args in (["-o", str(tmp_path / "m.zarr")], [f"--output={tmp_path / 'M.ZARR'}/"]):
        proc = run([sys.executable, "-m", "meshfmm", "allpairs", "x.obj", *args])
        assert proc.returncode == 2
        assert "x.obj" in proc.stderr and "Traceback" not in proc.stderr
    mesh_path = MESHES / "hand_lowres.obj"
    src = tmp_path / "s.txt"
    src.write_text("0\n400\n")
    out = tmp_path / "hand.zarr"
    proc = run([sys.executable, "-m", "meshfmm", "allpairs", str(mesh_path), "-o", str(out),
                "--workers", "1", "--sources", str(src), "--dtype", "float64"])
    assert proc.returncode == 0, proc.stderr
    mesh = meshfmm.Mesh.from_file(mesh_path)
    assert np.array_equal(zarr.open_array(str(out), mode="r")[:],
                          mesh.distance_matrix([0, 400], backend="serial", dtype="float64"))


def test_console_script(binary):
    script = console_script()
    if script is None:
        pytest.skip(f"no meshfmm console script beside {sys.executable} "
                    "(the package is not pip-installed into this environment)")
    proc = run([script, "--help"])
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == run([binary, "--help"]).stdout
    proc = run([script, "--version"])
    assert proc.returncode == 0 and meshfmm.__version__ in proc.stdout


def test_installed_package_carries_its_binary():
    """A pip-installed package has the command line inside it (not needed,
    and skipped, for a development build through $MESHFMM_LIBRARY)."""
    pkg = Path(meshfmm.__file__).resolve().parent
    if not (pkg / "libmeshfmm.so").is_file():
        pytest.skip("a development build (the library is not inside the package)")
    exe = pkg / "_bin" / "meshfmm"
    assert exe.is_file() and os.access(exe, os.X_OK)
    assert cli_main.cli_path() == str(exe)


# --------------------------------------------------------- mesh inputs
def test_mesh_from_a_trimesh_object():
    trimesh = pytest.importorskip("trimesh", reason="pip install -r requirements-dev.txt")
    tm = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
    m = meshfmm.Mesh(tm)
    assert m.n_vertices == len(tm.vertices) and m.n_faces == len(tm.faces)
    np.testing.assert_array_equal(m.vertices, np.asarray(tm.vertices))
    np.testing.assert_array_equal(m.faces, np.asarray(tm.faces))
    ref = meshfmm.Mesh(np.asarray(tm.vertices), np.asarray(tm.faces)).distance(0)
    d = m.distance(0)
    np.testing.assert_array_equal(d, ref)
    # on the unit sphere the farthest point is pi away (first-order error)
    assert abs(d.max() - np.pi) < 0.05 * np.pi
    # a mesh read by trimesh's own loader (it may renumber vertices)
    need_data()
    tm2 = trimesh.load(MESHES / "camelhead.off", process=False, force="mesh")
    m2 = meshfmm.Mesh(tm2)
    assert m2.n_faces == load("camelhead.off")[1].shape[0]
    np.testing.assert_array_equal(m2.distance(0), meshfmm.Mesh(tm2.vertices, tm2.faces).distance(0))


def test_mesh_from_any_object_with_vertices_and_faces():
    V, F = grid(3)

    class Soup:
        vertices = V.tolist()
        faces = F.tolist()

    m = meshfmm.Mesh(Soup())
    np.testing.assert_array_equal(m.distance(0), meshfmm.Mesh(V, F).distance(0))
    np.testing.assert_array_equal(meshfmm.Mesh(m).distance(0), m.distance(0))
    with pytest.raises(TypeError, match="vertices"):
        meshfmm.Mesh(V)
    with pytest.raises(TypeError, match="vertices"):
        meshfmm.Mesh(object())


def test_mesh_from_file(tmp_path):
    need_data()
    for name in ("spot.obj", "camelhead.off"):
        m = meshfmm.Mesh.from_file(MESHES / name)
        V, F = load(name)
        np.testing.assert_array_equal(m.vertices, V)
        np.testing.assert_array_equal(m.faces, F)
    m = meshfmm.Mesh.from_file(str(MESHES / "wingnut.obj"), max_unfold_steps=1)
    assert m.info.n_unfold_failures > 0
    with pytest.raises(FileNotFoundError):
        meshfmm.Mesh.from_file(tmp_path / "missing.obj")


def test_meshio_one_liner_in_usage():
    """The documented meshio one-liner (meshio is not a dependency)."""
    usage = (Path(__file__).resolve().parents[2] / "bindings" / "python" / "USAGE.md").read_text()
    assert 'meshfmm.Mesh(m.points, m.cells_dict["triangle"])' in usage
    meshio = pytest.importorskip("meshio", reason="meshio is optional")
    need_data()
    m = meshio.read(MESHES / "spot.obj")
    mesh = meshfmm.Mesh(m.points, m.cells_dict["triangle"])
    assert mesh.n_faces == load("spot.obj")[1].shape[0]


def test_meshfmm_library_wins(monkeypatch, tmp_path):
    """$MESHFMM_LIBRARY names the library to load even when the package
    carries one (not silently ignored), and a path that is
    no file is an ImportError that names it."""
    from meshfmm import _lib as lib

    inside = tmp_path / "inside.so"
    inside.write_bytes(b"")
    monkeypatch.setattr(lib, "_candidates", lambda: [inside])
    mine = tmp_path / "mine.so"
    mine.write_bytes(b"")
    monkeypatch.setenv("MESHFMM_LIBRARY", str(mine))
    assert lib._find_library() == str(mine)
    monkeypatch.setenv("MESHFMM_LIBRARY", str(tmp_path / "missing.so"))
    with pytest.raises(ImportError, match="missing.so.*is not a file"):
        lib._find_library()
    monkeypatch.delenv("MESHFMM_LIBRARY")
    assert lib._find_library() == str(inside)
