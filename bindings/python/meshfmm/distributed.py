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

Needs ``dask[distributed]`` and ``zarr>=3``.
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import hashlib
import json
import math
import os
import socket
import sys
import threading
import time
import uuid
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import __version__
from . import _lib
from . import _args
from ._mesh import Mesh, load_mesh

__all__ = ["distance_matrix", "job_description", "complete_blocks", "symmetrize", "DASK_CONFIG",
           "StoreError", "StoreOwnerError"]

JOB_ATTR = "meshfmm_job"
RUN_ATTR = "meshfmm_last_run"
OWNER_ATTR = "meshfmm_owner"
# Key prefix of the per-block digests, beside Zarr's chunk tree "c/".
_SUMS = "meshfmm_blocks"
# The owner's heartbeat period, and how long without one a run on another
# host is taken for dead (on its own host its process is looked up instead).
_HEARTBEAT_S = 10.0
_LEASE_S = 60.0
# Tokens of the runs in progress in this process: a record naming this
# process with another token was left by a run of it that did not release.
_ACTIVE_TOKENS: set = set()
# Bytes of one block: large enough that scheduling is noise, small enough
# that a 2-worker cluster gets many tasks and a lost worker loses little.
_BLOCK_BYTES = 8 << 20
# Blosc (cname, clevel) per `compression`, always with bit shuffle: on real
# meshes' rows (bench/bench_compression.py) lz4 + bit shuffle stores within
# 0.5 % of zstd 3 + byte shuffle and encodes ~3x faster (the encoding is on
# each task's critical path); zstd 3 + bit shuffle is ~2 % smaller again.
_CODECS: Dict[str, Optional[Tuple[str, int]]] = {"lz4": ("lz4", 5), "zstd": ("zstd", 3),
                                                 "none": None}


# Dask settings for long compute-bound tasks. Dask's defaults poll every
# 10-500 ms (event-loop tick, memory and system monitors, GIL monitor,
# statistical profiler) in the scheduler, every nanny and every worker: on a
# 2-core LocalCluster that cost 5-9 % of the tasks' CPU, these ~2 %
# (bench/bench_cluster.py). distance_matrix's own LocalCluster runs with them;
# for a cluster of your own, start it inside dask.config.set(DASK_CONFIG), or
# give `dask scheduler` / `dask worker` the same as DASK_* variables
# (DASK_DISTRIBUTED__ADMIN__TICK__INTERVAL=1s, ...).
DASK_CONFIG: Dict[str, Any] = {
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.admin.system-monitor.gil.enabled": False,
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.worker.profile.enabled": False,
}


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
                    exact_start_radius: Union[None, float, str] = None) -> Dict[str, Any]:
    """What identifies a job (stored in the array's attributes): hashes of the
    mesh, sources, targets and cost, and the options that change the numbers.
    The backend and block size do not change them and are not part of it.
    exact_start_radius: the radius of the exact start in mean edge lengths
    (0: the plain start; None or "auto": the library's default, recorded as
    "auto", its rule MFMM_EXACT_START_AUTO)."""
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
        # None: the default (64), so that stores written before this key
        # still match
        "max_unfold_steps": mesh._options()["max_unfold_steps"],
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


def _same_job(stored: Dict[str, Any], job: Dict[str, Any]) -> List[str]:
    """The keys on which two jobs differ (the version is not compared: a
    store written by another release is refused only if its numbers differ)."""
    return [k for k in job if k != "meshfmm_version" and stored.get(k) != job[k]]


class StoreError(ValueError):
    """The store cannot take this job: it holds another job, it is not a
    meshfmm store (and ``overwrite`` was not given), or it is an input."""


class StoreOwnerError(RuntimeError):
    """Another run owns the store: a live one refused this run at its start,
    or one took the store over while this run was writing."""


def _job_key(job: Dict[str, Any]) -> str:
    """The hash of a recorded job that each block's digest is bound to (the
    version and unset options left out, as _same_job compares them)."""
    core = {k: v for k, v in job.items() if k != "meshfmm_version" and v is not None}
    return hashlib.sha256(json.dumps(core, sort_keys=True).encode()).hexdigest()


