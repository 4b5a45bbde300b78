"""open_memmap: a .npy file on disk for a matrix bigger than memory, with its
space reserved up front.

numpy.lib.format.open_memmap makes a sparse file: the disk blocks are only
taken when rows are written, so a full disk shows up half-way through as
SIGBUS (the process dies) and leaves a full-size .npy that looks complete.
Reserving the blocks first turns that into an OSError(ENOSPC) before any work.
"""

from __future__ import annotations

import errno
import os
from typing import Any, Tuple, Union

import numpy as np

__all__ = ["open_memmap"]

_CHUNK = 1 << 22  # bytes written per call where the file system cannot fallocate


def _reserve(fd: int, offset: int, length: int) -> None:
    """Allocates [offset, offset + length) of the file on disk."""
    if length <= 0:
        return
    if hasattr(os, "posix_fallocate"):
        try:
            os.posix_fallocate(fd, offset, length)
            return
        except OSError as exc:
            if exc.errno not in (errno.EOPNOTSUPP, errno.EINVAL, errno.ENOSYS):
                raise
    # No fallocate here: write zeros, which takes the blocks just as well.
    zeros = bytes(min(_CHUNK, length))
    os.lseek(fd, offset, os.SEEK_SET)
    left = length
    while left > 0:
        left -= os.write(fd, zeros[: min(left, len(zeros))])
    os.fsync(fd)


def open_memmap(path: Union[str, "os.PathLike[str]"], shape: Tuple[int, ...],
                dtype: Any = "float32") -> np.memmap:
    """A .npy file on disk, its full size reserved, memory-mapped for writing.

    Creates (or truncates) the file for a C-order array, reserves its blocks
    on disk, and returns it ready for ``Mesh.distance_matrix(out=...)``.
    Without the reservation a full disk would show up half-way through as
    SIGBUS. The contents read as zeros until written: to tell a finished
    matrix from an interrupted one, write to a temporary name and rename it
    when the job has returned::

        D = meshfmm.open_memmap("all.npy.partial", (n, n), "float32")
        mesh.distance_matrix(out=D)
        D.flush(); del D
        os.replace("all.npy.partial", "all.npy")

    Parameters
    ----------
    path : str or os.PathLike
        The .npy file to create.
    shape : int or tuple of int
        The array's shape, each >= 0.
    dtype : numpy dtype
        The array's dtype (default float32).

    Returns
    -------
    numpy.memmap
        Mode "r+", of `shape` and `dtype`.

    Raises
    ------
    OSError
        errno ENOSPC ("No space left on device") at once when the disk
        cannot hold the file (the file is removed), or another error
        creating it.
    ValueError
        A negative dimension.
    """
    fspath = os.fspath(path)
    dt = np.dtype(dtype)
    try:
        shape = tuple(int(n) for n in shape)
    except TypeError:
        shape = (int(shape),)  # type: ignore[call-overload]
    if any(n < 0 for n in shape):
        raise ValueError(f"shape must not be negative, got {shape}")
    header = {"descr": np.lib.format.dtype_to_descr(dt), "fortran_order": False, "shape": shape}
    nbytes = dt.itemsize
    for n in shape:
        nbytes *= n
    fd = os.open(fspath, os.O_RDWR | os.O_CREAT | os.O_TRUNC, 0o666)
    try:
        with os.fdopen(os.dup(fd), "wb") as f:
            np.lib.format.write_array_header_1_0(f, header)
            offset = f.tell()
        try:
            _reserve(fd, offset, nbytes)
        except OSError as exc:
            raise OSError(
                exc.errno,
                f"cannot reserve {offset + nbytes} bytes for {fspath} "
                f"({os.strerror(exc.errno) if exc.errno else exc})",
                fspath,
            ) from None
    except BaseException:
        os.close(fd)
        try:
            os.unlink(fspath)
        except OSError:
            pass
        raise
    os.close(fd)
    return np.lib.format.open_memmap(fspath, mode="r+")
