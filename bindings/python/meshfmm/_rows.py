"""The library's row job, shared by the dense and sparse matrix paths: the
mfmm_matrix_options of a call, the call itself with its callbacks guarded
(an exception or Ctrl-C stops the job and is raised after it), the
per-call :class:`MatrixInfo`, and the helpers that assemble rows (CSR
blocks into one matrix; symmetrisation in place)."""

from __future__ import annotations

import atexit
import ctypes
import threading
from ctypes import byref
from typing import TYPE_CHECKING, Any, Callable, List, Optional, Tuple

import numpy as np

from . import _args, _lib
from ._interrupt import sigint_as_flag
from ._types import MatrixInfo

if TYPE_CHECKING:  # pragma: no cover
    from ._mesh import Mesh


class Request:
    """The checked arguments every matrix path shares: sources (int32 (S,)
    or None for every vertex), targets (int32 (T,) or None), the output
    dtype and the backend."""

    def __init__(self, mesh: "Mesh", sources: Any, backend: Any, dtype: Any,
                 targets: Any) -> None:
        nv = mesh._nv  # the C mesh's (welded) count
        if sources is None:
            self.src: Optional[np.ndarray] = None
            self.n_rows = nv
        else:
            self.src = _args.index_array(sources, "source")
            self.n_rows = self.src.shape[0]
            if self.n_rows == 0:
                raise ValueError("at least one source is needed")
        self.dtype, self.c_dtype = _args.matrix_dtype(dtype)
        self.backend = _args.backend(backend)
        self._targets = targets
        self.tgt: Optional[np.ndarray] = None

    def check_targets(self, nv: int) -> None:
        """Checks the targets (after the flags, as the errors' order has it)."""
        if self._targets is not None:
            tgt = _args.index_array(self._targets, "target")
            if tgt.shape[0] == 0:
                raise ValueError("targets must hold at least one vertex id (None: every vertex)")
            if int(tgt.min()) < 0 or int(tgt.max()) >= nv:
                raise ValueError(f"target ids must lie in [0, {nv})")
            self.tgt = tgt
        self.width = nv if self.tgt is None else self.tgt.shape[0]

    def is_square(self, nv: int) -> bool:
        """Whether the result is square with row i and column i the same
        vertex: sources None or equal to the targets."""
        every = np.arange(nv)
        if self.src is None:
            return self.tgt is None or np.array_equal(self.tgt, every)
        return np.array_equal(self.src, self.tgt if self.tgt is not None else every)


def options(mesh: "Mesh", req: Request, out: np.ndarray, *, sparse: bool, cost: Any,
            cost_location: Optional[str], max_distance: Any, unfolding: bool,
            exact_start: Any, n_threads: Any, memory_limit: Any,
            method: Any = "fmm") -> Tuple[_lib.mfmm_matrix_options, List[Any]]:
    """The call's mfmm_matrix_options, and the arrays they point into (keep
    them alive until the call returns). `out` is the dense output, or an
    empty array for sparse output."""
    opts = _lib.mfmm_matrix_options()
    _lib.mfmm_matrix_options_init(byref(opts))
    opts.method = _args.solve_method(method, cost, "distance_matrix")
    opts.backend = req.backend
    opts.dtype = req.c_dtype
    c, loc = _args.cost_array(cost, cost_location, mesh._nv, mesh._nf)
    # The library writes rows into `out` while it still reads the sources
    # and the cost: an input that shares memory with `out` (a view of it)
    # would be overwritten mid-job, so such inputs are copied first.
    if req.src is not None and np.may_share_memory(req.src, out):
        req.src = req.src.copy()
    if c is not None and np.may_share_memory(c, out):
        c = c.copy()
    if c is not None:
        opts.cost = _args.addr(c)
        opts.cost_location = loc
    if max_distance is not None:
        opts.max_distance = _args.max_distance(max_distance)
    opts.unfolding = 1 if unfolding else 0
    radius = _args.exact_start_radius(exact_start)
    if radius is not None:
        opts.exact_start_radius = radius
    opts.n_threads = _args.index(n_threads, "n_threads")
    opts.memory_limit = _args.nbytes(memory_limit, "memory_limit")
    opts.out = _args.addr(out) if out.size else None
    if req.tgt is not None:
        opts.targets = _args.addr(req.tgt)
        opts.n_targets = req.tgt.shape[0]
    auto = _lib.BACKENDS["auto"]
    if req.backend == auto and (sparse or opts.method == _lib.MFMM_METHOD_WINDOWS):
        pass  # the library runs threads (sparse rows; auto runs windows on threads)
    elif req.backend in (auto, _lib.BACKENDS["opencl"]):
        opts.opencl = shared_opencl_context()
    return opts, [c, req.src, req.tgt, out]


