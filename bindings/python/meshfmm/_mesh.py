"""Mesh, SurfacePoint, GeodesicPath and load_mesh: the Python face of libmeshfmm.

All foreign calls go through :mod:`meshfmm._lib`.
"""

from __future__ import annotations

import atexit
import collections.abc
import contextlib
import ctypes
import dataclasses
import errno
import math
import numbers
import operator
import os
import signal
import threading
from ctypes import byref
from typing import Any, Callable, Dict, Iterator, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from . import _lib
from ._lib import MeshError

__all__ = ["Mesh", "MeshInfo", "SurfacePoint", "GeodesicPath", "load_mesh"]

_I32_MIN = -(2**31)
_I32_MAX = 2**31 - 1


class SurfacePoint(NamedTuple):
    """A point inside a face: ``face`` id and barycentric coordinates ``bary``
    (three numbers >= 0 summing to 1, weights of the face's corners in the
    order the face lists them). Usable as a source of :meth:`Mesh.distance`
    and as a target of :meth:`Mesh.geodesic_path`."""

    face: int
    bary: Sequence[float]


SourceLike = Union[int, SurfacePoint, Sequence[Union[int, SurfacePoint]], np.ndarray]


@dataclasses.dataclass(frozen=True)
class MeshInfo:
    """Diagnostics of a mesh, computed once when it was created
    (``mfmm_mesh_info``)."""

    n_vertices: int  #: vertices as given
    n_faces: int  #: faces as given
    n_edges: int  #: distinct undirected edges (of the surface built: T-junctions closed)
    n_boundary_edges: int  #: edges with one face
    n_nonmanifold_edges: int  #: edges with three or more faces
    n_components: int  #: edge-connected components of referenced vertices
    n_unreferenced_vertices: int  #: vertices no face names (always +inf)
    n_degenerate_faces: int  #: faces of (numerically) zero area, as given (needles included)
    n_obtuse_corners: int  #: corners with an angle > 90 degrees
    n_virtual_edges: int  #: obtuse corners split by a virtual edge (unfolding)
    n_unfold_failures: int  #: obtuse corners whose unfolding walk failed
    min_edge_length: float
    max_edge_length: float
    mean_edge_length: float
    bbox_diagonal: float  #: length of the bounding-box diagonal
    n_duplicate_faces: int  #: faces repeating another's vertices (copies; not walls)

    def as_dict(self) -> dict:
        """The fields as a plain dict."""
        return dataclasses.asdict(self)


@dataclasses.dataclass(frozen=True)
class GeodesicPath:
    """A polyline on the surface from a target back to its source.

    ``points`` (k,3) positions, ``faces`` (k,) the face each point lies in,
    ``barycentric`` (k,3) its coordinates in that face, ``length`` the
    polyline's Euclidean length, ``weighted_length`` its cost-weighted length
    (sum of F times segment length; equal to ``length`` without a cost).
    Point 0 is the target, point k-1 the source; ``faces[i]`` (i > 0) is the
    face the segment from point i-1 runs through.
    """

    points: np.ndarray
    faces: np.ndarray
    barycentric: np.ndarray
    length: float
    weighted_length: float

    def __len__(self) -> int:
        return int(self.faces.shape[0])


# ------------------------------------------------------------------ helpers
def _addr(a: np.ndarray) -> int:
    """Address of an ndarray's first element. (ctypes.c_char.from_buffer is
    several times faster than ndarray.ctypes.data, but needs a writable,
    non-empty buffer.)"""
    try:
        return ctypes.addressof(ctypes.c_char.from_buffer(a))
    except (TypeError, ValueError):
        return a.__array_interface__["data"][0]


def _is_int(x: Any) -> bool:
    return isinstance(x, (int, np.integer)) and not isinstance(x, (bool, np.bool_))


def _flag(x: Any, what: str) -> bool:
    """A yes/no option: True or False (numpy's bools too). Anything else is a
    TypeError: 'no', 0 or None read as truth values would pass silently."""
    if not isinstance(x, (bool, np.bool_)):
        raise TypeError(f"{what} must be True or False, got {x!r}")
    return bool(x)


def _size(x: Any, what: str) -> int:
    """A byte count for a C size_t: an integer in [0, 2**64)."""
    if not _is_int(x):
        raise TypeError(f"{what} must be an integer number of bytes, got {x!r}")
    i = int(x)
    if not (0 <= i < 2**64):
        raise ValueError(f"{what} must be in [0, 2**64), got {i}")
    return i


def _as_index(x: Any, what: str) -> int:
    if not _is_int(x):
        raise TypeError(f"{what} must be an integer, got {type(x).__name__}")
    i = int(x)
    if not (_I32_MIN <= i <= _I32_MAX):
        raise ValueError(f"{what} {i} is out of range (not a 32-bit index)")
    return i


