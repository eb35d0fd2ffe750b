#!/usr/bin/env bash
# CI only (docs/ci.md): one clang build with AddressSanitizer + UndefinedBehaviorSanitizer
# and libFuzzer coverage, then (1) the `unit` tests under the sanitizers and (2) each fuzz
# target for a bounded time. Fails on any test failure, sanitizer report or fuzz crash.
# Usage: scripts/ci_sanitize_fuzz.sh [build-dir] [seconds-per-fuzz-target]
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build-san}
fuzz_seconds=${2:-20}
start=$(date +%s)
stamp() { echo "ci_sanitize_fuzz: $1 at +$(( $(date +%s) - start )) s" >&2; }

scripts/setup_ci_extras.sh

# One build serves both: what it builds is compiled once with -fsanitize=address,undefined
# and -fsanitize=fuzzer-no-link. To keep .ci/run within its time it builds only what the
# two jobs run: the fuzz targets and the test programs of the libraries, not pdamp and
# its command-line tests (docs/ci.md, "Time").
CC=clang CXX=clang++ cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DPDAMP_SANITIZE=address,undefined -DPDAMP_FUZZ=ON >/dev/null
mapfile -t targets < <(ninja -C "$build_dir" -t targets all | sed -n 's/^\(test_[a-z_]*\|fuzz_[a-z_]*\): phony$/\1/p' \
  | grep -v '^test_cli_')
cmake --build "$build_dir" -j2 --target "${targets[@]}"
stamp "sanitizer and fuzz build done"

# halt_on_error: the first report ends the process, so the test fails; a leak fails too.
export ASAN_OPTIONS=halt_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
regex_of() { sed -e 's/[][\\.*^$+?(){}|]/\\&/g' | paste -sd'|' | sed -e 's/^/^(/' -e 's/$/)$/'; }
# Tests left out (each with its reason): scripts/sanitize_excluded_tests.txt, docs/ci.md.
excluded=$(grep -v -e '^#' -e '^[[:space:]]*$' scripts/sanitize_excluded_tests.txt)
# test_structure_cosimulation replaces operator new/delete by malloc/free but not the
# nothrow forms, so ASan's nothrow new meets the file's free(): a mismatch the C++
# replacement rules allow. Its tests run alone below with that one check off.
# (Catch's --list-test-names-only exits with the number of tests it lists.)
cosimulation=$( (ASAN_OPTIONS=$ASAN_OPTIONS:alloc_dealloc_mismatch=0 "$build_dir/tests/test_structure_cosimulation" \
  '~[long]' --list-test-names-only || true) | grep -v '^$' | sed 's/^/structure:/')
# The command-line tests ("cli:") are not built here.
ctest --test-dir "$build_dir" -L unit -E "$(printf '%s\n%s\n' "$excluded" "$cosimulation" | regex_of)|^cli:" \
  --output-on-failure -j2 --timeout 600
ASAN_OPTIONS=$ASAN_OPTIONS:alloc_dealloc_mismatch=0 "$build_dir/tests/test_structure_cosimulation" '~[long]'
stamp "unit tests under ASan+UBSan done"

# Each fuzz target from its seeds (tests/fuzz/corpus/<name>/) for a bounded time, two at
# a time (libFuzzer runs one process on one core); what it finds goes into a scratch
# corpus in the build folder, never into the source tree. A crash writes crash-* into
# that folder and exits non-zero, which fails CI.
fuzz_one() {
  local target=$1 name work timeout dict=()
  name=$(basename "$target")
  name=${name#fuzz_}
  work="$build_dir/fuzz-work/$name"
  mkdir -p "$work/corpus"
  case "$name" in *csv) ;; *) dict=(-dict=tests/fuzz/json.dict) ;; esac
  # A case may ask for an automatic lattice of up to 1e7 sites per slab (formulas'
  # kMaxSlabSites): 0.4 s in a release build, 10-40 s under ASan and coverage
  # (tests/data/fuzz_regressions/case_file/refused_cylinder_slab_of_3e6_sites.json).
  timeout=5
  [ "$name" = case_file ] && timeout=60
  if ! "$target" -max_total_time="$fuzz_seconds" -timeout="$timeout" -rss_limit_mb=2048 -max_len=16384 \
      -print_final_stats=1 "${dict[@]}" -artifact_prefix="$work/" "$work/corpus" "tests/fuzz/corpus/$name" \
      >"$work/log.txt" 2>&1; then
    tail -60 "$work/log.txt" >&2
    echo "ci_sanitize_fuzz: fuzz_$name found a crash: $(ls "$work"/crash-* "$work"/timeout-* "$work"/oom-* 2>/dev/null)" >&2
    return 1
  fi
  grep -E "stat::number_of_executed_units|stat::new_units_added" "$work/log.txt" | sed "s/^/fuzz_$name: /" >&2
}
targets=("$build_dir"/fuzz/fuzz_*)
echo "ci_sanitize_fuzz: ${#targets[@]} fuzz targets for $fuzz_seconds s each, two at a time" >&2
failed=0
for ((i = 0; i < ${#targets[@]}; i += 2)); do
  pids=()
  for target in "${targets[@]:i:2}"; do
    fuzz_one "$target" &
    pids+=($!)
  done
  for pid in "${pids[@]}"; do wait "$pid" || failed=1; done
done
[ "$failed" = 0 ] || exit 1
stamp "fuzzing done"
