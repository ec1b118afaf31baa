#!/usr/bin/env bash
# Growth benchmark (linear-cost issue): `qsmesh mesh` on models at growing multiples of their
# reference vertex counts, on P ranks x 1 thread. Per run: output vertices and quads, wall seconds
# of the pipeline (--stats "total"), seconds per 1000 output vertices and its ratio to the model's
# first (smallest) run, the same for the CPU seconds of all ranks (user + sys of mpirun's children,
# /usr/bin/time: on a loaded machine wall seconds of runs made minutes apart do not compare, CPU
# seconds do), the share of the cross-field stage (cross field, singularities, conformal scaling),
# the patterns and improvement shares, and the peak memory summed over the ranks per output quad.
# Prints a markdown table; --csv writes the rows as CSV, --png plots seconds per 1000 vertices
# against the multiple (scripts/plot_table.py).
# Usage: scripts/bench_growth.sh [--runs "MODEL:FACTOR:MULTIPLES ..."] [--ranks P]
#                                [--extra "qsmesh options"] [--csv FILE] [--png FILE]
#                                [--qsmesh BINARY]
#   MODEL is a file under ../shared/cad (or a path), FACTOR the size factor of its reference
#   vertex count, MULTIPLES comma-separated vertex multiples (the size factor is divided by their
#   square root). Defaults: --ranks 2, --runs "Block.stp:0.00463:1,4,16 A319.brep:0.00388426:1,16"
#   (the factors of docs/benchmarks.md's reference-count table). --qsmesh: the binary to run
#   (default build/drivers/qsmesh), e.g. a copy of main's to compare with.
set -euo pipefail
cd "$(dirname "$0")/.."
usage() { sed -n '11,18p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
runs="Block.stp:0.00463:1,4,16 A319.brep:0.00388426:1,16"
ranks=2
extra=
csv=
png=
qsmesh=build/drivers/qsmesh
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs=$2; shift 2 ;;
    --ranks) ranks=$2; shift 2 ;;
    --extra) extra=$2; shift 2 ;;
    --csv) csv=$2; shift 2 ;;
    --png) png=$2; shift 2 ;;
    --qsmesh) qsmesh=$2; shift 2 ;;
    -h|--help) usage ;;
    *) echo "bench_growth: unknown option $1" >&2; usage ;;
  esac
done
[[ "$ranks" =~ ^[1-9][0-9]*$ ]] || { echo "bench_growth: --ranks must be a positive integer" >&2; exit 2; }
[ -x "$qsmesh" ] || { echo "bench_growth: $qsmesh not found: run scripts/build.sh first" >&2; exit 2; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
rows="$work/rows.csv"
echo "run,model,multiple,size_factor,vertices,quads,seconds,s_per_1000_vertices,ratio_to_first,cpu_seconds,cpu_s_per_1000_vertices,cpu_ratio_to_first,crossfield_share,patterns_share,improvement_share,peak_mb_summed,bytes_per_quad" > "$rows"
for run in $runs; do
  IFS=: read -r name factor multiples <<< "$run"
  model=$name
  [ -f "$model" ] || model=../shared/cad/$name
  [ -f "$model" ] || { echo "bench_growth: no such model: $name" >&2; exit 2; }
  first=
  first_cpu=
  for m in ${multiples//,/ }; do
    f=$(python3 -c "print(f'{$factor / $m ** 0.5:.6g}')")
    json="$work/$(basename "$model").$m.json"
    # shellcheck disable=SC2086  # --extra is a list of options
    /usr/bin/time -f "%U %S" -o "$work/time.txt" \
      mpirun --oversubscribe -np "$ranks" "$qsmesh" mesh "$model" -o "$work/out.msh" --size-factor "$f" \
      --threads 1 -q --stats "$json" $extra
    line=$(python3 - "$json" "$(basename "$model")" "$m" "$f" "$first" "$work/time.txt" "$first_cpu" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
cpu = sum(float(x) for x in open(sys.argv[6]).read().split()[-2:])
cpu_per = 1000 * cpu / d["vertices"]
first_cpu = float(sys.argv[7]) if sys.argv[7] else cpu_per
t = d["seconds"]
total = t["total"]
per = 1000 * total / d["vertices"]
first = float(sys.argv[5]) if sys.argv[5] else per
peak = sum(d["rank_peak_memory_mb"])
print(",".join(str(x) for x in [
    f"{sys.argv[2].split('.')[0]} {sys.argv[3]}x", sys.argv[2], sys.argv[3], sys.argv[4], d["vertices"], d["quads"], f"{total:.1f}", f"{per:.3f}",
    f"{per / first:.2f}", f"{cpu:.1f}", f"{cpu_per:.3f}", f"{cpu_per / first_cpu:.2f}", f"{t.get('crossfield', 0) / total:.3f}", f"{t.get('patterns', 0) / total:.3f}",
    f"{t.get('improvement', 0) / total:.3f}", f"{peak:.0f}", f"{peak * 1048576 / max(d['quads'], 1):.0f}"]))
EOF
)
    echo "$line" >> "$rows"
    [ -n "$first" ] || first=$(echo "$line" | cut -d, -f8)
    [ -n "$first_cpu" ] || first_cpu=$(echo "$line" | cut -d, -f11)
    echo "$line" >&2
  done
done
python3 - "$rows" <<'EOF'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
print("| " + " | ".join(rows[0]) + " |")
print("|" + "---|" * len(rows[0]))
for r in rows[1:]:
    print("| " + " | ".join(r) + " |")
EOF
[ -z "$csv" ] || cp "$rows" "$csv"
if [ -n "$png" ]; then
  /usr/bin/python3 scripts/plot_table.py "$rows" -o "$png" --x run --y s_per_1000_vertices,cpu_s_per_1000_vertices,crossfield_share \
    --title "qsmesh: growth with the output ($ranks ranks)" --ylabel "s / 1000 vertices; share"
fi
