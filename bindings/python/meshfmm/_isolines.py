"""Isolines of a per-vertex field: the level sets of its linear
interpolant over each face, as polylines (one pass over the faces per
value, then the segments joined through the edges they share)."""

from __future__ import annotations

from typing import Any, Dict, List

import numpy as np

from ._types import Isoline


def isolines(V: np.ndarray, F: np.ndarray, d: np.ndarray, value: float) -> List[Isoline]:
    """The polylines where the linear interpolant of d over the faces equals
    `value`. A corner counts as above the level when d >= value, so each
    face with corners on both sides holds one segment between two of its
    edges; faces with an infinite corner hold none. Crossing points are
    computed from each edge's lower vertex id, so faces sharing an edge
    share the point."""
    c = float(value)
    fin = np.isfinite(d[F]).all(axis=1)
    above = d >= c
    A = above[F]
    cross = fin & (A.any(axis=1) & ~A.all(axis=1))
    fids = np.flatnonzero(cross)
    if fids.size == 0:
        return []
    Fc = F[fids]
    Ac = A[fids]
    nv = V.shape[0]
    # edge k of a face: corners (k+1, k+2) mod 3, opposite corner k
    seg_edges = np.empty((fids.size, 2), np.int64)  # local edge index of the 2 crossings
    ks = []
    for k in range(3):
        ks.append(Ac[:, (k + 1) % 3] != Ac[:, (k + 2) % 3])
    ks = np.stack(ks, axis=1)  # (m, 3): which local edges cross (exactly two)
    order = np.argsort(~ks, axis=1, kind="stable")[:, :2]
    seg_edges[:] = order
    rows = np.arange(fids.size)[:, None]
    p = Fc[rows, (seg_edges + 1) % 3]
    q = Fc[rows, (seg_edges + 2) % 3]
    lo, hi = np.minimum(p, q), np.maximum(p, q)
    dl, dh = d[lo], d[hi]
    t = (c - dl) / (dh - dl)
    X = V[lo] + t[..., None] * (V[hi] - V[lo])
    # barycentric coordinates of each end in its face
    B = np.zeros((fids.size, 2, 3))
    for j in range(2):
        for k in range(3):
            B[:, j, k] += np.where(Fc[:, k] == lo[:, j], 1.0 - t[:, j], 0.0)
            B[:, j, k] += np.where(Fc[:, k] == hi[:, j], t[:, j], 0.0)
    keys = lo * nv + hi  # (m, 2)
    uniq, node = np.unique(keys.ravel(), return_inverse=True)
    node = node.reshape(-1, 2)
    # node -> segments touching it
    touch: Dict[int, List[int]] = {}
    for s_, (a, b) in enumerate(node.tolist()):
        touch.setdefault(a, []).append(s_)
        touch.setdefault(b, []).append(s_)
    used = np.zeros(fids.size, bool)
    lines: List[Isoline] = []

    def walk(start_seg: int, start_end: int) -> Isoline:
        pts, fcs, brs = [], [], []
        s_, e = start_seg, start_end  # enter the segment at its end e
        first_node = int(node[s_, e])
        pts.append(X[s_, e]); fcs.append(int(fids[s_])); brs.append(B[s_, e])
        closed = False
        while True:
            used[s_] = True
            o = 1 - e
            pts.append(X[s_, o]); fcs.append(int(fids[s_])); brs.append(B[s_, o])
            n = int(node[s_, o])
            if n == first_node:
                closed = True
                break
            nxt = [x for x in touch[n] if not used[x]]
            if not nxt:
                break
            s_ = nxt[0]
            e = 0 if int(node[s_, 0]) == n else 1
        return Isoline(value=c, points=np.array(pts), faces=np.array(fcs, dtype=np.int32),
                       barycentric=np.array(brs), closed=closed)

    # open polylines from the ends (nodes touched once), then the loops
    for n, segs in sorted(touch.items()):
        if len(segs) == 1 and not used[segs[0]]:
            s_ = segs[0]
            lines.append(walk(s_, 0 if int(node[s_, 0]) == n else 1))
    for s_ in range(fids.size):
        if not used[s_]:
            lines.append(walk(s_, 0))
    return lines


def fix_faces(lines: List[Isoline], faces_out: Any) -> List[Isoline]:
    """The same polylines with face ids mapped by `faces_out`."""
    return [Isoline(value=ln.value, points=ln.points, faces=faces_out(ln.faces),
                    barycentric=ln.barycentric, closed=ln.closed) for ln in lines]
