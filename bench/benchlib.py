"""Helpers shared by the benchmarks of every bench/ folder: machine and version
info, where results and figures go, and the generated meshes. The mesh lists,
stored references and error metrics (docs/methods.md#metrics) are the tests'
own, from tests/python/meshfmm_testing.py, re-exported here.

A script in a bench/ folder imports it with

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    import benchlib
"""

from __future__ import annotations

import datetime
import os
import platform
import subprocess
import sys
import time
from importlib import metadata
from pathlib import Path

_TESTS_PYTHON = str(Path(__file__).resolve().parents[1] / "tests" / "python")
if _TESTS_PYTHON not in sys.path:
    sys.path.insert(0, _TESTS_PYTHON)

from meshfmm_testing import (  # noqa: E402,F401  (re-exported for the benchmarks)
    DATA,
    DATA_MESHES,
    MESHES,
    REFERENCE,
    REPO,
    bbox_diagonal,
    compact,
    errors,
    load_mesh,
    load_reference,
    mean_rel_error,
    nearest,
    plane_distance,
    reference_path,
    sphere_distance,
)

RESULTS = REPO / "bench" / "results"
IMAGES = REPO / "docs" / "images"
CLI = Path(os.environ.get("MESHFMM_CLI", REPO / "build" / "meshfmm"))


# ---------------------------------------------------------------- machine info
def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def _mem_total_gib() -> float:
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal:"):
                return round(int(line.split()[1]) / 2**20, 1)
    except OSError:
        pass
    return float("nan")


def _opencl_devices() -> list:
    try:
        out = subprocess.run(["clinfo", "-l"], capture_output=True, text=True, timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        return []
    return [ln.split("Device #", 1)[1].split(":", 1)[1].strip()
            for ln in out.splitlines() if "Device #" in ln]


def _git_commit() -> str:
    try:
        return subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def _git_dirty() -> list:
    """Library sources that differ from the commit (the build is of the working tree)."""
    try:
        out = subprocess.run(["git", "-C", str(REPO), "status", "--porcelain", "--", "src",
                              "include", "kernels", "bindings", "CMakeLists.txt"],
                             capture_output=True, text=True, timeout=10).stdout
    except (OSError, subprocess.SubprocessError):
        return []
    return [ln[3:] for ln in out.splitlines() if ln.strip()]


def versions() -> dict:
    import meshfmm

    out = {"python": platform.python_version(), "meshfmm": meshfmm.__version__,
           "meshfmm_library": meshfmm._lib.version(),
           "meshfmm_git_commit": _git_commit(), "meshfmm_uncommitted": _git_dirty()}
    for pkg in ("numpy", "scipy", "potpourri3d", "libigl", "gdist", "matplotlib"):
        try:
            out[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            out[pkg] = None
    return out


def machine_info() -> dict:
    return {
        "cpu_model": _cpu_model(),
        "logical_cpus": os.cpu_count(),
        "memory_gib": _mem_total_gib(),
        "platform": platform.platform(),
        "opencl_devices": _opencl_devices(),
        "date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
    }


# ---------------------------------------------------------------- meshes
def load_data(name: str):
    """(V, F) of a mesh of tests/data/meshes."""
    return load_mesh(name)


def generate(shape: str, n: int, workdir: Path):
    """A mesh from `meshfmm generate` (the library's own generators)."""
    import meshfmm

    out = Path(workdir) / f"{shape}_{n}.obj"
    if not out.is_file():
        subprocess.run([str(CLI), "generate", shape, str(n), "-o", str(out)], check=True,
                       capture_output=True)
    return meshfmm.load_mesh(out)


def best_of(rounds: int, fn):
    """Runs fn `rounds` times: the least wall time in seconds, and the last
    result."""
    times, out = [], None
    for _ in range(rounds):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out
