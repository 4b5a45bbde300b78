#!/usr/bin/env python3
"""The exact start of the march: accuracy against exact geodesics
with and without it, against potpourri3d's robust heat method, the choice of
the default radius, and the time per source.

Cases (3 sources each; references as in compare_peers.py):
  choice set (the radius is chosen on these): hand, spot, fertility, bunny
    (stored igl.exact_geodesic; the bunny set r = 7, the one mesh above 0.6x
    at 6), sphere 4 (2.5k, great circle), sine 50 (exact); for the default's
    growth on larger meshes (MFMM_EXACT_START_AUTO, column "auto"): igea
    (134k, 0.64x at r = 7) and sine 500 (251k), both against mfmm_solve_exact;
  held out (not used to choose it): wingnut, decimated-max, camelhead,
    nefertiti (stored igl), beetle (mfmm_solve_exact: igl.exact_geodesic
    and gdist crash on it), sphere 5 (10k), lattice 50 and 100
    (Euclidean), sine 100, and two cases made for this benchmark: a jittered
    sine surface (70 x 70, vertices moved by up to 0.3 h) and a random planar
    Delaunay mesh (3000 points in the unit square, Euclidean reference).
  The exact reference on the sine surfaces is mfmm_solve_exact (equal to
  igl.exact_geodesic to 1e-9 on every stored mesh, tests/c/test_exact.c).

Metrics (docs/methods.md#metrics): mean relative error % and max error % of the
bounding-box diagonal (MRE averaged over sources, max over sources).
Timing: per source, plain vs exact start in alternating rounds (median), on
the meshes of 10k vertices and more; ratios from one run.

Writes bench/results/exact_start.json.

    python bench/suite/bench_exact_start.py [--radii 0 3 5 6 7 8 10 auto] [--rounds 5]
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
import benchlib as bl  # noqa: E402

import meshfmm  # noqa: E402

CHOICE = ["hand_lowres.obj", "spot.obj", "fertility_FE_10k.off", "sphere 4", "sine 50",
          "stanford-bunny.obj", "igea.ply", "sine 500"]


def default_radius():
    """The library's default exact_start radius: "auto" (MFMM_EXACT_START_AUTO)
    or a number."""
    import ctypes

    from meshfmm import _lib

    o = _lib.mfmm_solve_options()
    _lib.mfmm_solve_options_init(ctypes.byref(o))
    r = float(o.exact_start_radius)
    return "auto" if r == _lib.EXACT_START_AUTO else r


def auto_edges(nv):
    """MFMM_EXACT_START_AUTO's radius in mean edges for a full row (meshfmm.h)."""
    return 7.0 * max(1.0, (nv / 40000) ** 0.5)


def radius_arg(x):
    return "auto" if x == "auto" else float(x)


nearest = bl.nearest


def stored(name):
    sources, distances = bl.load_reference(name)
    return [int(s) for s in sources], list(distances)


