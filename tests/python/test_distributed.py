"""meshfmm.distributed: all-pairs rows as Dask tasks writing a Zarr v3 array,
on real clusters started here (a LocalCluster of 2 worker processes, and a
scheduler and two workers started as separate processes on 127.0.0.1).
Every result is compared with the serial rows (float64 bit for bit)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

pytest.importorskip("distributed")
zarr = pytest.importorskip("zarr")

import meshfmm  # noqa: E402
import meshfmm.distributed as md  # noqa: E402
import meshfmm._zarr_store as zs  # noqa: E402
import meshfmm._zarr_tasks as zt  # noqa: E402
from meshfmm._zarr_cli import cli_allpairs_zarr  # noqa: E402
from conftest import MESHES  # noqa: E402

SOURCES = np.arange(0, 810, 7, dtype=np.int32)  # 116 rows of hand_lowres


@pytest.fixture(scope="module")
def hand():
    return meshfmm.Mesh(*meshfmm.load_mesh(MESHES / "hand_lowres.obj"))


@pytest.fixture(scope="module")
def serial64(hand):
    return hand.distance_matrix(SOURCES, backend="serial", dtype="float64")


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=":0")
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


def test_rows_equal_serial_float64_and_float32(hand, serial64, client, tmp_path):
    Z = md.distance_matrix(hand, str(tmp_path / "d64.zarr"), sources=SOURCES, client=client,
                           dtype="float64", block_rows=16, progress=False)
    assert Z.shape == (len(SOURCES), hand.n_vertices) and Z.dtype == np.float64
    assert np.array_equal(Z[:], serial64)
    for i in (0, 57, 115):  # and each row is Mesh.distance's
        assert np.array_equal(Z[i], hand.distance(int(SOURCES[i])))
    Z32 = md.distance_matrix(hand, str(tmp_path / "d32.zarr"), sources=SOURCES, client=client,
                             dtype="float32", block_rows=16, progress=False)
    assert np.array_equal(Z32[:], serial64.astype(np.float32))
    run = Z32.attrs[md.RUN_ATTR]
    assert run["blocks"] == 8 and run["blocks_computed"] == 8
    # each block's MatrixInfo, summed: the default backend on every block
    assert run["backends"] == {"threads": 8}
    assert run["vertices_settled"] == len(SOURCES) * hand.n_vertices
    assert run["start_fallbacks"] == 0


def test_targets_give_the_columns_of_full_rows(hand, serial64, client, tmp_path):
    targets = np.array([809, 3, 400, 3, 12], dtype=np.int32)
    Z = md.distance_matrix(hand, str(tmp_path / "st.zarr"), sources=SOURCES, targets=targets,
                           client=client, dtype="float64", block_rows=32, progress=False)
    assert Z.shape == (len(SOURCES), len(targets))
    assert np.array_equal(Z[:], serial64[:, targets])


class _Stop(Exception):
    pass


def test_interrupt_then_resume_computes_only_the_rest(hand, serial64, client, tmp_path):
    store = str(tmp_path / "r.zarr")
    calls = []

    def stop_after_3(done, total):
        calls.append(done)
        if len(calls) == 3:
            raise _Stop()

    with pytest.raises(_Stop):
        md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           block_rows=8, progress=stop_after_3)
    time.sleep(1.0)  # blocks in flight may still land: they are complete or absent
    Z = zarr.open_array(store, mode="r")
    n_blocks = 15
    complete = md.complete_blocks(Z, 8)
    # blocks in flight when it stopped may have landed (tiny blocks: maybe all)
    assert 3 <= len(complete) <= n_blocks
    Z = md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           progress=False)
    run = Z.attrs[md.RUN_ATTR]
    assert run["blocks_skipped"] == len(complete)
    assert run["blocks_computed"] == n_blocks - len(complete)
    assert np.array_equal(Z[:], serial64)
    # blocks never written (a job stopped before them): exactly those are computed
    for b in (4, 9, 10):
        os.remove(os.path.join(store, "c", str(b), "0"))
    assert sorted(set(range(n_blocks)) - set(md.complete_blocks(Z, 8))) == [4, 9, 10]
    Z = md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           progress=False)
    assert Z.attrs[md.RUN_ATTR]["blocks_computed"] == 3
    assert np.array_equal(Z[:], serial64)
    # a torn chunk (its checksum no longer matches) is recomputed, not trusted
    chunk = os.path.join(store, "c", "2", "0")
    data = open(chunk, "rb").read()
    open(chunk, "wb").write(data[:-5])
    Z = md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           progress=False)
    assert Z.attrs[md.RUN_ATTR]["blocks_computed"] == 1
    assert np.array_equal(Z[:], serial64)
    # another job on the same store is refused with a message
    with pytest.raises(ValueError, match="different job"):
        md.distance_matrix(hand, store, sources=SOURCES[:-1], client=client, progress=False)
    with pytest.raises(ValueError, match="different job"):
        md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float32",
                           progress=False)


def test_a_killed_worker_is_replaced_and_the_result_equals_serial(hand, serial64, tmp_path):
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as c:
        pids = list(c.run(os.getpid).values())
        killed = []

        def kill_one(done, total):
            if not killed:
                os.kill(pids[0], signal.SIGKILL)
                killed.append(pids[0])

        Z = md.distance_matrix(hand, str(tmp_path / "k.zarr"), sources=SOURCES, client=c,
                               dtype="float64", block_rows=4, progress=kill_one)
        assert killed
        assert np.array_equal(Z[:], serial64)


def _wait_for(path, seconds=60.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < seconds:
        if os.path.exists(path) and os.path.getsize(path) > 0:
            try:
                return json.load(open(path))
            except ValueError:
                pass
        time.sleep(0.2)
    raise TimeoutError(f"{path} did not appear")


def test_separate_scheduler_and_worker_processes(hand, serial64, tmp_path):
    from distributed import Client

    sched_file = str(tmp_path / "scheduler.json")
    dask = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
    worker = [sys.executable, "-m", "distributed.cli.dask_worker"]
    procs = [subprocess.Popen(dask + ["--host", "127.0.0.1", "--port", "0",
                                      "--dashboard-address", ":0",
                                      "--scheduler-file", sched_file],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        _wait_for(sched_file)
        for _ in range(2):
            procs.append(subprocess.Popen(worker + ["--scheduler-file", sched_file,
                                                    "--host", "127.0.0.1", "--nthreads", "1",
                                                    "--no-dashboard"],
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        with Client(scheduler_file=sched_file, timeout=60) as c:
            c.wait_for_workers(2, timeout=60)
            Z = md.distance_matrix(hand, str(tmp_path / "sep.zarr"), sources=SOURCES,
                                   client=c, dtype="float64", block_rows=16, progress=False)
            assert np.array_equal(Z[:], serial64)
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()


def test_symmetrize_matches_numpy(hand, tmp_path):
    store = str(tmp_path / "sq.zarr")
    sq = np.arange(0, 810, 20, dtype=np.int32)
    V, F = hand.vertices, hand.faces
    sub = meshfmm.Mesh(V, F)
    Z = md.distance_matrix(sub, store, sources=sq, targets=sq, n_workers=1, dtype="float64",
                           progress=False)
    S = md.symmetrize(store, str(tmp_path / "sym.zarr"))
    D = Z[:]
    assert np.allclose(S[:], (D + D.T) / 2, rtol=0, atol=0)


def test_symmetrize_never_deletes_what_it_did_not_write(hand, tmp_path):
    """symmetrize refuses its own input (or a directory around or inside it)
    as output, and a non-empty output unless overwrite=True, which replaces
    only the Zarr entries."""
    proj = tmp_path / "proj"
    proj.mkdir()
    store = str(proj / "sq.zarr")
    sq = np.arange(0, 810, 40, dtype=np.int32)
    Z = md.distance_matrix(hand, store, sources=sq, targets=sq, n_workers=1, dtype="float64",
                           progress=False)
    D = Z[:]
    for bad in (store, str(proj), str(proj / "sq.zarr" / "inner.zarr")):
        with pytest.raises(md.StoreError):
            md.symmetrize(store, bad)
    assert np.array_equal(zarr.open_array(store, mode="r")[:], D)
    out = tmp_path / "notes"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(md.StoreError, match="not empty"):
        md.symmetrize(store, str(out))
    for _ in range(2):  # onto a foreign directory, then over its own output
        S = md.symmetrize(store, str(out), overwrite=True)
        assert np.array_equal(S[:], (D + D.T) / 2)
        assert (out / "notes.txt").read_text() == "mine"
    with pytest.raises(md.StoreError, match="not empty"):
        md.symmetrize(store, str(out))


def test_bad_arguments_are_refused(hand, tmp_path):
    with pytest.raises(ValueError, match="targets"):
        md.distance_matrix(hand, str(tmp_path / "x.zarr"), targets=[10**6], n_workers=1)
    with pytest.raises(TypeError, match="max_distance"):
        md.distance_matrix(hand, str(tmp_path / "x.zarr"), max_distance="2.5", n_workers=1)
    with pytest.raises(ValueError, match="max_distance"):
        md.distance_matrix(hand, str(tmp_path / "x.zarr"), max_distance=-1.0, n_workers=1)
    with pytest.raises(TypeError, match="store"):
        md.distance_matrix(hand, 3, n_workers=1)
    with pytest.raises(TypeError, match="max_distance"):
        md.distance_matrix(hand, str(tmp_path / "x.zarr"), max_distance=True, n_workers=1)
    with pytest.raises(TypeError, match="unfolding"):
        md.distance_matrix(hand, str(tmp_path / "x.zarr"), unfolding="no", n_workers=1)
    assert not (tmp_path / "x.zarr").exists()


def test_a_bad_cost_is_refused_before_the_store_is_touched(hand, serial64, client, tmp_path):
    """resume=False overwrites the store; a bad cost (seen before only by the
    workers, after every task had failed and been retried) must not first
    replace a finished job."""
    out = str(tmp_path / "kept.zarr")
    md.distance_matrix(hand, out, sources=SOURCES[:8], client=client, dtype="float64",
                       backend="serial", progress=False)
    bad = np.ones(hand.n_vertices)
    bad[17] = -1.0
    for cost, words in ((bad, "17"), (np.ones(5), "5 entries")):
        with pytest.raises(ValueError, match=words):
            md.distance_matrix(hand, out, sources=SOURCES[:8], client=client, resume=False,
                               cost=cost, progress=False)
    assert np.array_equal(zarr.open_array(out, mode="r")[:], serial64[:8])


def test_command_line(tmp_path):
    out = str(tmp_path / "cli.zarr")
    src = tmp_path / "s.txt"
    src.write_text("0\n5\n9\n")
    code = ("import sys; from meshfmm._zarr_cli import cli_allpairs_zarr;"
            "sys.exit(cli_allpairs_zarr(sys.argv[1:]))")
    r = subprocess.run([sys.executable, "-c", code, str(MESHES / "hand_lowres.obj"), "-o", out,
                        "--workers", "1", "--sources", str(src), "--dtype", "float64"],
                       capture_output=True, text=True, timeout=180)
    assert r.returncode == 0, r.stderr
    assert "3 x 810" in r.stderr
    mesh = meshfmm.Mesh(*meshfmm.load_mesh(MESHES / "hand_lowres.obj"))
    assert np.array_equal(zarr.open_array(out, mode="r")[:],
                          mesh.distance_matrix([0, 5, 9], backend="serial", dtype="float64"))


@pytest.mark.parametrize("twice", [["-o", "b.zarr"], ["--dtype", "float32"], ["--workers", "2"]])
def test_command_line_refuses_a_value_option_twice(tmp_path, twice):
    # argparse let the last one win silently; the C command line refuses it
    with pytest.raises(SystemExit) as e:
        cli_allpairs_zarr([str(MESHES / "hand_lowres.obj"), "-o", str(tmp_path / "a.zarr"),
                              "--workers", "1", "--dtype", "float64", *twice])
    assert e.value.code == 2
    assert not (tmp_path / "a.zarr").exists() and not (tmp_path / "b.zarr").exists()


def test_progress_rate_counts_only_rows_computed_now(hand, client, tmp_path, capsys):
    # a resumed job's skipped rows are not work done in this run: before, they
    # entered the rate (a resumed job showed ~1e8 rows/s and 0 s left)
    store = str(tmp_path / "p.zarr")
    md.distance_matrix(hand, store, sources=SOURCES, client=client, block_rows=8,
                       progress=False)
    Z = zarr.open_array(store, mode="r+")
    for b in range(8, 15):  # the second half is to be computed again
        os.remove(os.path.join(store, "c", str(b), "0"))
    capsys.readouterr()
    md.distance_matrix(hand, store, sources=SOURCES, client=client, progress=True)
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if "rows/s" in ln]
    assert lines, err
    assert lines[0].startswith("64/116 rows") and "rows/s" in lines[0], lines
    rates = [float(ln.split(", ")[1].split()[0]) for ln in lines if "? rows/s" not in ln]
    assert rates and max(rates) < 1e5, lines  # hand rows: ~1e3-1e4 rows/s on 2 cores
    assert lines[-1].startswith("116/116 rows (100.0 %)")
    assert Z.shape == (116, 810)


def test_progress_formats_time_left():
    import io

    s = io.StringIO()
    p = md._Progress(1000, stream=s, done=100)
    p.t0 -= 10.0  # 10 s for 100 rows: 10 rows/s, 800 rows left
    p(100)
    assert s.getvalue().splitlines()[-1] == "200/1000 rows (20.0 %), 10.0 rows/s, 1 min 20 s left"
    assert md._fmt_seconds(3 * 3600 + 61) == "3 h 01 min"


def test_each_task_gets_its_hosts_share_of_cores(monkeypatch):
    # a LocalCluster of one 1-thread process per core: 1 library thread each
    # (all cores per task would oversubscribe 2 cores 2 x)
    class W:
        address = "tcp://10.0.0.7:4242"

        class state:
            nthreads = 1

    import distributed

    monkeypatch.setattr(distributed, "get_worker", lambda: W)
    monkeypatch.setattr(zt, "_cores", lambda: 16)
    assert zt._task_threads(0, {"10.0.0.7": 16}) == 1
    assert zt._task_threads(0, {"10.0.0.7": 4}) == 4
    assert zt._task_threads(0, {"10.0.0.7": 1}) == 16
    assert zt._task_threads(0, {}) == 16  # a host the job did not see: the worker's own threads
    assert zt._task_threads(3, {"10.0.0.7": 16}) == 3  # asked for: as given
    # outside a worker the library's own default (0: all cores)
    monkeypatch.setattr(distributed, "get_worker", lambda: (_ for _ in ()).throw(ValueError()))
    assert zt._task_threads(0, {}) == 0


def test_default_blocks_are_equal_multiples_of_the_threads():
    # camelhead float32 on 2 threads: 8 MiB chunks -> 62 blocks, 31 per thread
    b = md._default_block_rows(11381, 11381 * 4, 2)
    assert b == 184 and -(-11381 // b) == 62
    # a small job: at least 4 blocks per thread
    assert -(-116 // md._default_block_rows(116, 810 * 8, 2)) == 8
    assert md._default_block_rows(3, 810 * 8, 16) == 1


def test_compression_choices(hand, serial64, client, tmp_path):
    sizes = {}
    for c in ("lz4", "zstd", "none"):
        store = tmp_path / f"{c}.zarr"
        Z = md.distance_matrix(hand, str(store), sources=SOURCES, client=client,
                               dtype="float64", compression=c, progress=False)
        assert np.array_equal(Z[:], serial64)
        run = Z.attrs[md.RUN_ATTR]
        assert run["task_compute_seconds"] > 0 and run["task_write_seconds"] > 0
        sizes[c] = sum(f.stat().st_size for f in (store / "c").rglob("*") if f.is_file())
        names = [x.get("name") for x in json.loads((store / "zarr.json").read_text())["codecs"]]
        assert names[-1] == "crc32c"
    assert sizes["zstd"] < sizes["none"] and sizes["lz4"] < sizes["none"]
    with pytest.raises(ValueError, match="compression"):
        md.distance_matrix(hand, str(tmp_path / "x.zarr"), client=client, compression="gzip")


def test_resume_check_on_the_cluster_equals_the_local_check(hand, client, tmp_path):
    store = str(tmp_path / "v.zarr")
    Z = md.distance_matrix(hand, store, sources=SOURCES, client=client, block_rows=8,
                           progress=False)
    os.remove(os.path.join(store, "c", "3", "0"))  # never written
    chunk = os.path.join(store, "c", "11", "0")  # torn
    data = open(chunk, "rb").read()
    open(chunk, "wb").write(data[:-3])
    local = md.complete_blocks(Z, 8)
    assert local == [b for b in range(15) if b not in (3, 11)]
    assert md._complete_blocks_on(client, store, None, 116, 8, 2) == local
    assert md._complete_blocks_on(client, store, None, 116, 8, 64) == local  # a task per block


def test_own_local_cluster_runs_with_the_quiet_dask_settings(hand, serial64, tmp_path,
                                                             monkeypatch):
    # Dask's 10-500 ms pollers cost 5-9 % of a 2-core LocalCluster's CPU: the
    # cluster distance_matrix starts for the user runs with DASK_CONFIG
    import dask
    import distributed

    seen = {}
    real = distributed.LocalCluster

    def spy(*args, **kw):
        seen.update({k: dask.config.get(k) for k in md.DASK_CONFIG})
        return real(*args, **kw)

    monkeypatch.setattr(distributed, "LocalCluster", spy)
    Z = md.distance_matrix(hand, str(tmp_path / "q.zarr"), sources=SOURCES, client=None,
                           n_workers=2, dtype="float64", progress=False)
    assert np.array_equal(Z[:], serial64)
    assert seen == md.DASK_CONFIG
    # and the settings do not leak into the caller's configuration
    assert dask.config.get("distributed.admin.tick.interval") != "1s"


def test_a_fresh_store_is_not_verified_and_a_resumed_one_is(hand, client, tmp_path,
                                                            monkeypatch):
    # verifying reads every chunk: worth it on resume, waste on a store just created
    calls = []
    real = md._complete_blocks_on

    def spy(*args):
        calls.append(args)
        return real(*args)

    monkeypatch.setattr(md, "_complete_blocks_on", spy)
    store = str(tmp_path / "f.zarr")
    md.distance_matrix(hand, store, sources=SOURCES, client=client, progress=False)
    assert calls == []
    Z = md.distance_matrix(hand, store, sources=SOURCES, client=client, progress=False)
    assert len(calls) == 1 and Z.attrs[md.RUN_ATTR]["blocks_computed"] == 0


def test_settings_do_not_leak_when_the_cluster_fails_to_start(hand, tmp_path, monkeypatch):
    import dask
    import distributed

    before = dask.config.get("distributed.admin.tick.interval")

    def broken(*args, **kw):
        raise RuntimeError("no cluster today")

    monkeypatch.setattr(distributed, "LocalCluster", broken)
    with pytest.raises(RuntimeError, match="no cluster"):
        md.distance_matrix(hand, str(tmp_path / "n.zarr"), client=None, progress=False)
    assert dask.config.get("distributed.admin.tick.interval") == before


def test_back_to_back_jobs_on_one_mesh_and_client(hand, serial64, client, tmp_path):
    # each job scatters V and F; scattered by content hash, the second job got
    # the keys the first job's futures were releasing and lost them ("lost
    # dependencies": a failed or hung job)
    for k in range(8):
        Z = md.distance_matrix(hand, str(tmp_path / f"b{k}.zarr"), sources=SOURCES[:24],
                               client=client, dtype="float64", block_rows=4, progress=False)
        assert np.array_equal(Z[:], serial64[:24])


def test_exact_start_is_passed_through_and_part_of_the_job(hand, client, tmp_path):
    """The option reaches the tasks (the rows equal the plain
    start's serial rows), and the job records the radius, so a store
    computed with one start is not resumed with another."""
    src = SOURCES[:20]
    store = str(tmp_path / "plain.zarr")
    plain = hand.distance_matrix(src, backend="serial", dtype="float64", exact_start=False)
    assert not np.array_equal(plain, hand.distance_matrix(src, backend="serial", dtype="float64"))
    Z = md.distance_matrix(hand, store, sources=src, client=client, dtype="float64",
                           block_rows=8, progress=False, exact_start=False)
    assert np.array_equal(Z[:], plain)
    assert Z.attrs[md.JOB_ATTR]["exact_start_radius"] == 0.0
    with pytest.raises(ValueError, match="exact_start_radius"):
        md.distance_matrix(hand, store, sources=src, client=client, dtype="float64",
                           progress=False)
    Z = md.distance_matrix(hand, str(tmp_path / "r3.zarr"), sources=src, client=client,
                           dtype="float64", block_rows=8, progress=False, exact_start=3.5)
    assert np.array_equal(Z[:], hand.distance_matrix(src, backend="serial", dtype="float64",
                                                      exact_start=3.5))
    # the default is recorded as the library's rule, and a radius is checked
    job = md.job_description(hand, src, None, "float64", None, None, None, True)
    assert job["exact_start_radius"] == "auto"
    with pytest.raises(ValueError):
        md.distance_matrix(hand, str(tmp_path / "bad.zarr"), sources=src, client=client,
                           progress=False, exact_start=-1.0)


def test_method_is_passed_through_and_part_of_the_job(hand, client, tmp_path):
    """method="windows" reaches the tasks (the rows equal the serial
    windows rows), and the job records it, so that a store of one method is
    not resumed with the other (never a mix of rows); the march's jobs
    record None, as stores written before the option."""
    src = SOURCES[:20]
    want = hand.distance_matrix(src, backend="serial", dtype="float64", method="windows")
    store = str(tmp_path / "windows.zarr")
    Z = md.distance_matrix(hand, store, sources=src, client=client, dtype="float64",
                           block_rows=8, progress=False, method="windows")
    assert np.array_equal(Z[:], want)
    assert Z.attrs[md.JOB_ATTR]["method"] == "windows"
    with pytest.raises(md.StoreError, match="differs in: method"):
        md.distance_matrix(hand, store, sources=src, client=client, dtype="float64",
                           progress=False)
    Z = md.distance_matrix(hand, store, sources=src, client=client, dtype="float64",
                           progress=False, method="windows")  # the same job: resumed
    assert Z.attrs[md.RUN_ATTR]["blocks_computed"] == 0
    march = str(tmp_path / "march.zarr")
    Z = md.distance_matrix(hand, march, sources=src, client=client, dtype="float64",
                           block_rows=8, progress=False)
    assert Z.attrs[md.JOB_ATTR]["method"] is None
    with pytest.raises(md.StoreError, match="differs in: method"):
        md.distance_matrix(hand, march, sources=src, client=client, dtype="float64",
                           progress=False, method="windows")
    # a store that records no method is the march's: its blocks still verify
    job = md.job_description(hand, src, None, "float64", None, None, None, True)
    old = {k: v for k, v in job.items() if k != "method"}
    assert zs.same_job(old, job) == [] and zs.job_key(old) == zs.job_key(job)
    # refused before the store is touched
    bad = str(tmp_path / "bad.zarr")
    with pytest.raises(ValueError, match="not a method of"):
        md.distance_matrix(hand, bad, sources=src, client=client, progress=False,
                           method="exact")
    assert not os.path.exists(bad)


def test_command_line_method(hand, client, tmp_path, capsys):
    """--method windows on the Zarr command line: the windows rows; a
    resume with the other method is refused with one line and status 2."""
    src = tmp_path / "src.txt"
    src.write_text("0 5 9\n")
    store = str(tmp_path / "w.zarr")
    args = [str(MESHES / "hand_lowres.obj"), "-o", store, "--scheduler",
            client.scheduler.address, "--sources", str(src), "--dtype", "float64",
            "--no-progress"]
    assert cli_allpairs_zarr(args + ["--method", "windows"]) == 0
    assert np.array_equal(zarr.open_array(store, mode="r")[:],
                          hand.distance_matrix([0, 5, 9], backend="serial", dtype="float64",
                                               method="windows"))
    capsys.readouterr()
    assert cli_allpairs_zarr(args + ["--resume"]) == 2
    err = capsys.readouterr().err
    assert "differs in: method" in err and len(err.strip().splitlines()) == 1
    cost = tmp_path / "cost.txt"
    cost.write_text("1\n" * hand.n_vertices)
    store2 = str(tmp_path / "wc.zarr")
    args2 = [a if a != store else store2 for a in args]
    assert cli_allpairs_zarr(args2 + ["--method", "windows", "--cost", str(cost)]) == 0
    assert np.array_equal(zarr.open_array(store2, mode="r")[:],
                          hand.distance_matrix([0, 5, 9], backend="serial", dtype="float64",
                                               method="windows",
                                               cost=np.ones(hand.n_vertices)))


def test_mesh_options_reach_the_workers_and_the_job(hand, client, tmp_path):
    """The workers build the caller's mesh, options included: one unfolding
    step changes the rows of hand_lowres (an obtuse corner keeps its plain
    stencil), and the job records it, so that a store is not resumed with
    another mesh. spokes=False gives the same rows."""
    V, F = hand.vertices, hand.faces
    short = meshfmm.Mesh(V, F, max_unfold_steps=1)
    src = SOURCES[:24]
    ref = short.distance_matrix(src, backend="serial", dtype="float64")
    assert not np.array_equal(ref, hand.distance_matrix(src, backend="serial", dtype="float64"))
    store = str(tmp_path / "short.zarr")
    Z = md.distance_matrix(short, store, sources=src, client=client, dtype="float64",
                           block_rows=8, progress=False)
    assert np.array_equal(Z[:], ref)
    assert Z.attrs[md.JOB_ATTR]["max_unfold_steps"] == 1
    with pytest.raises(ValueError, match="max_unfold_steps"):
        md.distance_matrix(hand, store, sources=src, client=client, dtype="float64",
                           progress=False)
    lean = meshfmm.Mesh(V, F, spokes=False)
    Z = md.distance_matrix(lean, str(tmp_path / "lean.zarr"), sources=src, client=client,
                           dtype="float64", block_rows=8, progress=False)
    assert np.array_equal(Z[:], hand.distance_matrix(src, backend="serial", dtype="float64"))


# ------------------------------------------------ one owner per store, bound chunks

# the store's layout: the owner record in the attributes, the block digests
# beside the chunk tree
OWNER, SUMS = "meshfmm_owner", "meshfmm_blocks"


def _owner(store):
    return zarr.open_array(store, mode="r").attrs[OWNER]


def _set_owner(store, **changes):
    z = zarr.open_array(store, mode="r+")
    z.attrs[OWNER] = dict(z.attrs.get(OWNER) or {}, **changes)


def test_a_second_job_on_a_store_a_live_job_owns_is_refused(hand, serial64, client, tmp_path):
    # two jobs on one store both exited 0, the store labelled with one job and
    # holding rows of both; now the second is refused while the first runs
    store = str(tmp_path / "own.zarr")
    other = meshfmm.Mesh(hand.vertices * 1.5, hand.faces)
    refused = []

    def start_b(done, total):
        if not refused:
            with pytest.raises(RuntimeError, match="in use by another meshfmm job") as e:
                md.distance_matrix(other, store, sources=SOURCES, client=client,
                                   dtype="float64", resume=False, block_rows=8, progress=False)
            refused.append(e.value)

    Z = md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           block_rows=8, progress=start_b)
    assert refused and isinstance(refused[0], md.StoreOwnerError)
    assert np.array_equal(Z[:], serial64)
    assert Z.attrs[md.JOB_ATTR]["mesh_sha256"] == md.job_description(
        hand, SOURCES, None, "float64", None, None, None, True)["mesh_sha256"]
    assert _owner(store)["state"] == "finished"
    Z = md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           progress=False)
    assert Z.attrs[md.RUN_ATTR]["blocks_computed"] == 0


def test_a_run_whose_store_is_taken_over_writes_nothing_more(hand, serial64, client, tmp_path):
    store = str(tmp_path / "taken.zarr")
    Z = md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           block_rows=8, progress=False)
    # a task checks the owner token before it writes: with another run's
    # token in the store it refuses and leaves the chunk alone
    os.remove(os.path.join(store, "c", "2", "0"))
    V, F = hand.vertices, hand.faces
    with pytest.raises(RuntimeError, match="taken over") as e:
        zt.compute_block("k", V, F, store, None, 16, 24, SOURCES, None,
                          {"backend": "serial", "dtype": "float64", "n_threads": 1,
                           "max_distance": None, "unfolding": True, "cost": None,
                           "cost_location": None}, 2, "not-the-owner", "job")
    assert isinstance(e.value, md.StoreOwnerError)
    assert not os.path.exists(os.path.join(store, "c", "2", "0"))

    # another run (on another host) takes the store over while this one runs:
    # this one fails and leaves the other's record in place
    def take_over(done, total):
        if _owner(store)["token"] != "elsewhere":
            _set_owner(store, token="elsewhere", host="another-host", pid=1,
                       state="running", heartbeat=time.time())

    with pytest.raises(md.StoreOwnerError, match="taken over"):
        md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           resume=False, block_rows=8, progress=take_over)
    assert _owner(store)["token"] == "elsewhere"
    # that run is alive (a heartbeat within the lease): the store is refused
    with pytest.raises(md.StoreOwnerError, match="in use"):
        md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           progress=False)
    # its heartbeat stopped over a minute ago: a killed run, taken over
    _set_owner(store, heartbeat=time.time() - 2 * zs._LEASE_S)
    Z = md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           progress=False)
    assert np.array_equal(Z[:], serial64)
    assert _owner(store)["state"] == "finished"


def test_the_owner_heartbeat_advances_while_a_job_runs(hand, client, tmp_path, monkeypatch):
    # a run on another host is taken for dead after _LEASE_S without a
    # heartbeat: a live one beats every _HEARTBEAT_S (shortened here)
    monkeypatch.setattr(zs, "_HEARTBEAT_S", 0.05)
    store = str(tmp_path / "hb.zarr")
    beats = []

    def watch(done, total):
        if not beats:
            t0 = _owner(store)["heartbeat"]
            deadline = time.monotonic() + 5
            while _owner(store)["heartbeat"] == t0 and time.monotonic() < deadline:
                time.sleep(0.02)
            beats.append(_owner(store)["heartbeat"] - t0)

    md.distance_matrix(hand, store, sources=SOURCES[:24], client=client, block_rows=8,
                       progress=watch)
    assert beats and beats[0] > 0
    assert _owner(store)["state"] == "finished"


def test_a_killed_jobs_token_does_not_block_its_resume(hand, serial64, client, tmp_path,
                                                       capsys):
    store = str(tmp_path / "stale.zarr")
    md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                       block_rows=8, progress=False)
    for b in (1, 6):
        os.remove(os.path.join(store, "c", str(b), "0"))
    # a run on this host whose process is alive owns the store: refused, and
    # the command line says so in one line
    src = tmp_path / "s.txt"
    np.savetxt(src, SOURCES, fmt="%d")
    p = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
    try:
        _set_owner(store, token="live", pid=p.pid, pid_started=None, state="running")
        with pytest.raises(RuntimeError, match="in use") as e:
            md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                               progress=False)
        assert isinstance(e.value, md.StoreOwnerError)
        capsys.readouterr()
        rc = cli_allpairs_zarr([str(MESHES / "hand_lowres.obj"), "-o", store, "--sources",
                                   str(src), "--dtype", "float64", "--workers", "1",
                                   "--resume", "--no-progress"])
        err = capsys.readouterr().err
        assert rc == 2 and "in use" in err and len(err.strip().splitlines()) == 1
        assert _owner(store)["token"] == "live"
    finally:
        p.kill()
        p.wait()
    # its process was killed without releasing the store: the same job
    # resumes at once
    assert _owner(store)["state"] == "running"
    Z = md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           progress=False)
    assert Z.attrs[md.RUN_ATTR]["blocks_computed"] == 2
    assert np.array_equal(Z[:], serial64)
    # nor does a run of this process that did not release it
    for b in (1, 6):
        os.remove(os.path.join(store, "c", str(b), "0"))
    _set_owner(store, token="left-behind", pid=os.getpid(), state="running")
    Z = md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           progress=False)
    assert Z.attrs[md.RUN_ATTR]["blocks_computed"] == 2
    assert np.array_equal(Z[:], serial64)


def _copy_block(src_store, b_from, dst_store, b_to):
    """A chunk and, where there is one, its digest, copied as bytes."""
    for sub in (("c", "{}", "0"), (SUMS, "{}")):
        a = os.path.join(src_store, *sub).format(b_from)
        if os.path.exists(a):
            data = open(a, "rb").read()
            open(os.path.join(dst_store, *sub).format(b_to), "wb").write(data)


def test_a_chunk_from_another_block_or_job_is_recomputed(hand, serial64, client, tmp_path):
    # a chunk's CRC-32C covered only its bytes: a chunk copied from another
    # block or another job's store passed, and resume kept the wrong rows
    store = str(tmp_path / "a.zarr")
    md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                       block_rows=8, progress=False)
    other = str(tmp_path / "b.zarr")
    md.distance_matrix(meshfmm.Mesh(hand.vertices * 1.5, hand.faces), other, sources=SOURCES,
                       client=client, dtype="float64", block_rows=8, progress=False)
    _copy_block(store, 3, store, 4)
    _copy_block(other, 9, store, 9)
    Z = zarr.open_array(store, mode="r")
    assert not np.array_equal(Z[:], serial64)  # the copies hold other rows
    assert md.complete_blocks(Z, 8) == [b for b in range(15) if b not in (4, 9)]
    Z = md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           progress=False)
    assert Z.attrs[md.RUN_ATTR]["blocks_computed"] == 2
    assert np.array_equal(Z[:], serial64)


def test_a_chunk_that_does_not_decode_is_recomputed(hand, serial64, client, tmp_path):
    # a chunk whose CRC-32C matches but whose payload Blosc cannot decode made
    # resume die with RuntimeError; it is recomputed as a bad checksum is
    import google_crc32c

    store = str(tmp_path / "g.zarr")
    md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                       block_rows=8, progress=False)
    inner = np.random.default_rng(7).integers(0, 256, 5000, dtype=np.uint8).tobytes()
    crc = np.array([google_crc32c.value(inner)], dtype=np.uint32).tobytes()
    open(os.path.join(store, "c", "4", "0"), "wb").write(inner + crc)
    Z = zarr.open_array(store, mode="r")
    with pytest.raises(RuntimeError):  # what the codec raises on this chunk
        Z[32:40]
    assert md.complete_blocks(Z, 8) == [b for b in range(15) if b != 4]
    Z = md.distance_matrix(hand, store, sources=SOURCES, client=client, dtype="float64",
                           progress=False)
    assert Z.attrs[md.RUN_ATTR]["blocks_computed"] == 1
    assert np.array_equal(Z[:], serial64)


def _tree(root):
    return {os.path.relpath(os.path.join(d, f), root): open(os.path.join(d, f), "rb").read()
            for d, _, fs in os.walk(root) for f in fs}


def test_an_output_that_holds_an_input_is_refused_and_left_intact(tmp_path, capsys):
    # `-o DIR.zarr` deleted everything in DIR, the job's mesh and sources too
    proj = tmp_path / "proj.zarr"
    (proj / "sub").mkdir(parents=True)
    (proj / "mesh.obj").write_bytes((MESHES / "hand_lowres.obj").read_bytes())
    (proj / "src.txt").write_text("0\n1\n2\n")
    (proj / "notes.txt").write_text("my notes\n")
    (proj / "sub" / "results.csv").write_text("data\n")
    before = _tree(proj)
    (tmp_path / "link").symlink_to(proj)
    for mesh, src, out in ((proj / "mesh.obj", proj / "src.txt", proj),
                           (MESHES / "hand_lowres.obj", proj / "src.txt", proj / "src.txt"),
                           (tmp_path / "link" / "mesh.obj", None, proj)):
        capsys.readouterr()
        rc = cli_allpairs_zarr([str(mesh), "-o", str(out), "--workers", "1", "--no-progress",
                                   *(["--sources", str(src)] if src else [])])
        err = capsys.readouterr().err
        assert rc == 2 and "is an input or contains one" in err
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
        assert _tree(proj) == before


def test_a_location_that_is_not_a_meshfmm_store_needs_overwrite(hand, serial64, client,
                                                                tmp_path, capsys):
    out = tmp_path / "data.zarr"
    (out / "sub").mkdir(parents=True)
    (out / "notes.txt").write_text("my notes\n")
    (out / "sub" / "results.csv").write_text("data\n")
    before = _tree(out)
    for resume in (True, False):
        with pytest.raises(ValueError, match="not a meshfmm store") as e:
            md.distance_matrix(hand, str(out), sources=SOURCES, client=client, resume=resume,
                               progress=False)
        assert isinstance(e.value, md.StoreError)
    rc = cli_allpairs_zarr([str(MESHES / "hand_lowres.obj"), "-o", str(out), "--workers",
                               "1", "--no-progress"])
    err = capsys.readouterr().err
    assert rc == 2 and "--overwrite" in err and len(err.strip().splitlines()) == 1
    assert _tree(out) == before
    # asked for: the store is written beside the files, which stay
    Z = md.distance_matrix(hand, str(out), sources=SOURCES, client=client, dtype="float64",
                           block_rows=8, progress=False, overwrite=True)
    assert np.array_equal(Z[:], serial64)
    assert all(_tree(out)[k] == v for k, v in before.items())
    # starting over a meshfmm store deletes its own entries only: a smaller
    # job leaves no chunk or digest of the old one, and the files stay
    Z = md.distance_matrix(hand, str(out), sources=SOURCES[:24], client=client, dtype="float64",
                           block_rows=8, resume=False, progress=False)
    assert np.array_equal(Z[:], serial64[:24])
    assert md.complete_blocks(Z, 8) == [0, 1, 2]
    after = _tree(out)
    assert all(after[k] == v for k, v in before.items())
    assert sorted(k for k in after if k not in before) == sorted(
        ["zarr.json"] + [os.path.join("c", str(b), "0") for b in range(3)]
        + [os.path.join(SUMS, str(b)) for b in range(3)])
    # the command line's --overwrite reaches the call
    capsys.readouterr()
    other = tmp_path / "other"
    other.mkdir()
    (other / "keep.txt").write_text("kept\n")
    src = tmp_path / "s.txt"
    src.write_text("0\n5\n9\n")
    rc = cli_allpairs_zarr([str(MESHES / "hand_lowres.obj"), "-o", str(other), "--sources",
                               str(src), "--dtype", "float64", "--workers", "1",
                               "--no-progress", "--overwrite"])
    assert rc == 0, capsys.readouterr().err
    assert (other / "keep.txt").read_text() == "kept\n"
    assert np.array_equal(zarr.open_array(str(other), mode="r")[:],
                          hand.distance_matrix([0, 5, 9], backend="serial", dtype="float64"))
