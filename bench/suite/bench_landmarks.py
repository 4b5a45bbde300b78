#!/usr/bin/env python3
"""Geodesic farthest-point sampling (landmarks): meshfmm's
``Mesh.farthest_point_sampling`` (one solver, a running minimum, each march
stopped at the current farthest distance) against the same loop written by
hand over full solves, meshfmm's ``Mesh.distance`` and potpourri3d's heat
method (MeshHeatMethodDistanceSolver, its precompute timed apart), and the
landmarks' mutual S x S matrix in one call.

Writes bench/results/landmarks.json. Not a test: timings on a shared
machine are noisy; the best of a few rounds is reported.

    python bench/suite/bench_landmarks.py [--mesh camelhead.off] [-k 200] [--rounds 3]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/
from benchlib import RESULTS, best_of, compact, load_data, machine_info, versions  # noqa: E402


def loop_fps(solve, nv: int, k: int, start: int) -> np.ndarray:
    """The hand-written loop: k full solves, a running minimum, the
    farthest vertex not chosen (ties to the lowest id)."""
    dmin = np.full(nv, np.inf)
    chosen = [start]
    for _ in range(k - 1):
        dmin = np.minimum(dmin, solve(chosen[-1]))
        cand = dmin.copy()
        cand[chosen] = -1
        chosen.append(int(np.argmax(cand)))
    return np.array(chosen)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mesh", default="camelhead.off")
    ap.add_argument("-k", type=int, default=200)
    ap.add_argument("--start", type=int, default=0)
    ap.add_argument("--rounds", type=int, default=3)
    a = ap.parse_args()

    import meshfmm

    V, F = load_data(a.mesh)
    mesh = meshfmm.Mesh(V, F)
    mesh.distance(a.start)  # the first solve builds the spokes and exact tables
    res = {"mesh": a.mesh, "n_vertices": int(V.shape[0]), "k": a.k, "start": a.start,
           "versions": versions(), "machine": machine_info()}

    t, pts = best_of(a.rounds, lambda: mesh.farthest_point_sampling(a.k, a.start))
    res["meshfmm_fps_s"] = t
    t, loop = best_of(1, lambda: loop_fps(mesh.distance, mesh.n_vertices, a.k, a.start))
    res["meshfmm_loop_s"] = t
    res["fps_equals_loop"] = bool(np.array_equal(pts, loop))
    t, M = best_of(a.rounds, lambda: mesh.distance_matrix(pts, targets=pts))
    res["landmark_matrix_s"] = t
    res["landmark_matrix_shape"] = list(M.shape)

    try:
        import potpourri3d as pp3d
    except ImportError:
        pp3d = None
    if pp3d is not None:
        V2, F2, old_of_new, new_of_old = compact(V, F)
        t0 = time.perf_counter()
        heat = pp3d.MeshHeatMethodDistanceSolver(V2, F2)
        heat.compute_distance(int(new_of_old[a.start]))
        res["pp3d_heat_precompute_s"] = time.perf_counter() - t0
        t, hp = best_of(a.rounds, lambda: loop_fps(heat.compute_distance, V2.shape[0], a.k,
                                                   int(new_of_old[a.start])))
        res["pp3d_heat_loop_s"] = t
        res["pp3d_same_landmarks"] = int(np.isin(old_of_new[hp], pts).sum())
        res["speedup_vs_pp3d_heat_loop"] = res["pp3d_heat_loop_s"] / res["meshfmm_fps_s"]
    res["speedup_vs_meshfmm_loop"] = res["meshfmm_loop_s"] / res["meshfmm_fps_s"]

    out = RESULTS / "landmarks.json"
    out.write_text(json.dumps(res, indent=2) + "\n")
    for key in ("meshfmm_fps_s", "meshfmm_loop_s", "pp3d_heat_precompute_s", "pp3d_heat_loop_s",
                "speedup_vs_pp3d_heat_loop", "speedup_vs_meshfmm_loop", "landmark_matrix_s",
                "fps_equals_loop", "pp3d_same_landmarks"):
        if key in res:
            print(f"{key:28s} {res[key]}")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
