"""The worker side of a distributed job: one task computes a block of rows
with the in-process backends and writes it, with its digest, into its own
chunk of the store."""

from __future__ import annotations

import json
import os
import sys
import time
from typing import Any, Dict, Optional, Tuple

import numpy as np

from . import _zarr_store as _store
from ._mesh import Mesh
from ._types import MatrixInfo


def _worker_cache() -> Dict[str, Mesh]:
    """Meshes built on this worker, keyed by mesh hash (held by the worker
    object, so a worker builds each mesh once whatever the number of tasks)."""
    try:
        from distributed import get_worker

        w = get_worker()
    except (ImportError, ValueError):  # run in the client process
        w = sys.modules[__name__]
    cache = getattr(w, "_meshfmm_meshes", None)
    if cache is None:
        cache = {}
        setattr(w, "_meshfmm_meshes", cache)
    return cache


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _task_threads(n_threads: int, host_threads: Dict[str, int]) -> int:
    """Library threads for one task. 0: this worker's share of its machine's
    cores, cores / (Dask threads of all workers on this host), so that a
    LocalCluster of one process per core runs one library thread per task
    (Dask's own rule: its nannies set OMP_NUM_THREADS=1) while a single
    one-thread worker on a 16-core node still uses all 16 cores."""
    if n_threads > 0:
        return n_threads
    try:
        from distributed import get_worker
        from distributed.comm import get_address_host

        w = get_worker()
    except (ImportError, ValueError):  # run in the client process
        return 0
    total = host_threads.get(get_address_host(w.address)) or w.state.nthreads
    return max(1, _cores() // max(1, total))


def compute_block(key: str, V: np.ndarray, F: np.ndarray, url: str,
                  storage_options: Optional[dict], r0: int, r1: int,
                  src: Optional[np.ndarray], targets: Optional[np.ndarray],
                  opts: Dict[str, Any], b: int, token: str,
                  job_key: str) -> Tuple[int, int, float, float, float, MatrixInfo]:
    """One task: rows [r0, r1) (block b) into their own chunk, then the
    block's digest beside it. Idempotent: a retry writes the same bytes.
    Writes only while the store's owner token is `token` (checked before
    computing and again before writing). Returns r0, r1, the seconds spent
    computing and writing (encoding included), the CPU seconds of the
    task's thread (library threads started beyond it not counted) and the
    block's MatrixInfo (each worker picks its backend under "auto")."""
    import zarr

    _store.check_token(zarr.open_array(url, mode="r", storage_options=storage_options),
                       token, url, r0, r1)
    cache = _worker_cache()
    # the caller's mesh options (unfolding walk, spokes): part of the key
    mesh_opts = opts.get("mesh_options") or {}
    key = f"{key}-{sorted(mesh_opts.items())}"
    mesh = cache.get(key)
    if mesh is None:
        mesh = cache[key] = Mesh(V, F, **mesh_opts)
    t0, c0 = time.perf_counter(), time.thread_time()
    rows_src = np.arange(r0, r1, dtype=np.int32) if src is None else src[r0:r1]
    kw = dict(backend=opts["backend"], dtype=opts["dtype"],
              n_threads=_task_threads(opts["n_threads"], opts.get("host_threads") or {}),
              max_distance=opts["max_distance"], unfolding=opts["unfolding"],
              exact_start=opts.get("exact_start", True), method=opts.get("method", "fmm"))
    if opts["cost"] is not None:
        kw.update(cost=opts["cost"], cost_location=opts["cost_location"])
    # the library's target columns: each row stops once its targets settle
    rows, info = mesh.distance_matrix(rows_src, targets=targets, return_info=True, **kw)
    t1 = time.perf_counter()
    arr = zarr.open_array(url, mode="r+", storage_options=storage_options)
    _store.check_token(arr, token, url, r0, r1)
    rows = np.ascontiguousarray(rows, dtype=arr.dtype)
    arr[r0:r1, :] = rows
    _store.key_set(arr, f"{_store.SUMS}/{b}", json.dumps(
        {"block": b, "rows": [r0, r1], "job": job_key,
         "blake2b": _store.block_digest(job_key, b, r0, r1, rows)}).encode())
    return r0, r1, t1 - t0, time.perf_counter() - t1, time.thread_time() - c0, info
