"""meshfmm against exact geodesics (igl.exact_geodesic, MMP) and against
geometry-central's fast marching (potpourri3d) on the shared meshes.

Metrics (docs/methods.md#metrics): mean relative error in percent over vertices with a
positive exact distance, and max error in percent of the mesh diameter (the
bounding-box diagonal of the referenced vertices). Bound: no worse than
geometry-central's FMM from the same sources on the same mesh, within 2% of its
value; on the obtuse-heavy meshes unfolding must be clearly (1.5x) better in
mean relative error; no value more than 2% below the exact distance.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

import meshfmm
from conftest import (
    ACCURACY,
    LARGE_MESHES,
    MANIFOLD_MESHES,
    OBTUSE_MESHES,
    compact,
    diameter,
    errors,
    load,
    mesh,
    need_data,
    reference,
)

pp3d = pytest.importorskip("potpourri3d")

SLACK = 1.02  # "no worse than geometry-central, within 2% of its value"
# The march is first order: a few values fall below the exact distance
# (docs/methods.md#what-every-distance-is). Least (d - e) / e measured over
# the stored sources: -1.61 % (hand_lowres) to -0.44 % (bunny).
UNDER = -0.02
CLEARLY = 1.5  # obtuse-heavy meshes: geometry-central's MRE / ours at least this


@functools.lru_cache(maxsize=None)
def compacted(name: str):
    V, F = load(name)
    return compact(V, F)


@functools.lru_cache(maxsize=None)
def gc_solver(name: str):
    V2, F2, _, _ = compacted(name)
    return pp3d.MeshFastMarchingDistanceSolver(V2, F2)


def gc_distance(name: str, source) -> np.ndarray:
    """geometry-central FMM distances on the full vertex set (+inf at
    unreferenced vertices). source: a vertex id of the original mesh, or
    (face, bary)."""
    V, F = load(name)
    V2, F2, old_of_new, new_of_old = compacted(name)
    if isinstance(source, tuple):
        pt = (int(source[0]), [float(b) for b in source[1]])  # faces keep their ids
    else:
        pt = (int(new_of_old[source]), [])
    d2 = np.asarray(gc_solver(name).compute_distance([[pt]]), dtype=np.float64).reshape(-1)
    d = np.full(V.shape[0], np.inf)
    d[old_of_new] = d2
    return d


@pytest.mark.parametrize("name", MANIFOLD_MESHES)
def test_against_exact_and_geometry_central(name):
    need_data()
    sources, exact = reference(name)
    m = mesh(name)
    assert m.info.n_nonmanifold_edges == 0
    diam = diameter(name)
    ours, gc, plain = [], [], []
    for s, e in zip(sources, exact):
        d = m.distance(int(s))
        assert d.dtype == np.float64 and d.shape == e.shape
        assert not np.isnan(d).any()
        # +inf exactly where the exact distance is +inf (unreferenced vertices)
        np.testing.assert_array_equal(np.isinf(d), np.isinf(e))
        ours.append(errors(d, e, diam))
        ok = np.isfinite(e) & (e > 0)
        under = float(np.min((d[ok] - e[ok]) / e[ok]))
        assert under >= UNDER, f"source {s}: {-100 * under:.2f}% below the exact distance"
        gc.append(errors(gc_distance(name, int(s)), e, diam))
        plain.append(errors(m.distance(int(s), unfolding=False), e, diam))
    ours_mre = float(np.mean([o[0] for o in ours]))
    ours_max = float(np.max([o[1] for o in ours]))
    gc_mre = float(np.mean([g[0] for g in gc]))
    gc_max = float(np.max([g[1] for g in gc]))
    ACCURACY[name] = {
        "n_vertices": int(m.n_vertices),
        "sources": [int(s) for s in sources],
        "meshfmm": {
            "mean_rel_error_pct": ours_mre,
            "max_error_pct_diameter": ours_max,
            "per_source": ours,
        },
        "geometry_central_fmm": {
            "mean_rel_error_pct": gc_mre,
            "max_error_pct_diameter": gc_max,
            "per_source": gc,
        },
        "meshfmm_no_unfolding": {
            "mean_rel_error_pct": float(np.mean([p[0] for p in plain])),
            "max_error_pct_diameter": float(np.max([p[1] for p in plain])),
        },
        "mre_ratio_gc_over_meshfmm": gc_mre / ours_mre,
        "max_ratio_gc_over_meshfmm": gc_max / ours_max,
    }
    print(
        f"{name}: meshfmm MRE {ours_mre:.4f}% max {ours_max:.4f}% | "
        f"geometry-central MRE {gc_mre:.4f}% max {gc_max:.4f}%"
    )
    assert ours_mre <= SLACK * gc_mre, f"mean relative error {ours_mre:.4f}% vs geometry-central {gc_mre:.4f}%"
    assert ours_max <= SLACK * gc_max, f"max error {ours_max:.4f}% vs geometry-central {gc_max:.4f}%"
    if name in OBTUSE_MESHES:
        assert gc_mre / ours_mre >= CLEARLY, (
            f"unfolding should beat geometry-central clearly on {name}: "
            f"{ours_mre:.4f}% vs {gc_mre:.4f}% (ratio {gc_mre / ours_mre:.2f})"
        )


def test_live_exact_geodesic_hand():
    """One live igl.exact_geodesic call, so the stored-reference path stays
    tested: it must reproduce the stored row, and meshfmm's bound holds."""
    igl = pytest.importorskip("igl")
    name = "hand_lowres.obj"
    sources, exact = reference(name)
    V, F = load(name)
    V2, F2, old_of_new, new_of_old = compacted(name)
    s = int(sources[1])
    live = np.asarray(igl.exact_geodesic(V2, F2, np.array([new_of_old[s]], dtype=np.int64),
                                         np.array([], dtype=np.int64),
                                         np.arange(V2.shape[0], dtype=np.int64)))
    full = np.full(V.shape[0], np.inf)
    full[old_of_new] = live.reshape(-1)
    np.testing.assert_allclose(full, exact[1], rtol=1e-9, atol=1e-12)
    diam = diameter(name)
    ours = errors(mesh(name).distance(s), full, diam)
    gc = errors(gc_distance(name, s), full, diam)
    assert ours[0] <= SLACK * gc[0] and ours[1] <= SLACK * gc[1], (ours, gc)


