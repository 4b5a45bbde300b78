"""The workflow commands against the Python API and the unsplit mesh:
--weld on distance, path, allpairs, landmarks and voronoi (a mesh split at
a seam gives the unsplit mesh's values, in the split file's ids), paths
written from the source, `meshfmm voronoi` against the argmin over
single-source fields, `meshfmm isolines` against the linear interpolant,
and the C and Python helps listing the same commands."""

from __future__ import annotations

import io
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

import meshfmm
from conftest import MESHES, load, mesh
from meshfmm import SurfacePoint
from meshfmm_testing import write_off
from test_api import grid
from test_workflows import split_at_x


def _cli():
    from conftest import find_cli

    path = find_cli()
    if path is None:
        pytest.skip("no meshfmm command line found (set MESHFMM_CLI or build with CMake)")
    return path


def run(*args, ok=True):
    p = subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=300)
    if ok:
        assert p.returncode == 0, p.stderr
    return p


def py(*args, ok=True):
    return run(sys.executable, "-m", "meshfmm", *args, ok=ok)


def plain(V, F):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", meshfmm.MeshWarning)
        return meshfmm.Mesh(V, F)


def read_path_csv(text):
    a = np.loadtxt(io.StringIO(text), delimiter=",", skiprows=1, ndmin=2)
    return a[:, 0].astype(np.int64), a[:, 1:4], a[:, 4:7]


@pytest.fixture(scope="module")
def spot_split(tmp_path_factory):
    """spot.obj cut at x = 0 (the copies of the cut's vertices appended),
    written as OFF: welded, it is spot again, numbered as spot."""
    V, F = load("spot.obj")
    V2, F2, orig = split_at_x(V, F)
    off = tmp_path_factory.mktemp("split") / "split.off"
    write_off(off, V2, F2)
    return V, F, V2, F2, orig, off


@pytest.fixture(scope="module")
def grid_split(tmp_path_factory):
    V, F = grid(10)
    V2, F2, orig = split_at_x(V, F, 0.45)
    off = tmp_path_factory.mktemp("gsplit") / "grid.off"
    write_off(off, V2, F2)
    return V, F, V2, F2, orig, off


# ------------------------------------------------------------------ --weld
def test_distance_weld_gives_the_unsplit_values(spot_split, tmp_path):
    cli = _cli()
    V, F, V2, F2, orig, off = spot_split
    base = mesh("spot.obj")
    copy = V.shape[0] + 3              # a copy of vertex orig[copy]
    s = int(orig[copy])
    out = tmp_path / "d.npy"
    # unwelded, the cut is a wall: the other side is unreached
    run(cli, "distance", off, "--source", copy, "-o", out)
    assert np.isinf(np.load(out)).any()
    run(cli, "distance", off, "--weld", "--source", copy, "-o", out)
    d = np.load(out)
    assert d.shape == (V2.shape[0],) and np.array_equal(d, base.distance(s)[orig])
    # the same from the Python package's weld=True
    assert np.array_equal(d, meshfmm.Mesh(V2, F2, weld=True).distance(copy))
    # exact, a face source (the file's face ids), a per-vertex cost of the file's size
    run(cli, "distance", off, "--weld", "--source", copy, "--exact", "-o", out)
    assert np.array_equal(np.load(out), base.distance(s, method="exact")[orig])
    fs = SurfacePoint(4000, (0.2, 0.3, 0.5))
    run(cli, "distance", off, "--weld", "--face-source", 4000, 0.2, 0.3, 0.5, "-o", out)
    assert np.array_equal(np.load(out), base.distance(fs)[orig])
    cost = np.linspace(1, 2, V2.shape[0])
    np.save(tmp_path / "cost.npy", cost)
    run(cli, "distance", off, "--weld", "--source", copy, "--cost", tmp_path / "cost.npy",
        "-o", out)
    assert np.array_equal(np.load(out), base.distance(s, cost[:V.shape[0]])[orig])
    fcost = np.linspace(1, 3, F2.shape[0])
    np.savetxt(tmp_path / "fcost.txt", fcost)
    run(cli, "distance", off, "--weld", "--source", copy, "--cost", tmp_path / "fcost.txt",
        "--cost-per-face", "-o", out)
    assert np.array_equal(np.load(out), base.distance(s, fcost, cost_location="face")[orig])
    # ids are the file's: its last vertex is in range, one past it is not
    p = run(cli, "distance", off, "--weld", "--source", V2.shape[0], "-o", out, ok=False)
    assert p.returncode == 1 and f"outside [0, {V2.shape[0]})" in p.stderr


