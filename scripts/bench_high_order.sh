#!/usr/bin/env bash
# High-order quads (`--order N`, N = 2..5) on each shared model at its reference size factor
# (docs/benchmarks.md, "High order"): quads, quads straightened (face nodes; curve nodes too),
# quads still invalid, nodes left off the CAD, the curved elements' largest distance to the CAD
# over the model's diagonal (highorder::max_element_distance_to_cad), the time of the high-order
# stage and of writing the .vtu (Lagrange cells). One rank, 2 threads. Prints a markdown table.
# Usage: scripts/bench_high_order.sh [MODEL=FACTOR ...]   (after scripts/build.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
declare -A factor=([Block.stp]=0.00463 [A319.brep]=0.00388426 [wing_fuselage.step]=0.006
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
echo "| model | size factor | order | quads | reshaped | straightened (curve nodes too) | invalid | off the CAD | element distance / diagonal | high_order s | check s | write .vtu s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
for m in "${models[@]}"; do
  [ -f "../shared/cad/$m" ] || continue
  for n in $orders; do
    ./build/drivers/qsmesh mesh "../shared/cad/$m" -o "$out/m.vtu" --size-factor "${factor[$m]}" \
      --order "$n" --threads 2 -q --stats "$out/s.json" >/dev/null
    /usr/bin/python3 - "$m" "${factor[$m]}" "$n" "$out/s.json" <<'PY'
import json, sys
m, f, n, path = sys.argv[1:]
s = json.load(open(path))
t = s["seconds"]
print(f"| {m} | {f} | {n} | {s['quads']} | {s['high_order_reshaped_quads']} | "
      f"{s['high_order_straightened_quads']} "
      f"({s['high_order_curve_straightened_quads']}) | {s['high_order_invalid_quads']} | "
      f"{s['high_order_unprojected_nodes']} | {s['high_order_max_element_distance_to_cad']:.2e} | "
      f"{t['high_order']:.2f} | {t['high_order_check']:.2f} | {t.get('write', float('nan')):.2f} |")
PY
    rm -f "$out/m.vtu"
  done
done
