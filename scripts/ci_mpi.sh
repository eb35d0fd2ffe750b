#!/usr/bin/env bash
# CI only (docs/ci.md): switch the README's build to MPI (Open MPI installed if missing;
# only cli/distributed.cpp recompiles) and run the `mpi` tests, which start pdamp under
# mpirun with 2 ranks on this machine. Usage: scripts/ci_mpi.sh [build-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
scripts/setup.sh "$build_dir" --mpi --tests
ctest --test-dir "$build_dir" -L mpi --output-on-failure --timeout 300
