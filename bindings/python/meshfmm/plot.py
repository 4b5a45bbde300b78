"""Pictures of distance fields: :func:`render` draws a field on its mesh
with isolines and paths into a PNG, and ``meshfmm render`` does the same
from the command line.

Needs matplotlib (the ``[plot]`` extra: ``pip install 'meshfmm[plot]'``);
nothing else. The mesh is drawn by the painter's algorithm in an
orthographic view: each face coloured by its mean distance and shaded by its
normal, sorted back to front, with the isolines and paths drawn just above
the face they cross.
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _extras, _isolines

__all__ = ["render", "default_view", "isoline_segments"]

#: Colour of faces whose distance is not finite (never reached).
UNREACHED_RGB = (0.6, 0.6, 0.6)


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v)
    if not np.isfinite(n) or n == 0:
        raise ValueError(f"a direction must be a non-zero finite vector, not {v.tolist()}")
    return v / n


def default_view(vertices: Any, elevation: float = 25.0,
                 azimuth: float = 30.0) -> Tuple[np.ndarray, np.ndarray]:
    """The default camera for a mesh, from its bounding box.

    The box's longest side runs across the picture and its second longest
    up it, so that the view looks along the shortest side (a flat mesh is
    seen from the front); the eye is then raised by `elevation` and turned
    by `azimuth` degrees so that the relief shows.

    Parameters
    ----------
    vertices : array_like, shape (n, 3)
    elevation, azimuth : float
        Degrees.

    Returns
    -------
    view : numpy.ndarray, shape (3,)
        Unit vector from the mesh towards the eye.
    up : numpy.ndarray, shape (3,)
        Unit vector that points up in the picture.
    """
    V = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    extent = V.max(axis=0) - V.min(axis=0) if V.shape[0] else np.ones(3)
    # longest first; ties in axis order (x, y, z)
    order = np.argsort(-extent, kind="stable")
    axes = np.eye(3)
    right, up = axes[order[0]], axes[order[1]]
    back = np.cross(right, up)
    el, az = np.radians(elevation), np.radians(azimuth)
    view = np.cos(el) * (np.cos(az) * back + np.sin(az) * right) + np.sin(el) * up
    view = _unit(view)
    up = _unit(up - np.dot(up, view) * view)
    return view, up


def isoline_segments(vertices: Any, faces: Any, values: Any,
                     level: float) -> Tuple[np.ndarray, np.ndarray]:
    """Where the linear interpolant of `values` over each face equals `level`.

    The segments of :meth:`Mesh.isolines <meshfmm.Mesh.isolines>`'
    polylines, taken apart: a face whose corners are not all on one side of
    `level` (corners equal to it count as above) holds one segment, between
    the two points where its edges cross, each found by linear interpolation
    along the edge. Faces with a non-finite value hold none. The mesh must
    be one :class:`~meshfmm.Mesh` accepts; it is built for the call.

    Returns
    -------
    segments : numpy.ndarray, float64 (k, 2, 3)
        The segments' end points, each in the direction of its polyline.
    faces : numpy.ndarray, int64 (k,)
        The face of each segment, ascending.
    """
    V = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    F = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    d = np.asarray(values, dtype=np.float64).ravel()
    if d.shape[0] != V.shape[0]:
        raise ValueError(f"values has {d.shape[0]} entries for {V.shape[0]} vertices")
    seg, fids = _segments(None, V, F, d, np.array([float(level)]))
    order = np.argsort(fids, kind="stable")
    return seg[order], fids[order]


def _segments(mesh: Any, V: np.ndarray, F: np.ndarray, d: np.ndarray,
              levels: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Every level's isoline segments (:meth:`Mesh.isolines`' polylines cut
    at their points: one pass over the faces for all levels, in C), as
    (ends (k, 2, 3), faces (k,) int64); `mesh` a :class:`Mesh`, or anything
    else to build one from V and F. NaN values hold none, as infinite ones."""
    if levels.size == 0:
        return np.empty((0, 2, 3)), np.empty(0, dtype=np.int64)
    import warnings

    from ._mesh import Mesh
    from ._types import MeshWarning

    if not isinstance(mesh, Mesh):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshWarning)
            mesh = Mesh(V, F)
    d = np.where(np.isnan(d), np.inf, d)
    points, lines = mesh._isoline_records(d, levels)
    return _isolines.segments(points, lines)


