"""Helpers shared by the comparison benchmarks (bench/compare_*.py, the figures,
bench/make_results_md.py): machine and version info, the error metrics of
DESIGN.md, mesh loading and the generated test meshes."""

from __future__ import annotations

import datetime
import os
import platform
import subprocess
from importlib import metadata
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DATA = REPO / "tests" / "data"  # meshes/ and reference/ (copied into the repository)
RESULTS = REPO / "bench" / "results"
IMAGES = REPO / "docs" / "images"
CLI = Path(os.environ.get("MESHFMM_CLI", REPO / "build" / "meshfmm"))

# every mesh of tests/data/meshes, smallest first
DATA_MESHES = [
    "hand_lowres.obj",
    "beetle.obj",
    "spot.obj",
    "wingnut.obj",
    "fertility_FE_10k.off",
    "decimated-max.obj",
    "camelhead.off",
    "nefertiti-lowres.obj",
    "stanford-bunny.obj",
    "igea.ply",
]


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


# ---------------------------------------------------------------- metrics
def errors(d: np.ndarray, e: np.ndarray, diameter: float) -> tuple:
    """DESIGN.md's metrics: (mean relative error %, max error % of the diameter)
    over vertices where the reference is finite (relative error where e > 0)."""
    d = np.asarray(d, dtype=np.float64).reshape(-1)
    fin = np.isfinite(e)
    pos = fin & (e > 0)
    if not np.all(np.isfinite(d[fin])):
        return float("inf"), float("inf")
    mre = float(100.0 * np.mean(np.abs(d[pos] - e[pos]) / e[pos]))
    mx = float(100.0 * np.max(np.abs(d[fin] - e[fin])) / diameter)
    return mre, mx


def bbox_diagonal(V: np.ndarray) -> float:
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


# ---------------------------------------------------------------- meshes
def compact(V: np.ndarray, F: np.ndarray):
    """Drop unreferenced vertices (the peers want none): (V2, F2, old_of_new, new_of_old)."""
    used = np.zeros(V.shape[0], dtype=bool)
    used[F.reshape(-1)] = True
    old_of_new = np.flatnonzero(used)
    new_of_old = np.full(V.shape[0], -1, dtype=np.int64)
    new_of_old[old_of_new] = np.arange(old_of_new.size)
    return np.ascontiguousarray(V[old_of_new]), new_of_old[F].astype(np.int64), old_of_new, new_of_old


def load_data(name: str):
    import meshfmm

    return meshfmm.load_mesh(DATA / "meshes" / name)


def generate(shape: str, n: int, workdir: Path):
    """A mesh from `meshfmm generate` (the library's own generators)."""
    import meshfmm

    out = Path(workdir) / f"{shape}_{n}.obj"
    if not out.is_file():
        subprocess.run([str(CLI), "generate", shape, str(n), "-o", str(out)], check=True,
                       capture_output=True)
    return meshfmm.load_mesh(out)


def sphere_distance(V: np.ndarray, s: int) -> np.ndarray:
    """Great-circle distance on the unit sphere from vertex s (icosphere vertices lie on it)."""
    U = V / np.linalg.norm(V, axis=1, keepdims=True)
    return np.arccos(np.clip(U @ U[s], -1.0, 1.0))


def plane_distance(V: np.ndarray, s: int) -> np.ndarray:
    return np.linalg.norm(V - V[s], axis=1)
