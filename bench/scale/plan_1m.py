"""The numbers behind the 1M-vertex all-pairs plan (bench/RESULTS.md,
section "Plan: all pairs on a 1M-vertex mesh"), measured on this machine:

    MESHFMM_LIBRARY=build/libmeshfmm.so PYTHONPATH=bindings/python \
        python bench/scale/plan_1m.py && python bench/suite/make_results_md.py

Measured: the sine surface of `meshfmm generate sine 1000` (1,002,001
vertices), mesh build time, per-row time for `--rows` contiguous rows (as one
task computes them) on 1 thread, float32, best of `--repeats`; the compression ratio and encode
speed of those rows with the codecs meshfmm.distributed offers; the process's
resident memory with V and F, after the mesh, after a block; an idle Dask
worker's memory and the scheduler's time per (no-op) task. Extrapolated
(written as such in the plan): core-hours, node-hours on 16-core machines,
store sizes, task counts. Rerun after changes to the core (e.g. vertex
renumbering) to refresh the plan. Writes bench/results/plan_1m.json."""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numcodecs
import numpy as np
from numcodecs import Blosc

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/
import benchlib  # noqa: E402
import meshfmm  # noqa: E402

numcodecs.blosc.use_threads = False


def rss_mib() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1000, help="sine grid side (n+1)^2 vertices")
    ap.add_argument("--rows", type=int, default=16, help="rows timed (one task's block)")
    ap.add_argument("--node-cores", type=int, default=16)
    ap.add_argument("--repeats", type=int, default=2)
    a = ap.parse_args()
    rng = np.random.default_rng(11)
    work = Path(tempfile.mkdtemp(prefix="mfmm_plan_"))

    rss0 = rss_mib()
    V, F = benchlib.generate("sine", a.n, work)
    V = np.ascontiguousarray(V, np.float64)
    F = np.ascontiguousarray(F, np.int32)
    rss_vf = rss_mib()
    t0 = time.perf_counter()
    mesh = meshfmm.Mesh(V, F)  # what a worker does with the V, F it is sent
    t_build = time.perf_counter() - t0
    rss_mesh = rss_mib()
    vf_bytes = V.nbytes + F.nbytes
    del V, F
    nv = mesh.n_vertices
    print(f"sine {a.n}: {nv} vertices, {mesh.n_faces} faces; mesh built in {t_build:.2f} s; "
          f"RSS {rss_vf:.0f} -> {rss_mesh:.0f} MiB", flush=True)

    # warm-up row (page faults of the solver's arrays), not timed
    mesh.distance_matrix(np.array([0], np.int32), backend="threads", n_threads=1)
    # what a worker holds once it has computed a row: the mesh, the tables
    # its first march builds and keeps (spokes, the exact start's), a workspace
    rss_row = rss_mib()
    print(f"after the first row (spokes, exact tables, workspace): RSS {rss_row:.0f} MiB",
          flush=True)
    r0 = int(rng.integers(0, nv - a.rows))
    src = np.arange(r0, r0 + a.rows, dtype=np.int32)
    t_rows = float("inf")
    for _ in range(a.repeats):  # the best of the repeats: the box may be shared
        t0 = time.perf_counter()
        D = mesh.distance_matrix(src, backend="threads", n_threads=1, dtype="float32")
        t_rows = min(t_rows, time.perf_counter() - t0)
    rss_block = rss_mib()
    per_row = t_rows / a.rows
    print(f"{a.rows} rows from {r0}: {per_row * 1e3:.1f} ms/row on 1 thread "
          f"({nv / per_row / 1e6:.2f} M entries/s); RSS after the block {rss_block:.0f} MiB",
          flush=True)

    codecs = {}
    for name, cname, lvl in (("lz4", "lz4", 5), ("zstd", "zstd", 3)):
        c = Blosc(cname=cname, clevel=lvl, shuffle=Blosc.BITSHUFFLE)
        t0 = time.perf_counter()
        enc = c.encode(D)
        te = time.perf_counter() - t0
        codecs[name] = {"ratio": D.nbytes / len(enc), "encode_mb_s": D.nbytes / te / 1e6}
        print(f"  {name} + bitshuffle: ratio {codecs[name]['ratio']:.3f}, encode "
              f"{codecs[name]['encode_mb_s']:.0f} MB/s", flush=True)

    # Dask: a worker process's resident memory idle, and the scheduler's cost
    # per task (no-op tasks on a 2-process LocalCluster)
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as client:
        client.run(lambda: [__import__(m) for m in ("meshfmm", "zarr", "zarr.codecs")])
        worker_rss = max(client.run(rss_mib).values())
        n_tasks = 2000
        client.gather(client.map(int, range(200), pure=False))  # warm-up
        t0 = time.perf_counter()
        client.gather(client.map(int, range(n_tasks), pure=False))
        per_task = (time.perf_counter() - t0) / n_tasks
    print(f"Dask worker idle RSS {worker_rss:.0f} MiB; {per_task * 1e3:.2f} ms per no-op task "
          f"(2 workers)", flush=True)

    cl_path = benchlib.RESULTS / "cluster.json"
    cluster = json.loads(cl_path.read_text()) if cl_path.is_file() else None
    eff = cluster["cluster_over_in_process"] if cluster else None
    res = {"machine": benchlib.machine_info(), "versions": benchlib.versions(),
           "mesh": f"sine {a.n}", "n_vertices": nv, "n_faces": mesh.n_faces,
           "mesh_build_seconds": t_build, "rows_timed": a.rows, "first_row": r0,
           "seconds_per_row_1_thread": per_row,
           "rss_mib": {"after_import": rss0, "with_v_f": rss_vf,
                                                            "after_mesh": rss_mesh,
                                                            "after_first_row": rss_row,
                                                            "after_block": rss_block},
           "v_f_bytes": vf_bytes, "dask_worker_idle_rss_mib": worker_rss,
           "dask_seconds_per_noop_task": per_task,
           "repeats": a.repeats, "block_rows": a.rows, "codecs": codecs, "node_cores": a.node_cores,
           "cluster_efficiency_measured": eff, "load_average": os.getloadavg()}
    out = benchlib.RESULTS / "plan_1m.json"
    out.write_text(json.dumps(res, indent=1) + "\n")
    print("wrote", out)


if __name__ == "__main__":
    main()
