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
from ctypes import byref
from typing import Any, Callable, Dict, Iterator, List, Optional, Tuple, Union

import numpy as np

from . import _args, _dense, _lib, _rows, _sparse
from ._interrupt import sigint_as_flag
from ._types import GeodesicPath, MatrixInfo, MeshInfo, SourceLike, SurfacePoint

__all__ = ["Mesh", "MeshInfo", "SurfacePoint", "GeodesicPath", "MatrixInfo", "load_mesh"]


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
        380 bytes per vertex, on the first solve, kept with the mesh).
        False puts memory first: the march walks the faces instead, with the
        same results bit for bit and a march 1.25-1.6x as long.

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
        self._spokes = _args.flag(spokes, "spokes")
        self._lock = threading.Lock()
        # _leave notifies it when the last call in flight ends (close waits on it)
        self._idle = threading.Condition(self._lock)
        self._active = 0  # calls in flight
        self._callers: Dict[int, int] = {}  # thread id -> its calls in flight
        self._closing = False  # close() was called: no new calls
        self._close_waiters = 0  # close() calls waiting for the calls in flight
        self._solvers: List[int] = []
        self._exact_solvers: List[int] = []

        self._V, self._F = _args.mesh_arrays(V, F)
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
        return {"max_unfold_steps": self._max_unfold_steps, "spokes": self._spokes}

    @property
    def options(self) -> Dict[str, Any]:
        """The constructor's keyword options, ``max_unfold_steps`` (None: the
        default) and ``spokes``: ``Mesh(V, F, **mesh.options)`` builds an
        equal mesh (a new dict each time)."""
        return self._options()

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
        """The bytes the mesh holds, array by array (``mfmm_mesh_memory``).

        "spokes (once built)" and "exact tables (once built)" are 0 until
        the first solve that builds them (then kept with the mesh); solver
        workspaces are not counted.

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
        """Distance from the nearest source to every vertex.

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
        method : {"fmm", "exact"}
            "fmm" (default): the Fast Marching Method. "exact": exact
            polyhedral geodesic distances by window propagation
            (``mfmm_solve_exact``), without cost, targets, unfolding or
            exact_start options.
        exact_start : bool, "auto" or float
            True or "auto" (default): the march starts from the exact
            distances of the vertices within 7 mean edge lengths of each
            source, times sqrt(n_vertices / 40000) on larger meshes when
            max_distance is None (``MFMM_EXACT_START_AUTO``; about half the
            mean error of the paper's start). A number: that radius in mean
            edge lengths. False (or 0): the paper's plain start. With a
            cost, it applies where the cost is uniform around the source.

        Returns
        -------
        numpy.ndarray, float64, shape (n_vertices,)
            The distances; unreached vertices (other components, beyond
            max_distance) are +inf.

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
        unfolding = _args.flag(unfolding, "unfolding")
        if method == "exact":
            if cost is not None or targets is not None or not unfolding or exact_start is not True:
                raise ValueError("method='exact' computes geodesic distance: it takes no cost, "
                                 "targets, unfolding or exact_start")
            return self._distance_exact(sources, max_distance)
        if method != "fmm":
            raise ValueError(f"method must be 'fmm' or 'exact', not {method!r}")
        if _args.is_int(sources):  # the common case, kept cheap (bench/suite/bench_python.py)
            one = _lib.mfmm_source(_args.index(sources, "source"), -1)
            src_addr, n_src = ctypes.addressof(one), 1
        else:
            src = _args.source_records(sources)
            src_addr, n_src = _args.addr(src), src.shape[0]
        opts = None
        radius = _args.exact_start_radius(exact_start)
        if (cost is not None or max_distance is not None or targets is not None
                or not unfolding or cost_location is not None or radius is not None):
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

    def _distance_exact(self, sources: SourceLike, max_distance: Optional[float]) -> np.ndarray:
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
        return_info: bool = False,
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
        n_threads : int
            Threads of the threads backend; 0 for all cores.
        memory_limit : int
            Bytes the library may use for workspaces and blocks in flight; 0
            for its default, 16 MiB (on OpenCL at least one row per compute
            unit).
        progress : callable, optional
            Called as ``progress(rows_done, n_rows)`` as blocks of rows
            finish. An exception it raises (or Ctrl-C) stops the job and
            propagates.
        targets : array_like of int, shape (T,), optional
            Vertex ids in any order, duplicates allowed: the result is S x T,
            column j the distance to ``targets[j]``, and each row's march
            stops once its targets are settled (landmark matrices cost far
            less than full rows). None: every vertex. Every backend.
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

        Returns
        -------
        D : numpy.ndarray of dtype, shape (S, N) or (S, T), or scipy.sparse.csr_matrix
            The distances; unreached entries are +inf (dense) or absent
            (sparse). ``out`` itself when given.
        info : MatrixInfo
            Only with ``return_info=True``: the backend that ran, why "auto"
            fell back, the vertices settled and the exact start's fallbacks.

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
        """
        req = _rows.Request(self, sources, backend, dtype, targets)
        unfolding = _args.flag(unfolding, "unfolding")
        sparse = _args.flag(sparse, "sparse")
        symmetric = _args.flag(symmetric, "symmetric")
        return_info = _args.flag(return_info, "return_info")
        req.check_targets(self._nv)
        path = _sparse.sparse_matrix if sparse else _dense.dense_matrix
        result, info = path(self, req, out, symmetric=symmetric, progress=progress,
                            cost=cost, cost_location=cost_location, max_distance=max_distance,
                            unfolding=unfolding, exact_start=exact_start, n_threads=n_threads,
                            memory_limit=memory_limit)
        return (result, info) if return_info else result

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
            targets, max_distance, cost, ...) except ``sparse``,
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
        src = (np.arange(self._nv, dtype=np.int32) if sources is None
               else _args.index_array(sources, "source"))
        n_rows = src.shape[0]
        if n_rows == 0:
            raise ValueError("at least one source is needed")
        progress = kwargs.pop("progress", None)
        with_info = _args.flag(kwargs.pop("return_info", False), "return_info")
        for first in range(0, n_rows, block_rows):
            part = src[first : first + block_rows]

            def prog(done: int, _total: int, first: int = first) -> Any:
                if progress is not None:
                    return progress(first + done, n_rows)
                return None

            block, info = self.distance_matrix(part, progress=prog, return_info=True, **kwargs)
            yield (first, block, info) if with_info else (first, block)


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
