"""The one place that knows the C ABI of libmeshfmm (``include/meshfmm.h``).

Every ctypes prototype, every ``Structure`` mirror and the mapping of status
codes to Python exceptions live here; the rest of the package calls through
this module only.

Data pointers (vertex, face, cost, distance arrays) are declared ``c_void_p``
and passed as integer addresses of C-contiguous numpy arrays of the exact C
type; the callers in this package check dtype and contiguity before passing
them. Struct arguments are declared as typed pointers.
"""

from __future__ import annotations

import ctypes
import os
import sys
from ctypes import (
    CFUNCTYPE,
    POINTER,
    Structure,
    c_char,
    c_char_p,
    c_double,
    c_int,
    c_int32,
    c_int64,
    c_size_t,
    c_void_p,
)
from pathlib import Path
from typing import Any, Optional

import numpy as np

__all__ = [
    "lib",
    "library_path",
    "MeshError",
    "OpenCLError",
    "check",
]

# ------------------------------------------------------------- status codes
# enum mfmm_status, in order.
MFMM_OK = 0
MFMM_ERR_NULL_POINTER = 1
MFMM_ERR_BAD_COUNT = 2
MFMM_ERR_NONFINITE_VERTEX = 3
MFMM_ERR_INDEX_OUT_OF_RANGE = 4
MFMM_ERR_REPEATED_VERTEX = 5
MFMM_ERR_OUT_OF_MEMORY = 6
MFMM_ERR_BAD_COST = 7
MFMM_ERR_BAD_SOURCE = 8
MFMM_ERR_DEGENERATE_SOURCE = 9
MFMM_ERR_BAD_BARYCENTRIC = 10
MFMM_ERR_BAD_ARGUMENT = 11
MFMM_ERR_WRONG_MESH = 12
MFMM_ERR_UNREACHED = 13
MFMM_ERR_PATH_STALLED = 14
MFMM_ERR_NO_OPENCL = 15
MFMM_ERR_OPENCL_BUILD = 16
MFMM_ERR_OPENCL_RUNTIME = 17
MFMM_ERR_CANCELLED = 18
MFMM_ERR_IO = 19
MFMM_ERR_PARSE = 20
MFMM_ERR_MEMORY_LIMIT = 21
MFMM_STATUS_COUNT = 22

# exact_start_radius's default rule (meshfmm.h MFMM_EXACT_START_AUTO)
EXACT_START_AUTO = -1.0

STATUS_NAMES = (
    "MFMM_OK",
    "MFMM_ERR_NULL_POINTER",
    "MFMM_ERR_BAD_COUNT",
    "MFMM_ERR_NONFINITE_VERTEX",
    "MFMM_ERR_INDEX_OUT_OF_RANGE",
    "MFMM_ERR_REPEATED_VERTEX",
    "MFMM_ERR_OUT_OF_MEMORY",
    "MFMM_ERR_BAD_COST",
    "MFMM_ERR_BAD_SOURCE",
    "MFMM_ERR_DEGENERATE_SOURCE",
    "MFMM_ERR_BAD_BARYCENTRIC",
    "MFMM_ERR_BAD_ARGUMENT",
    "MFMM_ERR_WRONG_MESH",
    "MFMM_ERR_UNREACHED",
    "MFMM_ERR_PATH_STALLED",
    "MFMM_ERR_NO_OPENCL",
    "MFMM_ERR_OPENCL_BUILD",
    "MFMM_ERR_OPENCL_RUNTIME",
    "MFMM_ERR_CANCELLED",
    "MFMM_ERR_IO",
    "MFMM_ERR_PARSE",
    "MFMM_ERR_MEMORY_LIMIT",
)
assert len(STATUS_NAMES) == MFMM_STATUS_COUNT

# enum mfmm_cost_location
MFMM_COST_NONE = 0
MFMM_COST_PER_VERTEX = 1
MFMM_COST_PER_FACE = 2

# enum mfmm_backend
MFMM_BACKEND_AUTO = 0
MFMM_BACKEND_SERIAL = 1
MFMM_BACKEND_THREADS = 2
MFMM_BACKEND_OPENCL = 3
BACKENDS = {"auto": 0, "serial": 1, "threads": 2, "opencl": 3}

