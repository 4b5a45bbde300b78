"""Python-side safety, each case reproduced: max_distance checks, inputs
aliasing distance_matrix's out, copies and pickles of a Mesh, a full disk
under a memmapped matrix, Ctrl-C in distance_matrix."""

from __future__ import annotations

import copy
import errno
import os
import pickle
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

import meshfmm
from test_api import grid

HERE = Path(__file__).resolve().parent


def run_isolated(code: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """Runs `code` in a fresh interpreter, so that a crash (use-after-free,
    segfault) is a failed test, not a dead test run."""
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=timeout, cwd=str(HERE))


# ---------------------------------------------------- max_distance checks
@pytest.mark.parametrize("bad,exc,words", [
    (-1.0, ValueError, [">= 0", "-1"]),
    (-np.inf, ValueError, [">= 0"]),
    (float("nan"), ValueError, ["NaN"]),
    (np.float32("nan"), ValueError, ["NaN"]),
    ("2.5", TypeError, ["number", "str"]),
    (b"2.5", TypeError, ["number"]),
    (True, TypeError, ["bool"]),
    ([1.0], TypeError, ["list"]),
    (1 + 2j, TypeError, ["complex"]),
    (np.array(0.5), TypeError, ["ndarray"]),
])
@pytest.mark.parametrize("call", ["distance", "distance_matrix"])
def test_max_distance_refused(bad, exc, words, call):
    m = meshfmm.Mesh(*grid(3))
    with pytest.raises(exc) as info:
        if call == "distance":
            m.distance(0, max_distance=bad)
        else:
            m.distance_matrix([0, 1], backend="serial", max_distance=bad)
    msg = str(info.value)
    assert "max_distance" in msg
    for w in words:
        assert w in msg, msg


@pytest.mark.parametrize("ok", [0, 0.0, 0.5, np.float32(0.5), np.int64(2), Fraction(1, 3), np.inf,
                                None])
def test_max_distance_accepted(ok):
    m = meshfmm.Mesh(*grid(4))
    d = m.distance(0, max_distance=ok)
    limit = np.inf if ok is None else float(ok)
    full = m.distance(0)
    within = full <= limit
    np.testing.assert_array_equal(d[within], full[within])
    assert np.isinf(d[~within]).all()
    D = m.distance_matrix([0], backend="serial", dtype="float64", max_distance=ok)
    np.testing.assert_array_equal(D[0], d)


# ----------------------------------------------- inputs aliasing out
ALIAS_CASES = ["sources", "cost"]


@pytest.mark.parametrize("backend", ["serial", "threads"])
@pytest.mark.parametrize("what", ALIAS_CASES)
def test_inputs_sharing_memory_with_out(backend, what):
    """sources (or cost) that are a view of `out`: the library overwrites
    them with rows while it still reads them, unless they are copied first:
    else garbage vertex ids (a crash) or rows computed with a clobbered cost. Run in a
    subprocess so that a segfault fails the test."""
    code = f"""
    import numpy as np, meshfmm
    from test_api import grid
    V, F = grid(12)
    m = meshfmm.Mesh(V, F)
    nv = len(V)
    n = 40
    ids = (np.arange(n) * 7) % nv
    cost = np.linspace(1.0, 3.0, nv)
    ref = np.stack([m.distance(int(s), cost=cost, cost_location="vertex") for s in ids])
    if {what!r} == "sources":
        out = np.zeros((n, nv), np.float32)
        src = out.reshape(-1).view(np.int32)[nv:nv + n]    # lives in row 1
        src[:] = ids
        D = m.distance_matrix(src, backend={backend!r}, out=out, cost=cost,
                              cost_location="vertex", n_threads=2, memory_limit=1 << 16)
        assert D is out
        np.testing.assert_array_equal(D, ref.astype(np.float32))
    else:
        out = np.zeros((n, nv), np.float64)
        c = out[0]                                          # the cost is row 0
        c[:] = cost
        D = m.distance_matrix(ids, backend={backend!r}, dtype="float64", out=out, cost=c,
                              cost_location="vertex", n_threads=2, memory_limit=1 << 16)
        np.testing.assert_array_equal(D, ref)
    print("ok")
    """
    proc = run_isolated(code)
    assert proc.returncode == 0, f"rc {proc.returncode}: {proc.stderr[-3000:]}"
    assert proc.stdout.strip() == "ok"


