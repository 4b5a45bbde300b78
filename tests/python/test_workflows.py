"""Real files and workflow tools: coincident vertices (warning, counts,
weld=True mapping every result back), farthest-point sampling against a
loop of full solves, Voronoi labels against the argmin over single-source
fields, isolines against the linear interpolant, one-call paths against
the reversed two-call path, surface points as targets."""

from __future__ import annotations

import pickle
import warnings

import numpy as np
import pytest

import meshfmm
from conftest import MESHES, load, mesh
from meshfmm_testing import write_off
from meshfmm import MeshWarning, SurfacePoint


def split_at_x(V, F, x0=0.0):
    """Cuts a mesh along the edges between faces whose centroid lies left of
    x0 and the others: vertices shared by both sides get a copy (appended)
    for the right side. Returns (V2, F2, original id of each vertex)."""
    right = V[F].mean(axis=1)[:, 0] > x0
    left_used = np.zeros(V.shape[0], bool)
    left_used[F[~right].ravel()] = True
    right_used = np.zeros(V.shape[0], bool)
    right_used[F[right].ravel()] = True
    shared = np.flatnonzero(left_used & right_used)
    copy_of = np.full(V.shape[0], -1)
    copy_of[shared] = V.shape[0] + np.arange(shared.size)
    F2 = F.copy()
    fr = F2[right]
    fr = np.where(copy_of[fr] >= 0, copy_of[fr], fr)
    F2[right] = fr
    V2 = np.concatenate([V, V[shared]])
    orig = np.concatenate([np.arange(V.shape[0]), shared])
    return V2, F2, orig


@pytest.fixture(scope="module")
def spot_split():
    V, F = load("spot.obj")
    V2, F2, orig = split_at_x(V, F)
    return V, F, V2, F2, orig


def test_seam_warns_and_counts(spot_split):
    V, F, V2, F2, orig = spot_split
    n_dup = V2.shape[0] - V.shape[0]
    assert n_dup > 20
    with pytest.warns(MeshWarning, match="coincident vertices") as rec:
        m = meshfmm.Mesh(V2, F2)
    assert "weld=True" in str(rec[0].message)
    assert m.info.n_coincident_vertices == n_dup
    assert m.info.n_components == 2
    assert m.info.n_welded_components == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        meshfmm.Mesh(V, F)  # no coincident vertices: no warning
        w = meshfmm.Mesh(V2, F2, weld=True)
    assert w.info.n_vertices == V.shape[0] and w.info.n_faces == F.shape[0]
    assert w.info.n_coincident_vertices == 0 and w.info.n_components == 1
    assert w.n_vertices == V2.shape[0] and w.vertices.shape == V2.shape
    assert np.array_equal(w.weld_map, orig)


def test_weld_maps_every_result_back(spot_split):
    V, F, V2, F2, orig = spot_split
    base = mesh("spot.obj")
    w = meshfmm.Mesh(V2, F2, weld=True)
    copy = V.shape[0] + 3  # a copy of vertex orig[copy]
    s = int(orig[copy])
    d0 = base.distance(s)
    # the welded surface is the original one (copies come last): equal bits
    assert np.array_equal(w.distance(copy), d0[orig])
    assert np.array_equal(w.distance(s), d0[orig])
    assert np.array_equal(w.distance(copy, method="exact"), base.distance(s, method="exact")[orig])
    D = w.distance_matrix([copy, 10], dtype="float64")
    assert D.shape == (2, V2.shape[0])
    assert np.array_equal(D, base.distance_matrix([s, 10], dtype="float64")[:, orig])
    T = w.distance_matrix([copy], targets=[copy, 5], dtype="float64")
    assert np.array_equal(T[0], d0[[s, 5]])
    # a per-vertex cost of the input's size; a path with input ids
    cost = np.linspace(1, 2, V2.shape[0])
    assert np.array_equal(w.distance(copy, cost), base.distance(s, cost[:V.shape[0]])[orig])
    t = V.shape[0] + 40
    pw = w.geodesic_path(w.distance(copy), t, sources=[copy])
    pb = base.geodesic_path(d0, int(orig[t]), sources=[s])
    assert np.array_equal(pw.points, pb.points) and np.array_equal(pw.faces, pb.faces)
    assert np.array_equal(w.farthest_point_sampling(10, copy), base.farthest_point_sampling(10, s))
    again = pickle.loads(pickle.dumps(w))
    assert again.options["weld"] is True and np.array_equal(again.distance(copy), d0[orig])
    with pytest.raises(ValueError, match="out of range"):
        w.distance(V2.shape[0])


