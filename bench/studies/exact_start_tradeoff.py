#!/usr/bin/env python3
"""The exact start's radius against the speed targets, in one run.

Study, 2026-11-24: per source on the four meshes under 5k vertices, r = 7
costs 1.7-2.3x the plain start and is slower than libigl's heat solve on all
four; r = 5 beats it on spot and wingnut, r = 3 on hand, only the plain start
on beetle. All pairs on camelhead: r = 7 costs 1.21x the plain start and is
still 1.53x faster than the batched heat method
(bench/results/exact_start_tradeoff.json; the accuracy per radius in
bench/RESULTS.md, "Exact start").

The exact start seeds each march with the exact distances within r
mean edge lengths of its source; r = 7 (the default up to 40,000 vertices)
is the least radius that brings the bunny's mean error to 0.6x the plain
start's. Its patch costs about the same on any mesh, so it weighs most on
small meshes and on all pairs around 10k vertices. This script measures, at
several radii and the plain start (r = 0):

  per source   Mesh.distance against libigl's heat solve after its precompute
               (target: no slower on meshes under 5k vertices), three
               sources alternating, median over rounds, one thread each;
  all pairs    `meshfmm allpairs --backend serial` against the batched heat
               method in one process (bench/suite/heat_batched.py), camelhead 2000
               rows spread over the mesh, both extrapolated to the full matrix
               as bench/suite/compare_allpairs.py does (target: 1.5x
               the batched heat method's rate).

The accuracy at each radius is bench_exact_start.py's (RESULTS.md, "Exact
start"). Writes bench/results/exact_start_tradeoff.json.

    python bench/studies/exact_start_tradeoff.py [--rounds R] [--radii 7 5 4 3]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

# one thread each (set before numpy loads)
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "suite"))
import benchlib as bl  # noqa: E402
import compare_allpairs as ca  # noqa: E402

SMALL = ["hand_lowres.obj", "beetle.obj", "spot.obj", "wingnut.obj"]


def per_source(name, radii, rounds):
    """Median ms per source of libigl's heat solve and of meshfmm at each radius."""
    import igl
    import meshfmm

    V, F = meshfmm.load_mesh(bl.DATA / "meshes" / name)
    Vc, Fc, old_of_new, new_of_old = bl.compact(V, F)
    mesh = meshfmm.Mesh(V, F)
    heat = igl.HeatGeodesicsData()
    igl.heat_geodesics_precompute(Vc, Fc, heat)
    sources = old_of_new[np.linspace(0, Vc.shape[0] - 1, 3).astype(int)]
    runs = {"igl_heat": lambda s: igl.heat_geodesics_solve(
        heat, np.array([new_of_old[s]], dtype=np.int64))}
    for r in radii:
        runs[f"r={r:g}"] = (lambda r: lambda s: mesh.distance(int(s), exact_start=r))(r)
    times = {k: [] for k in runs}
    for _ in range(rounds):
        for k, f in runs.items():
            for s in sources:
                t0 = time.perf_counter()
                f(s)
                times[k].append(time.perf_counter() - t0)
    return {k: 1e3 * float(np.median(v)) for k, v in times.items()}


def all_pairs(name, n_rows, radii, rounds):
    """Full-matrix seconds (extrapolated from n_rows) of meshfmm serial at each
    radius and of the batched heat method in one process; the minimum over
    rounds, every method once per round."""
    import meshfmm

    path = bl.DATA / "meshes" / name
    V, F = meshfmm.load_mesh(path)
    Vc, Fc, old_of_new, new_of_old = bl.compact(V, F)
    nv, nvc = V.shape[0], Vc.shape[0]
    rows = old_of_new[(np.arange(n_rows) * nvc) // n_rows]
    best = {}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        out = tmp / "D.npy"
        np.save(tmp / "rows.npy", rows.astype(np.int64))
        np.save(tmp / "one.npy", rows[:1].astype(np.int64))
        np.save(tmp / "rows_c.npy", new_of_old[rows].astype(np.int64))

        def cli(rows_file, r):
            cmd = [str(bl.CLI), "allpairs", str(path), "-o", str(out), "--backend", "serial",
                   "--quiet", "--sources", str(rows_file), "--exact-start-radius", repr(float(r))]
            wall = ca.run_child_rss(cmd)[0]
            out.unlink(missing_ok=True)
            return wall

        for _ in range(rounds):
            for r in radii:
                wall = cli(tmp / "rows.npy", r)
                setup = min(cli(tmp / "one.npy", r), wall)  # process, load, build
                full = setup + (wall - setup) * (nv - 1) / (n_rows - 1)
                best[f"r={r:g}"] = min(best.get(f"r={r:g}", np.inf), full)
            _, _, h = ca.py_worker("heat_batched_p1", name, tmp / "rows_c.npy", out)
            out.unlink(missing_ok=True)
            full = h["precompute_s"] + h["rows_s"] * nv / n_rows
            best["heat_batched_p1"] = min(best.get("heat_batched_p1", np.inf), full)
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=40, help="per-source rounds")
    ap.add_argument("--radii", type=float, nargs="*", default=[7, 5, 4, 3])
    ap.add_argument("--allpairs-rounds", type=int, default=2)
    ap.add_argument("-o", default=str(bl.RESULTS / "exact_start_tradeoff.json"))
    args = ap.parse_args()
    radii = [float(r) for r in args.radii] + [0.0]
    doc = {"radii": radii, "machine": bl.machine_info(), "per_source_ms": {}, "all_pairs_s": {}}
    for name in SMALL:
        t = per_source(name, radii, args.rounds)
        doc["per_source_ms"][name] = t
        print(f"{name:18s} per source, libigl heat / meshfmm: "
              + "  ".join(f"{k} {t['igl_heat'] / v:.2f}x" for k, v in t.items() if k != "igl_heat")
              + f"  (libigl {t['igl_heat']:.3f} ms)", flush=True)
    t = all_pairs("camelhead.off", 2000, radii, args.allpairs_rounds)
    doc["all_pairs_s"]["camelhead.off"] = t
    print("camelhead.off      all pairs 1 core, batched heat / meshfmm: "
          + "  ".join(f"{k} {t['heat_batched_p1'] / v:.2f}x" for k, v in t.items()
                      if k != "heat_batched_p1")
          + f"  (heat {t['heat_batched_p1']:.1f} s full matrix)", flush=True)
    Path(args.o).parent.mkdir(parents=True, exist_ok=True)
    Path(args.o).write_text(json.dumps(doc, indent=1))


if __name__ == "__main__":
    main()
