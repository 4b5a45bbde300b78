"""Exact geodesics: meshfmm's mfmm_solve_exact against the stored
igl.exact_geodesic references (Kirsanov's MMP) and against gdist
(gdist.compute_gdist, also Kirsanov's MMP), timed per source in one run.

    MESHFMM_LIBRARY=build/libmeshfmm.so python bench/suite/bench_exact.py [--json OUT] [mesh ...]

One JSON line per mesh as it finishes, then a table. Times are the least of
BENCH_REPEAT (3) runs per source, averaged over the reference's 3 sources;
"max rel err" is against the stored igl reference, "vs gdist" against
gdist's distances from the same sources.

Meshes: tests/data/meshes (or $MESHFMM_DATA_DIR/meshes), references in
tests/data/reference. gdist is skipped (and said so) when it does not import:
run scripts/setup.sh --bench first (it builds gdist from source, since its
wheel does not import under numpy 2)."""

from __future__ import annotations

import ctypes
import json
import os
import sys
import time
from ctypes import c_double, c_void_p
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "bindings" / "python"))
os.environ.setdefault("MESHFMM_LIBRARY", str(REPO / "build" / "libmeshfmm.so"))
from meshfmm import _lib  # noqa: E402

# each solve is timed REPEAT times and the least kept (the machine is shared)
REPEAT = int(os.environ.get("BENCH_REPEAT", "3"))
DATA = Path(os.environ.get("MESHFMM_DATA_DIR", REPO / "tests" / "data"))
MESHES = ["hand_lowres.obj", "beetle.obj", "spot.obj", "wingnut.obj", "fertility_FE_10k.off",
          "decimated-max.obj", "camelhead.off", "nefertiti-lowres.obj", "stanford-bunny.obj"]


def load(path: Path):
    import igl
    V, F = igl.read_triangle_mesh(str(path))
    return np.ascontiguousarray(V, dtype=np.float64), np.ascontiguousarray(F, dtype=np.int32)


class Exact:
    def __init__(self, V, F):
        self.V, self.F = V, F
        err = _lib.mfmm_error()
        self.mesh = c_void_p()
        st = _lib.mfmm_mesh_create(V.ctypes.data, len(V), F.ctypes.data, len(F), None,
                                   ctypes.byref(self.mesh), ctypes.byref(err))
        assert st == 0, err.message
        self.solver = c_void_p()
        assert _lib.mfmm_exact_solver_create(self.mesh, ctypes.byref(self.solver)) == 0

    def solve(self, source: int, max_distance=np.inf):
        src = _lib.mfmm_source(source, -1, (c_double * 3)(0, 0, 0), 0.0)
        opt = _lib.mfmm_exact_options()
        _lib.mfmm_exact_options_init(ctypes.byref(opt))
        opt.max_distance = max_distance
        out = np.empty(len(self.V))
        info = _lib.mfmm_exact_info()
        err = _lib.mfmm_error()
        st = _lib.mfmm_solve_exact(self.solver, ctypes.byref(src), 1, ctypes.byref(opt),
                                   out.ctypes.data, ctypes.byref(info), ctypes.byref(err))
        assert st == 0, err.message
        return out, info

    def close(self):
        _lib.mfmm_exact_solver_destroy(self.solver)
        _lib.mfmm_mesh_destroy(self.mesh)


GDIST_CHILD = r"""
import sys, time, numpy as np, gdist
z = np.load(sys.argv[1])
V, F = z["V"], z["F"]
times, rows = [], []
for s in z["sources"]:
    best = np.inf
    for _ in range(int(z["repeat"])):
        t0 = time.perf_counter()
        d = gdist.compute_gdist(V, F, source_indices=np.array([s], dtype=np.int32))
        best = min(best, time.perf_counter() - t0)
    times.append(best)
    rows.append(d)
np.savez(sys.argv[2], times=np.array(times), distances=np.array(rows))
"""


class GdistProcess:
    """gdist in another interpreter (GDIST_PYTHON), for when this one's numpy
    is too new for gdist's wheel: same timing (compute_gdist alone)."""

    def __init__(self, python):
        self.python = python

    def run(self, V, F, sources, repeat):
        import subprocess
        import tempfile
        with tempfile.TemporaryDirectory() as tmp:
            a, b = Path(tmp) / "in.npz", Path(tmp) / "out.npz"
            np.savez(a, V=V, F=F, sources=np.array(sources, dtype=np.int32), repeat=repeat)
            subprocess.run([self.python, "-c", GDIST_CHILD, str(a), str(b)], check=True)
            z = np.load(b)
            return list(z["times"]), z["distances"]


def components(nv, F):
    """Vertex components of the faces (union-find), -1 for unreferenced."""
    parent = np.arange(nv)

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a
    for f in F:
        r = [find(int(v)) for v in f]
        for x in r[1:]:
            parent[find(x)] = find(r[0])
    roots = np.array([find(v) for v in range(nv)])
    used = np.zeros(nv, bool)
    used[F.ravel()] = True
    return np.where(used, roots, -1)


