"""Target columns (S x T), sparse local matrices, row streaming and
symmetric output, against the full dense rows (the serial core)."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import mesh, need_data

SOURCES = [0, 17, 400, 809, 3, 17]


@pytest.mark.parametrize("backend", ["serial", "threads", "opencl", "auto"])
def test_targets_equal_full_columns(backend):
    need_data()
    if backend == "opencl":
        import meshfmm

        try:
            mesh("hand_lowres.obj").distance_matrix([0], backend="opencl")
        except meshfmm.OpenCLError as exc:
            pytest.skip(f"no OpenCL device: {exc}")
    m = mesh("hand_lowres.obj")
    # (auto may run full rows on OpenCL, which counts no work: threads here)
    full_backend = "threads" if backend in ("auto", "opencl") else backend
    full, full_info = m.distance_matrix(SOURCES, backend=full_backend, dtype="float64",
                                        n_threads=2, return_info=True)
    tg = [5, 400, 5, 800, 2]
    D, info = m.distance_matrix(SOURCES, backend=backend, dtype="float64", n_threads=2,
                                targets=tg, return_info=True)
    assert D.shape == (len(SOURCES), len(tg))
    assert np.array_equal(D.view(np.uint64), full[:, tg].view(np.uint64))
    if info.backend != "opencl":  # (OpenCL counts no work)
        assert info.vertices_settled < full_info.vertices_settled
    if backend != "auto":
        assert info.backend == backend
    D32 = m.distance_matrix(SOURCES, backend=backend, n_threads=2, targets=tg)
    assert np.array_equal(D32, full[:, tg].astype(np.float32))


@pytest.mark.parametrize("backend", ["serial", "threads", "auto"])
@pytest.mark.parametrize("dtype", ["float32", "float64"])
def test_sparse_equals_dense_within_r(backend, dtype):
    need_data()
    scipy_sparse = pytest.importorskip("scipy.sparse")
    m = mesh("hand_lowres.obj")
    r = 0.05
    dense = m.distance_matrix(None, backend="threads", dtype=dtype, max_distance=r)
    S = m.distance_matrix(None, backend=backend, dtype=dtype, max_distance=r, sparse=True, n_threads=2)
    assert isinstance(S, scipy_sparse.csr_matrix)
    assert S.shape == dense.shape and S.dtype == np.dtype(dtype)
    assert S.has_sorted_indices
    finite = np.isfinite(dense)
    assert S.nnz == int(finite.sum())
    coo = S.tocoo()
    assert np.array_equal(dense[coo.row, coo.col], coo.data)
    assert finite[coo.row, coo.col].all()
    assert np.array_equal(S.diagonal(), np.zeros(m.n_vertices, dtype))
    # the diagonal zeros are stored entries
    assert all(S[i].indices.tolist().count(i) == 1 for i in (0, 17, 400))
    with pytest.raises(ValueError):
        m.distance_matrix(SOURCES, sparse=True)


def test_sparse_with_targets():
    need_data()
    pytest.importorskip("scipy.sparse")
    m = mesh("hand_lowres.obj")
    tg = [5, 400, 800, 2, 17]
    dense = m.distance_matrix(SOURCES, dtype="float64", targets=tg, max_distance=0.08)
    S = m.distance_matrix(SOURCES, dtype="float64", targets=tg, max_distance=0.08, sparse=True)
    A = S.toarray()
    A[~np.isfinite(dense)] = np.inf
    stored = np.zeros(dense.shape, bool)
    coo = S.tocoo()
    stored[coo.row, coo.col] = True
    assert np.array_equal(stored, np.isfinite(dense))
    assert np.array_equal(A, dense)


def test_iter_distance_rows():
    need_data()
    m = mesh("hand_lowres.obj")
    src = list(range(0, 700, 7))
    ref = m.distance_matrix(src, dtype="float64", targets=[1, 2, 3, 805])
    seen = []
    blocks = list(
        m.iter_distance_rows(
            src, block_rows=32, dtype="float64", targets=[1, 2, 3, 805],
            progress=lambda d, n: seen.append((d, n)),
        )
    )
    assert [b[0] for b in blocks] == [0, 32, 64, 96]
    assert np.array_equal(np.concatenate([b[1] for b in blocks]), ref)
    assert seen[-1] == (len(src), len(src))
    it = m.iter_distance_rows(src, block_rows=10)
    first, blk = next(it)
    assert first == 0 and blk.shape == (10, m.n_vertices)
    it.close()  # stops: no further block is computed
    with pytest.raises(StopIteration):
        next(it)


def test_symmetric():
    need_data()
    m = mesh("hand_lowres.obj")
    n = m.n_vertices
    D = m.distance_matrix(None, dtype="float64")
    S = m.distance_matrix(None, dtype="float64", symmetric=True)
    assert np.array_equal(S, (D + D.T) / 2)
    D32 = m.distance_matrix(None)
    S32 = m.distance_matrix(None, symmetric=True)
    assert np.array_equal(S32, (D32 + D32.T) / 2)
    sub = [3, 50, 9, 700]
    Ssub = m.distance_matrix(sub, dtype="float64", targets=sub, symmetric=True)
    Dsub = D[np.ix_(sub, sub)]
    assert np.array_equal(Ssub, (Dsub + Dsub.T) / 2)
    with pytest.raises(ValueError):
        m.distance_matrix([1, 2], symmetric=True)
    assert n > 0


def test_cli_npz_and_targets(tmp_path):
    """`meshfmm allpairs --max-distance R -o OUT.npz` loads with
    scipy.sparse.load_npz and equals Python's CSR; --targets gives the
    columns; the output may not be the targets file; .npz needs a radius."""
    import subprocess

    need_data()
    sp = pytest.importorskip("scipy.sparse")
    from conftest import find_cli

    exe = find_cli()
    if exe is None:
        pytest.skip("no meshfmm command line")
    from conftest import MESHES

    path = str(MESHES / "hand_lowres.obj")
    m = mesh("hand_lowres.obj")
    (tmp_path / "t.txt").write_text("5 400 5 800 2\n")
    (tmp_path / "s.txt").write_text("0 17 400\n")
    run = lambda *a: subprocess.run([exe, "allpairs", path, "--quiet", *a], capture_output=True, text=True)
    for dt in ("float32", "float64"):
        r = run("--max-distance", "0.05", "--dtype", dt, "-o", str(tmp_path / "o.npz"))
        assert r.returncode == 0, r.stderr
        S = sp.load_npz(tmp_path / "o.npz")
        P = m.distance_matrix(None, dtype=dt, max_distance=0.05, sparse=True)
        assert S.shape == P.shape and S.dtype == P.dtype
        assert np.array_equal(S.indptr, P.indptr) and np.array_equal(S.indices, P.indices)
        assert np.array_equal(S.data, P.data)
    r = run("--sources", str(tmp_path / "s.txt"), "--targets", str(tmp_path / "t.txt"),
            "--dtype", "float64", "-o", str(tmp_path / "t.npy"))
    assert r.returncode == 0, r.stderr
    ref = m.distance_matrix([0, 17, 400], dtype="float64")[:, [5, 400, 5, 800, 2]]
    assert np.array_equal(np.load(tmp_path / "t.npy"), ref)
    r = run("-o", str(tmp_path / "x.npz"))
    assert r.returncode == 2 and "--max-distance" in r.stderr
    assert not (tmp_path / "x.npz").exists()
    (tmp_path / "t.npz").write_bytes(b"")
    r = run("--targets", str(tmp_path / "t.npz"), "--max-distance", "1", "-o", str(tmp_path / "t.npz"))
    assert r.returncode == 2