def _levels(isolines: Union[None, int, Sequence[float]], lo: float, hi: float) -> np.ndarray:
    if isolines is None or isolines is False:
        return np.empty(0)
    if isolines is True:
        isolines = 10
    if isinstance(isolines, (int, np.integer)) and not isinstance(isolines, bool):
        if isolines < 0:
            raise ValueError(f"isolines must be >= 0 or a list of values, not {isolines}")
        if isolines == 0 or not hi > lo:
            return np.empty(0)
        # evenly spaced inside (lo, hi): neither the source nor the farthest point
        return lo + (hi - lo) * np.arange(1, isolines + 1) / (isolines + 1)
    levels = np.asarray(isolines, dtype=np.float64).ravel()
    if not np.isfinite(levels).all():
        raise ValueError("isoline values must be finite")
    return levels


def _quads(p: np.ndarray, q: np.ndarray, half_width: float) -> np.ndarray:
    """Screen-space segments p->q (k, 2) as quadrilaterals (k, 4, 2)."""
    t = q - p
    n = np.linalg.norm(t, axis=1, keepdims=True)
    t = np.divide(t, n, out=np.zeros_like(t), where=n > 0)
    o = np.stack([-t[:, 1], t[:, 0]], axis=1) * half_width
    # a little past each end, so that consecutive pieces join
    p = p - t * half_width
    q = q + t * half_width
    return np.stack([p + o, q + o, q - o, p - o], axis=1)


def _path_arrays(path: Any) -> Tuple[np.ndarray, Optional[np.ndarray]]:
    if hasattr(path, "points"):
        faces = getattr(path, "faces", None)
        return (np.asarray(path.points, dtype=np.float64).reshape(-1, 3),
                None if faces is None else np.asarray(faces, dtype=np.int64).ravel())
    return np.asarray(path, dtype=np.float64).reshape(-1, 3), None