# mfmm_method (the C solve's methods; "exact" is mfmm_solve_exact, apart)
MFMM_METHOD_FMM = 0
MFMM_METHOD_WINDOWS = 1
METHODS = {"fmm": MFMM_METHOD_FMM, "windows": MFMM_METHOD_WINDOWS}

# enum mfmm_dtype
MFMM_FLOAT32 = 0
MFMM_FLOAT64 = 1

# C enums are int-sized on every ABI this library targets.
c_enum = c_int


# The ABI these mirrors describe (meshfmm.h MFMM_VERSION_MAJOR.MINOR): while
# MAJOR is 0 every MINOR release may change it, so a library of another
# MAJOR.MINOR is refused at import.
ABI_VERSION = (0, 2)


# ------------------------------------------------------------ struct mirrors
class _Sized(Structure):
    """A struct that starts with struct_size: a new instance has it set to
    its sizeof (option structs are then filled by their C _init function;
    output structs are passed as they are)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        if not self.struct_size:
            self.struct_size = ctypes.sizeof(self)


class mfmm_error(Structure):
    _fields_ = [
        ("status", c_enum),
        ("index", c_int64),
        ("message", c_char * 256),
    ]


# Option structs start with struct_size (set by their C _init function, which
# the package always calls before setting fields); output structs too (set
# to their sizeof on creation, see _Sized).
class mfmm_mesh_options(_Sized):
    _fields_ = [("struct_size", c_size_t), ("max_unfold_steps", c_int32), ("spokes", c_int32)]


class mfmm_mesh_info(_Sized):
    _fields_ = [
        ("struct_size", c_size_t),
        ("n_vertices", c_int32),
        ("n_faces", c_int32),
        ("n_edges", c_int32),
        ("n_boundary_edges", c_int32),
        ("n_nonmanifold_edges", c_int32),
        ("n_components", c_int32),
        ("n_unreferenced_vertices", c_int32),
        ("n_degenerate_faces", c_int32),
        ("n_duplicate_faces", c_int32),
        ("n_obtuse_corners", c_int32),
        ("n_virtual_edges", c_int32),
        ("n_unfold_failures", c_int32),
        ("min_edge_length", c_double),
        ("max_edge_length", c_double),
        ("mean_edge_length", c_double),
        ("bbox_diagonal", c_double),
        ("n_coincident_vertices", c_int32),
        ("n_welded_components", c_int32),
    ]


class mfmm_source(Structure):
    _fields_ = [
        ("vertex", c_int32),
        ("face", c_int32),
        ("bary", c_double * 3),
        ("value", c_double),
    ]


class mfmm_solve_options(_Sized):
    _fields_ = [
        ("struct_size", c_size_t),
        ("cost", c_void_p),  # const double *
        ("cost_location", c_enum),
        ("max_distance", c_double),
        ("targets", c_void_p),  # const int32_t *
        ("n_targets", c_int32),
        ("unfolding", c_int32),
        ("exact_start_radius", c_double),  # the exact start, in mean edge lengths
        ("method", c_enum),  # mfmm_method
    ]


class mfmm_solve_info(_Sized):
    _fields_ = [("struct_size", c_size_t), ("start_fallbacks", c_int64)]


class mfmm_exact_options(_Sized):
    _fields_ = [
        ("struct_size", c_size_t),
        ("max_distance", c_double),
        ("memory_limit", c_size_t),
        ("interrupt", CFUNCTYPE(c_int, c_void_p)),  # non-zero stops the solve
        ("user", c_void_p),
    ]


class mfmm_exact_info(_Sized):
    _fields_ = [
        ("struct_size", c_size_t),
        ("n_windows", c_int64),
        ("n_propagated", c_int64),
        ("n_pseudo_sources", c_int64),
        ("peak_windows", c_int64),
        ("peak_bytes", c_size_t),
        ("nonmanifold_walls", c_int32),
    ]


class mfmm_surface_point(Structure):
    _fields_ = [
        ("face", c_int32),
        ("bary", c_double * 3),
        ("xyz", c_double * 3),
    ]


class mfmm_isoline(Structure):
    _fields_ = [
        ("start", c_int64),
        ("n_points", c_int64),
        ("value", c_int32),
        ("closed", c_int32),
    ]


class mfmm_path_options(_Sized):
    _fields_ = [
        ("struct_size", c_size_t),
        ("max_points", c_int32),
        ("sources", c_void_p),  # const mfmm_source *
        ("n_sources", c_int32),
        ("cost", c_void_p),  # const double *
        ("cost_location", c_enum),
        ("weighted_length", c_void_p),  # double * (out), may be NULL
        ("straighten", c_int32),
    ]


# typedef int (*mfmm_rows_callback)(void *user, int32_t first_row, int32_t n_rows,
#                                   const void *rows);
mfmm_rows_callback = CFUNCTYPE(c_int, c_void_p, c_int32, c_int32, c_void_p)
# (user, first_row, n_rows, indptr int64*, indices int32*, values)
mfmm_sparse_callback = CFUNCTYPE(c_int, c_void_p, c_int32, c_int32, c_void_p, c_void_p, c_void_p)


class mfmm_opencl_options(_Sized):
    _fields_ = [
        ("struct_size", c_size_t),
        ("device", c_char_p),
        ("cache_dir", c_char_p),
        ("library", c_char_p),
    ]


class mfmm_matrix_options(_Sized):
    _fields_ = [
        ("struct_size", c_size_t),
        ("backend", c_enum),
        ("dtype", c_enum),
        ("cost", c_void_p),  # const double *
        ("cost_location", c_enum),
        ("max_distance", c_double),
        ("targets", c_void_p),  # const int32_t *: target columns, or NULL
        ("n_targets", c_int32),
        ("unfolding", c_int32),
        ("exact_start_radius", c_double),
        ("n_threads", c_int32),
        ("memory_limit", c_size_t),
        ("out", c_void_p),
        ("on_rows", mfmm_rows_callback),
        ("on_sparse", mfmm_sparse_callback),
        ("user", c_void_p),
        ("opencl", c_void_p),  # mfmm_opencl_context *
        ("opencl_options", c_void_p),  # const mfmm_opencl_options *
        ("method", c_enum),  # mfmm_method
    ]


class mfmm_matrix_info(_Sized):
    _fields_ = [
        ("struct_size", c_size_t),
        ("backend_used", c_enum),
        ("backend_reason", c_char * 256),  # why another backend than the one asked for ran
        ("vertices_settled", c_int64),
        ("start_fallbacks", c_int64),
    ]


# numpy views of the array-of-struct types, so that many sources or path
# points are filled and read without a Python loop. align=True gives the C
# layout; a check below compares it with the ctypes mirror.
SOURCE_DTYPE = np.dtype(
    {
        "names": ["vertex", "face", "bary", "value"],
        "formats": [np.int32, np.int32, (np.float64, 3), np.float64],
        "offsets": [
            mfmm_source.vertex.offset,
            mfmm_source.face.offset,
            mfmm_source.bary.offset,
            mfmm_source.value.offset,
        ],
        "itemsize": ctypes.sizeof(mfmm_source),
    }
)
SURFACE_POINT_DTYPE = np.dtype(
    {
        "names": ["face", "bary", "xyz"],
        "formats": [np.int32, (np.float64, 3), (np.float64, 3)],
        "offsets": [
            mfmm_surface_point.face.offset,
            mfmm_surface_point.bary.offset,
            mfmm_surface_point.xyz.offset,
        ],
        "itemsize": ctypes.sizeof(mfmm_surface_point),
    }
)
ISOLINE_DTYPE = np.dtype(
    {
        "names": ["start", "n_points", "value", "closed"],
        "formats": [np.int64, np.int64, np.int32, np.int32],
        "offsets": [
            mfmm_isoline.start.offset,
            mfmm_isoline.n_points.offset,
            mfmm_isoline.value.offset,
            mfmm_isoline.closed.offset,
        ],
        "itemsize": ctypes.sizeof(mfmm_isoline),
    }
)


# ------------------------------------------------------------ the library
def _candidates() -> list:
    here = Path(__file__).resolve().parent
    names = []
    if sys.platform == "win32":
        names = ["meshfmm.dll", "libmeshfmm.dll"]
    elif sys.platform == "darwin":
        names = ["libmeshfmm.dylib"]
    else:
        names = ["libmeshfmm.so"]
    found = [here / n for n in names]
    # the soname of the ABI mirrored here (libmeshfmm.so.0.2), then any
    # versioned file a build installed (libmeshfmm.so.0.2.0)
    if sys.platform not in ("win32", "darwin"):
        found.append(here / ("libmeshfmm.so." + ".".join(map(str, ABI_VERSION))))
        found += sorted(here.glob("libmeshfmm.so.*"))
    return found


def _find_library() -> str:
    # MESHFMM_LIBRARY, when set, wins (it was ignored, silently, whenever the
    # package carried a library of its own)
    env = os.environ.get("MESHFMM_LIBRARY")
    if env:
        if not Path(env).is_file():
            raise ImportError(f"meshfmm: MESHFMM_LIBRARY={env!r} is not a file (unset it to "
                              "load the library inside the package)")
        return env
    for path in _candidates():
        if path.is_file():
            return str(path)
    raise ImportError(
        "meshfmm: the shared library libmeshfmm was not found inside the package "
        f"({Path(__file__).resolve().parent}); install the package with `pip install .` "
        "at the repository root, or point MESHFMM_LIBRARY at a built libmeshfmm for a "
        "development build"
    )


def _load() -> ctypes.CDLL:
    path = _find_library()
    try:
        found = ctypes.CDLL(path)
    except OSError as exc:
        raise ImportError(f"meshfmm: cannot load the shared library {path!r}: {exc}") from exc
    try:
        fn = found.mfmm_version
        fn.restype = c_char_p
        fn.argtypes = []
        have = fn().decode("ascii")
    except (AttributeError, UnicodeDecodeError) as exc:
        raise ImportError(f"meshfmm: {path!r} is not a meshfmm library: {exc}") from exc
    if tuple(int(x) for x in have.split(".")[:2]) != ABI_VERSION:
        want = ".".join(map(str, ABI_VERSION))
        raise ImportError(f"meshfmm: {path!r} is meshfmm {have}, but this package speaks the "
                          f"ABI of meshfmm {want}.x (build the library of this tree)")
    return found


lib = _load()
library_path: str = lib._name


def _missing(name: str):
    def stub(*args, **kwargs):
        raise NotImplementedError(
            f"meshfmm: the loaded library {library_path} has no function {name} "
            "(built from an older tree?)")
    stub.__name__ = name
    return stub


def _proto(name: str, restype, argtypes):
    """Declares one C function. A symbol the loaded library lacks (a build of
    an older tree) becomes a stub that raises NotImplementedError when called,
    so that the rest of the package still imports."""
    try:
        fn = getattr(lib, name)
    except AttributeError:
        return _missing(name)
    fn.restype = restype
    fn.argtypes = argtypes
    return fn


P = POINTER
mfmm_status_string = _proto("mfmm_status_string", c_char_p, [c_enum])
mfmm_version = _proto("mfmm_version", c_char_p, [])
# mesh
mfmm_mesh_options_init = _proto("mfmm_mesh_options_init", None, [P(mfmm_mesh_options)])
mfmm_mesh_create = _proto(
    "mfmm_mesh_create",
    c_enum,
    # vertices (double *), nv, faces (int32_t *), nf, options, out, err
    [c_void_p, c_int32, c_void_p, c_int32, P(mfmm_mesh_options), P(c_void_p), P(mfmm_error)],
)
mfmm_mesh_destroy = _proto("mfmm_mesh_destroy", None, [c_void_p])
mfmm_mesh_get_info = _proto("mfmm_mesh_get_info", c_enum, [c_void_p, P(mfmm_mesh_info)])
mfmm_mesh_vertex_count = _proto("mfmm_mesh_vertex_count", c_int32, [c_void_p])
mfmm_mesh_face_count = _proto("mfmm_mesh_face_count", c_int32, [c_void_p])
mfmm_mesh_memory = _proto(
    "mfmm_mesh_memory",
    c_int,
    # mesh, names (const char **), bytes (size_t *), max
    [c_void_p, P(c_char_p), P(c_size_t), c_int],
)
# solver
mfmm_solver_create = _proto("mfmm_solver_create", c_enum, [c_void_p, P(c_void_p)])
mfmm_solver_destroy = _proto("mfmm_solver_destroy", None, [c_void_p])
mfmm_solve_options_init = _proto("mfmm_solve_options_init", None, [P(mfmm_solve_options)])
mfmm_solve = _proto(
    "mfmm_solve",
    c_enum,
    # solver, sources (mfmm_source *), n_sources, options, distances (double *), err
    [c_void_p, c_void_p, c_int32, P(mfmm_solve_options), c_void_p, P(mfmm_error)],
)
mfmm_solver_get_info = _proto("mfmm_solver_get_info", c_enum, [c_void_p, P(mfmm_solve_info)])
mfmm_farthest_points = _proto(
    "mfmm_farthest_points",
    c_enum,
    # solver, start, k, options, points (int32_t *), radii (double *), distances (double *), err
    [c_void_p, c_int32, c_int32, P(mfmm_solve_options), c_void_p, c_void_p, c_void_p,
     P(mfmm_error)],
)
mfmm_weld_map = _proto(
    "mfmm_weld_map",
    c_enum,
    # vertices (double *), nv, map (int32_t *), n_welded (int32_t *), err
    [c_void_p, c_int32, c_void_p, P(c_int32), P(mfmm_error)],
)
mfmm_voronoi_labels = _proto(
    "mfmm_voronoi_labels",
    c_enum,
    # mesh, distances (double *), sources (mfmm_source *), n_sources, labels (int32_t *), err
    [c_void_p, c_void_p, c_void_p, c_int32, c_void_p, P(mfmm_error)],
)
mfmm_isolines = _proto(
    "mfmm_isolines",
    c_enum,
    # mesh, field (double *), values (double *), n_values, points (mfmm_surface_point **),
    # n_points, lines (mfmm_isoline **), n_lines, err
    [c_void_p, c_void_p, c_void_p, c_int32, P(c_void_p), P(c_int64), P(c_void_p), P(c_int64),
     P(mfmm_error)],
)
# exact
mfmm_exact_solver_create = _proto("mfmm_exact_solver_create", c_enum, [c_void_p, P(c_void_p)])
mfmm_exact_solver_destroy = _proto("mfmm_exact_solver_destroy", None, [c_void_p])
mfmm_exact_options_init = _proto("mfmm_exact_options_init", None, [P(mfmm_exact_options)])
mfmm_solve_exact = _proto(
    "mfmm_solve_exact",
    c_enum,
    # solver, sources (mfmm_source *), n_sources, options, distances (double *), info, err
    [c_void_p, c_void_p, c_int32, P(mfmm_exact_options), c_void_p, P(mfmm_exact_info),
     P(mfmm_error)],
)
# paths
mfmm_path_options_init = _proto("mfmm_path_options_init", None, [P(mfmm_path_options)])
mfmm_trace_path = _proto(
    "mfmm_trace_path",
    c_enum,
    # mesh, distances (double *), target, options, points (mfmm_surface_point *),
    # capacity, n_points, length, err
    [
        c_void_p,
        c_void_p,
        P(mfmm_source),
        P(mfmm_path_options),
        c_void_p,
        c_int32,
        P(c_int32),
        P(c_double),
        P(mfmm_error),
    ],
)
# matrix
mfmm_backend_name = _proto("mfmm_backend_name", c_char_p, [c_enum])
mfmm_matrix_options_init = _proto("mfmm_matrix_options_init", None, [P(mfmm_matrix_options)])
mfmm_distance_matrix = _proto(
    "mfmm_distance_matrix",
    c_enum,
    # mesh, sources (int32_t *), n_sources, options, info, err
    [c_void_p, c_void_p, c_int32, P(mfmm_matrix_options), P(mfmm_matrix_info), P(mfmm_error)],
)


# I/O
mfmm_opencl_options_init = _proto("mfmm_opencl_options_init", None, [P(mfmm_opencl_options)])
mfmm_opencl_context_create = _proto(
    "mfmm_opencl_context_create",
    c_enum,
    # options (NULL: defaults), out, err
    [P(mfmm_opencl_options), P(c_void_p), P(mfmm_error)],
)
mfmm_opencl_context_destroy = _proto("mfmm_opencl_context_destroy", None, [c_void_p])
mfmm_opencl_context_device_name = _proto("mfmm_opencl_context_device_name", c_char_p, [c_void_p])

mfmm_load_mesh = _proto(
    "mfmm_load_mesh",
    c_enum,
    # path, vertices (double **), nv, faces (int32_t **), nf, err
    [c_char_p, P(c_void_p), P(c_int32), P(c_void_p), P(c_int32), P(mfmm_error)],
)
mfmm_free = _proto("mfmm_free", None, [c_void_p])


def version() -> str:
    """The version string of the loaded library ("MAJOR.MINOR.PATCH")."""
    return mfmm_version().decode("ascii")


# ---------------------------------------------------------------- errors
class MeshError(ValueError):
    """A mesh was refused: wrong shapes, NaN or infinite coordinates, face
    indices out of range, a face that repeats a vertex, or a malformed mesh
    file. A ValueError; ``status`` and ``index`` name the C status and the
    offending vertex/face/line (-1 when none applies)."""

    status: str = ""
    index: int = -1


class OpenCLError(RuntimeError):
    """The OpenCL backend failed: no platform or device, the program did not
    build, or an OpenCL call failed at run time."""

    status: str = ""
    index: int = -1


def status_string(status: int) -> str:
    """The library's sentence for a status code."""
    return mfmm_status_string(status).decode("utf-8", "replace")


