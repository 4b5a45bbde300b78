"""One Mesh used from several threads at once gives the serial results, and
close() while they compute waits for the calls in flight."""

from __future__ import annotations

import copy
import threading
import time

import numpy as np
import pytest

import meshfmm
from conftest import load, mesh, need_data
from test_api import grid


def test_four_threads_equal_serial():
    need_data()
    m = mesh("camelhead.off")
    rng = np.random.default_rng(5)
    sources = [int(s) for s in rng.choice(m.n_vertices, size=24, replace=False)]
    cost = rng.uniform(1.0, 2.0, m.n_faces)
    jobs = [(s, None if i % 3 else cost) for i, s in enumerate(sources)]
    serial = [m.distance(s, cost=c) for s, c in jobs]

    results = [None] * len(jobs)
    errors = []
    start = threading.Barrier(4)

    def work(k):
        try:
            start.wait()
            for _ in range(2):
                for j in range(k, len(jobs), 4):
                    s, c = jobs[j]
                    results[j] = m.distance(s, cost=c)
        except BaseException as exc:  # report in the main thread
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    for j, (r, s) in enumerate(zip(results, serial)):
        assert r.tobytes() == s.tobytes(), f"job {j} differs"
    # each concurrent call had its own workspace; they are pooled, not leaked
    assert 1 <= len(m._solvers) <= 4



@pytest.mark.parametrize("slow_backend, fast_backend", [("threads", "serial"),
                                                        ("serial", "threads")])
def test_matrix_info_is_per_call(slow_backend, fast_backend):
    """Two threads share one Mesh with different backends: each call returns
    its own MatrixInfo, also when the other call ends while it is in flight."""
    m = meshfmm.Mesh(*grid(10))
    fast_done = threading.Event()
    results = {}
    errors = []

    def slow():
        def wait_for_fast(done, n):
            # hold this call in flight until the other one has returned
            if not fast_done.wait(30):
                raise TimeoutError("the other call did not return")
        try:
            results["slow"] = m.distance_matrix([0, 5, 60], backend=slow_backend,
                                                n_threads=2, progress=wait_for_fast,
                                                return_info=True)
        except BaseException as exc:
            errors.append(exc)

    def fast():
        try:
            results["fast"] = m.distance_matrix([1, 2], backend=fast_backend, n_threads=2,
                                                return_info=True)
        except BaseException as exc:
            errors.append(exc)
        finally:
            fast_done.set()

    t_slow = threading.Thread(target=slow)
    t_slow.start()
    _hold_until(lambda: m._active > 0)
    t_fast = threading.Thread(target=fast)
    t_fast.start()
    t_fast.join()
    t_slow.join()
    assert not errors, errors
    (d_slow, i_slow), (d_fast, i_fast) = results["slow"], results["fast"]
    assert i_slow.backend == slow_backend and i_fast.backend == fast_backend
    assert i_slow.vertices_settled == 3 * 121 and i_fast.vertices_settled == 2 * 121
    assert np.array_equal(d_slow[2], m.distance(60).astype(np.float32))
    assert not hasattr(m, "backend_used")

def _hold_until(cond, seconds=5.0):
    """Polls cond() every millisecond for at most `seconds`."""
    deadline = time.monotonic() + seconds
    while not cond() and time.monotonic() < deadline:
        time.sleep(0.001)


def test_close_while_busy_waits_for_the_calls_in_flight():
    """Workers computing in a loop while the main thread closes the mesh:
    close() is never refused; it returns once the calls in flight end, whose
    results are the serial ones; every later call raises ValueError."""
    need_data()
    V, F = load("camelhead.off")
    m = meshfmm.Mesh(V, F)
    sources = [0, 17, 400, 2024, 5000, 9000]
    serial = {s: m.distance(s) for s in sources}
    results = {k: [] for k in range(3)}
    errors = []
    started = threading.Barrier(4)

    def work(k):
        try:
            started.wait()
            i = k
            deadline = time.monotonic() + 5  # a close() that never comes ends the test
            while time.monotonic() < deadline:
                s = sources[i % len(sources)]
                results[k].append((s, m.distance(s)))
                i += 1
        except ValueError as exc:
            results[k].append(("closed", str(exc)))
        except BaseException as exc:
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(k,), daemon=True) for k in range(3)]
    for t in threads:
        t.start()
    started.wait()
    time.sleep(0.05)  # the workers are mid-loop: some call is in flight now
    m.close()  # no RuntimeError, no retry loop
    assert m.closed and m._ptr is None and m._active == 0
    for t in threads:
        t.join(5)
        assert not t.is_alive()
    assert not errors, errors
    for k, got in results.items():
        assert got and got[-1] == ("closed", "the mesh is closed"), k
        assert len(got) > 1, "each worker computed before the close"
        for s, d in got[:-1]:
            assert d.tobytes() == serial[s].tobytes(), f"worker {k}, source {s}"
    with pytest.raises(ValueError, match="the mesh is closed"):
        m.distance(0)


