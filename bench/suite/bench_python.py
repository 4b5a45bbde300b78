#!/usr/bin/env python3
"""meshfmm from Python against geometry-central (potpourri3d), in one process.

For each mesh of tests/data/meshes: the median time per source of
``Mesh.distance`` against potpourri3d's fast marching
(MeshFastMarchingDistanceSolver) and heat method (MeshHeatMethodDistanceSolver,
timed after its precompute: solver built and one solve done), with the mean
relative error of each against the stored exact distances where there are
some. Then the call overhead: a ~1k-vertex solve from Python against the same
solve timed in C (a small C program compiled against the same libmeshfmm, or a
bare ctypes loop on mfmm_solve without a compiler).

Writes bench/results/python_speed.json. Not a test: timings on a shared
machine are noisy; the medians over rounds of per-method blocks are reported.

    python bench/suite/bench_python.py [--meshes a.obj b.off ...] [--sources 20] [--large]
"""

from __future__ import annotations

import argparse
import ctypes
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/
from benchlib import DATA, DATA_MESHES, REPO, compact, load_reference, reference_path  # noqa: E402
from benchlib import mean_rel_error as mre  # noqa: E402

# the manifold meshes with stored exact references (not beetle, not igea)
MESHES = [m for m in DATA_MESHES if m not in ("beetle.obj", "igea.ply")]

import meshfmm  # noqa: E402
from meshfmm import _lib  # noqa: E402


def timed(fn, *args):
    t = time.perf_counter()
    r = fn(*args)
    return time.perf_counter() - t, r


def bench_mesh(name, n_sources, repeats):
    import potpourri3d as pp3d

    V, F = meshfmm.load_mesh(DATA / "meshes" / name)
    V2, F2, old_of_new, new_of_old = compact(V, F)
    t_build, mesh = timed(meshfmm.Mesh, V, F)
    t_gc_build, fmm = timed(pp3d.MeshFastMarchingDistanceSolver, V2, F2)
    t0 = time.perf_counter()
    heat = pp3d.MeshHeatMethodDistanceSolver(V2, F2)
    heat.compute_distance(0)  # the factorisations happen here
    t_heat_pre = time.perf_counter() - t0

    rng = np.random.default_rng(1)
    sources = rng.choice(old_of_new, size=min(n_sources, old_of_new.size), replace=False)
    ours, gcf, gch = [], [], []
    # Rounds of blocks (all sources with one method, then the next): machine
    # load hits all three alike, and each runs with its own data in cache, as
    # a user's loop over sources would.
    for _ in range(repeats):
        for s in sources:
            ours.append(timed(mesh.distance, int(s))[0])
        for s in sources:
            gcf.append(timed(fmm.compute_distance, [[(int(new_of_old[s]), [])]])[0])
        for s in sources:
            gch.append(timed(heat.compute_distance, int(new_of_old[s]))[0])
    row = {
        "n_vertices": int(V.shape[0]),
        "n_faces": int(F.shape[0]),
        "sources": int(len(sources)),
        "repeats": repeats,
        "meshfmm_s": float(np.median(ours)),
        "gc_fmm_s": float(np.median(gcf)),
        "gc_heat_s": float(np.median(gch)),
        "meshfmm_build_s": t_build,
        "gc_fmm_build_s": t_gc_build,
        "gc_heat_precompute_s": t_heat_pre,
    }
    row["speedup_vs_gc_fmm"] = row["gc_fmm_s"] / row["meshfmm_s"]
    row["speedup_vs_gc_heat"] = row["gc_heat_s"] / row["meshfmm_s"]
    row["meshfmm_vertices_per_s"] = V.shape[0] / row["meshfmm_s"]
    if reference_path(name).is_file():
        errs = {"meshfmm": [], "gc_fmm": [], "gc_heat": []}
        for s, e in zip(*load_reference(name)):
            errs["meshfmm"].append(mre(mesh.distance(int(s)), e))
            for key, f in (("gc_fmm", lambda t: fmm.compute_distance([[(t, [])]])),
                           ("gc_heat", lambda t: heat.compute_distance(t))):
                d = np.full(V.shape[0], np.inf)
                d[old_of_new] = np.asarray(f(int(new_of_old[s]))).reshape(-1)
                errs[key].append(mre(d, e))
        row["mean_rel_error_pct"] = {k: float(np.mean(v)) for k, v in errs.items()}
    mesh.close()
    return row