def test_path_weld_gives_the_unsplit_path(spot_split, tmp_path):
    cli = _cli()
    V, F, V2, F2, orig, off = spot_split
    base = mesh("spot.obj")
    copy, t = V.shape[0] + 3, V.shape[0] + 40
    p = run(cli, "path", off, "--weld", "--source", copy, "--target", t, "-o", "-")
    faces, bary, xyz = read_path_csv(p.stdout)
    want = base.path(int(orig[copy]), int(orig[t]))
    assert np.array_equal(xyz, want.points) and np.array_equal(faces, want.faces)
    assert np.allclose(bary, want.barycentric, rtol=0, atol=1e-12)
    assert float(p.stderr.split()[0]) == pytest.approx(want.length, rel=1e-15)
    # the split mesh unwelded: the target is beyond the cut
    far = int(np.flatnonzero(np.isinf(plain(V2, F2).distance(copy)))[0])
    p = run(cli, "path", off, "--source", copy, "--target", far, "-o", tmp_path / "p.csv",
            ok=False)
    assert p.returncode == 1 and "reached" in p.stderr
    p = run(cli, "path", off, "--weld", "--source", copy, "--target", far, "-o", "-")
    assert np.array_equal(read_path_csv(p.stdout)[2],
                          base.path(int(orig[copy]), int(orig[far])).points)


def test_allpairs_weld_gives_the_unsplit_matrix(grid_split, tmp_path):
    """Every row and column in the file's ids, dense and sparse, with
    --sources and --targets in the file's ids too."""
    cli = _cli()
    V, F, V2, F2, orig, off = grid_split
    base = meshfmm.Mesh(V, F)
    n2 = V2.shape[0]
    assert n2 > V.shape[0]
    full = base.distance_matrix(backend="serial", dtype="float64")
    out = tmp_path / "D.npy"
    run(cli, "allpairs", off, "--weld", "--dtype", "float64", "--backend", "serial", "-o", out,
        "--quiet")
    D = np.load(out)
    assert D.shape == (n2, n2) and np.array_equal(D, full[np.ix_(orig, orig)])
    run(cli, "allpairs", off, "--weld", "--backend", "threads", "-o", out, "--quiet")
    assert np.array_equal(np.load(out), full.astype(np.float32)[np.ix_(orig, orig)])
    src, tgt = tmp_path / "s.txt", tmp_path / "t.npy"
    rows, cols = [n2 - 1, 0, 17], [n2 - 2, 3, n2 - 1, 3]
    src.write_text(" ".join(map(str, rows)))
    np.save(tgt, np.array(cols, dtype=np.int32))
    run(cli, "allpairs", off, "--weld", "--dtype", "float64", "--sources", src, "--targets",
        tgt, "-o", out, "--quiet")
    assert np.array_equal(np.load(out), full[np.ix_(orig[rows], orig[cols])])
    scipy_sparse = pytest.importorskip("scipy.sparse")
    r = 0.3
    npz = tmp_path / "S.npz"
    run(cli, "allpairs", off, "--weld", "--dtype", "float64", "--max-distance", r, "-o", npz,
        "--quiet")
    S = scipy_sparse.load_npz(npz)
    assert S.shape == (n2, n2) and S.has_sorted_indices
    want = full[np.ix_(orig, orig)]
    assert np.array_equal(S.toarray()[want <= r], want[want <= r])
    within = want <= r
    assert S.nnz == within.sum()
    # an unwelded allpairs of the split file differs (the cut is a wall)
    run(cli, "allpairs", off, "--dtype", "float64", "-o", out, "--quiet")
    assert np.isinf(np.load(out)).any()