def render(mesh: Any, distances: Any, path_png: Union[str, "os.PathLike[str]"], *,
           isolines: Union[None, int, Sequence[float]] = 10,
           paths: Optional[Sequence[Any]] = None,
           cmap: str = "viridis", size: Tuple[int, int] = (800, 600),
           view: Any = None, up: Any = None, title: Optional[str] = None,
           colorbar: bool = True, isoline_color: str = "white",
           path_color: str = "#e8202a") -> str:
    """Draws a distance field on its mesh, with isolines and paths, into a PNG.

    Each face is coloured by the mean of its corners' distances (faces with
    an infinite distance in grey) and shaded by its normal (lit from the
    eye, both sides alike); isolines are where the linear interpolant over
    each face equals a level; faces, isolines and paths are drawn back to
    front in an orthographic view.

    Parameters
    ----------
    mesh : Mesh or object with ``.vertices`` and ``.faces``
    distances : array_like, shape (nv,)
        One value per vertex (``Mesh.distance``'s result, or any scalar
        field).
    path_png : str or os.PathLike
        The PNG to write.
    isolines : int or sequence of float or None
        A number of levels evenly spaced between 0 (or the smallest value)
        and the largest finite value, or the levels themselves; 0, None or
        False for none (True: 10).
    paths : sequence, optional
        Polylines on the surface: :class:`~meshfmm.GeodesicPath` objects
        (drawn above the faces they run through) or (k, 3) arrays of points
        (drawn above everything).
    cmap : str
        A matplotlib colour map.
    size : (int, int)
        Width and height in pixels.
    view : array_like (3,), optional
        Direction from the mesh towards the eye; default
        :func:`default_view`'s.
    up : array_like (3,), optional
        The direction that points up in the picture (made perpendicular to
        `view`); default :func:`default_view`'s.
    title : str, optional
    colorbar : bool
        A colour bar of the distances on the right.
    isoline_color, path_color : str
        Matplotlib colours.

    Returns
    -------
    str
        `path_png`.

    Raises
    ------
    ImportError
        matplotlib is not installed (the ``[plot]`` extra), before anything
        is drawn.
    ValueError
        `distances` does not have one value per vertex, or a bad `view`,
        `up`, `size` or `isolines`; with isolines, a mesh (not a
        :class:`~meshfmm.Mesh`) that :class:`~meshfmm.Mesh` refuses (the
        isolines are :meth:`Mesh.isolines <meshfmm.Mesh.isolines>`').
    """
    _extras.require("meshfmm.plot.render", "plot")
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import Normalize, to_rgba
    from matplotlib.figure import Figure

    if not (hasattr(mesh, "vertices") and hasattr(mesh, "faces")):
        raise TypeError(f"mesh must have .vertices and .faces, not {type(mesh).__name__}")
    V = np.asarray(mesh.vertices, dtype=np.float64).reshape(-1, 3)
    F = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    d = np.asarray(distances, dtype=np.float64).ravel()
    if d.shape[0] != V.shape[0]:
        raise ValueError(f"distances has {d.shape[0]} values for {V.shape[0]} vertices")
    width, height = (int(s) for s in size)
    if width < 16 or height < 16:
        raise ValueError(f"size must be at least 16 x 16 pixels, not {size}")

    dview, dup = default_view(V)
    eye = dview if view is None else _unit(np.asarray(view, dtype=np.float64).ravel()[:3])
    upv = dup if up is None else np.asarray(up, dtype=np.float64).ravel()[:3]
    if view is not None and up is None and abs(np.dot(upv, eye)) > 0.99:
        upv = np.eye(3)[int(np.argmin(np.abs(eye)))]
    upv = _unit(upv - np.dot(upv, eye) * eye)
    right = np.cross(upv, eye)

    X = np.stack([V @ right, V @ upv], axis=1)  # screen
    Z = V @ eye                                  # larger: nearer the eye
    depth = Z[F].mean(axis=1)
    scale = float(np.ptp(X, axis=0).max()) if V.shape[0] else 1.0
    scale = scale if scale > 0 else 1.0
    eps = 1e-6 * (float(np.ptp(Z)) + scale)

    finite = d[np.isfinite(d)]
    lo = float(min(0.0, finite.min())) if finite.size else 0.0
    hi = float(finite.max()) if finite.size else 1.0
    norm = Normalize(vmin=lo, vmax=hi if hi > lo else lo + 1.0)
    cm = colormaps[cmap]

    # faces: colour of the mean distance, shaded by |normal . eye|
    fd = d[F]
    face_ok = np.isfinite(fd).all(axis=1)
    rgb = np.empty((F.shape[0], 3))
    rgb[face_ok] = cm(norm(fd[face_ok].mean(axis=1)))[:, :3]
    rgb[~face_ok] = UNREACHED_RGB
    nrm = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    ln = np.linalg.norm(nrm, axis=1)
    cosine = np.abs(nrm @ eye) / np.where(ln > 0, ln, 1.0)
    shade = 0.35 + 0.65 * np.where(ln > 0, cosine, 0.0)
    face_rgba = np.concatenate([rgb * shade[:, None], np.ones((F.shape[0], 1))], axis=1)

    # triangles as quadrilaterals (last corner twice), to share one array
    # with the isolines' and paths' quadrilaterals
    polys: List[np.ndarray] = [X[F[:, [0, 1, 2, 2]]]]
    colors: List[np.ndarray] = [face_rgba]
    keys: List[np.ndarray] = [depth]
    widths: List[np.ndarray] = [np.full(F.shape[0], 0.3)]
    on_top: List[Tuple[np.ndarray, Any]] = []

    iso_half = 0.0018 * scale * 800.0 / max(width, height) + 0.0008 * scale
    # every level's segments from one pass over the faces
    seg, seg_faces = _segments(mesh, V, F, d, _levels(isolines, lo, hi))
    if seg.shape[0]:
        p = np.stack([seg[:, 0] @ right, seg[:, 0] @ upv], axis=1)
        q = np.stack([seg[:, 1] @ right, seg[:, 1] @ upv], axis=1)
        polys.append(_quads(p, q, iso_half))
        colors.append(np.tile(to_rgba(isoline_color, 0.9), (seg.shape[0], 1)))
        keys.append(depth[seg_faces] + eps)
        widths.append(np.zeros(seg.shape[0]))

    path_half = 2.2 * iso_half
    for path in paths or ():
        pts, pfaces = _path_arrays(path)
        if pts.shape[0] < 2:
            continue
        S = np.stack([pts @ right, pts @ upv], axis=1)
        quads = _quads(S[:-1], S[1:], path_half)
        if pfaces is not None and pfaces.shape[0] == pts.shape[0]:
            # segment i-1 -> i runs through faces[i]
            polys.append(quads)
            colors.append(np.tile(to_rgba(path_color), (quads.shape[0], 1)))
            keys.append(depth[pfaces[1:]] + 2 * eps)
            widths.append(np.zeros(quads.shape[0]))
        else:
            on_top.append((quads, path_color))

    allp = np.concatenate(polys)
    allc = np.concatenate(colors)
    order = np.argsort(np.concatenate(keys), kind="stable")
    allw = np.concatenate(widths)[order]

    dpi = 100
    fig = Figure(figsize=(width / dpi, height / dpi), dpi=dpi, facecolor="white")
    ax = fig.add_axes((0.02, 0.02, 0.80 if colorbar else 0.96, 0.90 if title else 0.96))
    ax.set_axis_off()
    ax.set_aspect("equal")
    # the faces' edges in their own colour close the hairline seams
    ax.add_collection(PolyCollection(allp[order], facecolors=allc[order],
                                     edgecolors=allc[order], linewidths=allw))
    for quads, color in on_top:
        ax.add_collection(PolyCollection(quads, facecolors=color, edgecolors=color,
                                         linewidths=0, zorder=3))
    pad = 0.03 * scale
    if X.shape[0]:
        ax.set_xlim(X[:, 0].min() - pad, X[:, 0].max() + pad)
        ax.set_ylim(X[:, 1].min() - pad, X[:, 1].max() + pad)
    if title:
        fig.suptitle(title)
    if colorbar:
        cax = fig.add_axes((0.86, 0.15, 0.03, 0.7))
        sm = ScalarMappable(norm=norm, cmap=cm)
        fig.colorbar(sm, cax=cax, label="geodesic distance")
    fig.savefig(os.fspath(path_png), dpi=dpi, facecolor="white")
    return os.fspath(path_png)


