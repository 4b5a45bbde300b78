"""Argument coercion and validation shared by the Mesh methods, the matrix
paths and :mod:`meshfmm.distributed`: vertex ids, sources and targets, costs,
the exact start's radius, max_distance, output dtypes and backends, each
turned into what the C library takes or refused with a TypeError or
ValueError that names the argument."""

from __future__ import annotations

import collections.abc
import ctypes
import math
import numbers
from typing import Any, Optional, Tuple

import numpy as np

from . import _lib
from ._lib import MeshError
from ._types import SurfacePoint

I32_MIN = -(2**31)
I32_MAX = 2**31 - 1


def mesh_arrays(V: Any, F: Any) -> Tuple[np.ndarray, np.ndarray]:
    """A mesh's vertices (n, 3) and faces (m, 3) -> private read-only copies,
    float64 and int32, C order. Raises MeshError for non-numeric arrays,
    wrong shapes, counts or vertex ids beyond 32 bits (the rest is the
    library's to check)."""
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
    if nv > I32_MAX or nf > I32_MAX:
        raise MeshError(f"too many vertices or faces for 32-bit indices ({nv}, {nf})")
    if nf and Fa.dtype.itemsize >= 4 and Fa.dtype != np.int32:
        lo, hi = Fa.min(), Fa.max()
        if lo < I32_MIN or hi > I32_MAX:
            bad = np.argwhere((Fa < I32_MIN) | (Fa > I32_MAX))[0]
            raise MeshError(
                f"face {bad[0]} names vertex {Fa[bad[0], bad[1]]}, out of range "
                f"(the mesh has {nv} vertices)"
            )
    # One private copy each, in the C types; read-only views go out.
    V = np.array(Va, dtype=np.float64, order="C", copy=True)
    F = np.array(Fa, dtype=np.int32, order="C", copy=True)
    V.setflags(write=False)
    F.setflags(write=False)
    return V, F


def addr(a: np.ndarray) -> int:
    """Address of an ndarray's first element. (ctypes.c_char.from_buffer is
    several times faster than ndarray.ctypes.data, but needs a writable,
    non-empty buffer.)"""
    try:
        return ctypes.addressof(ctypes.c_char.from_buffer(a))
    except (TypeError, ValueError):
        return a.__array_interface__["data"][0]


def is_int(x: Any) -> bool:
    """True for a Python or numpy integer that is not a bool."""
    return isinstance(x, (int, np.integer)) and not isinstance(x, (bool, np.bool_))


def flag(x: Any, what: str) -> bool:
    """A yes/no option: True or False (numpy's bools too). Anything else is a
    TypeError: 'no', 0 or None read as truth values would pass silently."""
    if not isinstance(x, (bool, np.bool_)):
        raise TypeError(f"{what} must be True or False, got {x!r}")
    return bool(x)


def nbytes(x: Any, what: str) -> int:
    """A byte count for a C size_t: an integer in [0, 2**64)."""
    if not is_int(x):
        raise TypeError(f"{what} must be an integer number of bytes, got {x!r}")
    i = int(x)
    if not (0 <= i < 2**64):
        raise ValueError(f"{what} must be in [0, 2**64), got {i}")
    return i


def index(x: Any, what: str) -> int:
    """An integer that fits a C int32_t."""
    if not is_int(x):
        raise TypeError(f"{what} must be an integer, got {type(x).__name__}")
    i = int(x)
    if not (I32_MIN <= i <= I32_MAX):
        raise ValueError(f"{what} {i} is out of range (not a 32-bit index)")
    return i


