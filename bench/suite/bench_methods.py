#!/usr/bin/env python3
"""The solve methods side by side: "windows" (two windows per half-edge)
against "fmm" (the march from the exact start, the default) on the cases of
bench_exact_start.py, for accuracy, the lower bound and time per source.

Cases: bench_exact_start.py's (its choice set and held-out meshes; none was
used to tune the windows method, which was tuned on hand, spot, camelhead,
nefertiti, the bunny, wingnut and flat Delaunay meshes), 3 sources each, the
same references.
Per case and method: mean relative error %, max error % of the bounding-box
diagonal (docs/methods.md#metrics), the least (d - exact) / exact over
vertices with exact > 0 (below 0: a value under the geodesic distance), and
the time per source (the least of --rounds rounds, methods alternating),
with the ratio windows / fmm.

Writes bench/results/methods.json.

    python bench/suite/bench_methods.py [--rounds 3] [--quick]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/
sys.path.insert(0, str(Path(__file__).resolve().parent))  # bench/suite/
import benchlib as bl  # noqa: E402
import bench_exact_start as bes  # noqa: E402

import meshfmm  # noqa: E402

METHODS = ["fmm", "windows"]


def least_relative(d, e):
    ok = np.isfinite(e) & (e > 0)
    return float(np.min((d[ok] - e[ok]) / e[ok]))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="skip the cases over 100k vertices")
    args = ap.parse_args()
    out = {"what": __doc__.split("\n\n")[0], "machine": bl.machine_info(),
           "versions": bl.versions(), "rounds": args.rounds, "cases": []}
    t_all = time.perf_counter()
    print(f"{'case':22s} {'nv':>7s} | {'fmm mean/max %':>16s} {'least':>9s} | "
          f"{'windows mean/max %':>18s} {'least':>9s} | {'ms fmm':>8s} {'ms win':>8s} {'x':>6s}")
    with tempfile.TemporaryDirectory() as wd:
        for name, V, F, src, ref, ref_kind in bes.cases(wd):
            if args.quick and len(V) > 100000:
                continue
            m = meshfmm.Mesh(V, F)
            V2 = bl.compact(V, F)[0]
            diam = bl.bbox_diagonal(V2)
            if ref is None:
                ref = [m.distance(s, method="exact") for s in src]
            row = {"name": name, "n_vertices": int(m.n_vertices), "reference": ref_kind,
                   "sources": src, "methods": {}}
            for meth in METHODS:
                ds = [m.distance(s, method=meth) for s in src]
                errs = [bl.errors(d, e, diam) for d, e in zip(ds, ref)]
                row["methods"][meth] = {
                    "mre_pct": float(np.mean([x[0] for x in errs])),
                    "max_pct": float(np.max([x[1] for x in errs])),
                    "least_rel": float(min(least_relative(d, np.asarray(e, dtype=float))
                                           for d, e in zip(ds, ref)))}
            best = {k: np.inf for k in METHODS}
            for _ in range(args.rounds):
                for meth in METHODS:
                    t0 = time.perf_counter()
                    for s in src:
                        m.distance(s, method=meth)
                    best[meth] = min(best[meth], (time.perf_counter() - t0) / len(src))
            for meth in METHODS:
                row["methods"][meth]["time_per_source_s"] = float(best[meth])
            row["time_ratio"] = float(best["windows"] / best["fmm"])
            out["cases"].append(row)
            f, w = row["methods"]["fmm"], row["methods"]["windows"]
            print(f"{name:22s} {row['n_vertices']:7d} | {f['mre_pct']:7.3f}/{f['max_pct']:7.3f} "
                  f"{f['least_rel']:9.2e} | {w['mre_pct']:9.3f}/{w['max_pct']:7.3f} "
                  f"{w['least_rel']:9.2e} | {1e3 * best['fmm']:8.2f} {1e3 * best['windows']:8.2f} "
                  f"{row['time_ratio']:6.2f}", flush=True)
    out["total_s"] = time.perf_counter() - t_all
    path = bl.RESULTS / "methods.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print("wrote", path)


if __name__ == "__main__":
    main()