def test_inputs_not_aliasing_are_not_copied_needlessly():
    """out that only looks like the sources (same values, own memory) is fine."""
    m = meshfmm.Mesh(*grid(4))
    src = np.array([0, 3, 7], dtype=np.int32)
    out = np.empty((3, m.n_vertices), np.float32)
    D = m.distance_matrix(src, backend="serial", out=out)
    assert D is out
    np.testing.assert_array_equal(src, [0, 3, 7])
    for i, s in enumerate(src):
        np.testing.assert_array_equal(D[i], m.distance(int(s)).astype(np.float32))


# --------------------------------------------------- copies and pickles
def test_copy_then_close_one_other_works():
    """A copy sharing the C pointer would free the mesh under the other copy
    when one is closed (use-after-free, then a double free). In a
    subprocess, so that the crash shows as a failure."""
    code = """
    import copy, gc, pickle, numpy as np, meshfmm
    from test_api import grid
    m = meshfmm.Mesh(*grid(6), max_unfold_steps=5)
    ref = m.distance(3)
    copies = [copy.copy(m), copy.deepcopy(m), pickle.loads(pickle.dumps(m)),
              pickle.loads(pickle.dumps(m, protocol=0))]
    m.close()
    for c in copies:
        assert not c.closed
        np.testing.assert_array_equal(c.distance(3), ref)
        np.testing.assert_array_equal(c.distance_matrix([3], dtype="float64")[0], ref)
    copies[0].close()
    for c in copies[1:]:
        np.testing.assert_array_equal(c.distance(3), ref)
    del m, copies
    gc.collect()
    print("ok")
    """
    proc = run_isolated(code)
    assert proc.returncode == 0, f"rc {proc.returncode}: {proc.stderr[-3000:]}"
    assert proc.stdout.strip() == "ok"


def test_spokes_off_gives_the_same_rows_and_survives_copies():
    """Mesh(spokes=False), memory first: the march walks the faces instead
    of the spokes, the same rows bit for bit (one march, two readings of
    the mesh), and copies keep the choice."""
    V, F = meshfmm.load_mesh(HERE.parent / "data" / "meshes" / "wingnut.obj")
    on, off = meshfmm.Mesh(V, F), meshfmm.Mesh(V, F, spokes=False)
    src = np.arange(0, len(V), 97)
    np.testing.assert_array_equal(off.distance_matrix(src, dtype="float64"),
                                  on.distance_matrix(src, dtype="float64"))
    np.testing.assert_array_equal(off.distance(3), on.distance(3))
    c = pickle.loads(pickle.dumps(off))
    assert c._options() == {"max_unfold_steps": None, "spokes": False, "weld": False}
    np.testing.assert_array_equal(c.distance(5), on.distance(5))


@pytest.mark.parametrize("how", ["copy", "deepcopy", "pickle"])
def test_copies_are_equal_and_independent(how):
    V, F = grid(5)
    m = meshfmm.Mesh(V, F, max_unfold_steps=3)
    if how == "copy":
        c = copy.copy(m)
    elif how == "deepcopy":
        c = copy.deepcopy(m)
    else:
        c = pickle.loads(pickle.dumps(m, protocol=pickle.HIGHEST_PROTOCOL))
    assert type(c) is meshfmm.Mesh
    assert c is not m and c._ptr != m._ptr
    np.testing.assert_array_equal(c.vertices, m.vertices)
    np.testing.assert_array_equal(c.faces, m.faces)
    assert c.vertices.dtype == np.float64 and c.faces.dtype == np.int32
    assert c.info == m.info
    assert c._max_unfold_steps == 3
    for s in (0, 11, [2, 30]):
        np.testing.assert_array_equal(c.distance(s), m.distance(s))
    c.close()
    assert m.distance(0)[0] == 0.0
    m.close()


def test_copy_of_a_closed_mesh_is_refused():
    m = meshfmm.Mesh(*grid(2))
    m.close()
    for f in (copy.copy, copy.deepcopy, pickle.dumps):
        with pytest.raises(ValueError, match="closed"):
            f(m)


