#!/usr/bin/env bash
# The blocks of the coarse layout as single Lagrange patches (`--block-patches --order N`) on each
# shared model: blocks, patches folded, nodes off the CAD, the patches' largest distance to the
# fine block mesh over the model's diagonal, and the seconds of the layout and of the patches.
# One rank, 2 threads. Prints a markdown table.
# Usage: scripts/bench_block_patches.sh [MODEL=FACTOR ...]   (after scripts/build.sh; ORDERS="2 4")
set -euo pipefail
cd "$(dirname "$0")/.."
declare -A factor=([Block.stp]=0.00463 [A319.brep]=0.005 [wing_fuselage.step]=0.006
                   [mambo_s34.step]=0.00484712 [cube_filet.stp]=0.00434721
                   [t20_data.step]=0.0048345)
models=(Block.stp A319.brep wing_fuselage.step mambo_s34.step cube_filet.stp t20_data.step)
orders=${ORDERS:-"2 3 4 5"}
if [ $# -gt 0 ]; then
  models=()
  for a in "$@"; do models+=("${a%%=*}"); [ "$a" = "${a%%=*}" ] || factor[${a%%=*}]=${a#*=}; done
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "| model | size factor | order | layout | blocks | patches folded | nodes off the CAD | distance to the fine mesh / diagonal | layout s | patches s |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for m in "${models[@]}"; do
  [ -f "../shared/cad/$m" ] || continue
  for n in $orders; do
    ./build/drivers/qsmesh mesh "../shared/cad/$m" -o "$out/p.vtu" --size-factor "${factor[$m]}" \
      --block-patches --order "$n" --threads 2 -q --stats "$out/s.json" >/dev/null 2>&1
    /usr/bin/python3 - "$m" "${factor[$m]}" "$n" "$out/s.json" <<'PY'
import json, sys
m, f, n, path = sys.argv[1:]
s = json.load(open(path))
t = s["seconds"]
print(f"| {m} | {f} | {n} | {s['block_layout']} | {s['blocks']} | {s['block_patches_invalid']} | "
      f"{s['block_patch_nodes_off_cad']} | {s['block_patch_max_deviation']:.2e} | "
      f"{t['layout']:.2f} | {t['patches']:.2f} |")
PY
    rm -f "$out/p.vtu"
  done
done