C_PROGRAM = r"""
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "meshfmm.h"
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t);
                          return t.tv_sec + 1e-9 * t.tv_nsec; }
static int cmp(const void *a, const void *b) { double x = *(const double *)a, y = *(const double *)b;
                                               return (x > y) - (x < y); }
int main(int argc, char **argv) {
    int n = atoi(argv[1]), reps = atoi(argv[2]);
    int nv = (n + 1) * (n + 1), nf = 2 * n * n;
    double *V = malloc(sizeof(double) * 3 * nv); int32_t *F = malloc(sizeof(int32_t) * 3 * nf);
    for (int j = 0, k = 0; j <= n; j++) for (int i = 0; i <= n; i++, k++) {
        V[3*k] = (double)i / n; V[3*k+1] = (double)j / n;
        V[3*k+2] = 0.1 * ((i * 7 + j * 13) % 5) / n; }
    for (int j = 0, k = 0; j < n; j++) for (int i = 0; i < n; i++) {
        int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = a + n + 2;
        F[3*k] = a; F[3*k+1] = b; F[3*k+2] = d; k++;
        F[3*k] = a; F[3*k+1] = d; F[3*k+2] = c; k++; }
    mfmm_mesh *mesh; mfmm_solver *solver;
    if (mfmm_mesh_create(V, nv, F, nf, NULL, &mesh, NULL) || mfmm_solver_create(mesh, &solver)) return 1;
    double *d = malloc(sizeof(double) * nv), *t = malloc(sizeof(double) * reps);
    mfmm_source s = {0, -1, {0, 0, 0}, 0.0};
    for (int r = 0; r < reps; r++) {
        s.vertex = r % nv;
        double t0 = now();
        mfmm_solve(solver, &s, 1, NULL, d, NULL);
        t[r] = now() - t0; }
    qsort(t, reps, sizeof(double), cmp);
    double t0 = now(); mfmm_solver *x;
    for (int r = 0; r < reps; r++) { mfmm_solver_create(mesh, &x); mfmm_solver_destroy(x); }
    printf("%.9e %.9e\n", t[reps / 2], (now() - t0) / reps);
    return 0;
}
"""