def test_pickled_mesh_in_a_container_and_deepcopy_memo():
    m = meshfmm.Mesh(*grid(3))
    a, b = copy.deepcopy([m, m])
    assert a is b  # the memo keeps shared references shared
    a.close()
    assert m.distance(0)[0] == 0.0


# -------------------------------------------- reserving the memmap's space
def test_open_memmap_writes_a_valid_npy(tmp_path):
    m = meshfmm.Mesh(*grid(5))
    n = m.n_vertices
    path = tmp_path / "all.npy.partial"
    D = meshfmm.open_memmap(path, (n, n), "float32")
    assert isinstance(D, np.memmap) and D.shape == (n, n) and D.dtype == np.float32
    assert os.stat(path).st_blocks * 512 >= D.nbytes  # blocks taken, not a sparse file
    m.distance_matrix(out=D, backend="serial")
    D.flush()
    del D
    os.replace(path, tmp_path / "all.npy")
    back = np.load(tmp_path / "all.npy")
    np.testing.assert_array_equal(back, m.distance_matrix(backend="serial"))
    E = meshfmm.open_memmap(tmp_path / "e.npy", (3, 4), np.float64)
    assert E.shape == (3, 4) and E.dtype == np.float64 and not E.any()


class _Usage:
    def __init__(self, free):
        self.total, self.used, self.free = 10 * free + 1, 9 * free + 1, free


def test_open_memmap_compares_the_size_with_the_free_space(tmp_path, monkeypatch):
    """open_memmap asks shutil.disk_usage about the file's folder before
    touching the file: a file larger than the free space is refused with
    both numbers (header included) and nothing written; one that fits, a
    file it replaces (its blocks count as free) and size_check=False go
    ahead."""
    asked = []

    def usage(free):
        def disk_usage(path):
            asked.append(os.fspath(path))
            return _Usage(free)
        return disk_usage

    path = tmp_path / "m.npy"
    need = 100 * 200 * 8 + 128                       # float64 (100, 200) and its header
    monkeypatch.setattr(shutil, "disk_usage", usage(need - 1))
    with pytest.raises(OSError) as info:
        meshfmm.open_memmap(path, (100, 200), np.float64)
    assert info.value.errno == errno.ENOSPC and info.value.filename == str(path)
    assert "160 kB (160128 bytes)" in str(info.value)
    assert "160 kB (160127 bytes) free" in str(info.value)
    assert asked == [str(tmp_path)] and not path.exists()
    D = meshfmm.open_memmap(path, (100, 200), np.float64, size_check=False)
    assert D.shape == (100, 200) and os.path.getsize(path) == need
    del D
    # the file it replaces frees its blocks: the same size fits again
    monkeypatch.setattr(shutil, "disk_usage", usage(1000))
    D = meshfmm.open_memmap(path, (100, 200), np.float64)
    del D
    os.remove(path)
    with pytest.raises(OSError, match="160 kB"):
        meshfmm.open_memmap(path, (100, 200), np.float64)
    monkeypatch.setattr(shutil, "disk_usage", usage(need))
    D = meshfmm.open_memmap(path, (100, 200), np.float64)
    assert D.shape == (100, 200) and not D.any()
    del D
    with pytest.raises(TypeError, match="size_check"):
        meshfmm.open_memmap(path, (1, 1), size_check="no")


def _tmpfs(size: str):
    """A fresh tmpfs of `size`, or a skip saying why there is none."""
    if not hasattr(os, "geteuid") or os.geteuid() != 0:
        pytest.skip("mounting a small tmpfs needs root (the test runs as an ordinary user)")
    if shutil.which("mount") is None:
        pytest.skip("no mount command")
    where = tempfile.mkdtemp(prefix="meshfmm-tmpfs-")
    proc = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", where],
                          capture_output=True, text=True)
    if proc.returncode != 0:
        os.rmdir(where)
        pytest.skip(f"cannot mount a tmpfs here (a container without CAP_SYS_ADMIN?): "
                    f"{proc.stderr.strip()}")
    return where


@pytest.fixture
def small_tmpfs():
    where = _tmpfs("1m")
    try:
        yield Path(where)
    finally:
        subprocess.run(["umount", where], check=False)
        os.rmdir(where)


