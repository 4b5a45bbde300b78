#!/usr/bin/env bash
# Sets everything up (scripts/setup.sh), then runs every test: the C tests
# (ctest), the C tests again under AddressSanitizer and
# UndefinedBehaviorSanitizer, the Python tests (pytest), and a short run of
# every libFuzzer harness (tests/fuzz; a crash fails the run).
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

echo "== Fuzzing (libFuzzer harnesses of tests/fuzz, ${MESHFMM_FUZZ_SECONDS:-15} s each)"
if command -v clang >/dev/null 2>&1; then
    cmake -S . -B build-fuzz -DCMAKE_C_COMPILER=clang -DMESHFMM_BUILD_FUZZ=ON \
          -DMESHFMM_BUILD_TESTS=OFF -DMESHFMM_BUILD_BENCH=OFF -DMESHFMM_BUILD_CLI=OFF >/dev/null
    cmake --build build-fuzz -j"$jobs" >/dev/null
    bash tests/fuzz/run.sh build-fuzz "${MESHFMM_FUZZ_SECONDS:-15}"
else
    echo "no clang: fuzzing skipped (scripts/setup.sh installs it)"
fi
