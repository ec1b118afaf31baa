#!/usr/bin/env bash
# Holomorphic basis timing (issue 32, paper 004): a plate with 9 holes (10 boundary loops) built
# with OpenCASCADE, triangulated at about the vertex count of the paper's aneurysm (26,165
# vertices, basis in 165.6 s on a 6-core laptop), basis (2 factorizations, 2 x 9 solves) and the
# energy minimisation timed by build/tests/holomorphic/bench_holomorphic, the median of N runs.
# Usage: scripts/bench_holomorphic.sh [--size S] [--repeat N]   (defaults: S = 0.049, N = 3)
set -euo pipefail
cd "$(dirname "$0")/.."
size=0.049
repeat=3
while [ $# -gt 0 ]; do
  case "$1" in
    --size) size=$2; shift 2 ;;
    --repeat) repeat=$2; shift 2 ;;
    -h|--help) sed -n '7p' "$0" | sed 's/^# //' >&2; exit 2 ;;
    *) echo "bench_holomorphic: unknown option $1" >&2; exit 2 ;;
  esac
done
[[ "$repeat" =~ ^[1-9][0-9]*$ ]] || { echo "bench_holomorphic: --repeat must be a positive integer" >&2; exit 2; }
bench=build/tests/holomorphic/bench_holomorphic
[ -x "$bench" ] || { echo "bench_holomorphic: build the target bench_holomorphic first" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for i in $(seq "$repeat"); do "$bench" "$size" "$tmp" > "$tmp/run$i.txt"; done
cat "$tmp/run1.txt"
basis=$(for i in $(seq "$repeat"); do sed -n 's/^background_s.* basis_s \([0-9.]*\) .*/\1/p' "$tmp/run$i.txt"; done | sort -g)
median=$(echo "$basis" | sed -n "$(( (repeat + 1) / 2 ))p")
echo "basis seconds over $repeat runs: $(echo $basis | tr '\n' ' ')"
echo "median basis ${median} s; paper 165.61 s; speedup $(awk -v m="$median" 'BEGIN { printf "%.0f", 165.61 / m }')x"
