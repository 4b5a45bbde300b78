"""Isolines of a per-vertex field: the level sets of its linear
interpolant over each face, as segments (:func:`segments`, :func:`crossings`
for one value; :mod:`meshfmm.plot` draws them) or as polylines
(:func:`isolines`, :meth:`Mesh.isolines`: the segments joined through the
edges they share).

Any number of values costs one pass over the faces (each vertex's rank
among the sorted values; each face's least and greatest corner rank: the
values it crosses), then work in proportion to the segments found."""

from __future__ import annotations

from typing import Any, List, Tuple

import numpy as np

from ._types import Isoline

Segments = Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def segments(V: np.ndarray, F: np.ndarray, d: np.ndarray, values: Any) -> Segments:
    """Where the linear interpolant of d over the faces equals each of
    `values`: one segment per face and value when the face's corners are
    not all on one side (a corner counts as above when d >= value: the face
    crosses the values in (least corner, greatest corner]; faces with a
    non-finite corner hold none), between the two points where its edges
    cross. Each crossing point is interpolated from its edge's lower vertex
    id, so faces that share an edge share the point bit for bit.

    Returns
    -------
    which : numpy.ndarray, int64 (m,)
        The index in `values` of each segment; ascending, and within one
        value the faces ascending.
    faces : numpy.ndarray, int64 (m,)
        The face of each segment.
    points : numpy.ndarray, float64 (m, 2, 3)
        The segments' ends.
    barycentric : numpy.ndarray, float64 (m, 2, 3)
        Each end's coordinates in its face.
    edges : numpy.ndarray, int64 (m, 2)
        Each end's edge, as lower id * n_vertices + higher id.
    """
    vals = np.atleast_1d(np.asarray(values, dtype=np.float64)).ravel()
    nv, nf = V.shape[0], F.shape[0]
    order = np.argsort(vals, kind="stable")
    sv = vals[order]
    # k(x), the count of values <= x, per vertex (-1: not finite); a face
    # crosses the values in (least corner, greatest corner], those of sorted
    # index k(least) <= i < k(greatest), and k is monotone: one pass over
    # the faces takes the least and greatest k of their corners
    kv = np.searchsorted(sv, d, side="right").astype(np.int32)
    kv[~np.isfinite(d)] = -1  # faces with such a corner hold none
    kF = kv[F]
    a, b, c3 = kF[:, 0], kF[:, 1], kF[:, 2]
    k0 = np.minimum(np.minimum(a, b), c3)
    k1 = np.maximum(np.maximum(a, b), c3)
    count = np.where(k0 >= 0, k1 - k0, 0)
    fids = np.repeat(np.arange(nf, dtype=np.int64), count)
    if fids.size == 0:
        empty = np.empty(0, np.int64)
        return (empty, empty, np.empty((0, 2, 3)), np.empty((0, 2, 3)),
                np.empty((0, 2), np.int64))
    first = np.cumsum(count) - count
    rank = np.arange(fids.size) - np.repeat(first, count) + np.repeat(k0, count)
    which = order[rank]
    sort = np.lexsort((fids, which))
    which, fids = which[sort], fids[sort]
    c = vals[which]
    # the segments: work in proportion to their count
    Fc = F[fids].astype(np.int64)
    Ac = d[Fc] >= c[:, None]
    # edge k of a face: corners (k+1, k+2) mod 3, opposite corner k; exactly
    # two cross: the segment's ends, in local order
    quiet = np.where(Ac[:, 1] == Ac[:, 2], 0, np.where(Ac[:, 0] == Ac[:, 2], 1, 2))
    seg_edges = np.array([[1, 2], [0, 2], [0, 1]])[quiet]
    rows = np.arange(fids.size)[:, None]
    kp, kq = (seg_edges + 1) % 3, (seg_edges + 2) % 3  # the edges' corners
    p, q = Fc[rows, kp], Fc[rows, kq]
    swap = p > q
    lo, hi = np.where(swap, q, p), np.where(swap, p, q)
    klo, khi = np.where(swap, kq, kp), np.where(swap, kp, kq)
    dl, dh = d[lo], d[hi]
    t = (c[:, None] - dl) / (dh - dl)
    X = V[lo] + t[..., None] * (V[hi] - V[lo])
    B = np.zeros((fids.size, 2, 3))
    ends = np.arange(2)[None, :]
    B[rows, ends, klo] = 1.0 - t
    B[rows, ends, khi] = t
    return which, fids, X, B, lo * nv + hi


