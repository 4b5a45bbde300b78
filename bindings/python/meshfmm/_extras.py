"""The optional dependencies ("extras" of the package).

The package itself needs only numpy. A feature that needs more checks its
modules here, first, before it computes anything, and a missing one is an
ImportError that names the feature, the module and the extra that installs
it (``pip install 'meshfmm[sparse]'``), instead of a bare ModuleNotFoundError
after the work is done.
"""

from __future__ import annotations

import importlib
from typing import Dict, Tuple

__all__ = ["EXTRAS", "require"]

#: extra -> the modules its features import (pyproject.toml's
#: [project.optional-dependencies] lists the distributions).
EXTRAS: Dict[str, Tuple[str, ...]] = {
    "sparse": ("scipy.sparse",),
    "dask": ("zarr", "dask", "distributed"),
    "plot": ("matplotlib",),
}

# module -> the distribution pip installs it from, where the names differ
_DISTRIBUTIONS = {"scipy.sparse": "scipy", "distributed": "dask[distributed]",
                  "dask": "dask[distributed]", "zarr": "zarr>=3"}


def require(feature: str, extra: str) -> None:
    """Imports every module of `extra`, or raises an ImportError that says
    what `feature` needs and how to install it.

    Parameters
    ----------
    feature : str
        What the caller is about to do, as the user wrote it
        (``"distance_matrix(sparse=True)"``).
    extra : str
        A key of :data:`EXTRAS`.

    Raises
    ------
    ImportError
        A module of the extra is missing or fails to import; its ``name`` is
        the module, and the original error is its ``__cause__``.
    """
    for module in EXTRAS[extra]:
        try:
            importlib.import_module(module)
        except ImportError as exc:
            dist = _DISTRIBUTIONS.get(module, module)
            raise ImportError(
                f"meshfmm: {feature} needs {module.split('.')[0]}, which is not installed "
                f"({exc}); install the extra with pip install 'meshfmm[{extra}]' "
                f"(or pip install '{dist}')",
                name=module,
            ) from exc
