"""Distance matrices on a Dask cluster, written into a Zarr v3 array.

``distance_matrix(mesh, store, ...)`` splits the rows into blocks; each block
is one task that computes its rows with the in-process backends (threads or
OpenCL inside the worker) and writes them into its own chunk of the array, so
tasks are independent, idempotent and retryable (the model of Dask's own
array code). The mesh goes to each worker once, as V and F, and is built once
per worker.

Resuming: the array's attributes record the job (mesh hash, sources, targets,
options, meshfmm version). Chunks carry a CRC-32C (Zarr's crc32c codec) and
the array's fill value is NaN, which the library never returns. Each task
also writes a digest of its rows beside its chunk (``meshfmm_blocks/<b>``),
computed over the job's hash, the block's index and rows and the values, so
a block is complete exactly when its chunk decodes, holds no NaN and matches
that digest: a torn or altered chunk, or one copied from another block or
another job, is recomputed. Re-running the same job skips complete blocks; a
different job on the same store is refused.

One owner at a time: a run writes a fresh token into the attributes
(``meshfmm_owner``, with its host, pid and a heartbeat every 10 s) before
any task starts, and every task checks that token before it computes and
again before it writes, so a run whose store was taken over writes nothing
more and fails with :class:`StoreOwnerError`. A run refuses a store that a
live run owns (same host: its process is alive; another host: a heartbeat
within 60 s); a run that was killed leaves a stale token that the next run
(``resume`` of the same job) replaces at once on the same host.

Starting over deletes only the store's own entries (``zarr.json``, the chunk
tree ``c/`` and ``meshfmm_blocks/``), never other files; a location that
holds something else than a meshfmm store is refused unless
``overwrite=True``.

From the command line: ``meshfmm allpairs MESH -o OUT.zarr [--workers N |
--scheduler ADDRESS] [--resume] ...`` (``meshfmm allpairs --help``).

Needs ``dask[distributed]`` and ``zarr>=3``.
"""

from __future__ import annotations

import contextlib
import ctypes
import hashlib
import math
import os
import sys
import time
import uuid
from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np

from . import __version__
from . import _args, _extras, _lib, _zarr_tasks
from . import _zarr_store as _store
from ._mesh import Mesh
from ._zarr_store import JOB_ATTR, OWNER_ATTR, RUN_ATTR, StoreError, StoreOwnerError

__all__ = ["distance_matrix", "job_description", "complete_blocks", "symmetrize", "DASK_CONFIG",
           "StoreError", "StoreOwnerError", "JOB_ATTR", "RUN_ATTR", "OWNER_ATTR"]

# Bytes of one block: large enough that scheduling is noise, small enough
# that a 2-worker cluster gets many tasks and a lost worker loses little.
_BLOCK_BYTES = 8 << 20


# Blosc (cname, clevel) per `compression`, always with bit shuffle: on real
# meshes' rows (bench/scale/bench_compression.py) lz4 + bit shuffle stores within
# 0.5 % of zstd 3 + byte shuffle and encodes ~3x faster (the encoding is on
# each task's critical path); zstd 3 + bit shuffle is ~2 % smaller again.
_CODECS: Dict[str, Optional[Tuple[str, int]]] = {"lz4": ("lz4", 5), "zstd": ("zstd", 3),
                                                 "none": None}


DASK_CONFIG: Dict[str, Any] = {
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.admin.system-monitor.gil.enabled": False,
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.worker.profile.enabled": False,
}
"""Dask settings for long compute-bound tasks.

Dask's defaults poll every 10-500 ms (event-loop tick, memory and system
monitors, GIL monitor, statistical profiler) in the scheduler, every nanny
and every worker: on a 2-core LocalCluster that cost 5-9 % of the tasks'
CPU, these settings about 2 % (bench/scale/bench_cluster.py).
:func:`distance_matrix`'s own LocalCluster runs with them; for a cluster of
your own, start it inside ``dask.config.set(DASK_CONFIG)``, or give
``dask scheduler`` / ``dask worker`` the same as ``DASK_*`` variables
(``DASK_DISTRIBUTED__ADMIN__TICK__INTERVAL=1s``, ...).
"""