def _block_digest(job_key: str, b: int, r0: int, r1: int, rows: np.ndarray) -> str:
    """Digest of block b's values bound to the job and the block, so that a
    chunk holding another block's or another job's rows does not verify."""
    a = np.ascontiguousarray(rows, dtype=rows.dtype.newbyteorder("<"))
    h = hashlib.blake2b(digest_size=16)
    h.update(f"meshfmm-block:{job_key}:{b}:{r0}:{r1}:{a.dtype.str}:{a.shape}:".encode())
    h.update(a.tobytes())
    return h.hexdigest()


def _key_get(arr: Any, key: str) -> Optional[bytes]:
    from zarr.core.sync import sync

    buf = sync((arr.store_path / key).get())
    return None if buf is None else buf.to_bytes()


def _key_set(arr: Any, key: str, data: bytes) -> None:
    from zarr.core.buffer import default_buffer_prototype
    from zarr.core.sync import sync

    sync((arr.store_path / key).set(default_buffer_prototype().buffer.from_bytes(data)))


def _owner_record(token: str) -> Dict[str, Any]:
    pid = os.getpid()
    try:
        import psutil

        started: Optional[float] = psutil.Process(pid).create_time()
    except Exception:  # no psutil: the pid alone identifies the process
        started = None
    now = time.time()
    return {"token": token, "host": socket.gethostname(), "pid": pid, "pid_started": started,
            "started": now, "heartbeat": now, "state": "running"}


def _pid_alive(pid: Any, started: Any) -> bool:
    if not _args.is_int(pid) or pid <= 0:
        return False
    try:
        import psutil
    except ImportError:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:
            return True
        return True
    try:
        p = psutil.Process(pid)
        # another process reusing the pid is not the owner
        if isinstance(started, (int, float)) and abs(p.create_time() - started) > 1.0:
            return False
        return p.status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False
    except psutil.AccessDenied:
        return True


def _owner_alive(rec: Any) -> bool:
    """Whether the run recorded in `rec` may still be writing: it has not
    released the store, and its process is alive (same host) or its last
    heartbeat is younger than _LEASE_S (another host)."""
    if not isinstance(rec, dict) or rec.get("state") != "running":
        return False
    if rec.get("host") == socket.gethostname():
        if rec.get("pid") == os.getpid():
            return rec.get("token") in _ACTIVE_TOKENS
        return _pid_alive(rec.get("pid"), rec.get("pid_started"))
    hb = rec.get("heartbeat")
    return isinstance(hb, (int, float)) and time.time() - hb < _LEASE_S


def _refuse_live_owner(url: str, rec: Any) -> None:
    if _owner_alive(rec):
        hb = rec.get("heartbeat")
        age = time.time() - hb if isinstance(hb, (int, float)) else float("nan")
        raise StoreOwnerError(
            f"the store {url} is in use by another meshfmm job (pid {rec.get('pid')} on "
            f"{rec.get('host')}, last heartbeat {age:.0f} s ago); wait for it to finish or "
            f"stop it (a killed job's store is free at once on its host, after "
            f"{_LEASE_S:.0f} s from another host)")


def _check_token(arr: Any, token: str, url: str, r0: int, r1: int) -> None:
    rec = arr.attrs.get(OWNER_ATTR) or {}
    if rec.get("token") != token:
        raise StoreOwnerError(f"the store {url} was taken over by another run while this job "
                              f"ran; rows {r0}:{r1} were not written")


# ------------------------------------------------------------- worker side

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