def test_landmarks_weld(spot_split, tmp_path):
    cli = _cli()
    V, F, V2, F2, orig, off = spot_split
    base = mesh("spot.obj")
    copy = V.shape[0] + 3
    out = tmp_path / "L.txt"
    p = run(cli, "landmarks", off, "--weld", "-k", 12, "--start", copy, "-o", out)
    want, dist = base.farthest_point_sampling(12, int(orig[copy]), return_distances=True)
    assert np.array_equal(np.loadtxt(out, dtype=np.int64), want)  # the lowest file ids
    assert f"within {dist.max():.6g}" in p.stderr and "unreached" not in p.stderr


def test_voronoi_weld(spot_split, tmp_path):
    cli = _cli()
    V, F, V2, F2, orig, off = spot_split
    base = mesh("spot.obj")
    copy = V.shape[0] + 3
    lab = tmp_path / "lab.npy"
    run(cli, "voronoi", off, "--weld", "--source", copy, "--source", 1500, "-o", lab)
    assert np.array_equal(np.load(lab), base.voronoi_labels([int(orig[copy]), 1500])[orig])


# ------------------------------------------------------------------- path
@pytest.mark.parametrize("source,target", [
    ((77,), (1500,)),
    (("face", 100, 0.3, 0.3, 0.4), ("face", 2000, 0.6, 0.2, 0.2)),
    ((55,), ("face", 4000, 0.1, 0.1, 0.8)),
])
def test_path_runs_from_the_source_to_the_target(source, target, tmp_path):
    """`meshfmm path` writes Python's Mesh.path(source, target): the
    reversed two-call path, source first."""
    cli = _cli()
    m = mesh("spot.obj")

    def point(x):
        return x[0] if len(x) == 1 else SurfacePoint(x[1], x[2:])

    def args(x, kind):
        if len(x) == 1:
            return [f"--{kind}", x[0]]
        return [f"--{kind}-face" if kind == "target" else "--face-source", *x[1:]]

    cmd = [cli, "path", MESHES / "spot.obj", *args(source, "source"), *args(target, "target")]
    p = run(*cmd, "-o", "-")
    faces, bary, xyz = read_path_csv(p.stdout)
    want = m.path(point(source), point(target))
    back = m.geodesic_path(m.distance(point(source)), point(target), sources=[point(source)])
    assert np.array_equal(xyz, want.points) and np.array_equal(xyz, back.points[::-1])
    assert np.array_equal(faces, want.faces)
    assert np.allclose(bary, want.barycentric, rtol=0, atol=1e-12)
    # every point in its face where its coordinates say
    FV = m.vertices[m.faces[faces]]
    assert np.allclose(np.einsum("ij,ijk->ik", bary, FV), xyz, rtol=0, atol=1e-12)
    if len(source) == 1:
        assert np.array_equal(xyz[0], m.vertices[source[0]])
    if len(target) == 1:
        assert np.array_equal(xyz[-1], m.vertices[target[0]])
    obj = tmp_path / "p.obj"
    run(*cmd, "-o", obj)
    text = obj.read_text()
    assert "source first" in text
    v = np.array([[float(x) for x in ln.split()[1:]] for ln in text.splitlines()
                  if ln.startswith("v ")])
    assert np.array_equal(v, want.points)


