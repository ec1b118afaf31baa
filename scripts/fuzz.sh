#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz with clang into build-fuzz/ and runs each for a bounded
# time from its committed seed corpus. Fails on the first crash, sanitizer report or uncaught
# exception; the input that caused it is left in build-fuzz/artifacts/ (crash-*, ...) and can be
# replayed with `build-fuzz/fuzz_NAME build-fuzz/artifacts/crash-...`.
# Usage: scripts/fuzz.sh [SECONDS per target, default 60]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
jobs=$(nproc 2>/dev/null || echo 2)
cxx=${QSMESH_FUZZ_CXX:-clang++-14}
cmake -S tests/fuzz -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build build-fuzz -j "$jobs"

symbolizer=$(command -v llvm-symbolizer-14 || command -v llvm-symbolizer || true)
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1${symbolizer:+:external_symbolizer_path=$symbolizer}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
mkdir -p build-fuzz/artifacts
while read -r target; do
  [ -n "$target" ] || continue
  seeds=tests/fuzz/corpus/${target#fuzz_}
  dict=tests/fuzz/${target#fuzz_}.dict
  # New inputs go to a scratch corpus in build-fuzz, never into the committed seeds.
  work=build-fuzz/corpus/${target#fuzz_}
  mkdir -p "$work"
  log=build-fuzz/$target.log
  echo "fuzz: $target for ${seconds}s (seeds $seeds, log $log)"
  dict_arg=()
  [ -f "$dict" ] && dict_arg=(-dict="$dict")
  if ! "build-fuzz/$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
      -print_final_stats=1 -artifact_prefix=build-fuzz/artifacts/ "${dict_arg[@]}" "$work" "$seeds" \
      > "$log" 2>&1; then
    tail -n 60 "$log"
    echo "fuzz: $target FAILED (reproducer in build-fuzz/artifacts/)" >&2
    exit 1
  fi
  grep -E '^(Done|stat::number_of_executed_units|stat::new_units_added)' "$log" || true
done < build-fuzz/targets.txt
