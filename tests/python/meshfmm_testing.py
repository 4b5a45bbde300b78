"""Meshes, exact references and error metrics shared by the tests and the benchmarks.

tests/python/conftest.py imports this module for its fixtures, and
bench/benchlib.py (which puts tests/python on sys.path) for the benchmarks, so
that a test and a benchmark measure the same thing in the same way. Nothing here
depends on pytest, and only the loaders import meshfmm.

The metrics are those of docs/methods.md#metrics: mean relative error in percent
over vertices with a positive exact distance, and the max error in percent of
the bounding-box diagonal.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
DATA = (REPO / "tests" / "data").resolve()
MESHES = DATA / "meshes"
REFERENCE = DATA / "reference"  # igl.exact_geodesic distances from 3 sources per mesh

# Every mesh of tests/data/meshes, smallest first.
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
# The same meshes by role.
MANIFOLD_MESHES = [
    "hand_lowres.obj",
    "spot.obj",
    "wingnut.obj",
    "fertility_FE_10k.off",
    "decimated-max.obj",
    "camelhead.off",
    "nefertiti-lowres.obj",
    "stanford-bunny.obj",
]
# Obtuse-heavy meshes where unfolding must beat geometry-central clearly.
OBTUSE_MESHES = ["wingnut.obj", "decimated-max.obj", "camelhead.off"]
NONMANIFOLD_MESHES = ["beetle.obj"]
LARGE_MESHES = ["igea.ply"]


# ---------------------------------------------------------------- meshes
def load_mesh(name: str):
    """(V, F) of a mesh of tests/data/meshes through meshfmm's own readers."""
    import meshfmm

    return meshfmm.load_mesh(MESHES / name)


def compact(V: np.ndarray, F: np.ndarray):
    """Drops unreferenced vertices (libigl and potpourri3d want none).
    Returns (V2, F2, old_of_new, new_of_old) with new_of_old -1 for dropped."""
    used = np.zeros(V.shape[0], dtype=bool)
    used[F.reshape(-1)] = True
    old_of_new = np.flatnonzero(used)
    new_of_old = np.full(V.shape[0], -1, dtype=np.int64)
    new_of_old[old_of_new] = np.arange(old_of_new.size)
    return (np.ascontiguousarray(V[old_of_new]), new_of_old[F].astype(np.int64),
            old_of_new, new_of_old)


def nearest(V: np.ndarray, points) -> list:
    """The vertex nearest to each point."""
    return [int(np.argmin(np.linalg.norm(V - p, axis=1))) for p in points]


# ---------------------------------------------------------------- references
def reference_path(name: str) -> Path:
    return REFERENCE / (Path(name).stem + ".npz")


def load_reference(name: str):
    """(sources int64 (3,), exact distances (3, nv)) stored for a mesh of
    tests/data/meshes; FileNotFoundError where none is stored."""
    z = np.load(reference_path(name))
    return z["sources"].astype(np.int64), z["distances"]


def sphere_distance(V: np.ndarray, s: int) -> np.ndarray:
    """Great-circle distance on the unit sphere from vertex s (icosphere vertices lie on it)."""
    U = V / np.linalg.norm(V, axis=1, keepdims=True)
    return np.arccos(np.clip(U @ U[s], -1.0, 1.0))


def plane_distance(V: np.ndarray, s: int) -> np.ndarray:
    """Euclidean distance from vertex s (the geodesic distance on a flat convex mesh)."""
    return np.linalg.norm(V - V[s], axis=1)


# ---------------------------------------------------------------- metrics
def bbox_diagonal(V: np.ndarray) -> float:
    """The length scale of the max error: the bounding-box diagonal of V."""
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


def mean_rel_error(d: np.ndarray, e: np.ndarray) -> float:
    """Mean relative error in percent over vertices with a finite, positive e."""
    d = np.asarray(d, dtype=np.float64).reshape(-1)
    pos = np.isfinite(e) & (e > 0)
    return float(100.0 * np.mean(np.abs(d[pos] - e[pos]) / e[pos]))


def errors(d: np.ndarray, e: np.ndarray, diameter: float) -> tuple:
    """(mean relative error %, max error % of `diameter`) of distances d against
    exact distances e, over vertices where e is finite (> 0 for the relative
    error); (inf, inf) where d is not finite at such a vertex."""
    d = np.asarray(d, dtype=np.float64).reshape(-1)
    fin = np.isfinite(e)
    if not np.all(np.isfinite(d[fin])):
        return float("inf"), float("inf")
    mx = float(100.0 * np.max(np.abs(d[fin] - e[fin])) / diameter)
    return mean_rel_error(d, e), mx


def write_off(path, V: np.ndarray, F: np.ndarray) -> None:
    """Writes V, F as an OFF file, coordinates to full precision."""
    with open(path, "w") as f:
        f.write(f"OFF\n{V.shape[0]} {F.shape[0]} 0\n")
        np.savetxt(f, V, fmt="%.17g")
        np.savetxt(f, np.hstack([np.full((F.shape[0], 1), 3), F]), fmt="%d")
