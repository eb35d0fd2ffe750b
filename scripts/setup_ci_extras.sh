#!/usr/bin/env bash
# Install what the CI-only sanitizer and fuzz builds need beyond scripts/setup.sh:
# clang, the compiler-rt runtimes of ASan/UBSan/libFuzzer (libclang-rt-14-dev: only a
# Recommends of clang, which --no-install-recommends skips, so it is named here) and
# llvm-symbolizer (llvm-14) for readable reports; chromium, which the report test uses to
# render report.html, python3-vtk9, whose reader loads the ParaView files, and liggghts,
# which runs the deck of pdamp export liggghts in its comparison test. A no-op when all are present.
# With --all, first everything scripts/setup.sh and scripts/ci_mpi.sh install too, in the
# same apt-get call: .ci/run starts with it on a fresh machine, so there is one
# `apt-get update` and one install instead of three, and the later scripts find their
# packages present.
# Usage: scripts/setup_ci_extras.sh [--all]   (called by .ci/run; see docs/ci.md)
set -euo pipefail
cd "$(dirname "$0")/.."

# chromium: the report test renders report.html headless; python3-vtk9: VTK's reader loads
# pdamp dem's ParaView files (both tests are skipped where these are missing); pybind11-dev,
# python3-dev, python3-numpy, python3-pytest: the Python module and its tests (ci_python.sh);
# liggghts: the LIGGGHTS run of an exported deck against pdamp dem (tests/cli/test_liggghts.cpp,
# skipped where it is missing; users who only run pdamp do not need it).
packages=(clang libclang-rt-14-dev llvm-14 ninja-build chromium python3-vtk9
  pybind11-dev python3-dev python3-numpy python3-pytest liggghts)
if [ "${1:-}" = --all ]; then
  read -r -a base <<<"$(scripts/setup.sh --list-packages --mpi)"
  packages=("${base[@]}" "${packages[@]}")
fi
missing=()
for p in "${packages[@]}"; do
  [[ " ${missing[*]} " == *" $p "* ]] && continue  # named by both lists
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup_ci_extras: installing ${missing[*]}" >&2
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  # --force-unsafe-io: dpkg without an fsync per unpacked file, most of an install's time
  # on a slow disk. Only here: CI's machine is thrown away after the run, while a power
  # cut during an install on a user's machine (scripts/setup.sh) must not corrupt it.
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends \
    -o Dpkg::Options::=--force-unsafe-io "${missing[@]}" >&2
fi

# The runtimes must really be there: a clang without them fails only at link time.
for lib in libclang_rt.asan-x86_64.a libclang_rt.ubsan_standalone-x86_64.a libclang_rt.fuzzer-x86_64.a; do
  file=$(clang++ -print-file-name="$lib")
  [ -f "$file" ] || { echo "setup_ci_extras: clang finds no $lib after the install" >&2; exit 1; }
done
