#!/usr/bin/env bash
# Strong-scaling study of `qsmesh mesh` on one model: the same run at several rank x thread
# counts, each repeated, with the median wall time, the speedup and parallel efficiency against the
# first configuration, the main stages' times, the load imbalance of the face partition (the
# ranks' time in the per-face stages, max / mean, from --stats), the peak memory of rank 0 (which
# assembles and writes the mesh) and the largest of the other ranks' (--stats),
# and whether the mesh is byte-identical to the first configuration's (it must be: the mesh does
# not depend on the numbers of ranks and threads). Prints a markdown table; --csv also writes the
# rows as CSV, --png plots speedup and efficiency per configuration (scripts/plot_table.py).
# --simulate LIST predicts the configurations of LIST (P or PxT, comma-separated) from the median
# run of the first configuration (one rank) with scripts/simulate_scaling.py (the faces' METIS
# partitions from `qsmesh info --partition`, the costs of messages measured by scripts/mpi_costs.c
# where mpicc exists), compares its predictions with the configurations run, and then --png plots
# the predicted speedup instead. --keep DIR keeps the runs' --stats (CONFIG.REPEAT.json) there,
# and, when a mesh differs, the meshes that do and the first configuration's (CONFIG.REPEAT.msh).
# Every repeat's mesh is compared: a race shows only now and then.
# Usage: scripts/scaling_study.sh MODEL [--size-factor F] [--until STAGE] [--configs "PxT ..."]
#                                 [--repeat N] [--csv FILE] [--png FILE] [--simulate LIST] [--keep DIR]
#   defaults: --size-factor 0.02, --until quasi-structured, --configs "1x1 1x2 2x1" (and 2x2, 4x1,
#   4x2, 8x1, 8x2, 16x1 where the machine has that many cores), --repeat 3.
# Wall time is that of the whole command (mpiexec, loading and writing included); the median of an
# even number of runs is the lower middle one, and the stage times shown are that run's.
# Configurations with more processes x threads than cores are run but marked: their times say
# nothing of scaling.
set -euo pipefail
cd "$(dirname "$0")/.."
usage() { sed -n '15,18p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
[ $# -ge 1 ] || usage
model=$1; shift
[ -f "$model" ] || { echo "scaling_study: no such model file: $model" >&2; exit 2; }
factor=0.02
until=quasi-structured
repeat=3
csv=
png=
simulate=
keep=
cores=$(nproc)
configs=
while [ $# -gt 0 ]; do
  case "$1" in
    --size-factor) factor=$2; shift 2 ;;
    --until) until=$2; shift 2 ;;
    --configs) configs=$2; shift 2 ;;
    --repeat) repeat=$2; shift 2 ;;
    --csv) csv=$2; shift 2 ;;
    --png) png=$2; shift 2 ;;
    --simulate) simulate=$2; shift 2 ;;
    --keep) keep=$2; shift 2 ;;
    *) echo "scaling_study: unknown option $1" >&2; usage ;;
  esac