def gdist_module():
    try:
        import gdist
        return gdist, None
    except Exception as exc:  # numpy 2 vs a numpy 1 wheel: ValueError at import
        why = f"{type(exc).__name__}: {exc}"
    py = os.environ.get("GDIST_PYTHON")
    if py:
        return GdistProcess(py), f"in-process import failed ({why}); using {py}"
    return None, why


def main(names):
    gd, why = gdist_module()
    if gd is None:
        print(f"gdist skipped: it does not import ({why}); set GDIST_PYTHON to an "
              "interpreter with gdist and numpy < 2")
    elif why:
        print(f"gdist: {why}")
    rows = []
    for name in names or MESHES:
        V, F = load(DATA / "meshes" / name)
        ex = Exact(V, F)
        ref_path = DATA / "reference" / (Path(name).stem + ".npz")
        if ref_path.exists():
            ref = np.load(ref_path)
            sources, refd = [int(s) for s in ref["sources"]], ref["distances"]
        else:
            ref, refd = None, None
            sources = [int(np.argmax(np.bincount(F.ravel(), minlength=len(V)) > 0))]
        worst, worst_gd, t_ours, t_gd, gd_rows = 0.0, None, [], [], None
        # no reference: beetle, on which gdist and igl crash (non-manifold)
        if isinstance(gd, GdistProcess) and refd is not None:
            t_gd, gd_rows = gd.run(V, F, sources, REPEAT)
        for i, s in enumerate(sources):
            best = np.inf
            for _ in range(REPEAT):
                t0 = time.perf_counter()
                d, info = ex.solve(s)
                best = min(best, time.perf_counter() - t0)
            t_ours.append(best)
            if refd is not None:
                r = refd[i]
                fin = np.isfinite(r)
                assert np.array_equal(fin, np.isfinite(d)), f"{name}: finite sets differ"
                rel = np.abs(d[fin] - r[fin]) / np.maximum(r[fin], 1e-300)
                rel[r[fin] == 0] = np.abs(d[fin][r[fin] == 0])
                worst = max(worst, float(rel.max()))
            else:
                # no reference (beetle: igl and gdist crash on it): finite on
                # exactly the source's component, never NaN
                assert not np.isnan(d).any()
                comp = components(len(V), F)
                assert np.array_equal(np.isfinite(d), comp == comp[s]), f"{name}: finite set"
            if gd_rows is not None:
                g = gd_rows[i]
                fin = np.isfinite(d) & (d > 0)
                e = float((np.abs(d[fin] - g[fin]) / d[fin]).max())
                worst_gd = e if worst_gd is None else max(worst_gd, e)
            elif gd is not None and refd is not None:
                best = np.inf
                for _ in range(REPEAT):
                    t0 = time.perf_counter()
                    gd.compute_gdist(V, F, source_indices=np.array([s], dtype=np.int32))
                    best = min(best, time.perf_counter() - t0)
                t_gd.append(best)
        row = {"mesh": name, "nv": len(V), "nf": len(F), "max_rel_err": worst if ref else None,
               "ours_s": float(np.mean(t_ours)), "windows": info.n_windows,
               "peak_windows": info.peak_windows, "propagated": info.n_propagated, "pseudo": info.n_pseudo_sources, "peak_MB": info.peak_bytes / 2**20,
               "gdist_s": float(np.mean(t_gd)) if t_gd else None,
               "max_rel_vs_gdist": worst_gd}
        if t_gd:
            row["speedup"] = row["gdist_s"] / row["ours_s"]
        rows.append(row)
        print(json.dumps(row), flush=True)
        ex.close()
    return rows


def table(rows):
    print(f"{'mesh':22s} {'nv':>6s} {'max rel err':>11s} {'vs gdist':>9s} "
          f"{'ours ms':>9s} {'gdist ms':>9s} {'ratio':>6s} {'windows':>9s} {'peak MB':>8s}")
    for r in rows:
        err = "-" if r["max_rel_err"] is None else f"{r['max_rel_err']:.1e}"
        vs = "-" if r["max_rel_vs_gdist"] is None else f"{r['max_rel_vs_gdist']:.1e}"
        gd = "-" if r["gdist_s"] is None else f"{1e3 * r['gdist_s']:.2f}"
        ratio = f"{r['speedup']:.1f}x" if "speedup" in r else "-"
        print(f"{r['mesh']:22s} {r['nv']:6d} {err:>11s} {vs:>9s} {1e3 * r['ours_s']:9.2f} "
              f"{gd:>9s} {ratio:>6s} {r['windows']:9d} {r['peak_MB']:8.1f}")


if __name__ == "__main__":
    args = sys.argv[1:]
    out = None
    if "--json" in args:
        i = args.index("--json")
        out = Path(args[i + 1])
        del args[i:i + 2]
    rows = main(args)
    table(rows)
    if out:
        sys.path.insert(0, str(REPO / "bench"))
        import benchlib
        gd = os.environ.get("GDIST_PYTHON")
        out.write_text(json.dumps({
            "machine": benchlib.machine_info(), "versions": benchlib.versions(),
            "gdist_python": gd, "repeat": REPEAT, "rows": rows}, indent=1) + "\n")
        print(f"written to {out}")
