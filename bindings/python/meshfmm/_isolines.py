"""Isolines of a per-vertex field: the level sets of its linear
interpolant over each face, as segments (:func:`segments`, :func:`crossings`
for one value; :mod:`meshfmm.plot` draws them) or as polylines
(:func:`isolines`, :meth:`Mesh.isolines`: the segments joined through the
edges they share); and the ``meshfmm isolines`` command.

Any number of values costs one pass over the faces (each vertex's rank
among the sorted values; each face's least and greatest corner rank: the
values it crosses), then work in proportion to the segments found."""

from __future__ import annotations

from typing import Any, List, Tuple

import numpy as np

from ._types import Isoline

Segments = Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def segments(V: np.ndarray, F: np.ndarray, d: np.ndarray, values: Any) -> Segments:
    """Where the linear interpolant of d over the faces equals each of
    `values`: one segment per face and value when the face's corners are
    not all on one side (a corner counts as above when d >= value: the face
    crosses the values in (least corner, greatest corner]; faces with a
    non-finite corner hold none), between the two points where its edges
    cross. Each crossing point is interpolated from its edge's lower vertex
    id, so faces that share an edge share the point bit for bit.

    Returns
    -------
    which : numpy.ndarray, int64 (m,)
        The index in `values` of each segment; ascending, and within one
        value the faces ascending.
    faces : numpy.ndarray, int64 (m,)
        The face of each segment.
    points : numpy.ndarray, float64 (m, 2, 3)
        The segments' ends.
    barycentric : numpy.ndarray, float64 (m, 2, 3)
        Each end's coordinates in its face.
    edges : numpy.ndarray, int64 (m, 2)
        Each end's edge, as lower id * n_vertices + higher id.
    """
    vals = np.atleast_1d(np.asarray(values, dtype=np.float64)).ravel()
    nv, nf = V.shape[0], F.shape[0]
    order = np.argsort(vals, kind="stable")
    sv = vals[order]
    # k(x), the count of values <= x, per vertex (-1: not finite); a face
    # crosses the values in (least corner, greatest corner], those of sorted
    # index k(least) <= i < k(greatest), and k is monotone: one pass over
    # the faces takes the least and greatest k of their corners
    kv = np.searchsorted(sv, d, side="right").astype(np.int32)
    kv[~np.isfinite(d)] = -1  # faces with such a corner hold none
    kF = kv[F]
    a, b, c3 = kF[:, 0], kF[:, 1], kF[:, 2]
    k0 = np.minimum(np.minimum(a, b), c3)
    k1 = np.maximum(np.maximum(a, b), c3)
    count = np.where(k0 >= 0, k1 - k0, 0)
    fids = np.repeat(np.arange(nf, dtype=np.int64), count)
    if fids.size == 0:
        empty = np.empty(0, np.int64)
        return (empty, empty, np.empty((0, 2, 3)), np.empty((0, 2, 3)),
                np.empty((0, 2), np.int64))
    first = np.cumsum(count) - count
    rank = np.arange(fids.size) - np.repeat(first, count) + np.repeat(k0, count)
    which = order[rank]
    sort = np.lexsort((fids, which))
    which, fids = which[sort], fids[sort]
    c = vals[which]
    # the segments: work in proportion to their count
    Fc = F[fids].astype(np.int64)
    Ac = d[Fc] >= c[:, None]
    # edge k of a face: corners (k+1, k+2) mod 3, opposite corner k; exactly
    # two cross: the segment's ends, in local order
    quiet = np.where(Ac[:, 1] == Ac[:, 2], 0, np.where(Ac[:, 0] == Ac[:, 2], 1, 2))
    seg_edges = np.array([[1, 2], [0, 2], [0, 1]])[quiet]
    rows = np.arange(fids.size)[:, None]
    kp, kq = (seg_edges + 1) % 3, (seg_edges + 2) % 3  # the edges' corners
    p, q = Fc[rows, kp], Fc[rows, kq]
    swap = p > q
    lo, hi = np.where(swap, q, p), np.where(swap, p, q)
    klo, khi = np.where(swap, kq, kp), np.where(swap, kp, kq)
    dl, dh = d[lo], d[hi]
    t = (c[:, None] - dl) / (dh - dl)
    X = V[lo] + t[..., None] * (V[hi] - V[lo])
    B = np.zeros((fids.size, 2, 3))
    ends = np.arange(2)[None, :]
    B[rows, ends, klo] = 1.0 - t
    B[rows, ends, khi] = t
    return which, fids, X, B, lo * nv + hi