def _compute_block(key: str, V: np.ndarray, F: np.ndarray, url: str,
                   storage_options: Optional[dict], r0: int, r1: int,
                   src: Optional[np.ndarray], targets: Optional[np.ndarray],
                   opts: Dict[str, Any], b: int, token: str,
                   job_key: str) -> Tuple[int, int, float, float, float]:
    """One task: rows [r0, r1) (block b) into their own chunk, then the
    block's digest beside it. Idempotent: a retry writes the same bytes.
    Writes only while the store's owner token is `token` (checked before
    computing and again before writing). Returns r0, r1, the seconds spent
    computing and writing (encoding included), and the CPU seconds of the
    task's thread (library threads started beyond it not counted)."""
    import zarr

    _check_token(zarr.open_array(url, mode="r", storage_options=storage_options),
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
              exact_start=opts.get("exact_start", True))
    if opts["cost"] is not None:
        kw.update(cost=opts["cost"], cost_location=opts["cost_location"])
    # the library's target columns: each row stops once its targets settle
    rows = mesh.distance_matrix(rows_src, targets=targets, **kw)
    t1 = time.perf_counter()
    arr = zarr.open_array(url, mode="r+", storage_options=storage_options)
    _check_token(arr, token, url, r0, r1)
    rows = np.ascontiguousarray(rows, dtype=arr.dtype)
    arr[r0:r1, :] = rows
    _key_set(arr, f"{_SUMS}/{b}", json.dumps(
        {"block": b, "rows": [r0, r1], "job": job_key,
         "blake2b": _block_digest(job_key, b, r0, r1, rows)}).encode())
    return r0, r1, t1 - t0, time.perf_counter() - t1, time.thread_time() - c0


# ------------------------------------------------------------- client side

def _open_store(store: Any, storage_options: Optional[dict]) -> Tuple[str, Optional[dict]]:
    url = os.fspath(store) if isinstance(store, (str, os.PathLike)) else None
    if url is None:
        raise TypeError("store must be a path or an fsspec URL (a string), not "
                        f"{type(store).__name__}")
    return url, storage_options


def _verified(arr: Any, blocks: Sequence[int], block_rows: int) -> List[int]:
    """Those of `blocks` whose chunk decodes (its CRC-32C matches and the
    codecs accept its payload), holds no NaN (a chunk never written reads as
    the NaN fill value) and matches its digest for the store's job and this
    block."""
    job = arr.attrs.get(JOB_ATTR)
    if not isinstance(job, dict) or not job:
        return []
    key = _job_key(job)
    n_rows = arr.shape[0]
    done = []
    for b in blocks:
        r0, r1 = b * block_rows, min(n_rows, (b + 1) * block_rows)
        try:
            block = arr[r0:r1, :]
        except (OSError, MemoryError):  # the store itself failed: not the chunk's fault
            raise
        except Exception:  # a torn or altered chunk: a checksum mismatch (ValueError) or a
            continue       # payload the codecs cannot decode (Blosc: RuntimeError, ...)
        if np.isnan(block).any():
            continue
        try:
            rec = json.loads(_key_get(arr, f"{_SUMS}/{b}") or b"null")
        except ValueError:
            rec = None
        if isinstance(rec, dict) and rec.get("blake2b") == _block_digest(key, b, r0, r1, block):
            done.append(b)
    return done


def _verify_task(url: str, storage_options: Optional[dict], blocks: List[int],
                 block_rows: int) -> List[int]:
    import zarr

    arr = zarr.open_array(url, mode="r", storage_options=storage_options)
    return _verified(arr, blocks, block_rows)


def complete_blocks(arr: Any, block_rows: int) -> List[int]:
    """Indices of the row blocks of `arr` that are complete and verified: the
    chunk decodes (its CRC-32C matches), holds no NaN (the fill value of a
    chunk never written) and matches the digest its task wrote for the
    store's job and this block. Reads the whole array in this process; a resumed
    ``distance_matrix`` does the same check as tasks on its cluster."""
    return _verified(arr, range(math.ceil(arr.shape[0] / block_rows)), block_rows)


def _complete_blocks_on(client: Any, url: str, storage_options: Optional[dict], n_rows: int,
                        block_rows: int, dask_threads: int) -> List[int]:
    """complete_blocks as tasks on the cluster (each reads and checks a share
    of the chunks), so resuming a big store does not read it all through the
    client."""
    n_blocks = math.ceil(n_rows / block_rows)
    n_tasks = max(1, min(n_blocks, 4 * dask_threads))
    batches = [list(range(i, n_blocks, n_tasks)) for i in range(n_tasks)]
    futures = client.map(_verify_task, [url] * n_tasks, [storage_options] * n_tasks, batches,
                         [block_rows] * n_tasks, pure=False,
                         key=[f"meshfmm-verify-{i}-{time.time_ns()}" for i in range(n_tasks)])
    return sorted(b for done in client.gather(futures) for b in done)


