#!/usr/bin/env python3
"""The paper's Fig. 8b and Fig. 10, redrawn with meshfmm:

- Fig. 8b: a box whose three visible sides carry the costs F = 2 (the near side,
  with the source), 1 (the top) and 4 (the side with the destinations); the
  minimal weighted paths bend where they cross an edge, by Snell's law
  (F1 sin a1 = F2 sin a2, angles from the edge's normal), which the figure checks
  numerically. -> docs/images/fig8b_snell_polyhedron.png
- Fig. 10: distance isolines and minimal geodesics on a head
  (tests/data/meshes/decimated-max.obj, the Max Planck head with very skinny
  triangles). -> docs/images/fig10_head_paths.png

Both are drawn with bench/figures/render.py (a z-buffer, so hidden curves stay hidden).
Writes bench/results/figures.json (the Snell check and the path lengths).

    python bench/figures/figures_cost_head.py
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/
import benchlib as bl  # noqa: E402
import render  # noqa: E402

import meshfmm  # noqa: E402


# ---------------------------------------------------------------- Fig. 8b
def box_mesh(size=(1.0, 1.0, 1.0), n=48):
    """The surface of [0,a]x[0,b]x[0,c]: each side an n-per-unit grid of squares
    split along alternating diagonals; vertices on the edges shared."""
    a, b, c = size
    pts, tris = [], []

    def side(origin, u, v, nu, nv):
        base = sum(len(p) for p in pts)
        i, j = np.meshgrid(np.arange(nu + 1), np.arange(nv + 1), indexing="ij")
        P = origin + (i / nu).reshape(-1, 1) * u + (j / nv).reshape(-1, 1) * v
        pts.append(P)
        for ii in range(nu):
            for jj in range(nv):
                p00 = base + ii * (nv + 1) + jj
                p10, p01, p11 = p00 + nv + 1, p00 + 1, p00 + nv + 2
                if (ii + jj) % 2 == 0:
                    tris.extend([(p00, p10, p11), (p00, p11, p01)])
                else:
                    tris.extend([(p00, p10, p01), (p10, p11, p01)])

    na, nb, nc = (max(1, int(round(n * s))) for s in (a, b, c))
    O = np.zeros(3)
    X, Y, Z = np.array([a, 0, 0]), np.array([0, b, 0]), np.array([0, 0, c])
    side(O, X, Z, na, nc)          # y = 0 (front)
    side(O + Y, Z, X, nc, na)      # y = b (back)
    side(O, Z, Y, nc, nb)          # x = 0 (left)
    side(O + X, Y, Z, nb, nc)      # x = a (right)
    side(O, Y, X, nb, na)          # z = 0 (bottom)
    side(O + Z, X, Y, na, nb)      # z = c (top)
    P = np.vstack(pts)
    key = np.round(P * 1e9).astype(np.int64)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    V = P[first]
    F = inv.reshape(-1)[np.array(tris)].astype(np.int32)
    # orient outwards
    cen = V.mean(axis=0)
    nrm = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    flip = np.einsum("ij,ij->i", nrm, V[F].mean(axis=1) - cen) < 0
    F[flip] = F[flip][:, ::-1]
    return V, F


def fig8b(out: Path, record: dict) -> Path:
    a, b, c = 1.0, 1.0, 0.8
    V, F = box_mesh((a, b, c), n=50)
    C = V[F].mean(axis=1)
    eps = 1e-9
    side = np.full(len(F), "hidden", dtype=object)
    side[np.abs(C[:, 1]) < eps] = "front"
    side[np.abs(C[:, 2] - c) < eps] = "top"
    side[np.abs(C[:, 0] - a) < eps] = "right"
    costs = {"front": 2.0, "top": 1.0, "right": 4.0, "hidden": 8.0}  # hidden sides: dear, so no path uses them
    cost = np.array([costs[s] for s in side])
    mesh = meshfmm.Mesh(V, F)
    src = int(np.argmin(np.linalg.norm(V - np.array([0.22, 0.0, 0.28]), axis=1)))
    T = mesh.distance(src, cost=cost)
    targets_xyz = [(a, y, z) for y, z in [(0.2, 0.2), (0.45, 0.15), (0.7, 0.12), (0.9, 0.3),
                                          (0.6, 0.45), (0.35, 0.5), (0.85, 0.6), (0.15, 0.55)]]
    targets = [int(np.argmin(np.linalg.norm(V - np.array(p), axis=1))) for p in targets_xyz]
    paths = [mesh.geodesic_path(T, t, sources=[src], cost=cost) for t in targets]

    # Snell's law at the crossings: F * (unit direction . edge tangent) is conserved
    def crossings(P):
        out = []
        sides = []
        for q in P:
            s = ("front" if abs(q[1]) < 1e-7 else "top" if abs(q[2] - c) < 1e-7
                 else "right" if abs(q[0] - a) < 1e-7 else "hidden")
            sides.append(s)
        # walk from the target: successive runs on one side
        runs = []
        for i, s in enumerate(sides):
            if not runs or runs[-1][0] != s:
                runs.append([s, [i]])
            else:
                runs[-1][1].append(i)
        for (s1, i1), (s2, i2) in zip(runs, runs[1:]):
            tang = {frozenset(("front", "top")): np.array([1.0, 0, 0]),
                    frozenset(("top", "right")): np.array([0, 1.0, 0]),
                    frozenset(("front", "right")): np.array([0, 0, 1.0])}.get(frozenset((s1, s2)))
            if tang is None or len(i1) < 3 or len(i2) < 3:
                continue
            # directions of chords of ~0.08 length on each side of the edge
            p_edge = P[i2[0]]

            def chord(idx, toward_edge_last):
                pts = P[idx]
                dist = np.linalg.norm(pts - p_edge, axis=1)
                far = pts[np.argmin(np.abs(dist - 0.08))]
                d = (p_edge - far) if toward_edge_last else (far - p_edge)
                return d / np.linalg.norm(d)
            d1 = chord(i1, True)
            d2 = chord(i2, False)
            out.append({"from": s1, "to": s2,
                        "F1_cos": costs[s1] * abs(d1 @ tang), "F2_cos": costs[s2] * abs(d2 @ tang)})
        return out

    snell = [crossings(p.points) for p in paths]
    used = sorted({str(side[f]) for p in paths for f in p.faces if f >= 0})
    record["fig8b"] = {
        "mesh": {"n_vertices": int(V.shape[0]), "n_faces": int(F.shape[0]), "box": [a, b, c]},
        "costs": costs, "source_xyz": V[src].tolist(),
        "paths": [{"target_xyz": V[t].tolist(), "T": float(T[t]),
                   "weighted_length": p.weighted_length, "length": p.length}
                  for t, p in zip(targets, paths)],
        "snell": snell, "sides_crossed": used,
    }

    # draw
    base = {"front": np.array([0.95, 0.80, 0.55]), "top": np.array([0.70, 0.88, 0.70]),
            "right": np.array([0.72, 0.78, 0.95]), "hidden": np.array([0.8, 0.8, 0.8])}
    face_rgb = np.array([base[s] for s in side])
    cam = render.Camera(V, -55, 28, width=820)
    img = cam.render(V, F, face_rgb=face_rgb, light=(-0.2, 0.5, 1.0), ambient=0.6)
    fig, ax = plt.subplots(figsize=(8.2, 7.2))
    ax.imshow(img, interpolation="bilinear")
    levels = np.linspace(0, np.nanmax(T[np.isfinite(T)]), 30)[1:]
    iso = [s for g in render.isoline_segments(V, F, T, levels) for s in cam.visible_segments(g)]
    ax.add_collection(LineCollection(iso, colors="0.35", linewidths=0.6))
    for p in paths:
        ax.add_collection(LineCollection(cam.visible_segments(p.points), colors="crimson",
                                         linewidths=2.0))
    sxy, _ = cam.project(V[[src]])
    ax.plot(*sxy[0], "o", ms=9, mfc="white", mec="k")
    txy, _ = cam.project(V[targets])
    ax.plot(txy[:, 0], txy[:, 1], "s", ms=5, mfc="crimson", mec="k")
    for s, pos in (("front", (0.5, 0.0, 0.06)), ("top", (0.5, 0.5, c)), ("right", (a, 0.5, 0.06))):
        xy, _ = cam.project(np.array([pos]))
        ax.text(*xy[0], f"F = {costs[s]:g}", ha="center", va="center", fontsize=13,
                fontweight="bold", color="k",
                bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.7))
    ratios = [x["F2_cos"] / x["F1_cos"] for s in snell for x in s if x["F1_cos"] > 0.05]
    ax.set_title("Paper Fig. 8b: weighted geodesics on a box, cost F = 2 (source side), 1 (top), "
                 "4 (targets' side)\nthey bend at the edges by Snell's law: "
                 f"F2 sin a2 / F1 sin a1 = {np.mean(ratios):.3f} ± {np.std(ratios):.3f} "
                 f"over {len(ratios)} crossings", fontsize=10)
    ax.set_axis_off()
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)
    record["fig8b"]["snell_ratio_mean"] = float(np.mean(ratios))
    record["fig8b"]["snell_ratio_std"] = float(np.std(ratios))
    return out


# ---------------------------------------------------------------- Fig. 10
def fig10(out: Path, record: dict) -> Path:
    name = "decimated-max.obj"
    V, F = bl.load_data(name)
    mesh = meshfmm.Mesh(V, F)
    # the face looks towards -z, y is up
    src = int(np.argmin(V[:, 2]))  # the tip of the nose
    T = mesh.distance(src)
    lo, hi = V.min(axis=0), V.max(axis=0)
    mid = (lo + hi) / 2

    def near(p):
        return int(np.argmin(np.linalg.norm(V - p, axis=1)))
    targets = [near(np.array(p)) for p in [
        (mid[0], hi[1], mid[2]),                 # crown
        (lo[0], mid[1] + 30, mid[2] + 20),       # one ear
        (hi[0], mid[1] + 30, mid[2] + 20),       # the other
        (mid[0], mid[1] + 40, hi[2]),            # back of the head
        (mid[0] - 60, mid[1] + 90, mid[2] - 10),
        (mid[0] + 60, mid[1] + 90, mid[2] - 10),
        (mid[0], mid[1] - 60, lo[2]),            # chin
        (mid[0] - 50, lo[1] + 40, mid[2]),       # neck
        (mid[0] + 50, lo[1] + 40, mid[2]),
        (mid[0] + 75, mid[1] - 20, mid[2] + 60),
        (mid[0] - 75, mid[1] - 20, mid[2] + 60),
    ]]
    paths = [mesh.geodesic_path(T, t, sources=[src]) for t in targets]
    record["fig10"] = {"mesh": name, "source": src, "n_vertices": int(V.shape[0]),
                       "paths": [{"target": int(t), "T": float(T[t]), "length": p.length,
                                  "n_points": int(len(p.points))}
                                 for t, p in zip(targets, paths)]}
    levels = np.linspace(0, np.nanmax(T), 26)[1:]
    iso3d = render.isoline_segments(V, F, T, levels)
    base = plt.get_cmap("YlGnBu_r")

    def cmap(x):  # the lighter part of the map, so that the paths and isolines stand out
        return base(0.3 + 0.7 * np.asarray(x))
    fig, axs = plt.subplots(1, 2, figsize=(12, 6.6))
    for ax, azim in zip(axs, (60, 205)):
        cam = render.Camera(V, azim, 12, width=620, up=(0, 1, 0))
        img = cam.render(V, F, vertex_values=T, cmap=cmap, vmax=np.nanmax(T),
                         light=(0.2, 0.5, 1.0), ambient=0.3)
        ax.imshow(img, interpolation="bilinear")
        iso = [s for g in iso3d for s in cam.visible_segments(g)]
        ax.add_collection(LineCollection(iso, colors="k", linewidths=0.45, alpha=0.8))
        for p in paths:
            ax.add_collection(LineCollection(cam.visible_segments(p.points), colors="red",
                                             linewidths=1.8))
        vis_t = [t for t in targets if cam.visible(V[[t]])[0]]
        txy, _ = cam.project(V[vis_t])
        ax.plot(txy[:, 0], txy[:, 1], "s", ms=4, mfc="red", mec="k", mew=0.6)
        if cam.visible(V[[src]])[0]:
            sxy, _ = cam.project(V[[src]])
            ax.plot(*sxy[0], "o", ms=7, mfc="white", mec="k")
        ax.set_axis_off()
    fig.suptitle("Paper Fig. 10 on the Max Planck head (decimated-max.obj, 5,272 vertices, 49% "
                 "obtuse triangles):\ndistance isolines from the tip of the nose and minimal "
                 "geodesics (red)", fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return out


def main():
    bl.IMAGES.mkdir(parents=True, exist_ok=True)
    record = {"machine": bl.machine_info(), "versions": bl.versions()}
    print(fig8b(bl.IMAGES / "fig8b_snell_polyhedron.png", record))
    print(fig10(bl.IMAGES / "fig10_head_paths.png", record))
    out = bl.RESULTS / "figures.json"
    out.write_text(json.dumps(record, indent=1) + "\n")
    print(out)


if __name__ == "__main__":
    main()
