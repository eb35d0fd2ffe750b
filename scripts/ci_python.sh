#!/usr/bin/env bash
# CI only (docs/ci.md, docs/python.md): build the Python module pdamp in a folder of its own
# (every library position-independent, which costs the DEM about 9 % in the README's build,
# so that build keeps them plain) and run its pytest suite, comparing with the README
# build's pdamp (the same numbers to the bit: position independence changes addressing, not
# arithmetic). Usage: scripts/ci_python.sh [python-build-dir] [readme-build-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build-python}
main_build=${2:-build}
# Debian's interpreter: the one python3-dev, python3-numpy and python3-pytest belong to.
python=/usr/bin/python3
generator=(); [ -f "$build_dir/CMakeCache.txt" ] || generator=(-G Ninja)
cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DPDAMP_PYTHON=ON \
  -DPython_EXECUTABLE="$python" -DPDAMP_BUILD_TESTS=OFF >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target pdamp_python
PYTHONPATH="$build_dir/python" PDAMP_BINARY="$main_build/pdamp" PDAMP_SOURCE_DIR="$PWD" \
  "$python" -m pytest -q -p no:cacheprovider tests/python
