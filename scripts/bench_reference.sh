#!/usr/bin/env bash
# End-to-end time and peak memory of `qsmesh mesh` (default stage) on each shared model at the size
# that gives the vertex count of the Gmsh reference run (../shared/cad/README.md), at 1 and 2
# threads (one rank) and 1 and 2 ranks (one thread each), beside the reference's time and memory
# (one thread). Time: wall clock of the whole command (mpiexec, loading, writing included). Prints
# a markdown table (the reference numbers are read from ../shared/cad/README.md by
# scripts/gmsh_reference.py). The size factors are those scripts/compare_reference.sh
# found (eleventh session, A319's twelfth; vertex counts within 5% of the reference's); give
# MODEL=FACTOR arguments to use others. Peak memory: the largest resident set of one process (the
# largest rank's under mpiexec), as GNU time reports it.
# Usage: scripts/bench_reference.sh [MODEL=FACTOR ...]   (after scripts/build.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
[ -x /usr/bin/time ] || { echo "bench_reference: /usr/bin/time missing (Debian package 'time')" >&2; exit 2; }
declare -A factor=([Block.stp]=0.00468292 [A319.brep]=0.0042893
                   [wing_fuselage.step]=0.00645448 [mambo_s34.step]=0.00493082
                   [cube_filet.stp]=0.00438062 [t20_data.step]=0.00476072)
models=(Block.stp A319.brep wing_fuselage.step mambo_s34.step cube_filet.stp t20_data.step)
if [ $# -gt 0 ]; then
  models=()
  for a in "$@"; do models+=("${a%%=*}"); [ "$a" = "${a%%=*}" ] || factor[${a%%=*}]=${a#*=}; done
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
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
  python3 - "$m" "$f" "${runs[@]}" <<'PY'
import json, sys
sys.path.insert(0, "scripts")
import gmsh_reference
model, f, runs = sys.argv[1], sys.argv[2], sys.argv[3:]
ref = gmsh_reference.runs()[model]
cells, t, mem = [], [], []
for r in runs:
    path, kb, wall = r.rsplit(":", 2)
    d = json.load(open(path))
    t.append(float(wall)); mem.append(int(kb) / 1024)
    cells.append(f"{t[-1]:.1f} / {mem[-1]:.0f}")
    nv = d["vertices"]
print(f"| {model} | {f} | {nv} ({ref.vertices}) | {cells[0]} | {cells[1]} | {cells[2]} | {ref.seconds} / {ref.mb} | "
      f"{ref.seconds / t[0]:.1f}x, {ref.seconds / t[1]:.1f}x | {100 * mem[0] / ref.mb:.0f}% |")
PY
done