def crossings(V: np.ndarray, F: np.ndarray, d: np.ndarray, value: float
              ) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`segments` of one value: (faces, points, barycentric, edges),
    the faces ascending."""
    _, fids, X, B, keys = segments(V, F, d, [value])
    return fids, X, B, keys


def _join(c: float, fids: np.ndarray, X: np.ndarray, B: np.ndarray,
          keys: np.ndarray) -> List[Isoline]:
    """One value's segments joined into polylines through the edges they
    share: open ones from their ends (in edge order), then the loops; at an
    edge that more than two segments share (a non-manifold edge) a polyline
    goes on with the first unused one."""
    m = fids.size
    if m == 0:
        return []
    uniq, flat = np.unique(keys.ravel(), return_inverse=True)
    flat = flat.ravel()  # entry 2 s + e: the node (edge) of segment s's end e
    deg = np.bincount(flat, minlength=uniq.size)
    byn = np.argsort(flat, kind="stable")  # entries grouped by node, ascending
    partner = np.full(2 * m, -1, dtype=np.int64)  # the other entry at the same node
    if deg.max() <= 2:
        same = flat[byn[:-1]] == flat[byn[1:]]
        partner[byn[:-1][same]] = byn[1:][same]
        partner[byn[1:][same]] = byn[:-1][same]
        nxt_of = None
    else:
        starts = np.concatenate([[0], np.cumsum(deg)])
        nxt_of = [byn[starts[n]:starts[n + 1]].tolist() for n in range(uniq.size)]
    node = flat.tolist()
    part = partner.tolist()
    used = [False] * m
    faces32 = fids.astype(np.int32)

    def walk(s_: int, e: int) -> Isoline:
        seg, end = [s_], [e]  # enter segment s_ at its end e
        first_node = node[2 * s_ + e]
        closed = False
        while True:
            used[s_] = True
            o = 1 - e
            seg.append(s_)
            end.append(o)
            ent = 2 * s_ + o
            if node[ent] == first_node:
                closed = True
                break
            if nxt_of is None:
                p = part[ent]
                if p < 0 or used[p >> 1]:
                    break
            else:
                p = next((x for x in nxt_of[node[ent]] if not used[x >> 1]), -1)
                if p < 0:
                    break
            s_, e = p >> 1, p & 1
        si, ei = np.array(seg), np.array(end)
        return Isoline(value=c, points=X[si, ei], faces=faces32[si], barycentric=B[si, ei],
                       closed=closed)

    lines: List[Isoline] = []
    for ent in byn[deg[flat[byn]] == 1].tolist():  # the ends, by node
        if not used[ent >> 1]:
            lines.append(walk(ent >> 1, ent & 1))
    for s_ in range(m):
        if not used[s_]:
            lines.append(walk(s_, 0))
    return lines


def isolines(V: np.ndarray, F: np.ndarray, d: np.ndarray, values: Any) -> List[List[Isoline]]:
    """For each of `values`, the polylines where the linear interpolant of
    d over the faces equals it: :func:`segments` (one pass over the faces
    for all values), each value's joined through the edges they share."""
    vals = np.atleast_1d(np.asarray(values, dtype=np.float64)).ravel()
    which, fids, X, B, keys = segments(V, F, d, vals)
    bounds = np.searchsorted(which, np.arange(vals.size + 1))
    return [_join(float(c), fids[a:b], X[a:b], B[a:b], keys[a:b])
            for c, a, b in zip(vals.tolist(), bounds[:-1], bounds[1:])]


def fix_faces(lines: List[Isoline], faces_out: Any) -> List[Isoline]:
    """The same polylines with face ids mapped by `faces_out`."""
    return [Isoline(value=ln.value, points=ln.points, faces=faces_out(ln.faces),
                    barycentric=ln.barycentric, closed=ln.closed) for ln in lines]
