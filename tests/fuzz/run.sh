#!/usr/bin/env bash
# Runs every libFuzzer harness built in BUILD_DIR for SECONDS each on a copy
# of its seed corpus (tests/fuzz/corpus/<name>) with its dictionary. A crash,
# sanitizer report, timeout or broken invariant fails the run; the input that
# caused it is copied to tests/fuzz/regressions/<name>/ (commit it: ctest
# replays it in every build from then on).
#   tests/fuzz/run.sh BUILD_DIR [SECONDS] [HARNESS...]
# The random seed is fixed (MESHFMM_FUZZ_SEED, default 1): a tree runs the
# same inputs again as far as its time allows, so a red CI run is reproduced
# by running it again; CI is the gate, the search for new inputs is longer
# runs with other seeds (MESHFMM_FUZZ_SEED=0: a new one each run).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:?usage: run.sh BUILD_DIR [SECONDS] [HARNESS...]}
secs=${2:-20}
seed=${MESHFMM_FUZZ_SEED:-1}
shift 2 2>/dev/null || shift $#
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
    for f in "$build"/tests/fuzz/fuzz_*; do
        [ -x "$f" ] && names+=("$(basename "$f" | sed 's/^fuzz_//')")
    done
fi
[ ${#names[@]} -gt 0 ] || { echo "run.sh: no fuzz_* harness in $build/tests/fuzz"; exit 1; }
work=$(mktemp -d "${TMPDIR:-/tmp}/mfmm_fuzz.XXXXXX")
trap 'rm -rf "$work"' EXIT
export MESHFMM_CACHE_DIR="$work/cl_cache"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export LSAN_OPTIONS="suppressions=$here/../c/lsan_opencl.supp:print_suppressions=0"
failed=0
for name in "${names[@]}"; do
    bin="$build/tests/fuzz/fuzz_$name"
    dict=
    case $name in
        mesh_obj) dict=obj ;; mesh_off) dict=off ;; mesh_ply) dict=ply ;; mesh_stl) dict=stl ;;
        mesh_sniff) dict=sniff ;; number) dict=number ;; cli_vectors) dict=cli_vectors ;;
    esac
    t=$secs
    case $name in solve_opencl) t=$(( secs * 3 / 4 )) ;; esac  # slow to start; a short run
    mkdir -p "$work/$name/corpus" "$work/$name/artifacts"
    cp "$here/corpus/$name"/* "$work/$name/corpus/" 2>/dev/null
    args=(-max_total_time="$t" -timeout=10 -rss_limit_mb=2048 -max_len=4096
          -artifact_prefix="$work/$name/artifacts/" -print_final_stats=1 -seed="$seed")
    [ -n "$dict" ] && args+=(-dict="$here/dict/$dict.dict")
    [ "$name" = cli_vectors ] && args+=(-close_fd_mask=2)  # the readers' messages
    "$bin" "${args[@]}" "$work/$name/corpus" >"$work/$name/log" 2>&1
    rc=$?
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$work/$name/log" | grep -o '[0-9]*$')
    cov=$(grep -o 'cov: [0-9]*' "$work/$name/log" | tail -1)
    if [ $rc -ne 0 ]; then
        failed=1
        echo "FUZZ FAIL $name (exit $rc, seed $seed): $(grep -m1 -E 'ERROR|SUMMARY|runtime error|deadly signal' "$work/$name/log")"
        tail -40 "$work/$name/log"
        mkdir -p "$here/regressions/$name"
        for a in "$work/$name/artifacts"/*; do
            [ -f "$a" ] && cp "$a" "$here/regressions/$name/" && echo "  kept $here/regressions/$name/$(basename "$a")"
        done
    else
        echo "fuzz $name: ok, ${runs:-?} inputs in ${t} s (seed $seed), ${cov:-cov ?}"
        grep -h '^fuzz_' "$work/$name/log" | sort -u | head -3
    fi
done
exit $failed