def cases(workdir):
    for name in ["hand_lowres.obj", "spot.obj", "fertility_FE_10k.off", "wingnut.obj",
                 "decimated-max.obj", "camelhead.off", "nefertiti-lowres.obj",
                 "stanford-bunny.obj"]:
        V, F = bl.load_data(name)
        src, ref = stored(name)
        yield name, V, F, src, ref, "igl.exact_geodesic (stored)"
    rng = np.random.default_rng(1)
    for name in ["igea.ply", "beetle.obj"]:
        V, F = bl.load_data(name)
        src = [int(s) for s in rng.choice(len(V), 3, replace=False)]
        yield name, V, F, src, None, "mfmm_solve_exact"
    for lv in (4, 5):
        V, F = bl.generate("sphere", lv, workdir)
        dirs = np.array([[0.3, 0.5, 0.81], [-0.7, 0.1, -0.2], [0.05, -0.9, 0.4]])
        dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
        src = nearest(V, dirs)
        yield f"sphere {lv}", V, F, src, [bl.sphere_distance(V, s) for s in src], "great circle"
    for n in (50, 100):
        V, F = bl.generate("lattice", n, workdir)
        lo, hi = V.min(axis=0), V.max(axis=0)
        src = nearest(V, [lo + f * (hi - lo) for f in (np.array([0.5, 0.5, 0]),
                                                       np.array([0.23, 0.31, 0]),
                                                       np.array([0.71, 0.77, 0]))])
        rows = np.round(V[:, 1] / (hi[1] - lo[1] + 1e-300) * 1e9)
        xmin = max(V[rows == r, 0].min() for r in np.unique(rows))
        xmax = min(V[rows == r, 0].max() for r in np.unique(rows))
        inside = (V[:, 0] >= xmin - 1e-12) & (V[:, 0] <= xmax + 1e-12)
        ref = []
        for s in src:
            e = bl.plane_distance(V, s)
            e[~inside] = np.nan
            ref.append(e)
        yield f"lattice {n}", V, F, src, ref, "Euclidean"
    for n in (50, 100, 500):
        V, F = bl.generate("sine", n, workdir)
        src = nearest(V[:, :2], [np.array(p) for p in ([0.5, 0.5], [0.23, 0.31], [0.71, 0.77])])
        yield f"sine {n}", V, F, src, None, "mfmm_solve_exact"
    # made for this benchmark (never used to choose the radius)
    rng = np.random.default_rng(12)
    V, F = bl.generate("sine", 70, workdir)
    h = 1.0 / 70
    V = V.copy()
    xy = V[:, :2]
    interior = (xy > 1e-9).all(axis=1) & (xy < 1 - 1e-9).all(axis=1)
    xy[interior] += rng.uniform(-0.3 * h, 0.3 * h, size=(int(interior.sum()), 2))
    V[:, 2] = 0.45 * np.sin(2 * np.pi * V[:, 0]) * np.sin(2 * np.pi * V[:, 1])
    src = nearest(V[:, :2], [np.array(p) for p in ([0.5, 0.5], [0.23, 0.31], [0.71, 0.77])])
    yield "sine 70 jittered", V, F, src, None, "mfmm_solve_exact"
    from scipy.spatial import Delaunay

    P = np.vstack([rng.uniform(0, 1, size=(2996, 2)), [[0, 0], [1, 0], [0, 1], [1, 1]]])
    tri = Delaunay(P)
    V = np.column_stack([P, np.zeros(len(P))])
    F = tri.simplices.astype(np.int32)
    src = nearest(V[:, :2], [np.array(p) for p in ([0.5, 0.5], [0.23, 0.31], [0.71, 0.77])])
    yield "delaunay 3000", V, F, src, [bl.plane_distance(V, s) for s in src], "Euclidean (convex square)"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--radii", type=radius_arg, nargs="*", default=[0, 3, 5, 6, 7, 8, 10, "auto"])
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    import potpourri3d as pp3d

    out = {"what": __doc__.split("\n\n")[0], "machine": bl.machine_info(),
           "versions": bl.versions(), "choice_set": CHOICE, "radii": args.radii,
           "default_radius": default_radius(), "cases": []}
    with tempfile.TemporaryDirectory() as wd:
        for name, V, F, src, ref, ref_kind in cases(wd):
            m = meshfmm.Mesh(V, F)
            V2, F2, old_of_new, new_of_old = bl.compact(V, F)
            diam = bl.bbox_diagonal(V2)
            if ref is None:
                ref = [m.distance(s, method="exact") for s in src]
            row = {"name": name, "n_vertices": int(m.n_vertices), "reference": ref_kind,
                   "auto_radius_edges": auto_edges(int(m.n_vertices)),
                   "sources": src, "held_out": name not in CHOICE, "meshfmm": {}}
            for r in args.radii:
                errs = [bl.errors(m.distance(s, exact_start=r), e, diam) for s, e in zip(src, ref)]
                row["meshfmm"][str(r)] = {"mre_pct": float(np.mean([x[0] for x in errs])),
                                          "max_pct": float(np.max([x[1] for x in errs]))}
            heat = pp3d.MeshHeatMethodDistanceSolver(V2, F2, use_robust=True)
            errs = []
            for s, e in zip(src, ref):
                d2 = heat.compute_distance(int(new_of_old[s]))
                d = np.full(V.shape[0], np.inf)
                d[old_of_new] = d2
                errs.append(bl.errors(d, e, diam))
            row["heat_robust"] = {"mre_pct": float(np.mean([x[0] for x in errs])),
                                  "max_pct": float(np.max([x[1] for x in errs]))}
            if m.n_vertices >= 10000:
                t = {0: [], 1: []}
                for _ in range(args.rounds):
                    for k in (0, 1):
                        t0 = time.perf_counter()
                        for s in src:
                            m.distance(s, exact_start=(k == 1))
                        t[k].append((time.perf_counter() - t0) / len(src))
                row["time_per_source_s"] = {"plain": float(np.median(t[0])),
                                            "exact_start": float(np.median(t[1]))}
                row["time_ratio"] = row["time_per_source_s"]["exact_start"] / row["time_per_source_s"]["plain"]
            out["cases"].append(row)
            mm = row["meshfmm"]
            line = " ".join(f"r{r} {mm[str(r)]['mre_pct']:.3f}/{mm[str(r)]['max_pct']:.3f}"
                            for r in args.radii)
            print(f"{name:22s} {row['n_vertices']:6d} {'held' if row['held_out'] else 'pick'} | {line} | "
                  f"heat {row['heat_robust']['mre_pct']:.3f}/{row['heat_robust']['max_pct']:.3f}"
                  + (f" | time x{row['time_ratio']:.3f}" if "time_ratio" in row else ""), flush=True)
    path = bl.RESULTS / "exact_start.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print("wrote", path)


if __name__ == "__main__":
    main()
