"""Distances against references that need no other solver (oracles.py):
the Euclidean distance on flat meshes, the unfolding on books, the
Euclidean lower bound and the edge-graph upper bound on any mesh, and the
serial row for every matrix backend.

Seeded random meshes (a few hundred, seconds), the slit closed by slivers of
a needle shortcut, a flat square rotated into 3D where the exact solver once
returned 3x the Euclidean distance, and a random flat mesh with slivers where
it returned less than the Euclidean distance. bench/studies/oracle_sweep.py runs the
same checks on 10,000 meshes.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import meshfmm
import oracles as O
from conftest import DATA

ORACLE_DATA = DATA / "oracles"


def _src(s):
    return s if isinstance(s, (int, np.integer)) else meshfmm.SurfacePoint(s[0], s[1])


def _broken(bad: dict) -> dict:
    return {k: v[:5].tolist() for k, v in bad.items() if len(v)}


def _check_case(case, sources, backends=("serial", "threads", "opencl")):
    """Every method's distances from every source against the bounds;
    returns a list of failure lines (empty: all bounds met)."""
    fails = []
    mesh = meshfmm.Mesh(case.V, case.F)
    vsrc = [s for s in sources if isinstance(s, (int, np.integer))]
    rows = {}
    for b in backends:
        try:
            rows[b] = mesh.distance_matrix(vsrc, backend=b, dtype="float64")
        except meshfmm.OpenCLError:
            if b != "opencl":
                raise
    tag = f"{case.kind} {case.params}"
    for s in sources:
        eu = O.euclid(case.V, case.F, s)
        gr = O.edge_graph(case.V, case.F, s)
        e = mesh.distance(_src(s), method="exact")
        bad = _broken(O.check_exact(case, s, e, eu, gr))
        if bad:
            fails.append(f"{tag} source {s}: exact {bad}")
        d = mesh.distance(_src(s))
        bad = _broken(O.check_march(case, s, d, eu, gr))
        if bad:
            fails.append(f"{tag} source {s}: default {bad}")
        if not isinstance(s, (int, np.integer)):
            continue
        ser = rows["serial"][vsrc.index(s)]
        if not np.array_equal(ser.view(np.uint64), d.view(np.uint64)):
            fails.append(f"{tag} source {s}: serial row != distance")
        for b, D in rows.items():
            if b != "serial" and not np.array_equal(D[vsrc.index(s)].view(np.uint64),
                                                    ser.view(np.uint64)):
                fails.append(f"{tag} source {s}: {b} row != serial row")
    mesh.close()
    return fails


@pytest.mark.filterwarnings("ignore::meshfmm.MeshWarning")  # coincident on purpose
@pytest.mark.parametrize("kind,n,seed", [("flat", 120, 1), ("slit", 80, 2), ("book", 150, 10)])
def test_random_meshes_meet_bounds(kind, n, seed):
    """Random meshes of one kind (seeded): exact == reference where known,
    Euclidean <= exact <= edge graph, the default march within its bounds,
    every backend's row the serial row bit for bit."""
    rng = np.random.default_rng(seed)
    gen = {"flat": O.random_flat, "slit": O.random_slit, "book": O.random_book}[kind]
    fails = []
    n_known = 0
    for _ in range(n):
        case = gen(rng)
        n_known += case.known
        fails += _check_case(case, O.pick_sources(rng, case, n_vertex=2, n_face=1))
    # the generators make cases with a known distance, not only bounds
    assert n_known >= n // 3, n_known
    assert not fails, f"{len(fails)} (mesh, source, method) broke a bound:\n" + "\n".join(fails[:20])


