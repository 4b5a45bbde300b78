"""The sparse matrix path of :meth:`Mesh.distance_matrix`: the library's CSR
blocks of the finite entries, joined into one scipy.sparse.csr_matrix."""

from __future__ import annotations

import ctypes
from typing import TYPE_CHECKING, Any, Callable, List, Optional, Tuple

import numpy as np

from . import _extras, _rows
from ._types import MatrixInfo

if TYPE_CHECKING:  # pragma: no cover
    from ._mesh import Mesh


def _copy_block(n: int, indptr: Any, indices: Any, values: Any,
                dt: np.dtype) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Copies one CSR block of n rows out of the library's buffers (valid
    only during the callback)."""
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
    return ip.copy(), ix, vals


def sparse_matrix(mesh: "Mesh", req: _rows.Request, out: Optional[np.ndarray], *,
                  symmetric: bool, progress: Optional[Callable[[int, int], Any]],
                  **options: Any) -> Tuple[Any, MatrixInfo]:
    """The finite entries of ``req``'s rows as a csr_matrix (needs a finite
    max_distance; no `out`, not symmetric). `options` are
    :func:`_rows.options`' keywords. Returns the matrix and the call's
    MatrixInfo."""
    _extras.require("distance_matrix(sparse=True)", "sparse")
    if symmetric:
        raise ValueError("symmetric=True is for dense results")
    if out is not None:
        raise ValueError("out is for dense results; sparse=True returns a csr_matrix")
    max_distance = options.get("max_distance")
    if max_distance is None or not np.isfinite(float(max_distance)):
        raise ValueError("sparse=True needs a finite max_distance (else every entry is stored)")
    dt = req.dtype
    opts, keep = _rows.options(mesh, req, np.empty((0, 0), dtype=dt), sparse=True, **options)
    n_rows = req.n_rows
    pieces: List[Any] = []

    def on_sparse(first: int, n: int, indptr: Any, indices: Any, values: Any) -> None:
        pieces.append(_copy_block(n, indptr, indices, values, dt))
        if progress is not None:
            progress(first + n, n_rows)

    info = _rows.run(mesh, req, opts, on_sparse=on_sparse)
    del keep
    return _rows.csr_from_pieces(pieces, (n_rows, req.width), dt), info
