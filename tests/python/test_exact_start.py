"""The exact start of the march: against the stored
igl.exact_geodesic references, never worse than the paper's plain start and
at most 0.6x its mean relative error, below potpourri3d's robust heat method
in mean and max error; rows equal on every backend (OpenCL bit for bit); the
option through Python and the command line."""

from __future__ import annotations

import os
import subprocess

import numpy as np
import pytest

import meshfmm
from conftest import (
    MANIFOLD_MESHES,
    compact,
    diameter,
    errors,
    load,
    mesh,
    need_data,
    reference,
)

TARGET = 0.6  # mean relative error at most 0.6x the plain start's (docs/methods.md#metrics)


@pytest.mark.parametrize("name", MANIFOLD_MESHES)
def test_exact_start_against_stored_references(name):
    need_data()
    sources, exact = reference(name)
    m = mesh(name)
    diam = diameter(name)
    plain, ours = [], []
    for s, e in zip(sources, exact):
        plain.append(errors(m.distance(int(s), exact_start=False), e, diam))
        ours.append(errors(m.distance(int(s)), e, diam))
    p_mre, o_mre = np.mean([p[0] for p in plain]), np.mean([o[0] for o in ours])
    p_max, o_max = np.max([p[1] for p in plain]), np.max([o[1] for o in ours])
    print(f"{name}: plain {p_mre:.4f}% / {p_max:.4f}%, exact start {o_mre:.4f}% / {o_max:.4f}% "
          f"({o_mre / p_mre:.2f}x)")
    for p, o in zip(plain, ours):  # per source: never worse in mean error
        assert o[0] <= p[0]
    assert o_max <= p_max
    assert o_mre <= TARGET * p_mre, (o_mre, p_mre)


@pytest.mark.parametrize("name", ["hand_lowres.obj", "spot.obj", "wingnut.obj",
                                  "fertility_FE_10k.off", "decimated-max.obj"])
def test_below_robust_heat(name):
    pp3d = pytest.importorskip("potpourri3d")
    need_data()
    sources, exact = reference(name)
    V, F = load(name)
    V2, F2, old_of_new, new_of_old = compact(V, F)
    heat = pp3d.MeshHeatMethodDistanceSolver(V2, F2, use_robust=True)
    m = mesh(name)
    diam = diameter(name)
    ours, hm = [], []
    for s, e in zip(sources, exact):
        ours.append(errors(m.distance(int(s)), e, diam))
        d = np.full(V.shape[0], np.inf)
        d[old_of_new] = heat.compute_distance(int(new_of_old[s]))
        hm.append(errors(d, e, diam))
    assert np.mean([o[0] for o in ours]) < np.mean([h[0] for h in hm])
    assert np.max([o[1] for o in ours]) < np.max([h[1] for h in hm])


@pytest.mark.parametrize("exact_start", [True, False, 3.5])
@pytest.mark.parametrize("backend", ["serial", "threads", "opencl"])
def test_rows_equal_on_every_backend(backend, exact_start):
    need_data()
    m = mesh("wingnut.obj")
    src = [5, 80, 2593, 1000, 7]
    ref = np.stack([m.distance(s, exact_start=exact_start) for s in src])
    try:
        D = m.distance_matrix(src, backend=backend, dtype="float64", n_threads=2,
                              exact_start=exact_start)
    except meshfmm.OpenCLError as exc:
        pytest.skip(f"no OpenCL device: {exc}")
    assert np.array_equal(D.view(np.uint64), ref.view(np.uint64))
    # a uniform cost: the exact start at F = 2.5; targets: the same columns
    cost = np.full(m.n_faces, 2.5)
    ref = np.stack([m.distance(s, cost=cost, exact_start=exact_start) for s in src])
    np.testing.assert_allclose(ref, 2.5 * np.stack([m.distance(s, exact_start=exact_start)
                                                     for s in src]), rtol=1e-12)
    D = m.distance_matrix(src, backend=backend, dtype="float64", cost=cost, n_threads=2,
                          exact_start=exact_start)
    assert np.array_equal(D.view(np.uint64), ref.view(np.uint64))
    tg = [3, 2000, 17]
    D = m.distance_matrix(src, backend=backend, dtype="float64", targets=tg, n_threads=2,
                          exact_start=exact_start)
    full = np.stack([m.distance(s, exact_start=exact_start) for s in src])
    assert np.array_equal(D, full[:, tg])


def test_exact_start_option_values():
    m = meshfmm.Mesh(*meshfmm.load_mesh(os.path.join(os.path.dirname(__file__), "..", "data",
                                                      "meshes", "hand_lowres.obj")))
    d0 = m.distance(21, exact_start=False)
    assert np.array_equal(m.distance(21, exact_start=0), d0)
    # the default rule gives the base radius on a mesh of <= 40k vertices
    assert np.array_equal(m.distance(21, exact_start=7.0), m.distance(21))
    assert np.array_equal(m.distance(21, exact_start="auto"), m.distance(21))
    assert not np.array_equal(m.distance(21), d0)
    for bad in (-1, float("nan"), float("inf"), "5", "Auto", None):
        with pytest.raises(ValueError):
            m.distance(21, exact_start=bad)
    with pytest.raises(ValueError):
        m.distance(21, method="exact", exact_start=False)