# ---------------------------------------------------------------- voronoi
def test_voronoi_command_equals_the_argmin_of_single_fields(tmp_path):
    """Labels from landmarks (--sources FILE, the output of `meshfmm
    landmarks`): Python's voronoi_labels exactly, the argmin over the
    single-source fields but within an edge of a cell's border."""
    cli = _cli()
    m = mesh("spot.obj")
    L = tmp_path / "L.txt"
    run(cli, "landmarks", MESHES / "spot.obj", "-k", 8, "-o", L)
    ids = np.loadtxt(L, dtype=np.int64)
    lab, dist = tmp_path / "lab.npy", tmp_path / "d.npy"
    p = run(cli, "voronoi", MESHES / "spot.obj", "--sources", L, "--distances", dist, "-o", lab)
    labels = np.load(lab)
    assert labels.dtype == np.int32 and labels.shape == (m.n_vertices,)
    assert np.array_equal(labels, m.voronoi_labels(ids.tolist()))
    assert np.array_equal(np.load(dist), m.distance(ids.tolist()))
    assert f"{m.n_vertices} vertices in 8 cells of 8 sources" in p.stderr
    fields = np.stack([m.distance(int(s)) for s in ids])
    best = np.argmin(fields, axis=0)
    srt = np.sort(fields, axis=0)
    wrong = labels != best
    assert wrong.sum() <= 0.01 * m.n_vertices
    assert np.all(srt[1][wrong] - srt[0][wrong] < m.info.mean_edge_length)
    assert np.array_equal(labels[ids], np.arange(8))
    # --source before --sources in the numbering; text output; a radius
    txt = tmp_path / "lab.txt"
    run(cli, "voronoi", MESHES / "spot.obj", "--source", 5, "--sources", L, "--max-distance",
        0.2, "--exact-start-radius", 0, "-o", txt)
    got = np.loadtxt(txt, dtype=np.int64)
    d = m.distance([5, *ids.tolist()], max_distance=0.2, exact_start=0)
    assert np.array_equal(got == -1, np.isinf(d)) and (got == -1).any()
    assert np.array_equal(got, m.voronoi_labels([5, *ids.tolist()], d))
    # exact distances
    run(cli, "voronoi", MESHES / "spot.obj", "--source", 0, "--source", 2000, "--exact",
        "-o", lab)
    assert np.array_equal(np.load(lab), m.voronoi_labels([0, 2000], method="exact"))


# --------------------------------------------------------------- isolines
def parse_obj_polylines(text):
    """{object name: [polyline as (k, 3) points]} of an OBJ of v/l records."""
    verts, objects, name = [], {}, None
    for ln in text.splitlines():
        if ln.startswith("o "):
            name = ln.split()[1]
            objects[name] = []
        elif ln.startswith("v "):
            verts.append([float(x) for x in ln.split()[1:]])
        elif ln.startswith("l "):
            ids = [int(x) - 1 for x in ln.split()[1:]]
            objects[name].append(np.array(verts)[ids])
    return objects


def test_isolines_command_writes_mesh_isolines(tmp_path):
    m = mesh("spot.obj")
    d = m.distance([0, 1700])
    values = [0.1, 0.35, 0.6]
    lines = m.isolines(d, values)
    out = tmp_path / "iso.obj"
    p = py("isolines", MESHES / "spot.obj", "--source", 0, "--source", 1700, "--values",
           "0.1,0.35,0.6", "-o", out)
    n = sum(len(x) for x in lines)
    assert f"({n} polylines at 3 values)" in p.stdout
    objs = parse_obj_polylines(out.read_text())
    assert list(objs) == ["isoline_0", "isoline_1", "isoline_2"]
    for j, want in enumerate(lines):
        got = objs[f"isoline_{j}"]
        assert len(got) == len(want) > 0
        for g, w in zip(got, want):
            assert np.array_equal(g, w.points)  # a closed line ends at its first vertex
    # CSV: every point where the linear interpolant over its face is the value
    csv = tmp_path / "iso.csv"
    py("isolines", MESHES / "spot.obj", "--source", 0, "--source", 1700, "--values",
       "0.1,0.35,0.6", "-o", csv)
    a = np.loadtxt(csv, delimiter=",", skiprows=1)
    faces = a[:, 3].astype(np.int64)
    interp = (a[:, 4:7] * d[m.faces[faces]]).sum(axis=1)
    assert np.allclose(interp, a[:, 0], rtol=0, atol=1e-12)
    xyz = np.einsum("ij,ijk->ik", a[:, 4:7], m.vertices[m.faces[faces]])
    assert np.allclose(xyz, a[:, 7:10], rtol=0, atol=1e-12)
    assert a.shape[0] == sum(len(ln) for x in lines for ln in x)
    # a field from a file: the same lines
    np.save(tmp_path / "d.npy", d)
    py("isolines", MESHES / "spot.obj", "--field", tmp_path / "d.npy", "--values",
       "0.1,0.35,0.6", "-o", tmp_path / "f.csv")
    assert (tmp_path / "f.csv").read_text() == csv.read_text()


