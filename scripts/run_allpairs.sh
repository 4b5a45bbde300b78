#!/usr/bin/env bash
# The main job, from nothing: sets everything up (scripts/setup.sh), generates
# a mesh (the paper's z = 0.45 sin(2 pi x) sin(2 pi y) surface, 40 x 40
# squares: 1681 vertices) and computes its all-pairs geodesic distance matrix
# with the auto backend: OpenCL on a GPU, threads on a CPU (they run the same
# rows faster there: README, "Command line"), saying which and why.
# Output: build/allpairs.npy (float32, N x N). Extra arguments go to
# `meshfmm allpairs` (e.g. --backend serial, --dtype float64).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
build/meshfmm generate sine 40 -o build/sine40.obj
build/meshfmm allpairs build/sine40.obj -o build/allpairs.npy "$@"
