"""Mesh.geodesic_path (paper section 5) on every manifold mesh of tests/data/meshes
against the stored exact distances (igl.exact_geodesic): 20 random targets
each from the stored source."""

from __future__ import annotations

import numpy as np
import pytest

import meshfmm

from conftest import MANIFOLD_MESHES, load, mesh, reference

N_TARGETS = 20


def mean_edge_length(V: np.ndarray, F: np.ndarray) -> float:
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    return float(np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1).mean())


@pytest.mark.parametrize("name", MANIFOLD_MESHES)
def test_paths_against_exact(name):
    V, F = load(name)
    m = mesh(name)
    sources, exact = reference(name)
    s, e = int(sources[0]), exact[0]
    d = m.distance(s)
    h = mean_edge_length(V, F)
    rng = np.random.default_rng(20240505)
    candidates = np.flatnonzero(np.isfinite(e) & (e > 0))
    targets = rng.choice(candidates, N_TARGETS, replace=False)
    L = np.empty(N_TARGETS)
    L_raw = np.empty(N_TARGETS)
    for i, t in enumerate(targets):
        assert np.isfinite(d[t]), f"target {t} reached by igl but not by meshfmm"
        p = m.geodesic_path(d, int(t), sources=[s])  # raises if tracing fails
        assert np.allclose(p.points[0], V[t], atol=1e-12 * h)
        assert np.allclose(p.points[-1], V[s], atol=1e-12 * h)  # ends at the source
        seg = np.linalg.norm(np.diff(p.points, axis=0), axis=1).sum()
        assert p.length == pytest.approx(seg, rel=1e-12)
        L[i] = p.length
        raw = m.geodesic_path(d, int(t), sources=[s], straighten=False)
        assert np.allclose(raw.points[-1], V[s], atol=1e-12 * h)
        L_raw[i] = raw.length
        assert p.length <= raw.length  # straightening never lengthens the path
    et, Tt = e[targets], d[targets]
    below = np.max((et - L) / h)
    path_err = np.mean(np.abs(L - et) / et)
    path_vs_T = np.mean(np.abs(L - Tt) / Tt)
    raw_err = np.mean(np.abs(L_raw - et) / et)
    T_err = np.mean(np.abs(Tt - et) / et)
    print(
        f"\n{name}: max (exact - length) / h = {below:.4f}; mean |length - exact| / exact = "
        f"{100 * path_err:.3f}% (traced, not straightened: {100 * raw_err:.3f}%); "
        f"mean |length - T| / T = {100 * path_vs_T:.3f}%; "
        f"(T's own mean error {100 * T_err:.3f}%)"
    )
    # A surface path is never shorter than the exact geodesic, up to discretisation.
    assert below < 0.5
    assert path_err < 0.02
    # Within 2% of T on average, except where T itself is farther than that from
    # the exact distance (hand_lowres: T is 2.75% high, the paths 0.5%): then the
    # path may not stray from T farther than T strays from the exact distance.
    assert path_vs_T < max(0.02, T_err)


def test_unreached_and_bad_target():
    m = mesh(MANIFOLD_MESHES[0])
    d = m.distance(0, max_distance=1e-9)
    far = int(np.flatnonzero(~np.isfinite(d))[0])
    with pytest.raises(ValueError):
        m.geodesic_path(d, far, sources=[0])
    with pytest.raises(ValueError):
        m.geodesic_path(d, m.n_vertices + 5, sources=[0])


# ---- paths end at their source or raise; point sources on edges


def _ends_at(p, x, h):
    return np.linalg.norm(p.points[-1] - x) <= 1e-9 * h


