#!/usr/bin/env python3
"""The matrix backends side by side: entries per second of float32 rows on
serial, threads and OpenCL, for the march (the default) and method="windows".

Per mesh and method: the least wall time of --rounds rounds over the same
--rows sources (spread over the mesh), backends alternating within a round,
as entries (rows x columns) per second, with the ratio OpenCL / threads (the
brief's target for the march on a CPU: at least 0.85). The OpenCL program is
built (or loaded from its cache) before the first timed round. Rows of the
two backends are checked equal bit for bit in float32.

Writes bench/results/backends.json.

    python bench/suite/bench_backends.py [--rows 64] [--rounds 3] [MESH ...]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/
import benchlib as bl  # noqa: E402

import meshfmm  # noqa: E402

BACKENDS = ["serial", "threads", "opencl"]
METHODS = ["fmm", "windows"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("meshes", nargs="*", default=["camelhead.off", "nefertiti-lowres.obj"])
    ap.add_argument("--rows", type=int, default=64)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    out = {"what": __doc__.split("\n\n")[0], "machine": bl.machine_info(),
           "versions": bl.versions(), "rows": args.rows, "rounds": args.rounds, "cases": []}
    print(f"{'mesh':22s} {'method':8s} | " + " ".join(f"{b + ' M/s':>12s}" for b in BACKENDS)
          + f" | {'opencl/threads':>14s}")
    for name in args.meshes:
        V, F = bl.load_data(name)
        mesh = meshfmm.Mesh(V, F)
        nv = mesh.n_vertices
        src = np.linspace(0, nv - 1, args.rows).astype(np.int64).tolist()
        for method in METHODS:
            try:
                mesh.distance_matrix(src[:2], backend="opencl", method=method)
            except meshfmm.OpenCLError as e:
                print(f"{name}: no OpenCL ({e})")
                return 1
            best = {b: np.inf for b in BACKENDS}
            rows = {}
            for _ in range(args.rounds):
                for b in BACKENDS:
                    t0 = time.perf_counter()
                    rows[b] = mesh.distance_matrix(src, backend=b, method=method)
                    best[b] = min(best[b], time.perf_counter() - t0)
            if not np.array_equal(rows["opencl"], rows["threads"]):
                raise SystemExit(f"{name} {method}: OpenCL rows differ from threads rows")
            rate = {b: len(src) * nv / best[b] / 1e6 for b in BACKENDS}
            ratio = rate["opencl"] / rate["threads"]
            print(f"{name:22s} {method:8s} | " + " ".join(f"{rate[b]:12.2f}" for b in BACKENDS)
                  + f" | {ratio:14.2f}")
            out["cases"].append({"mesh": name, "nv": nv, "method": method,
                                 "seconds": best, "M_entries_per_s": rate,
                                 "opencl_over_threads": ratio})
    res = Path(__file__).resolve().parents[1] / "results" / "backends.json"
    res.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {res}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