# ------------------------------------------------------------ the command
def cli_render(argv: Sequence[str]) -> int:
    """``meshfmm render MESH -o OUT.png [--source V]... [--path-to T]...``:
    the distance from the sources (vertex 0 by default) drawn with
    :func:`render`. Errors are one line on standard error and exit status 2."""
    ap = argparse.ArgumentParser(
        prog="meshfmm render",
        description="Draw the geodesic distance from the sources on the mesh, with "
                    "isolines and paths, into a PNG (needs matplotlib).")
    ap.add_argument("mesh", help="OBJ, OFF, PLY or STL")
    ap.add_argument("-o", "--output", required=True, help="OUT.png")
    ap.add_argument("--source", type=int, action="append", metavar="V",
                    help="source vertex (repeat for several; default: 0)")
    ap.add_argument("--path-to", type=int, action="append", default=[], metavar="T",
                    help="draw the geodesic path from vertex T to its nearest source "
                         "(repeat for several)")
    ap.add_argument("--isolines", type=int, default=10, metavar="N",
                    help="number of evenly spaced isolines, 0 for none (default: 10)")
    ap.add_argument("--levels", metavar="A,B,...",
                    help="isoline values, comma-separated (instead of --isolines)")
    ap.add_argument("--method", choices=["fmm", "windows", "exact"], default="fmm",
                    help="distance method: fmm (default), windows (more accurate, never "
                         "below the geodesic distance) or exact (Mesh.distance's method)")
    ap.add_argument("--size", type=int, nargs=2, default=[800, 600], metavar=("W", "H"),
                    help="picture size in pixels (default: 800 600)")
    ap.add_argument("--cmap", default="viridis", help="matplotlib colour map (default: viridis)")
    ap.add_argument("--view", type=float, nargs=3, metavar=("X", "Y", "Z"),
                    help="direction from the mesh towards the eye (default: from the "
                         "bounding box)")
    ap.add_argument("--up", type=float, nargs=3, metavar=("X", "Y", "Z"),
                    help="direction that points up in the picture")
    ap.add_argument("--title", help="a title above the picture")
    ap.add_argument("--no-colorbar", action="store_true", help="leave out the colour bar")
    args = ap.parse_args(list(argv))

    def fail(msg: str) -> int:
        sys.stderr.write(f"meshfmm render: {msg}\n")
        return 2

    try:
        _extras.require("meshfmm render", "plot")
    except ImportError as e:
        sys.stderr.write(f"{e}\n")
        return 2
    from ._lib import MeshError
    from ._mesh import Mesh

    levels: Union[int, List[float]] = args.isolines
    if args.levels:
        try:
            levels = [float(x) for x in args.levels.split(",") if x.strip()]
        except ValueError:
            return fail(f"--levels must be numbers separated by commas, not {args.levels!r}")
    sources = args.source or [0]
    try:
        mesh = Mesh.from_file(args.mesh)
        d = mesh.distance(sources, method=args.method)
        paths = [mesh.geodesic_path(d, t, sources=sources) for t in args.path_to]
        render(mesh, d, args.output, isolines=levels, paths=paths, cmap=args.cmap,
               size=tuple(args.size), view=args.view, up=args.up, title=args.title,
               colorbar=not args.no_colorbar)
    except (OSError, ValueError, TypeError, KeyError, MeshError) as e:
        msg = e.args[0] if isinstance(e, KeyError) and e.args else e
        return fail(str(msg) or type(e).__name__)
    print(f"meshfmm render: wrote {args.output}")
    return 0
