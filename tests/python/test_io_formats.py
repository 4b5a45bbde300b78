"""meshfmm.load_mesh goes through the C loader: STL (binary and ascii, welded),
unsupported formats named, files that are not regular refused, and number
parsing that does not depend on the locale."""
import os
import struct
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import meshfmm

SQUARE_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64)
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32)


def _binary_stl(path, header=b"binary"):
    facets = [SQUARE_V[f] for f in SQUARE_F]
    with open(path, "wb") as fh:
        fh.write(header.ljust(80, b"\0"))
        fh.write(struct.pack("<I", len(facets)))
        for tri in facets:
            fh.write(struct.pack("<3f", 0, 0, 1))
            fh.write(struct.pack("<9f", *tri.ravel()))
            fh.write(b"\0\0")


def _ascii_stl(path):
    lines = ["solid square"]
    for f in SQUARE_F:
        lines += ["  facet normal 0 0 1", "    outer loop"]
        lines += ["      vertex %.17g %.17g %.17g" % tuple(SQUARE_V[i]) for i in f]
        lines += ["    endloop", "  endfacet"]
    lines.append("endsolid square")
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")


@pytest.mark.parametrize("kind", ["binary", "binary-solid-header", "ascii"])
def test_stl_loads_welded(tmp_path, kind):
    path = tmp_path / "square.stl"
    if kind == "ascii":
        _ascii_stl(path)
    else:
        _binary_stl(path, b"solid looks ascii" if kind == "binary-solid-header" else b"bin")
    V, F = meshfmm.load_mesh(path)
    np.testing.assert_array_equal(V, SQUARE_V)
    np.testing.assert_array_equal(F, SQUARE_F)
    # and the mesh works: the square's diagonal
    d = meshfmm.Mesh(V, F).distance(0)
    assert d[2] == pytest.approx(np.sqrt(2), rel=1e-12)


def test_stl_truncated_is_an_error(tmp_path):
    path = tmp_path / "cut.stl"
    _binary_stl(path)
    data = path.read_bytes()
    path.write_bytes(data[:-10])
    with pytest.raises(meshfmm.MeshError, match="84 \\+ 50 n"):
        meshfmm.load_mesh(path)


@pytest.mark.parametrize("ext", ["gltf", "glb", "3ds", "fbx", "dae"])
def test_unsupported_format_named(tmp_path, ext):
    path = tmp_path / ("model." + ext)
    path.write_bytes(b'{"asset": {"version": "2.0"}}')
    with pytest.raises(meshfmm.MeshError, match="OBJ, OFF, PLY .* and STL"):
        meshfmm.load_mesh(path)


def test_not_regular_files_refused(tmp_path):
    with pytest.raises(OSError, match="directory"):
        meshfmm.load_mesh(tmp_path)
    if os.path.exists("/dev/zero"):
        with pytest.raises(OSError, match="character device"):
            meshfmm.load_mesh("/dev/zero")
    fifo = tmp_path / "pipe.obj"
    os.mkfifo(fifo)
    with pytest.raises(OSError, match="FIFO"):
        meshfmm.load_mesh(fifo)  # opening a FIFO for reading would block


def _comma_locale_env(tmp_path):
    """An environment where de_DE.UTF-8 can be set: installed, or built by
    localedef into tmp_path (LOCPATH); None when neither works."""
    env = dict(os.environ)
    probe = "import locale; locale.setlocale(locale.LC_ALL, 'de_DE.UTF-8')"
    if subprocess.run([sys.executable, "-c", probe], env=env).returncode == 0:
        return env
    try:
        subprocess.run(
            ["localedef", "-i", "de_DE", "-f", "UTF-8", str(tmp_path / "de_DE.UTF-8")],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            timeout=120,
        )
    except (OSError, subprocess.TimeoutExpired):
        return None
    env["LOCPATH"] = str(tmp_path)
    if subprocess.run([sys.executable, "-c", probe], env=env).returncode == 0:
        return env
    return None


def test_load_under_decimal_comma_locale(tmp_path):
    env = _comma_locale_env(tmp_path)
    if env is None:
        pytest.skip("no de_DE.UTF-8 locale and localedef cannot make one (Debian: locales)")
    (tmp_path / "m.obj").write_text("v 0.5 0 0\nv 1.25 0 0\nv 0 1e-1 0.75\nf 1 2 3\n")
    (tmp_path / "m.off").write_text("OFF\n3 1 0\n0.5 0 0\n1.25 0 0\n0 1e-1 0.75\n3 0 1 2\n")
    (tmp_path / "m.ply").write_text(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property double z\nelement face 1\nproperty list uchar int vertex_indices\n"
        "end_header\n0.5 0 0\n1.25 0 0\n0 0.1 0.75\n3 0 1 2\n"
    )
    script = textwrap.dedent(
        """
        import locale, sys
        locale.setlocale(locale.LC_ALL, "de_DE.UTF-8")
        assert locale.localeconv()["decimal_point"] == ","
        import meshfmm
        for name in ("m.obj", "m.off", "m.ply"):
            V, F = meshfmm.load_mesh(sys.argv[1] + "/" + name)
            assert V.tolist() == [[0.5, 0, 0], [1.25, 0, 0], [0, 0.1, 0.75]], (name, V)
            assert F.tolist() == [[0, 1, 2]], (name, F)
        print("ok")
        """
    )
    r = subprocess.run(
        [sys.executable, "-c", script, str(tmp_path)], env=env, capture_output=True, text=True
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "ok"
