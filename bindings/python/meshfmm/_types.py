"""The value types of the Python API: SurfacePoint, MeshInfo, GeodesicPath
and MatrixInfo."""

from __future__ import annotations

import dataclasses
from typing import NamedTuple, Sequence, Union

import numpy as np

__all__ = ["SurfacePoint", "MeshInfo", "GeodesicPath", "MatrixInfo", "Isoline", "MeshWarning",
           "SourceLike"]


class MeshWarning(UserWarning):
    """A mesh is accepted but likely not what was meant: coincident vertices
    (texture seams, unmerged STL corners) cut its surface. The message
    names the counts and ``Mesh(V, F, weld=True)``, which welds them."""


class SurfacePoint(NamedTuple):
    """A point inside a face, usable as a source of :meth:`Mesh.distance`
    and as a target of :meth:`Mesh.geodesic_path`.

    Attributes
    ----------
    face : int
        Face id, 0-based.
    bary : sequence of 3 float
        Barycentric coordinates, >= 0 and summing to 1: the weights of the
        face's corners in the order the face lists them.
    """

    face: int
    bary: Sequence[float]


#: What a ``sources`` argument accepts: a vertex id, a SurfacePoint, a
#: sequence mixing those, or an integer array of vertex ids.
SourceLike = Union[int, SurfacePoint, Sequence[Union[int, SurfacePoint]], np.ndarray]


@dataclasses.dataclass(frozen=True)
class MeshInfo:
    """Diagnostics of a mesh, computed once when it is created
    (``mfmm_mesh_info``). Counts are ints, lengths floats."""

    n_vertices: int  #: vertices as given
    n_faces: int  #: faces as given
    n_edges: int  #: distinct undirected edges (of the surface built: T-junctions closed)
    n_boundary_edges: int  #: edges with one face
    n_nonmanifold_edges: int  #: edges with three or more faces
    n_components: int  #: edge-connected components of referenced vertices
    n_unreferenced_vertices: int  #: vertices no face names (always +inf)
    n_degenerate_faces: int  #: faces of (numerically) zero area, as given (needles included)
    n_obtuse_corners: int  #: corners with an angle > 90 degrees
    n_virtual_edges: int  #: obtuse corners split by a virtual edge (unfolding)
    n_unfold_failures: int  #: obtuse corners whose unfolding walk failed
    min_edge_length: float  #: shortest edge
    max_edge_length: float  #: longest edge
    mean_edge_length: float  #: mean edge length
    bbox_diagonal: float  #: length of the bounding-box diagonal
    n_duplicate_faces: int  #: faces repeating another's vertices (copies; not walls)
    #: referenced vertices at exactly another's position (seams): welding removes them
    n_coincident_vertices: int = 0
    #: components with coincident vertices welded (far below n_components: cut at seams)
    n_welded_components: int = 0

    def as_dict(self) -> dict:
        """The fields as a plain ``dict``.

        Returns
        -------
        dict
            Field name -> value (int or float), in the order above.
        """
        return dataclasses.asdict(self)


@dataclasses.dataclass(frozen=True)
class GeodesicPath:
    """A polyline on the surface from a target back to its source, as
    returned by :meth:`Mesh.geodesic_path`.

    Point 0 is the target, point k-1 the source; ``faces[i]`` (i > 0) is the
    face the segment from point i-1 runs through. ``len(path)`` is k.

    Attributes
    ----------
    points : numpy.ndarray, float64 (k, 3)
        Positions.
    faces : numpy.ndarray, int32 (k,)
        The face each point lies in.
    barycentric : numpy.ndarray, float64 (k, 3)
        Each point's coordinates in its face.
    length : float
        The polyline's Euclidean length.
    weighted_length : float
        Its cost-weighted length (sum of F times segment length); equal to
        ``length`` without a cost.
    """

    points: np.ndarray
    faces: np.ndarray
    barycentric: np.ndarray
    length: float
    weighted_length: float

    def __len__(self) -> int:
        return int(self.faces.shape[0])


@dataclasses.dataclass(frozen=True)
class MatrixInfo:
    """What one distance-matrix call did, returned with its result by
    ``Mesh.distance_matrix(..., return_info=True)`` (and
    :meth:`Mesh.iter_distance_rows` with ``return_info=True``). Each call gets
    its own, so threads sharing a :class:`Mesh` never read each other's.

    Attributes
    ----------
    backend : str
        The backend that ran: ``"serial"``, ``"threads"`` or ``"opencl"``.
    reason : str
        Why ``backend="auto"`` ran threads instead of OpenCL (the OpenCL
        error, a CPU device, too few rows to keep the device busy, sparse
        output; a CPU device left to the threads is the expected case);
        ``""`` when the backend asked for ran.
    vertices_settled : int
        Vertices the marches settled, summed over the rows: the work done
        (0 from OpenCL, which does not count it).
    start_fallbacks : int
        Vertices of the exact start, over all rows, whose exact distance
        failed a bound every distance meets and which the march computed
        instead (0 unless the exact solver erred on a degenerate mesh).
    """

    backend: str
    reason: str
    vertices_settled: int
    start_fallbacks: int


@dataclasses.dataclass(frozen=True)
class Isoline:
    """One polyline of a level set, as returned by :meth:`Mesh.isolines`:
    where the linear interpolant of a per-vertex field over the faces
    equals ``value``.

    ``faces[i]`` (i > 0) is the face the segment from point i-1 runs
    through (``faces[0] == faces[1]``) and ``barycentric[i]`` the point's
    coordinates in ``faces[i]``; every point lies on an edge (where a
    T-junction was closed, possibly the edge that splits a face). A closed
    polyline repeats its first point at its end.

    Attributes
    ----------
    value : float
        The level.
    points : numpy.ndarray, float64 (k, 3)
        Positions.
    faces : numpy.ndarray, int32 (k,)
        Faces, as above.
    barycentric : numpy.ndarray, float64 (k, 3)
        Each point's coordinates in its face.
    closed : bool
        Whether the polyline is a loop (else it ends at a boundary, an
        unreached face or a non-manifold edge).
    """

    value: float
    points: np.ndarray
    faces: np.ndarray
    barycentric: np.ndarray
    closed: bool

    def __len__(self) -> int:
        return int(self.faces.shape[0])