done
if [ -z "$configs" ]; then
  configs="1x1 1x2 2x1"
  for c in 2x2 4x1 4x2 8x1 8x2 16x1; do
    p=${c%x*}; t=${c#*x}
    [ $((p * t)) -le "$cores" ] && configs="$configs $c"
  done
fi
[[ "$repeat" =~ ^[1-9][0-9]*$ ]] || { echo "scaling_study: --repeat must be a positive integer" >&2; exit 2; }
for c in $configs; do
  [[ "$c" =~ ^[1-9][0-9]*x[1-9][0-9]*$ ]] || { echo "scaling_study: configuration '$c' is not PxT (ranks x threads)" >&2; exit 2; }
done
if [ -n "$simulate" ]; then
  first=${configs%% *}
  [ "${first%x*}" = 1 ] || { echo "scaling_study: --simulate replays a run on one rank: the first configuration must be 1xT" >&2; exit 2; }
  [[ "$simulate" =~ ^[1-9][0-9]*(x[1-9][0-9]*)?(,[1-9][0-9]*(x[1-9][0-9]*)?)*$ ]] ||
    { echo "scaling_study: --simulate takes P or PxT, comma-separated (e.g. 4,8,16x2)" >&2; exit 2; }
fi
exe=./build/drivers/qsmesh
[ -x "$exe" ] || { echo "scaling_study: $exe missing; run scripts/build.sh first" >&2; exit 2; }
if [ -n "$png" ]; then
  /usr/bin/python3 -c "import vtkmodules.vtkChartsCore" 2>/dev/null ||
    { echo "scaling_study: --png needs VTK's Python module (Debian python3-vtk9; scripts/setup.sh installs it)" >&2; exit 2; }
fi
[ -x /usr/bin/time ] || { echo "scaling_study: /usr/bin/time missing (Debian package 'time'; scripts/setup.sh installs it)" >&2; exit 2; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# Runs: one line per run, "config repeat wall_s peak_kb stats.json mesh.msh".
runs=$out/runs.txt
: > "$runs"
for c in $configs; do
  p=${c%x*}; t=${c#*x}
  for k in $(seq 1 "$repeat"); do
    /usr/bin/time -f "%e %M" -o "$out/time" mpiexec --oversubscribe --bind-to none -n "$p" "$exe" mesh "$model" \
      -o "$out/$c.$k.msh" --size-factor "$factor" --until "$until" --threads "$t" -q \
      --stats "$out/$c.$k.json" >/dev/null
    read -r wall kb < <(tail -n1 "$out/time")
    [ -z "$keep" ] || { mkdir -p "$keep" && cp "$out/$c.$k.json" "$keep/"; }
    echo "$c $k $wall $kb $out/$c.$k.json $out/$c.$k.msh" >> "$runs"
    # Every repeat's mesh is compared with the first configuration's first one (a mesh that
    # differs only now and then is a race); the ones equal to it are dropped at once.
    base_msh=$out/${configs%% *}.1.msh
    if [ "$out/$c.$k.msh" != "$base_msh" ] && cmp -s "$base_msh" "$out/$c.$k.msh"; then
      rm -f "$out/$c.$k.msh"
      ln -s "$base_msh" "$out/$c.$k.msh"
    fi
  done
done

table_csv=$csv
[ -n "$table_csv" ] || table_csv=$out/table.csv
status=0
python3 - "$runs" "$model" "$factor" "$until" "$cores" "$repeat" "$table_csv" <<'PY' || status=$?
import csv, json, os, statistics, sys
runs_path, model, factor, until, cores, repeat, csv_path = sys.argv[1:8]
cores = int(cores)
runs = {}
order = []
for line in open(runs_path):
    c, k, wall, kb, stats, mesh = line.split()
    if c not in runs:
        runs[c] = []
        order.append(c)
    runs[c].append({"wall": float(wall), "kb": int(kb), "stats": json.load(open(stats)), "mesh": mesh})

def peak_mb(r):
    # Per rank from --stats; the largest process under mpiexec (GNU time) for older binaries.
    mb = r["stats"].get("rank_peak_memory_mb")
    if not mb:
        return f"{r['kb'] / 1024:.0f}"
    return f"{mb[0]:.0f}" + (f" / {max(mb[1:]):.0f}" if len(mb) > 1 else "")

def median_run(rs):
    # The run whose wall time is the median (the lower middle for an even count).
    return sorted(rs, key=lambda r: r["wall"])[(len(rs) - 1) // 2]

base = order[0]
base_cores = int(base.split("x")[0]) * int(base.split("x")[1])
base_wall = median_run(runs[base])["wall"]
base_mesh = runs[base][0]["mesh"]
header = ["ranks x threads", "cores", "wall s (median)", "wall s (min-max)", "speedup", "efficiency",
          "crossfield s", "patterns s", "improvement s", "load imbalance", "peak MB rank 0 / others",
          "vertices", "same mesh as " + base]
rows = []
for c in order:
    rs = runs[c]
    m = median_run(rs)
    p, t = (int(x) for x in c.split("x"))
    n = p * t
    walls = [r["wall"] for r in rs]
    speedup = base_wall / m["wall"] if m["wall"] > 0 else float("nan")
    eff = speedup * base_cores / n
    s = m["stats"]["seconds"]
    # The run loop compared each mesh once and left a link to the base where they are equal.
    differ = [r for r in rs if r["mesh"] != base_mesh and not os.path.islink(r["mesh"])]
    label = c + (" (oversubscribed)" if n > cores else "")
    rows.append([label, n, f"{m['wall']:.2f}", f"{min(walls):.2f}-{max(walls):.2f}", f"{speedup:.2f}",
                 f"{eff:.2f}", f"{s.get('crossfield', 0):.2f}", f"{s.get('patterns', 0):.2f}",
                 f"{s.get('improvement', 0):.2f}", f"{m['stats'].get('load_imbalance', 1.0):.2f}",
                 peak_mb(m), m["stats"]["vertices"],
                 "yes" if not differ else f"NO ({len(differ)} of {len(rs)})"])
print(f"model: {model}, --size-factor {factor}, --until {until}, {cores} cores, {repeat} run(s) per configuration")
print()
print("| " + " | ".join(header) + " |")
print("|" + "---|" * len(header))
for r in rows:
    print("| " + " | ".join(str(x) for x in r) + " |")
if csv_path:
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)
if any(r[-1].startswith("NO") for r in rows):
    print("\nscaling_study: the mesh differs between configurations", file=sys.stderr)
    sys.exit(1)
PY
# A mesh that differs is kept for diagnosis, with the first configuration's.
if [ "$status" -ne 0 ] && [ -n "$keep" ]; then
  mkdir -p "$keep"
  for f in "$out"/*.msh; do [ -L "$f" ] || cp "$f" "$keep/"; done
fi
if [ -n "$simulate" ]; then
  # The median run of each configuration (as in the table), the first one the simulation's base.
  python3 - "$runs" > "$out/medians.txt" <<'PY'
import sys
runs = {}
for line in open(sys.argv[1]):
    c, k, wall, kb, stats, mesh = line.split()
    runs.setdefault(c, []).append((float(wall), stats))
for c, rs in runs.items():
    print(c, sorted(rs)[(len(rs) - 1) // 2][1])
PY
  base_stats=$(head -n1 "$out/medians.txt" | cut -d' ' -f2)
  ranks_list=$(echo "$simulate,$(cut -d' ' -f1 "$out/medians.txt" | tr '\n' ',')" | tr ',' '\n' |
               sed -n 's/^\([0-9][0-9]*\).*/\1/p' | sort -nu | paste -sd, -)
  "$exe" info "$model" --json --partition "$ranks_list" --size-factor "$factor" > "$out/partitions.json"
  comm_args=()
  if command -v mpicc >/dev/null && mpicc -O2 -o "$out/mpi_costs" scripts/mpi_costs.c 2>/dev/null &&
     mpiexec --oversubscribe --bind-to none -n 2 "$out/mpi_costs" > "$out/comm.json"; then
    comm_args=(--comm "$out/comm.json")
  else
    echo "scaling_study: no mpicc or mpi_costs failed: the simulation takes its default costs of messages" >&2
  fi
  real_args=()
  while read -r c stats; do real_args+=(--real "$c=$stats"); done < <(tail -n +2 "$out/medians.txt")
  echo
  echo "simulated from the median ${configs%% *} run (scripts/simulate_scaling.py):"
  echo
  python3 scripts/simulate_scaling.py "$base_stats" --configs "$simulate" --partitions "$out/partitions.json" \
    "${comm_args[@]}" "${real_args[@]}" --csv "$out/simulated.csv" || status=$?
  [ -z "$csv" ] || cp "$out/simulated.csv" "${csv%.csv}.simulated.csv"
  if [ -n "$png" ]; then
    /usr/bin/python3 scripts/plot_table.py "$out/simulated.csv" -o "$png" --x "ranks x threads" \
      --y "predicted speedup,unlimited ranks speedup,efficiency" \
      --title "$(basename "$model"), --size-factor $factor: simulated speedup against ${configs%% *}"
  fi
elif [ -n "$png" ]; then
  /usr/bin/python3 scripts/plot_table.py "$table_csv" -o "$png" --x "ranks x threads" --y speedup,efficiency \
    --title "$(basename "$model"), --size-factor $factor: speedup and efficiency against ${configs%% *}"
fi
exit "$status"
