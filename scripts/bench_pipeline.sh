#!/usr/bin/env bash
# End-to-end time per stage and peak memory of `qsmesh mesh` on one model at one size, at 1 and 2
# threads (one rank) and 1 and 2 ranks (one thread each), with the quality of the result. Prints a
# markdown table. Peak memory is the largest resident set of one process (the run's, or the largest
# rank's under mpiexec), as GNU time reports it.
# Usage: scripts/bench_pipeline.sh [MODEL] [SIZE_FACTOR] [STAGE]   (after scripts/build.sh)
#   defaults: ../shared/cad/Block.stp 0.02 unstructured
set -euo pipefail
cd "$(dirname "$0")/.."
model=${1:-../shared/cad/Block.stp}
factor=${2:-0.02}
stage=${3:-unstructured}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
exe=./build/drivers/qsmesh
[ -x /usr/bin/time ] || { echo "bench_pipeline: /usr/bin/time missing (Debian package 'time'; scripts/setup.sh installs it)" >&2; exit 2; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
row() {  # label, ranks, threads
  local label=$1 np=$2 nt=$3
  /usr/bin/time -f "%M" -o "$out/mem" mpiexec --oversubscribe --bind-to none -n "$np" $exe mesh "$model" \
    -o "$out/m.vtu" --size-factor "$factor" --until "$stage" --threads "$nt" -q --stats "$out/s.json" >/dev/null
  python3 - "$out/s.json" "$label" "$(tail -n1 "$out/mem")" <<'PY'
import json, sys
d = json.load(open(sys.argv[1])); s = d["seconds"]
def t(k): return f"{s[k]:.2f}" if k in s else "-"
nv = d["vertices"]
irr = f"{100.0 * d['irregular_interior'] / nv:.1f}%" if nv else "-"
quality = f"{d['sicn_min']:.3f} / {d['sicn_avg']:.3f}" if d["quads"] else f"{d['min_angle_deg']:.1f} deg"
stages = " | ".join(t(k) for k in ["curves", "background", "crossfield", "sizemap", "quantize", "patterns", "unstructured", "improvement", "write"])
print(f"| {sys.argv[2]} | {nv} | {d['quads']} | {irr} | {quality} | {stages} | {s['total']:.2f} | {int(sys.argv[3]) / 1024:.0f} |")
PY
}
echo "model: $model, --size-factor $factor, --until $stage, $(nproc) cores"
echo
echo "| run | vertices | quads | interior irregular | SICN min / avg | curves | background | crossfield | sizemap | quantize | patterns | unstructured | improvement | write | total (s) | peak MB |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
row "1 rank x 1 thread" 1 1
row "1 rank x 2 threads" 1 2
row "2 ranks x 1 thread" 2 1