def test_trimesh_spot_welds_back():
    trimesh = pytest.importorskip("trimesh")
    tm = trimesh.load(MESHES / "spot.obj")
    with pytest.warns(MeshWarning, match="coincident vertices"):
        split = meshfmm.Mesh(tm)
    assert split.info.n_components > 1 and split.info.n_welded_components == 1
    w = meshfmm.Mesh(tm, weld=True)
    base = mesh("spot.obj")
    assert (w.info.n_vertices, w.info.n_faces) == (base.n_vertices, base.n_faces)
    # the same surface numbered otherwise: map by position
    V = np.asarray(tm.vertices)
    key = {tuple(p): i for i, p in enumerate(base.vertices)}
    to_base = np.array([key[tuple(p)] for p in V])
    d = w.distance(0)
    assert np.allclose(d, base.distance(int(to_base[0]))[to_base], rtol=1e-12, atol=1e-12)
    assert np.isfinite(d).all()


# ------------------------------------------------------------ farthest points
def brute_fps(m, k, start):
    """k full solves, a running minimum, the farthest vertex not chosen
    (ties to the lowest id)."""
    dmin = np.full(m.n_vertices, np.inf)
    chosen, radii = [start], [np.inf]
    for i in range(k):
        dmin = np.minimum(dmin, m.distance(chosen[-1]))
        if i == k - 1:
            break
        cand = dmin.copy()
        cand[chosen] = -1
        nxt = int(np.argmax(cand))
        chosen.append(nxt)
        radii.append(cand[nxt])
    dmin[chosen] = 0
    return np.array(chosen), np.array(radii), dmin


@pytest.mark.parametrize("name,k,start", [("hand_lowres.obj", 60, 0), ("spot.obj", 40, 1234),
                                          ("camelhead.off", 25, 17)])
def test_fps_equals_brute_force(name, k, start):
    m = mesh(name)
    pts, radii, dist = m.farthest_point_sampling(k, start, return_radii=True,
                                                 return_distances=True)
    ref_pts, ref_radii, ref_dist = brute_fps(m, k, start)
    assert pts.dtype == np.int32 and pts[0] == start
    assert np.array_equal(pts, ref_pts)
    assert np.array_equal(radii, ref_radii)
    assert np.array_equal(dist, ref_dist)
    assert np.all(np.diff(radii[1:]) <= 0)


def test_fps_arguments():
    m = mesh("hand_lowres.obj")
    with pytest.raises(ValueError):
        m.farthest_point_sampling(0)
    with pytest.raises(ValueError):
        m.farthest_point_sampling(m.n_vertices + 1)
    with pytest.raises(ValueError):
        m.farthest_point_sampling(3, start=-1)
    with pytest.raises(TypeError):
        m.farthest_point_sampling(3, return_radii=1)