def _bary(b: Any, what: str) -> np.ndarray:
    try:
        arr = np.asarray(b, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: barycentric coordinates must be 3 numbers, got {b!r}") from None
    if arr.shape != (3,):
        raise ValueError(
            f"{what}: barycentric coordinates must be 3 numbers, got shape {arr.shape}"
        )
    return arr


def _source_records(sources: Any, what: str = "source") -> np.ndarray:
    """Any accepted form of sources -> a C-contiguous array of mfmm_source."""
    if isinstance(sources, SurfacePoint):
        sources = [sources]
    elif _is_int(sources):
        rec = np.zeros(1, dtype=_lib.SOURCE_DTYPE)
        rec["vertex"] = _as_index(sources, what)
        rec["face"] = -1
        return rec
    if isinstance(sources, np.ndarray):
        if sources.dtype.kind not in "iu":
            raise TypeError(f"{what}s as an array must be integer vertex ids, got dtype {sources.dtype}")
        ids = sources.reshape(-1)
        if ids.size == 0:
            raise ValueError(f"at least one {what} is needed")
        if ids.min() < _I32_MIN or ids.max() > _I32_MAX:
            bad = ids[(ids < _I32_MIN) | (ids > _I32_MAX)][0]
            raise ValueError(f"{what} {bad} is out of range (not a 32-bit index)")
        rec = np.zeros(ids.size, dtype=_lib.SOURCE_DTYPE)
        rec["vertex"] = ids
        rec["face"] = -1
        return rec
    if (isinstance(sources, (str, bytes, collections.abc.Mapping))
            or not hasattr(sources, "__len__")):
        raise TypeError(
            f"{what}s must be a vertex id, a SurfacePoint or a sequence of those, "
            f"got {type(sources).__name__}"
        )
    n = len(sources)
    if n == 0:
        raise ValueError(f"at least one {what} is needed")
    if all(_is_int(s) for s in sources):  # vertex ids only: filled at once
        ids = [int(s) for s in sources]
        for i, v in enumerate(ids):
            if not (_I32_MIN <= v <= _I32_MAX):
                raise ValueError(f"{what} {i}: vertex {v} is out of range (not a 32-bit index)")
        rec = np.zeros(n, dtype=_lib.SOURCE_DTYPE)
        rec["vertex"] = ids
        rec["face"] = -1
        return rec
    rec = np.zeros(n, dtype=_lib.SOURCE_DTYPE)
    for i, s in enumerate(sources):
        if isinstance(s, SurfacePoint):
            face = _as_index(s.face, f"{what} {i}: face")
            if face < 0:
                raise ValueError(f"{what} {i}: face {face} is out of range (face ids are >= 0)")
            rec["face"][i] = face
            rec["vertex"][i] = -1
            rec["bary"][i] = _bary(s.bary, f"{what} {i}")
        elif _is_int(s):
            rec["vertex"][i] = _as_index(s, f"{what} {i}: vertex")
            rec["face"][i] = -1
        else:
            raise TypeError(
                f"{what} {i} must be a vertex id or a SurfacePoint, got {type(s).__name__}"
            )
    return rec


def _target_record(target: Any) -> _lib.mfmm_source:
    src = _lib.mfmm_source()
    if isinstance(target, SurfacePoint):
        src.vertex = -1
        src.face = _as_index(target.face, "target face")
        if src.face < 0:
            raise ValueError(f"target face {src.face} is out of range (face ids are >= 0)")
        b = _bary(target.bary, "target")
        src.bary[0], src.bary[1], src.bary[2] = float(b[0]), float(b[1]), float(b[2])
    elif _is_int(target):
        src.vertex = _as_index(target, "target vertex")
        src.face = -1
    else:
        raise TypeError(f"target must be a vertex id or a SurfacePoint, got {type(target).__name__}")
    return src


_COST_LOCATIONS = {"vertex": _lib.MFMM_COST_PER_VERTEX, "face": _lib.MFMM_COST_PER_FACE}


def _cost_array(cost: Any, cost_location: Optional[str], nv: int, nf: int) -> Tuple[Optional[np.ndarray], int]:
    if cost is None:
        if cost_location is not None and cost_location not in _COST_LOCATIONS:
            raise ValueError(f"cost_location must be 'vertex' or 'face', got {cost_location!r}")
        return None, _lib.MFMM_COST_NONE
    c = np.asarray(cost)
    if c.dtype.kind not in "iuf":
        raise ValueError(f"cost must be an array of numbers, got dtype {c.dtype}")
    c = np.ascontiguousarray(c, dtype=np.float64)
    if c.ndim != 1:
        raise ValueError(f"cost must be 1-D, (n_vertices,) or (n_faces,), got shape {c.shape}")
    if cost_location is None:
        if c.shape[0] == nv and nv == nf:
            raise ValueError(
                f"the mesh has as many vertices as faces ({nv}): say cost_location='vertex' or 'face'"
            )
        if c.shape[0] == nv:
            loc = _lib.MFMM_COST_PER_VERTEX
        elif c.shape[0] == nf:
            loc = _lib.MFMM_COST_PER_FACE
        else:
            raise ValueError(
                f"cost has {c.shape[0]} entries; the mesh has {nv} vertices and {nf} faces"
            )
    else:
        if cost_location not in _COST_LOCATIONS:
            raise ValueError(f"cost_location must be 'vertex' or 'face', got {cost_location!r}")
        loc = _COST_LOCATIONS[cost_location]
        want = nv if loc == _lib.MFMM_COST_PER_VERTEX else nf
        if c.shape[0] != want:
            raise ValueError(
                f"cost per {cost_location} must have {want} entries, got {c.shape[0]}"
            )
    return c, loc


def _exact_start(x: Any) -> Optional[float]:
    """The exact_start option: True or "auto" (the library's default radius,
    MFMM_EXACT_START_AUTO) -> None, False -> 0.0 (the paper's plain start), a
    number -> that radius in mean edge lengths (finite, >= 0)."""
    if x is True or (isinstance(x, str) and x == "auto"):
        return None
    if x is False:
        return 0.0
    if isinstance(x, (bool, np.bool_)):
        return None if x else 0.0
    if isinstance(x, (str, bytes)) or not isinstance(x, (int, float, np.integer, np.floating)):
        raise ValueError(f"exact_start must be True, 'auto', False or a radius in mean edge "
                         f"lengths, not {x!r}")
    r = float(x)
    if not np.isfinite(r) or r < 0:
        raise ValueError(f"exact_start radius must be finite and >= 0, not {r}")
    return r


def _max_distance(x: Any) -> float:
    """max_distance as a C double: None -> +inf; a real number >= 0 (+inf
    allowed). Strings, bools and other types are a TypeError (no silent
    float("2.5")); NaN and negative values a ValueError."""
    if x is None:
        return math.inf
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, numbers.Real):
        raise TypeError(f"max_distance must be a real number or None, got {type(x).__name__} {x!r}")
    d = float(x)
    if math.isnan(d):
        raise ValueError("max_distance is NaN; give a number >= 0, or None for no limit")
    if d < 0:
        raise ValueError(f"max_distance must be >= 0, got {d!r}")
    return d


