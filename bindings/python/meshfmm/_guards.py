"""Guards and feedback for long jobs: the memory a dense result would take
against the memory available, and a progress bar on standard error."""

from __future__ import annotations

import os
import sys
import time
from typing import Any, Optional, TextIO


def format_bytes(n: float) -> str:
    """A byte count as "14.4 GB" (decimal units, as free(1) -h --si)."""
    for unit in ("bytes", "kB", "MB", "GB", "TB", "PB"):
        if n < 1000 or unit == "PB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.3g} {unit}"
        n /= 1000.0
    return f"{n:.3g} PB"  # pragma: no cover


def _read_int(path: str) -> Optional[int]:
    try:
        with open(path) as f:
            text = f.read().strip()
    except OSError:
        return None
    return int(text) if text.isdigit() else None


def available_memory() -> Optional[int]:
    """Bytes this process may still allocate: the least of the system's
    available memory (MemAvailable), what the cgroup's limit leaves and
    what the address-space limit (RLIMIT_AS) leaves; None when none of
    them is known."""
    found = []
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    found.append(int(line.split()[1]) * 1024)
                    break
    except (OSError, ValueError, IndexError):
        pass
    if not found and hasattr(os, "sysconf"):
        try:
            found.append(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
        except (ValueError, OSError):
            pass
    limit = _read_int("/sys/fs/cgroup/memory.max")  # cgroup v2 ("max": no limit)
    if limit is not None:
        used = _read_int("/sys/fs/cgroup/memory.current") or 0
        found.append(max(limit - used, 0))
    try:
        import resource

        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft != resource.RLIM_INFINITY:
            size = 0
            with open("/proc/self/statm") as f:
                size = int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
            found.append(max(soft - size, 0))
    except (ImportError, OSError, ValueError):
        pass
    return min(found) if found else None


def check_memory(nbytes: int, what: str) -> None:
    """Refuses (MemoryError, with both numbers) a result of `nbytes` that
    the available memory cannot hold."""
    avail = available_memory()
    if avail is not None and nbytes > avail:
        raise MemoryError(
            f"the result would take {format_bytes(nbytes)} ({what}) but {format_bytes(avail)} "
            "of memory are available: write it to disk (out=meshfmm.open_memmap(...)), ask for "
            "fewer rows or columns (sources, targets, iter_distance_rows), or pass "
            "size_check=False to allocate anyway")


class ProgressBar:
    """A one-line progress bar on standard error, ``progress=True``'s:
    called as ``bar(done, total)``; :meth:`close` ends the line, naming the
    backend that ran and, under "auto", why."""

    def __init__(self, what: str, stream: Optional[TextIO] = None, every: float = 0.1) -> None:
        self.what = what
        self.stream = stream if stream is not None else sys.stderr
        self.every = every
        self.t0 = time.monotonic()
        self.last = -1.0
        self.done = 0
        self.total = 0
        self.width = 0

    def __call__(self, done: int, total: int) -> None:
        self.done, self.total = done, total
        now = time.monotonic()
        if now - self.last < self.every and done < total:
            return
        self.last = now
        self._draw(now)

    def _draw(self, now: float, tail: str = "") -> None:
        t = now - self.t0
        if self.total:
            frac = self.done / self.total
            bar = "#" * int(24 * frac)
            eta = (f", {t / frac - t:.1f} s left" if 0 < frac < 1 else "")
            line = (f"{self.what} [{bar:<24}] {self.done}/{self.total} "
                    f"({100 * frac:.0f}%), {t:.1f} s{eta}{tail}")
        else:
            line = f"{self.what}: {t:.1f} s{tail}"
        pad = max(self.width - len(line), 0)
        self.width = len(line)
        self.stream.write("\r" + line + " " * pad)
        self.stream.flush()

    def tick(self) -> None:
        """For a job without a count (an exact solve): the time so far."""
        now = time.monotonic()
        if now - self.last >= self.every:
            self.last = now
            self._draw(now)

    def close(self, info: Any = None) -> None:
        """Ends the line; with a MatrixInfo, names its backend (and why
        "auto" chose it)."""
        tail = ""
        if info is not None and getattr(info, "backend", ""):
            tail = f", backend {info.backend}"
            if info.reason:
                tail += f" (auto: {info.reason})"
        self._draw(time.monotonic(), tail)
        self.stream.write("\n")
        self.stream.flush()


def progress_callback(progress: Any, what: str) -> "tuple[Any, Optional[ProgressBar]]":
    """A ``progress`` argument -> (the callable to pass on, the bar to close
    or None): True draws a bar, False or None nothing, a callable is kept."""
    if progress is True:
        bar = ProgressBar(what)
        return bar, bar
    if progress is None or progress is False:
        return None, None
    if not callable(progress):
        raise TypeError(f"progress must be True, False, None or a callable, got {progress!r}")
    return progress, None
