#!/usr/bin/env bash
# Sets everything up (scripts/setup.sh), then runs every test: the C tests
# (ctest), the C tests again under AddressSanitizer and
# UndefinedBehaviorSanitizer, and the Python tests (pytest).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
jobs=$(nproc 2>/dev/null || echo 2)

echo "== C tests (ctest, Release)"
ctest --test-dir build --output-on-failure -j"$jobs"

echo "== C tests under AddressSanitizer + UndefinedBehaviorSanitizer"
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=Debug -DMESHFMM_SANITIZE=ON \
      -DMESHFMM_BUILD_BENCH=OFF >/dev/null
cmake --build build-sanitize -j"$jobs" >/dev/null
ASAN_OPTIONS=detect_leaks=1 ctest --test-dir build-sanitize --output-on-failure -j"$jobs"

echo "== Python tests (pytest)"
MESHFMM_CLI="$PWD/build/meshfmm" .venv/bin/python -m pytest tests/python -q
