"""``meshfmm allpairs MESH -o OUT.zarr ...``: the command line of the Dask +
Zarr job (:func:`meshfmm.distributed.distance_matrix`), run by the
``meshfmm`` command and by ``python -m meshfmm.distributed``."""

from __future__ import annotations

import argparse
import sys
from typing import Sequence

import numpy as np

from . import _zarr_store as _store
from . import distributed as _job
from ._mesh import Mesh, load_mesh
from ._zarr_store import RUN_ATTR, StoreOwnerError

def _read_ids(path: str, what: str) -> np.ndarray:
    if path.endswith(".npy"):
        a = np.load(path, allow_pickle=False)
    else:
        a = np.loadtxt(path, dtype=np.int64, ndmin=1)
    if a.ndim != 1 or not np.issubdtype(a.dtype, np.integer):
        raise ValueError(f"{path}: {what} must be a 1-D integer array")
    return a


class _Once(argparse.Action):
    """A value option that may be given once: argparse would keep the last of
    several silently (``-o a.zarr -o b.zarr``); the C command line refuses
    them too (cli_once)."""

    def __call__(self, parser, namespace, values, option_string=None):
        given = namespace.__dict__.setdefault("_given", set())
        if self.dest in given:
            parser.error(f"{'/'.join(self.option_strings)} given twice; give it once")
        given.add(self.dest)
        setattr(namespace, self.dest, values)


def cli_allpairs_zarr(argv: Sequence[str]) -> int:
    """``meshfmm allpairs MESH -o OUT.zarr [--scheduler ADDRESS | --workers N]
    [--resume] [--overwrite] ...``: the distributed all-pairs job from the
    command line. OUT may not be an input or contain one; without
    ``--resume`` a meshfmm store there is started over (only its own Zarr
    entries deleted); ``--overwrite`` is needed to write into a location
    that exists and is not a meshfmm store (its Zarr entries are replaced,
    other files kept). Errors are one line on stderr and exit status 2."""
    a = zarr_parser().parse_args(list(argv))
    return _run(a)


def zarr_parser() -> argparse.ArgumentParser:
    """The argument parser of ``meshfmm allpairs MESH -o OUT.zarr``."""
    ap = argparse.ArgumentParser(prog="meshfmm allpairs",
                                 description="All-pairs geodesic distances on a Dask cluster, "
                                             "written into a Zarr v3 array.")
    ap.add_argument("mesh")
    ap.add_argument("-o", "--output", required=True, action=_Once,
                    help="OUT.zarr (a directory or fsspec URL)")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--scheduler", action=_Once,
                   help="address of a running Dask scheduler (tcp://host:port)")
    g.add_argument("--workers", type=int, action=_Once,
                   help="worker processes of a local cluster (default: cores)")
    ap.add_argument("--resume", action="store_true",
                    help="go on with a job already in OUT (default: start over, deleting "
                         "only the store's own entries)")
    ap.add_argument("--overwrite", action="store_true",
                    help="write into OUT even where it exists and is not a meshfmm store: its "
                         "Zarr entries (zarr.json, c/) are replaced, other files kept "
                         "(default: refuse)")
    ap.add_argument("--dtype", choices=["float32", "float64"], default="float32", action=_Once)
    ap.add_argument("--sources", help="vertex ids (.npy or .txt)", action=_Once)
    ap.add_argument("--targets", help="vertex ids for the columns (.npy or .txt)", action=_Once)
    ap.add_argument("--max-distance", type=float, action=_Once)
    ap.add_argument("--cost", help="per-vertex or per-face cost (.npy or .txt)", action=_Once)
    ap.add_argument("--backend", choices=["threads", "serial", "opencl", "auto"], default="threads",
                    action=_Once)
    ap.add_argument("--method", choices=["fmm", "windows"], default="fmm", action=_Once,
                    help="fmm (default): the march; windows: window propagation, more "
                         "accurate, never below the geodesic distance, several times the "
                         "time (with --cost: windows within faces of one cost); part of the "
                         "job, so --resume refuses a store of the other method")
    st = ap.add_mutually_exclusive_group()
    st.add_argument("--exact-start-radius", type=float, metavar="R", action=_Once,
                    help="radius of the exact start in mean edge lengths (default: the library's)")
    st.add_argument("--plain-start", action="store_true", help="the paper's plain start")
    ap.add_argument("--block-rows", type=int, action=_Once)
    ap.add_argument("--compression", choices=list(_job._CODECS), default="lz4", action=_Once,
                    help="Blosc lz4 or zstd (bit shuffle), or none (default: lz4)")
    ap.add_argument("--no-progress", action="store_true")
    ap.add_argument("--no-spokes", action="store_true",
                    help="memory first: no per-vertex update records on the workers "
                         "(~380 bytes per vertex each; same matrix, marches 1.25-1.6x as long)")
    return ap


def _run(a: argparse.Namespace) -> int:
    client = None
    try:
        _store.refuse_inputs(a.output, [a.mesh, a.sources, a.targets, a.cost])
        mesh = Mesh(*load_mesh(a.mesh), spokes=not a.no_spokes)
        src = _read_ids(a.sources, "sources") if a.sources else None
        tgt = _read_ids(a.targets, "targets") if a.targets else None
        cost = None
        if a.cost:
            cost = np.load(a.cost) if a.cost.endswith(".npy") else np.loadtxt(a.cost, ndmin=1)
        if a.scheduler:
            from distributed import Client

            client = Client(a.scheduler)
            link = getattr(client, "dashboard_link", None)
            if link and not a.no_progress:
                print(f"meshfmm: Dask dashboard at {link}", file=sys.stderr)
        Z = _job.distance_matrix(mesh, a.output, sources=src, targets=tgt, client=client,
                            dtype=a.dtype, resume=a.resume, block_rows=a.block_rows,
                            backend=a.backend, method=a.method,
                            max_distance=a.max_distance, cost=cost,
                            n_workers=a.workers, progress=not a.no_progress,
                            exact_start=(False if a.plain_start else
                                         True if a.exact_start_radius is None
                                         else a.exact_start_radius),
                            compression=a.compression, overwrite=a.overwrite)
        run = Z.attrs.get(RUN_ATTR, {})
        print(f"meshfmm: wrote {Z.shape[0]} x {Z.shape[1]} {Z.dtype} to {a.output} "
              f"({run.get('blocks_computed')} blocks computed, {run.get('blocks_skipped')} "
              "already complete)", file=sys.stderr)
        return 0
    except KeyboardInterrupt:
        print("meshfmm: interrupted; complete blocks are kept (run again with --resume)",
              file=sys.stderr)
        return 130
    except (ValueError, TypeError, OSError, StoreOwnerError) as e:
        print(f"meshfmm: {e}", file=sys.stderr)
        return 2
    finally:
        # on failure too: a client left open keeps reconnecting to its
        # scheduler after the command returned
        if client is not None:
            client.close()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(cli_allpairs_zarr(sys.argv[1:]))
