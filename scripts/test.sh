#!/usr/bin/env bash
# Sets up the dependencies (scripts/setup.sh --deps-only --wheel: Debian
# packages, .venv, and the wheel's build and test environments), then runs
# every test in a fresh `git clone` of HEAD in a temporary folder with
# nothing beside it, so that a test depending on a file outside the
# repository (or not committed) fails here: the C tests (ctest: cmocka,
# command line, consumer), the C tests again under AddressSanitizer and
# UndefinedBehaviorSanitizer, the tests that run threads under
# ThreadSanitizer, the Python tests (pytest) against the clone's
# library, and the wheel (scripts/build_wheel.sh: built with the OpenCL
# backend, repaired to a manylinux tag, installed into the clean .venv-wheel
# and the Python tests run there against it). After the C tests, the product
# checks (scripts/check_product_text.py: no issue numbers or work-log text;
# scripts/check_rooms.py: the rooms of src/ depend downward) and the
# documentation (mkdocs build --strict: a broken link, or a page missing
# from the navigation, fails). The clone's builds are the only builds (no
# duplicate in place). Outside a git checkout it runs in place.
# Last, a short run of every libFuzzer harness (tests/fuzz; a crash fails
# the run; a fixed seed, so that a red run is reproduced by running it again:
# tests/fuzz/run.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$PWD
bash scripts/setup.sh --deps-only --wheel
jobs=$(nproc 2>/dev/null || echo 2)

if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    if [ -n "$(git status --porcelain --untracked-files=no)" ]; then
        echo "test: note: uncommitted changes are not tested (the clone has HEAD only)" >&2
    fi
    tmp=$(mktemp -d)
    trap 'rm -rf "$tmp"' EXIT
    git clone -q --no-local "$repo" "$tmp/meshfmm"
    # the environment, not sources: the venv setup.sh made
    ln -s "$repo/.venv" "$tmp/meshfmm/.venv"
    ln -s "$repo/.venv-wheel" "$tmp/meshfmm/.venv-wheel"
    ln -s "$repo/.venv-wheel-build" "$tmp/meshfmm/.venv-wheel-build"
    cd "$tmp/meshfmm"
    echo "== testing a clean clone of $(git rev-parse --short HEAD) in $PWD"
fi

echo "== C tests (ctest, Release)"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DMESHFMM_BUILD_BENCH=OFF >/dev/null
cmake --build build -j"$jobs" >/dev/null
ctest --test-dir build --output-on-failure -j"$jobs"

echo "== Product checks"
python3 scripts/check_product_text.py
python3 scripts/check_rooms.py

echo "== Documentation (mkdocs build --strict)"
# the command-line page runs this build's meshfmm; the site goes into build/
MESHFMM_CLI="$PWD/build/meshfmm" MESHFMM_LIBRARY="$PWD/build/libmeshfmm.so" \
PYTHONPATH="$PWD/bindings/python" NO_MKDOCS_2_WARNING=1 \
    .venv/bin/mkdocs build --strict --quiet -d "$PWD/build/site"

echo "== C tests under AddressSanitizer + UndefinedBehaviorSanitizer"
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=Debug -DMESHFMM_SANITIZE=ON \
      -DMESHFMM_BUILD_BENCH=OFF >/dev/null
cmake --build build-sanitize -j"$jobs" >/dev/null
ASAN_OPTIONS=detect_leaks=1 ctest --test-dir build-sanitize --output-on-failure -j"$jobs"

echo "== Threaded C tests under ThreadSanitizer"
cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMESHFMM_TSAN=ON \
      -DMESHFMM_BUILD_BENCH=OFF >/dev/null
cmake --build build-tsan -j"$jobs" >/dev/null
TSAN_OPTIONS=halt_on_error=1 ctest --test-dir build-tsan --output-on-failure -j"$jobs" \
    -R '^test_(matrix|exact|exact_start|windows|slots|spokes|solve|workflows|shared_meshes|job_inputs)$'

echo "== Python tests (pytest, against this tree's build)"
MESHFMM_LIBRARY="$PWD/build/libmeshfmm.so" PYTHONPATH="$PWD/bindings/python" \
MESHFMM_CLI="$PWD/build/meshfmm" .venv/bin/python -m pytest tests/python -q -p no:cacheprovider

echo "== Wheel (scripts/build_wheel.sh: manylinux, OpenCL in, tested in a clean venv)"
bash scripts/build_wheel.sh build/wheelhouse

echo "== Fuzzing (libFuzzer harnesses of tests/fuzz, ${MESHFMM_FUZZ_SECONDS:-15} s each)"
if command -v clang >/dev/null 2>&1; then
    cmake -S . -B build-fuzz -DCMAKE_C_COMPILER=clang -DMESHFMM_BUILD_FUZZ=ON \
          -DMESHFMM_BUILD_TESTS=OFF -DMESHFMM_BUILD_BENCH=OFF -DMESHFMM_BUILD_CLI=OFF >/dev/null
    cmake --build build-fuzz -j"$jobs" >/dev/null
    bash tests/fuzz/run.sh build-fuzz "${MESHFMM_FUZZ_SECONDS:-15}"
else
    echo "no clang: fuzzing skipped (scripts/setup.sh installs it)"
fi