def call_library(mesh_ptr: int, src: Optional[np.ndarray], n_rows: int,
                 opts: _lib.mfmm_matrix_options) -> Tuple[int, _lib.mfmm_error, MatrixInfo]:
    """The one call of mfmm_distance_matrix, and the one place that reads its
    outputs: returns (status, error, the call's MatrixInfo)."""
    err = _lib.mfmm_error()
    out = _lib.mfmm_matrix_info()
    status = _lib.mfmm_distance_matrix(
        mesh_ptr, None if src is None else _args.addr(src), n_rows, byref(opts), byref(out),
        byref(err)
    )
    name = _lib.mfmm_backend_name(out.backend_used)
    info = MatrixInfo(
        backend=name.decode("ascii") if name else "",
        reason=out.backend_reason.decode("utf-8", "replace"),
        vertices_settled=int(out.vertices_settled),
        start_fallbacks=int(out.start_fallbacks),
    )
    return status, err, info


def run(mesh: "Mesh", req: Request, opts: _lib.mfmm_matrix_options, *,
        on_rows: Optional[Callable[..., None]] = None,
        on_sparse: Optional[Callable[..., None]] = None) -> MatrixInfo:
    """Runs the job with one of the two callbacks (called with the library's
    arguments after the ``user`` pointer) and returns its MatrixInfo.

    An exception a callback raises, and Ctrl-C on the main thread, make the
    callback return the cancel code; the library stops at the next block
    and the exception (or one KeyboardInterrupt) is raised here. A failed
    call raises the library's error (OpenCLError, ValueError, ...)."""
    caught: List[BaseException] = []
    interrupted: List[int] = []

    def guarded(fn: Callable[..., None]) -> Callable[..., int]:
        # Returns the cancel code instead of raising: an exception escaping a
        # ctypes callback is only printed, and the job goes on.
        def callback(user: Any, *args: Any) -> int:
            try:
                if interrupted:
                    return 1
                fn(*args)
                return 0
            except BaseException as exc:  # KeyboardInterrupt too: stop the library
                caught.append(exc)
                return 1
        return callback

    if on_sparse is not None:
        callback = _lib.mfmm_sparse_callback(guarded(on_sparse))
        opts.on_sparse = callback
    else:
        assert on_rows is not None
        callback = _lib.mfmm_rows_callback(guarded(on_rows))
        opts.on_rows = callback
    with mesh._in_call() as mesh_ptr, sigint_as_flag(interrupted):
        status, err, info = call_library(mesh_ptr, req.src, req.n_rows, opts)
    if caught:
        raise caught[0]
    if interrupted:
        raise KeyboardInterrupt
    _lib.check(status, err)
    return info


_opencl_lock = threading.Lock()
_opencl_context: Optional[ctypes.c_void_p] = None


def shared_opencl_context() -> Optional[ctypes.c_void_p]:
    """The process's OpenCL context (device and built program), made on first
    use and reused by every matrix call, so the kernel is built once per
    process (the C library itself keeps no global state). None when no
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


def csr_from_pieces(pieces: List[Any], shape: Tuple[int, int], dt: Any) -> Any:
    """Joins the library's CSR blocks, (indptr, indices, values) each, into
    one scipy.sparse.csr_matrix of `shape` and dtype `dt`."""
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


def symmetrize_in_place(d: np.ndarray, tile: int = 256) -> None:
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
