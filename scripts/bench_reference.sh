#!/usr/bin/env bash
# End-to-end time and peak memory of `qsmesh mesh` (default stage) on each shared model at the size
# that gives the vertex count of the Gmsh reference run (../shared/cad/README.md), at 1 and 2
# threads (one rank) and 1 and 2 ranks (one thread each), beside the reference's time and memory
# (one thread). Time: wall clock of the whole command (mpiexec, loading, writing included). Prints
# two markdown tables: quality (vertices, interior irregular vertices, SICN min / avg, quads below
# SICN 0.1 and how many of them a sharp CAD corner forces; from the one-thread run, which the
# other two must reproduce: the script says so where they do not), then time and memory. The
# reference numbers are read from ../shared/cad/README.md by scripts/gmsh_reference.py. The size
# factors are the reference factors of docs/benchmarks.md ("Current state": vertex counts within
# 6% of the reference's); give MODEL=FACTOR arguments to use others. Peak memory: the largest
# resident set of one process (the largest rank's under mpiexec), as GNU time reports it.
# Usage: scripts/bench_reference.sh [MODEL=FACTOR ...]   (after scripts/build.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
[ -x /usr/bin/time ] || { echo "bench_reference: /usr/bin/time missing (Debian package 'time')" >&2; exit 2; }
declare -A factor=([Block.stp]=0.00463 [A319.brep]=0.00388426
                   [wing_fuselage.step]=0.006 [mambo_s34.step]=0.00484712
                   [cube_filet.stp]=0.00434721 [t20_data.step]=0.0048345)
models=(Block.stp A319.brep wing_fuselage.step mambo_s34.step cube_filet.stp t20_data.step)
if [ $# -gt 0 ]; then
  models=()
  for a in "$@"; do models+=("${a%%=*}"); [ "$a" = "${a%%=*}" ] || factor[${a%%=*}]=${a#*=}; done
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
quality="$out/quality.md"
echo "| model | size factor | vertices (Gmsh) | interior irregular (Gmsh) | SICN min / avg (Gmsh) | quads below 0.1: all, forced by a corner (Gmsh) |" >"$quality"
echo "|---|---|---|---|---|---|" >>"$quality"
echo "| model | size factor | vertices (Gmsh) | 1 thread: s / MB | 2 threads: s / MB | 2 ranks: s / MB | Gmsh 1 thread: s / MB | Gmsh time / ours (1 thread, 2 threads) | ours / Gmsh memory (1 thread) |"
echo "|---|---|---|---|---|---|---|---|---|"
for m in "${models[@]}"; do
  [ -f "../shared/cad/$m" ] || continue
  f=${factor[$m]}
  runs=()
  for cfg in "1 1" "1 2" "2 1"; do
    set -- $cfg
    /usr/bin/time -f "%M %e" -o "$out/mem" mpiexec --oversubscribe --bind-to none -n "$1" ./build/drivers/qsmesh mesh \
      "../shared/cad/$m" -o "$out/m.vtu" --size-factor "$f" --threads "$2" -q --stats "$out/s_$1_$2.json" >/dev/null
    runs+=("$out/s_$1_$2.json:$(tail -n1 "$out/mem" | tr ' ' :)")
  done
  python3 - "$m" "$f" "$quality" "${runs[@]}" <<'PY'
import json, sys
sys.path.insert(0, "scripts")
import gmsh_reference
model, f, quality, runs = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
ref = gmsh_reference.runs()[model]
cells, t, mem, stats = [], [], [], []
for r in runs:
    path, kb, wall = r.rsplit(":", 2)
    stats.append(json.load(open(path)))
    t.append(float(wall)); mem.append(int(kb) / 1024)
    cells.append(f"{t[-1]:.1f} / {mem[-1]:.0f}")
KEYS = ("vertices", "irregular_interior", "sicn_min", "sicn_avg", "quads_sicn_below_0_1",
        "quads_sicn_below_0_1_forced_by_corner")
d = stats[0]
nv = d["vertices"]
same = all(all(s[k] == d[k] for k in KEYS) for s in stats[1:])
pct = lambda n, v: f"{n} = {100 * n / v:.2f}%"
with open(quality, "a") as q:
    q.write(f"| {model} | {f} | {nv} ({ref.vertices}) | {pct(d['irregular_interior'], nv)} "
            f"({pct(ref.irregular, ref.vertices)}) | {d['sicn_min']:.3f} / {d['sicn_avg']:.4f} "
            f"({ref.sicn_min:.3f} / {ref.sicn_avg:.3f}) | {d['quads_sicn_below_0_1']}, "
            f"{d['quads_sicn_below_0_1_forced_by_corner']} ({ref.below_0_1}) |"
            + ("" if same else " **2 threads or 2 ranks gave other statistics** |") + "\n")
print(f"| {model} | {f} | {nv} ({ref.vertices}) | {cells[0]} | {cells[1]} | {cells[2]} | {ref.seconds} / {ref.mb} | "
      f"{ref.seconds / t[0]:.1f}x, {ref.seconds / t[1]:.1f}x | {100 * mem[0] / ref.mb:.0f}% |")
PY
done
echo
cat "$quality"
