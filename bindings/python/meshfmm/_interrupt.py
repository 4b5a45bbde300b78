"""Ctrl-C during a long C call: a flag the library's callbacks poll, so the
call stops cleanly and raises one KeyboardInterrupt afterwards."""

from __future__ import annotations

import contextlib
import signal
import threading
from typing import Any, Iterator, List


@contextlib.contextmanager
def sigint_as_flag(flag: List[int]) -> Iterator[None]:
    """While a long C call runs on the main thread, Ctrl-C appends to `flag`
    instead of raising KeyboardInterrupt inside a ctypes callback (where
    Python can only print it and go on); the callback then returns the
    cancel code and the caller raises one KeyboardInterrupt after the call.
    Leaves a handler other than Python's default one alone, and does nothing
    off the main thread (signals are only handled there)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    try:
        previous = signal.getsignal(signal.SIGINT)
    except (ValueError, OSError):  # pragma: no cover
        yield
        return
    if previous is not signal.default_int_handler:
        yield
        return

    def handler(signum: int, frame: Any) -> None:
        flag.append(signum)

    signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
