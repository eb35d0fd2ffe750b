#!/usr/bin/env bash
# pdamp's DEM against LIGGGHTS-PUBLIC (Debian's `liggghts`) on the same work: the case is
# exported with `pdamp export liggghts` (the same bed, contact law, time step, settling and
# periods), then LIGGGHTS on the deck and `pdamp dem` on the case run in turn, RUNS times
# each, one core each, whole processes timed by the wall clock. Prints every pair, the
# medians and the ratio, and both codes' eta* (pdamp import liggghts for LIGGGHTS), for
# bench/results/<machine>/liggghts.txt (docs/liggghts.md "Speed").
# Needs: liggghts (apt-get install liggghts), python3 (reads the JSON) and a built pdamp
# (scripts/setup.sh).
# Usage: scripts/bench_liggghts.sh [BUILD_DIR] [CASE] [RUNS]
#   (default build, bench/cases/layer_6x6_liggghts.json, 3 runs)
# With LIGGGHTS_RANKS=N in the environment LIGGGHTS runs under mpirun -np N instead (pdamp
# then gets N OpenMP threads: the same cores on both sides).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
case_file=${2:-bench/cases/layer_6x6_liggghts.json}
runs=${3:-3}
ranks=${LIGGGHTS_RANKS:-1}
command -v liggghts > /dev/null || { echo "bench_liggghts: liggghts is not installed (apt-get install liggghts)" >&2; exit 2; }
[ -x "$build/pdamp" ] || { echo "bench_liggghts: $build/pdamp is not built (scripts/setup.sh)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$build/pdamp" export liggghts "$case_file" -o "$work/deck" --json > "$work/export.json" 2> "$work/export.err"
liggghts_cmd=(liggghts -in in.pdamp -log none)
if [ "$ranks" -gt 1 ]; then
  root=(); [ "$(id -u)" = 0 ] && root=(--allow-run-as-root)
  liggghts_cmd=(mpirun -np "$ranks" "${root[@]}" "${liggghts_cmd[@]}")
fi
seconds_of() {  # runs "$@", prints its wall time in seconds
  local start end
  start=$(date +%s.%N)
  "$@"
  end=$(date +%s.%N)
  awk -v a="$start" -v b="$end" 'BEGIN { printf "%.3f", b - a }'
}
run_liggghts() { (cd "$work/deck" && "${liggghts_cmd[@]}" > "$work/liggghts.log" 2>&1); }
run_pdamp() { "$build/pdamp" dem "$case_file" --threads "$ranks" --json > "$work/dem.json" 2> "$work/dem.err"; }

field() { python3 -c 'import json, sys; print(json.load(open(sys.argv[2]))[sys.argv[1]])' "$1" "$2"; }  # a top-level key
particles=$(field particles "$work/export.json")
steps=$(awk -v s="$(field settling_steps "$work/export.json")" -v p="$(field steps_per_period "$work/export.json")" \
  -v n="$(( $(field transient_periods "$work/export.json") + $(field analysed_periods "$work/export.json") ))" \
  'BEGIN { print s + n * p }')
echo "# scripts/bench_liggghts.sh $case_file: $particles spheres, $steps steps, $runs runs each in turn, $ranks core(s) each"
echo "# $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
version=$(cd "$work" && liggghts -h < /dev/null 2>/dev/null | sed -n '/LIGGGHTS/{p;q}' || true)
echo "# ${version:-LIGGGHTS} | $("$build/pdamp" --version | head -1)"
printf '%-5s %12s %12s %8s\n' run liggghts_s pdamp_s ratio
for ((k = 1; k <= runs; ++k)); do
  l=$(seconds_of run_liggghts)
  p=$(seconds_of run_pdamp)
  printf '%-5d %12s %12s %8.2f\n' "$k" "$l" "$p" "$(awk -v a="$l" -v b="$p" 'BEGIN { print a / b }')"
  echo "$l $p" >> "$work/times"
done
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
l_med=$(cut -d' ' -f1 "$work/times" | median)
p_med=$(cut -d' ' -f2 "$work/times" | median)
awk -v l="$l_med" -v p="$p_med" -v n="$particles" -v s="$steps" 'BEGIN {
  printf "median: LIGGGHTS %.2f s (%.3g particle-steps/s), pdamp %.2f s (%.3g particle-steps/s): pdamp %.2f times as fast\n",
         l, n * s / l, p, n * s / p, l / p }'
"$build/pdamp" import liggghts "$work/deck" --json > "$work/import.json"
echo "eta* LIGGGHTS $(field eta_star "$work/import.json") +- $(field eta_star_stderr "$work/import.json"), pdamp $(field eta_star "$work/dem.json") +- $(field eta_star_stderr "$work/dem.json")"
