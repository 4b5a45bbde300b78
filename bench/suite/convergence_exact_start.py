#!/usr/bin/env python3
"""Convergence with and without the exact start, and of the window
method (method="windows") beside them: mean relative error and fitted order
on icospheres (levels 4-7, source at an icosahedron
vertex, great-circle distance) and on the obtuse lattice (x stretched 3x,
n = 20..160, source nearest (1.5, 0.43), Euclidean distance), the meshes and
sources of tests/c/test_convergence.c. Writes bench/results/convergence.json.

    python bench/suite/convergence_exact_start.py
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/
import benchlib as bl  # noqa: E402

import meshfmm  # noqa: E402


mre = bl.mean_rel_error


def order(h, err):
    return float(np.polyfit(np.log(h), np.log(err), 1)[0])


def main():
    runs = {"plain": {"exact_start": 0.0}, "exact start (default)": {},
            "windows": {"method": "windows"}}
    out = {"what": __doc__.split("\n\n")[0], "machine": bl.machine_info(), "families": []}
    with tempfile.TemporaryDirectory() as wd:
        fams = [("icosphere", [4, 5, 6, 7], "sphere"), ("obtuse lattice", [20, 40, 80, 160], "lattice")]
        for fam, sizes, shape in fams:
            rows = []
            for n in sizes:
                V, F = bl.generate(shape, n, wd)
                m = meshfmm.Mesh(V, F)
                if shape == "sphere":
                    s = 0
                    e = bl.sphere_distance(V, s)
                    h = 1 / np.sqrt(len(V))
                else:
                    s = int(np.argmin(np.linalg.norm(V - np.array([1.5, 0.43, 0.0]), axis=1)))
                    e = bl.plane_distance(V, s)
                    h = 1 / n
                row = {"n": n, "n_vertices": len(V), "h": h}
                for label, kw in runs.items():
                    row[label] = mre(m.distance(s, **kw), e)
                rows.append(row)
                print(fam, n, len(V), {k: round(row[k], 4) for k in runs}, flush=True)
            # an error at rounding level (windows on the flat lattice) has no order
            orders = {k: order([r["h"] for r in rows], [r[k] for r in rows])
                      if min(r[k] for r in rows) > 1e-9 else None for k in runs}
            out["families"].append({"family": fam, "rows": rows, "order": orders})
            print(fam, "order", orders)
    path = bl.RESULTS / "convergence.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print("wrote", path)


if __name__ == "__main__":
    main()
