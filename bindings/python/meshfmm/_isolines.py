"""Isolines of a per-vertex field: the level sets of its linear
interpolant over each face, computed in C (``mfmm_isolines``: one pass over
the faces for all the values, then work in proportion to the segments
found, joined into polylines through the edges they share) and turned into
:class:`Isoline` objects (:meth:`Mesh.isolines`) or unjoined segments
(:mod:`meshfmm.plot`); and the ``meshfmm isolines`` command."""

from __future__ import annotations

import ctypes
from ctypes import byref
from typing import Any, List, Tuple

import numpy as np

from . import _args, _lib
from ._types import Isoline


def _copy_out(ptr: ctypes.c_void_p, n: int, dtype: np.dtype) -> np.ndarray:
    """n records of `dtype` at a library-owned address, copied."""
    if n == 0 or not ptr.value:
        return np.empty(0, dtype=dtype)
    raw = (ctypes.c_char * (n * dtype.itemsize)).from_address(ptr.value)
    return np.frombuffer(raw, dtype=dtype).copy()


def compute(mesh_ptr: int, d: np.ndarray, values: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """``mfmm_isolines`` on a C mesh: d (nv,) float64 contiguous, values
    (k,) float64 contiguous. Returns (points, lines): the library's arrays
    copied, as ``_lib.SURFACE_POINT_DTYPE`` and ``_lib.ISOLINE_DTYPE``
    records."""
    pts_ptr, lines_ptr = ctypes.c_void_p(), ctypes.c_void_p()
    n_pts, n_lines = ctypes.c_int64(0), ctypes.c_int64(0)
    err = _lib.mfmm_error()
    status = _lib.mfmm_isolines(mesh_ptr, _args.addr(d), _args.addr(values), values.shape[0],
                                byref(pts_ptr), byref(n_pts), byref(lines_ptr), byref(n_lines),
                                byref(err))
    try:
        _lib.check(status, err)
        return (_copy_out(pts_ptr, n_pts.value, _lib.SURFACE_POINT_DTYPE),
                _copy_out(lines_ptr, n_lines.value, _lib.ISOLINE_DTYPE))
    finally:
        _lib.mfmm_free(pts_ptr)
        _lib.mfmm_free(lines_ptr)


def polylines(points: np.ndarray, lines: np.ndarray, values: np.ndarray) -> List[List[Isoline]]:
    """:func:`compute`'s result as Isoline objects, one list per value."""
    xyz = np.ascontiguousarray(points["xyz"])
    bary = np.ascontiguousarray(points["bary"])
    faces = np.ascontiguousarray(points["face"])
    vals = values.tolist()
    out: List[List[Isoline]] = [[] for _ in vals]
    for start, n, j, closed in lines.tolist():
        end = start + n
        out[j].append(Isoline(value=vals[j], points=xyz[start:end], faces=faces[start:end],
                              barycentric=bary[start:end], closed=bool(closed)))
    return out


def segments(points: np.ndarray, lines: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """:func:`compute`'s polylines cut into their segments: (ends (m, 2, 3)
    float64, faces (m,) int64), segment i-1 -> i of a polyline on point i's
    face."""
    second = np.ones(points.shape[0], dtype=bool)
    second[lines["start"]] = False
    k = np.flatnonzero(second)
    xyz = points["xyz"]
    return np.stack([xyz[k - 1], xyz[k]], axis=1), points["face"][k].astype(np.int64)


# ------------------------------------------------------------ the command
def _read_numbers(path: str) -> np.ndarray:
    """A 1-D vector from .npy, or from text (numbers separated by blanks,
    newlines or commas; '#' comments)."""
    if path.lower().endswith(".npy"):
        a = np.load(path, allow_pickle=False)
        if a.ndim == 2 and 1 in a.shape:
            a = a.ravel()
        if a.ndim != 1 or a.dtype.kind not in "iuf":
            raise ValueError(f"{path}: a 1-D array of numbers is needed, got {a.dtype} "
                             f"of shape {a.shape}")
        return a
    with open(path) as f:
        text = " ".join(line.split("#", 1)[0] for line in f)
    try:
        return np.array([float(x) for x in text.replace(",", " ").split()])
    except ValueError:
        raise ValueError(f"{path}: numbers separated by blanks or newlines are needed") from None


def _ids(path: str) -> List[int]:
    a = _read_numbers(path)
    if a.size == 0:
        raise ValueError(f"{path}: no sources")
    if a.dtype.kind == "f" and not np.array_equal(a, np.floor(a)):
        raise ValueError(f"{path}: the sources must be vertex ids (whole numbers)")
    return [int(x) for x in a]


def _write_atomic(path: str, text: str) -> None:
    """`text` into a temporary file beside `path`, renamed over it when
    complete (no half-written file under the name)."""
    import os
    import tempfile

    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=os.path.basename(path) + ".", dir=folder)
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def _obj_text(per_value: List[List[Isoline]], values: np.ndarray, mesh_path: str) -> str:
    """OBJ polylines: per value an object (``o``) of v records and one ``l``
    record per polyline (a closed one ends at its first vertex again)."""
    n_lines = sum(len(lines) for lines in per_value)
    out = [f"# meshfmm isolines of {mesh_path}: {n_lines} polylines at {len(values)} "
           "values\n"]
    base = 1
    for j, (c, lines) in enumerate(zip(values.tolist(), per_value)):
        out.append(f"# isoline {j}: value {c!r}, {len(lines)} polylines\no isoline_{j}\n")
        for ln in lines:
            pts = ln.points[:-1] if ln.closed else ln.points
            out.extend(f"v {x!r} {y!r} {z!r}\n" for x, y, z in pts.tolist())
            ids = list(range(base, base + pts.shape[0]))
            if ln.closed:
                ids.append(base)
            out.append("l " + " ".join(map(str, ids)) + "\n")
            base += pts.shape[0]
    return "".join(out)


def _csv_text(per_value: List[List[Isoline]], values: np.ndarray) -> str:
    """One row per point: value, polyline (numbered per value), closed,
    face, barycentric coordinates, position."""
    out = ["value,line,closed,face,b0,b1,b2,x,y,z\n"]
    for c, lines in zip(values.tolist(), per_value):
        for i, ln in enumerate(lines):
            head = f"{c!r},{i},{int(ln.closed)},"
            for f, b, p in zip(ln.faces.tolist(), ln.barycentric.tolist(), ln.points.tolist()):
                out.append(head + f"{f}," + ",".join(repr(x) for x in b + p) + "\n")
    return "".join(out)


def cli_isolines(argv: Any) -> int:
    """``meshfmm isolines MESH --source V ... --values A,B,... -o OUT.obj``:
    the isolines of the distance from the sources (or of a per-vertex field
    from a file) at the values, written as OBJ polylines or CSV. Errors are
    one line on standard error and exit status 2."""
    import argparse
    import os
    import sys

    ap = argparse.ArgumentParser(
        prog="meshfmm isolines",
        description="The isolines of the geodesic distance from the sources (or of a field "
                    "given per vertex) at given values, as polylines: where the linear "
                    "interpolant over each face equals a value (Mesh.isolines).")
    ap.add_argument("mesh", help="OBJ, OFF, PLY or STL")
    ap.add_argument("-o", "--output", required=True, metavar="OUT",
                    help="OUT.obj: per value an object (o isoline_J) of v records and one l "
                         "record per polyline (a closed one ends at its first vertex): OBJ "
                         "polylines, which Blender imports as edges; OUT.csv: one row per point (value, "
                         "line, closed, face, b0, b1, b2, x, y, z; a closed line repeats its "
                         "first point). Written to a temporary file beside OUT, then renamed")
    ap.add_argument("--values", required=True, metavar="A,B,...",
                    help="the levels, comma-separated")
    ap.add_argument("--source", type=int, action="append", default=[], metavar="V",
                    help="a source vertex (repeat for several)")
    ap.add_argument("--sources", metavar="FILE",
                    help="source vertex ids from a file: .txt (as meshfmm landmarks writes) "
                         "or .npy")
    ap.add_argument("--field", metavar="FILE",
                    help="a per-vertex field instead of a solve: .npy or .txt, one value per "
                         "vertex (as meshfmm distance writes); no sources then")
    ap.add_argument("--method", choices=["fmm", "windows", "exact"], default="fmm",
                    help="distance method: fmm (default), windows (more accurate, never "
                         "below the geodesic distance) or exact (Mesh.distance's method)")
    ap.add_argument("--max-distance", type=float, metavar="X",
                    help="stop the solve past X; farther vertices are unreached")
    ap.add_argument("--cost", metavar="FILE",
                    help="slowness F (.npy or .txt), one value per vertex (default) or per "
                         "face (--cost-per-face); fmm only")
    ap.add_argument("--cost-per-face", action="store_true", help="--cost holds one value per "
                    "face")
    ap.add_argument("--weld", action="store_true",
                    help="weld vertices at the same position (texture seams, unmerged "
                         "corners) first, as meshfmm weld does; ids stay the file's")
    args = ap.parse_args(list(argv))

    def fail(msg: str) -> int:
        sys.stderr.write(f"meshfmm isolines: {msg}\n")
        return 2

    out = args.output
    lower = out.lower()
    if not (lower.endswith(".obj") or lower.endswith(".csv")):
        return fail("the output must end in .obj or .csv")
    if args.cost_per_face and not args.cost:
        return fail("--cost-per-face needs --cost")
    if args.field and (args.source or args.sources or args.cost or args.max_distance is not None
                       or args.method != "fmm"):
        return fail("--field gives the values to draw: it takes no sources, --cost, "
                    "--max-distance or --method")
    if not args.field and not (args.source or args.sources):
        return fail("no source given (--source V, --sources FILE or --field FILE)")
    try:
        values = np.array([float(x) for x in args.values.split(",") if x.strip()])
    except ValueError:
        return fail(f"--values must be numbers separated by commas, not {args.values!r}")
    if values.size == 0 or not np.isfinite(values).all():
        return fail("--values must be finite numbers separated by commas")
    for given in (args.mesh, args.field, args.sources, args.cost):
        if given and os.path.exists(out) and os.path.exists(given) and \
                os.path.samefile(out, given):
            return fail(f"the output {out!r} is the input {given!r}; refusing to overwrite it")

    from ._lib import MeshError
    from ._mesh import Mesh

    try:
        mesh = Mesh.from_file(args.mesh, weld=True) if args.weld else _quiet_mesh(args.mesh)
        if args.field:
            d = _read_numbers(args.field).astype(np.float64)
            if d.shape != (mesh.n_vertices,):
                return fail(f"{args.field}: {d.shape[0]} values, the mesh has "
                            f"{mesh.n_vertices} vertices")
        else:
            sources = list(args.source) + (_ids(args.sources) if args.sources else [])
            cost = _read_numbers(args.cost) if args.cost else None
            d = mesh.distance(sources, cost, args.max_distance, method=args.method,
                              cost_location=("face" if args.cost_per_face else "vertex")
                              if args.cost else None)
        per_value = mesh.isolines(d, values)
        text = _obj_text(per_value, values, args.mesh) if lower.endswith(".obj") \
            else _csv_text(per_value, values)
        _write_atomic(out, text)
    except (OSError, ValueError, TypeError, MeshError) as e:
        return fail(str(e) or type(e).__name__)
    n = sum(len(lines) for lines in per_value)
    print(f"meshfmm isolines: wrote {out} ({n} polylines at {values.size} values)")
    return 0


def _quiet_mesh(path: str) -> Any:
    """Mesh.from_file, its coincident-vertices warning as one line on
    standard error (naming --weld) instead of a Python warning."""
    import sys
    import warnings

    from ._mesh import Mesh
    from ._types import MeshWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", MeshWarning)
        mesh = Mesh.from_file(path)
    noted = False
    for w in caught:
        if not issubclass(w.category, MeshWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        elif not noted:
            sys.stderr.write("meshfmm isolines: note: the mesh has coincident vertices "
                             "(texture seams, unmerged corners); --weld welds them\n")
            noted = True
    return mesh
