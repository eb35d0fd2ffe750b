#!/usr/bin/env bash
# Install pdamp's build dependencies from Debian's packages (a no-op when all are
# present), then configure and build into build/. Usage: scripts/setup.sh [build-dir] [--mpi]
# --mpi: also Open MPI, and a build whose sweeps spread over mpirun's ranks (docs/distributed.md).
# --list-packages: print the packages it would install (with --mpi, Open MPI's too) and stop.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=build
mpi=OFF
list=no
targets=(--target pdamp)
for arg in "$@"; do
  case "$arg" in
    --mpi) mpi=ON ;;
    --list-packages) list=yes ;;
    --tests) targets=() ;;
    -*) echo "setup: unknown option $arg (usage: scripts/setup.sh [build-dir] [--mpi] [--tests] [--list-packages])" >&2; exit 2 ;;
    *) build_dir=$arg ;;
  esac
done

packages=(build-essential cmake pkg-config libeigen3-dev libnlopt-cxx-dev
  coinor-libipopt-dev libfftw3-dev catch2 nlohmann-json3-dev libomp-dev
  gnuplot-nox libbenchmark-dev ninja-build)
[ "$mpi" = ON ] && packages+=(libopenmpi-dev openmpi-bin)
if [ "$list" = yes ]; then
  echo "${packages[*]}"
  exit 0
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi

# Without --mpi the folder keeps what it was configured with (a new one: no MPI).
mpi_flag=(); [ "$mpi" = ON ] && mpi_flag=(-DPDAMP_MPI=ON)
# A new folder is built with Ninja (about 10% faster than make on 2 cores: no recursive
# make); a folder made by an earlier setup keeps its generator.
generator=(); [ -f "$build_dir/CMakeCache.txt" ] || generator=(-G Ninja)
cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release "${mpi_flag[@]}" >/dev/null
cmake --build "$build_dir" -j"$(nproc)" "${targets[@]}"