def test_isolines_command_weld_and_errors(spot_split, tmp_path):
    V, F, V2, F2, orig, off = spot_split
    base = mesh("spot.obj")
    copy = V.shape[0] + 3
    want = base.isolines(base.distance(int(orig[copy])), [0.3])[0]
    csv = tmp_path / "w.csv"
    py("isolines", off, "--weld", "--source", copy, "--values", "0.3", "-o", csv)
    a = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert np.array_equal(a[:, 7:10], np.concatenate([ln.points for ln in want]))
    assert np.array_equal(a[:, 3], np.concatenate([ln.faces for ln in want]))
    p = py("isolines", off, "--source", copy, "--values", "0.3", "-o", csv)
    assert "coincident vertices" in p.stderr and "--weld" in p.stderr
    for args, words in [
        ([MESHES / "spot.obj", "--values", "0.3", "-o", tmp_path / "x.obj"], "no source"),
        ([MESHES / "spot.obj", "--source", 0, "--values", "a", "-o", tmp_path / "x.obj"],
         "--values"),
        ([MESHES / "spot.obj", "--source", 0, "--values", "1", "-o", tmp_path / "x.png"],
         ".obj or .csv"),
        ([tmp_path / "missing.obj", "--source", 0, "--values", "1", "-o", tmp_path / "x.obj"],
         "missing.obj"),
        ([MESHES / "spot.obj", "--source", 99999, "--values", "1", "-o", tmp_path / "x.obj"],
         "99999"),
    ]:
        p = py("isolines", *args, ok=False)
        assert p.returncode == 2 and p.stderr.startswith("meshfmm isolines: "), p.stderr
        assert words in p.stderr and p.stderr.count("\n") == 1
    assert not (tmp_path / "x.obj").exists()
    p = py("isolines", "--help")
    for option in ("--output", "--values", "--source", "--sources", "--field", "--method",
                   "--max-distance", "--cost", "--cost-per-face", "--weld"):
        assert option in p.stdout, option


# ----------------------------------------------------------------- helps
def test_c_and_python_helps_list_the_same_commands():
    """The C command's --help lists the Python package's commands with the
    lines the package gives them; each runs through python -m meshfmm, and
    the C command points there; the docs page gets a section for each."""
    from meshfmm.__main__ import PYTHON_COMMANDS

    cli = _cli()
    top = run(cli, "--help").stdout
    section = top[top.index("python commands"):]
    for name, line in PYTHON_COMMANDS.items():
        assert f"  {name:<10} {line}\n" in section
        assert py(name, "--help").stdout.startswith(f"usage: meshfmm {name}")
        p = run(cli, name, "x", ok=False)
        assert p.returncode == 2 and f"python -m meshfmm {name}" in p.stderr
    assert "python -m meshfmm" in top
    import importlib.util

    from conftest import REPO

    spec = importlib.util.spec_from_file_location("docs_cli_hook",
                                                  REPO / "docs" / "hooks" / "cli.py")
    hook = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hook)
    assert hook._commands(top, "python commands") == list(PYTHON_COMMANDS)
    c_commands = hook._commands(top)
    assert "voronoi" in c_commands and not set(c_commands) & set(PYTHON_COMMANDS)
    # the pip-installed command runs the C help: the same text
    assert py("--help").stdout == top


def test_python_help_without_the_binary_lists_its_commands(tmp_path):
    from meshfmm.__main__ import PYTHON_COMMANDS

    env = {k: v for k, v in os.environ.items() if k != "MESHFMM_CLI"}
    probe = subprocess.run([sys.executable, "-c", "from meshfmm.__main__ import cli_path; "
                            "print(cli_path())"], capture_output=True, text=True, env=env)
    if probe.stdout.strip() != "None":
        pytest.skip("the package holds its own binary")
    p = subprocess.run([sys.executable, "-m", "meshfmm", "--help"], capture_output=True,
                       text=True, env=env)
    assert p.returncode == 0
    for name in PYTHON_COMMANDS:
        assert f"  {name} " in p.stdout