def _default_block_rows(n_rows: int, row_bytes: int, dask_threads: int) -> int:
    """Rows per block: at most ~_BLOCK_BYTES a chunk, at least 4 blocks per
    Dask thread, and a multiple of the threads in blocks of equal rows, so
    that no thread idles at the end while another runs a last block alone."""
    max_rows = max(1, _BLOCK_BYTES // row_bytes)
    per_thread = max(4, math.ceil(n_rows / (dask_threads * max_rows)))
    return max(1, math.ceil(n_rows / (per_thread * dask_threads)))


def _sha256(*arrays: Optional[np.ndarray]) -> Optional[str]:
    if all(a is None for a in arrays):
        return None
    h = hashlib.sha256()
    for a in arrays:
        if a is None:
            h.update(b"none")
            continue
        a = np.ascontiguousarray(a)
        h.update(str(a.dtype).encode() + str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def job_description(mesh: Mesh, sources: Optional[np.ndarray], targets: Optional[np.ndarray],
                    dtype: str, max_distance: Optional[float], cost: Optional[np.ndarray],
                    cost_location: Optional[str], unfolding: bool,
                    exact_start_radius: Union[None, float, str] = None,
                    method: str = "fmm") -> Dict[str, Any]:
    """What identifies a job, as stored in the array's attributes.

    Hashes of the mesh, sources, targets and cost, and the options that
    change the numbers; the backend and block size do not change them and
    are not part of it.

    Parameters
    ----------
    mesh : Mesh
        The mesh (its vertices, faces and ``max_unfold_steps``).
    sources, targets : numpy.ndarray of int32, shape (S,) and (T,), or None
        Row and column vertex ids; None for every vertex.
    dtype : {"float32", "float64"}
        The output dtype.
    max_distance : float or None
        The march's limit.
    cost : numpy.ndarray of float64 or None
        Per-vertex or per-face cost.
    cost_location : {"vertex", "face"} or None
        Where the cost lives.
    unfolding : bool
        Whether obtuse corners are unfolded.
    exact_start_radius : float, "auto" or None
        The exact start's radius in mean edge lengths (0: the plain start;
        None or "auto": the library's default, recorded as "auto").
    method : {"fmm", "windows"}
        The rows' method, recorded as None for "fmm" (so a job of the
        march matches stores that do not record it) and as "windows" else:
        a store of one method is a different job for the other.

    Returns
    -------
    dict
        JSON-serialisable: ``meshfmm_version``, ``mesh_sha256``,
        ``n_vertices``, ``n_faces``, ``sources_sha256``, ``n_sources``,
        ``targets_sha256``, ``n_targets``, ``dtype``, ``max_distance``,
        ``cost_sha256``, ``cost_location``, ``unfolding``,
        ``exact_start_radius``, ``max_unfold_steps``, ``method``.
    """
    V = np.ascontiguousarray(mesh.vertices, dtype=np.float64)
    F = np.ascontiguousarray(mesh.faces, dtype=np.int32)
    return {
        "meshfmm_version": __version__,
        "mesh_sha256": _sha256(V, F),
        "n_vertices": int(V.shape[0]),
        "n_faces": int(F.shape[0]),
        "sources_sha256": _sha256(sources) if sources is not None else "all",
        "n_sources": int(V.shape[0] if sources is None else sources.shape[0]),
        "targets_sha256": _sha256(targets) if targets is not None else "all",
        "n_targets": int(V.shape[0] if targets is None else targets.shape[0]),
        "dtype": dtype,
        "max_distance": None if max_distance is None else float(max_distance),
        "cost_sha256": _sha256(cost) if cost is not None else None,
        "cost_location": cost_location if cost is not None else None,
        "unfolding": bool(unfolding),
        "exact_start_radius": _start_radius(exact_start_radius),
        # as given (None: the default, 64), so a job that leaves it unset
        # matches stores that do not record it
        "max_unfold_steps": mesh.options["max_unfold_steps"],
        # None for the march (the default), so that its jobs match stores
        # that do not record a method
        "method": None if method == "fmm" else method,
    }


def _start_radius(radius: Union[None, float, str]) -> Union[float, str]:
    """The exact start's radius a job runs with: None -> the library's default
    ("auto" for its rule MFMM_EXACT_START_AUTO, meshfmm.h), "auto" kept."""
    if radius == "auto":
        return radius
    if radius is not None:
        return float(radius)
    o = _lib.mfmm_matrix_options()
    _lib.mfmm_matrix_options_init(ctypes.byref(o))
    return "auto" if o.exact_start_radius == _lib.EXACT_START_AUTO else float(o.exact_start_radius)


def complete_blocks(arr: Any, block_rows: int) -> List[int]:
    """The row blocks of a meshfmm store that are complete and verified.

    A block is complete when its chunk decodes (its CRC-32C matches), holds
    no NaN (the fill value of a chunk never written) and matches the digest
    its task wrote for the store's job and this block. Reads the whole
    array in this process; a resumed :func:`distance_matrix` does the same
    check as tasks on its cluster.

    Parameters
    ----------
    arr : zarr.Array
        A store written by :func:`distance_matrix`.
    block_rows : int
        Rows per block (``arr.chunks[0]``).

    Returns
    -------
    list of int
        Indices of the complete blocks, ascending.
    """
    return _store.verified_blocks(arr, range(math.ceil(arr.shape[0] / block_rows)), block_rows)


def _complete_blocks_on(client: Any, url: str, storage_options: Optional[dict], n_rows: int,
                        block_rows: int, dask_threads: int) -> List[int]:
    """complete_blocks as tasks on the cluster (each reads and checks a share
    of the chunks), so resuming a big store does not read it all through the
    client."""
    n_blocks = math.ceil(n_rows / block_rows)
    n_tasks = max(1, min(n_blocks, 4 * dask_threads))
    batches = [list(range(i, n_blocks, n_tasks)) for i in range(n_tasks)]
    futures = client.map(_store.verify_task, [url] * n_tasks, [storage_options] * n_tasks, batches,
                         [block_rows] * n_tasks, pure=False,
                         key=[f"meshfmm-verify-{i}-{time.time_ns()}" for i in range(n_tasks)])
    return sorted(b for done in client.gather(futures) for b in done)


def _fmt_seconds(s: float) -> str:
    if not math.isfinite(s):
        return "?"
    s = int(round(s))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60:02d} s"
    return f"{s // 3600} h {s % 3600 // 60:02d} min"


class _Progress:
    """A progress bar on a terminal (rows done, rows/s, time left), plain lines
    every ~10 % or 30 s when piped. `done`: rows already complete (a resumed
    job); they count in rows done, not in the rate."""

    def __init__(self, total: int, stream=None, done: int = 0) -> None:
        self.total, self.done, self.done0 = total, done, done
        self.stream = stream or sys.stderr
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.t0 = self.last = time.monotonic()
        self.last_frac = -1.0

    def __call__(self, rows: int) -> None:
        self.done += rows
        now = time.monotonic()
        new = self.done - self.done0
        rate = new / (now - self.t0) if new > 0 and now > self.t0 else float("nan")
        left = (self.total - self.done) / rate if rate > 0 else float("nan")
        frac = self.done / self.total if self.total else 1.0
        rate_s = "?" if not math.isfinite(rate) else f"{rate:.1f}"
        msg = (f"{self.done}/{self.total} rows ({100 * frac:.1f} %), {rate_s} rows/s, "
               f"{_fmt_seconds(left)} left")
        if self.tty:
            w = 30
            bar = "#" * int(w * frac) + "-" * (w - int(w * frac))
            self.stream.write(f"\r[{bar}] {msg}   ")
            if self.done >= self.total:
                self.stream.write("\n")
            self.stream.flush()
        elif frac - self.last_frac >= 0.1 or now - self.last >= 30 or self.done >= self.total:
            self.stream.write(msg + "\n")
            self.stream.flush()
            self.last, self.last_frac = now, frac


def distance_matrix(mesh: Mesh, store: Any, sources: Any = None, targets: Any = None,
                    client: Any = None, dtype: str = "float32", resume: bool = True, *,
                    block_rows: Optional[int] = None, backend: str = "threads",
                    n_threads: int = 0, max_distance: Optional[float] = None,
                    cost: Any = None, cost_location: Optional[str] = None,
                    unfolding: bool = True, exact_start: Any = True,
                    method: str = "fmm", n_workers: Optional[int] = None,
                    storage_options: Optional[dict] = None, compression: str = "lz4",
                    progress: Any = True, retries: int = 3, overwrite: bool = False) -> Any:
    """A dense S x N (or S x T) distance matrix computed as Dask tasks
    writing a Zarr v3 array.

    Each task computes one block of rows with ``Mesh.distance_matrix`` and
    writes them into its own chunk, with a digest beside it. A run owns the
    store while it writes (a token in the attribute ``meshfmm_owner``,
    checked by every task before it writes): if another run takes the store
    over meanwhile, this one writes nothing more and raises
    :class:`StoreOwnerError`.

    Parameters
    ----------
    mesh : Mesh
        Shipped to the workers as V and F, with its options
        (``Mesh(..., spokes=False)``: each worker's mesh skips the march's
        ~380 bytes per vertex of spokes, same rows).
    store : str or os.PathLike
        A directory path or an fsspec URL (with `storage_options`).
    sources : array_like of int, shape (S,), optional
        Row vertex ids; None for every vertex.
    targets : array_like of int, shape (T,), optional
        Column vertex ids, in the given order; None for every vertex.
    client : distributed.Client, optional
        None starts a ``LocalCluster`` of `n_workers` processes (default:
        the machine's cores) with one thread each and the settings of
        :data:`DASK_CONFIG`, and prints its dashboard address.
    dtype : {"float32", "float64"}
        The values equal ``Mesh.distance`` per row (float64 bit for bit,
        float32 the same rounding).
    resume : bool
        True skips blocks already complete and verified when the store holds
        the same job, and refuses a store holding another job. False starts
        a meshfmm store over, deleting only its own entries (``zarr.json``,
        ``c/``, ``meshfmm_blocks/``), never other files. Either way a store
        that another live run owns is refused, and a run killed before it
        finished does not block the next one.
    block_rows : int, optional
        Rows per task and chunk (default: about 8 MiB a chunk, at least 4
        tasks per Dask thread of the cluster).
    backend : {"threads", "serial", "opencl", "auto"}
        The in-process backend each task runs. Under "auto" each worker
        picks its own; the run record counts the blocks per backend.
    n_threads : int
        Library threads per task; 0: the worker's share of its machine
        (cores / Dask threads on that host, so a LocalCluster of one
        1-thread process per core runs 1 library thread per task).
    max_distance, cost, cost_location, unfolding, exact_start
        As in ``Mesh.distance``; the job records the exact start's radius,
        so a store computed with another one is a different job.
    method : {"fmm", "windows"}
        The rows' method, as in ``Mesh.distance_matrix`` (under "auto"
        the workers run "windows" on threads). The job records it: resuming a store with the other
        method is refused (:class:`StoreError`), never a mix of rows.
    n_workers : int, optional
        Processes of the LocalCluster started when `client` is None.
    storage_options : dict, optional
        fsspec options for a URL `store`.
    compression : {"lz4", "zstd", "none"}
        Blosc lz4 with bit shuffle (default), Blosc zstd level 3 with bit
        shuffle (~2 % smaller, ~3x slower to encode), or none; chunks always
        carry a CRC-32C.
    progress : bool or callable
        True for a progress bar on a terminal (plain lines when piped),
        False for none, or ``progress(rows_done, n_rows)``; an exception it
        raises stops the job (blocks in flight still finish).
    retries : int
        Times a failed task is retried (a killed worker's tasks are
        rescheduled by Dask regardless).
    overwrite : bool
        Write the store into a location that exists and is not a meshfmm
        store (a non-empty directory, another Zarr node): its Zarr entries
        (``zarr.json``, ``c/``) are replaced and other files kept.

    Returns
    -------
    zarr.Array
        The matrix, shape (S, N) or (S, T), of `dtype`. Its attribute
        ``meshfmm_last_run`` records this call's blocks computed and
        skipped, the task seconds computing and writing (encoding included)
        and the CPU seconds of the tasks' threads, and, summed over the
        blocks computed, their :class:`~meshfmm.MatrixInfo`: ``backends``
        (backend name -> blocks), ``vertices_settled`` and
        ``start_fallbacks``.

    Raises
    ------
    StoreError
        The location holds another job (with `resume`), or is not a meshfmm
        store (without `overwrite`), or is an input.
    StoreOwnerError
        Another live run owns the store, or takes it over during the run.
    ValueError, TypeError
        Bad arguments, checked before the store is touched (one row is
        computed with the job's options first).
    ImportError
        Zarr, Dask or Dask's distributed scheduler is not installed (the
        ``[dask]`` extra), checked before anything is computed.
    """
    _extras.require("meshfmm.distributed.distance_matrix", "dask")
    import zarr
    from zarr.codecs import BloscCodec, BloscShuffle, Crc32cCodec

    if not isinstance(mesh, Mesh):
        raise TypeError(f"mesh must be a meshfmm.Mesh, not {type(mesh).__name__}")
    nv = mesh.n_vertices
    src = None if sources is None else _args.vertex_ids(sources, "sources", nv)
    tgt = None if targets is None else _args.vertex_ids(targets, "targets", nv)
    dt = np.dtype(dtype)
    if dt not in (np.float32, np.float64):
        raise ValueError(f"dtype must be float32 or float64, not {dtype}")
    if max_distance is not None:
        _args.max_distance(max_distance)  # TypeError or ValueError, as Mesh.distance
    cost_arr = None
    if cost is not None:
        cost_arr, _ = _args.cost_array(cost, cost_location, nv, mesh.n_faces)
    radius = _start_radius(_args.exact_start_radius(exact_start))
    _args.solve_method(method, cost, "meshfmm.distributed.distance_matrix")
    if compression not in _CODECS:
        raise ValueError(f"compression must be one of {', '.join(map(repr, _CODECS))}, "
                         f"not {compression!r}")
    if backend not in ("auto", "threads", "serial", "opencl"):
        raise ValueError(f"backend must be auto, threads, serial or opencl, not {backend!r}")
    if not _args.is_int(retries) or retries < 0:
        raise ValueError(f"retries must be an integer >= 0, not {retries!r}")
    if block_rows is not None and (not _args.is_int(block_rows) or block_rows < 1):
        raise ValueError(f"block_rows must be an integer >= 1, not {block_rows!r}")
    # Every option a task hands the library, checked here before the store is
    # touched (resume=False overwrites it): one row marched to radius 0 with
    # the job's options; the library checks the whole cost array up front.
    # Else a bad cost failed every task on the workers, retried, and only
    # then surfaced, after an existing store had been replaced.
    mesh.distance_matrix(src[:1] if src is not None else [0], targets=tgt, backend="serial",
                         dtype=dt.name, max_distance=0.0, cost=cost_arr,
                         cost_location=cost_location, unfolding=unfolding,
                         exact_start=exact_start, method=method,
                         n_threads=_args.index(n_threads, "n_threads"))
    url, storage_options = _store.open_store(store, storage_options)
    n_rows = nv if src is None else src.shape[0]
    n_cols = nv if tgt is None else tgt.shape[0]
    job = job_description(mesh, src, tgt, dt.name, max_distance, cost_arr, cost_location,
                          unfolding, radius, method)
    # refused before a cluster is started for nothing; checked again below
    _store.check_store(url, storage_options, job, (n_rows, n_cols), resume, overwrite)
    token = uuid.uuid4().hex  # this run's owner token

    own_cluster = None
    quiet = contextlib.ExitStack()
    if client is None:
        import dask
        from distributed import Client, LocalCluster

        workers = n_workers or os.cpu_count() or 1
        quiet.enter_context(dask.config.set(DASK_CONFIG))
        try:
            own_cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=":0")
            client = Client(own_cluster)
        except BaseException:
            if own_cluster is not None:
                own_cluster.close()
            quiet.close()  # the settings never outlive the call
            raise
        link = getattr(own_cluster, "dashboard_link", None)
        if progress and link:
            print(f"meshfmm: Dask dashboard at {link}", file=sys.stderr)
    try:
        host_threads: Dict[str, int] = {}
        for w in client.scheduler_info().get("workers", {}).values():
            host = w.get("host", "")
            host_threads[host] = host_threads.get(host, 0) + int(w.get("nthreads", 1))
        dask_threads = max(1, sum(host_threads.values()))
        owner = _store.Ownership(url, storage_options, token)
        record = _store.owner_record(token)
        _store.ACTIVE_TOKENS.add(token)
        try:
            kind, _ = _store.check_store(url, storage_options, job, (n_rows, n_cols), resume,
                                   overwrite)
            fresh = not (resume and kind == "meshfmm")
            if not fresh:
                zarr.open_array(url, mode="r+", storage_options=storage_options) \
                    .attrs[OWNER_ATTR] = record
            else:
                if kind == "meshfmm":
                    # the previous run's tasks still in flight see the new token first
                    zarr.open_array(url, mode="r+", storage_options=storage_options) \
                        .attrs[OWNER_ATTR] = record
                if kind in ("meshfmm", "foreign"):
                    _store.delete_own_entries(url, storage_options)
                if block_rows is None:
                    block_rows = _default_block_rows(n_rows, n_cols * dt.itemsize,
                                                     dask_threads)
                compressors = [Crc32cCodec()]
                if _CODECS[compression] is not None:
                    cname, clevel = _CODECS[compression]
                    compressors.insert(0, BloscCodec(cname=cname, clevel=clevel,
                                                     shuffle=BloscShuffle.bitshuffle,
                                                     typesize=dt.itemsize))
                zarr.create_array(url, shape=(n_rows, n_cols),
                                  chunks=(int(block_rows), n_cols), dtype=dt,
                                  fill_value=np.nan, compressors=compressors,
                                  attributes={JOB_ATTR: job, OWNER_ATTR: record},
                                  overwrite=False, storage_options=storage_options)
            arr = zarr.open_array(url, mode="r+", storage_options=storage_options)
            if (arr.attrs.get(OWNER_ATTR) or {}).get("token") != token:  # two runs at once
                raise StoreOwnerError(f"the store {url} was taken by another run starting at "
                                      "the same time; run again once it has finished")
            owner.start()
            run = _run_blocks(client, arr, url, storage_options, mesh, src, tgt, token,
                              fresh, n_rows, dask_threads, progress, owner,
                              {"backend": backend, "dtype": dt.name,
                               "max_distance": max_distance, "unfolding": unfolding,
                               "exact_start": radius, "method": method, "cost": cost_arr,
                               "cost_location": cost_location, "n_threads": n_threads,
                               "host_threads": host_threads,
                               "mesh_options": mesh.options}, retries)
        except BaseException:
            # release the store (only where this run's token is still there)
            owner.stop()
            try:
                owner.update({"state": "stopped"})
            except Exception:  # the job's own error is the one to report
                pass
            raise
        owner.stop()
        if not owner.update({"state": "finished", "heartbeat": time.time()}, {RUN_ATTR: run}):
            raise StoreOwnerError(f"the store {url} was taken over by another run before this "
                                  "job finished")
        return zarr.open_array(url, mode="r+", storage_options=storage_options)
    finally:
        _store.ACTIVE_TOKENS.discard(token)
        if own_cluster is not None:
            client.close()
            own_cluster.close()
        quiet.close()