def test_flat_square_rotated_exact_is_euclidean():
    """A clean flat triangulation of the unit square (27 vertices, no zero-area
    face), rotated into 3D: every exact and default distance, from every
    vertex, is the Euclidean one (the exact solver gave 1.5235 for 0.4982
    between vertices 5 and 1, above the edge-graph path)."""
    V, F = meshfmm.load_mesh(ORACLE_DATA / "flat27_rotated.obj")
    case = O.Case("flat", V, F, known=True)
    assert meshfmm.Mesh(V, F).info.n_degenerate_faces == 0
    fails = _check_case(case, list(range(len(V))))
    assert not fails, "\n".join(fails[:20])


def test_needle_slit_not_below_euclidean():
    """A flat square whose centre vertex is split into two 2e-15 apart, the
    slit closed by two slivers: no distance below the Euclidean one (the exact
    solver, and through its exact start the march, gave 0 for 0.5)."""
    gap = 2e-15
    V = np.array([[0, 0, 0], [.5, 0, 0], [1, 0, 0], [0, .5, 0], [.5, .5, 0], [1, .5, 0],
                  [0, 1, 0], [.5, 1, 0], [1, 1, 0], [.5, .5 + gap, 0]], float)
    F = np.array([[0, 1, 4], [0, 4, 3], [1, 2, 4], [2, 5, 4],
                  [3, 9, 6], [9, 7, 6], [9, 5, 8], [9, 8, 7],
                  [3, 4, 9], [4, 5, 9]], dtype=np.int32)
    case = O.Case("slit", V, F)
    m = meshfmm.Mesh(V, F)
    # along edge 5-4 the path is 0.5, the Euclidean distance: both bounds pin it
    assert m.distance(5, method="exact")[4] == pytest.approx(0.5, rel=1e-12)
    assert m.distance(5)[4] == pytest.approx(0.5, rel=1e-12)
    fails = _check_case(case, list(range(len(V))) + [(3, (0.2, 0.3, 0.5)), (5, (0.4, 0.3, 0.3))])
    assert not fails, "\n".join(fails[:20])


@pytest.mark.parametrize("faces", ["F", "F_other_order"])
def test_flat_mesh_with_slivers_not_below_euclidean(faces):
    """A random flat mesh with slivers and near-coincident vertices (225
    vertices, 4 zero-area faces), in two face orders: the exact solver gave
    8 vertices below the Euclidean distance (by up to 0.14 %)."""
    z = np.load(ORACLE_DATA / "flat_slivers_below_euclid.npz")
    V, F, s = z["V"], z[faces], int(z["source"])
    case = O.Case("flat", V, F)
    rng = np.random.default_rng(4)
    fails = _check_case(case, [s] + O.pick_sources(rng, case, n_vertex=3, n_face=2))
    assert not fails, "\n".join(fails[:20])


@pytest.mark.parametrize("V,F,face,bary", [
    # face 0 a needle (vertex 0 inside edge 1-2), so face 1 is split at
    # vertex 0; the source lies on the split line 0-3
    ([[2, 0, 0], [3, 0, 0], [0, 0, 0], [4, 1, 0]], [[0, 1, 2], [1, 3, 2]], 1, (0.5, 0.25, 0.25)),
    # face 1 a needle (vertex 0 the middle of edge 1-4), so face 2 is split
    # at vertex 0; the source lies on edge 4-3 of face 2
    ([[1, 1, 2], [0, 0, 1], [0, 2, 0], [1, 2, 0], [2, 2, 3]], [[3, 2, 0], [1, 4, 0], [4, 3, 1]],
     2, (3 / 7, 4 / 7, 0.0)),
])
def test_face_source_beside_t_junction_within_bounds(V, F, face, bary):
    """A point source in a face that the mesh splits at a T-junction (a
    zero-area needle face beside it): every distance between the Euclidean
    and edge-graph bounds (the march once started the wrong half and gave
    1.559 for 0.559 at a corner of the source's face)."""
    V = np.array(V, float)
    F = np.array(F, dtype=np.int32)
    case = O.Case("tjunction", V, F)
    s = (face, bary)
    fails = _check_case(case, [s] + list(range(len(V))))
    assert not fails, "\n".join(fails[:20])