def test_open_memmap_full_disk_raises_enospc_up_front(small_tmpfs):
    """On a 1 MiB file system a 2 MiB matrix: refused with both sizes before
    the file is made; with size_check=False, OSError(ENOSPC) when its blocks
    are reserved, at once and no file left behind (numpy's open_memmap makes
    a sparse file there, and the process dies of SIGBUS half-way through the
    rows)."""
    path = small_tmpfs / "big.npy"
    with pytest.raises(OSError) as info:
        meshfmm.open_memmap(path, (724, 724), "float32")
    free = shutil.disk_usage(small_tmpfs).free
    assert info.value.errno == errno.ENOSPC and info.value.filename == str(path)
    assert f"({724 * 724 * 4 + 128} bytes)" in str(info.value)
    assert f"({free} bytes) free" in str(info.value) and "size_check=False" in str(info.value)
    assert not path.exists()
    with pytest.raises(OSError) as info:
        meshfmm.open_memmap(path, (724, 724), "float32", size_check=False)
    assert info.value.errno == errno.ENOSPC
    assert "cannot reserve" in str(info.value) and str(path) in str(info.value)
    assert not path.exists()
    # what fits still works, and the space is really taken
    m = meshfmm.Mesh(*grid(15))
    n = m.n_vertices  # 256: 256 KiB
    D = meshfmm.open_memmap(small_tmpfs / "ok.npy", (n, n), "float32")
    m.distance_matrix(out=D, backend="serial")
    np.testing.assert_array_equal(D[7], m.distance(7).astype(np.float32))
    st = os.statvfs(small_tmpfs)
    assert (st.f_blocks - st.f_bfree) * st.f_frsize >= D.nbytes
    del D


def test_numpy_open_memmap_dies_of_sigbus_on_a_full_disk(small_tmpfs):
    """The defect itself (the README's old pattern): a sparse memmap on a
    full disk kills the process with SIGBUS while writing rows."""
    code = f"""
    import numpy as np, meshfmm
    from test_api import grid
    m = meshfmm.Mesh(*grid(40))
    n = m.n_vertices
    D = np.lib.format.open_memmap({str(small_tmpfs / "big.npy")!r}, mode="w+",
                                  dtype=np.float32, shape=(n, n))
    m.distance_matrix(out=D, backend="serial")
    print("finished")
    """
    proc = run_isolated(code)
    assert "finished" not in proc.stdout
    # (a library built with AddressSanitizer reports the SIGBUS and exits)
    assert proc.returncode == -signal.SIGBUS or "AddressSanitizer: BUS" in proc.stderr, \
        (proc.returncode, proc.stderr[-2000:])


# ----------------------------------------------------------------- Ctrl-C
CTRL_C = """
import sys, time, numpy as np, meshfmm
from test_api import grid
m = meshfmm.Mesh(*grid(70))
started = []
def progress(done, n):
    if not started:
        started.append(1)
        print("started", flush=True)
    time.sleep(0.01)
kw = dict(progress=progress) if {with_progress} else {{}}
if not {with_progress}:
    print("started", flush=True)
m.distance_matrix(backend={backend!r}, n_threads=2, memory_limit=1 << 16, **kw)
print("finished", flush=True)
"""


@pytest.mark.parametrize("with_progress", [True, False], ids=["progress", "no-progress"])
@pytest.mark.parametrize("backend", ["serial", "threads"])
def test_sigint_gives_one_keyboard_interrupt(backend, with_progress):
    """SIGINT from outside while distance_matrix runs: the process stops with
    one KeyboardInterrupt traceback and no "Exception ignored on calling
    ctypes callback function" (which an exception escaping the callback
    prints once per Ctrl-C while the job goes on)."""
    code = textwrap.dedent(CTRL_C.format(backend=backend, with_progress=with_progress))
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=str(HERE))
    try:
        line = proc.stdout.readline()
        assert line.strip() == "started", (line, proc.stderr.read()[-2000:])
        import time

        time.sleep(0.3)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert "finished" not in out, "Ctrl-C did not stop the job"
    assert "Exception ignored" not in err, err[-3000:]
    lines = err.rstrip().splitlines()
    assert err.count("Traceback (most recent call last)") == 1, err[-3000:]
    assert sum(ln.startswith("KeyboardInterrupt") for ln in lines) == 1, err[-3000:]
    assert lines[-1] == "KeyboardInterrupt", err[-3000:]
    assert proc.returncode != 0
