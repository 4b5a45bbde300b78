"""Path-tracing sweep: does every traced path end at its source, and does
none stall?

Study, 2026-11-27: on the 8 manifold meshes (4,800 default calls, 4,800 with
the sources, 1,600 face-to-face pairs; about 7 s) no path ends elsewhere, none
raises and none stalls. tests/python/test_path.py runs a reduced form of it.

For each mesh of tests/data/reference/index.json (the 8 manifold meshes with
stored sources), for each of its 3 reference sources, 200 random target
vertices (fixed seed):
  - the default call  ``geodesic_path(d, t)``        (no sources given)
  - with the sources  ``geodesic_path(d, t, sources=[s])``
A default call must end at the source vertex or raise; one that returns a
path ending elsewhere is a *wrong ending* (silent). A call with sources must
not raise (a *failure*). Then 200 random face-to-face pairs per mesh (random
face, random barycentric point; fixed seed): d = distance(SurfacePoint) and
``geodesic_path(d, SurfacePoint, sources=[src])``; a raise is a *stall*, a
path not ending at the source point a wrong ending.

Usage (development build):
  MESHFMM_LIBRARY=build/libmeshfmm.so PYTHONPATH=bindings/python \\
      python bench/studies/sweep_paths.py [--targets 200] [--pairs 200] [--meshes a.obj,b.off]
Prints one line per mesh and the totals; exit status 1 when anything failed.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

import meshfmm

DATA = Path(__file__).resolve().parents[2] / "tests" / "data"
SEED = 20260509


def mean_edge(V: np.ndarray, F: np.ndarray) -> float:
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    return float(np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1).mean())


def random_point(rng: np.random.Generator, nf: int) -> meshfmm.SurfacePoint:
    b = rng.dirichlet((1.0, 1.0, 1.0))
    return meshfmm.SurfacePoint(int(rng.integers(nf)), tuple(float(x) for x in b))


def sweep_mesh(name: str, sources, n_targets: int, n_pairs: int, verbose: bool) -> dict:
    V, F = meshfmm.load_mesh(str(DATA / "meshes" / name))
    m = meshfmm.Mesh(V, F)
    tol = 1e-9 * mean_edge(V, F)
    rng = np.random.default_rng(SEED)
    r = dict(default_wrong=0, default_raised=0, default_n=0, given_failed=0, given_wrong=0,
             given_n=0, pair_stalled=0, pair_wrong=0, pair_n=0)
    for s in sources:
        s = int(s)
        d = m.distance(s)
        reached = np.flatnonzero(np.isfinite(d) & (d > 0))
        targets = rng.choice(reached, min(n_targets, reached.size), replace=False)
        for t in targets:
            t = int(t)
            r["default_n"] += 1
            try:
                p = m.geodesic_path(d, t)
                if np.linalg.norm(p.points[-1] - V[s]) > tol:
                    r["default_wrong"] += 1
                    if verbose:
                        print(f"  {name} default {s}->{t}: ends at {p.points[-1]} "
                              f"(face {p.faces[-1]}), length {p.length:.4g}, T {d[t]:.4g}")
            except (RuntimeError, ValueError) as e:
                r["default_raised"] += 1
                if verbose:
                    print(f"  {name} default {s}->{t}: raised {e}")
            r["given_n"] += 1
            try:
                p = m.geodesic_path(d, t, sources=[s])
                if np.linalg.norm(p.points[-1] - V[s]) > tol:
                    r["given_wrong"] += 1
                    if verbose:
                        print(f"  {name} sources {s}->{t}: ends at {p.points[-1]}")
            except (RuntimeError, ValueError) as e:
                r["given_failed"] += 1
                if verbose:
                    print(f"  {name} sources {s}->{t}: {e}")
    nf = F.shape[0]
    for _ in range(n_pairs):
        src, tgt = random_point(rng, nf), random_point(rng, nf)
        d = m.distance(src)
        xs = np.asarray(src.bary) @ V[F[src.face]]
        r["pair_n"] += 1
        try:
            p = m.geodesic_path(d, tgt, sources=[src])
            if np.linalg.norm(p.points[-1] - xs) > tol:
                r["pair_wrong"] += 1
                if verbose:
                    print(f"  {name} pair {src} -> {tgt}: ends at {p.points[-1]}")
        except (RuntimeError, ValueError) as e:
            r["pair_stalled"] += 1
            if verbose:
                print(f"  {name} pair {src} -> {tgt}: {e}")
    return r


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--targets", type=int, default=200)
    ap.add_argument("--pairs", type=int, default=200)
    ap.add_argument("--meshes", default="", help="comma-separated subset")
    ap.add_argument("-v", "--verbose", action="store_true", help="print every failure")
    a = ap.parse_args()
    index = json.loads((DATA / "reference" / "index.json").read_text())["meshes"]
    names = [n for n in index if not a.meshes or n in a.meshes.split(",")]
    tot: dict = {}
    print(f"{'mesh':24s} default: wrong/raised/n   sources: failed/wrong/n   "
          f"face pairs: stalled/wrong/n")
    for name in names:
        r = sweep_mesh(name, index[name]["sources"], a.targets, a.pairs, a.verbose)
        for k, v in r.items():
            tot[k] = tot.get(k, 0) + v
        print(f"{name:24s} {r['default_wrong']:5d} {r['default_raised']:5d} {r['default_n']:5d}"
              f"   {r['given_failed']:12d} {r['given_wrong']:5d} {r['given_n']:5d}"
              f"   {r['pair_stalled']:14d} {r['pair_wrong']:5d} {r['pair_n']:5d}", flush=True)
    r = tot
    print(f"{'total':24s} {r['default_wrong']:5d} {r['default_raised']:5d} {r['default_n']:5d}"
          f"   {r['given_failed']:12d} {r['given_wrong']:5d} {r['given_n']:5d}"
          f"   {r['pair_stalled']:14d} {r['pair_wrong']:5d} {r['pair_n']:5d}")
    bad = r["default_wrong"] + r["given_failed"] + r["given_wrong"] + r["pair_stalled"] + r["pair_wrong"]
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