def test_exact_ends_with_coincident_vertices():
    """A flat grid with two coincident vertices and a point source: the exact
    solve ends (it once looped for ever) and meets the bounds. Run in a child
    interpreter with a time limit, so that a loop fails instead of hanging."""
    code = textwrap.dedent(
        """
        import sys
        sys.path.insert(0, %r)
        import numpy as np, meshfmm, oracles as O
        V = np.array([[2, 0, 0], [3, 0, 0], [2, 1, 0], [3, 1, 0], [4, 1, 0], [2, 2, 0],
                      [0, 0, 0], [0, 0, 0], [0, 2, 0], [3, 3, 0], [4, 3, 0], [5, 3, 0]], float)
        F = np.array([[0, 1, 3], [0, 3, 2], [1, 4, 3], [2, 3, 6], [2, 6, 5], [3, 4, 7],
                      [3, 7, 6], [4, 8, 7], [5, 6, 9], [6, 7, 10], [6, 10, 9], [7, 8, 11],
                      [7, 11, 10]], dtype=np.int32)
        s = (2, (0.5, 0.25, 0.25))
        e = meshfmm.Mesh(V, F).distance(meshfmm.SurfacePoint(*s), method="exact")
        bad = {k: v.tolist() for k, v in O.check_exact(O.Case("x", V, F), s, e).items() if len(v)}
        print(bad)
        """
    ) % str(Path(__file__).parent)
    try:
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                              timeout=30)
    except subprocess.TimeoutExpired:
        pytest.fail("the exact solve did not end within 30 s (12 vertices)")
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.strip() == "{}", proc.stdout


def test_book_oracle_matches_igl():
    """The unfolding of a book against an independent exact solver (libigl's
    MMP) on clean two-page books (no slivers, which igl does not survive), so
    that the oracle itself is checked."""
    igl = pytest.importorskip("igl")
    rng = np.random.default_rng(5)
    none = np.array([], dtype=np.int64)
    for _ in range(6):
        case = O.random_book(rng, n_pages=2, scale=1.0, clean=True, min_gap=0.3)
        assert case.known
        for v in rng.choice(len(case.V), 2, replace=False):
            ref = igl.exact_geodesic(case.V, case.F.astype(np.int64), np.array([v]), none,
                                     np.arange(len(case.V)), none)
            np.testing.assert_allclose(O.book_distance(case, int(v)), ref, rtol=1e-12, atol=1e-14)


def test_oracles_on_a_flat_book():
    """Sanity of the references: a book opened flat (pages at 0 and pi) is a
    planar region; its unfolding is >= the Euclidean distance and equal to it
    where the straight segment crosses the spine, and every reference lies
    between the Euclidean and edge-graph bounds."""
    rng = np.random.default_rng(6)
    case = O.random_book(rng, n_pages=2, scale=1.0)
    # rebuild the same pages opened flat: a vertex (x, h) on page p at
    # (x, +-h) in the plane
    sign = np.where(case.page == 1, -1.0, 1.0)
    V = np.stack([case.xh[:, 0], sign * case.xh[:, 1], np.zeros(len(case.V))], axis=1)
    flat = O.Case("book", V, case.F, known=True, page=case.page, xh=case.xh, spine=case.spine)
    for v in range(0, len(V), 7):
        ref = O.book_distance(flat, v)
        eu = O.euclid(V, case.F, v)
        gr = O.edge_graph(V, case.F, v)
        assert (ref >= eu * (1 - 1e-14)).all()
        assert (ref <= gr * (1 + 1e-14)).all()
        a = case.xh[v]
        for w in range(len(V)):
            if case.page[w] != case.page[v] and case.page[w] >= 0 and case.page[v] >= 0:
                b = case.xh[w]
                t = a[0] + (b[0] - a[0]) * a[1] / (a[1] + b[1])
                if 0 <= t <= case.spine:
                    assert ref[w] == pytest.approx(eu[w], rel=1e-12)
