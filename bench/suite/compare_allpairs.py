#!/usr/bin/env python3
"""All-pairs geodesic distance matrices: entries per second and peak memory of
meshfmm (`meshfmm allpairs`, backends serial, threads and OpenCL) against the
peers' best routes to the same matrix:

  gc_heat_loop    one potpourri3d.MeshHeatMethodDistanceSolver precompute, then a
                  loop of heat solves, one row each (written into a .npy memmap)
  igl_heat_loop   the same with igl.heat_geodesics_precompute / _solve
  gdist_local     gdist.local_gdist_matrix with a max distance (small meshes; a
                  sparse matrix), against `meshfmm allpairs --max-distance` with the
                  same radius
  gdist_loop      gdist.compute_gdist per row (exact), a few rows, extrapolated
  heat_batched_pN the heat method batched over blocks of 32 sources (bench/suite/heat_batched.py:
                  intrinsic Delaunay Laplacian, one CHOLMOD factorisation per process), in N
                  processes of one BLAS thread each; its rows are checked against meshfmm's

Every run is its own child process; peak memory is that child's ru_maxrss
(os.wait4). Times are wall seconds of the whole child (load, precompute,
rows, write), except where a row says otherwise. On big meshes a subset of rows
(spread over the mesh) is computed and the time to the full N x N matrix is
extrapolated (marked "extrapolated").

Writes bench/results/allpairs_peers.json. Needs the peers: run
scripts/setup.sh --bench first.

    python bench/suite/compare_allpairs.py [--quick]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/
import benchlib as bl  # noqa: E402


def run_child_rss(cmd, env=None):
    """(wall seconds, peak RSS MiB, stdout) of a child process, reaped with
    os.wait4 so that ru_maxrss is this child's own."""
    t0 = time.perf_counter()
    with tempfile.TemporaryFile("w+") as fo, tempfile.TemporaryFile("w+") as fe:
        p = subprocess.Popen(cmd, stdout=fo, stderr=fe, text=True, env=env)
        _, status, ru = os.wait4(p.pid, 0)
        p.returncode = os.waitstatus_to_exitcode(status)
        wall = time.perf_counter() - t0
        fo.seek(0)
        fe.seek(0)
        out, err = fo.read(), fe.read()
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd[:4]))} failed ({p.returncode}): {err[-500:]}")
    return wall, ru.ru_maxrss / 1024.0, out