def barycentric(b: Any, what: str) -> np.ndarray:
    """Three barycentric coordinates as float64 (3,) (their values are the
    library's to check)."""
    try:
        arr = np.asarray(b, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: barycentric coordinates must be 3 numbers, got {b!r}") from None
    if arr.shape != (3,):
        raise ValueError(
            f"{what}: barycentric coordinates must be 3 numbers, got shape {arr.shape}"
        )
    return arr


def _vertex_records(ids: Any, n: int) -> np.ndarray:
    rec = np.zeros(n, dtype=_lib.SOURCE_DTYPE)
    rec["vertex"] = ids
    rec["face"] = -1
    return rec


def source_records(sources: Any, what: str = "source") -> np.ndarray:
    """Any accepted form of sources (a vertex id, a SurfacePoint, a sequence
    mixing those, an integer array of vertex ids) -> a C-contiguous array of
    mfmm_source records (``_lib.SOURCE_DTYPE``)."""
    if isinstance(sources, np.ndarray) and sources.dtype == _lib.SOURCE_DTYPE:
        if sources.size == 0:
            raise ValueError(f"at least one {what} is needed")
        return np.ascontiguousarray(sources.reshape(-1))  # records already
    if isinstance(sources, SurfacePoint):
        sources = [sources]
    elif is_int(sources):
        return _vertex_records(index(sources, what), 1)
    if isinstance(sources, np.ndarray):
        if sources.dtype.kind not in "iu":
            raise TypeError(f"{what}s as an array must be integer vertex ids, got dtype {sources.dtype}")
        ids = sources.reshape(-1)
        if ids.size == 0:
            raise ValueError(f"at least one {what} is needed")
        if ids.min() < I32_MIN or ids.max() > I32_MAX:
            bad = ids[(ids < I32_MIN) | (ids > I32_MAX)][0]
            raise ValueError(f"{what} {bad} is out of range (not a 32-bit index)")
        return _vertex_records(ids, ids.size)
    if (isinstance(sources, (str, bytes, collections.abc.Mapping))
            or not hasattr(sources, "__len__")):
        raise TypeError(
            f"{what}s must be a vertex id, a SurfacePoint or a sequence of those, "
            f"got {type(sources).__name__}"
        )
    n = len(sources)
    if n == 0:
        raise ValueError(f"at least one {what} is needed")
    if all(is_int(s) for s in sources):  # vertex ids only: filled at once
        ids = [int(s) for s in sources]
        for i, v in enumerate(ids):
            if not (I32_MIN <= v <= I32_MAX):
                raise ValueError(f"{what} {i}: vertex {v} is out of range (not a 32-bit index)")
        return _vertex_records(ids, n)
    rec = np.zeros(n, dtype=_lib.SOURCE_DTYPE)
    for i, s in enumerate(sources):
        if isinstance(s, SurfacePoint):
            face = index(s.face, f"{what} {i}: face")
            if face < 0:
                raise ValueError(f"{what} {i}: face {face} is out of range (face ids are >= 0)")
            rec["face"][i] = face
            rec["vertex"][i] = -1
            rec["bary"][i] = barycentric(s.bary, f"{what} {i}")
        elif is_int(s):
            rec["vertex"][i] = index(s, f"{what} {i}: vertex")
            rec["face"][i] = -1
        else:
            raise TypeError(
                f"{what} {i} must be a vertex id or a SurfacePoint, got {type(s).__name__}"
            )
    return rec


def target_record(target: Any) -> _lib.mfmm_source:
    """A path's target (a vertex id or a SurfacePoint) as one mfmm_source."""
    src = _lib.mfmm_source()
    if isinstance(target, SurfacePoint):
        src.vertex = -1
        src.face = index(target.face, "target face")
        if src.face < 0:
            raise ValueError(f"target face {src.face} is out of range (face ids are >= 0)")
        b = barycentric(target.bary, "target")
        src.bary[0], src.bary[1], src.bary[2] = float(b[0]), float(b[1]), float(b[2])
    elif is_int(target):
        src.vertex = index(target, "target vertex")
        src.face = -1
    else:
        raise TypeError(f"target must be a vertex id or a SurfacePoint, got {type(target).__name__}")
    return src


def index_array(x: Any, what: str) -> np.ndarray:
    """Vertex ids (a scalar or 1-D integers) as C-contiguous int32; the range
    against the mesh is checked by the caller or the library."""
    a = np.asarray(x)
    if a.ndim == 0:
        a = a.reshape(1)
    if a.size and a.dtype.kind not in "iu":
        raise TypeError(f"{what}s must be integer vertex ids, got dtype {a.dtype}")
    if a.ndim != 1:
        raise ValueError(f"{what}s must be 1-D, got shape {a.shape}")
    if a.size and (a.min() < I32_MIN or a.max() > I32_MAX):
        bad = a[(a < I32_MIN) | (a > I32_MAX)][0]
        raise ValueError(f"{what} {bad} is out of range (not a 32-bit index)")
    return np.ascontiguousarray(a, dtype=np.int32)


def vertex_ids(x: Any, what: str, n: int) -> np.ndarray:
    """A non-empty 1-D sequence of vertex ids in [0, n), as int32."""
    a = np.asarray(x)
    if a.ndim != 1 or a.size == 0:
        raise ValueError(f"{what} must be a non-empty 1-D sequence of vertex ids")
    if not np.issubdtype(a.dtype, np.integer):
        raise TypeError(f"{what} must be integers, not {a.dtype}")
    if a.min() < 0 or a.max() >= n:
        raise ValueError(f"{what} must be vertex ids in [0, {n}); got {a.min()}..{a.max()}")
    return a.astype(np.int32)


_COST_LOCATIONS = {"vertex": _lib.MFMM_COST_PER_VERTEX, "face": _lib.MFMM_COST_PER_FACE}


def cost_array(cost: Any, cost_location: Optional[str], nv: int,
               nf: int) -> Tuple[Optional[np.ndarray], int]:
    """A cost per vertex (nv,) or per face (nf,) -> (float64 array or None,
    the C cost location). ``cost_location`` ('vertex', 'face' or None) is
    needed only when nv == nf; the values are the library's to check."""
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


def exact_start_radius(x: Any) -> Optional[float]:
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


def max_distance(x: Any) -> float:
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


def matrix_dtype(dtype: Any) -> Tuple[np.dtype, int]:
    """A matrix's output dtype (float32 or float64) -> (numpy dtype, the C
    mfmm_dtype)."""
    dt = np.dtype(dtype)
    if dt == np.float32:
        return dt, _lib.MFMM_FLOAT32
    if dt == np.float64:
        return dt, _lib.MFMM_FLOAT64
    raise ValueError(f"dtype must be float32 or float64, got {dt}")


def method(name: Any, exact: bool = True) -> int:
    """A method name -> the C mfmm_method ("fmm", "windows"); "exact" (where
    the caller takes it: exact=True) -> -1."""
    names = ["fmm", "windows"] + (["exact"] if exact else [])
    if not isinstance(name, str) or name not in names:
        raise ValueError(f"method must be one of {names}, not {name!r}")
    return -1 if name == "exact" else _lib.METHODS[name]


def solve_method(name: Any, cost: Any, what: str) -> int:
    """The C mfmm_method of a call that solves by mfmm_solve or its rows
    (`what` names it in messages): "fmm" or "windows", each with or without
    a cost; "exact" (its own solver, mfmm_solve_exact) is refused."""
    if name == "exact":
        raise ValueError(f"method='exact' is not a method of {what}: it takes 'fmm' or "
                         "'windows' (exact distances: Mesh.distance(method='exact'), one "
                         "solve per source)")
    del cost  # both methods take a cost
    return method(name, exact=False)


def backend(name: Any) -> int:
    """A backend name ("auto", "serial", "threads", "opencl"; any case) -> the
    C mfmm_backend."""
    if not isinstance(name, str) or name.lower() not in _lib.BACKENDS:
        raise ValueError(f"backend must be one of {sorted(_lib.BACKENDS)}, got {name!r}")
    return _lib.BACKENDS[name.lower()]
