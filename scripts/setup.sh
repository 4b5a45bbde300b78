#!/usr/bin/env bash
# Installs everything meshfmm needs on Debian (as root), builds the C library,
# command line, tests and benchmarks into build/, and installs the Python
# package into .venv/. Safe to run again: it only does what is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential cmake pkg-config python3 python3-venv python3-dev
          pocl-opencl-icd ocl-icd-opencl-dev opencl-headers clinfo libcmocka-dev
          clang locales)
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
.venv/bin/python -m pip install -q --upgrade pip >/dev/null
.venv/bin/python -m pip install -q -r requirements-dev.txt

jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs" >/dev/null
echo "setup: built build/ (library, meshfmm command, tests, benchmarks)"

.venv/bin/python -m pip install -q . >/dev/null
echo "setup: installed the meshfmm Python package into .venv"
