#!/usr/bin/env bash
# The coarse block-structured outputs (`--block-structured --layout coarse`, issue 30's "Checks")
# on every shared model and the built-in wing-body example: the .cgns at 1, 2 and 4 ranks compared
# byte for byte, check_blocks --conforming (every block side shared whole with one other side, or
# on the free boundary; 1-to-1 points matched), cgnscheck's errors and warnings, ParaView's CGNS
# reader (pvpython scripts/check_paraview.py, where pvpython is installed: Debian's paraview and
# python3-paraview) against check_blocks' zone and quad counts, and the PLOT3D file of the same run
# read back (scripts/check_plot3d.py). Prints a markdown table; exit status 1 on any failure.
# Usage: scripts/check_coarse.sh [--threads T] [MODEL=FACTOR ...]   (after scripts/build.sh)
set -uo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
threads=1
if [ "${1:-}" = --threads ]; then threads=$2; shift 2; fi
exe=./build/drivers/qsmesh
check=./build/tests/layout/check_blocks
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
declare -A factor=([Block.stp]=0.00463 [A319.brep]=0.005 [wing_fuselage.step]=0.006
                   [mambo_s34.step]=0.00484712 [cube_filet.stp]=0.00434721
                   [t20_data.step]=0.0048345 [wing_body.step]=0.01)
models=()
for m in Block.stp A319.brep wing_fuselage.step mambo_s34.step cube_filet.stp t20_data.step; do
  [ -f "../shared/cad/$m" ] && models+=("../shared/cad/$m")
done
$exe example wing-body -o "$out/wing_body.step" >/dev/null && models+=("$out/wing_body.step")
if [ $# -gt 0 ]; then
  models=()
  for a in "$@"; do
    m=${a%%=*}
    [ "$a" = "$m" ] || factor[$(basename "$m")]=${a#*=}
    [ -f "$m" ] || m=../shared/cad/$m
    models+=("$m")
  done
fi
pv=$(command -v pvpython || true)
status=0
echo "| model | size factor | layout written, fine SICN avg | blocks | quads | ranks 1/2/4 identical | check_blocks --conforming | cgnscheck errors / warnings | ParaView | PLOT3D read back |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for model in "${models[@]}"; do
  name=$(basename "$model")
  f=${factor[$name]:-0.01}
  same=yes
  for np in 1 2 4; do
    mpiexec --oversubscribe --bind-to none -n $np $exe mesh "$model" -o "$out/c_$np.cgns" \
      --size-factor "$f" --block-structured --layout coarse --threads "$threads" -q \
      --stats "$out/s_$np.json" >/dev/null 2>"$out/err_$np" || { same="FAILED (np $np)"; status=1; }
  done
  cmp -s "$out/c_1.cgns" "$out/c_2.cgns" && cmp -s "$out/c_1.cgns" "$out/c_4.cgns" ||
    { [ "$same" = yes ] && same=no; status=1; }
  layout=$(/usr/bin/python3 -c 'import json,sys; d = json.load(open(sys.argv[1])); print(d.get("block_layout", "?"), "SICN %.4f" % d.get("block_mesh_sicn_avg", 0))' "$out/s_1.json" 2>/dev/null)
  conf=$($check --conforming "$out/c_1.cgns" 2>&1)
  conf_rc=$?
  zones=$(sed -n 's/.*: \([0-9]*\) structured zones (\([0-9]*\) quads).*/\1 \2/p' <<<"$conf" | head -1)
  blocks=${zones% *}; quads=${zones#* }
  [ $conf_rc -eq 0 ] && conf_cell="pass" || { conf_cell="FAIL: $(tail -1 <<<"$conf" | cut -c1-80)"; status=1; }
  cc=$(cgnscheck "$out/c_1.cgns" 2>&1)
  errors=$(grep -ci "error" <<<"$cc"); warnings=$(grep -ci "warning" <<<"$cc")
  [ "$errors" -eq 0 ] || status=1
  if [ -n "$pv" ]; then
    line=$($pv scripts/check_paraview.py "$out/c_1.cgns" 2>/dev/null | tail -1)
    pv_blocks=$(sed -n 's/.*, \([0-9]*\) block(s), \([0-9]*\) cells.*/\1 \2/p' <<<"$line")
    if [ "$pv_blocks" = "$blocks $quads" ]; then pv_cell="opens: $blocks zones, $quads cells"
    else pv_cell="MISMATCH: ${line:-no output}"; status=1; fi
  else
    pv_cell="not installed"
  fi
  mpiexec -n 1 $exe mesh "$model" -o "$out/c.xyz" --size-factor "$f" --block-structured \
    --layout coarse --threads "$threads" -q >/dev/null 2>&1 &&
    /usr/bin/python3 scripts/check_plot3d.py "$out/c.xyz" "$out/c_1.cgns" >"$out/p3d" 2>&1 &&
    p3d=pass || { p3d="FAIL: $(tail -1 "$out/p3d" 2>/dev/null | cut -c1-60)"; status=1; }
  echo "| $name | $f | $layout | $blocks | $quads | $same | $conf_cell | $errors / $warnings | $pv_cell | $p3d |"
  rm -f "$out"/c*.cgns "$out"/c.xyz "$out"/*.json
done
exit $status
