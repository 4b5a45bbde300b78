#!/usr/bin/env python3
"""What Voronoi labels and isolines cost after the solve: on each mesh, one
default single-source solve; Voronoi labels of 8 sources
(``Mesh.voronoi_labels`` given the distances: one pass over the vertices'
edges in C) against the 8-source solve they follow; isolines at 10 values
(``Mesh.isolines``: in C, ``mfmm_isolines``, one pass over the faces for all
values, the crossing points of the faces found and joined into polylines;
then Python's Isoline objects. The C call alone, its arrays copied out, is
timed apart) against one numpy pass over the faces (each face's three
corner values gathered, their min and max). The claim measured: each
costs at most about one extra pass over the faces after the solve.

Writes bench/results/workflows.json. Not a test: timings on a shared
machine are noisy; the best of a few rounds is reported.

    python bench/suite/bench_workflows.py [--meshes camelhead.off nefertiti-lowres.obj]
                                          [--rounds 7]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/
from benchlib import RESULTS, best_of, load_data, machine_info, versions  # noqa: E402


def face_pass(d: np.ndarray, F: np.ndarray):
    """One numpy pass over the faces: the three corner values of every
    face, and each face's min and max (what deciding which faces a level
    crosses needs). Elementwise over the three columns: numpy's
    ``min(axis=1)`` over rows of 3 takes about 10x as long."""
    dF = d[F]
    a, b, c = dF[:, 0], dF[:, 1], dF[:, 2]
    return np.minimum(np.minimum(a, b), c), np.maximum(np.maximum(a, b), c)


def bench_mesh(name: str, rounds: int) -> dict:
    import meshfmm

    V, F = load_data(name)
    mesh = meshfmm.Mesh(V, F)
    nv, nf = mesh.n_vertices, mesh.n_faces
    mesh.distance(0)  # the first solve builds the spokes and exact tables
    r = {"mesh": name, "n_vertices": nv, "n_faces": nf}

    r["solve_1_s"], d1 = best_of(rounds, lambda: mesh.distance(0))
    sources = [int(s) for s in mesh.farthest_point_sampling(8, 0)]  # well spread
    r["sources"] = sources
    r["solve_8_s"], d8 = best_of(rounds, lambda: mesh.distance(sources))
    r["voronoi_labels_s"], labels = best_of(rounds, lambda: mesh.voronoi_labels(sources, d8))
    r["voronoi_with_solve_s"], _ = best_of(rounds, lambda: mesh.voronoi_labels(sources))
    r["voronoi_cells"] = int(np.unique(labels[labels >= 0]).size)

    Fi = np.asarray(mesh.faces)
    r["face_pass_s"], _ = best_of(rounds, lambda: face_pass(d1, Fi))
    finite = d1[np.isfinite(d1)]
    values = finite.max() * np.arange(1, 11) / 11.0
    r["isolines_10_s"], lines = best_of(rounds, lambda: mesh.isolines(d1, values))
    r["isolines_c_10_s"], (pts, polys) = best_of(
        rounds, lambda: mesh._isoline_records(d1, values))
    r["isoline_segments"] = int(pts.shape[0] - polys.shape[0])
    r["isolines_polylines"] = int(sum(len(x) for x in lines))
    r["isolines_points"] = int(sum(len(ln) for x in lines for ln in x))

    r["voronoi_over_solve_8"] = r["voronoi_labels_s"] / r["solve_8_s"]
    r["voronoi_over_face_pass"] = r["voronoi_labels_s"] / r["face_pass_s"]
    r["isolines_10_over_face_pass"] = r["isolines_10_s"] / r["face_pass_s"]
    r["isolines_per_value_over_face_pass"] = r["isolines_10_over_face_pass"] / 10
    r["isolines_10_over_solve_1"] = r["isolines_10_s"] / r["solve_1_s"]
    r["isolines_c_10_over_face_pass"] = r["isolines_c_10_s"] / r["face_pass_s"]
    r["face_pass_over_solve_1"] = r["face_pass_s"] / r["solve_1_s"]
    return r


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--meshes", nargs="+", default=["camelhead.off", "nefertiti-lowres.obj"])
    ap.add_argument("--rounds", type=int, default=7)
    a = ap.parse_args()

    res = {"rounds": a.rounds, "versions": versions(), "machine": machine_info(),
           "meshes": [bench_mesh(m, a.rounds) for m in a.meshes]}
    out = RESULTS / "workflows.json"
    out.write_text(json.dumps(res, indent=2) + "\n")

    def ms(x):
        return f"{1e3 * x:8.2f}"

    print(f"{'mesh':22s} {'vertices':>8s} {'faces':>8s}   times in ms (best of {a.rounds})")
    for r in res["meshes"]:
        print(f"{r['mesh']:22s} {r['n_vertices']:8d} {r['n_faces']:8d}")
        print(f"  solve, 1 source          {ms(r['solve_1_s'])}")
        print(f"  solve, 8 sources         {ms(r['solve_8_s'])}")
        print(f"  Voronoi labels, 8        {ms(r['voronoi_labels_s'])}   "
              f"{r['voronoi_over_solve_8']:.3f} x the 8-source solve, "
              f"{r['voronoi_over_face_pass']:.2f} x a face pass")
        print(f"  one numpy face pass      {ms(r['face_pass_s'])}   "
              f"{r['face_pass_over_solve_1']:.3f} x the 1-source solve")
        print(f"  isolines, 10 values      {ms(r['isolines_10_s'])}   "
              f"{r['isolines_10_over_face_pass']:.2f} x a face pass "
              f"({r['isolines_per_value_over_face_pass']:.2f} per value), "
              f"{r['isolines_10_over_solve_1']:.3f} x the 1-source solve; "
              f"{r['isolines_polylines']} polylines")
        print(f"    of which the C call    {ms(r['isolines_c_10_s'])}   "
              f"{r['isolines_c_10_over_face_pass']:.2f} x a face pass; "
              f"{r['isoline_segments']} segments (the rest: Isoline objects, in Python)")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
