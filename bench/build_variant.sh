#!/usr/bin/env bash
# Builds a variant of the GPU solver that is kept as a patch (bench/results/*.patch) rather than
# merged, for a lease to measure beside main: applies PATCH to a fresh worktree of HEAD in /tmp,
# builds the variant's fluidcast-bench-gpu and gpu_solver_test there, and copies them into
# build/bin as fluidcast-bench-gpu-NAME and gpu_solver_test-NAME, where gpu-bundle and
# bench/gpu_lease.sh find them (a few minutes on two cores).
#   bench/build_variant.sh NAME PATCH
#   e.g. bench/build_variant.sh tiles bench/results/gpu-tiles-2026-11-30.patch
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: bench/build_variant.sh NAME PATCH"
name=${1:?$usage}
patch=$(realpath "${2:?$usage}")
tree=/tmp/fluidcast-variant-$name
git worktree remove --force "$tree" 2>/dev/null || rm -rf "$tree"
git worktree prune
git worktree add --detach "$tree" HEAD >/dev/null
git -C "$tree" apply "$patch"
cmake --preset release -S "$tree" -B "$tree/build" >/dev/null
cmake --build "$tree/build" --target fluidcast-bench-gpu gpu_solver_test
mkdir -p build/bin
cp "$tree/build/bin/fluidcast-bench-gpu" "build/bin/fluidcast-bench-gpu-$name"
cp "$tree/build/bin/gpu_solver_test" "build/bin/gpu_solver_test-$name"
echo "build/bin/fluidcast-bench-gpu-$name and build/bin/gpu_solver_test-$name: $(git rev-parse --short HEAD) with $(basename "$patch")"
