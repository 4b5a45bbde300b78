"""The optional dependencies (the package's extras [sparse], [dask], [plot]):
a feature whose module is missing says so, and names the extra, before it
computes anything. A missing module is simulated by a None entry in
sys.modules (the import system then raises ModuleNotFoundError)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import meshfmm
import meshfmm.__main__ as cli_main
from meshfmm import _extras, _rows
from test_api import grid

ROOT = Path(__file__).resolve().parents[2]


def hide(monkeypatch, *modules):
    """Makes `modules` (and their submodules already imported) unimportable
    for the test."""
    for name in list(sys.modules):
        if any(name == m or name.startswith(m + ".") for m in modules):
            monkeypatch.setitem(sys.modules, name, None)
    for m in modules:
        monkeypatch.setitem(sys.modules, m, None)


@pytest.fixture
def no_work(monkeypatch):
    """Fails the test if a matrix is computed."""
    def computed(*args, **kwargs):
        raise AssertionError("computed before the missing extra was reported")
    monkeypatch.setattr(_rows, "run", computed)
    monkeypatch.setattr(meshfmm.Mesh, "distance_matrix", computed)
    monkeypatch.setattr(meshfmm.Mesh, "distance", computed)


def test_sparse_without_scipy(monkeypatch):
    mesh = meshfmm.Mesh(*grid(6))
    def computed(*args, **kwargs):
        raise AssertionError("computed before the missing extra was reported")
    monkeypatch.setattr(_rows, "run", computed)
    hide(monkeypatch, "scipy")
    with pytest.raises(ImportError, match=r"sparse=True\) needs scipy.*meshfmm\[sparse\]") as e:
        mesh.distance_matrix([0, 1], max_distance=0.5, sparse=True)
    assert e.value.name == "scipy.sparse"
    assert isinstance(e.value.__cause__, ImportError)


def test_sparse_with_scipy_still_works():
    pytest.importorskip("scipy.sparse")
    mesh = meshfmm.Mesh(*grid(6))
    S = mesh.distance_matrix([0, 1], max_distance=0.5, sparse=True, dtype="float64")
    D = mesh.distance_matrix([0, 1], max_distance=0.5, dtype="float64")
    np.testing.assert_array_equal(S.toarray()[np.isfinite(D)], D[np.isfinite(D)])


@pytest.mark.parametrize("missing", ["zarr", "dask", "distributed"])
def test_distributed_without_its_modules(monkeypatch, tmp_path, no_work, missing):
    import meshfmm.distributed as dist

    mesh = meshfmm.Mesh(*grid(4))
    hide(monkeypatch, missing)
    with pytest.raises(ImportError, match=rf"needs {missing}.*meshfmm\[dask\]"):
        dist.distance_matrix(mesh, tmp_path / "D.zarr")
    assert not (tmp_path / "D.zarr").exists()
    with pytest.raises(ImportError, match=r"symmetrize needs .*meshfmm\[dask\]"):
        dist.symmetrize(tmp_path / "D.zarr", tmp_path / "S.zarr")


def test_allpairs_zarr_command_without_zarr(monkeypatch, capsys, no_work, tmp_path):
    hide(monkeypatch, "zarr")
    assert cli_main.main(["allpairs", "x.obj", "-o", str(tmp_path / "D.zarr")]) == 2
    err = capsys.readouterr().err
    assert "meshfmm allpairs -o OUT.zarr needs zarr" in err
    assert "pip install 'meshfmm[dask]'" in err
    assert "Traceback" not in err


def test_plot_without_matplotlib(monkeypatch, capsys, tmp_path):
    import meshfmm.plot as plot

    hide(monkeypatch, "matplotlib")
    mesh = meshfmm.Mesh(*grid(4))
    out = tmp_path / "p.png"
    with pytest.raises(ImportError, match=r"render needs matplotlib.*meshfmm\[plot\]"):
        plot.render(mesh, np.zeros(mesh.n_vertices), out)
    def computed(*args, **kwargs):
        raise AssertionError("computed before the missing extra was reported")
    monkeypatch.setattr(meshfmm.Mesh, "from_file", computed)
    assert cli_main.main(["render", "mesh.obj", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "meshfmm render needs matplotlib" in err and "meshfmm[plot]" in err
    assert not out.exists()


def test_require_names_the_module_and_the_extra(monkeypatch):
    hide(monkeypatch, "matplotlib")
    with pytest.raises(ImportError) as e:
        _extras.require("a picture", "plot")
    msg = str(e.value)
    assert msg.startswith("meshfmm: a picture needs matplotlib, which is not installed")
    assert "pip install 'meshfmm[plot]'" in msg and "pip install 'matplotlib'" in msg


def test_extras_match_pyproject():
    """pyproject.toml's extras install what meshfmm._extras imports, and
    [all] is their union (run from a checkout)."""
    tomllib = pytest.importorskip("tomllib")
    path = ROOT / "pyproject.toml"
    if not path.is_file():
        pytest.skip("no pyproject.toml (not a checkout)")
    extras = tomllib.loads(path.read_text())["project"]["optional-dependencies"]
    dist = {"scipy.sparse": "scipy", "dask": "dask[distributed]",
            "distributed": "dask[distributed]", "zarr": "zarr>=3"}
    for extra, modules in _extras.EXTRAS.items():
        assert sorted(set(extras[extra])) == sorted({dist.get(m, m) for m in modules}), extra
    union = {d for e in _extras.EXTRAS for d in extras[e]}
    assert sorted(extras["all"]) == sorted(union)


def test_python_m_meshfmm_distributed_without_zarr(tmp_path):
    """`python -m meshfmm.distributed` (the job's own command line): one
    line and status 2, no traceback."""
    import subprocess

    code = ("import sys, runpy; sys.modules['zarr'] = None; "
            "sys.argv = ['meshfmm.distributed', 'm.obj', '-o', sys.argv[1]]; "
            "runpy.run_module('meshfmm.distributed', run_name='__main__')")
    proc = subprocess.run([sys.executable, "-c", code, str(tmp_path / "D.zarr")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert "python -m meshfmm.distributed needs zarr" in proc.stderr
    assert "meshfmm[dask]" in proc.stderr and "Traceback" not in proc.stderr
