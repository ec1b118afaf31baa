#!/usr/bin/env bash
# Checks the foundation on every shared CAD model and the built-in example:
#  - `qsmesh info` counts against ../shared/cad/README.md;
#  - the mesh written as CGNS, VTU, MSH and HDF5 at 1, 2 and 4 ranks, files compared
#    byte for byte across rank counts, cgnscheck output scanned for warnings and errors;
#  - statistics (vertices, triangles, smallest angles, time) from --stats; with --until unstructured
#    the quad statistics instead (quads, interior irregular vertices, SICN min/avg, failed faces);
#    with --until quasi-structured also the faces meshed by patterns.
# Usage: scripts/check_models.sh [--size-factor F] [--threads T] [--until STAGE]   (after scripts/build.sh)
set -uo pipefail
cd "$(dirname "$0")/.."
factor=0.02
threads=1
until=background
while [ $# -gt 0 ]; do
  case "$1" in
    --size-factor) factor=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --until) until=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
exe=./build/drivers/qsmesh
cad=../shared/cad
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
status=0

declare -A expected=(
  [Block.stp]="1044 1584 533" [A319.brep]="287 375 83" [wing_fuselage.step]="20 38 16"
  [mambo_s34.step]="77 123 46" [cube_filet.stp]="40 74 25" [t20_data.step]="28 48 21")

models=()
for m in Block.stp A319.brep wing_fuselage.step mambo_s34.step cube_filet.stp t20_data.step; do
  [ -f "$cad/$m" ] && models+=("$cad/$m")
done
$exe example wing-body -o "$out/wing_body.step" >/dev/null && models+=("$out/wing_body.step")

if [ "$until" != background ]; then
  printf "| model | corners/curves/faces | ranks 1/2/4 identical (cgns, vtu, msh, h5) | cgnscheck | vertices | quads | triangles | interior irregular (%% of vertices) | SICN min / avg | conforming | faces failed / fell back | faces by pattern | time 1 rank (s) |\n"
  printf "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n"
else
  printf "| model | corners/curves/faces | ranks 1/2/4 identical (cgns, vtu, msh, h5) | cgnscheck | vertices | triangles | min angle | tris < 10 deg (at sharp corners) | faces failed / fell back | time 1 rank (s) |\n"
  printf "|---|---|---|---|---|---|---|---|---|---|\n"
fi
for model in "${models[@]}"; do
  name=$(basename "$model")
  counts=$($exe info --json "$model" 2>/dev/null | python3 -c 'import json,sys; d=json.load(sys.stdin); print(d["corners"], d["curves"], d["faces"])')
  if [ -n "${expected[$name]:-}" ] && [ "$counts" != "${expected[$name]}" ]; then
    counts="$counts (expected ${expected[$name]})"; status=1
  fi
  same=yes
  for ext in cgns vtu msh h5; do
    for np in 1 2 4; do
      mpiexec --oversubscribe --bind-to none -n $np $exe mesh "$model" -o "$out/m_$np.$ext" --size-factor "$factor" \
        --until "$until" --threads "$threads" -q --stats "$out/s_$np.json" >/dev/null 2>"$out/err_$np" || { same="FAILED (np $np)"; status=1; }
    done
    cmp -s "$out/m_1.$ext" "$out/m_2.$ext" && cmp -s "$out/m_1.$ext" "$out/m_4.$ext" || { same="no ($ext)"; status=1; }
    if [ "$ext" = cgns ]; then
      check=$(cgnscheck "$out/m_1.cgns" 2>&1 | grep -ciE "warning|error")
      [ "$check" = 0 ] && check=clean || { check="$check issues"; status=1; }
      cp "$out/s_1.json" "$out/stats.json"
    fi
  done
  if [ "$until" != background ]; then
    python3 - "$out/stats.json" "$name" "$counts" "$same" "$check" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
irr = 100.0 * d["irregular_interior"] / max(1, d["vertices"])
print(f"| {sys.argv[2]} | {sys.argv[3]} | {sys.argv[4]} | {sys.argv[5]} | {d['vertices']} | {d['quads']} | {d['triangles']} | "
      f"{d['irregular_interior']} ({irr:.1f}%) | {d['sicn_min']:.3f} / {d['sicn_avg']:.3f} | {d['conforming']} | "
      f"{d['faces_failed']} / {d['faces_fell_back']} | {d.get('faces_meshed_by_pattern', '-')} | {d['seconds']['total']:.2f} |")
PY
    continue
  fi
  read -r v t a h0 h1 sc ff fb sec < <(python3 - "$out/stats.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
h = d["min_angle_histogram"]
print(d["vertices"], d["triangles"], round(d["min_angle_deg"], 2), h["0-5"], h["5-10"],
      d["small_angle_at_sharp_corner"], d["faces_failed"], d["faces_fell_back"], round(d["seconds"]["total"], 2))
PY
)
  printf "| %s | %s | %s | %s | %s | %s | %s | %s (%s) | %s / %s | %s |\n" "$name" "$counts" "$same" "$check" "$v" "$t" "$a" "$((h0 + h1))" "$sc" "$ff" "$fb" "$sec"
done
exit $status