# ---------------------------------------------------------------- Voronoi
def test_voronoi_equals_argmin_of_single_fields():
    m = mesh("spot.obj")
    sources = [0, 700, 1500, 2200, SurfacePoint(3000, (0.2, 0.5, 0.3))]
    fields = np.stack([m.distance(s) for s in sources])
    labels = m.voronoi_labels(sources)
    assert labels.dtype == np.int32 and labels.shape == (m.n_vertices,)
    best = np.argmin(fields, axis=0)  # ties: the lower index
    srt = np.sort(fields, axis=0)
    gap = srt[1] - srt[0]
    wrong = labels != best
    assert wrong.sum() <= 0.01 * m.n_vertices
    assert np.all(gap[wrong] < m.info.mean_edge_length)
    for i, s in enumerate(sources[:4]):
        assert labels[s] == i
    d = m.distance(sources)
    assert np.array_equal(m.voronoi_labels(sources, d), labels)


def test_voronoi_unreached_is_minus_one(spot_split):
    _, _, V2, F2, _ = spot_split
    with pytest.warns(MeshWarning):
        m = meshfmm.Mesh(V2, F2)
    labels = m.voronoi_labels([0, 1])
    d = m.distance([0, 1])
    assert np.array_equal(labels == -1, np.isinf(d))


# ---------------------------------------------------------------- isolines
def test_isolines_cross_faces_where_the_interpolant_says():
    m = mesh("spot.obj")
    d = m.distance(0)
    levels = [0.1 * d.max(), 0.45 * d.max(), 0.9 * d.max()]
    res = m.isolines(d, levels)
    assert len(res) == 3
    F = m.faces
    for c, lines in zip(levels, res):
        assert lines
        n_seg = 0
        seen = []
        for ln in lines:
            assert ln.value == c and len(ln) >= 2
            # every point on its face, where the linear interpolant is c
            vals = (ln.barycentric * d[F[ln.faces]]).sum(axis=1)
            assert np.allclose(vals, c, rtol=0, atol=1e-12)
            xyz = np.einsum("ij,ijk->ik", ln.barycentric, m.vertices[F[ln.faces]])
            assert np.allclose(xyz, ln.points, atol=1e-12)
            assert ln.faces[0] == ln.faces[1]
            if ln.closed:
                assert np.allclose(ln.points[0], ln.points[-1])
            n_seg += len(ln) - 1
            seen.extend(ln.faces[1:].tolist())
        # one segment in each face the level crosses, and no other
        A = d[F] >= c
        crossed = np.flatnonzero(A.any(axis=1) & ~A.all(axis=1))
        assert n_seg == crossed.size
        assert sorted(seen) == crossed.tolist()
    assert all(ln.closed for ln in res[0])  # a closed surface: loops
    assert m.isolines(d, 1e9) == [[]]


