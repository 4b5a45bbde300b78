"""open_memmap: a .npy file on disk for a matrix bigger than memory, its size
compared with the free space first and its space reserved up front.

numpy.lib.format.open_memmap makes a sparse file: the disk blocks are only
taken when rows are written, so a full disk shows up half-way through as
SIGBUS (the process dies) and leaves a full-size .npy that looks complete.
Comparing the size with the file system's free space refuses such a job
with both numbers before the file is touched; reserving the blocks turns
what the comparison cannot see (a quota, another writer) into an
OSError(ENOSPC) before any work.
"""

from __future__ import annotations

import errno
import io
import os
import shutil
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


def _check_free_space(fspath: str, nbytes: int) -> None:
    """Refuses (OSError ENOSPC, with both numbers) a file of `nbytes` that
    the free space of its folder's file system cannot hold; a file already
    at `fspath`, which the new one replaces, counts as free."""
    from ._guards import format_bytes

    folder = os.path.dirname(os.path.abspath(fspath))
    try:
        free = shutil.disk_usage(folder).free
    except OSError:
        return  # the folder's own error comes when the file is created
    try:
        if os.path.isfile(fspath):
            free += os.stat(fspath).st_blocks * 512
    except (OSError, AttributeError):
        pass
    if nbytes > free:
        raise OSError(
            errno.ENOSPC,
            f"the array would take {format_bytes(nbytes)} ({nbytes} bytes) on disk but its "
            f"file system has {format_bytes(free)} ({free} bytes) free; write it elsewhere, "
            "ask for fewer rows or columns, or pass size_check=False to try anyway",
            fspath,
        )


def open_memmap(path: Union[str, "os.PathLike[str]"], shape: Tuple[int, ...],
                dtype: Any = "float32", *, size_check: bool = True) -> np.memmap:
    """A .npy file on disk, its full size reserved, memory-mapped for writing.

    Compares the file's size with the free space of its file system (unless
    ``size_check=False``), creates (or truncates) the file for a C-order
    array, reserves its blocks on disk, and returns it ready for
    ``Mesh.distance_matrix(out=...)``. Without the reservation a full disk
    would show up half-way through as SIGBUS. The contents read as zeros
    until written: to tell a finished
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
    size_check : bool
        True (default): before touching the file, compare its size (header
        included) with the free space of the file system that holds its
        folder (``shutil.disk_usage``; a file it replaces counts as free)
        and refuse with both numbers. False skips the comparison; the
        reservation still fails at once on a full disk.

    Returns
    -------
    numpy.memmap
        Mode "r+", of `shape` and `dtype`.

    Raises
    ------
    OSError
        errno ENOSPC: the file would not fit in the free space (both sizes
        in the message; nothing is created or truncated), or the disk
        cannot hold it when its blocks are reserved ("No space left on
        device"; the file is removed); or another error creating it.
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
    if not isinstance(size_check, (bool, np.bool_)):
        raise TypeError(f"size_check must be True or False, got {size_check!r}")
    if size_check:
        with io.BytesIO() as head:
            np.lib.format.write_array_header_1_0(head, header)
            _check_free_space(fspath, head.tell() + nbytes)
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
