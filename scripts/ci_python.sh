#!/usr/bin/env bash
# CI only (docs/ci.md, docs/python.md): build the Python module pdamp in the README's build
# folder (its libraries are position-independent already: only the module compiles) and
# run its pytest suite against the module and that folder's pdamp.
# Usage: scripts/ci_python.sh [build-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
# Debian's interpreter: the one python3-dev, python3-numpy and python3-pytest belong to.
python=/usr/bin/python3
cmake -S . -B "$build_dir" -DPDAMP_PYTHON=ON -DPython_EXECUTABLE="$python" >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target pdamp_python
PYTHONPATH="$build_dir/python" PDAMP_BINARY="$build_dir/pdamp" PDAMP_SOURCE_DIR="$PWD" \
  "$python" -m pytest -q -p no:cacheprovider tests/python