def grid_mesh(n):
    """The same bumpy (n+1)^2 grid as C_PROGRAM."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="xy")
    V = np.stack([i / n, j / n, 0.1 * ((i * 7 + j * 13) % 5) / n], axis=-1).reshape(-1, 3)
    F = []
    for jj in range(n):
        for ii in range(n):
            a = jj * (n + 1) + ii
            F += [(a, a + 1, a + n + 2), (a, a + n + 2, a + n + 1)]
    return V.astype(np.float64), np.array(F, dtype=np.int32)


def bench_overhead(n=31, reps=4000):
    """Python Mesh.distance against C mfmm_solve on a (n+1)^2 = 1024-vertex grid."""
    V, F = grid_mesh(n)
    mesh = meshfmm.Mesh(V, F)
    nv = V.shape[0]
    for r in range(200):
        mesh.distance(r % nv)
    py = []
    for r in range(reps):
        t0 = time.perf_counter()
        mesh.distance(r % nv)
        py.append(time.perf_counter() - t0)
    result = {"n_vertices": nv, "python_s": float(np.median(py))}

    # C, compiled against the same header and library
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc:
        with tempfile.TemporaryDirectory() as tmp:
            src = Path(tmp) / "overhead.c"
            src.write_text(C_PROGRAM)
            # the package holds libmeshfmm.so alone; the link records its soname
            for name in ("libmeshfmm.so.0", "libmeshfmm.so"):
                (Path(tmp) / name).symlink_to(meshfmm.library_path)
            libdir = tmp
            exe = Path(tmp) / "overhead"
            subprocess.run([cc, "-O2", "-std=c99", "-I", str(REPO / "include"), str(src),
                            meshfmm.library_path, "-o", str(exe), f"-Wl,-rpath,{libdir}"],
                           check=True)
            out = subprocess.run([str(exe), str(n), str(reps)], check=True, capture_output=True,
                                 text=True).stdout.split()
            result["c_s"] = float(out[0])
            result["c_solver_create_destroy_s"] = float(out[1])
            result["c_timer"] = "compiled C loop on mfmm_solve (clock_gettime per solve, median)"
    else:  # a bare ctypes loop: the C time plus the least Python can add
        m = mesh._ptr
        solver = ctypes.c_void_p()
        _lib.mfmm_solver_create(m, ctypes.byref(solver))
        src = _lib.mfmm_source(0, -1, (_lib.c_double * 3)(), 0.0)
        d = np.empty(nv)
        addr = d.ctypes.data
        ts = []
        for r in range(reps):
            src.vertex = r % nv
            t0 = time.perf_counter()
            _lib.mfmm_solve(solver, ctypes.addressof(src), 1, None, addr, None)
            ts.append(time.perf_counter() - t0)
        _lib.mfmm_solver_destroy(solver)
        result["c_s"] = float(np.median(ts))
        result["c_timer"] = "bare ctypes loop on mfmm_solve (no C compiler)"
    result["python_over_c"] = result["python_s"] / result["c_s"]
    mesh.close()
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--meshes", nargs="*", default=MESHES)
    ap.add_argument("--sources", type=int, default=10)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--large", action="store_true", help="also igea.ply (134k vertices)")
    ap.add_argument("-o", default=str(REPO / "bench" / "results" / "python_speed.json"))
    args = ap.parse_args()
    if not (DATA / "meshes").is_dir():
        sys.exit(f"no meshes at {DATA / 'meshes'}")
    meshes = list(args.meshes) + (["igea.ply"] if args.large else [])

    rows = {}
    print(f"meshfmm {meshfmm.__version__} ({meshfmm.library_path}), median time per source")
    print(f"{'mesh':<22}{'nv':>7}{'meshfmm ms':>12}{'gc-FMM ms':>11}{'gc-heat ms':>11}"
          f"{'FMM/ours':>10}{'heat/ours':>10}{'Mvert/s':>9}   MRE% ours / gc-FMM / gc-heat")
    for name in meshes:
        r = bench_mesh(name, args.sources, args.repeats)
        rows[name] = r
        err = r.get("mean_rel_error_pct")
        errs = (f"{err['meshfmm']:.3f} / {err['gc_fmm']:.3f} / {err['gc_heat']:.3f}"
                if err else "-")
        print(f"{name:<22}{r['n_vertices']:>7}{1e3 * r['meshfmm_s']:>12.3f}"
              f"{1e3 * r['gc_fmm_s']:>11.3f}{1e3 * r['gc_heat_s']:>11.3f}"
              f"{r['speedup_vs_gc_fmm']:>10.2f}{r['speedup_vs_gc_heat']:>10.2f}"
              f"{r['meshfmm_vertices_per_s'] / 1e6:>9.2f}   {errs}", flush=True)

    ov = bench_overhead()
    print(f"\ncall overhead, {ov['n_vertices']}-vertex solve: Python {1e6 * ov['python_s']:.1f} us, "
          f"C {1e6 * ov['c_s']:.1f} us ({ov['c_timer']}): Python/C = {ov['python_over_c']:.3f}")
    if "c_solver_create_destroy_s" in ov:
        print(f"solver create+destroy: {1e6 * ov['c_solver_create_destroy_s']:.2f} us "
              "(the binding pools solvers instead)")

    doc = {
        "machine": {"platform": platform.platform(), "processor": platform.processor(),
                    "cpus": os.cpu_count(), "python": platform.python_version()},
        "meshfmm_version": meshfmm.__version__,
        "timing": "median seconds per source over rounds of per-method blocks; heat after its precompute",
        "meshes": rows,
        "call_overhead": ov,
    }
    out = Path(args.o)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"written to {out}")


if __name__ == "__main__":
    main()