_MESH_STATUSES = {
    MFMM_ERR_NONFINITE_VERTEX,
    MFMM_ERR_INDEX_OUT_OF_RANGE,
    MFMM_ERR_REPEATED_VERTEX,
    MFMM_ERR_PARSE,
}
_OPENCL_STATUSES = {MFMM_ERR_NO_OPENCL, MFMM_ERR_OPENCL_BUILD, MFMM_ERR_OPENCL_RUNTIME}


def make_error(status: int, err: Optional[mfmm_error] = None, *, mesh: bool = False,
               context: str = "") -> BaseException:
    """The exception for a failed status. ``mesh`` marks mesh creation, where
    every refusal but out-of-memory is a MeshError."""
    message = ""
    index = -1
    if err is not None and err.status == status:
        message = err.message.decode("utf-8", "replace")
        index = int(err.index)
    if not message:
        message = status_string(status)
    if context:
        message = f"{context}: {message}"
    name = STATUS_NAMES[status] if 0 <= status < MFMM_STATUS_COUNT else f"status {status}"
    exc: BaseException
    if status in (MFMM_ERR_OUT_OF_MEMORY, MFMM_ERR_MEMORY_LIMIT):
        exc = MemoryError(message)
    elif status in _OPENCL_STATUSES:
        exc = OpenCLError(message)
    elif status == MFMM_ERR_IO:
        exc = OSError(message)
    elif mesh or status in _MESH_STATUSES:
        exc = MeshError(message)
    elif status == MFMM_ERR_PATH_STALLED:
        exc = RuntimeError(message)
    elif status == MFMM_ERR_CANCELLED:
        exc = KeyboardInterrupt(message)
    else:
        # NULL pointer, bad count, bad cost/source/barycentric/argument,
        # wrong mesh, unreached target, unknown codes.
        exc = ValueError(message)
    try:
        exc.status = name  # type: ignore[attr-defined]
        exc.index = index  # type: ignore[attr-defined]
    except AttributeError:  # pragma: no cover
        pass
    return exc


def check(status: int, err: Optional[mfmm_error] = None, *, mesh: bool = False,
          context: str = "") -> None:
    """Raises the mapped exception when ``status`` is not MFMM_OK."""
    if status != MFMM_OK:
        raise make_error(status, err, mesh=mesh, context=context)


# The numpy record layouts must be the ctypes mirrors byte for byte.
assert SOURCE_DTYPE.itemsize == ctypes.sizeof(mfmm_source)
assert SURFACE_POINT_DTYPE.itemsize == ctypes.sizeof(mfmm_surface_point)
assert ISOLINE_DTYPE.itemsize == ctypes.sizeof(mfmm_isoline)
