#!/usr/bin/env bash
# Speed-up of 2 MPI ranks over 1 on a DEM effective field, and the load balance (busy
# fraction per rank), for bench/results/<machine>/mpi_field.txt (docs/distributed.md).
# Needs an MPI build: cmake -S . -B build -DPDAMP_MPI=ON && cmake --build build -j2 --target pdamp
# Usage: scripts/bench_mpi_field.sh [BUILD_DIR] [CASE]   (default build, the shipped 36-sphere case)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
case_file=${2:-cases/low_intensity_36_spheres.json}
"$build/pdamp" --help | grep -q "(MPI build)" || { echo "$build/pdamp is not an MPI build (-DPDAMP_MPI=ON)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# One point at a time per rank: the case's field.threads set to 1, so that 1 rank is one core.
sed 's/"threads": *[0-9]*/"threads": 1/' "$case_file" > "$work/case.json"
root=(); [ "$(id -u)" = 0 ] && root=(--allow-run-as-root)
echo "# pdamp field $case_file --source dem (field.threads = 1), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
for ranks in 1 2; do
  start=$(date +%s.%N)
  mpirun -n "$ranks" --oversubscribe "${root[@]}" "$build/pdamp" field "$work/case.json" --source dem \
    -o "$work/ranks$ranks" --json > "$work/ranks$ranks.json" 2> "$work/ranks$ranks.err"
  end=$(date +%s.%N)
  wall=$(awk -v a="$start" -v b="$end" 'BEGIN { print b - a }')
  result=$(tr -d '\n' < "$work/ranks$ranks.json")
  printf 'ranks %d: %.2f s wall; %s\n' "$ranks" "$wall" "$(grep -o '"sweep": *"[^"]*"' <<< "$result")"
  grep -o '"mpi": *{[^}]*}' <<< "$result" | tr -s ' ' || true
  eval "wall$ranks=$wall"
done
awk -v a="$wall1" -v b="$wall2" 'BEGIN { printf "speed-up of 2 ranks over 1: %.2f\n", a / b }'
cmp -s <(grep -v created_utc "$work/ranks1/field.json") <(grep -v created_utc "$work/ranks2/field.json") \
  && echo "field.json of 1 and 2 ranks: identical (creation time aside)" || echo "field.json of 1 and 2 ranks DIFFER"