def crossings(V: np.ndarray, F: np.ndarray, d: np.ndarray, value: float
              ) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`segments` of one value: (faces, points, barycentric, edges),
    the faces ascending."""
    _, fids, X, B, keys = segments(V, F, d, [value])
    return fids, X, B, keys


def _join(c: float, fids: np.ndarray, X: np.ndarray, B: np.ndarray,
          keys: np.ndarray) -> List[Isoline]:
    """One value's segments joined into polylines through the edges they
    share: open ones from their ends (in edge order), then the loops; at an
    edge that more than two segments share (a non-manifold edge) a polyline
    goes on with the first unused one."""
    m = fids.size
    if m == 0:
        return []
    uniq, flat = np.unique(keys.ravel(), return_inverse=True)
    flat = flat.ravel()  # entry 2 s + e: the node (edge) of segment s's end e
    deg = np.bincount(flat, minlength=uniq.size)
    byn = np.argsort(flat, kind="stable")  # entries grouped by node, ascending
    partner = np.full(2 * m, -1, dtype=np.int64)  # the other entry at the same node
    if deg.max() <= 2:
        same = flat[byn[:-1]] == flat[byn[1:]]
        partner[byn[:-1][same]] = byn[1:][same]
        partner[byn[1:][same]] = byn[:-1][same]
        nxt_of = None
    else:
        starts = np.concatenate([[0], np.cumsum(deg)])
        nxt_of = [byn[starts[n]:starts[n + 1]].tolist() for n in range(uniq.size)]
    node = flat.tolist()
    part = partner.tolist()
    used = [False] * m
    faces32 = fids.astype(np.int32)

    def walk(s_: int, e: int) -> Isoline:
        seg, end = [s_], [e]  # enter segment s_ at its end e
        first_node = node[2 * s_ + e]
        closed = False
        while True:
            used[s_] = True
            o = 1 - e
            seg.append(s_)
            end.append(o)
            ent = 2 * s_ + o
            if node[ent] == first_node:
                closed = True
                break
            if nxt_of is None:
                p = part[ent]
                if p < 0 or used[p >> 1]:
                    break
            else:
                p = next((x for x in nxt_of[node[ent]] if not used[x >> 1]), -1)
                if p < 0:
                    break
            s_, e = p >> 1, p & 1
        si, ei = np.array(seg), np.array(end)
        return Isoline(value=c, points=X[si, ei], faces=faces32[si], barycentric=B[si, ei],
                       closed=closed)

    lines: List[Isoline] = []
    for ent in byn[deg[flat[byn]] == 1].tolist():  # the ends, by node
        if not used[ent >> 1]:
            lines.append(walk(ent >> 1, ent & 1))
    for s_ in range(m):
        if not used[s_]:
            lines.append(walk(s_, 0))
    return lines


def isolines(V: np.ndarray, F: np.ndarray, d: np.ndarray, values: Any) -> List[List[Isoline]]:
    """For each of `values`, the polylines where the linear interpolant of
    d over the faces equals it: :func:`segments` (one pass over the faces
    for all values), each value's joined through the edges they share."""
    vals = np.atleast_1d(np.asarray(values, dtype=np.float64)).ravel()
    which, fids, X, B, keys = segments(V, F, d, vals)
    bounds = np.searchsorted(which, np.arange(vals.size + 1))
    return [_join(float(c), fids[a:b], X[a:b], B[a:b], keys[a:b])
            for c, a, b in zip(vals.tolist(), bounds[:-1], bounds[1:])]


def fix_faces(lines: List[Isoline], faces_out: Any) -> List[Isoline]:
    """The same polylines with face ids mapped by `faces_out`."""
    return [Isoline(value=ln.value, points=ln.points, faces=faces_out(ln.faces),
                    barycentric=ln.barycentric, closed=ln.closed) for ln in lines]


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
    ap.add_argument("--method", choices=["fmm", "exact"], default="fmm",
                    help="distance method (default: fmm)")
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
