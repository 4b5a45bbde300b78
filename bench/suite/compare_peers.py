#!/usr/bin/env python3
"""Per-source accuracy and time of meshfmm against the libraries a user would
use instead, on every mesh of tests/data/meshes and on generated families.

Methods (same source vertices for all; several fixed sources per mesh):
  meshfmm            Mesh.distance (FMM with unfolding of obtuse angles)
  meshfmm_nounfold   Mesh.distance(..., unfolding=False)
  gc_fmm             potpourri3d.MeshFastMarchingDistanceSolver (geometry-central FMM)
  gc_heat            potpourri3d.MeshHeatMethodDistanceSolver (timed after its precompute)
  igl_heat           igl.heat_geodesics_precompute / igl.heat_geodesics_solve (default t)
  gdist              gdist.compute_gdist (exact, MMP)
  igl_exact          igl.exact_geodesic (exact, MMP; the reference where it runs)

References: tests/data/reference (igl.exact_geodesic, with the stored timings of
index.json), great-circle distance on icospheres, Euclidean distance on the
planar stretched lattice, igl.exact_geodesic run here on the small sine
surfaces, and gdist (the same exact polyhedral distance; the agreement with
the stored igl references is checked and recorded) where igl would take minutes.

Timing: for the fast methods, rounds of per-method blocks (each method runs all
sources, then the next method), the median over rounds x sources; the exact
methods run once per source (they take up to seconds). Errors
(docs/methods.md#metrics): mean relative error % and max error % of the
bounding-box diagonal; MRE is averaged over sources, the max is the max over
sources.

Writes bench/results/peers.json. Needs the peers: run scripts/setup.sh --bench
first.

    python bench/suite/compare_peers.py [--quick] [--only shared|sphere|lattice|sine]
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

FAST = ["meshfmm", "meshfmm_nounfold", "gc_fmm", "gc_heat", "igl_heat"]
EXACT = ["gdist", "igl_exact"]

# vertex-count caps for the exact methods on generated meshes (one call takes
# ~n^1.7: gdist 0.4 s and igl 1.6-3.4 s at 10k vertices on the 2-core machine)
GDIST_ALL_SOURCES_MAX = 12_000
GDIST_ONE_SOURCE_MAX = 45_000
GDIST_LARGEST = 260_000  # one source on the largest sphere and sine surface (~1-2 min each)
IGL_EXACT_MAX = 12_000


def now():
    return time.perf_counter()


class Peers:
    """Solvers of every method on one mesh (V, F compacted: no unreferenced vertices)."""

    def __init__(self, V, F):
        self.V, self.F = V, F
        self.F32 = F.astype(np.int32)
        self.F64 = F.astype(np.int64)
        self.setup = {}
        self.failed = {}
        self.solvers = {}

    def build(self, methods):
        import gdist  # noqa: F401
        import igl
        import potpourri3d as pp3d

        import meshfmm

        for m in methods:
            t0 = now()
            try:
                if m == "meshfmm":
                    mesh = meshfmm.Mesh(self.V, self.F32)
                    self.mesh = mesh
                    self.solvers[m] = lambda s: mesh.distance(int(s))
                elif m == "meshfmm_nounfold":
                    mesh = self.mesh
                    self.solvers[m] = lambda s: mesh.distance(int(s), unfolding=False)
                elif m == "gc_fmm":
                    fmm = pp3d.MeshFastMarchingDistanceSolver(self.V, self.F64)
                    self.solvers[m] = lambda s, fmm=fmm: fmm.compute_distance([[(int(s), [])]])
                elif m == "gc_heat":
                    heat = pp3d.MeshHeatMethodDistanceSolver(self.V, self.F64)
                    heat.compute_distance(0)  # the factorisations happen on the first solve
                    self.solvers[m] = lambda s, heat=heat: heat.compute_distance(int(s))
                elif m == "igl_heat":
                    data = igl.HeatGeodesicsData()
                    igl.heat_geodesics_precompute(self.V, self.F64, data)
                    self.solvers[m] = lambda s, data=data: igl.heat_geodesics_solve(
                        data, np.array([int(s)], dtype=np.int64))
                elif m == "gdist":
                    import gdist as gd

                    V, F32 = self.V, self.F32
                    self.solvers[m] = lambda s: gd.compute_gdist(
                        V, F32, source_indices=np.array([int(s)], dtype=np.int32))
                elif m == "igl_exact":
                    V, F64 = self.V, self.F64
                    allv = np.arange(V.shape[0], dtype=np.int64)
                    none = np.array([], dtype=np.int64)
                    self.solvers[m] = lambda s: igl.exact_geodesic(
                        V, F64, np.array([int(s)], dtype=np.int64), none, allv, none)
                if m == "meshfmm_nounfold":
                    self.setup[m] = self.setup["meshfmm"]
                else:
                    self.setup[m] = now() - t0
            except Exception as exc:  # a peer refusing a mesh is a result too
                self.failed[m] = f"{type(exc).__name__}: {exc}"[:200]

    def solve(self, m, s):
        d = np.asarray(self.solvers[m](s), dtype=np.float64).reshape(-1)
        return d


def run_case(case, rounds, exact_plan, log):
    """case: dict(family, name, V, F, sources, ref) where ref(s_index, s) -> e or None."""
    V0, F0 = case["V"], case["F"]
    V, F, old_of_new, new_of_old = bl.compact(V0, F0)
    diameter = bl.bbox_diagonal(V)
    sources = [int(s) for s in case["sources"]]  # ids in the compacted mesh
    methods = FAST + [m for m in EXACT if exact_plan.get(m)]
    peers = Peers(V, F)
    peers.build(methods)
    row = {
        "family": case["family"], "name": case["name"], "param": case.get("param"),
        "n_vertices": int(V.shape[0]), "n_faces": int(F.shape[0]),
        "n_obtuse_corners": None, "diameter": diameter,
        "sources": [int(old_of_new[s]) for s in sources],
        "reference": case["ref_kind"], "reference_method": case.get("ref_from"),
        "rounds": rounds, "methods": {},
    }
    if hasattr(peers, "mesh"):
        info = peers.mesh.info
        row["n_obtuse_corners"] = int(info.n_obtuse_corners)
        row["n_virtual_edges"] = int(info.n_virtual_edges)

    # references (analytic, stored, or computed by an exact method below)
    refs = {}
    for k, s in enumerate(sources):
        refs[k] = case["ref"](k, s, V, F)
    ref_time = case.get("ref_time")

    # exact methods: once per source (or on the first source only)
    results = {m: {} for m in methods}
    for m in EXACT:
        plan = exact_plan.get(m)
        if not plan or m in peers.failed:
            continue
        ks = list(range(len(sources))) if plan == "all" else [0]
        for k in ks:
            t0 = now()
            try:
                d = peers.solve(m, sources[k])
            except Exception as exc:
                peers.failed[m] = f"{type(exc).__name__}: {exc}"[:200]
                break
            results[m].setdefault("times", []).append(now() - t0)
            results[m].setdefault("d", {})[k] = d
            if refs[k] is None and case.get("ref_from") == m:
                refs[k] = d

    # fast methods: rounds of per-method blocks
    fast = [m for m in FAST if m not in peers.failed]
    for m in list(fast):  # warm up and keep the first result per source for the errors
        try:
            results[m]["d"] = {k: peers.solve(m, s) for k, s in enumerate(sources)}
        except Exception as exc:
            peers.failed[m] = f"{type(exc).__name__}: {exc}"[:200]
            fast.remove(m)
            continue
        results[m]["times"] = []
    for _ in range(rounds):
        for m in fast:
            for s in sources:
                t0 = now()
                peers.solve(m, s)
                results[m]["times"].append(now() - t0)

    for m in methods:
        out = {}
        if m in peers.failed:
            out["failed"] = peers.failed[m]
            row["methods"][m] = out
            continue
        r = results[m]
        out["setup_s"] = peers.setup.get(m)
        if r.get("times"):
            out["time_s"] = float(np.median(r["times"]))
            out["n_timed"] = len(r["times"])
        per = []
        for k, d in sorted(r.get("d", {}).items()):
            if refs.get(k) is None:
                continue
            per.append(bl.errors(d, refs[k], diameter))
        if per:
            out["per_source"] = per
            out["mre_pct"] = float(np.mean([p[0] for p in per]))
            out["max_pct"] = float(np.max([p[1] for p in per]))
            out["n_sources_err"] = len(per)
        row["methods"][m] = out
    if ref_time is not None:  # the stored igl.exact_geodesic timing (index.json)
        row["methods"].setdefault("igl_exact", {}).update(
            {"time_s": ref_time, "timing_from": "stored (tests/data/reference/index.json)"})
    row["reference_available"] = [k for k in range(len(sources)) if refs[k] is not None]
    if "check" in case:
        row["reference_check"] = case["check"](results)
    peers_txt = "  ".join(
        f"{m}={1e3 * row['methods'][m]['time_s']:.2f}ms"
        + (f"/{row['methods'][m]['mre_pct']:.3f}%" if "mre_pct" in row["methods"][m] else "")
        for m in methods if "time_s" in row["methods"].get(m, {}))
    log(f"{case['family']:<8}{case['name']:<22}{row['n_vertices']:>8}  {peers_txt}")
    for m, why in peers.failed.items():
        log(f"        {m} failed: {why}")
    if hasattr(peers, "mesh"):
        peers.mesh.close()
    return row


# ---------------------------------------------------------------- the cases
nearest = bl.nearest


def shared_cases(index, log):
    for name in bl.DATA_MESHES:
        path = bl.DATA / "meshes" / name
        if not path.is_file():
            log(f"missing {path}")
            continue
        V, F = bl.load_data(name)
        _, _, old_of_new, new_of_old = bl.compact(V, F)
        case = {"family": "shared", "name": name, "V": V, "F": F}
        if bl.reference_path(name).is_file():
            ref_sources, ref_distances = bl.load_reference(name)
            stored = ref_distances[:, old_of_new]
            case["sources"] = [int(new_of_old[s]) for s in ref_sources]
            case["ref"] = lambda k, s, V_, F_, stored=stored: stored[k]
            case["ref_kind"] = "igl.exact_geodesic (stored)"
            case["ref_time"] = index["meshes"][name]["seconds"]

            def check(results, stored=stored):  # gdist against the stored igl distances
                d = results.get("gdist", {}).get("d", {})
                if not d:
                    return None
                return float(max(np.max(np.abs(v - stored[k])[np.isfinite(stored[k])])
                                 for k, v in d.items()))
            case["check"] = check
        else:
            rng = np.random.default_rng(6)
            case["sources"] = [int(x) for x in rng.choice(old_of_new.size, 3, replace=False)]
            if name == "beetle.obj":  # non-manifold: no exact code runs on it
                case["ref"] = lambda k, s, V_, F_: None
                case["ref_kind"] = None
            else:  # igea: gdist from the first source (igl.exact_geodesic takes > 10 min)
                case["ref"] = lambda k, s, V_, F_: None
                case["ref_kind"] = "gdist (exact MMP), first source only"
                case["ref_from"] = "gdist"
        yield case


def plan_shared(name, nv):
    if name == "beetle.obj":
        return {}
    if name == "igea.ply":
        return {"gdist": "first"}
    return {"gdist": "all"}  # igl_exact: the stored reference and timing


def generated_cases(family, sizes, workdir):
    shape = {"sphere": "sphere", "lattice": "lattice", "sine": "sine"}[family]
    for n in sizes:
        V, F = bl.generate(shape, n, workdir)
        case = {"family": family, "name": f"{family} {n}", "param": n, "V": V, "F": F}
        if family == "sphere":
            dirs = np.array([[0.3, 0.5, 0.81], [-0.7, 0.1, -0.2], [0.05, -0.9, 0.4]])
            dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
            case["sources"] = nearest(V, dirs)
            case["ref"] = lambda k, s, V_, F_: bl.sphere_distance(V_, s)
            case["ref_kind"] = "great-circle distance (analytic)"
        elif family == "lattice":
            lo, hi = V.min(axis=0), V.max(axis=0)
            case["sources"] = nearest(V, [lo + f * (hi - lo) for f in
                                          (np.array([0.5, 0.5, 0]), np.array([0.23, 0.31, 0]),
                                           np.array([0.71, 0.77, 0]))])
            # Euclidean distance is the geodesic one inside the largest rectangle
            # the zig-zag side boundaries enclose; the few vertices on the
            # outer zig-zag are left out of the errors
            rows = np.round(V[:, 1] / (hi[1] - lo[1] + 1e-300) * 1e9)
            xmin = max(V[rows == r, 0].min() for r in np.unique(rows))
            xmax = min(V[rows == r, 0].max() for r in np.unique(rows))
            inside = (V[:, 0] >= xmin - 1e-12) & (V[:, 0] <= xmax + 1e-12)

            def ref(k, s, V_, F_, inside=inside):
                e = bl.plane_distance(V_, s)
                e[~inside] = np.nan
                return e
            case["ref"] = ref
            case["ref_kind"] = "Euclidean distance (analytic; zig-zag side vertices excluded)"
        else:  # sine surface z = 0.45 sin(2 pi x) sin(2 pi y)
            case["sources"] = nearest(V[:, :2], [np.array(p) for p in
                                                 ([0.5, 0.5], [0.23, 0.31], [0.71, 0.77])])
            if V.shape[0] <= IGL_EXACT_MAX:
                case["ref"] = lambda k, s, V_, F_: None
                case["ref_kind"] = "igl.exact_geodesic (run here)"
                case["ref_from"] = "igl_exact"
            elif V.shape[0] <= GDIST_ONE_SOURCE_MAX:
                case["ref"] = lambda k, s, V_, F_: None
                case["ref_kind"] = "gdist (exact MMP), all sources"
                case["ref_from"] = "gdist"
            elif V.shape[0] <= GDIST_LARGEST:
                case["ref"] = lambda k, s, V_, F_: None
                case["ref_kind"] = "gdist (exact MMP), first source only"
                case["ref_from"] = "gdist"
            else:
                case["ref"] = lambda k, s, V_, F_: None
                case["ref_kind"] = None
        yield case


def plan_generated(family, nv):
    plan = {}
    if nv <= GDIST_ALL_SOURCES_MAX:
        plan["gdist"] = "all"
    elif nv <= GDIST_ONE_SOURCE_MAX:
        plan["gdist"] = "all" if family == "sine" else "first"
    elif nv <= GDIST_LARGEST and family != "lattice":
        plan["gdist"] = "first"
    if nv <= IGL_EXACT_MAX and family != "lattice":
        plan["igl_exact"] = "all" if family == "sine" else "first"
    return plan


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", nargs="*", default=["shared", "sphere", "lattice", "sine"])
    ap.add_argument("--quick", action="store_true", help="small sizes only (a smoke test)")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("-o", default=str(bl.RESULTS / "peers.json"))
    args = ap.parse_args()

    def log(msg):
        print(msg, flush=True)

    sizes = {"sphere": [4, 5, 6, 7], "lattice": [50, 100, 200, 400], "sine": [50, 100, 200, 500]}
    if args.quick:
        sizes = {"sphere": [3, 4], "lattice": [20, 40], "sine": [20, 40]}
    index = json.loads((bl.DATA / "reference" / "index.json").read_text())
    t_start = now()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for fam in args.only:
            if fam == "shared":
                for case in shared_cases(index, log):
                    if args.quick and case["V"].shape[0] > 6000:
                        continue
                    rounds = args.rounds + 2 if case["V"].shape[0] < 20000 else args.rounds
                    rows.append(run_case(case, rounds, plan_shared(case["name"], 0), log))
            else:
                for case in generated_cases(fam, sizes[fam], tmp):
                    nv = case["V"].shape[0]
                    rounds = args.rounds + 2 if nv < 20000 else args.rounds
                    rows.append(run_case(case, rounds, plan_generated(fam, nv), log))
    doc = {
        "what": "per-source geodesic distance: accuracy and median time per source",
        "machine": bl.machine_info(),
        "versions": bl.versions(),
        "metrics": {
            "mre_pct": "100/N sum |d-e|/e over vertices with finite e > 0; mean over sources",
            "max_pct": "100 max |d-e| / bounding-box diagonal; max over sources",
        },
        "methods": {
            "meshfmm": "meshfmm Mesh.distance (unfolding on)",
            "meshfmm_nounfold": "meshfmm Mesh.distance(unfolding=False)",
            "gc_fmm": "potpourri3d.MeshFastMarchingDistanceSolver (geometry-central)",
            "gc_heat": "potpourri3d.MeshHeatMethodDistanceSolver, after precompute",
            "igl_heat": "igl.heat_geodesics_precompute/solve (default t), after precompute",
            "gdist": "gdist.compute_gdist (exact MMP)",
            "igl_exact": "igl.exact_geodesic (exact MMP)",
        },
        "timing": "median seconds per source; fast methods over rounds of per-method blocks, "
                  "exact methods one call per source; setup_s = mesh build / precompute",
        "cases": rows,
        "total_s": now() - t_start,
    }
    out = Path(args.o)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(doc, indent=1) + "\n")
    log(f"written {out} ({doc['total_s']:.0f} s)")


if __name__ == "__main__":
    main()