def test_close_returns_after_the_call_in_flight_with_its_serial_row():
    """A call held in flight (its progress callback) when close() starts:
    close() waits for it, the call returns the reference rows, the worker's
    next call gets ValueError."""
    need_data()
    V, F = load("camelhead.off")
    m = meshfmm.Mesh(V, F)
    rows = [0, 100, 2000, 7000]
    ref = m.distance_matrix(rows, backend="serial", dtype="float64")
    in_flight = threading.Event()
    out = {}

    def progress(done, total):
        in_flight.set()
        _hold_until(lambda: m.closed)  # close() has begun...
        time.sleep(0.2)  # ...and the call goes on a while

    def work():
        try:
            out["rows"] = m.distance_matrix(rows, backend="serial", dtype="float64",
                                            progress=progress)
            out["done"] = time.monotonic()
            m.distance(0)
        except BaseException as exc:
            out["next"] = exc

    t = threading.Thread(target=work, daemon=True)
    t.start()
    assert in_flight.wait(5)
    t0 = time.monotonic()
    m.close()
    waited = time.monotonic() - t0
    t.join(5)
    assert not t.is_alive()
    assert waited >= 0.15, f"close() returned after {waited:.3f} s, during the call"
    assert m._ptr is None
    assert out["rows"].tobytes() == ref.tobytes()
    assert isinstance(out["next"], ValueError) and str(out["next"]) == "the mesh is closed"


def test_close_timeout_leaves_the_mesh_closing_then_frees_it():
    """close(timeout) with a call in flight raises TimeoutError: the mesh takes
    no new calls, the call in flight finishes with its normal result and frees
    the mesh as it returns; a later close() is then a no-op."""
    need_data()
    V, F = load("spot.obj")
    m = meshfmm.Mesh(V, F)
    ref = m.distance_matrix([3, 30], backend="serial", dtype="float64")
    in_flight = threading.Event()
    release = threading.Event()
    out = {}

    def progress(done, total):
        in_flight.set()
        release.wait(5)

    def work():
        out["rows"] = m.distance_matrix([3, 30], backend="serial", dtype="float64",
                                        progress=progress)

    t = threading.Thread(target=work, daemon=True)
    t.start()
    assert in_flight.wait(5)
    t0 = time.monotonic()
    with pytest.raises(TimeoutError, match="in flight"):
        m.close(timeout=0.1)
    assert 0.08 <= time.monotonic() - t0 < 2
    with pytest.raises(TimeoutError):
        m.close(timeout=0)  # does not wait at all
    assert m.closed and "closed" in repr(m)
    assert m._ptr is not None  # still held by the call in flight
    with pytest.raises(ValueError, match="the mesh is closed"):
        m.distance(0)
    with pytest.raises(ValueError, match="closed"):
        copy.copy(m)
    release.set()
    t.join(5)
    assert not t.is_alive()
    assert out["rows"].tobytes() == ref.tobytes()
    assert m._ptr is None and not m._solvers  # freed by the last call in flight
    m.close()  # idempotent


def test_close_after_a_timeout_waits_and_frees():
    """A close() that timed out, then close() without a timeout: it waits for
    the call in flight and frees the mesh itself."""
    V, F = grid(20)
    m = meshfmm.Mesh(V, F)
    in_flight = threading.Event()
    release = threading.Event()

    def progress(done, total):
        in_flight.set()
        release.wait(5)

    t = threading.Thread(target=lambda: m.distance_matrix([0, 1], backend="serial",
                                                          progress=progress), daemon=True)
    t.start()
    assert in_flight.wait(5)
    with pytest.raises(TimeoutError):
        m.close(timeout=0.01)
    threading.Timer(0.1, release.set).start()
    m.close()
    assert m._ptr is None
    t.join(5)


@pytest.mark.parametrize("bad, exc", [(-1, ValueError), (float("nan"), ValueError),
                                      ("1", TypeError), (True, TypeError)])
def test_close_timeout_refuses_bad_values(bad, exc):
    m = meshfmm.Mesh(*grid(4))
    with pytest.raises(exc, match="timeout"):
        m.close(timeout=bad)
    assert not m.closed
    m.close(timeout=0)  # nothing in flight: closes at once
    assert m._ptr is None


@pytest.mark.parametrize("backend", ["serial", "threads"])
def test_close_from_a_callback_of_its_own_call_raises(backend):
    """close() from a progress callback (the calling thread has the call in
    flight) would wait for itself: RuntimeError, propagated out of the call,
    and the mesh stays open."""
    V, F = grid(12)
    m = meshfmm.Mesh(V, F)
    with pytest.raises(RuntimeError, match="in flight"):
        m.distance_matrix([0, 5, 9], backend=backend, progress=lambda done, n: m.close())
    assert not m.closed
    ref = m.distance_matrix([0, 5, 9], backend="serial")
    seen = []

    def progress(done, n):
        try:
            m.close(timeout=1)
        except RuntimeError as exc:
            seen.append(exc)

    blocks = list(m.iter_distance_rows([0, 5, 9], block_rows=2, backend=backend,
                                       progress=progress))
    assert len(seen) == 2 and not m.closed
    assert np.concatenate([b for _, b in blocks]).tobytes() == ref.tobytes()
    # between two blocks no call is in flight: close() there ends the job
    it = m.iter_distance_rows([0, 5, 9], block_rows=2, backend=backend)
    next(it)
    m.close()
    with pytest.raises(ValueError, match="the mesh is closed"):
        next(it)


def test_del_never_blocks():
    """__del__ with the mesh's lock held elsewhere returns at once and leaves
    the memory alone."""
    m = meshfmm.Mesh(*grid(4))
    with m._lock:
        t = threading.Thread(target=m.__del__, daemon=True)
        t.start()
        t.join(1)
        blocked = t.is_alive()
    t.join(5)
    assert not blocked, "__del__ waited for the lock"
    assert m._ptr is not None
    m.__del__()
    assert m._ptr is None