def test_cli_exact_start(tmp_path):
    need_data()
    import meshfmm.__main__

    cli = meshfmm.__main__.cli_path()  # the package's binary, else $MESHFMM_CLI
    if not cli:
        pytest.skip("no meshfmm command line in the package and MESHFMM_CLI not set")
    path = os.path.join(os.path.dirname(__file__), "..", "data", "meshes", "hand_lowres.obj")
    m = meshfmm.Mesh.from_file(path)
    for args, kw in (([], {}), (["--plain-start"], {"exact_start": False}),
                     (["--exact-start-radius", "2.5"], {"exact_start": 2.5})):
        out = tmp_path / "d.npy"
        subprocess.run([cli, "distance", path, "--source", "21", "-o", str(out), *args], check=True)
        assert np.array_equal(np.load(out), m.distance(21, **kw))
        out = tmp_path / "a.npy"
        subprocess.run([cli, "allpairs", path, "--sources", str(write_ids(tmp_path, [21, 144])),
                        "--dtype", "float64", "--backend", "threads", "-q", "-o", str(out), *args],
                       check=True)
        assert np.array_equal(np.load(out), m.distance_matrix([21, 144], dtype="float64",
                                                              backend="threads", **kw))
    r = subprocess.run([cli, "distance", path, "--source", "21", "-o", str(tmp_path / "x.npy"),
                        "--exact-start-radius", "-1"], capture_output=True, text=True)
    assert r.returncode == 2 and "exact-start-radius" in r.stderr


def write_ids(tmp_path, ids):
    p = tmp_path / "src.txt"
    p.write_text("".join(f"{i}\n" for i in ids))
    return p


def surface_points(name, n_faces=3, n_edges=1):
    """Deterministic point sources of a mesh: inside faces and on edges."""
    _, F = load(name)
    rng = np.random.default_rng(sum(map(ord, name)))
    pts = [meshfmm.SurfacePoint(int(f), rng.dirichlet([1.0, 1.0, 1.0]))
           for f in rng.integers(0, len(F), n_faces)]
    for f in rng.integers(0, len(F), n_edges):
        t = rng.uniform(0.2, 0.8)
        b = np.zeros(3)
        k = int(rng.integers(0, 3))
        b[k], b[(k + 1) % 3] = t, 1.0 - t
        pts.append(meshfmm.SurfacePoint(int(f), b))
    return pts


@pytest.mark.parametrize("name", MANIFOLD_MESHES + ["beetle.obj"])
def test_point_sources_never_worse(name):
    """Points inside faces and on edges start no worse than the
    plain start (mean relative error against the library's exact solver,
    which equals the stored igl references, test_exact.py). The straight
    start's walk reaches the mesh's longest edge (6.6 mean edges on
    fertility, 12 on beetle), beyond a radius-6 patch, which alone gives
    fertility 1.12x."""
    need_data()
    m = mesh(name)
    for p in surface_points(name):
        e = m.distance(p, method="exact")
        ok = np.isfinite(e) & (e > 0)
        plain = np.mean(np.abs(m.distance(p, exact_start=False)[ok] - e[ok]) / e[ok])
        ours = m.distance(p)
        assert np.all(np.isfinite(ours) == np.isfinite(e))
        ours = np.mean(np.abs(ours[ok] - e[ok]) / e[ok])
        assert ours <= plain, (p.face, list(p.bary), ours / plain)


@pytest.mark.parametrize("backend", ["serial", "threads", "opencl"])
def test_local_rows_within_the_radius_are_exact(backend):
    """A row with max_distance inside the exact start's radius is the exact
    patch (the patch ends at max_distance, so a local row costs its
    reach): equal to the exact solver to 1e-12 where finite, +inf exactly
    where the exact distance passes max_distance; the same on every backend
    (sparse on the CPU ones, dense rows on OpenCL)."""
    need_data()
    m = mesh("wingnut.obj")
    h = m.info.mean_edge_length
    r = 4.0 * h  # inside the default radius (7 mean edges)
    src = [5, 80, 2593, 1000]
    exact = np.stack([m.distance(s, method="exact") for s in src])
    try:
        if backend == "opencl":
            D = m.distance_matrix(src, backend=backend, dtype="float64", max_distance=r)
        else:
            D = m.distance_matrix(src, backend=backend, dtype="float64", max_distance=r,
                                  sparse=True, n_threads=2).toarray()
            D[D == 0] = np.inf
            D[np.arange(len(src)), src] = 0.0
    except meshfmm.OpenCLError as exc:
        pytest.skip(f"no OpenCL device: {exc}")
    finite = np.isfinite(D)
    near = exact <= r * (1 - 1e-9)
    far = exact > r * (1 + 1e-9)
    assert np.all(finite[near]) and not np.any(finite[far])
    assert np.max(np.abs(D[finite] - exact[finite]) / np.maximum(exact[finite], h)) < 1e-12
    ref = np.stack([m.distance(s, max_distance=r) for s in src])  # the serial core
    assert np.array_equal(D.view(np.uint64), ref.view(np.uint64))
    plain = np.stack([m.distance(s, max_distance=r, exact_start=False) for s in src])
    assert np.max(np.abs(plain[near] - exact[near])) > 1e-6  # what the patch replaces
