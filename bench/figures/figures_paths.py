"""Pictures of minimal geodesics (paper section 5): Fig. 8a (the surface
z = 0.45 sin(2 pi x) sin(2 pi y), 50x50 grid, distance isolines and paths, in 3D
and projected to the xy plane) and Fig. 9 (a torus with equidistance curves and
paths, some through the hole). Writes docs/images/fig8a_sine_paths.png and
docs/images/fig9_torus_paths.png.

    MESHFMM_LIBRARY=build/libmeshfmm.so PYTHONPATH=bindings/python \
        python bench/figures/figures_paths.py
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection  # noqa: E402

import meshfmm  # noqa: E402

OUT = Path(__file__).resolve().parents[2] / "docs" / "images"


def grid_faces(nu: int, nv: int, wrap_u: bool, wrap_v: bool) -> np.ndarray:
    """Quads of an (nu x nv) vertex grid split in two along alternating diagonals."""
    faces = []
    cu = nu if wrap_u else nu - 1
    cv = nv if wrap_v else nv - 1
    for i in range(cu):
        for j in range(cv):
            a, b = i * nv + j, ((i + 1) % nu) * nv + j
            c, d = ((i + 1) % nu) * nv + (j + 1) % nv, i * nv + (j + 1) % nv
            if (i + j) % 2 == 0:
                faces += [(a, b, c), (a, c, d)]
            else:
                faces += [(a, b, d), (b, c, d)]
    return np.array(faces, dtype=np.int32)


def isolines(V: np.ndarray, F: np.ndarray, T: np.ndarray, levels) -> list:
    """Segments of the level sets of the piecewise linear T, per face."""
    segs = []
    for lv in levels:
        t = T[F] - lv
        for f in np.flatnonzero((t.min(axis=1) < 0) & (t.max(axis=1) >= 0)):
            pts = []
            for k in range(3):
                a, b = k, (k + 1) % 3
                ta, tb = t[f, a], t[f, b]
                if (ta < 0) != (tb < 0):
                    w = ta / (ta - tb)
                    pts.append((1 - w) * V[F[f, a]] + w * V[F[f, b]])
            if len(pts) == 2:
                segs.append(pts)
    return segs


def shaded(ax, V, F, T, cmap="viridis", alpha=1.0):
    tri = V[F]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True) + 1e-300
    light = np.array([0.3, -0.5, 0.8])
    light /= np.linalg.norm(light)
    shade = 0.55 + 0.45 * np.abs(n @ light)
    tf = T[F].mean(axis=1)
    col = plt.get_cmap(cmap)(tf / np.nanmax(tf[np.isfinite(tf)]))
    col[:, :3] *= shade[:, None]
    col[:, 3] = alpha
    ax.add_collection3d(Poly3DCollection(tri, facecolors=col, edgecolors="none", linewidths=0,
                                         zorder=1))


def fig8a() -> Path:
    n = 51  # 50 x 50 squares
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n), indexing="ij")
    z = 0.45 * np.sin(2 * np.pi * x) * np.sin(2 * np.pi * y)
    V = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    F = grid_faces(n, n, False, False)
    mesh = meshfmm.Mesh(V, F)
    src = 25 * n + 25  # (0.5, 0.5)
    T = mesh.distance(src)
    ring = [(0, 10), (0, 40), (10, 50), (40, 50), (50, 40), (50, 10), (40, 0), (10, 0),
            (0, 25), (25, 50), (50, 25), (25, 0), (8, 8), (42, 42)]
    paths = [mesh.geodesic_path(T, i * n + j, sources=[src]) for i, j in ring]
    levels = np.linspace(0, np.nanmax(T), 16)[1:]

    fig = plt.figure(figsize=(13, 6))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    shaded(ax, V, F, T, alpha=0.9)
    lift = np.array([0, 0, 0.004])
    ax.add_collection3d(Line3DCollection([np.array(s) + lift for s in isolines(V, F, T, levels)],
                                         colors="k", linewidths=0.5))
    for p in paths:
        ax.plot(*(p.points + 2 * lift).T, color="red", lw=1.6, zorder=10)
    ax.scatter(*V[src], color="white", edgecolor="k", s=40, zorder=11)
    ax.set_xlim(0, 1), ax.set_ylim(0, 1), ax.set_zlim(-0.6, 0.6)
    ax.set_box_aspect((1, 1, 0.55))
    ax.view_init(elev=38, azim=-58)
    ax.set_title("minimal geodesics on z = 0.45 sin(2πx) sin(2πy), 50×50 grid")
    ax2 = fig.add_subplot(1, 2, 2)
    ax2.tricontour(V[:, 0], V[:, 1], F, T, levels=levels, colors="0.45", linewidths=0.7)
    ax2.tricontourf(V[:, 0], V[:, 1], F, z.ravel(), levels=20, cmap="coolwarm", alpha=0.25)
    for p in paths:
        ax2.plot(p.points[:, 0], p.points[:, 1], color="red", lw=1.4)
    ax2.plot(*V[src, :2], "o", color="white", mec="k")
    ax2.set_aspect("equal")
    ax2.set_title("projected to the xy plane (grey: distance isolines; shading: height)")
    fig.tight_layout()
    out = OUT / "fig8a_sine_paths.png"
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def fig9() -> Path:
    R, r, nu, nv = 1.0, 0.45, 120, 48
    u, v = np.meshgrid(2 * np.pi * np.arange(nu) / nu, 2 * np.pi * np.arange(nv) / nv,
                       indexing="ij")
    V = np.column_stack([((R + r * np.cos(v)) * np.cos(u)).ravel(),
                         ((R + r * np.cos(v)) * np.sin(u)).ravel(), (r * np.sin(v)).ravel()])
    F = grid_faces(nu, nv, True, True)
    mesh = meshfmm.Mesh(V, F)
    src = 0 * nv + 0  # outer equator, u = 0
    T = mesh.distance(src)
    targets = [(i * nu // 16) * nv + j for i, j in
               [(4, 0), (6, 0), (8, 0), (10, 0), (12, 0), (7, 12), (9, 12), (8, 24), (6, 36),
                (10, 36), (5, 30), (11, 18)]]
    paths = [mesh.geodesic_path(T, t, sources=[src]) for t in targets]
    levels = np.linspace(0, np.nanmax(T), 18)[1:]

    def normal(P):  # outward unit normal of the torus at points P
        c = P.copy()
        c[:, 2] = 0
        c *= R / np.linalg.norm(c, axis=1, keepdims=True)
        return (P - c) / np.linalg.norm(P - c, axis=1, keepdims=True)

    fig = plt.figure(figsize=(13, 6.5))
    for k, (elev, azim) in enumerate([(55, -60), (22, -60)]):
        ax = fig.add_subplot(1, 2, k + 1, projection="3d")
        ax.computed_zorder = False  # draw in zorder: surface, curves, paths
        e, a = np.radians(elev), np.radians(azim)
        eye = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
        # mplot3d does not hide what is behind: draw only what faces the viewer
        front = normal(V[F].mean(axis=1)) @ eye > 0
        shaded(ax, V, F[front], T, cmap="magma", alpha=1.0)
        segs = [np.array(g) * 1.004 for g in isolines(V, F[front], T, levels)]
        ax.add_collection3d(Line3DCollection(segs, colors="w", linewidths=0.5, zorder=2))
        for p in paths:
            P = p.points
            vis = normal(P) @ eye > 0
            cut = [np.array([P[i], P[i + 1]]) * 1.01 for i in range(len(P) - 1)
                   if vis[i] and vis[i + 1]]
            ax.add_collection3d(Line3DCollection(cut, colors="cyan", linewidths=1.6, zorder=3))
        ax.scatter(*V[src] * 1.01, color="lime", edgecolor="k", s=50, zorder=4)
        lim = R + r
        ax.set_xlim(-lim, lim), ax.set_ylim(-lim, lim), ax.set_zlim(-lim, lim)
        ax.set_box_aspect((1, 1, 1))
        ax.view_init(elev=elev, azim=azim)
        ax.set_axis_off()
    fig.suptitle("shortest paths on a torus (cyan) from the green source, with equidistance "
                 "curves; some cut through the hole")
    fig.tight_layout()
    out = OUT / "fig9_torus_paths.png"
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


if __name__ == "__main__":
    OUT.mkdir(parents=True, exist_ok=True)
    for f in (fig8a, fig9):
        print(f())