# ---------------------------------------------------------------- workers (child side)
def worker(kind, mesh_name, rows_file, out_file, radius):
    import meshfmm

    V, F = meshfmm.load_mesh(bl.DATA / "meshes" / mesh_name)
    V, F, old_of_new, new_of_old = bl.compact(V, F)
    rows = np.load(rows_file) if rows_file != "-" else None
    res = {}
    t0 = time.perf_counter()
    if kind == "baseline":  # what the interpreter and the peers' modules cost
        import gdist  # noqa: F401
        import igl  # noqa: F401
        import potpourri3d  # noqa: F401
    elif kind in ("gc_heat_loop", "igl_heat_loop"):
        out = np.lib.format.open_memmap(out_file, mode="w+", dtype=np.float32,
                                        shape=(rows.size, V.shape[0]))
        if kind == "gc_heat_loop":
            import potpourri3d as pp3d

            heat = pp3d.MeshHeatMethodDistanceSolver(V, F)
            heat.compute_distance(int(rows[0]))
            solve = heat.compute_distance
        else:
            import igl

            data = igl.HeatGeodesicsData()
            igl.heat_geodesics_precompute(V, F, data)

            def solve(s):
                return igl.heat_geodesics_solve(data, np.array([s], dtype=np.int64))
        res["precompute_s"] = time.perf_counter() - t0
        t1 = time.perf_counter()
        for i, s in enumerate(rows):
            out[i] = solve(int(s))
        out.flush()
        res["rows_s"] = time.perf_counter() - t1
    elif kind.startswith("heat_batched_p"):
        nproc = int(kind[len("heat_batched_p"):])
        out = np.lib.format.open_memmap(out_file, mode="w+", dtype=np.float32,
                                        shape=(rows.size, V.shape[0]))
        del out
        parts = np.array_split(np.arange(rows.size), nproc)
        import multiprocessing as mp

        ctx = mp.get_context("fork")
        with ctx.Pool(nproc) as pool:
            times = pool.starmap(_heat_part, [(V, F, rows, p, out_file) for p in parts])
        res["precompute_s"] = max(t[0] for t in times)
        res["rows_s"] = time.perf_counter() - t0 - res["precompute_s"]
        # agreement with meshfmm on a few rows (mean relative difference)
        import meshfmm as mf

        D = np.load(out_file, mmap_mode="r")
        pick = np.linspace(0, rows.size - 1, min(8, rows.size)).astype(int)
        ref = mf.Mesh(V, F).distance_matrix(rows[pick], backend="serial", dtype="float64")
        got = np.asarray(D[pick], dtype=np.float64)
        pos = ref > 0
        res["mean_rel_diff_vs_meshfmm_pct"] = float(100 * np.mean(np.abs(got[pos] - ref[pos]) / ref[pos]))
    elif kind == "gdist_loop":
        import gdist

        F32 = F.astype(np.int32)
        out = np.lib.format.open_memmap(out_file, mode="w+", dtype=np.float32,
                                        shape=(rows.size, V.shape[0]))
        t0 = time.perf_counter()
        for i, s in enumerate(rows):
            out[i] = gdist.compute_gdist(V, F32, source_indices=np.array([s], dtype=np.int32))
        out.flush()
        res["rows_s"] = time.perf_counter() - t0
    elif kind == "gdist_local":
        import gdist

        M = gdist.local_gdist_matrix(V, F.astype(np.int32), max_distance=float(radius))
        res["rows_s"] = time.perf_counter() - t0
        res["nnz"] = int(M.nnz)
    print(json.dumps(res))


def _heat_part(V, F, rows, part, out_file):
    """One process of heat_batched_pN: factor, then its share of the rows."""
    from heat_batched import BatchedHeat

    t0 = time.perf_counter()
    h = BatchedHeat(V, F)
    t1 = time.perf_counter()
    out = np.load(out_file, mmap_mode="r+")
    step = 512
    for i in range(0, part.size, step):
        idx = part[i:i + step]
        out[idx] = h.rows(rows[idx])
    out.flush()
    return t1 - t0, time.perf_counter() - t1


# ---------------------------------------------------------------- driver
def meshfmm_run(mesh_path, backend, rows_file, out_file, radius=None, threads=None):
    cmd = [str(bl.CLI), "allpairs", str(mesh_path), "-o", str(out_file), "--backend", backend,
           "--quiet"]
    if rows_file is not None:
        cmd += ["--sources", str(rows_file)]
    if radius is not None:
        cmd += ["--max-distance", repr(float(radius))]
    if threads:
        cmd += ["--threads", str(threads)]
    wall, rss, _ = run_child_rss(cmd)
    return wall, rss