def _run_blocks(client: Any, arr: Any, url: str, storage_options: Optional[dict], mesh: Mesh,
                src: Optional[np.ndarray], tgt: Optional[np.ndarray], token: str, fresh: bool,
                n_rows: int, dask_threads: int, progress: Any, owner: _store.Ownership,
                opts: Dict[str, Any], retries: int) -> Dict[str, Any]:
    """Verifies a resumed store's blocks, then computes the others as tasks;
    returns the run's record (RUN_ATTR)."""
    block_rows = int(arr.chunks[0])
    n_blocks = math.ceil(n_rows / block_rows)
    job_key = _store.job_key(arr.attrs[JOB_ATTR])
    # a store just created holds nothing to verify
    done = (set(_complete_blocks_on(client, url, storage_options, n_rows, block_rows,
                                    dask_threads)) if not fresh else set())
    todo = [b for b in range(n_blocks) if b not in done]

    report: Optional[Callable[[int], None]] = None
    if progress is True:
        bar = _Progress(n_rows, done=sum(min(n_rows, (b + 1) * block_rows) - b * block_rows
                                         for b in done))
        bar(0)
        report = bar
    elif callable(progress):
        rows_done = [sum(min(n_rows, (b + 1) * block_rows) - b * block_rows for b in done)]

        def report(rows: int) -> None:
            rows_done[0] += rows
            progress(rows_done[0], n_rows)

    V = np.ascontiguousarray(mesh.vertices, dtype=np.float64)
    F = np.ascontiguousarray(mesh.faces, dtype=np.int32)
    computed, t_compute, t_write, t_cpu = 0, 0.0, 0.0, 0.0
    backends: Dict[str, int] = {}
    settled, start_fallbacks = 0, 0
    if todo:
        from distributed import as_completed

        # hash=False: keys of this call alone. Scattered by content hash, a
        # second job on the same mesh reused the keys the first job's
        # futures were releasing, and the scheduler lost them under the new
        # tasks ("lost dependencies": the job failed, or hung)
        V_f, F_f = client.scatter([V, F], broadcast=True, hash=False)
        src_f = (client.scatter(src, broadcast=True, hash=False) if src is not None
                 else None)
        key = arr.attrs[JOB_ATTR]["mesh_sha256"]
        futures = [client.submit(_zarr_tasks.compute_block, key, V_f, F_f, url, storage_options,
                                 b * block_rows, min(n_rows, (b + 1) * block_rows),
                                 src_f, tgt, opts, b, token, job_key, retries=retries,
                                 pure=False,
                                 key=f"meshfmm-block-{key[:12]}-{b}-{time.time_ns()}")
                   for b in todo]
        try:
            for fut in as_completed(futures):
                r0, r1, tc, tw, tcpu, info = fut.result()
                computed += 1
                backends[info.backend] = backends.get(info.backend, 0) + 1
                settled += info.vertices_settled
                start_fallbacks += info.start_fallbacks
                t_compute += tc
                t_write += tw
                t_cpu += tcpu
                if owner.lost:
                    raise StoreOwnerError(f"the store {url} was taken over by another run "
                                          "while this job ran; this job stopped")
                if report:
                    report(r1 - r0)
        except BaseException:
            client.cancel(futures)
            raise
    return {"blocks": n_blocks, "blocks_computed": computed, "blocks_skipped": len(done),
            "block_rows": block_rows, "task_compute_seconds": t_compute,
            "task_write_seconds": t_write, "task_thread_cpu_seconds": t_cpu,
            "backends": backends, "vertices_settled": settled,
            "start_fallbacks": start_fallbacks}