def _local_path(url: str) -> Optional[str]:
    """The filesystem path of a local store, None for another fsspec URL."""
    if url.startswith("file://"):
        return url[len("file://"):]
    return None if "://" in url else url


def _probe(url: str, storage_options: Optional[dict]) -> Tuple[str, Any]:
    """What is at `url`: ("absent", None), ("empty", None), ("meshfmm", the
    array, read-only) or ("foreign", None) for anything else (files, a Zarr
    node that records no meshfmm job)."""
    import zarr

    try:
        arr = zarr.open_array(url, mode="r", storage_options=storage_options)
    except FileNotFoundError:
        arr = None
    except OSError:
        raise
    except Exception:  # a group, or metadata that is not an array's
        return "foreign", None
    if arr is not None:
        return ("meshfmm", arr) if isinstance(arr.attrs.get(JOB_ATTR), dict) else ("foreign", None)
    path = _local_path(url)
    if path is not None:
        if not os.path.lexists(path):
            return "absent", None
        if not os.path.isdir(path):
            raise StoreError(f"the output {url} exists and is not a directory")
        return ("empty", None) if not os.listdir(path) else ("foreign", None)
    from zarr.core.sync import sync
    from zarr.storage import FsspecStore

    root = FsspecStore.from_url(url, storage_options=storage_options, read_only=True)
    return ("empty", None) if sync(root.is_empty("")) else ("foreign", None)


def _check_store(url: str, storage_options: Optional[dict], job: Dict[str, Any],
                 shape: Tuple[int, int], resume: bool, overwrite: bool) -> Tuple[str, Any]:
    """Refuses a store this job may not write (another live job owns it, it
    holds another job and `resume` is set, it is not a meshfmm store and
    `overwrite` is not set); else returns _probe's answer."""
    kind, arr = _probe(url, storage_options)
    if kind == "meshfmm":
        _refuse_live_owner(url, arr.attrs.get(OWNER_ATTR))
        if resume:
            diff = _same_job(dict(arr.attrs.get(JOB_ATTR) or {}), job)
            if diff or tuple(arr.shape) != shape:
                raise StoreError(
                    f"the store {url} holds a different job (differs in: "
                    f"{', '.join(diff) or 'shape'}); use another store, or resume=False "
                    "to overwrite it")
    elif kind == "foreign" and not overwrite:
        raise StoreError(
            f"the output {url} exists and is not a meshfmm store (no {JOB_ATTR} attribute); "
            "choose another output, or pass overwrite=True (--overwrite) to write the store "
            "into it (its Zarr entries are replaced, other files kept)")
    return kind, arr


def _delete_own_entries(url: str, storage_options: Optional[dict]) -> None:
    """Deletes a store's Zarr entries (metadata, the chunk tree, the block
    digests) and nothing else: files beside them are not the job's."""
    from zarr.core.sync import sync
    from zarr.storage import FsspecStore, LocalStore, StorePath

    path = _local_path(url)
    store = (LocalStore(path) if path is not None else
             FsspecStore.from_url(url, storage_options=storage_options, read_only=False))
    root = StorePath(store, "")
    for key in ("zarr.json", ".zarray", ".zattrs", ".zgroup"):
        sync((root / key).delete())
    for prefix in ("c", _SUMS):
        sync((root / prefix).delete_dir())


