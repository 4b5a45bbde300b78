#!/usr/bin/env bash
# The whole comparison against the peers, from one command:
#   bash bench/suite/run_all.sh      # about 16 minutes on a 2-core machine
# (bench/README.md: what each step takes.) Sets everything up first
# (scripts/setup.sh --bench: Debian packages, .venv with requirements-dev.txt
# and the peers of bench/requirements.txt, the build), then writes
# bench/results/*.json, the plots and figures under docs/images/,
# and bench/RESULTS.md (all generated; never edit them by hand; the README's
# headline table quotes RESULTS.md by hand).
set -euo pipefail
cd "$(dirname "$0")/../.."

bash scripts/setup.sh --bench
py=.venv/bin/python
"$py" -c "import gdist, igl, potpourri3d, matplotlib, meshfmm, robust_laplacian, sksparse.cholmod"

export MESHFMM_CLI="$PWD/build/meshfmm"
start=$(date +%s)
step() { echo; echo "== $* ($(( $(date +%s) - start )) s)"; }

step "accuracy against the stored exact references (pytest)"
MESHFMM_ACCURACY_JSON="$PWD/bench/results/accuracy_python.json" "$py" -m pytest -q tests/python/test_accuracy.py
step "per-source accuracy and time against the peers"
"$py" bench/suite/compare_peers.py
"$py" bench/suite/bench_exact_start.py   # the exact start: radii, robust heat, time per source
"$py" bench/suite/bench_methods.py       # method="windows" beside the default
"$py" bench/suite/convergence_exact_start.py
step "all pairs"
"$py" bench/suite/compare_allpairs.py
step "paper figures 8b and 10"
"$py" bench/figures/figures_cost_head.py
step "plots"
"$py" bench/figures/plot_bench.py
step "bench/RESULTS.md"
"$py" bench/suite/make_results_md.py
step "done"