def symmetrize(store: Any, out: Any, storage_options: Optional[dict] = None,
               overwrite: bool = False) -> Any:
    """(D + D^T) / 2 of a square matrix in a Zarr store, written to `out`.

    Runs with Dask arrays, chunk by chunk, never the whole matrix in memory:
    ``da.from_zarr(store)`` then
    ``((D + D.T) / 2).astype(D.dtype).to_zarr(out)``.

    Parameters
    ----------
    store : str or os.PathLike
        The square matrix (a path or fsspec URL).
    out : str or os.PathLike
        Where the result goes.
    storage_options : dict, optional
        fsspec options for both.
    overwrite : bool
        Replace `out`'s Zarr entries when it exists and is not empty (other
        files in it are kept).

    Returns
    -------
    zarr.Array
        The symmetric matrix, read-only.

    Raises
    ------
    StoreError
        `out` is `store`, holds it or lies inside it, or exists and is not
        empty without `overwrite`.
    ValueError
        The matrix is not square.
    ImportError
        Zarr or Dask is not installed (the ``[dask]`` extra).
    """
    _extras.require("meshfmm.distributed.symmetrize", "dask")
    import dask.array as da
    import zarr

    url, storage_options = _store.open_store(store, storage_options)
    out_url, _ = _store.open_store(out, storage_options)
    a, b = _store.local_path(url), _store.local_path(out_url)
    if a is not None and b is not None:
        _store.refuse_inputs(out_url, [url])
        ra, rb = os.path.realpath(a), os.path.realpath(b)
        if os.path.commonpath([ra, rb]) == ra:
            raise StoreError(f"the output {out_url} lies inside the input store {url}; "
                             "choose another output")
    elif url.rstrip("/") == out_url.rstrip("/"):
        raise StoreError(f"the output {out_url} is the input store; choose another output")
    D = da.from_zarr(url, storage_options=storage_options)
    if D.ndim != 2 or D.shape[0] != D.shape[1]:
        raise ValueError(f"symmetrize needs a square matrix, not {D.shape}")
    kind, _ = _store.probe(out_url, storage_options)
    if kind in ("meshfmm", "foreign"):
        if not overwrite:
            raise StoreError(f"the output {out_url} exists and is not empty; choose another "
                             "output, or pass overwrite=True (its Zarr entries are replaced, "
                             "other files kept)")
        _store.delete_own_entries(out_url, storage_options)
    S = ((D + D.T) / 2).astype(D.dtype)
    S.to_zarr(out_url, storage_options=storage_options)
    return zarr.open_array(out_url, mode="r", storage_options=storage_options)


if __name__ == "__main__":  # pragma: no cover
    try:
        _extras.require("python -m meshfmm.distributed", "dask")
    except ImportError as e:
        sys.stderr.write(f"{e}\n")
        sys.exit(2)
    from ._zarr_cli import cli_allpairs_zarr

    sys.exit(cli_allpairs_zarr(sys.argv[1:]))
