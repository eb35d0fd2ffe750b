#!/usr/bin/env bash
# CI only (docs/ci.md): the bench/ programs built into the README's folder
# (PDAMP_BUILD_BENCH=ON; only bench/ compiles, Google Benchmark comes with scripts/setup.sh)
# and each run once on its smallest work, so that a change which breaks one (it no longer
# compiles, or refuses its own cases) is seen where it is made. Their figures are not
# checked here: timings go to bench/results, measured on a quiet machine.
# Usage: scripts/ci_bench_smoke.sh [build-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
cmake -S . -B "$build_dir" -DPDAMP_BUILD_BENCH=ON >/dev/null
programs=(bench_formulas bench_surrogate bench_structure bench_optimizer bench_dem bench_cosimulation)
cmake --build "$build_dir" -j"$(nproc)" --target "${programs[@]}"
bench="$build_dir/bench"
run() {
  echo "ci_bench_smoke: $*" >&2
  "$@" >/dev/null
}
# Google Benchmark programs: the shortest timing per benchmark; the optimiser's shipped
# filling-ratio case with its DEM verification (30 s) is left out (the long tests verify it).
for p in bench_formulas bench_surrogate bench_structure; do run "$bench/$p" --benchmark_min_time=0.001; done
run "$bench/bench_optimizer" --benchmark_min_time=0.001 --benchmark_filter=-FillingRatiosVerified
# Plain programs: bench_dem's 6 x 6 layer rows at a thousandth of their timed steps (its
# first argument scales them, the second picks the 36-sphere rows); bench_cosimulation's
# one period, once.
run "$bench/bench_dem" 0.001 36
run "$bench/bench_cosimulation" 1 1
echo "ci_bench_smoke: all bench programs ran" >&2
