"""The Mesh class and load_mesh: the Python face of libmeshfmm.

Mesh is a thin facade: argument coercion lives in :mod:`meshfmm._args`, the
matrix paths in :mod:`meshfmm._dense` and :mod:`meshfmm._sparse` over the row
job of :mod:`meshfmm._rows`; all foreign calls go through :mod:`meshfmm._lib`.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import math
import numbers
import os
import threading
import warnings
from ctypes import byref
from typing import Any, Dict, Iterator, List, Optional, Tuple, Union

import numpy as np

from . import _args, _dense, _guards, _isolines, _lib, _rows, _sparse
from ._interrupt import sigint_as_flag
from ._points import Points, combine
from ._types import (GeodesicPath, Isoline, MatrixInfo, MeshInfo, MeshWarning, SourceLike,
                     SurfacePoint)
from ._weld import Weld

__all__ = ["Mesh", "MeshInfo", "SurfacePoint", "GeodesicPath", "MatrixInfo", "Isoline",
           "MeshWarning", "load_mesh"]


class Mesh:
    """An immutable triangle mesh, validated and preprocessed by the C core.

    ``Mesh(V, F)`` builds it from arrays; ``Mesh(obj)`` from any object with
    ``.vertices`` and ``.faces`` (a ``trimesh.Trimesh``, for one);
    :meth:`from_file` reads a file. V and F are copied.

    Boundaries, several components, unreferenced vertices, non-manifold
    edges and degenerate faces are accepted. Copies of a face (its vertices
    again, in any order) are counted in :attr:`info` and stand aside, so
    that they make no edge non-manifold. A T-junction closed by a zero-area
    needle face is closed inside (the faces across the needle split at its
    middle vertex), so distances and paths cross it; face ids, per-face
    costs and points stay the ones given (docs/imperfect-meshes.md).

    A Mesh may be used from several threads at once: each concurrent call
    gets its own solver workspace, the C calls release the GIL, and every
    result (a :class:`MatrixInfo` included) belongs to its call. Free it
    early with :meth:`close` or a ``with`` block; otherwise it is freed when
    garbage-collected. Copies (``copy.copy``, ``copy.deepcopy``, pickling)
    rebuild the C mesh from ``vertices``, ``faces`` and the options, so
    closing one leaves the others working.

    Parameters
    ----------
    V : array_like, shape (n, 3)
        Vertex coordinates; anything numpy turns into float64 (lists,
        float32, Fortran order, strided views). Or an object with
        ``.vertices`` and ``.faces`` when F is None.
    F : array_like of int, shape (m, 3), optional
        Faces as 0-based vertex ids; any integer dtype whose values fit
        int32.
    max_unfold_steps : int, optional
        Bound of the unfolding walk that finds the virtual edge of an obtuse
        corner (default 64).
    spokes : bool
        True (default): the march builds per-vertex update records (about
        400 bytes per vertex, kept with the mesh) once the mesh's solves
        have marched over it 8 times without them, or for a distance
        matrix of 8 rows or more.
        False puts memory first: the march walks the faces instead, with the
        same results bit for bit and a march 1.25-1.6x as long.
    weld : bool
        False (default): every vertex is its own, and vertices at the same
        position (texture seams, unmerged STL corners) cut the surface; a
        :class:`MeshWarning` says so. True: vertices of exactly equal
        position are welded into one (faces whose corners weld together are
        dropped); the methods still take and return the vertex and face ids
        given (``vertices``, ``faces``, ``n_vertices`` are the input's), and
        every per-vertex result holds, for each input vertex, the value of
        its welded vertex. :attr:`info` and :meth:`memory` describe the
        welded surface; :attr:`weld_map` maps input vertices to it.

    Warns
    -----
    MeshWarning
        With ``weld=False``, when vertices coincide: it names their count,
        the components with and without welding, and ``weld=True``.

    Raises
    ------
    MeshError
        (a ValueError) with the reason, for wrong shapes, NaN or infinite
        coordinates, face indices out of range or a face that repeats a
        vertex.
    TypeError
        ``Mesh(obj)`` with an object lacking ``.vertices`` or ``.faces``.
    """

    def __init__(self, V: Any, F: Any = None, *, max_unfold_steps: Optional[int] = None,
                 spokes: bool = True, weld: bool = False) -> None:
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
        self._spokes = _args.flag(spokes, "spokes")
        self._weld_opt = _args.flag(weld, "weld")
        self._lock = threading.Lock()
        # _leave notifies it when the last call in flight ends (close waits on it)
        self._idle = threading.Condition(self._lock)
        self._active = 0  # calls in flight
        self._callers: Dict[int, int] = {}  # thread id -> its calls in flight
        self._closing = False  # close() was called: no new calls
        self._close_waiters = 0  # close() calls waiting for the calls in flight
        self._solvers: List[int] = []
        self._exact_solvers: List[int] = []

        # _V_in, _F_in: as given (the public arrays); _V, _F: what the C mesh
        # is built from (welded when weld=True)
        self._V_in, self._F_in = _args.mesh_arrays(V, F)
        self._weld: Optional[Weld] = None
        if self._weld_opt and Weld.applicable(self._V_in, self._F_in):
            self._weld = Weld(self._V_in, self._F_in)
            self._V, self._F = self._weld.V, self._weld.F
            self._V.setflags(write=False)
            self._F.setflags(write=False)
        else:
            self._V, self._F = self._V_in, self._F_in
        nv, nf = self._V.shape[0], self._F.shape[0]

        opts = _lib.mfmm_mesh_options()
        _lib.mfmm_mesh_options_init(byref(opts))
        if max_unfold_steps is not None:
            opts.max_unfold_steps = _args.index(max_unfold_steps, "max_unfold_steps")
        opts.spokes = int(self._spokes)
        err = _lib.mfmm_error()
        out = ctypes.c_void_p()
        status = _lib.mfmm_mesh_create(
            _args.addr(self._V), nv, _args.addr(self._F), nf, byref(opts), byref(out), byref(err)
        )
        _lib.check(status, err, mesh=True)
        self._ptr = out.value
        self._nv = nv
        self._nf = nf
        info = _lib.mfmm_mesh_info()
        _lib.check(_lib.mfmm_mesh_get_info(self._ptr, byref(info)))
        self._info = MeshInfo(**{name: getattr(info, name) for name, _ in info._fields_
                                 if name != "struct_size"})
        if self._info.n_coincident_vertices and self._weld is None:
            i = self._info
            warnings.warn(
                f"{i.n_coincident_vertices} coincident vertices (at the position of another "
                "vertex: texture seams or unmerged STL corners) cut the surface, which falls "
                f"into {i.n_components} component(s) ({i.n_welded_components} once welded); "
                "distances and paths do not cross the cuts. Mesh(V, F, weld=True) welds them.",
                MeshWarning, stacklevel=2)
        self._opts_template = _lib.mfmm_solve_options()
        _lib.mfmm_solve_options_init(byref(self._opts_template))

    @classmethod
    def from_file(cls, path: Union[str, "os.PathLike[str]"], **kwargs: Any) -> "Mesh":
        """Reads a mesh file and builds a Mesh.

        Parameters
        ----------
        path : str or os.PathLike
            An OBJ, OFF, PLY (ascii or binary) or STL file, read by
            :func:`load_mesh`.
        **kwargs
            The constructor's keyword options (``max_unfold_steps``,
            ``spokes``).

        Returns
        -------
        Mesh

        Raises
        ------
        FileNotFoundError, OSError
            The file cannot be read.
        MeshError
            The file is malformed or the mesh is refused.
        """
        V, F = load_mesh(path)
        return cls(V, F, **kwargs)

    # ---- copies and pickling: by vertices, faces and options, never the C pointer
    def _options(self) -> dict:
        return {"max_unfold_steps": self._max_unfold_steps, "spokes": self._spokes,
                "weld": self._weld_opt}

    @property
    def options(self) -> Dict[str, Any]:
        """The constructor's keyword options, ``max_unfold_steps`` (None: the
        default), ``spokes`` and ``weld``: ``Mesh(V, F, **mesh.options)``
        builds an equal mesh (a new dict each time)."""
        return self._options()

    def __reduce__(self) -> Tuple[Any, ...]:
        if self.closed:
            raise ValueError("cannot pickle or copy a closed mesh")
        return (_rebuild_mesh, (type(self), self._V_in, self._F_in, self._options()))

    def __copy__(self) -> "Mesh":
        # a new C mesh (the vertex and face arrays are read-only, so shared)
        if self.closed:
            raise ValueError("cannot copy a closed mesh")
        return _rebuild_mesh(type(self), self._V_in, self._F_in, self._options())

    def __deepcopy__(self, memo: dict) -> "Mesh":
        if self.closed:
            raise ValueError("cannot copy a closed mesh")
        return _rebuild_mesh(type(self), self._V_in.copy(), self._F_in.copy(), self._options())

    # ---- lifetime
    def close(self, timeout: Optional[float] = None) -> None:
        """Frees the C mesh and its solver workspaces. Idempotent.

        The mesh is closed to new calls at once: from then on every method
        that reaches the C library (:meth:`distance`,
        :meth:`distance_matrix`, :meth:`geodesic_path`, :meth:`memory`, ...)
        raises ``ValueError("the mesh is closed")``, from any thread. Calls
        other threads already have in flight run to the end with their
        normal results; close() waits for them, then frees the memory. The
        Python-side properties (``vertices``, ``faces``, ``info``,
        ``n_vertices``) stay readable. Safe to call from any thread, and
        from several at once.

        Parameters
        ----------
        timeout : float, optional
            None (default) waits as long as the calls in flight take; a
            number of seconds >= 0 waits at most that long (0: not at all).

        Raises
        ------
        TimeoutError
            Calls are still in flight after `timeout`. The mesh stays closed
            to new calls and the last call in flight frees the memory as it
            returns (a later close() waits for that).
        RuntimeError
            The calling thread itself has a call on this mesh in flight
            (close() from a ``progress`` callback): it would wait for
            itself. Nothing changes; the mesh stays open.
        TypeError, ValueError
            `timeout` is not a number, or is NaN or negative.
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

    @contextlib.contextmanager
    def _in_call(self) -> Iterator[int]:
        """The C mesh pointer for one call in flight (ValueError when the mesh
        is closed); close() waits for the call to leave."""
        ptr = self._enter()
        try:
            yield ptr
        finally:
            self._leave()

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
        """Number of vertices (unreferenced ones included), as given."""
        return int(self._V_in.shape[0])

    @property
    def n_faces(self) -> int:
        """Number of faces, as given."""
        return int(self._F_in.shape[0])

    @property
    def vertices(self) -> np.ndarray:
        """The vertices as given, float64 (n_vertices, 3), read-only."""
        return self._V_in

    @property
    def faces(self) -> np.ndarray:
        """The faces as given, int32 (n_faces, 3), read-only."""
        return self._F_in

    @property
    def weld_map(self) -> Optional[np.ndarray]:
        """With ``weld=True``: int32 (n_vertices,), the welded vertex of
        each input vertex (welded vertices are numbered by their lowest
        input id, in input order); None without welding."""
        return None if self._weld is None else self._weld.to_welded.copy()

    @property
    def info(self) -> MeshInfo:
        """Diagnostics: counts of edges, boundary and non-manifold edges,
        components, unreferenced vertices, degenerate faces, obtuse corners,
        virtual edges and failed unfoldings; edge lengths; bounding-box
        diagonal (:class:`MeshInfo`)."""
        return self._info

    def memory(self) -> Dict[str, int]:
        """The bytes the mesh holds, array by array (``mfmm_mesh_memory``).

        "spokes (once built)" and "exact tables (once built)" are 0 until
        solves build them (then kept with the mesh; the exact tables grow
        with the regions the exact start has solved); solver workspaces
        are not counted.

        Returns
        -------
        dict of str to int
            Array name -> bytes, in the library's order;
            ``sum(mesh.memory().values())`` is the total.

        Raises
        ------
        ValueError
            The mesh is closed.
        """
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
            state = f"{self.n_vertices} vertices, {self.n_faces} faces"
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
        at: Any = None,
        progress: bool = False,
    ) -> np.ndarray:
        """Distance from the nearest source to every vertex, or to given
        points.

        Parameters
        ----------
        sources : int, SurfacePoint, or sequence of those
            A vertex id, a :class:`SurfacePoint` (a point inside a face), or
            a sequence mixing those; an integer array is read as vertex ids.
        cost : array_like of float, shape (n_vertices,) or (n_faces,), optional
            The slowness F (``|grad T| = F``), finite and > 0; None for plain
            geodesic distance. Per face, F is constant on each face; per
            vertex, F is linear along each edge and local path (trapezoid
            means).
        max_distance : float, optional
            Stop marching past it; vertices beyond are +inf.
        targets : array_like of int, optional
            Vertex ids; the march stops once all of them are settled (then
            only settled vertices are final, the rest may be +inf).
        unfolding : bool
            False uses plain stencils at obtuse corners (for comparison).
        cost_location : {"vertex", "face"}, optional
            Where ``cost`` lives; needed only when the mesh has as many
            vertices as faces.
        method : {"fmm", "windows", "exact"}
            "fmm" (default): the Fast Marching Method from the exact start.
            "windows": window propagation keeping two windows per
            half-edge (``MFMM_METHOD_WINDOWS``; the documentation's page
            "The windows method"): more accurate than "fmm", never below
            the geodesic distance, exact where the surface unfolds flat, at
            several times its time; with a cost, windows within faces of
            one cost and the march's update where the cost changes
            (unfolding and exact_start do not apply). "exact": exact polyhedral geodesic
            distances by window propagation (``mfmm_solve_exact``), without
            cost, targets, unfolding or exact_start options.
        exact_start : bool, "auto" or float
            True or "auto" (default): the march starts from the exact
            distances of the vertices within 7 mean edge lengths of each
            source, times sqrt(n_vertices / 40000) on larger meshes when
            max_distance is None (``MFMM_EXACT_START_AUTO``; about half the
            mean error of the paper's start). A number: that radius in mean
            edge lengths. False (or 0): the paper's plain start. With a
            cost, it applies where the cost is uniform around the source.
        at : int, SurfacePoint, or sequence of those, optional
            Points to return the distances of instead of every vertex's: a
            vertex id gives its vertex's distance; a point in a face the
            value the path tracer reads there (:meth:`geodesic_path`), the
            linear interpolant of the face's corners, sum of ``b_k * d_k``
            over the corners with ``b_k > 0`` (+inf when one of them is
            unreached). The march stops once those corners are settled.
        progress : bool
            True: with ``method="exact"`` (which can run minutes on millions
            of vertices), the time so far on standard error while it runs.

        Returns
        -------
        numpy.ndarray, float64, shape (n_vertices,) or (P,)
            The distances (at the P points of ``at`` when given); unreached
            vertices (other components, beyond max_distance) are +inf.

        Raises
        ------
        ValueError
            A bad source, barycentric coordinates, cost, radius or option
            combination; the mesh is closed.
        TypeError
            An argument of the wrong type (a max_distance that is not a
            number, a flag that is not a bool, ...).
        KeyboardInterrupt
            Ctrl-C during ``method="exact"``.
        """
        pts = None
        if at is not None:
            pts = Points.parse(at, "at", self.n_vertices, self.n_faces)
        if self._weld is not None:
            w = self._weld
            sources = w.sources(sources)
            cost, cost_location = w.cost(cost, cost_location)
            if targets is not None:
                targets = w.vertices(targets, "target")
            if pts is not None:
                pts = pts.welded(w, "at")
        if pts is not None and method != "exact":
            stop = pts.columns(self._F)[0]
            targets = stop if targets is None else np.concatenate(
                [_args.index_array(targets, "target"), stop])
        bar = None
        if _args.flag(progress, "progress") and method == "exact":
            bar = _guards.ProgressBar("exact solve")
        try:
            d = self._distance(sources, cost, max_distance, targets=targets,
                               unfolding=unfolding, cost_location=cost_location, method=method,
                               exact_start=exact_start, bar=bar)
        finally:
            if bar is not None:
                bar.close()
        if pts is not None:
            return pts.values(d, self._F)
        return d if self._weld is None else self._weld.per_vertex(d)

    def _distance(self, sources: Any, cost: Any, max_distance: Optional[float], *,
                  targets: Any, unfolding: Any, cost_location: Optional[str], method: str,
                  exact_start: Any, bar: Any = None) -> np.ndarray:
        """:meth:`distance` in the C mesh's vertex ids (welded ones)."""
        unfolding = _args.flag(unfolding, "unfolding")
        if method == "exact":
            if cost is not None or targets is not None or not unfolding or exact_start is not True:
                raise ValueError("method='exact' computes geodesic distance: it takes no cost, "
                                 "targets, unfolding or exact_start")
            return self._distance_exact(sources, max_distance, bar)
        windows = _args.method(method) == _lib.MFMM_METHOD_WINDOWS
        if _args.is_int(sources):  # the common case, kept cheap (bench/suite/bench_python.py)
            one = _lib.mfmm_source(_args.index(sources, "source"), -1)
            src_addr, n_src = ctypes.addressof(one), 1
        else:
            src = _args.source_records(sources)
            src_addr, n_src = _args.addr(src), src.shape[0]
        opts = None
        radius = _args.exact_start_radius(exact_start)
        if (cost is not None or max_distance is not None or targets is not None
                or not unfolding or cost_location is not None or radius is not None or windows):
            opts = _lib.mfmm_solve_options.from_buffer_copy(self._opts_template)
            c, loc = _args.cost_array(cost, cost_location, self._nv, self._nf)
            if c is not None:
                opts.cost = _args.addr(c)
                opts.cost_location = loc
            if max_distance is not None:
                opts.max_distance = _args.max_distance(max_distance)
            if targets is not None:
                t = _args.index_array(targets, "target")
                if t.shape[0] == 0:
                    raise ValueError("targets must hold at least one vertex id (None: every vertex)")
                opts.targets = _args.addr(t)
                opts.n_targets = t.shape[0]
            if not unfolding:
                opts.unfolding = 0
            if radius is not None:
                opts.exact_start_radius = radius
            if windows:
                opts.method = _lib.MFMM_METHOD_WINDOWS
            opts = byref(opts)
        out = np.empty(self._nv, dtype=np.float64)
        err = _lib.mfmm_error()
        solver = None
        mesh_ptr = self._enter()
        try:
            solver = self._take_solver(mesh_ptr)
            status = _lib.mfmm_solve(solver, src_addr, n_src, opts, _args.addr(out), byref(err))
        finally:
            if solver is not None:
                self._solvers.append(solver)
            self._leave()
        if status:
            raise _lib.make_error(status, err)
        return out

    def _distance_exact(self, sources: SourceLike, max_distance: Optional[float],
                        bar: Any = None) -> np.ndarray:
        src = _args.source_records(sources)
        opts = _lib.mfmm_exact_options()
        _lib.mfmm_exact_options_init(byref(opts))
        if max_distance is not None:
            opts.max_distance = _args.max_distance(max_distance)
        out = np.empty(self._nv, dtype=np.float64)
        err = _lib.mfmm_error()
        info = _lib.mfmm_exact_info()
        # Ctrl-C stops a long solve: the library asks every few milliseconds
        interrupted: List[int] = []
        def ask(user: Any) -> int:
            if bar is not None:
                bar.tick()
            return 1 if interrupted else 0

        interrupt = type(opts.interrupt)(ask)
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
            with sigint_as_flag(interrupted):
                status = _lib.mfmm_solve_exact(solver, _args.addr(src), src.shape[0], byref(opts),
                                               _args.addr(out), byref(info), byref(err))
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
        section 5).

        Parameters
        ----------
        distances : array_like of float, shape (n_vertices,)
            Distances from :meth:`distance`.
        target : int or SurfacePoint
            Where the path starts: a vertex id or a point inside a face.
        sources : int, SurfacePoint, or sequence of those, optional
            The sources ``distances`` came from; the path then ends exactly
            at the nearest one. Without them it ends at a vertex where T is
            0 (a vertex source).
        cost, cost_location : optional
            The cost ``distances`` was solved with, as in :meth:`distance`.
        max_points : int, optional
            Most points the path may have (default: the library's).
        straighten : bool
            True (default): the traced path is replaced by the shortest
            polyline inside the strip of faces it crossed (unfolded, funnel
            algorithm; rerouted around a vertex where that is shorter),
            which removes the drift of the first-order T's gradient. With a
            per-face cost only runs of equal cost are straightened; with a
            per-vertex cost nothing is. Never longer than the traced path.
            False: the raw section-5 path.

        Returns
        -------
        GeodesicPath
            From the target (point 0) to the source.

        Raises
        ------
        ValueError
            An unreached (+inf) target, distances of the wrong shape, a bad
            target or source.
        RuntimeError
            Tracing stalls or cannot reach a source (without ``sources``,
            where T stops decreasing above 0: a face source, a source value
            > 0). It never returns a path that ends elsewhere.
        """
        if self._weld is not None:
            w = self._weld
            distances = w.distances_in(distances)
            target = w.point(target, "target")
            if sources is not None:
                sources = w.sources(sources)
            cost, cost_location = w.cost(cost, cost_location)
        d = np.ascontiguousarray(distances, dtype=np.float64)
        if d.shape != (self._nv,):
            raise ValueError(f"distances must have shape ({self._nv},), got {d.shape}")
        tgt = _args.target_record(target)
        opts = _lib.mfmm_path_options()
        _lib.mfmm_path_options_init(byref(opts))
        if max_points is not None:
            opts.max_points = _args.index(max_points, "max_points")
        opts.straighten = 1 if _args.flag(straighten, "straighten") else 0
        src = None
        if sources is not None:
            src = _args.source_records(sources)
            opts.sources = _args.addr(src)
            opts.n_sources = src.shape[0]
        c, loc = _args.cost_array(cost, cost_location, self._nv, self._nf)
        if c is not None:
            opts.cost = _args.addr(c)
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
                    mesh_ptr, _args.addr(d), byref(tgt), byref(opts), _args.addr(buf), capacity,
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
        faces = np.ascontiguousarray(pts["face"])
        if self._weld is not None:
            faces = self._weld.faces_out(faces)
        return GeodesicPath(
            points=np.ascontiguousarray(pts["xyz"]),
            faces=faces,
            barycentric=np.ascontiguousarray(pts["bary"]),
            length=float(length.value),
            weighted_length=float(weighted.value),
        )

    # ---- workflow tools
    def path(
        self,
        source: Union[int, SurfacePoint],
        target: Union[int, SurfacePoint],
        *,
        method: str = "fmm",
        cost: Any = None,
        cost_location: Optional[str] = None,
        exact_start: Any = True,
        max_points: Optional[int] = None,
        straighten: bool = True,
    ) -> GeodesicPath:
        """The shortest path from ``source`` to ``target`` in one call.

        Solves from the source (:meth:`distance`), traces back from the
        target (:meth:`geodesic_path` with ``sources=[source]``) and returns
        the polyline reversed: point 0 is the source, the last point the
        target. Equal, point for point, to the reversed two-call path.

        Parameters
        ----------
        source, target : int or SurfacePoint
            Vertex ids or points inside faces.
        method : {"fmm", "windows", "exact"}
            The distances the path descends (:meth:`distance`; "exact"
            takes no cost).
        cost, cost_location, exact_start
            As in :meth:`distance`.
        max_points, straighten
            As in :meth:`geodesic_path`.

        Returns
        -------
        GeodesicPath
            From the source (point 0) to the target; ``faces[i]`` (i > 0)
            is the face the segment from point i-1 runs through and
            ``barycentric[i]`` point i's coordinates in it.

        Raises
        ------
        ValueError
            A bad source or target, or a target the source does not reach.
        RuntimeError
            Tracing stalls (as :meth:`geodesic_path`).
        """
        d = self.distance(source, cost, method=method, cost_location=cost_location,
                          exact_start=exact_start)
        back = self.geodesic_path(d, target, sources=[source], cost=cost,
                                  cost_location=cost_location, max_points=max_points,
                                  straighten=straighten)
        return _reverse_path(back, self._V_in, self._F_in)

    def farthest_point_sampling(
        self,
        k: int,
        start: int = 0,
        *,
        cost: Any = None,
        cost_location: Optional[str] = None,
        unfolding: bool = True,
        exact_start: Any = True,
        method: str = "fmm",
        return_radii: bool = False,
        return_distances: bool = False,
    ) -> Any:
        """Geodesic farthest-point sampling (landmarks): k vertices, the
        first ``start``, each next the vertex farthest from those chosen
        (ties to the lowest vertex id).

        One solver and a running minimum (``mfmm_farthest_points``): each
        march stops at the current farthest distance, past which it cannot
        lower the minimum, so later points cost a fraction of a full solve;
        the points equal those of a loop of full :meth:`distance` solves.
        Vertices in no face are never chosen; a component not yet reached
        is farther than any reached vertex, so each component gets a point
        before any gets a second.

        Parameters
        ----------
        k : int
            Points to choose, 1 <= k <= the vertices in faces.
        start : int
            The first point, a vertex in a face.
        cost, cost_location, unfolding, exact_start
            As in :meth:`distance`.
        method : {"fmm", "windows"}
            The solve of each point (:meth:`distance`): "fmm" (default) or
            "windows" (unfolding and exact_start do not apply).
            The points equal those of a loop of ``distance(...,
            method=method)`` solves. "exact" is not offered here.
        return_radii : bool
            Also return float64 (k,): each point's distance to the points
            before it when chosen (+inf for the first): the covering radius
            of the points before, non-increasing.
        return_distances : bool
            Also return float64 (n_vertices,): each vertex's distance to its
            nearest point.

        Returns
        -------
        points : numpy.ndarray, int32 (k,)
            Vertex ids, in the order chosen (with ``weld=True``: the lowest
            input id of each welded vertex).
        radii, distances : numpy.ndarray
            Only when asked for, in that order.

        Raises
        ------
        ValueError
            k out of range, a start out of range or in no face, a bad cost,
            a method other than "fmm" or "windows".
        """
        m = _args.solve_method(method, cost, "farthest_point_sampling")
        k = _args.index(k, "k")
        start = _args.index(start, "start")
        if not (0 <= start < self.n_vertices):
            raise ValueError(f"start vertex {start} is out of range (the mesh has "
                             f"{self.n_vertices} vertices)")
        return_radii = _args.flag(return_radii, "return_radii")
        return_distances = _args.flag(return_distances, "return_distances")
        if self._weld is not None:
            start = int(self._weld.to_welded[start])
            cost, cost_location = self._weld.cost(cost, cost_location)
        opts = _lib.mfmm_solve_options.from_buffer_copy(self._opts_template)
        c, loc = _args.cost_array(cost, cost_location, self._nv, self._nf)
        if c is not None:
            opts.cost = _args.addr(c)
            opts.cost_location = loc
        opts.unfolding = 1 if _args.flag(unfolding, "unfolding") else 0
        radius = _args.exact_start_radius(exact_start)
        if radius is not None:
            opts.exact_start_radius = radius
        opts.method = m
        if k < 1:
            raise ValueError(f"k must be >= 1, got {k}")
        points = np.empty(k, dtype=np.int32)
        radii = np.empty(k, dtype=np.float64)
        dist = np.empty(self._nv, dtype=np.float64) if return_distances else None
        err = _lib.mfmm_error()
        solver = None
        mesh_ptr = self._enter()
        try:
            solver = self._take_solver(mesh_ptr)
            status = _lib.mfmm_farthest_points(
                solver, start, k, byref(opts), _args.addr(points), _args.addr(radii),
                None if dist is None else _args.addr(dist), byref(err))
        finally:
            if solver is not None:
                self._solvers.append(solver)
            self._leave()
        _lib.check(status, err)
        if self._weld is not None:
            points = self._weld.rep[points].astype(np.int32)
            if dist is not None:
                dist = self._weld.per_vertex(dist)
        out: List[Any] = [points]
        if return_radii:
            out.append(radii)
        if return_distances:
            out.append(dist)
        return out[0] if len(out) == 1 else tuple(out)

    def voronoi_labels(self, sources: SourceLike, distances: Any = None,
                       **kwargs: Any) -> np.ndarray:
        """Geodesic Voronoi labels: which source each vertex's distance comes
        from.

        One pass over the vertices' edges after the solve
        (``mfmm_voronoi_labels``): a source's own vertex takes that source;
        any other vertex the label of its lower neighbour u minimizing
        ``d(u) + |uv|``. Inside a cell this is the argmin over the
        single-source fields; within about an edge of a cell's border, where
        two sources' distances differ by less than the march's error,
        either may be given (ties of exactly equal distance: the lower
        source index where a source decides).

        Parameters
        ----------
        sources : int, SurfacePoint, or sequence of those
            The sources, as for :meth:`distance`; labels index this list.
        distances : array_like of float, shape (n_vertices,), optional
            The distances from these sources (:meth:`distance` with the same
            sources); None solves them.
        **kwargs
            :meth:`distance`'s options for that solve (cost, method: "fmm",
            "windows" or "exact", ...).

        Returns
        -------
        numpy.ndarray, int32 (n_vertices,)
            The index in ``sources`` of each vertex's nearest source; -1
            where the distance is +inf.
        """
        src = _args.source_records(sources)
        if distances is None:
            d = self.distance(src, **kwargs)
        elif kwargs:
            raise ValueError("options are for the solve: give them without distances")
        else:
            d = distances
        if self._weld is not None:
            src = self._weld.sources(src)
            d = self._weld.distances_in(d)
        d = np.ascontiguousarray(d, dtype=np.float64)
        if d.shape != (self._nv,):
            raise ValueError(f"distances must have shape ({self.n_vertices},), got {d.shape}")
        labels = np.empty(self._nv, dtype=np.int32)
        err = _lib.mfmm_error()
        with self._in_call() as mesh_ptr:
            status = _lib.mfmm_voronoi_labels(mesh_ptr, _args.addr(d), _args.addr(src),
                                              src.shape[0], _args.addr(labels), byref(err))
        _lib.check(status, err)
        return labels if self._weld is None else self._weld.per_vertex(labels)

    def isolines(self, distances: Any, values: Any) -> List[List[Isoline]]:
        """Isolines of a per-vertex field at given values, as polylines.

        Where the linear interpolant of ``distances`` over each face equals a
        value, computed in C (``mfmm_isolines``): one pass over the faces for
        all the values (which values each face's corners straddle), then the
        segments found, joined through their shared edges. A corner counts
        as above a level when its value is >= it; faces with an infinite
        corner hold no segment. Each crossing point is interpolated from its
        edge's lower vertex id, so neighbouring faces share it bit for bit.
        A value's polylines: first the open ones, each from its end with the
        lower edge (vertex ids); then the loops (and, on non-manifold
        edges, the pieces between them), each from the first unused face.
        On a mesh whose T-junctions were closed, the faces as built (a
        split face's pieces, reported as that face).

        Parameters
        ----------
        distances : array_like of float, shape (n_vertices,)
            The field (any per-vertex values, e.g. from :meth:`distance`).
        values : float or sequence of float
            The levels.

        Returns
        -------
        list of list of Isoline
            For each value, its polylines (an empty list where none).
        """
        d = np.ascontiguousarray(distances, dtype=np.float64)
        if d.shape != (self.n_vertices,):
            raise ValueError(f"distances must have shape ({self.n_vertices},), got {d.shape}")
        if np.isnan(d).any():
            raise ValueError("distances hold NaN")
        vals = np.atleast_1d(np.asarray(values, dtype=np.float64))
        if vals.ndim != 1 or not np.isfinite(vals).all():
            raise ValueError("values must be finite numbers")
        points, lines = self._isoline_records(d, vals)
        return _isolines.polylines(points, lines, vals)

    def _isoline_records(self, d: np.ndarray, values: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """mfmm_isolines of a checked field (n_vertices,) at checked values:
        (points, lines) as _lib.SURFACE_POINT_DTYPE and _lib.ISOLINE_DTYPE
        records, the face ids the input's (also for meshfmm.plot)."""
        if self._weld is not None:
            d = self._weld.distances_in(d)
        d = np.ascontiguousarray(d, dtype=np.float64)
        vals = np.ascontiguousarray(values, dtype=np.float64)
        with self._in_call() as mesh_ptr:
            points, lines = _isolines.compute(mesh_ptr, d, vals)
        if self._weld is not None:
            points["face"] = self._weld.faces_out(points["face"])
        return points, lines

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
        method: str = "fmm",
        n_threads: int = 0,
        memory_limit: int = 0,
        progress: Any = None,
        targets: Any = None,
        sparse: bool = False,
        symmetric: bool = False,
        return_info: bool = False,
        size_check: bool = True,
    ) -> Any:
        """Distances from many vertex sources, one row per source.

        Row i holds the distances from ``sources[i]`` to every vertex (equal
        to :meth:`distance`'s), or to ``targets``.

        Parameters
        ----------
        sources : array_like of int, shape (S,), optional
            Vertex ids; None (default) for every vertex in order (an N x N
            matrix).
        backend : {"auto", "opencl", "threads", "serial"}
            "auto" runs OpenCL on a usable device that is not a CPU (or that
            ``MESHFMM_OPENCL_DEVICE`` names), else threads, which run the
            same rows faster on a CPU. ``return_info=True`` tells which ran.
        dtype : {"float32", "float64"}
            Output dtype; the arithmetic is float64 either way.
        out : numpy.ndarray, shape (S, N) or (S, T), optional
            A preallocated C-contiguous writable array (a ``numpy.memmap``
            works) of the given dtype, written in place and returned; None
            allocates one.
        max_distance, cost, cost_location, unfolding, exact_start
            As in :meth:`distance`. Every backend starts each row alike;
            OpenCL rows equal the serial rows bit for bit.
        method : {"fmm", "windows"}
            As in :meth:`distance`, on every backend; "auto" runs
            "windows" on threads (saying why in :class:`MatrixInfo`).
            Rows equal ``distance(source,
            method=method)`` bit for bit in float64, with targets,
            max_distance and sparse rows alike. "exact" is not a matrix
            method (a ValueError): solve each row with
            ``distance(method="exact")``.
        n_threads : int
            Threads of the threads backend; 0 for all cores.
        memory_limit : int
            Bytes the library may use for workspaces and blocks in flight; 0
            for its default, 16 MiB (on OpenCL at least one row per compute
            unit).
        progress : bool or callable, optional
            True: a progress bar on standard error (rows done, time, time
            left), ending with the backend that ran and, under "auto", why.
            A callable is called as ``progress(rows_done, n_rows)`` as
            blocks of rows finish; an exception it raises (or Ctrl-C) stops
            the job and propagates.
        targets : array_like of int or SurfacePoint, shape (T,), optional
            Vertex ids in any order, duplicates allowed: the result is S x T,
            column j the distance to ``targets[j]``, and each row's march
            stops once its targets are settled (landmark matrices cost far
            less than full rows). None: every vertex. Every backend. Points
            inside faces (:class:`SurfacePoint`, mixed with ids or not) get
            the value the path tracer reads there, as ``distance(at=...)``:
            the rows go to their faces' corners (float64) and are combined;
            dense only.
        sparse : bool
            Return a ``scipy.sparse.csr_matrix`` of the finite entries only
            (with ``max_distance=r``: the pairs within r; the diagonal holds
            explicit zeros), column ids sorted; memory O(nnz), never S x N.
            Needs a finite max_distance. Not on OpenCL ("auto" runs threads);
            ``out`` must be None.
        symmetric : bool
            For a square result (sources None, or equal to targets) return
            (D + D^T) / 2, symmetrised in place without a copy. Dense only.
        return_info : bool
            Also return the call's :class:`MatrixInfo`.
        size_check : bool
            True (default): before allocating a dense result (``out`` None),
            compare its size with the memory available (the system's, a
            cgroup's limit, RLIMIT_AS) and refuse with both numbers rather
            than start a job that cannot finish. False allocates anyway.

        Returns
        -------
        D : numpy.ndarray of dtype, shape (S, N) or (S, T), or scipy.sparse.csr_matrix
            The distances; unreached entries are +inf (dense) or absent
            (sparse). ``out`` itself when given.
        info : MatrixInfo
            Only with ``return_info=True``: the backend that ran, why "auto"
            chose it, the vertices settled and the exact start's fallbacks.

        Raises
        ------
        OpenCLError
            ``backend="opencl"`` cannot run.
        ValueError, TypeError
            Bad arguments (ids out of range, a wrong ``out``, ``sparse``
            without a finite max_distance, ``symmetric`` on a non-square
            result, ...).
        KeyboardInterrupt
            Ctrl-C, after the library stopped at the next block of rows.
        MemoryError
            The dense result would not fit the memory available
            (``size_check``).
        """
        _args.solve_method(method, cost, "distance_matrix")
        pts = None
        if targets is not None and _has_surface_point(targets):
            pts = Points.parse(targets, "target", self.n_vertices, self.n_faces)
        if self._weld is not None:
            w = self._weld
            sources = w.to_welded if sources is None else w.vertices(sources, "source")
            if pts is not None:
                pts = pts.welded(w, "target")
            else:
                targets = w.to_welded if targets is None else w.vertices(targets, "target")
            cost, cost_location = w.cost(cost, cost_location)
        progress, bar = _guards.progress_callback(progress, "distance matrix")
        kw = dict(max_distance=max_distance, cost=cost, cost_location=cost_location,
                  unfolding=unfolding, exact_start=exact_start, method=method,
                  n_threads=n_threads, memory_limit=memory_limit, progress=progress,
                  size_check=_args.flag(size_check, "size_check"))
        info = None
        try:
            if pts is not None:
                result, info = self._matrix_at_points(pts, sources, backend, dtype, out,
                                                      sparse=sparse, symmetric=symmetric, **kw)
            else:
                result, info = self._matrix(sources, backend, dtype, out, targets=targets,
                                            sparse=sparse, symmetric=symmetric, **kw)
        finally:
            if bar is not None:
                bar.close(info)
        return (result, info) if _args.flag(return_info, "return_info") else result

    def _matrix_at_points(self, pts: Points, sources: Any, backend: Any, dtype: Any,
                          out: Optional[np.ndarray], *, sparse: Any, symmetric: Any,
                          **kw: Any) -> Tuple[np.ndarray, MatrixInfo]:
        """Columns at surface points: the rows to the corners they need
        (float64), combined as the tracer interpolates."""
        if _args.flag(sparse, "sparse") or _args.flag(symmetric, "symmetric"):
            raise ValueError("targets with points in faces give a dense S x T result: "
                             "sparse and symmetric do not apply")
        dt, _ = _args.matrix_dtype(dtype)
        U, cols, wts = pts.columns(self._F)
        DU, info = self._matrix(sources, backend, "float64", None, targets=U, sparse=False,
                                symmetric=False, **kw)
        shape = (DU.shape[0], cols.shape[0])
        if out is None:
            out = np.empty(shape, dtype=dt)
        else:
            _dense.check_out(out, shape, dt)
        combine(DU, cols, wts, out=out)
        return out, info

    def _matrix(self, sources: Any, backend: Any, dtype: Any, out: Optional[np.ndarray], *,
                targets: Any, sparse: Any, symmetric: Any, progress: Any,
                **kw: Any) -> Tuple[Any, MatrixInfo]:
        """:meth:`distance_matrix` in the C mesh's vertex ids."""
        req = _rows.Request(self, sources, backend, dtype, targets)
        unfolding = _args.flag(kw.pop("unfolding"), "unfolding")
        sparse = _args.flag(sparse, "sparse")
        symmetric = _args.flag(symmetric, "symmetric")
        req.check_targets(self._nv)
        if sparse:
            kw.pop("size_check")  # memory follows the entries
        path = _sparse.sparse_matrix if sparse else _dense.dense_matrix
        return path(self, req, out, symmetric=symmetric, progress=progress,
                    unfolding=unfolding, **kw)

    def iter_distance_rows(
        self, sources: Any = None, block_rows: int = 256, **kwargs: Any
    ) -> Iterator[Tuple[Any, ...]]:
        """Dense blocks of rows of :meth:`distance_matrix`, in order, without
        the whole matrix in memory (for writing into h5py, Zarr or a
        database).

        Each block is one library call; closing the generator early
        (``break``) computes no further block.

        Parameters
        ----------
        sources : array_like of int, shape (S,), optional
            Vertex ids; None for every vertex in order.
        block_rows : int
            Most rows per block, >= 1.
        **kwargs
            :meth:`distance_matrix`'s keyword options (backend, dtype,
            targets, max_distance, cost, method, ...) except ``sparse``,
            ``symmetric`` and ``out``. ``progress`` is called as
            ``progress(rows_done, S)`` over the whole job;
            ``return_info=True`` adds each block's :class:`MatrixInfo`.

        Yields
        ------
        first_row : int
            Index of the block's first row.
        block : numpy.ndarray of dtype, shape (at most block_rows, N or T)
            The block's rows.
        info : MatrixInfo
            Only with ``return_info=True``: the block's call.

        Raises
        ------
        ValueError, TypeError
            As :meth:`distance_matrix`, and for ``sparse``, ``symmetric``,
            ``out`` or ``block_rows < 1``.
        """
        if kwargs.get("sparse") or kwargs.get("symmetric") or kwargs.get("out") is not None:
            raise ValueError("iter_distance_rows yields dense blocks: no sparse, symmetric or out")
        if block_rows < 1:
            raise ValueError("block_rows must be >= 1")
        src = (np.arange(self.n_vertices, dtype=np.int32) if sources is None
               else _args.index_array(sources, "source"))
        n_rows = src.shape[0]
        if n_rows == 0:
            raise ValueError("at least one source is needed")
        progress, bar = _guards.progress_callback(kwargs.pop("progress", None), "distance rows")
        with_info = _args.flag(kwargs.pop("return_info", False), "return_info")
        info = None
        try:
            for first in range(0, n_rows, block_rows):
                part = src[first : first + block_rows]

                def prog(done: int, _total: int, first: int = first) -> Any:
                    if progress is not None:
                        return progress(first + done, n_rows)
                    return None

                block, info = self.distance_matrix(part, progress=prog, return_info=True,
                                                   **kwargs)
                yield (first, block, info) if with_info else (first, block)
        finally:
            if bar is not None:
                bar.close(info)


def _reverse_path(p: GeodesicPath, V: np.ndarray, F: np.ndarray) -> GeodesicPath:
    """A path run backwards, keeping GeodesicPath's convention (faces[i],
    i > 0, the face of the segment from point i-1; barycentric[i] in
    faces[i]): a point whose face changes gets its coordinates in the new
    face, from its position."""
    k = len(p)
    pts = p.points[::-1].copy()
    if k < 2:
        return p
    old_f = p.faces
    faces = np.empty(k, dtype=np.int32)
    faces[0] = old_f[k - 1]
    faces[1:] = old_f[k - 1 : 0 : -1]
    bary = p.barycentric[::-1].copy()
    old_of_new = np.arange(k - 1, -1, -1)
    for j in range(k):
        if faces[j] != old_f[old_of_new[j]]:
            A, B, C = V[F[faces[j]]]
            M = np.stack([B - A, C - A], axis=1)
            lam, *_ = np.linalg.lstsq(M, pts[j] - A, rcond=None)
            b = np.array([1.0 - lam[0] - lam[1], lam[0], lam[1]])
            b = np.clip(b, 0.0, None)
            bary[j] = b / b.sum()
    return GeodesicPath(points=pts, faces=faces, barycentric=bary, length=p.length,
                        weighted_length=p.weighted_length)


def _has_surface_point(x: Any) -> bool:
    """Whether a targets argument holds a SurfacePoint."""
    if isinstance(x, SurfacePoint):
        return True
    if isinstance(x, (np.ndarray, str, bytes)) or not hasattr(x, "__iter__"):
        return False
    return any(isinstance(t, SurfacePoint) for t in x)


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


def load_mesh(path: Union[str, "os.PathLike[str]"]) -> Tuple[np.ndarray, np.ndarray]:
    """Reads a triangle mesh file with the library's readers.

    Parameters
    ----------
    path : str or os.PathLike
        An OBJ, OFF, PLY (ascii or binary) or STL file (binary or ascii;
        coincident vertices welded).

    Returns
    -------
    V : numpy.ndarray, float64, shape (nv, 3)
        Vertex coordinates.
    F : numpy.ndarray, int32, shape (nf, 3)
        Faces as 0-based vertex ids.

    Raises
    ------
    FileNotFoundError, OSError
        The file cannot be read.
    MeshError
        The file is malformed.
    """
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
            ctypes.memmove(_args.addr(V), vp.value, V.nbytes)
        if F.size:
            ctypes.memmove(_args.addr(F), fp.value, F.nbytes)
    finally:
        _lib.mfmm_free(vp)
        _lib.mfmm_free(fp)
    return V, F