# --------------------------------------------------------------------- mesh
class Mesh:
    """An immutable triangle mesh, validated and preprocessed by the C core.

    ``Mesh(V, F)``: ``V`` anything numpy turns into float64 ``(n, 3)``
    (lists, float32, Fortran order, strided views), ``F`` anything numpy
    turns into integer ``(m, 3)`` (0-based vertex ids; int64 accepted when the
    values fit). Both are copied. ``max_unfold_steps`` bounds the unfolding
    walk that finds the virtual edge of an obtuse corner (default 64).
    ``spokes=False`` puts memory first: the march then never builds its
    per-vertex update records (about 380 bytes per vertex, built on the
    first solve and kept with the mesh) and walks the faces instead, with
    the same results bit for bit and a march about 1.25x as long.

    ``Mesh(obj)``: any object with ``.vertices`` and ``.faces`` (a
    ``trimesh.Trimesh``, for one). ``Mesh.from_file(path)`` reads a file.

    Raises :class:`meshfmm.MeshError` (a ValueError) with the reason for wrong
    shapes, NaN or infinite coordinates, face indices out of range or a face
    that repeats a vertex. Boundaries, several components, unreferenced
    vertices, non-manifold edges and degenerate faces are accepted; copies of
    a face (its vertices again, in any order) are counted in ``info`` and
    stand aside, so that they make no edge non-manifold. A T-junction closed
    by a zero-area needle face is closed inside (the faces across the needle,
    every page of a non-manifold edge, split at its middle vertex), so
    distances and paths cross it; face ids,
    per-face costs and points stay the ones given (README, "Imperfect
    meshes").

    A Mesh may be used from several threads at once: each concurrent call
    gets its own solver workspace, and the C calls release the GIL. Free it
    early with :meth:`close` or a ``with`` block; otherwise it is freed when
    garbage-collected. :meth:`close` may be called while other threads
    compute: it refuses new calls at once (ValueError), waits for the calls
    in flight to end, then frees the C memory.

    Copies are independent: ``copy.copy``, ``copy.deepcopy`` and pickling
    rebuild the C mesh from ``vertices``, ``faces`` and the options, so
    closing one copy leaves the others working.
    """

    def __init__(self, V: Any, F: Any = None, *, max_unfold_steps: Optional[int] = None,
                 spokes: bool = True) -> None:
        self._ptr: Optional[int] = None
        if F is None:
            # Mesh(obj): anything with .vertices and .faces (a trimesh.Trimesh,
            # another Mesh, ...).
            if not (hasattr(V, "vertices") and hasattr(V, "faces")):
                raise TypeError(
                    "Mesh(V, F) needs faces F, or one object with .vertices and .faces "
                    f"(e.g. a trimesh.Trimesh); got {type(V).__name__} without them"
                )
            V, F = V.vertices, V.faces
        self._max_unfold_steps = max_unfold_steps
        self._spokes = _flag(spokes, "spokes")
        self._lock = threading.Lock()
        # _leave notifies it when the last call in flight ends (close waits on it)
        self._idle = threading.Condition(self._lock)
        self._active = 0  # calls in flight
        self._callers: Dict[int, int] = {}  # thread id -> its calls in flight
        self._closing = False  # close() was called: no new calls
        self._close_waiters = 0  # close() calls waiting for the calls in flight
        self._solvers: List[int] = []
        self._exact_solvers: List[int] = []
        #: Name of the backend that ran the last :meth:`distance_matrix` call
        #: ("serial", "threads" or "opencl"), None before the first.
        self.backend_used: Optional[str] = None
        #: Why the last "auto" call ran threads instead of OpenCL ("" when it
        #: did not fall back), from the library's fallback_reason.
        self.fallback_reason: str = ""

        Va = np.asarray(V)
        if Va.dtype.kind not in "iuf":
            raise MeshError(f"vertices must be numbers, got dtype {Va.dtype}")
        if Va.ndim != 2 or Va.shape[1] != 3:
            raise MeshError(f"vertices must have shape (n, 3), got {Va.shape}")
        Fa = np.asarray(F)
        if Fa.size == 0 and Fa.ndim <= 2 and Fa.dtype.kind == "f":
            Fa = Fa.astype(np.int32)  # an empty list: let the shape check speak
        if Fa.dtype.kind not in "iu":
            raise MeshError(f"faces must be integer vertex ids, got dtype {Fa.dtype}")
        if Fa.ndim != 2 or Fa.shape[1] != 3:
            raise MeshError(f"faces must have shape (m, 3), got {Fa.shape}")
        nv, nf = Va.shape[0], Fa.shape[0]
        if nv > _I32_MAX or nf > _I32_MAX:
            raise MeshError(f"too many vertices or faces for 32-bit indices ({nv}, {nf})")
        if nf and Fa.dtype.itemsize >= 4 and Fa.dtype != np.int32:
            lo, hi = Fa.min(), Fa.max()
            if lo < _I32_MIN or hi > _I32_MAX:
                bad = np.argwhere((Fa < _I32_MIN) | (Fa > _I32_MAX))[0]
                raise MeshError(
                    f"face {bad[0]} names vertex {Fa[bad[0], bad[1]]}, out of range "
                    f"(the mesh has {nv} vertices)"
                )
        # One private copy each, in the C types; read-only views go out.
        self._V = np.array(Va, dtype=np.float64, order="C", copy=True)
        self._F = np.array(Fa, dtype=np.int32, order="C", copy=True)
        self._V.setflags(write=False)
        self._F.setflags(write=False)

        opts = _lib.mfmm_mesh_options()
        _lib.mfmm_mesh_options_init(byref(opts))
        if max_unfold_steps is not None:
            opts.max_unfold_steps = _as_index(max_unfold_steps, "max_unfold_steps")
        opts.spokes = int(self._spokes)
        err = _lib.mfmm_error()
        out = ctypes.c_void_p()
        status = _lib.mfmm_mesh_create(
            _addr(self._V), nv, _addr(self._F), nf, byref(opts), byref(out), byref(err)
        )
        _lib.check(status, err, mesh=True)
        self._ptr = out.value
        self._nv = nv
        self._nf = nf
        info = _lib.mfmm_mesh_info()
        _lib.check(_lib.mfmm_mesh_get_info(self._ptr, byref(info)))
        self._info = MeshInfo(**{name: getattr(info, name) for name, _ in info._fields_
                                 if name != "struct_size"})
        self._opts_template = _lib.mfmm_solve_options()
        _lib.mfmm_solve_options_init(byref(self._opts_template))

    @classmethod
    def from_file(cls, path: Union[str, "os.PathLike[str]"], **kwargs: Any) -> "Mesh":
        """Reads a mesh file with :func:`load_mesh` (OBJ, OFF, PLY, STL) and
        builds a Mesh; keyword arguments go to the constructor."""
        V, F = load_mesh(path)
        return cls(V, F, **kwargs)

    # ---- copies and pickling: by vertices, faces and options, never the C pointer
    def _options(self) -> dict:
        return {"max_unfold_steps": self._max_unfold_steps, "spokes": self._spokes}

    def __reduce__(self) -> Tuple[Any, ...]:
        if self.closed:
            raise ValueError("cannot pickle or copy a closed mesh")
        return (_rebuild_mesh, (type(self), self._V, self._F, self._options()))

    def __copy__(self) -> "Mesh":
        # a new C mesh (the vertex and face arrays are read-only, so shared)
        if self.closed:
            raise ValueError("cannot copy a closed mesh")
        return _rebuild_mesh(type(self), self._V, self._F, self._options())

    def __deepcopy__(self, memo: dict) -> "Mesh":
        if self.closed:
            raise ValueError("cannot copy a closed mesh")
        return _rebuild_mesh(type(self), self._V.copy(), self._F.copy(), self._options())

    # ---- lifetime
    def close(self, timeout: Optional[float] = None) -> None:
        """Frees the C mesh and its solver workspaces. Idempotent.

        The mesh is closed to new calls at once: from then on every method
        that reaches the C library (:meth:`distance`, :meth:`distance_matrix`,
        :meth:`geodesic_path`, :meth:`memory`, ...) raises
        ``ValueError("the mesh is closed")``, from any thread. Calls that other
        threads already have in flight run to the end with their normal
        results; close() waits for them, then frees the memory and returns.
        (The Python-side properties -- ``vertices``, ``faces``, ``info``,
        ``n_vertices`` -- stay readable.)

        timeout: None (default) waits as long as the calls in flight take;
            a number of seconds >= 0 waits at most that long (0: not at all).
            When calls are still in flight then, TimeoutError is raised and
            the mesh stays closed to new calls; the last call in flight frees
            the memory as it returns (a later close() waits for that, and
            garbage collection frees whatever is left).

        Raises RuntimeError, and changes nothing, when the calling thread
        itself has a call on this mesh in flight (close() from a ``progress``
        callback, for one): it would wait for itself. The call in flight then
        goes on, and the mesh stays open. Safe to call from any thread, and
        from several at once.
        """
        if timeout is not None:
            if isinstance(timeout, (bool, np.bool_)) or not isinstance(timeout, numbers.Real):
                raise TypeError(f"timeout must be a number of seconds or None, got {timeout!r}")
            timeout = float(timeout)
            if math.isnan(timeout) or timeout < 0:
                raise ValueError(f"timeout must be >= 0 seconds or None, got {timeout!r}")
        freed = None
        busy = 0
        try:
            with self._idle:
                if self._ptr is None:
                    return
                if self._callers.get(threading.get_ident()):
                    raise RuntimeError(
                        "Mesh.close() called on a thread that has a call on this mesh in "
                        "flight (from a callback?): it would wait for itself; close the mesh "
                        "after the call returns"
                    )
                self._closing = True
                self._close_waiters += 1
                try:
                    self._idle.wait_for(lambda: self._active == 0, timeout)
                finally:
                    # also when the wait is interrupted (Ctrl-C): with calls still
                    # in flight, the last of them frees the mesh (_leave)
                    self._close_waiters -= 1
                    busy = self._active
                    if not busy:
                        freed = self._detach()
        finally:
            if freed is not None:
                _free(*freed)
        if busy:
            raise TimeoutError(
                f"Mesh.close(): {busy} call(s) on this mesh still in flight after {timeout} s; "
                "the mesh takes no new calls and is freed when they end"
            )

    def _detach(self) -> Tuple[Optional[int], List[int], List[int]]:
        """With the lock held and no call in flight: takes the C pointers off
        the mesh (which is then closed) for _free to release outside the lock."""
        ptr, self._ptr = self._ptr, None
        solvers, self._solvers = self._solvers, []
        exact, self._exact_solvers = self._exact_solvers, []
        self._closing = True
        return ptr, solvers, exact

    @property
    def closed(self) -> bool:
        """True once :meth:`close` has been called: the mesh takes no new
        calls. (After a close() that timed out, the C memory is freed a
        little later, when the calls in flight end.)"""
        return self._closing or self._ptr is None

    def __enter__(self) -> "Mesh":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __del__(self) -> None:
        # Never blocks: garbage collection may run it on any thread, at any
        # point. With no reference left no call can be in flight, so the lock
        # is free; if it is not, the memory is left to the process's end.
        try:
            lock = getattr(self, "_lock", None)
            if lock is None or getattr(self, "_ptr", None) is None:
                return
            if not lock.acquire(blocking=False):
                return
            try:
                if self._active or self._ptr is None:
                    return
                freed = self._detach()
            finally:
                lock.release()
            _free(*freed)
        except Exception:  # interpreter shutdown: the library may be gone
            pass

    def _enter(self) -> int:
        with self._lock:
            if self._ptr is None or self._closing:
                raise ValueError("the mesh is closed")
            self._active += 1
            me = threading.get_ident()
            self._callers[me] = self._callers.get(me, 0) + 1
            return self._ptr

    def _leave(self) -> None:
        freed = None
        with self._lock:
            self._active -= 1
            me = threading.get_ident()
            left = self._callers[me] - 1
            if left:
                self._callers[me] = left
            else:
                del self._callers[me]
            if self._active == 0 and self._closing:
                if self._close_waiters:
                    self._idle.notify_all()  # a waiting close() frees the mesh
                elif self._ptr is not None:
                    freed = self._detach()  # after a close() that timed out
        if freed is not None:
            _free(*freed)

    def _take_solver(self, mesh_ptr: int) -> int:
        try:
            return self._solvers.pop()  # atomic under the GIL
        except IndexError:
            out = ctypes.c_void_p()
            _lib.check(_lib.mfmm_solver_create(mesh_ptr, byref(out)))
            return out.value  # type: ignore[return-value]

    # ---- properties
    @property
    def n_vertices(self) -> int:
        """Number of vertices (unreferenced ones included)."""
        return self._nv

    @property
    def n_faces(self) -> int:
        """Number of faces."""
        return self._nf

    @property
    def vertices(self) -> np.ndarray:
        """The vertices, float64 (n_vertices, 3), read-only."""
        return self._V

    @property
    def faces(self) -> np.ndarray:
        """The faces, int32 (n_faces, 3), read-only."""
        return self._F

    @property
    def info(self) -> MeshInfo:
        """Diagnostics: counts of edges, boundary and non-manifold edges,
        components, unreferenced vertices, degenerate faces, obtuse corners,
        virtual edges and failed unfoldings; edge lengths; bounding-box
        diagonal (:class:`MeshInfo`)."""
        return self._info

    def memory(self) -> Dict[str, int]:
        """The bytes the mesh holds, array by array (mfmm_mesh_memory), as an
        ordered dict of name -> bytes; ``sum(mesh.memory().values())`` is the
        total. "spokes (once built)" and "exact tables (once built)" are 0
        until the first solve that builds them (then kept with the mesh);
        solver workspaces are not counted. Raises ValueError on a closed mesh."""
        ptr = self._enter()
        try:
            n = _lib.mfmm_mesh_memory(ptr, None, None, 0)
            names = (ctypes.c_char_p * n)()
            sizes = (ctypes.c_size_t * n)()
            n = _lib.mfmm_mesh_memory(ptr, names, sizes, n)
        finally:
            self._leave()
        return {names[i].decode(): int(sizes[i]) for i in range(n)}

    def __repr__(self) -> str:
        if self._ptr is None:
            state = "closed"
        elif self._closing:
            state = "closed, freed when its calls in flight end"
        else:
            state = f"{self._nv} vertices, {self._nf} faces"
        return f"<meshfmm.Mesh {state}>"

    # ---- distances
    def distance(
        self,
        sources: SourceLike,
        cost: Any = None,
        max_distance: Optional[float] = None,
        *,
        targets: Any = None,
        unfolding: bool = True,
        cost_location: Optional[str] = None,
        method: str = "fmm",
        exact_start: Any = True,
    ) -> np.ndarray:
        """Distance from the nearest source to every vertex, float64 (n_vertices,).

        sources: a vertex id, a :class:`SurfacePoint` (a point inside a face),
            or a sequence mixing those (an integer array is read as vertex ids).
        cost: the slowness F (``|grad T| = F``), per vertex (n_vertices,) or per
            face (n_faces,), finite and > 0; None for plain geodesic distance.
            Per face, F is constant on each face; per vertex, F is linear
            along each edge and local path (trapezoid means). When the mesh has as many vertices as faces, ``cost_location``
            ('vertex' or 'face') must say which.
        max_distance: stop marching past it; vertices beyond are +inf.
        targets: vertex ids; the march stops once all of them are settled
            (then only settled vertices are final, the rest may be +inf).
        unfolding: False uses plain stencils at obtuse corners (for comparison).
        exact_start: True (default): the march starts from the exact
            distances of the vertices within 7 mean edge lengths of each
            source, times sqrt(n_vertices / 40000) on larger meshes when
            max_distance is None (MFMM_EXACT_START_AUTO; about half the mean
            error of the paper's start); a
            number: that radius in mean edge lengths; False (or 0): the
            paper's plain start. With a cost, it applies where the cost is
            uniform around the source (else the plain start).
        method: "fmm" (the Fast Marching Method, the default) or "exact":
            exact polyhedral geodesic distances by window propagation
            (mfmm_solve_exact; no cost, targets or unfolding options).

        Unreached vertices (other components, beyond max_distance) are +inf.
        Raises ValueError (bad source, barycentric coordinates, cost, ...).
        """
        unfolding = _flag(unfolding, "unfolding")
        if method == "exact":
            if cost is not None or targets is not None or not unfolding or exact_start is not True:
                raise ValueError("method='exact' computes geodesic distance: it takes no cost, "
                                 "targets, unfolding or exact_start")
            return self._distance_exact(sources, max_distance)
        if method != "fmm":
            raise ValueError(f"method must be 'fmm' or 'exact', not {method!r}")
        if _is_int(sources):  # the common case, kept cheap (see bench_python.py)
            one = _lib.mfmm_source(_as_index(sources, "source"), -1)
            src_addr, n_src = ctypes.addressof(one), 1
        else:
            src = _source_records(sources)
            src_addr, n_src = _addr(src), src.shape[0]
        opts = None
        radius = _exact_start(exact_start)
        if (cost is not None or max_distance is not None or targets is not None
                or not unfolding or cost_location is not None or radius is not None):
            opts = _lib.mfmm_solve_options.from_buffer_copy(self._opts_template)
            c, loc = _cost_array(cost, cost_location, self._nv, self._nf)
            if c is not None:
                opts.cost = _addr(c)
                opts.cost_location = loc
            if max_distance is not None:
                opts.max_distance = _max_distance(max_distance)
            if targets is not None:
                t = _index_array(targets, "target")
                if t.shape[0] == 0:
                    raise ValueError("targets must hold at least one vertex id (None: every vertex)")
                opts.targets = _addr(t)
                opts.n_targets = t.shape[0]
            if not unfolding:
                opts.unfolding = 0
            if radius is not None:
                opts.exact_start_radius = radius
            opts = byref(opts)
        out = np.empty(self._nv, dtype=np.float64)
        err = _lib.mfmm_error()
        solver = None
        mesh_ptr = self._enter()
        try:
            solver = self._take_solver(mesh_ptr)
            status = _lib.mfmm_solve(solver, src_addr, n_src, opts, _addr(out), byref(err))
        finally:
            if solver is not None:
                self._solvers.append(solver)
            self._leave()
        if status:
            raise _lib.make_error(status, err)
        return out

    def _distance_exact(self, sources: SourceLike, max_distance: Optional[float]) -> np.ndarray:
        src = _source_records(sources)
        opts = _lib.mfmm_exact_options()
        _lib.mfmm_exact_options_init(byref(opts))
        if max_distance is not None:
            opts.max_distance = _max_distance(max_distance)
        out = np.empty(self._nv, dtype=np.float64)
        err = _lib.mfmm_error()
        info = _lib.mfmm_exact_info()
        # Ctrl-C stops a long solve: the library asks every few milliseconds
        interrupted: List[int] = []
        interrupt = type(opts.interrupt)(lambda user: 1 if interrupted else 0)
        opts.interrupt = interrupt
        solver = None
        mesh_ptr = self._enter()
        try:
            try:
                solver = self._exact_solvers.pop()
            except IndexError:
                ptr = ctypes.c_void_p()
                _lib.check(_lib.mfmm_exact_solver_create(mesh_ptr, byref(ptr)))
                solver = ptr.value
            with _sigint_as_flag(interrupted):
                status = _lib.mfmm_solve_exact(solver, _addr(src), src.shape[0], byref(opts),
                                               _addr(out), byref(info), byref(err))
        finally:
            if solver is not None:
                self._exact_solvers.append(solver)
            self._leave()
        if interrupted:
            raise KeyboardInterrupt
        if status:
            raise _lib.make_error(status, err)
        return out

    # ---- paths
    def geodesic_path(
        self,
        distances: Any,
        target: Union[int, SurfacePoint],
        *,
        sources: Optional[SourceLike] = None,
        cost: Any = None,
        cost_location: Optional[str] = None,
        max_points: Optional[int] = None,
        straighten: bool = True,
    ) -> GeodesicPath:
        """Backtracks from ``target`` along -grad T to the source (paper
        section 5) and returns a :class:`GeodesicPath`.

        distances: (n_vertices,) from :meth:`distance`.
        target: a vertex id or a :class:`SurfacePoint`.
        sources: the sources ``distances`` came from; the path then ends
            exactly at the nearest one. Without them it ends at a vertex
            where T is 0 (a vertex source); where T stops decreasing above 0
            (a face source, a source value > 0) it raises RuntimeError.
        cost, cost_location: the cost ``distances`` was solved with.
        max_points: most points the path may have (default: the library's).
        straighten: True (default): the traced path is replaced by the
            shortest polyline inside the strip of faces it crossed (unfolded,
            funnel algorithm; rerouted around a vertex where that is shorter),
            which removes the drift of the first-order T's gradient. With a
            per-face cost only runs of equal cost are straightened (border
            crossings stay); with a per-vertex cost nothing is. Never longer
            than the traced path. False: the raw section-5 path.

        Raises ValueError for an unreached (+inf) target, RuntimeError when
        tracing stalls or cannot reach a source; it never returns a path
        that ends elsewhere.
        """
        d = np.ascontiguousarray(distances, dtype=np.float64)
        if d.shape != (self._nv,):
            raise ValueError(f"distances must have shape ({self._nv},), got {d.shape}")
        tgt = _target_record(target)
        opts = _lib.mfmm_path_options()
        _lib.mfmm_path_options_init(byref(opts))
        if max_points is not None:
            opts.max_points = _as_index(max_points, "max_points")
        opts.straighten = 1 if _flag(straighten, "straighten") else 0
        src = None
        if sources is not None:
            src = _source_records(sources)
            opts.sources = _addr(src)
            opts.n_sources = src.shape[0]
        c, loc = _cost_array(cost, cost_location, self._nv, self._nf)
        if c is not None:
            opts.cost = _addr(c)
            opts.cost_location = loc
        capacity = 1024
        n = ctypes.c_int32(0)
        length = ctypes.c_double(0.0)
        weighted = ctypes.c_double(0.0)
        opts.weighted_length = ctypes.addressof(weighted)
        err = _lib.mfmm_error()
        mesh_ptr = self._enter()
        try:
            while True:
                buf = np.empty(capacity, dtype=_lib.SURFACE_POINT_DTYPE)
                status = _lib.mfmm_trace_path(
                    mesh_ptr, _addr(d), byref(tgt), byref(opts), _addr(buf), capacity,
                    byref(n), byref(length), byref(err),
                )
                if status == _lib.MFMM_ERR_BAD_COUNT and n.value > capacity:
                    capacity = n.value
                    continue
                break
        finally:
            self._leave()
        _lib.check(status, err)
        pts = buf[: n.value]
        return GeodesicPath(
            points=np.ascontiguousarray(pts["xyz"]),
            faces=np.ascontiguousarray(pts["face"]),
            barycentric=np.ascontiguousarray(pts["bary"]),
            length=float(length.value),
            weighted_length=float(weighted.value),
        )

    # ---- many sources
    def distance_matrix(
        self,
        sources: Any = None,
        backend: str = "auto",
        dtype: Any = "float32",
        out: Optional[np.ndarray] = None,
        *,
        max_distance: Optional[float] = None,
        cost: Any = None,
        cost_location: Optional[str] = None,
        unfolding: bool = True,
        exact_start: Any = True,
        n_threads: int = 0,
        memory_limit: int = 0,
        progress: Optional[Callable[[int, int], Any]] = None,
        targets: Any = None,
        sparse: bool = False,
        symmetric: bool = False,
    ) -> Any:
        """Distances from many vertex sources: row i holds the distances from
        ``sources[i]`` to every vertex (equal to :meth:`distance`'s), or to
        ``targets``.

        sources: vertex ids; None for all vertices in order (an N x N matrix).
        backend: "auto" (OpenCL on a usable device that is not a CPU, or
            that MESHFMM_OPENCL_DEVICE names; else threads, which run the same
            rows faster on a CPU),
            "opencl", "threads" or "serial". The backend that ran is stored in
            :attr:`backend_used`.
        dtype: "float32" or "float64" output (arithmetic is always float64).
        out: a preallocated C-contiguous writable array (a numpy.memmap
            works) of shape (len(sources) or n_vertices, n_vertices) and the
            given dtype, written in place and returned; None allocates one.
        max_distance, cost, cost_location, unfolding, exact_start: as in
            :meth:`distance` (every backend starts each row alike; OpenCL rows
            still equal the serial rows bit for bit).
        n_threads: threads for the threads backend, 0 for all cores.
        memory_limit: bytes the library may use for blocks in flight (0: default).
        progress: called as ``progress(rows_done, n_rows)`` as blocks of rows
            finish; an exception it raises (or Ctrl-C) stops the computation
            and propagates.
        targets: vertex ids (T of them, any order, duplicates allowed): the
            result is len(sources) x T, column j the distance to
            ``targets[j]``, and each row's march stops once all its targets
            are settled (landmark matrices cost far less than full rows).
            None: every vertex. Every backend, OpenCL included.
        sparse: return a ``scipy.sparse.csr_matrix`` of the finite entries
            only (with ``max_distance=r``: the pairs within r; the diagonal
            holds explicit zeros), sorted column ids; memory O(nnz), never
            S x N. Needs max_distance (a sparse full matrix is dense). Not on
            OpenCL ("auto" runs threads); ``out`` must be None.
        symmetric: for a square result (sources None, or sources equal to
            targets) return (D + D^T) / 2, symmetrised in place (no copy of
            D); dense only.

        After the call, :attr:`vertices_settled` holds the vertices the
        marches settled in all (the work done; 0 from OpenCL).

        Raises OpenCLError when backend="opencl" cannot run, ValueError for
        bad arguments.
        """
        if sources is None:
            src = None
            n_rows = self._nv
        else:
            src = _index_array(sources, "source")
            n_rows = src.shape[0]
            if n_rows == 0:
                raise ValueError("at least one source is needed")
        dt = np.dtype(dtype)
        if dt == np.float32:
            cdt = _lib.MFMM_FLOAT32
        elif dt == np.float64:
            cdt = _lib.MFMM_FLOAT64
        else:
            raise ValueError(f"dtype must be float32 or float64, got {dt}")
        if not isinstance(backend, str) or backend.lower() not in _lib.BACKENDS:
            raise ValueError(f"backend must be one of {sorted(_lib.BACKENDS)}, got {backend!r}")
        unfolding = _flag(unfolding, "unfolding")
        sparse = _flag(sparse, "sparse")
        symmetric = _flag(symmetric, "symmetric")
        tgt = None
        if targets is not None:
            tgt = _index_array(targets, "target")
            if tgt.shape[0] == 0:
                raise ValueError("targets must hold at least one vertex id (None: every vertex)")
            if int(tgt.min()) < 0 or int(tgt.max()) >= self._nv:
                raise ValueError(f"target ids must lie in [0, {self._nv})")
        width = self._nv if tgt is None else tgt.shape[0]
        if symmetric:
            if sparse:
                raise ValueError("symmetric=True is for dense results")
            square = (src is None and (tgt is None or np.array_equal(tgt, np.arange(self._nv)))) or (
                src is not None
                and np.array_equal(src, tgt if tgt is not None else np.arange(self._nv))
            )
            if not square:
                raise ValueError(
                    "symmetric=True needs a square result: sources None or equal to targets"
                )
        if sparse:
            if out is not None:
                raise ValueError("out is for dense results; sparse=True returns a csr_matrix")
            if max_distance is None or not np.isfinite(float(max_distance)):
                raise ValueError("sparse=True needs a finite max_distance (else every entry is stored)")
            out = np.empty((0, 0), dtype=dt)  # no dense buffer
        shape = (n_rows, width)
        if sparse:
            pass
        elif out is None:
            out = np.empty(shape, dtype=dt)
        else:
            if not isinstance(out, np.ndarray):
                raise TypeError(f"out must be a numpy array or memmap, got {type(out).__name__}")
            if out.shape != shape:
                raise ValueError(f"out must have shape {shape}, got {out.shape}")
            if out.dtype != dt:
                raise ValueError(f"out must have dtype {dt}, got {out.dtype}")
            if not out.flags.c_contiguous:
                raise ValueError("out must be C-contiguous")
            if not out.flags.writeable:
                raise ValueError("out must be writable")
        opts = _lib.mfmm_matrix_options()
        _lib.mfmm_matrix_options_init(byref(opts))
        opts.backend = _lib.BACKENDS[backend.lower()]
        opts.dtype = cdt
        c, loc = _cost_array(cost, cost_location, self._nv, self._nf)
        # The library writes rows into `out` while it still reads the sources
        # and the cost: an input that shares memory with `out` (a view of
        # it) would be overwritten mid-job (wrong rows, or vertex ids that
        # are garbage). Such inputs are copied first.
        if src is not None and np.may_share_memory(src, out):
            src = src.copy()
        if c is not None and np.may_share_memory(c, out):
            c = c.copy()
        if c is not None:
            opts.cost = _addr(c)
            opts.cost_location = loc
        if max_distance is not None:
            opts.max_distance = _max_distance(max_distance)
        opts.unfolding = 1 if unfolding else 0
        radius = _exact_start(exact_start)
        if radius is not None:
            opts.exact_start_radius = radius
        opts.n_threads = _as_index(n_threads, "n_threads")
        opts.memory_limit = _size(memory_limit, "memory_limit")
        opts.out = _addr(out) if out.size else None
        if tgt is not None:
            opts.targets = _addr(tgt)
            opts.n_targets = tgt.shape[0]
        if opts.backend == _lib.BACKENDS["auto"] and sparse:
            pass  # the library runs threads (OpenCL does dense rows only)
        elif opts.backend in (_lib.BACKENDS["auto"], _lib.BACKENDS["opencl"]):
            opts.opencl = _shared_opencl_context()

        caught: List[BaseException] = []
        interrupted: List[int] = []

        def on_rows(user: Any, first: int, n: int, rows: Any) -> int:
            # Returns the cancel code instead of raising: an exception escaping
            # a ctypes callback is printed ("Exception ignored on calling
            # ctypes callback function") and the job goes on.
            try:
                if interrupted:
                    return 1
                if progress is not None:
                    progress(first + n, n_rows)
                return 0
            except BaseException as exc:  # KeyboardInterrupt too: stop the library
                caught.append(exc)
                return 1

        pieces: List[Any] = []

        def on_sparse(user: Any, first: int, n: int, indptr: Any, indices: Any, values: Any) -> int:
            try:
                if interrupted:
                    return 1
                ip = np.ctypeslib.as_array(ctypes.cast(indptr, ctypes.POINTER(ctypes.c_int64)), (n + 1,))
                nnz = int(ip[n])
                if nnz:
                    ix = np.ctypeslib.as_array(
                        ctypes.cast(indices, ctypes.POINTER(ctypes.c_int32)), (nnz,)
                    ).copy()
                    ctype = ctypes.c_double if dt == np.float64 else ctypes.c_float
                    vals = np.ctypeslib.as_array(ctypes.cast(values, ctypes.POINTER(ctype)), (nnz,)).copy()
                else:
                    ix = np.empty(0, np.int32)
                    vals = np.empty(0, dt)
                pieces.append((ip.copy(), ix, vals))
                if progress is not None:
                    progress(first + n, n_rows)
                return 0
            except BaseException as exc:
                caught.append(exc)
                return 1

        if sparse:
            callback = _lib.mfmm_sparse_callback(on_sparse)
            opts.on_sparse = callback
        else:
            callback = _lib.mfmm_rows_callback(on_rows)
            opts.on_rows = callback
        err = _lib.mfmm_error()
        mesh_ptr = self._enter()
        try:
            with _sigint_as_flag(interrupted):
                status, call = _lib.distance_matrix(
                    mesh_ptr, None if src is None else _addr(src), n_rows, opts, err
                )
        finally:
            self._leave()
        if caught:
            raise caught[0]
        if interrupted:
            raise KeyboardInterrupt
        _lib.check(status, err)
        self.backend_used = call.backend_used
        self.fallback_reason = call.reason
        self.vertices_settled = call.vertices_settled
        if sparse:
            return _csr_from_pieces(pieces, (n_rows, width), dt)
        if symmetric:
            _symmetrize_in_place(out)
        return out

    def iter_distance_rows(
        self, sources: Any = None, block_rows: int = 256, **kwargs: Any
    ) -> Iterator[Tuple[int, np.ndarray]]:
        """Yields ``(first_row, block)``: dense blocks of at most ``block_rows``
        rows of :meth:`distance_matrix` (same keyword options: backend, dtype,
        targets, max_distance, cost, ...), in order, without the whole matrix
        in memory, for writing into h5py, Zarr or a database. ``progress`` is
        called as ``progress(rows_done, n_rows)`` over the whole job. Each
        block is one library call; closing the generator early (``break``)
        computes no further block."""
        if kwargs.get("sparse") or kwargs.get("symmetric") or kwargs.get("out") is not None:
            raise ValueError("iter_distance_rows yields dense blocks: no sparse, symmetric or out")
        if block_rows < 1:
            raise ValueError("block_rows must be >= 1")
        src = np.arange(self._nv, dtype=np.int32) if sources is None else _index_array(sources, "source")
        n_rows = src.shape[0]
        if n_rows == 0:
            raise ValueError("at least one source is needed")
        progress = kwargs.pop("progress", None)
        for first in range(0, n_rows, block_rows):
            part = src[first : first + block_rows]

            def prog(done: int, _total: int, first: int = first) -> Any:
                if progress is not None:
                    return progress(first + done, n_rows)
                return None

            block = self.distance_matrix(part, progress=prog, **kwargs)
            yield first, block


