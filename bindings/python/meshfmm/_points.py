"""Points on the surface as targets: vertex ids and SurfacePoints parsed
into arrays, the vertices whose distances determine them, and the values
there, interpolated as the path tracer reads T at a point: the linear
interpolant of the face's corners, sum of b_k T_k over the corners with
b_k > 0 (+inf when one of those is unreached)."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from . import _args
from ._types import SurfacePoint


class Points:
    """P points: ``vertex`` (P,) int64 (-1 for a point in a face), ``face``
    (P,) int64 (-1 for a vertex), ``bary`` (P, 3) float64."""

    def __init__(self, vertex: np.ndarray, face: np.ndarray, bary: np.ndarray) -> None:
        self.vertex, self.face, self.bary = vertex, face, bary

    @property
    def has_surface_points(self) -> bool:
        return bool((self.face >= 0).any())

    @classmethod
    def parse(cls, points: Any, what: str, nv: int, nf: int) -> "Points":
        """A vertex id, a SurfacePoint, a sequence mixing those or an integer
        array -> Points, ids and barycentric coordinates checked (>= 0,
        summing to 1 within 1e-9, as the library checks a source)."""
        if isinstance(points, SurfacePoint) or _args.is_int(points):
            points = [points]
        if isinstance(points, np.ndarray):
            ids = _args.index_array(points, what).astype(np.int64)
            n = ids.shape[0]
            vertex, face = ids, np.full(n, -1, np.int64)
            bary = np.zeros((n, 3))
        else:
            if isinstance(points, (str, bytes)) or not hasattr(points, "__len__"):
                raise TypeError(f"{what} must be vertex ids, SurfacePoints or a sequence of "
                                f"those, got {type(points).__name__}")
            n = len(points)
            vertex = np.full(n, -1, np.int64)
            face = np.full(n, -1, np.int64)
            bary = np.zeros((n, 3))
            for i, p in enumerate(points):
                if isinstance(p, SurfacePoint):
                    face[i] = _args.index(p.face, f"{what} {i}: face")
                    bary[i] = _args.barycentric(p.bary, f"{what} {i}")
                elif _args.is_int(p):
                    vertex[i] = _args.index(p, f"{what} {i}: vertex")
                else:
                    raise TypeError(f"{what} {i} must be a vertex id or a SurfacePoint, got "
                                    f"{type(p).__name__}")
        if n == 0:
            raise ValueError(f"{what} must hold at least one point")
        isv = face < 0
        bad = isv & ((vertex < 0) | (vertex >= nv))
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"{what} {i}: vertex {vertex[i]} is out of range (the mesh has "
                             f"{nv} vertices)")
        bad = ~isv & (face >= nf)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"{what} {i}: face {face[i]} is out of range (the mesh has "
                             f"{nf} faces)")
        b = bary[~isv]
        bad_b = ~np.isfinite(b).all(axis=1) | (b < 0).any(axis=1) | (np.abs(b.sum(axis=1) - 1) > 1e-9)
        if bad_b.any():
            i = int(np.flatnonzero(~isv)[np.flatnonzero(bad_b)[0]])
            raise ValueError(f"{what} {i}: barycentric coordinates {tuple(bary[i])} must be "
                             "finite, >= 0 and sum to 1")
        return cls(vertex, face, bary)

    def welded(self, weld: Any, what: str) -> "Points":
        """The same points in a welded mesh's ids."""
        vertex = self.vertex.copy()
        face = self.face.copy()
        isv = face < 0
        vertex[isv] = weld.to_welded[vertex[isv]]
        for i in np.flatnonzero(~isv):
            face[i] = weld.face(int(face[i]), f"{what} {i}")
        return Points(vertex, face, self.bary)

    def columns(self, F: np.ndarray) -> "tuple[np.ndarray, np.ndarray, np.ndarray]":
        """The vertices the values need, and how to combine them: (U int32
        sorted unique vertex ids, cols (P, 3) indices into U, w (P, 3)
        weights; a vertex point has weight 1 on its first column)."""
        n = self.vertex.shape[0]
        corners = np.empty((n, 3), np.int64)
        w = self.bary.copy()
        isv = self.face < 0
        corners[isv] = self.vertex[isv, None]
        w[isv] = (1.0, 0.0, 0.0)
        corners[~isv] = F[self.face[~isv]]
        U, inv = np.unique(corners, return_inverse=True)
        return U.astype(np.int32), inv.reshape(n, 3), w

    def values(self, d: np.ndarray, F: np.ndarray) -> np.ndarray:
        """The values of the per-vertex field d at the points, (P,)."""
        U, cols, w = self.columns(F)
        return combine(d[U][None, :], cols, w)[0]


def combine(DU: np.ndarray, cols: np.ndarray, w: np.ndarray,
            out: Optional[np.ndarray] = None) -> np.ndarray:
    """Rows of values at the vertices U (S, len(U)) -> at the points (S, P):
    sum over k with w[:, k] > 0 of w[:, k] * DU[:, cols[:, k]]."""
    S, P = DU.shape[0], cols.shape[0]
    res = np.zeros((S, P), dtype=np.float64)
    for k in range(3):
        m = w[:, k] > 0
        if m.any():
            res[:, m] += w[m, k] * DU[:, cols[m, k]]
    if out is not None:
        out[...] = res
        return out
    return res
