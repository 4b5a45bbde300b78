"""meshfmm: geodesic distances and shortest paths on triangle meshes by the
Fast Marching Method of Kimmel & Sethian (PNAS 1998), a ctypes binding of the
C99 library libmeshfmm.

>>> import meshfmm
>>> V, F = meshfmm.load_mesh("spot.obj")            # doctest: +SKIP
>>> mesh = meshfmm.Mesh(V, F)                       # doctest: +SKIP
>>> d = mesh.distance(0)                            # float64 (nv,)  # doctest: +SKIP
>>> path = mesh.geodesic_path(d, 1234)              # doctest: +SKIP
>>> D = mesh.distance_matrix([0, 10, 20])           # float32 (3, nv)  # doctest: +SKIP
>>> D, info = mesh.distance_matrix([0, 10], return_info=True)  # doctest: +SKIP
>>> info.backend                                    # "threads"  # doctest: +SKIP
"""

from __future__ import annotations

from . import _lib
from ._lib import MeshError, OpenCLError
from ._memmap import open_memmap
from ._mesh import Mesh, load_mesh
from ._types import GeodesicPath, Isoline, MatrixInfo, MeshInfo, MeshWarning, SurfacePoint

#: Version of the loaded libmeshfmm ("MAJOR.MINOR.PATCH").
__version__: str = _lib.version()

#: Path of the loaded shared library.
library_path: str = _lib.library_path

__all__ = [
    "Mesh",
    "MeshInfo",
    "SurfacePoint",
    "GeodesicPath",
    "MatrixInfo",
    "Isoline",
    "MeshWarning",
    "MeshError",
    "OpenCLError",
    "load_mesh",
    "open_memmap",
    "library_path",
    "__version__",
]