def _csr_from_pieces(pieces: List[Any], shape: Tuple[int, int], dt: Any) -> Any:
    """Joins the library's CSR blocks into one scipy.sparse.csr_matrix."""
    import scipy.sparse

    nnz = sum(int(p[0][-1]) for p in pieces)
    idx_dt = np.int32 if nnz < 2**31 else np.int64
    indptr = np.zeros(shape[0] + 1, dtype=idx_dt)
    indices = np.empty(nnz, dtype=np.int32)
    data = np.empty(nnz, dtype=dt)
    row = 0
    k = 0
    for ip, ix, vals in pieces:
        n = ip.shape[0] - 1
        m = int(ip[-1])
        indptr[row + 1 : row + n + 1] = ip[1:] + k
        indices[k : k + m] = ix
        data[k : k + m] = vals
        row += n
        k += m
    return scipy.sparse.csr_matrix((data, indices, indptr), shape=shape)


def _symmetrize_in_place(d: np.ndarray, tile: int = 256) -> None:
    """d <- (d + d^T) / 2 for a square array, tile by tile (O(tile^2) extra
    memory). Each pair (i, j), (j, i) gets the same value, (a + b) / 2 in
    the array's dtype."""
    n = d.shape[0]
    for i0 in range(0, n, tile):
        i1 = min(i0 + tile, n)
        for j0 in range(i0, n, tile):
            j1 = min(j0 + tile, n)
            a = d[i0:i1, j0:j1]
            m = (a + d[j0:j1, i0:i1].T) / 2
            d[i0:i1, j0:j1] = m
            d[j0:j1, i0:i1] = m.T


