"""Shared fixtures for the meshfmm Python tests.

The meshes and exact references live in the repository, in tests/data
(copied from the project's reference shelf with their licences; see
tests/data/meshes/README.md); a missing file is a failure, not a skip. For a development build without
``pip install .``, point ``MESHFMM_LIBRARY`` at a built libmeshfmm and put
``bindings/python`` on ``PYTHONPATH``. The mesh lists, references and error
metrics come from meshfmm_testing.py, which the benchmarks share.
"""

from __future__ import annotations

import functools
import os
import shutil
from pathlib import Path

import pytest

from meshfmm_testing import (  # noqa: F401  (re-exported for the tests)
    DATA,
    LARGE_MESHES,
    MANIFOLD_MESHES,
    MESHES,
    NONMANIFOLD_MESHES,
    OBTUSE_MESHES,
    REFERENCE,
    REPO,
    bbox_diagonal,
    compact,
    errors,
    load_reference,
    reference_path,
)


def need_data() -> None:
    if not MESHES.is_dir():
        pytest.fail(f"test meshes not found at {MESHES}")


@pytest.fixture(scope="session")
def meshes_dir() -> Path:
    need_data()
    return MESHES


@pytest.fixture(scope="session")
def reference_dir() -> Path:
    if not REFERENCE.is_dir():
        pytest.fail(f"stored references not found at {REFERENCE}")
    return REFERENCE


@functools.lru_cache(maxsize=None)
def load(name: str):
    """(V, F) of a shared mesh through meshfmm's own readers (cached)."""
    import meshfmm

    need_data()
    V, F = meshfmm.load_mesh(MESHES / name)
    V.setflags(write=False)
    F.setflags(write=False)
    return V, F


@functools.lru_cache(maxsize=None)
def mesh(name: str):
    """A meshfmm.Mesh of a shared mesh (cached for the session)."""
    import meshfmm

    V, F = load(name)
    return meshfmm.Mesh(V, F)


def reference(name: str):
    """(sources, exact distances (3, nv)) stored for a mesh, or skip."""
    path = reference_path(name)
    if not path.is_file():
        pytest.skip(f"no stored reference {path}")
    return load_reference(name)


@functools.lru_cache(maxsize=None)
def diameter(name: str) -> float:
    """Bounding-box diagonal of a test mesh's referenced vertices (the max
    error's scale, docs/methods.md#metrics)."""
    V, F = load(name)
    return bbox_diagonal(compact(V, F)[0])


# ------------------------------------------------------- accuracy table
# Filled by test_accuracy.py; printed at the end of the session, and written
# only where $MESHFMM_ACCURACY_JSON names a file (tests write nothing tracked;
# bench/suite/run_all.sh sets it to bench/results/accuracy_python.json).
ACCURACY: dict = {}
ACCURACY_JSON = os.environ.get("MESHFMM_ACCURACY_JSON")


def _accuracy_table() -> str:
    head = (
        f"{'mesh':<22}{'nv':>7} | {'meshfmm MRE%':>12}{'gc-FMM MRE%':>12}{'ratio':>7} | "
        f"{'meshfmm max%':>12}{'gc-FMM max%':>12}{'ratio':>7} | {'no-unfold MRE%':>14}"
    )
    lines = [head, "-" * len(head)]
    for name, r in ACCURACY.items():
        lines.append(
            f"{name:<22}{r['n_vertices']:>7} | {r['meshfmm']['mean_rel_error_pct']:>12.4f}"
            f"{r['geometry_central_fmm']['mean_rel_error_pct']:>12.4f}"
            f"{r['mre_ratio_gc_over_meshfmm']:>7.2f} | {r['meshfmm']['max_error_pct_diameter']:>12.4f}"
            f"{r['geometry_central_fmm']['max_error_pct_diameter']:>12.4f}"
            f"{r['max_ratio_gc_over_meshfmm']:>7.2f} | "
            f"{r['meshfmm_no_unfolding']['mean_rel_error_pct']:>14.4f}"
        )
    return "\n".join(lines)


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    if not ACCURACY:
        return
    import json

    terminalreporter.write_sep("-", "accuracy against igl.exact_geodesic (3 sources per mesh)")
    terminalreporter.write_line(_accuracy_table())
    terminalreporter.write_line(
        "MRE: mean relative error (%), mean over the sources; max: max error in % of the "
        "bounding-box diagonal, max over the sources; ratio: geometry-central / meshfmm"
    )
    if not ACCURACY_JSON:
        return
    path = Path(ACCURACY_JSON)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        doc = {
            "metrics": {
                "mean_rel_error_pct": "100/N sum |d-e|/e over vertices with e > 0, averaged over sources",
                "max_error_pct_diameter": "100 max |d-e| / bounding-box diagonal (referenced vertices), max over sources",
            },
            "reference": "igl.exact_geodesic (stored in tests/data/reference)",
            "competitor": "potpourri3d.MeshFastMarchingDistanceSolver (geometry-central FMM)",
            "meshes": {},
        }
        if path.is_file():  # a partial run updates its meshes only
            try:
                doc["meshes"] = json.loads(path.read_text()).get("meshes", {})
            except ValueError:
                pass
        doc["meshes"].update(ACCURACY)
        path.write_text(json.dumps(doc, indent=1) + "\n")
        terminalreporter.write_line(f"written to {path}")
    except OSError as exc:
        terminalreporter.write_line(f"could not write {path}: {exc}")


def find_cli():
    """The C command line: $MESHFMM_CLI, else the newest build*/meshfmm of the
    repository, else `meshfmm` on PATH; None when there is none."""
    env = os.environ.get("MESHFMM_CLI")
    if env:
        return env if os.access(env, os.X_OK) else None
    builds = [p for p in REPO.glob("build*/meshfmm") if p.is_file() and os.access(p, os.X_OK)]
    if builds:
        return str(max(builds, key=lambda p: p.stat().st_mtime))
    return shutil.which("meshfmm")


@pytest.fixture(scope="module")
def cli():
    """find_cli()'s path; skips the test when there is no command line."""
    path = find_cli()
    if path is None:
        pytest.skip("no meshfmm command line found (set MESHFMM_CLI or build with CMake)")
    return path