@pytest.mark.parametrize("name", ["hand_lowres.obj", "spot.obj", "wingnut.obj"])
def test_face_source_against_exact(name):
    """A source inside a face: igl.exact_geodesic takes a face source at its
    centroid, so ours is SurfacePoint(face, (1/3, 1/3, 1/3)); geometry-central
    gets the same point through its barycentric source API. Same bound as
    vertex sources, over three faces together."""
    igl = pytest.importorskip("igl")
    V, F = load(name)
    V2, F2, old_of_new, _ = compacted(name)
    m = mesh(name)
    diam = diameter(name)
    bary = (1 / 3, 1 / 3, 1 / 3)
    rng = np.random.default_rng(7)
    faces = rng.choice(F.shape[0], size=3, replace=False)
    ours, gc = [], []
    for f in faces:
        e2 = np.asarray(igl.exact_geodesic(V2, F2, np.array([], dtype=np.int64),
                                           np.array([f], dtype=np.int64),
                                           np.arange(V2.shape[0], dtype=np.int64)))
        e = np.full(V.shape[0], np.inf)
        e[old_of_new] = e2.reshape(-1)
        d = m.distance(meshfmm.SurfacePoint(int(f), bary))
        # the face's own corners: in-plane distances to the centroid, exactly
        c = V[F[f]].mean(axis=0)
        np.testing.assert_allclose(d[F[f]], np.linalg.norm(V[F[f]] - c, axis=1), rtol=1e-12)
        ours.append(errors(d, e, diam))
        gc.append(errors(gc_distance(name, (int(f), bary)), e, diam))
    o_mre, o_max = np.mean([o[0] for o in ours]), np.max([o[1] for o in ours])
    g_mre, g_max = np.mean([g[0] for g in gc]), np.max([g[1] for g in gc])
    print(f"{name} face sources: meshfmm MRE {o_mre:.4f}% max {o_max:.4f}% | "
          f"geometry-central MRE {g_mre:.4f}% max {g_max:.4f}%")
    assert o_mre <= SLACK * g_mre, (o_mre, g_mre)
    assert o_max <= SLACK * g_max, (o_max, g_max)


def test_nonmanifold_beetle_solves():
    """beetle: non-manifold, two components. It loads, its diagnostics say
    so, and a solve is finite on the source's component, +inf on the other,
    never NaN."""
    need_data()
    m = mesh("beetle.obj")
    info = m.info
    assert info.n_nonmanifold_edges == 47
    assert info.n_components == 2
    assert info.n_boundary_edges == 296
    F = m.faces
    # vertices of the small (6 V) component
    from collections import defaultdict

    parent = list(range(m.n_vertices))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b, c in F:
        for x, y in ((a, b), (b, c)):
            rx, ry = find(int(x)), find(int(y))
            if rx != ry:
                parent[rx] = ry
    comp = np.array([find(v) for v in range(m.n_vertices)])
    groups = defaultdict(list)
    for v in np.unique(F):
        groups[comp[v]].append(v)
    big = max(groups.values(), key=len)
    small = min(groups.values(), key=len)
    assert len(small) == 6
    for s in (big[0], big[len(big) // 2], small[0]):
        d = m.distance(int(s))
        assert not np.isnan(d).any()
        mine = big if s in big else small
        other = small if s in big else big
        assert np.isfinite(d[mine]).all()
        assert np.isinf(d[other]).all()


@pytest.mark.slow
@pytest.mark.parametrize("name", LARGE_MESHES)
def test_large_mesh_solves(name):
    """igea (134k vertices, PLY tristrips): no stored reference; it loads and
    a solve is finite everywhere (closed, one component)."""
    need_data()
    m = mesh(name)
    assert m.n_faces == 268686 and m.info.n_components == 1
    d = m.distance(0)
    assert np.isfinite(d).all() and d[0] == 0.0