@pytest.mark.parametrize("name", ["wingnut.obj", "spot.obj", "decimated-max.obj"])
def test_paths_end_at_source_sweep(name):
    """A reduced bench/studies/sweep_paths.py: 30 targets from one reference source,
    the default call and with sources, and 30 random face-to-face pairs; none
    may end away from the source or stall."""
    V, F = load(name)
    m = mesh(name)
    h = mean_edge_length(V, F)
    sources, _ = reference(name)
    s = int(sources[-1])
    d = m.distance(s)
    rng = np.random.default_rng(9)
    for t in rng.choice(np.flatnonzero(np.isfinite(d) & (d > 0)), 30, replace=False):
        assert _ends_at(m.geodesic_path(d, int(t)), V[s], h), f"{name}: {s} -> {t}"
        assert _ends_at(m.geodesic_path(d, int(t), sources=[s]), V[s], h)
    for _ in range(30):
        src = meshfmm.SurfacePoint(int(rng.integers(len(F))), tuple(rng.dirichlet((1, 1, 1))))
        tgt = meshfmm.SurfacePoint(int(rng.integers(len(F))), tuple(rng.dirichlet((1, 1, 1))))
        p = m.geodesic_path(m.distance(src), tgt, sources=[src])
        assert _ends_at(p, np.asarray(src.bary) @ V[F[src.face]], h), f"{name}: {src} -> {tgt}"


def test_wingnut_virtual_edge_minimum():
    """wingnut, 2593 -> 128: T(2793) came through a virtual edge below all its
    edge neighbours; the default call ended there (length 1.08 for T(128) =
    1.56), with sources it raised. The path now follows the virtual edge."""
    V, F = load("wingnut.obj")
    m = mesh("wingnut.obj")
    h = mean_edge_length(V, F)
    d = m.distance(2593)
    for kw in ({}, {"sources": [2593]}):
        p = m.geodesic_path(d, 128, **kw)
        assert _ends_at(p, V[2593], h)
        assert p.length == pytest.approx(d[128], rel=0.05)


def test_spot_face_source_across_edge():
    """spot: the far vertex 597 seeded from a face source across an edge was a
    1-ring minimum the path stalled at. Without sources the path cannot reach
    the point (T > 0 at every vertex): it raises rather than end elsewhere."""
    V, F = load("spot.obj")
    m = mesh("spot.obj")
    src = meshfmm.SurfacePoint(5007, (0.42, 0.14, 0.44))
    tgt = meshfmm.SurfacePoint(4898, (0.05, 0.73, 0.22))
    d = m.distance(src)
    p = m.geodesic_path(d, tgt, sources=[src])
    assert _ends_at(p, np.asarray(src.bary) @ V[F[src.face]], mean_edge_length(V, F))
    with pytest.raises(RuntimeError, match="local minimum"):
        m.geodesic_path(d, tgt)


def test_hand_edge_midpoint_source():
    """A point on an edge is a point of both faces: the same T whichever face
    names it (to 1e-12 relative; in fact bit for bit) and no jump when it
    moves 1e-9 off the edge (before: 0.76 % of the diagonal; the exact
    distance moves by at most the move)."""
    V, F = load("hand_lowres.obj")
    m = mesh("hand_lowres.obj")
    f = 100
    for k in range(3):
        a, b = F[f, (k + 1) % 3], F[f, (k + 2) % 3]
        g = [i for i in np.flatnonzero((F == a).any(1) & (F == b).any(1)) if i != f]
        if not g:
            continue
        g = int(g[0])
        bf = np.zeros(3)
        bf[[(k + 1) % 3, (k + 2) % 3]] = 0.5
        bg = np.where((F[g] == a) | (F[g] == b), 0.5, 0.0)
        d_f = m.distance(meshfmm.SurfacePoint(f, tuple(bf)))
        d_g = m.distance(meshfmm.SurfacePoint(g, tuple(bg)))
        np.testing.assert_allclose(d_g, d_f, rtol=1e-12, atol=0)
        for face, bary, kk in ((f, bf, k), (g, bg, int(np.flatnonzero(bg == 0)[0]))):
            bm = bary * (1 - 1e-9)
            bm[kk] = 1e-9
            move = 1e-9 * np.linalg.norm(V[F[face, kk]] - 0.5 * (V[a] + V[b]))
            d_m = m.distance(meshfmm.SurfacePoint(face, tuple(bm)))
            assert np.max(np.abs(d_m - d_f)) <= 10 * move


@pytest.mark.parametrize("bad", [-1.0, float("-inf"), float("nan")])
def test_max_distance_negative_or_nan_refused(bad):
    m = mesh("hand_lowres.obj")
    with pytest.raises(ValueError, match="max_distance"):
        m.distance(0, max_distance=bad)
    with pytest.raises(ValueError, match="max_distance"):
        m.distance_matrix([0, 1], max_distance=bad, backend="serial")
