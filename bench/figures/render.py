"""A small z-buffer renderer (orthographic, numpy) for the benchmark figures:
matplotlib's 3D axes cannot hide curves behind a surface, this can.

    cam = Camera(V, azim, elev, width)
    img = cam.render(V, F, vertex_values=T, cmap=...)   # RGB image with smooth shading
    segs = cam.visible_segments(points_3d)             # 2D segments not hidden by the surface
"""

from __future__ import annotations

import numpy as np


class Camera:
    def __init__(self, V, azim_deg, elev_deg, width=900, up=(0.0, 0.0, 1.0), margin=0.04):
        a, e = np.radians(azim_deg), np.radians(elev_deg)
        up = np.asarray(up, dtype=float)
        up /= np.linalg.norm(up)
        # a basis with `up` as world z: eye direction from azimuth/elevation around it
        t = np.array([1.0, 0, 0]) if abs(up[0]) < 0.9 else np.array([0, 1.0, 0])
        ex = t - up * (t @ up)
        ex /= np.linalg.norm(ex)
        ey = np.cross(up, ex)
        eye = np.cos(e) * np.cos(a) * ex + np.cos(e) * np.sin(a) * ey + np.sin(e) * up
        self.eye = eye  # unit vector from the scene towards the viewer
        right = np.cross(up, eye)
        if np.linalg.norm(right) < 1e-9:
            right = ex
        right /= np.linalg.norm(right)
        screen_up = np.cross(eye, right)
        self.R = np.stack([right, screen_up, eye])  # rows: screen x, screen y, depth
        P = V @ self.R.T
        lo, hi = P[:, :2].min(axis=0), P[:, :2].max(axis=0)
        span = (hi - lo).max() * (1 + 2 * margin)
        self.scale = width / span
        self.center = (lo + hi) / 2
        self.W = width
        self.H = int(np.ceil((hi - lo)[1] * (1 + 2 * margin) * self.scale))
        self.depth_tol = 0.004 * np.linalg.norm(V.max(axis=0) - V.min(axis=0))

    def project(self, P):
        """(n,3) points -> (n,2) pixel coordinates (x right, y down) and depth (n,)."""
        Q = np.asarray(P, dtype=float) @ self.R.T
        x = (Q[:, 0] - self.center[0]) * self.scale + self.W / 2
        y = self.H / 2 - (Q[:, 1] - self.center[1]) * self.scale
        return np.column_stack([x, y]), Q[:, 2]

    def rasterize(self, V, F):
        """Per pixel: face id (-1 background), barycentric coordinates, depth."""
        xy, z = self.project(V)
        H, W = self.H, self.W
        zbuf = np.full((H, W), -np.inf)
        fid = np.full((H, W), -1, dtype=np.int64)
        bary = np.zeros((H, W, 3))
        T = xy[F]  # (nf,3,2)
        Z = z[F]
        x0 = np.clip(np.floor(T[:, :, 0].min(axis=1)).astype(int), 0, W - 1)
        x1 = np.clip(np.ceil(T[:, :, 0].max(axis=1)).astype(int), 0, W - 1)
        y0 = np.clip(np.floor(T[:, :, 1].min(axis=1)).astype(int), 0, H - 1)
        y1 = np.clip(np.ceil(T[:, :, 1].max(axis=1)).astype(int), 0, H - 1)
        (ax, ay), (bx, by), (cx, cy) = T[:, 0].T, T[:, 1].T, T[:, 2].T
        den = (by - cy) * (ax - cx) + (cx - bx) * (ay - cy)
        for f in np.flatnonzero(np.abs(den) > 1e-12):
            xs = np.arange(x0[f], x1[f] + 1) + 0.5
            ys = np.arange(y0[f], y1[f] + 1) + 0.5
            px, py = np.meshgrid(xs, ys)
            l0 = ((by[f] - cy[f]) * (px - cx[f]) + (cx[f] - bx[f]) * (py - cy[f])) / den[f]
            l1 = ((cy[f] - ay[f]) * (px - cx[f]) + (ax[f] - cx[f]) * (py - cy[f])) / den[f]
            l2 = 1 - l0 - l1
            inside = (l0 >= -1e-9) & (l1 >= -1e-9) & (l2 >= -1e-9)
            if not inside.any():
                continue
            d = l0 * Z[f, 0] + l1 * Z[f, 1] + l2 * Z[f, 2]
            sl = (slice(y0[f], y1[f] + 1), slice(x0[f], x1[f] + 1))
            win = inside & (d > zbuf[sl])
            if not win.any():
                continue
            zbuf[sl][win] = d[win]
            fid[sl][win] = f
            bary[sl][win] = np.stack([l0, l1, l2], axis=-1)[win]
        self.zbuf, self.fid, self.bary = zbuf, fid, bary
        return fid, bary, zbuf

    def render(self, V, F, vertex_values=None, face_rgb=None, cmap=None, vmax=None,
               light=(0.4, 0.6, 1.0), ambient=0.35, background=(1, 1, 1)):
        """Smooth-shaded image; colour from vertex_values through cmap, or face_rgb."""
        fid, bary, _ = self.rasterize(V, F)
        mask = fid >= 0
        f = fid[mask]
        w = bary[mask]
        # vertex normals (area weighted)
        fn = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
        vn = np.zeros_like(V)
        for k in range(3):
            np.add.at(vn, F[:, k], fn)
        vn /= np.linalg.norm(vn, axis=1, keepdims=True) + 1e-300
        n = np.einsum("pk,pkj->pj", w, vn[F[f]])
        n /= np.linalg.norm(n, axis=1, keepdims=True) + 1e-300
        # light given in screen coordinates (x right, y up, towards viewer)
        L = np.asarray(light, dtype=float) @ self.R
        L /= np.linalg.norm(L)
        diffuse = np.abs(n @ L)
        shade = ambient + (1 - ambient) * diffuse
        if face_rgb is not None:
            rgb = np.asarray(face_rgb)[f, :3]
        else:
            val = np.einsum("pk,pk->p", w, vertex_values[F[f]])
            vmax = vmax if vmax is not None else np.nanmax(vertex_values[np.isfinite(vertex_values)])
            rgb = cmap(np.clip(val / vmax, 0, 1))[:, :3]
        img = np.ones((self.H, self.W, 3)) * np.asarray(background, dtype=float)
        img[mask] = rgb * shade[:, None]
        return img

    def visible(self, P):
        """Which of the 3D points P are not hidden by the rasterized surface."""
        xy, z = self.project(P)
        ix = np.clip(np.floor(xy[:, 0]).astype(int), 0, self.W - 1)
        iy = np.clip(np.floor(xy[:, 1]).astype(int), 0, self.H - 1)
        best = np.full(len(P), -np.inf)
        for dy in (-1, 0, 1):  # the nearest surface in a 3x3 neighbourhood
            for dx in (-1, 0, 1):
                jy = np.clip(iy + dy, 0, self.H - 1)
                jx = np.clip(ix + dx, 0, self.W - 1)
                best = np.maximum(best, self.zbuf[jy, jx])
        return z >= best - self.depth_tol

    def visible_segments(self, P):
        """Consecutive point pairs of the polyline P that are both visible, in pixels."""
        P = np.asarray(P, dtype=float)
        if len(P) < 2:
            return []
        # resample finely so that occlusion is judged along the whole curve
        seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
        step = 1.5 / self.scale
        pts = [P[0]]
        for i in range(len(P) - 1):
            k = max(1, int(np.ceil(seg[i] / step)))
            t = np.arange(1, k + 1)[:, None] / k
            pts.append(P[i] + t * (P[i + 1] - P[i]))
        Q = np.vstack([p.reshape(-1, 3) for p in pts])
        vis = self.visible(Q)
        xy, _ = self.project(Q)
        ok = vis[:-1] & vis[1:]
        return [xy[i:i + 2] for i in np.flatnonzero(ok)]


def isoline_segments(V, F, T, levels):
    """3D segments of the level sets of the piecewise linear T (vectorised per level)."""
    out = []
    for lv in levels:
        t = T[F] - lv
        fin = np.all(np.isfinite(t), axis=1)
        cross = fin & (t.min(axis=1) < 0) & (t.max(axis=1) >= 0)
        idx = np.flatnonzero(cross)
        if idx.size == 0:
            continue
        pts = []
        for a, b in ((0, 1), (1, 2), (2, 0)):
            ta, tb = t[idx, a], t[idx, b]
            hit = (ta < 0) != (tb < 0)
            w = np.where(hit, ta / np.where(hit, ta - tb, 1), 0)
            p = (1 - w)[:, None] * V[F[idx, a]] + w[:, None] * V[F[idx, b]]
            pts.append((hit, p))
        for j in range(idx.size):
            q = [p[j] for hit, p in pts if hit[j]]
            if len(q) == 2:
                out.append(np.array(q))
    return out
