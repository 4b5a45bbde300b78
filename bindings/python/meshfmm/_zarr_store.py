"""The Zarr store of a distributed job: where it is and what it holds, the
job it records, the per-block digests that tell a complete block, and the
ownership of a store by one run at a time (token, heartbeat, release). See
:mod:`meshfmm.distributed` for what these guarantee."""

from __future__ import annotations

import hashlib
import json
import os
import socket
import threading
import time
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from . import _args

#: Attribute of the array recording the job (see job_description).
JOB_ATTR = "meshfmm_job"
#: Attribute recording the last run: blocks computed and skipped, task seconds.
RUN_ATTR = "meshfmm_last_run"
#: Attribute recording the run that owns the store (token, host, pid, heartbeat).
OWNER_ATTR = "meshfmm_owner"
# Key prefix of the per-block digests, beside Zarr's chunk tree "c/".
SUMS = "meshfmm_blocks"
# The owner's heartbeat period, and how long without one a run on another
# host is taken for dead (on its own host its process is looked up instead).
_HEARTBEAT_S = 10.0
_LEASE_S = 60.0
# Tokens of the runs in progress in this process: a record naming this
# process with another token was left by a run of it that did not release.
ACTIVE_TOKENS: set = set()


class StoreError(ValueError):
    """The store cannot take this job: it holds another job, it is not a
    meshfmm store (and ``overwrite`` was not given), or it is an input."""


class StoreOwnerError(RuntimeError):
    """Another run owns the store: a live one refused this run at its start,
    or one took the store over while this run was writing."""


def same_job(stored: Dict[str, Any], job: Dict[str, Any]) -> List[str]:
    """The keys on which two jobs differ (the version is not compared: a
    store written by another release is refused only if its numbers differ)."""
    return [k for k in job if k != "meshfmm_version" and stored.get(k) != job[k]]


def job_key(job: Dict[str, Any]) -> str:
    """The hash of a recorded job that each block's digest is bound to (the
    version and unset options left out, as same_job compares them)."""
    core = {k: v for k, v in job.items() if k != "meshfmm_version" and v is not None}
    return hashlib.sha256(json.dumps(core, sort_keys=True).encode()).hexdigest()


def block_digest(job_key: str, b: int, r0: int, r1: int, rows: np.ndarray) -> str:
    """Digest of block b's values bound to the job and the block, so that a
    chunk holding another block's or another job's rows does not verify."""
    a = np.ascontiguousarray(rows, dtype=rows.dtype.newbyteorder("<"))
    h = hashlib.blake2b(digest_size=16)
    h.update(f"meshfmm-block:{job_key}:{b}:{r0}:{r1}:{a.dtype.str}:{a.shape}:".encode())
    h.update(a.tobytes())
    return h.hexdigest()


def key_get(arr: Any, key: str) -> Optional[bytes]:
    from zarr.core.sync import sync

    buf = sync((arr.store_path / key).get())
    return None if buf is None else buf.to_bytes()


def key_set(arr: Any, key: str, data: bytes) -> None:
    from zarr.core.buffer import default_buffer_prototype
    from zarr.core.sync import sync

    sync((arr.store_path / key).set(default_buffer_prototype().buffer.from_bytes(data)))


def open_store(store: Any, storage_options: Optional[dict]) -> Tuple[str, Optional[dict]]:
    url = os.fspath(store) if isinstance(store, (str, os.PathLike)) else None
    if url is None:
        raise TypeError("store must be a path or an fsspec URL (a string), not "
                        f"{type(store).__name__}")
    return url, storage_options


def local_path(url: str) -> Optional[str]:
    """The filesystem path of a local store, None for another fsspec URL."""
    if url.startswith("file://"):
        return url[len("file://"):]
    return None if "://" in url else url


def probe(url: str, storage_options: Optional[dict]) -> Tuple[str, Any]:
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
    path = local_path(url)
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


def check_store(url: str, storage_options: Optional[dict], job: Dict[str, Any],
                 shape: Tuple[int, int], resume: bool, overwrite: bool) -> Tuple[str, Any]:
    """Refuses a store this job may not write (another live job owns it, it
    holds another job and `resume` is set, it is not a meshfmm store and
    `overwrite` is not set); else returns probe's answer."""
    kind, arr = probe(url, storage_options)
    if kind == "meshfmm":
        _refuse_live_owner(url, arr.attrs.get(OWNER_ATTR))
        if resume:
            diff = same_job(dict(arr.attrs.get(JOB_ATTR) or {}), job)
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


def delete_own_entries(url: str, storage_options: Optional[dict]) -> None:
    """Deletes a store's Zarr entries (metadata, the chunk tree, the block
    digests) and nothing else: files beside them are not the job's."""
    from zarr.core.sync import sync
    from zarr.storage import FsspecStore, LocalStore, StorePath

    path = local_path(url)
    store = (LocalStore(path) if path is not None else
             FsspecStore.from_url(url, storage_options=storage_options, read_only=False))
    root = StorePath(store, "")
    for key in ("zarr.json", ".zarray", ".zattrs", ".zgroup"):
        sync((root / key).delete())
    for prefix in ("c", SUMS):
        sync((root / prefix).delete_dir())


def refuse_inputs(output: str, inputs: Sequence[Optional[str]]) -> None:
    """Refuses an output that is one of the job's input files or a directory
    holding one (compared by device and inode, walking up each input's
    parents as given and as resolved), as the C command line refuses an
    output that is an input: starting over would write into it."""
    path = local_path(output)
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


def owner_record(token: str) -> Dict[str, Any]:
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
            return rec.get("token") in ACTIVE_TOKENS
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


def check_token(arr: Any, token: str, url: str, r0: int, r1: int) -> None:
    rec = arr.attrs.get(OWNER_ATTR) or {}
    if rec.get("token") != token:
        raise StoreOwnerError(f"the store {url} was taken over by another run while this job "
                              f"ran; rows {r0}:{r1} were not written")


class Ownership:
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


def verified_blocks(arr: Any, blocks: Sequence[int], block_rows: int) -> List[int]:
    """Those of `blocks` whose chunk decodes (its CRC-32C matches and the
    codecs accept its payload), holds no NaN (a chunk never written reads as
    the NaN fill value) and matches its digest for the store's job and this
    block."""
    job = arr.attrs.get(JOB_ATTR)
    if not isinstance(job, dict) or not job:
        return []
    key = job_key(job)
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
            rec = json.loads(key_get(arr, f"{SUMS}/{b}") or b"null")
        except ValueError:
            rec = None
        if isinstance(rec, dict) and rec.get("blake2b") == block_digest(key, b, r0, r1, block):
            done.append(b)
    return done


def verify_task(url: str, storage_options: Optional[dict], blocks: List[int],
                 block_rows: int) -> List[int]:
    import zarr

    arr = zarr.open_array(url, mode="r", storage_options=storage_options)
    return verified_blocks(arr, blocks, block_rows)
