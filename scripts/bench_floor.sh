#!/usr/bin/env bash
# Against the floor (issue "Linear cost"): `qsmesh mesh` on one rank and one thread against Debian
# Gmsh's frontal triangulation (-algo front2d, one thread) of the same model at about the same
# vertex count, run alternately in one invocation so both see the same machine. Prints a markdown
# table: wall seconds and CPU seconds (user + system, /usr/bin/time; medians of the repeats),
# output vertices, and the ratios qsmesh / Gmsh, also per 1000 vertices. On a machine shared with
# other jobs the wall seconds follow the load; the CPU seconds much less. Gmsh is not a dependency of qsmesh: install it for this benchmark only
# (`apt-get install gmsh`).
# Usage: scripts/bench_floor.sh [MODEL] [--size-factor F] [--clscale C] [--repeat N] [-- ARGS]
#   defaults: ../shared/cad/Block.stp, F = 0.00463 (its reference count, docs/benchmarks.md),
#   C = 0.048 (Gmsh's mesh size factor giving about that vertex count), N = 3; ARGS: more
#   options for qsmesh mesh (e.g. -- --second-pass-quads 0).
set -euo pipefail
cd "$(dirname "$0")/.."
usage() { sed -n '9,12p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
model=../shared/cad/Block.stp
factor=0.00463
clscale=0.048
repeat=3
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --size-factor) factor=$2; shift 2 ;;
    --clscale) clscale=$2; shift 2 ;;
    --repeat) repeat=$2; shift 2 ;;
    -h|--help) usage ;;
    --) shift; extra=("$@"); break ;;
    -*) echo "bench_floor: unknown option $1" >&2; usage ;;
    *) model=$1; shift ;;
  esac
done
[ -f "$model" ] || { echo "bench_floor: no such model file: $model" >&2; exit 2; }
[[ "$repeat" =~ ^[1-9][0-9]*$ ]] || { echo "bench_floor: --repeat must be a positive integer" >&2; exit 2; }
qsmesh=build/drivers/qsmesh
[ -x "$qsmesh" ] || { echo "bench_floor: $qsmesh not found: run scripts/build.sh first" >&2; exit 2; }
command -v gmsh > /dev/null || { echo "bench_floor: gmsh not found: apt-get install gmsh" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Vertices of a Gmsh 4 .msh file: the second number of the line after $Nodes.
msh_vertices() { awk '/^\$Nodes/{getline; print $2; exit}' "$1"; }
calc() { python3 -c "print($1)"; }
now() { python3 -c "import time; print(time.monotonic())"; }
[ -x /usr/bin/time ] || { echo "bench_floor: /usr/bin/time not found: apt-get install time" >&2; exit 2; }
# CPU seconds (user + system) of the last command run through cpu_of.
cpu_of() { /usr/bin/time -f '%U %S' -o "$work/cpu" "$@"; }
cpu_last() { awk '{print $1 + $2}' "$work/cpu"; }
q_times=() g_times=() q_cpu=() g_cpu=()
for ((k = 0; k < repeat; k++)); do
  t0=$(now)
  cpu_of "$qsmesh" mesh "$model" -o "$work/q.msh" --size-factor "$factor" --threads 1 -q ${extra[@]+"${extra[@]}"}
  q_times+=("$(calc "$(now) - $t0")")
  q_cpu+=("$(cpu_last)")
  t0=$(now)
  cpu_of gmsh "$model" -2 -algo front2d -clscale "$clscale" -nt 1 -o "$work/g.msh" > "$work/g.log" 2>&1 ||
    { echo "bench_floor: gmsh failed:" >&2; tail -3 "$work/g.log" >&2; exit 1; }
  g_times+=("$(calc "$(now) - $t0")")
  g_cpu+=("$(cpu_last)")
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print a[int((NR + 1) / 2)]}'; }
qt=$(median "${q_times[@]}"); gt=$(median "${g_times[@]}")
qc=$(median "${q_cpu[@]}"); gc=$(median "${g_cpu[@]}")
qv=$(msh_vertices "$work/q.msh"); gv=$(msh_vertices "$work/g.msh")
echo "| tool | command | vertices | seconds (median of $repeat) | CPU seconds (median) | s per 1000 vertices |"
echo "|---|---|---|---|---|---|"
printf '| qsmesh | mesh %s --size-factor %s --threads 1%s | %s | %.1f | %.1f | %.3f |\n' "$(basename "$model")" "$factor" "${extra[*]+ ${extra[*]}}" "$qv" "$qt" "$qc" "$(calc "1000 * $qt / $qv")"
printf '| gmsh %s | -2 -algo front2d -clscale %s -nt 1 | %s | %.1f | %.1f | %.3f |\n' "$(gmsh --version 2>&1 | head -1)" "$clscale" "$gv" "$gt" "$gc" "$(calc "1000 * $gt / $gv")"
printf '\nqsmesh / gmsh: %.2f in time, %.2f per 1000 vertices; %.2f in CPU time, %.2f per 1000 vertices\n' "$(calc "$qt / $gt")" "$(calc "($qt / $qv) / ($gt / $gv)")" "$(calc "$qc / $gc")" "$(calc "($qc / $qv) / ($gc / $gv)")"