class _Ownership:
    """This run's hold on a store: its token in the attributes, a heartbeat
    every _HEARTBEAT_S while the job runs (from a thread), and the release
    (state "finished" or "stopped") at its end. Every write first re-reads
    the token, so a run never overwrites a newer owner's record."""

    def __init__(self, url: str, storage_options: Optional[dict], token: str) -> None:
        self.url, self.storage_options, self.token = url, storage_options, token
        self.lost = False
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: Optional[threading.Thread] = None

    def update(self, changes: Dict[str, Any], attrs: Optional[Dict[str, Any]] = None) -> bool:
        import zarr

        with self._lock:
            arr = zarr.open_array(self.url, mode="r+", storage_options=self.storage_options)
            rec = arr.attrs.get(OWNER_ATTR) or {}
            if rec.get("token") != self.token:
                self.lost = True
                return False
            arr.attrs.update({OWNER_ATTR: dict(rec, **changes), **(attrs or {})})
            return True

    def _beat(self) -> None:
        while not self._stop.wait(_HEARTBEAT_S):
            try:
                if not self.update({"heartbeat": time.time()}):
                    return
            except Exception:  # a missed beat (the store hiccuped): the next one tries again
                pass

    def start(self) -> None:
        self._thread = threading.Thread(target=self._beat, name="meshfmm-heartbeat",
                                        daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()


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
                    n_workers: Optional[int] = None,
                    storage_options: Optional[dict] = None, compression: str = "lz4",
                    progress: Any = True, retries: int = 3, overwrite: bool = False) -> Any:
    """Computes a dense S x N (or S x T) distance matrix as Dask tasks writing
    a Zarr v3 array at `store`, and returns the ``zarr.Array``.

    mesh: a :class:`meshfmm.Mesh`; shipped to the workers as V and F, with
        its options (``Mesh(..., spokes=False)``: each worker's mesh skips
        the march's ~380 bytes per vertex of spokes, same rows).
    store: a directory path or an fsspec URL (with `storage_options`).
    sources: vertex ids (S,), None for every vertex; targets: vertex ids
        (T,) for the columns, in the given order; None for every vertex.
    client: a ``distributed.Client``; None starts a ``LocalCluster`` of
        `n_workers` processes (default: the machine's cores) with one thread
        each and the settings of ``DASK_CONFIG``, and prints its dashboard
        address.
    dtype: "float32" or "float64"; the values equal ``mesh.distance`` per row
        (float64 bit for bit, float32 the same rounding).
    resume: True skips blocks already complete and verified when the store
        holds the same job, and refuses a store holding another job; False
        starts over a meshfmm store, deleting only its own entries
        (``zarr.json``, ``c/``, ``meshfmm_blocks/``), never other files.
        Either way a store that another live run owns is refused
        (:class:`StoreOwnerError`), and a run killed before it finished does
        not block the next one (see the module's notes).
    block_rows: rows per task and chunk (default: about 8 MiB a chunk, at
        least 4 tasks per Dask thread of the cluster).
    backend, n_threads: the in-process backend each task runs ("threads",
        "serial", "opencl", "auto") and its threads (0: the worker's share of
        its machine, cores / Dask threads on that host, so a LocalCluster of
        one 1-thread process per core runs 1 library thread per task).
    max_distance, cost, cost_location, unfolding, exact_start: as in
        ``Mesh.distance``; the job records the exact start's radius, so a
        store computed with another one is a different job.
    compression: "lz4" (Blosc lz4 with bit shuffle, the default), "zstd"
        (Blosc zstd level 3 with bit shuffle: ~2 % smaller, ~3x slower to
        encode) or "none"; chunks always carry a CRC-32C. Measured on real
        meshes' rows by bench/bench_compression.py (bench/RESULTS.md).
    progress: True for a progress bar on a terminal (plain lines when piped),
        False for none, or a callable ``progress(rows_done, n_rows)``; an
        exception it raises stops the job (blocks in flight still finish).
    retries: times a failed task is retried (a killed worker's tasks are
        rescheduled by Dask regardless).
    overwrite: write the store into a location that exists and is not a
        meshfmm store (a non-empty directory, another Zarr node): its Zarr
        entries (``zarr.json``, ``c/``) are replaced and other files kept.
        Without it such a location is refused with :class:`StoreError`, as
        is a store holding another job when `resume` is set.

    A run owns the store while it writes (a token in the attribute
    ``meshfmm_owner``, checked by every task before it writes): if another
    run takes the store over meanwhile, this one writes nothing more and
    raises :class:`StoreOwnerError`.

    The attribute ``meshfmm_last_run`` of the returned array records how many
    blocks this call computed and skipped, the task seconds spent computing
    and writing (encoding included) and the CPU seconds of the tasks' threads,
    summed over the tasks.
    """
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
                         exact_start=exact_start, n_threads=_args.index(n_threads, "n_threads"))
    url, storage_options = _open_store(store, storage_options)
    n_rows = nv if src is None else src.shape[0]
    n_cols = nv if tgt is None else tgt.shape[0]
    job = job_description(mesh, src, tgt, dt.name, max_distance, cost_arr, cost_location,
                          unfolding, radius)
    # refused before a cluster is started for nothing; checked again below
    _check_store(url, storage_options, job, (n_rows, n_cols), resume, overwrite)
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
        owner = _Ownership(url, storage_options, token)
        record = _owner_record(token)
        _ACTIVE_TOKENS.add(token)
        try:
            kind, _ = _check_store(url, storage_options, job, (n_rows, n_cols), resume,
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
                    _delete_own_entries(url, storage_options)
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
                               "exact_start": radius, "cost": cost_arr,
                               "cost_location": cost_location, "n_threads": n_threads,
                               "host_threads": host_threads,
                               "mesh_options": mesh._options()}, retries)
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
        _ACTIVE_TOKENS.discard(token)
        if own_cluster is not None:
            client.close()
            own_cluster.close()
        quiet.close()


