#!/usr/bin/env bash
# High-order quads (`--order N`, N = 2..5) on each shared model at its reference size factor
# (docs/benchmarks.md, "High order"): quads, quads reshaped along the parameter lines, quads
# untangled in parameter space, quads straightened (face nodes; curve nodes too), quads still
# invalid, nodes left off the CAD, the smallest scaled Jacobian, the
# curved elements' largest distance to the CAD over the model's diagonal
# (highorder::max_element_distance_to_cad), the time of the high-order stage and of writing the
# .vtu (Lagrange cells). With --block-patches: the blocks of the coarse layout as single patches
# (`--block-patches --order N`, A319 at 0.005): blocks, patches folded, nodes off the CAD, the
# patches' largest distance to the fine block mesh over the diagonal, the seconds of the layout
# and of the patches. One rank, 2 threads. Prints a markdown table.
# Usage: scripts/bench_high_order.sh [--block-patches] [MODEL=FACTOR ...]
#   (after scripts/build.sh; ORDERS="2 4" picks the orders)
set -euo pipefail
cd "$(dirname "$0")/.."
patches=0
if [ "${1:-}" = --block-patches ]; then patches=1; shift; fi
declare -A factor=([Block.stp]=0.00463 [A319.brep]=0.00388426 [wing_fuselage.step]=0.006
                   [mambo_s34.step]=0.00484712 [cube_filet.stp]=0.00434721
                   [t20_data.step]=0.0048345)
[ $patches = 1 ] && factor[A319.brep]=0.005
models=(Block.stp A319.brep wing_fuselage.step mambo_s34.step cube_filet.stp t20_data.step)
orders=${ORDERS:-"2 3 4 5"}
if [ $# -gt 0 ]; then
  models=()
  for a in "$@"; do models+=("${a%%=*}"); [ "$a" = "${a%%=*}" ] || factor[${a%%=*}]=${a#*=}; done
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
if [ $patches = 1 ]; then
  echo "| model | size factor | order | layout | blocks | patches folded | nodes off the CAD | distance to the fine mesh / diagonal | layout s | patches s |"
  echo "|---|---|---|---|---|---|---|---|---|---|"
  extra=--block-patches
else
  echo "| model | size factor | order | quads | reshaped | untangled | straightened (curve nodes too) | invalid | off the CAD | min scaled Jacobian | element distance / diagonal | high_order s | check s | write .vtu s |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
  extra=
fi
for m in "${models[@]}"; do
  [ -f "../shared/cad/$m" ] || continue
  for n in $orders; do
    ./build/drivers/qsmesh mesh "../shared/cad/$m" -o "$out/m.vtu" --size-factor "${factor[$m]}" \
      --order "$n" $extra --threads 2 -q --stats "$out/s.json" >/dev/null 2>&1
    /usr/bin/python3 - "$m" "${factor[$m]}" "$n" "$out/s.json" "$patches" <<'PY'
import json, sys
m, f, n, path, patches = sys.argv[1:]
s = json.load(open(path))
t = s["seconds"]
if patches == "1":
    print(f"| {m} | {f} | {n} | {s['block_layout']} | {s['blocks']} | {s['block_patches_invalid']} | "
          f"{s['block_patch_nodes_off_cad']} | {s['block_patch_max_deviation']:.2e} | "
          f"{t['layout']:.2f} | {t['patches']:.2f} |")
else:
    print(f"| {m} | {f} | {n} | {s['quads']} | {s['high_order_reshaped_quads']} | "
          f"{s['high_order_untangled_quads']} | {s['high_order_straightened_quads']} "
          f"({s['high_order_curve_straightened_quads']}) | {s['high_order_invalid_quads']} | "
          f"{s['high_order_unprojected_nodes']} | {s['high_order_min_scaled_jacobian']:.3f} | "
          f"{s['high_order_max_element_distance_to_cad']:.2e} | "
          f"{t['high_order']:.2f} | {t['high_order_check']:.2f} | {t.get('write', float('nan')):.2f} |")
PY
    rm -f "$out/m.vtu"
  done
done
