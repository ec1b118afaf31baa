#!/usr/bin/env bash
# Time of the background stage (curve meshing + per-face triangulation) on one model at one size,
# at 1 and 2 threads (one rank) and at 1 and 2 ranks (one thread each). Prints a markdown table.
# Usage: scripts/bench_background.sh [MODEL] [SIZE_FACTOR]   (run after scripts/build.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
model=${1:-../shared/cad/Block.stp}
factor=${2:-0.01}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
exe=./build/drivers/qsmesh
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
row() {  # label, ranks, threads
  local label=$1 np=$2 nt=$3
  /usr/bin/time -f "%M" -o "$out/mem" mpiexec --oversubscribe --bind-to none -n "$np" $exe mesh "$model" -o "$out/m.vtu" \
    --size-factor "$factor" --threads "$nt" -q --stats "$out/s.json" >/dev/null
  python3 - "$out/s.json" "$label" "$(cat "$out/mem")" <<'PY'
import json, sys
d = json.load(open(sys.argv[1])); s = d["seconds"]
print(f"| {sys.argv[2]} | {d['vertices']} | {d['triangles']} | {s['curves']:.3f} | {s['background']:.3f} | {s['total']:.3f} |")
PY
}
echo "model: $model, --size-factor $factor, $(nproc) cores"
echo
echo "| run | vertices | triangles | curves (s) | faces (s) | total (s) |"
echo "|---|---|---|---|---|---|"
row "1 rank x 1 thread" 1 1
row "1 rank x 2 threads" 1 2
row "2 ranks x 1 thread" 2 1