def py_worker(kind, mesh, rows_file, out_file, radius=0.0):
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", kind, mesh,
           str(rows_file) if rows_file else "-", str(out_file), repr(float(radius))]
    # one BLAS thread per process (set before numpy loads): peers run one thread each
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    wall, rss, out = run_child_rss(cmd, env=env)
    return wall, rss, json.loads(out.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--worker", nargs=5, metavar=("KIND", "MESH", "ROWS", "OUT", "RADIUS"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("-o", default=str(bl.RESULTS / "allpairs_peers.json"))
    args = ap.parse_args()
    if args.worker:
        worker(*args.worker)
        return

    def log(msg):
        print(msg, flush=True)

    # mesh, rows computed (None: all), gdist.local_gdist_matrix radius (fraction of diagonal)
    # (camelhead 2000 rows, nefertiti and a 250k+ mesh: sine 500, generated into
    # a scratch folder; absolute paths pass through
    # bl.DATA / "meshes" / name unchanged)
    gen_dir = Path(tempfile.gettempdir()) / "mfmm_bench_meshes"
    gen_dir.mkdir(exist_ok=True)
    bl.generate("sine", 500, gen_dir)
    sine500 = str(gen_dir / "sine_500.obj")
    plan = [("hand_lowres.obj", None, [None, 0.15]),
            ("spot.obj", None, [0.1]),
            ("camelhead.off", 2000, []),
            ("nefertiti-lowres.obj", 1000, []),
            (sine500, 64, [])]
    gdist_rows = {"hand_lowres.obj": 16, "spot.obj": 16, "camelhead.off": 4,
                  "nefertiti-lowres.obj": 4}  # none on sine 500 (~0.5 min a row)
    if args.quick:
        plan = [("hand_lowres.obj", None, [0.15]), ("spot.obj", 200, [])]
        gdist_rows = {"hand_lowres.obj": 4, "spot.obj": 2}

    import meshfmm

    env_note = os.environ.get("MESHFMM_OPENCL_DEVICE")
    t_start = time.perf_counter()
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        out_file = tmp / "D.npy"
        # warm the OpenCL program cache so no run below pays for the kernel build
        try:
            meshfmm_run(bl.DATA / "meshes" / "hand_lowres.obj", "opencl", None, out_file)
            have_opencl = True
        except RuntimeError as exc:
            have_opencl = False
            log(f"OpenCL unavailable: {exc}")
        base_wall, base_rss, _ = py_worker("baseline", "hand_lowres.obj", None, out_file)
        for name, n_rows, radii in plan:
            path = bl.DATA / "meshes" / name
            V, F = meshfmm.load_mesh(path)
            Vc, Fc, old_of_new, new_of_old = bl.compact(V, F)
            nv = V.shape[0]
            nvc = Vc.shape[0]
            diag = bl.bbox_diagonal(Vc)
            rows = (np.arange(nv) if n_rows is None
                    else old_of_new[(np.arange(n_rows) * nvc) // n_rows])
            rows_file = tmp / "rows.npy"
            np.save(rows_file, rows.astype(np.int64))
            rows_c_file = tmp / "rows_c.npy"  # the same rows in the compacted mesh
            np.save(rows_c_file, new_of_old[rows].astype(np.int64))
            full = nv * nv

            def add(method, time_s, wall, rss, n, extra=None, radius=None, full_s=None):
                r = {"mesh": Path(name).name, "n_vertices": nv, "method": method, "rows": int(n),
                     "radius": radius, "time_s": time_s, "wall_s": wall, "peak_rss_mib": rss,
                     "entries_per_s": n * nv / time_s,
                     "full_matrix_s": full_s if full_s is not None else time_s * nv / n,
                     "extrapolated": n < nv}
                if extra:
                    r.update(extra)
                results.append(r)
                log(f"{name:<22}{method:<18}{'r=' + format(radius, '.3g') if radius else '':>9}"
                    f"{n:>7} rows {time_s:8.2f} s {r['entries_per_s'] / 1e6:9.2f} M/s "
                    f"{rss:8.1f} MiB  full {r['full_matrix_s']:.4g} s"
                    + (" (extrapolated)" if r["extrapolated"] else ""))
                return r

            backends = ["serial", "threads"] + (["opencl"] if have_opencl else [])
            one_file = tmp / "one_row.npy"
            np.save(one_file, rows[:1].astype(np.int64))
            for be in backends:
                wall, rss = meshfmm_run(path, be, rows_file if n_rows else None, out_file)
                out_file.unlink(missing_ok=True)
                if rows.size < nv:
                    # the fixed part (process, load, build: a one-row run) counts once
                    # in the full matrix, as the heat method's precompute does
                    setup, _ = meshfmm_run(path, be, one_file, out_file)
                    out_file.unlink(missing_ok=True)
                    setup = min(setup, wall)
                    add(f"meshfmm_{be}", wall, wall, rss, rows.size, {"setup_s": setup},
                        full_s=setup + (wall - setup) * (nv - 1) / (rows.size - 1))
                else:
                    add(f"meshfmm_{be}", wall, wall, rss, rows.size)
            for kind in ("gc_heat_loop", "igl_heat_loop", "heat_batched_p1", "heat_batched_p2"):
                wall, rss, res = py_worker(kind, name, rows_c_file, out_file)
                # full matrix = precompute once + rows scaled up
                t = res["precompute_s"] + res["rows_s"]
                add(kind, t, wall, rss, rows.size, res,
                    full_s=res["precompute_s"] + res["rows_s"] * nv / rows.size)
                out_file.unlink(missing_ok=True)
            # exact rows: a few, extrapolated
            k = gdist_rows.get(name, 0)
            if k:
                g_rows = new_of_old[rows[(np.arange(k) * rows.size) // k]]
                np.save(tmp / "g_rows.npy", g_rows.astype(np.int64))
                wall, rss, res = py_worker("gdist_loop", name, tmp / "g_rows.npy", out_file)
                add("gdist_loop", res["rows_s"], wall, rss, k, res)
                out_file.unlink(missing_ok=True)
            # gdist.local_gdist_matrix against meshfmm --max-distance, same radius
            for frac in radii:
                radius = 1e100 if frac is None else frac * diag
                wall, rss, res = py_worker("gdist_local", name, None, out_file, radius)
                add("gdist_local", res["rows_s"], wall, rss, nv, dict(res, radius_frac_diag=frac),
                    radius=None if frac is None else radius)
                for be in (("threads",) if frac is not None else ()):  # unbounded: run above
                    wall, rss = meshfmm_run(path, be, None, out_file,
                                            radius=None if frac is None else radius)
                    add(f"meshfmm_{be}", wall, wall, rss, nv, {"radius_frac_diag": frac},
                        radius=None if frac is None else radius)
                    out_file.unlink(missing_ok=True)
    doc = {
        "what": "all-pairs distance matrices: entries per second and peak memory",
        "machine": bl.machine_info(),
        "versions": bl.versions(),
        "opencl_device_env": env_note,
        "python_worker_baseline": {"wall_s": base_wall, "peak_rss_mib": base_rss,
                                   "note": "a Python child that imports numpy, potpourri3d, "
                                           "igl and gdist and loads hand_lowres; the peers' "
                                           "rows include this much"},
        "notes": [
            "time_s: meshfmm: wall time of the whole `meshfmm allpairs` process (mesh load, "
            "build, rows, writing the float32 .npy); full_matrix_s: setup_s (a one-row run's "
            "wall time) once + the other rows' time scaled to N - 1 rows; Python peers: "
            "precompute + rows timed inside "
            "the child (interpreter start, imports and mesh loading left out, see wall_s); "
            "peak_rss_mib: the child's ru_maxrss",
            "meshfmm rows: `meshfmm allpairs MESH -o OUT.npy --backend B [--sources] "
            "[--max-distance]`, streamed to disk",
            "heat loops: one precompute, then one solve per row into a float32 .npy memmap; "
            "full_matrix_s = precompute + rows time scaled to N rows",
            "gdist_loop: gdist.compute_gdist per row; entries_per_s from the rows alone; "
            "full_matrix_s extrapolated",
            "gdist_local: gdist.local_gdist_matrix(max_distance=radius), a scipy sparse "
            "matrix of the entries within the radius; radius None means unbounded",
        ],
        "results": results,
        "total_s": time.perf_counter() - t_start,
    }
    out = Path(args.o)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(doc, indent=1) + "\n")
    log(f"written {out} ({doc['total_s']:.0f} s)")


if __name__ == "__main__":
    main()
