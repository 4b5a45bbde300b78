"""The dense matrix path of :meth:`Mesh.distance_matrix`: rows written into
a numpy array (or memmap), symmetrised in place on request."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable, Optional, Tuple

import numpy as np

from . import _guards, _rows
from ._types import MatrixInfo

if TYPE_CHECKING:  # pragma: no cover
    from ._mesh import Mesh


def check_out(out: Any, shape: Tuple[int, int], dt: np.dtype) -> None:
    """Refuses an ``out`` the library cannot write rows into."""
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


def dense_matrix(mesh: "Mesh", req: _rows.Request, out: Optional[np.ndarray], *,
                 symmetric: bool, progress: Optional[Callable[[int, int], Any]],
                 size_check: bool = True, **options: Any) -> Tuple[np.ndarray, MatrixInfo]:
    """Rows of ``req`` into `out` (allocated when None, after comparing its
    size with the memory available unless not `size_check`), then
    (D + D^T) / 2 in place if `symmetric`. `options` are
    :func:`_rows.options`' keywords. Returns the array and the call's
    MatrixInfo."""
    nv = mesh._nv
    if symmetric and not req.is_square(nv):
        raise ValueError("symmetric=True needs a square result: sources None or equal to targets")
    shape = (req.n_rows, req.width)
    if out is None:
        if size_check:
            _guards.check_memory(shape[0] * shape[1] * req.dtype.itemsize,
                                 f"{shape[0]} x {shape[1]} {req.dtype}")
        out = np.empty(shape, dtype=req.dtype)
    else:
        check_out(out, shape, req.dtype)
    opts, keep = _rows.options(mesh, req, out, sparse=False, **options)
    n_rows = req.n_rows

    def on_rows(first: int, n: int, rows: Any) -> None:
        if progress is not None:
            progress(first + n, n_rows)

    info = _rows.run(mesh, req, opts, on_rows=on_rows)
    del keep
    if symmetric:
        _rows.symmetrize_in_place(out)
    return out, info
