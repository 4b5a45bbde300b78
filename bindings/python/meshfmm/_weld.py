"""Welding of coincident vertices for ``Mesh(V, F, weld=True)``: the map
from the vertices and faces as given to those of the welded surface, and
the translations of arguments (vertex ids, sources, costs, distances) and
results (per-vertex arrays, path faces) across it."""

from __future__ import annotations

from ctypes import byref, c_int32
from typing import Any, Optional, Tuple

import numpy as np

from . import _args, _lib


class Weld:
    """Vertices of exactly equal position (``-0.0`` equal to ``0.0``) become
    one vertex, numbered by their lowest input id in input order (a mesh
    without coincident vertices keeps its numbering); faces keep their
    corner order, and a face two of whose corners weld into one (zero area)
    is dropped.

    Attributes
    ----------
    to_welded : numpy.ndarray, int32 (n_input_vertices,)
        The welded vertex of each input vertex.
    rep : numpy.ndarray, int64 (n_welded_vertices,)
        The lowest input id of each welded vertex.
    kept_faces : numpy.ndarray, int64 (n_welded_faces,)
        The input face of each welded face.
    face_to_welded : numpy.ndarray, int64 (n_input_faces,)
        The welded face of each input face, -1 where it was dropped.
    V, F : numpy.ndarray
        The welded vertices (float64) and faces (int32).
    """

    def __init__(self, V: np.ndarray, F: np.ndarray) -> None:
        nv, nf = V.shape[0], F.shape[0]
        self.nv_in, self.nf_in = nv, nf
        Vc = np.ascontiguousarray(V, dtype=np.float64)
        self.to_welded = np.empty(nv, dtype=np.int32)
        n_welded = c_int32(0)
        err = _lib.mfmm_error()
        status = _lib.mfmm_weld_map(_args.addr(Vc), nv, _args.addr(self.to_welded),
                                    byref(n_welded), byref(err))
        _lib.check(status, err)
        self.rep = np.unique(self.to_welded, return_index=True)[1]  # each id's first vertex
        Fw = self.to_welded[F]
        ok = (Fw[:, 0] != Fw[:, 1]) & (Fw[:, 1] != Fw[:, 2]) & (Fw[:, 0] != Fw[:, 2])
        self.kept_faces = np.flatnonzero(ok)
        self.face_to_welded = np.full(nf, -1, dtype=np.int64)
        self.face_to_welded[self.kept_faces] = np.arange(self.kept_faces.shape[0])
        self.V = np.ascontiguousarray(V[self.rep])
        self.F = np.ascontiguousarray(Fw[ok], dtype=np.int32)

    @staticmethod
    def applicable(V: np.ndarray, F: np.ndarray) -> bool:
        """Whether V, F are sound enough to weld (finite, ids in range);
        otherwise the mesh is built unwelded, so that the library names the
        offending input vertex or face."""
        return bool(np.isfinite(V).all()) and (
            F.size == 0 or (int(F.min()) >= 0 and int(F.max()) < V.shape[0]))

    # ---- arguments in input ids -> welded ids
    def vertices(self, ids: Any, what: str) -> np.ndarray:
        """Input vertex ids (scalar or 1-D) -> welded ids, int32 (range
        checked against the input)."""
        a = _args.index_array(ids, what)
        if a.size and (int(a.min()) < 0 or int(a.max()) >= self.nv_in):
            bad = a[(a < 0) | (a >= self.nv_in)][0]
            raise ValueError(f"{what} vertex {bad} is out of range (the mesh has "
                             f"{self.nv_in} vertices)")
        return self.to_welded[a]

    def face(self, f: int, what: str) -> int:
        """An input face id -> its welded face (ValueError when dropped)."""
        if not (0 <= f < self.nf_in):
            raise ValueError(f"{what}: face {f} is out of range (the mesh has "
                             f"{self.nf_in} faces)")
        w = int(self.face_to_welded[f])
        if w < 0:
            raise ValueError(f"{what}: face {f} has zero area once its coincident "
                             "corners are welded (it was dropped)")
        return w

    def sources(self, sources: Any, what: str = "source") -> np.ndarray:
        """Any accepted sources -> mfmm_source records in welded ids."""
        rec = _args.source_records(sources, what).copy()
        is_vertex = rec["face"] == -1
        if is_vertex.any():
            rec["vertex"][is_vertex] = self.vertices(rec["vertex"][is_vertex], what)
        for i in np.flatnonzero(~is_vertex):
            rec["face"][i] = self.face(int(rec["face"][i]), f"{what} {i}")
        return rec

    def point(self, p: Any, what: str) -> Any:
        """A vertex id or SurfacePoint in input ids -> the same in welded ids."""
        from ._types import SurfacePoint

        if isinstance(p, SurfacePoint):
            return SurfacePoint(self.face(_args.index(p.face, f"{what} face"), what), p.bary)
        if _args.is_int(p):
            return int(self.vertices(p, what)[0])
        raise TypeError(f"{what} must be a vertex id or a SurfacePoint, got {type(p).__name__}")

    def cost(self, cost: Any, cost_location: Optional[str]) -> Tuple[Any, Optional[str]]:
        """A cost per input vertex or face -> per welded vertex (the value of
        each group's lowest input id) or face, with its explicit location."""
        c, loc = _args.cost_array(cost, cost_location, self.nv_in, self.nf_in)
        if c is None:
            return None, cost_location
        if loc == _lib.MFMM_COST_PER_VERTEX:
            return np.ascontiguousarray(c[self.rep]), "vertex"
        return np.ascontiguousarray(c[self.kept_faces]), "face"

    def distances_in(self, d: Any) -> np.ndarray:
        """Per-input-vertex distances -> per welded vertex (the lowest input
        id's value)."""
        a = np.ascontiguousarray(d, dtype=np.float64)
        if a.shape != (self.nv_in,):
            raise ValueError(f"distances must have shape ({self.nv_in},), got {a.shape}")
        return np.ascontiguousarray(a[self.rep])

    # ---- results in welded ids -> input ids
    def per_vertex(self, d: np.ndarray) -> np.ndarray:
        """A per-welded-vertex array -> per input vertex."""
        return d[self.to_welded]

    def faces_out(self, f: np.ndarray) -> np.ndarray:
        """Welded face ids -> input face ids (int32)."""
        return self.kept_faces[f].astype(np.int32)