def test_isolines_of_many_values_at_once_on_a_non_manifold_mesh():
    """beetle.obj has non-manifold edges (more than two segments meet at
    some crossing points) and unreached vertices under a radius: many
    values in one call, values at vertices' own values and out of range,
    each value's segments where the linear interpolant says, one per crossed
    face, and equal to the value asked alone."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshWarning)
        m = meshfmm.Mesh.from_file(MESHES / "beetle.obj")
    assert m.info.n_nonmanifold_edges > 0
    d = m.distance([0, 500], max_distance=0.6)
    assert np.isinf(d).any()
    top = d[np.isfinite(d)].max()
    levels = [*np.linspace(0.02, 0.98, 25) * top, d[3], d[3], -1.0, 10 * top]
    res = m.isolines(d, levels)
    F, V = m.faces, m.vertices
    for c, lines in zip(levels, res):
        assert lines == [] if not 0 < c <= top else lines
        seen = []
        for ln in lines:
            assert ln.value == c
            vals = (ln.barycentric * d[F[ln.faces]]).sum(axis=1)
            assert np.allclose(vals, c, rtol=0, atol=1e-12)
            xyz = np.einsum("ij,ijk->ik", ln.barycentric, V[F[ln.faces]])
            assert np.allclose(xyz, ln.points, atol=1e-12)
            seen.extend(ln.faces[1:].tolist())
        with np.errstate(invalid="ignore"):
            A = d[F] >= c
        crossed = np.flatnonzero(np.isfinite(d[F]).all(axis=1) & A.any(axis=1) & ~A.all(axis=1))
        assert sorted(seen) == crossed.tolist()
        alone = m.isolines(d, c)[0]
        assert len(alone) == len(lines)
        for a, b in zip(alone, lines):
            assert np.array_equal(a.points, b.points) and np.array_equal(a.faces, b.faces)
            assert np.array_equal(a.barycentric, b.barycentric) and a.closed == b.closed


# ---------------------------------------------------------------- paths
@pytest.mark.parametrize("source,target", [(0, 1234),
                                           (SurfacePoint(100, (0.3, 0.3, 0.4)),
                                            SurfacePoint(2000, (0.6, 0.2, 0.2))),
                                           (55, SurfacePoint(4000, (0.1, 0.1, 0.8)))])
def test_path_is_the_reversed_two_call_path(source, target):
    m = mesh("spot.obj")
    p = m.path(source, target)
    d = m.distance(source)
    back = m.geodesic_path(d, target, sources=[source])
    assert np.array_equal(p.points, back.points[::-1])
    assert p.length == back.length
    F, V = m.faces, m.vertices
    xyz = np.einsum("ij,ijk->ik", p.barycentric, V[F[p.faces]])
    assert np.allclose(xyz, p.points, atol=1e-9)
    # faces[i] holds the segment from point i-1: both ends in it
    for i in range(1, len(p)):
        assert set(p.faces[i:i + 1]) == set(back.faces[len(p) - i:len(p) - i + 1])
    if isinstance(source, int):
        assert np.allclose(p.points[0], V[source])


# ---------------------------------------------------------- surface targets
def test_surface_points_as_targets():
    m = mesh("spot.obj")
    pts = [SurfacePoint(10, (0.2, 0.3, 0.5)), 77, SurfacePoint(5000, (1.0, 0.0, 0.0))]
    d = m.distance(3)
    F = m.faces
    want = np.array([0.2 * d[F[10, 0]] + 0.3 * d[F[10, 1]] + 0.5 * d[F[10, 2]], d[77],
                     d[F[5000, 0]]])
    got = m.distance(3, at=pts)
    assert np.allclose(got, want, rtol=1e-15, atol=0)
    D = m.distance_matrix([3, 900], targets=pts, dtype="float64")
    assert D.shape == (2, 3)
    assert np.allclose(D[0], want, rtol=1e-15, atol=0)
    assert np.allclose(D[1], m.distance(900, at=pts), rtol=1e-15, atol=0)
    D32 = m.distance_matrix([3, 900], targets=pts)
    assert D32.dtype == np.float32 and np.allclose(D32, D, rtol=1e-6)
    assert np.allclose(m.distance(3, at=pts, method="exact"),
                       m.distance(3, at=pts, method="exact"))
    with pytest.raises(ValueError, match="barycentric"):
        m.distance(3, at=[SurfacePoint(1, (0.5, 0.6, 0.0))])
    with pytest.raises(ValueError, match="sparse"):
        m.distance_matrix([3], targets=pts, sparse=True, max_distance=1.0)


# ---------------------------------------------------------------- the CLI
def _cli():
    from conftest import find_cli

    path = find_cli()
    if path is None:
        pytest.skip("no meshfmm command line found (set MESHFMM_CLI or build with CMake)")
    return path


def test_cli_info_notes_coincident_vertices(spot_split, tmp_path):
    import json
    import subprocess

    cli = _cli()
    V, F, V2, F2, _ = spot_split
    off = tmp_path / "split.off"
    write_off(off, V2, F2)
    p = subprocess.run([cli, "info", "--json", str(off)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    got = json.loads(p.stdout)
    assert got["coincident_vertices"] == V2.shape[0] - V.shape[0]
    assert got["components"] == 2 and got["welded_components"] == 1
    assert "coincident vertices" in p.stderr and "weld=True" in p.stderr
    p = subprocess.run([cli, "info", str(MESHES / "spot.obj")], capture_output=True, text=True)
    assert p.returncode == 0 and "coincident vertices:   0" in p.stdout and p.stderr == ""


def test_cli_landmarks_equal_python(tmp_path):
    import subprocess

    cli = _cli()
    out = tmp_path / "L.txt"
    p = subprocess.run([cli, "landmarks", str(MESHES / "spot.obj"), "-k", "30", "--start", "12",
                        "-o", str(out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    want, dist = mesh("spot.obj").farthest_point_sampling(30, 12, return_distances=True)
    assert np.array_equal(np.loadtxt(out, dtype=np.int64), want)
    assert f"within {dist.max():.6g}" in p.stderr
    npy = tmp_path / "L.npy"
    p = subprocess.run([cli, "landmarks", str(MESHES / "spot.obj"), "-k", "30", "--start", "12",
                        "-o", str(npy)], capture_output=True, text=True)
    assert p.returncode == 0 and np.array_equal(np.load(npy), want)
    assert np.load(npy).dtype == np.int32
    p = subprocess.run([cli, "landmarks", str(MESHES / "spot.obj"), "-o", str(out)],
                       capture_output=True, text=True)
    assert p.returncode == 2 and "-k" in p.stderr


# ------------------------------------------------------- guards and messages
def test_dense_result_refused_past_a_memory_limit(tmp_path):
    """Under an address-space limit a dense matrix that cannot fit is
    refused before any work, with both sizes; small jobs still run, and
    size_check=False skips the check (numpy's own allocation then fails)."""
    import subprocess
    import sys
    import textwrap

    script = textwrap.dedent(f"""
        import os, resource, meshfmm
        m = meshfmm.Mesh(*meshfmm.load_mesh({str(MESHES / "camelhead.off")!r}))
        size = int(open("/proc/self/statm").read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
        resource.setrlimit(resource.RLIMIT_AS, (size + 300 * 2**20, resource.RLIM_INFINITY))
        assert m.distance_matrix([0, 1], backend="serial").shape == (2, m.n_vertices)
        try:
            m.distance_matrix(backend="serial")
        except MemoryError as e:
            print("REFUSED", e)
        try:
            m.distance_matrix(backend="serial", size_check=False)
        except MemoryError as e:
            print("NUMPY", e)
    """)
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 0, p.stderr
    refused = [ln for ln in p.stdout.splitlines() if ln.startswith("REFUSED")]
    assert refused and "518 MB (11381 x 11381 float32)" in refused[0]
    assert "size_check=False" in refused[0] and "available" in refused[0]
    numpy_line = [ln for ln in p.stdout.splitlines() if ln.startswith("NUMPY")]
    assert numpy_line and "size_check" not in numpy_line[0]


def test_progress_bar_on_stderr(capfd):
    m = mesh("hand_lowres.obj")
    D, info = m.distance_matrix(np.arange(300), progress=True, return_info=True)
    err = capfd.readouterr().err
    assert "distance matrix [" in err and "300/300 (100%)" in err
    assert err.endswith("\n") and f"backend {info.backend}" in err
    assert "falling back" not in err
    m.distance(0, method="exact", progress=True)
    assert "exact solve" in capfd.readouterr().err
    m.distance_matrix([0, 1])
    assert capfd.readouterr().err == ""  # quiet by default
    with pytest.raises(TypeError):
        m.distance_matrix([0], progress="yes")


def test_every_cli_help_lists_every_option():
    import re
    import subprocess

    from conftest import REPO

    cli = _cli()
    for src in sorted((REPO / "src" / "cli").glob("cmd_*.c")):
        sub = src.stem[4:]
        text = src.read_text()
        table = text[text.index("longopts[] = {"):]
        table = table[: table.index("{NULL, 0, NULL, 0}")]
        names = set(re.findall(r'\{"([a-z-]+)",', table))
        if sub == "allpairs":
            names.discard("source")  # a trap for --source, not an option (--sources is)
        if "CLI_SHARED_LONG_OPTIONS" in table:
            names |= {"help", "output", "source", "face-source", "cost", "cost-per-face",
                      "plain-start", "exact-start-radius", "weld", "method"}
        helptext = subprocess.run([cli, sub, "--help"], capture_output=True, text=True).stdout
        missing = [n for n in names if not re.search(rf"--{n}\b", helptext)]
        assert not missing, f"meshfmm {sub} --help lacks {missing}"


def test_pip_allpairs_help_lists_the_zarr_options():
    import subprocess
    import sys

    p = subprocess.run([sys.executable, "-m", "meshfmm", "allpairs", "--help"],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    for word in (".zarr", "--workers", "--resume", "--scheduler", "--no-size-check", ".npz"):
        assert word in p.stdout, word


def test_cli_refuses_a_matrix_larger_than_the_disk(tmp_path):
    import signal
    import subprocess
    import time

    cli = _cli()
    grid = tmp_path / "grid.obj"
    subprocess.run([cli, "generate", "grid", "1000", "-o", str(grid)], check=True)
    out = tmp_path / "D.npy"
    p = subprocess.run([cli, "allpairs", str(grid), "--dtype", "float64", "-o", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 1
    assert "would take 7.31 TiB (1002001 x 1002001 float64)" in p.stderr
    assert "free" in p.stderr and "--no-size-check" in p.stderr
    assert not out.exists() and list(tmp_path.iterdir()) == [grid]
    # the override starts the job (stopped by SIGINT, which removes its file)
    proc = subprocess.Popen([cli, "allpairs", str(grid), "--dtype", "float64", "-o", str(out),
                             "--no-size-check"], stderr=subprocess.PIPE, text=True)
    time.sleep(4)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "would take" not in err
    assert list(tmp_path.iterdir()) == [grid]


def test_weld_drops_collapsed_faces_and_keeps_face_ids():
    """A sliver whose two corners coincide is dropped by welding: face ids
    after it still name the faces given, points in it are refused."""
    n = 6
    xs, ys = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    V = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(n * n)])
    F = []
    for j in range(n - 1):
        for i in range(n - 1):
            a, b, c, d = j * n + i, j * n + i + 1, (j + 1) * n + i, (j + 1) * n + i + 1
            F += [[a, b, d], [a, d, c]]
    F = np.array(F)
    # vertex 36 repeats vertex 7; face 0 becomes a sliver (0, 1, 36 = 7)... and
    # every face after it keeps its id
    V2 = np.vstack([V, V[7]])
    F2 = np.vstack([[[7, 8, 36]], F])
    with pytest.warns(MeshWarning):
        meshfmm.Mesh(V2, F2)
    w = meshfmm.Mesh(V2, F2, weld=True)
    plain = meshfmm.Mesh(V, F)
    assert w.info.n_faces == F.shape[0] and w.n_faces == F.shape[0] + 1
    assert np.array_equal(w.distance(36), plain.distance(7)[np.r_[np.arange(36), 7]])
    with pytest.raises(ValueError, match="dropped"):
        w.distance(SurfacePoint(0, (0.2, 0.3, 0.5)))
    p = w.path(SurfacePoint(5, (0.2, 0.3, 0.5)), 36)
    q = plain.path(SurfacePoint(4, (0.2, 0.3, 0.5)), 7)
    assert np.array_equal(p.points, q.points) and np.array_equal(p.faces, q.faces + 1)
    cost = np.linspace(1, 2, F2.shape[0])
    assert np.array_equal(w.distance(0, cost, cost_location="face"),
                          plain.distance(0, cost[1:], cost_location="face")[np.r_[np.arange(36), 7]])
    d = w.distance(0)
    lines = w.isolines(d, [0.5])[0]
    lines_plain = plain.isolines(plain.distance(0), [0.5])[0]
    assert [np.array_equal(a.faces, b.faces + 1) for a, b in zip(lines, lines_plain)] == [True]
    lab = w.voronoi_labels([0, 36])
    assert lab[36] == 1 and lab[7] == 1 and lab[0] == 0


def test_readme_python_example_runs(tmp_path):
    """The README's Python block, as written, from a folder holding spot.obj."""
    import os
    import re
    import shutil

    from conftest import REPO

    text = (REPO / "README.md").read_text()
    block = re.search(r"## Python.*?```python\n(.*?)```", text, re.S).group(1)
    shutil.copy(MESHES / "spot.obj", tmp_path / "spot.obj")
    here = os.getcwd()
    os.chdir(tmp_path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            exec(compile(block, "README.md", "exec"), {})
    finally:
        os.chdir(here)


def test_cli_weld_writes_the_welded_mesh_and_map(spot_split, tmp_path):
    import subprocess

    cli = _cli()
    V, F, V2, F2, orig = spot_split
    off = tmp_path / "split.off"
    write_off(off, V2, F2)
    out, mp = tmp_path / "welded.obj", tmp_path / "map.npy"
    p = subprocess.run([cli, "weld", str(off), "-o", str(out), "--map", str(mp)],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert f"{V2.shape[0]} vertices, {V.shape[0]} once welded" in p.stderr
    Vw, Fw = meshfmm.load_mesh(out)
    assert np.array_equal(Vw, V) and np.array_equal(Fw, F)  # the original spot back
    python_map = meshfmm.Mesh(V2, F2, weld=True).weld_map
    assert np.array_equal(np.load(mp), python_map) and np.load(mp).dtype == np.int32
    info = subprocess.run([cli, "info", str(out)], capture_output=True, text=True)
    assert "coincident vertices:   0" in info.stdout and info.stderr == ""
    txt = tmp_path / "map.txt"
    p = subprocess.run([cli, "weld", str(off), "-o", str(out), "--map", str(txt)],
                       capture_output=True, text=True)
    assert p.returncode == 0 and np.array_equal(np.loadtxt(txt, dtype=np.int64), orig)


@pytest.mark.parametrize("where", ["vertex", "face"])
def test_fps_with_a_cost_equals_brute_force(where):
    m = mesh("hand_lowres.obj")
    n = m.n_vertices if where == "vertex" else m.n_faces
    cost = 1.0 + 0.5 * np.sin(np.arange(n))
    pts, dist = m.farthest_point_sampling(25, 3, cost=cost, cost_location=where,
                                          return_distances=True)
    dmin = np.full(m.n_vertices, np.inf)
    chosen = [3]
    for i in range(25):
        dmin = np.minimum(dmin, m.distance(chosen[-1], cost, cost_location=where))
        if i < 24:
            cand = dmin.copy()
            cand[chosen] = -1
            chosen.append(int(np.argmax(cand)))
    dmin[chosen] = 0
    assert np.array_equal(pts, chosen) and np.array_equal(dist, dmin)


def test_fps_beyond_the_auto_radius_size_equals_brute_force():
    """Above MFMM_EXACT_START_AUTO_VERTICES a full solve's exact start grows
    with the mesh; the bounded marches keep that radius."""
    n = 215  # 46,656 vertices
    xs, ys = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    z = 0.1 * np.sin(3 * xs) * np.cos(2 * ys)
    V = np.column_stack([xs.ravel(), ys.ravel(), z.ravel()])
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    F = np.concatenate([np.column_stack([a, b, d]), np.column_stack([a, d, c])])
    m = meshfmm.Mesh(V, F)
    assert m.n_vertices > 40000
    pts, radii, dist = m.farthest_point_sampling(6, 1000, return_radii=True,
                                                 return_distances=True)
    ref_pts, ref_radii, ref_dist = brute_fps(m, 6, 1000)
    assert np.array_equal(pts, ref_pts) and np.array_equal(radii, ref_radii)
    assert np.array_equal(dist, ref_dist)
