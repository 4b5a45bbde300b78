#!/usr/bin/env bash
# The whole comparison against the field, from one command (issue 6):
#   bash bench/suite/run_all.sh            # ~10-20 minutes on a 2-core machine
# Sets everything up (scripts/setup.sh: Debian packages, .venv with the peers
# from requirements-dev.txt, the build), then writes bench/results/*.json,
# the plots and figures under docs/images/, bench/RESULTS.md and the summary
# block of README.md (all generated; never edit them by hand).
set -euo pipefail
cd "$(dirname "$0")/../.."

bash scripts/setup.sh
py=.venv/bin/python

# The peers' own needs: CHOLMOD and a threaded OpenBLAS (Debian), then bench/requirements.txt.
bench_debs=(libsuitesparse-dev libopenblas0-pthread)
for p in "${bench_debs[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
            "${bench_debs[@]}" >/dev/null
        break
    fi
done
"$py" -m pip install -q -r bench/requirements.txt

# gdist's PyPI wheel (2.1.0) is compiled against numpy 1.x and fails to import
# under numpy 2 ("numpy.dtype size changed"); rebuilding it from its sdist
# against the installed numpy fixes that.
if ! "$py" -c "import gdist" >/dev/null 2>&1; then
    echo "run_all: gdist does not import with this numpy; rebuilding it from source"
    "$py" -m pip install -q --no-binary gdist --no-deps --force-reinstall gdist
fi
"$py" -c "import gdist, igl, potpourri3d, matplotlib, meshfmm, robust_laplacian, sksparse.cholmod"

export MESHFMM_CLI="$PWD/build/meshfmm"
start=$(date +%s)
step() { echo; echo "== $* ($(( $(date +%s) - start )) s)"; }

step "accuracy against the stored exact references (pytest)"
MESHFMM_ACCURACY_JSON="$PWD/bench/results/accuracy_python.json" "$py" -m pytest -q tests/python/test_accuracy.py
step "per-source accuracy and time against the peers"
"$py" bench/suite/compare_peers.py
"$py" bench/suite/bench_exact_start.py   # the exact start: radii, robust heat, time per source
"$py" bench/suite/convergence_exact_start.py
step "all pairs"
"$py" bench/suite/compare_allpairs.py
step "paper figures 8b and 10"
"$py" bench/figures/figures_cost_head.py
step "plots"
"$py" bench/figures/plot_bench.py
step "bench/RESULTS.md and the README block"
"$py" bench/suite/make_results_md.py
step "done"