@contextlib.contextmanager
def _sigint_as_flag(flag: List[int]) -> Iterator[None]:
    """While a long C call runs on the main thread, Ctrl-C appends to `flag`
    instead of raising KeyboardInterrupt inside a ctypes callback (where
    Python can only print it and go on); the row callback then returns the
    cancel code and the caller raises one KeyboardInterrupt after the call.
    Leaves a handler other than Python's default one alone, and does nothing
    off the main thread (signals are only handled there)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    try:
        previous = signal.getsignal(signal.SIGINT)
    except (ValueError, OSError):  # pragma: no cover
        yield
        return
    if previous is not signal.default_int_handler:
        yield
        return

    def handler(signum: int, frame: Any) -> None:
        flag.append(signum)

    signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _free(ptr: Optional[int], solvers: List[int], exact: List[int]) -> None:
    """Releases what Mesh._detach took off a mesh."""
    for s in solvers:
        _lib.mfmm_solver_destroy(s)
    for s in exact:
        _lib.mfmm_exact_solver_destroy(s)
    if ptr is not None:
        _lib.mfmm_mesh_destroy(ptr)


def _rebuild_mesh(cls: type, V: np.ndarray, F: np.ndarray, options: dict) -> Mesh:
    """Unpickling and copying: a new, independent C mesh from V, F, options."""
    return cls(V, F, **options)


_opencl_lock = threading.Lock()
_opencl_context: Optional[ctypes.c_void_p] = None


def _shared_opencl_context() -> Optional[ctypes.c_void_p]:
    """The process's OpenCL context (device and built program), made on first
    use and reused by every distance_matrix call, so the kernel is built once
    per process (the C library itself keeps no global state). None when no
    device works: the library then reports why, or falls back under "auto"."""
    global _opencl_context
    with _opencl_lock:
        if _opencl_context is None:
            ptr = ctypes.c_void_p()
            err = _lib.mfmm_error()
            if _lib.mfmm_opencl_context_create(None, byref(ptr), byref(err)) != 0 or not ptr:
                return None
            _opencl_context = ptr
            atexit.register(_lib.mfmm_opencl_context_destroy, ptr)
        return _opencl_context


def _index_array(x: Any, what: str) -> np.ndarray:
    a = np.asarray(x)
    if a.ndim == 0:
        a = a.reshape(1)
    if a.size and a.dtype.kind not in "iu":
        raise TypeError(f"{what}s must be integer vertex ids, got dtype {a.dtype}")
    if a.ndim != 1:
        raise ValueError(f"{what}s must be 1-D, got shape {a.shape}")
    if a.size and (a.min() < _I32_MIN or a.max() > _I32_MAX):
        bad = a[(a < _I32_MIN) | (a > _I32_MAX)][0]
        raise ValueError(f"{what} {bad} is out of range (not a 32-bit index)")
    return np.ascontiguousarray(a, dtype=np.int32)


def load_mesh(path: Union[str, "os.PathLike[str]"]) -> Tuple[np.ndarray, np.ndarray]:
    """Reads a triangle mesh file (OBJ, OFF, PLY ascii or binary) with the
    library's readers and returns ``(V, F)``: float64 (nv, 3) and int32 (nf, 3).

    Raises FileNotFoundError / OSError when the file cannot be read and
    :class:`meshfmm.MeshError` when it is malformed."""
    fspath = os.fspath(path)
    if not os.path.exists(fspath):
        raise FileNotFoundError(errno.ENOENT, "no such mesh file", fspath)
    vp = ctypes.c_void_p()
    fp = ctypes.c_void_p()
    nv = ctypes.c_int32(0)
    nf = ctypes.c_int32(0)
    err = _lib.mfmm_error()
    status = _lib.mfmm_load_mesh(
        os.fsencode(fspath), byref(vp), byref(nv), byref(fp), byref(nf), byref(err)
    )
    try:
        _lib.check(status, err, context=str(fspath))
        V = np.empty((nv.value, 3), dtype=np.float64)
        F = np.empty((nf.value, 3), dtype=np.int32)
        if V.size:
            ctypes.memmove(_addr(V), vp.value, V.nbytes)
        if F.size:
            ctypes.memmove(_addr(F), fp.value, F.nbytes)
    finally:
        _lib.mfmm_free(vp)
        _lib.mfmm_free(fp)
    return V, F
