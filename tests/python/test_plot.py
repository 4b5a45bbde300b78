"""meshfmm.plot and `meshfmm render`: a distance field drawn on its mesh
with isolines and paths into a PNG that is not blank; isolines where the
linear interpolant says."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import meshfmm
from conftest import MESHES, need_data
from test_api import grid

pytest.importorskip("matplotlib", reason="the [plot] extra (pip install 'meshfmm[plot]')")
import meshfmm.plot as plot  # noqa: E402


def picture_stats(path):
    """(height, width, pixel standard deviation, distinct colours) of a PNG."""
    from matplotlib.image import imread

    img = imread(str(path))[..., :3]
    rgb = np.round(img * 255).astype(np.uint8).reshape(-1, 3)
    return img.shape[0], img.shape[1], float(img.std()), len(np.unique(rgb, axis=0))


def assert_not_blank(path, size):
    h, w, std, colours = picture_stats(path)
    assert (w, h) == size
    assert std > 0.05, std          # not one flat colour
    assert colours >= 50, colours   # a colour map, shading, lines


def test_render_a_field_with_isolines_and_a_path(tmp_path):
    need_data()
    mesh = meshfmm.Mesh.from_file(MESHES / "hand_lowres.obj")
    d = mesh.distance(0)
    path = mesh.geodesic_path(d, int(np.argmax(d)), sources=[0])
    out = tmp_path / "hand.png"
    assert plot.render(mesh, d, out, isolines=8, paths=[path, path.points],
                       size=(240, 180), title="hand") == str(out)
    assert_not_blank(out, (240, 180))


def test_render_without_isolines_paths_or_colour_bar(tmp_path):
    V, F = grid(12)
    mesh = meshfmm.Mesh(V, F)
    d = mesh.distance(0, max_distance=0.5)     # unreached vertices: grey faces
    assert np.isinf(d).any()
    out = tmp_path / "g.png"
    plot.render(mesh, d, out, isolines=None, colorbar=False, size=(120, 100),
                view=(0, 0, 1), up=(0, 1, 0))
    assert_not_blank(out, (120, 100))


def test_render_checks_its_arguments(tmp_path):
    mesh = meshfmm.Mesh(*grid(3))
    with pytest.raises(ValueError, match="values for"):
        plot.render(mesh, np.zeros(3), tmp_path / "x.png")
    with pytest.raises(ValueError, match="isolines"):
        plot.render(mesh, np.zeros(mesh.n_vertices), tmp_path / "x.png", isolines=-1)
    with pytest.raises(ValueError, match="direction"):
        plot.render(mesh, np.zeros(mesh.n_vertices), tmp_path / "x.png", view=(0, 0, 0))
    with pytest.raises(TypeError, match="vertices"):
        plot.render(object(), np.zeros(3), tmp_path / "x.png")
    assert not (tmp_path / "x.png").exists()


def test_isoline_segments_follow_the_linear_interpolant():
    rng = np.random.default_rng(7)
    V, F = grid(9)
    V = V + 0.01 * rng.standard_normal(V.shape)
    values = rng.random(V.shape[0])
    values[5] = np.inf                    # faces at an unreached vertex hold no segment
    level = 0.4
    seg, faces = plot.isoline_segments(V, F, values, level)
    assert seg.shape == (faces.shape[0], 2, 3) and faces.shape[0] > 0
    tri = F[faces]
    assert not np.isin(5, tri).any()
    for k in range(faces.shape[0]):
        P = V[tri[k]]
        val = values[tri[k]]
        for p in seg[k]:
            # barycentric coordinates of p in its face (least squares: p is in the plane)
            A = np.vstack([P.T, np.ones(3)])
            b, *_ = np.linalg.lstsq(A, np.append(p, 1.0), rcond=None)
            assert np.all(b > -1e-9) and np.min(b) < 1e-9      # on an edge
            assert abs(b @ val - level) < 1e-9                   # where the interpolant says
    # every face whose corners straddle the level holds one segment, no other
    finite = np.isfinite(values[F]).all(axis=1)
    above = values[F] >= level
    straddle = finite & above.any(axis=1) & ~above.all(axis=1)
    assert sorted(faces.tolist()) == np.nonzero(straddle)[0].tolist()


def test_default_view_looks_along_the_shortest_side():
    V = np.array([[0, 0, 0], [4, 0, 0], [0, 2, 0], [4, 2, 0.1]], float)
    view, up = plot.default_view(V, elevation=0, azimuth=0)
    np.testing.assert_allclose(np.abs(view), [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(up, [0, 1, 0], atol=1e-12)
    view, up = plot.default_view(V)
    assert abs(np.dot(view, up)) < 1e-12 and view[2] > 0.5


def run(args):
    return subprocess.run([sys.executable, "-m", "meshfmm", *args], capture_output=True,
                          text=True, timeout=120)


def test_render_command(tmp_path):
    need_data()
    out = tmp_path / "spot.png"
    proc = run(["render", str(MESHES / "spot.obj"), "--source", "0", "--source", "100",
                "--path-to", "1234", "--isolines", "6", "--size", "200", "160", "-o", str(out)])
    assert proc.returncode == 0, proc.stderr
    assert_not_blank(out, (200, 160))
    proc = run(["render", str(tmp_path / "missing.obj"), "-o", str(tmp_path / "m.png")])
    assert proc.returncode == 2
    assert proc.stderr.startswith("meshfmm render: ") and "missing.obj" in proc.stderr
    assert "Traceback" not in proc.stderr and proc.stderr.count("\n") == 1
    proc = run(["render", str(MESHES / "spot.obj"), "--source", "99999999",
                "-o", str(tmp_path / "b.png")])
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    proc = run(["render", "--help"])
    assert proc.returncode == 0
    for option in ("--source", "--path-to", "--isolines", "--levels", "--method", "--size",
                   "--cmap", "--view", "--up", "--title", "--no-colorbar", "--output"):
        assert option in proc.stdout, option