def _run_blocks(client: Any, arr: Any, url: str, storage_options: Optional[dict], mesh: Mesh,
                src: Optional[np.ndarray], tgt: Optional[np.ndarray], token: str, fresh: bool,
                n_rows: int, dask_threads: int, progress: Any, owner: _Ownership,
                opts: Dict[str, Any], retries: int) -> Dict[str, Any]:
    """Verifies a resumed store's blocks, then computes the others as tasks;
    returns the run's record (RUN_ATTR)."""
    block_rows = int(arr.chunks[0])
    n_blocks = math.ceil(n_rows / block_rows)
    job_key = _job_key(arr.attrs[JOB_ATTR])
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
        futures = [client.submit(_compute_block, key, V_f, F_f, url, storage_options,
                                 b * block_rows, min(n_rows, (b + 1) * block_rows),
                                 src_f, tgt, opts, b, token, job_key, retries=retries,
                                 pure=False,
                                 key=f"meshfmm-block-{key[:12]}-{b}-{time.time_ns()}")
                   for b in todo]
        try:
            for fut in as_completed(futures):
                r0, r1, tc, tw, tcpu = fut.result()
                computed += 1
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
            "task_write_seconds": t_write, "task_thread_cpu_seconds": t_cpu}


def symmetrize(store: Any, out: Any, storage_options: Optional[dict] = None,
               overwrite: bool = False) -> Any:
    """(D + D^T) / 2 of a square matrix in a Zarr store, written to `out`, with
    Dask arrays (chunk by chunk, never the whole matrix in memory):
    ``da.from_zarr(store)`` then ``((D + D.T) / 2).astype(D.dtype).to_zarr(out)``.
    Returns the new ``zarr.Array``.

    Raises StoreError when `out` is `store`, holds it or lies inside it, and
    when `out` exists and is not empty unless `overwrite` is set; then only
    its Zarr entries are replaced, and other files in it are kept."""
    import dask.array as da
    import zarr

    url, storage_options = _open_store(store, storage_options)
    out_url, _ = _open_store(out, storage_options)
    a, b = _local_path(url), _local_path(out_url)
    if a is not None and b is not None:
        _refuse_inputs(out_url, [url])
        ra, rb = os.path.realpath(a), os.path.realpath(b)
        if os.path.commonpath([ra, rb]) == ra:
            raise StoreError(f"the output {out_url} lies inside the input store {url}; "
                             "choose another output")
    elif url.rstrip("/") == out_url.rstrip("/"):
        raise StoreError(f"the output {out_url} is the input store; choose another output")
    D = da.from_zarr(url, storage_options=storage_options)
    if D.ndim != 2 or D.shape[0] != D.shape[1]:
        raise ValueError(f"symmetrize needs a square matrix, not {D.shape}")
    kind, _ = _probe(out_url, storage_options)
    if kind in ("meshfmm", "foreign"):
        if not overwrite:
            raise StoreError(f"the output {out_url} exists and is not empty; choose another "
                             "output, or pass overwrite=True (its Zarr entries are replaced, "
                             "other files kept)")
        _delete_own_entries(out_url, storage_options)
    S = ((D + D.T) / 2).astype(D.dtype)
    S.to_zarr(out_url, storage_options=storage_options)
    return zarr.open_array(out_url, mode="r", storage_options=storage_options)


# ------------------------------------------------------------- command line

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


