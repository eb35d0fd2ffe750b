#!/usr/bin/env bash
# Set up (dependencies, build) and run every test: the fast `unit` label, then the
# `long` DEM checks. Usage: scripts/test.sh [build-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
scripts/setup.sh "$build_dir" --tests
ctest --test-dir "$build_dir" -L unit --output-on-failure -j2 --timeout 300
ctest --test-dir "$build_dir" -L long --output-on-failure -j2 --timeout 900