def _refuse_inputs(output: str, inputs: Sequence[Optional[str]]) -> None:
    """Refuses an output that is one of the job's input files or a directory
    holding one (compared by device and inode, walking up each input's
    parents as given and as resolved), as the C command line refuses an
    output that is an input: starting over would write into it."""
    path = _local_path(output)
    if path is None:
        return
    try:
        st = os.stat(path)
    except OSError:  # not there yet: it holds nothing
        return
    ident = (st.st_dev, st.st_ino)
    for given in inputs:
        if given is None:
            continue
        for q in {os.path.abspath(given), os.path.realpath(given)}:
            while True:
                try:
                    s = os.stat(q)
                    if (s.st_dev, s.st_ino) == ident:
                        raise StoreError(f"the output {output} is an input or contains one "
                                         f"({given}); choose another output")
                except OSError:
                    pass
                parent = os.path.dirname(q)
                if parent == q:
                    break
                q = parent


def cli_allpairs_zarr(argv: Sequence[str]) -> int:
    """``meshfmm allpairs MESH -o OUT.zarr [--scheduler ADDRESS | --workers N]
    [--resume] [--overwrite] ...``: the distributed all-pairs job from the
    command line. OUT may not be an input or contain one; without
    ``--resume`` a meshfmm store there is started over (only its own Zarr
    entries deleted); ``--overwrite`` is needed to write into a location
    that exists and is not a meshfmm store (its Zarr entries are replaced,
    other files kept). Errors are one line on stderr and exit status 2."""
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
    st = ap.add_mutually_exclusive_group()
    st.add_argument("--exact-start-radius", type=float, metavar="R", action=_Once,
                    help="radius of the exact start in mean edge lengths (default: the library's)")
    st.add_argument("--plain-start", action="store_true", help="the paper's plain start")
    ap.add_argument("--block-rows", type=int, action=_Once)
    ap.add_argument("--compression", choices=list(_CODECS), default="lz4", action=_Once,
                    help="Blosc lz4 or zstd (bit shuffle), or none (default: lz4)")
    ap.add_argument("--no-progress", action="store_true")
    ap.add_argument("--no-spokes", action="store_true",
                    help="memory first: no per-vertex update records on the workers "
                         "(~380 bytes per vertex each; same matrix, marches 1.25-1.6x as long)")
    a = ap.parse_args(list(argv))
    try:
        _refuse_inputs(a.output, [a.mesh, a.sources, a.targets, a.cost])
        from ._mesh import load_mesh

        mesh = Mesh(*load_mesh(a.mesh), spokes=not a.no_spokes)
        src = _read_ids(a.sources, "sources") if a.sources else None
        tgt = _read_ids(a.targets, "targets") if a.targets else None
        cost = None
        if a.cost:
            cost = np.load(a.cost) if a.cost.endswith(".npy") else np.loadtxt(a.cost, ndmin=1)
        client = None
        if a.scheduler:
            from distributed import Client

            client = Client(a.scheduler)
            link = getattr(client, "dashboard_link", None)
            if link and not a.no_progress:
                print(f"meshfmm: Dask dashboard at {link}", file=sys.stderr)
        Z = distance_matrix(mesh, a.output, sources=src, targets=tgt, client=client,
                            dtype=a.dtype, resume=a.resume, block_rows=a.block_rows,
                            backend=a.backend, max_distance=a.max_distance, cost=cost,
                            n_workers=a.workers, progress=not a.no_progress,
                            exact_start=(False if a.plain_start else
                                         True if a.exact_start_radius is None
                                         else a.exact_start_radius),
                            compression=a.compression, overwrite=a.overwrite)
        run = Z.attrs.get(RUN_ATTR, {})
        print(f"meshfmm: wrote {Z.shape[0]} x {Z.shape[1]} {Z.dtype} to {a.output} "
              f"({run.get('blocks_computed')} blocks computed, {run.get('blocks_skipped')} "
              "already complete)", file=sys.stderr)
        if client is not None:
            client.close()
        return 0
    except KeyboardInterrupt:
        print("meshfmm: interrupted; complete blocks are kept (run again with --resume)",
              file=sys.stderr)
        return 130
    except (ValueError, TypeError, OSError, StoreOwnerError) as e:
        print(f"meshfmm: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(cli_allpairs_zarr(sys.argv[1:]))
