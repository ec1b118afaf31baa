#!/usr/bin/env bash
# Runs `qsmesh mesh --until STAGE` on each shared model at a size that gives the vertex count of the
# Gmsh reference run of ../shared/cad/README.md (the size factor is searched, up to eight runs per
# model, until the count is within 1%; the run closest to the reference count is reported), and
# prints qsmesh's numbers beside the reference's: vertices, interior irregular vertices, SICN
# min / avg, wall time and peak memory (one thread, one rank). The reference numbers
# are read from that README by scripts/gmsh_reference.py.
# Usage: scripts/compare_reference.sh [STAGE] [MODEL...]   (after scripts/build.sh; default stage
# quasi-structured, default models: all six). QSMESH_ARGS adds options to every run, e.g.
# QSMESH_ARGS="--curvature-edges 0" for the reference's sizing (Gmsh's quasi-structured algorithm
# sizes by the cross field and the CAD features, not by the curvature).
set -euo pipefail
cd "$(dirname "$0")/.."
stage=${1:-quasi-structured}
shift || true
models=("$@")
[ ${#models[@]} -gt 0 ] || models=(Block.stp A319.brep wing_fuselage.step mambo_s34.step cube_filet.stp t20_data.step)
[ -x /usr/bin/time ] || { echo "compare_reference: /usr/bin/time missing (Debian package 'time')" >&2; exit 2; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "| model | size factor | vertices (Gmsh) | interior irregular (Gmsh) | SICN min / avg (Gmsh) | faces by pattern | time s (Gmsh) | peak MB (Gmsh) |"
echo "|---|---|---|---|---|---|---|---|"
for m in "${models[@]}"; do
  [ -f "../shared/cad/$m" ] || continue
  python3 - "$m" "$stage" "$out" <<'PY'
import json, math, os, subprocess, sys
sys.path.insert(0, "scripts")
import gmsh_reference
model, stage, out = sys.argv[1], sys.argv[2], sys.argv[3]
ref = gmsh_reference.runs()[model]
target = ref.vertices
def run(f):
    cmd = ["/usr/bin/time", "-f", "%M", "-o", f"{out}/mem", "./build/drivers/qsmesh", "mesh", f"../shared/cad/{model}",
           "-o", f"{out}/m.vtu", "--size-factor", f"{f:.6g}", "--until", stage, "--threads", "1", "-q", "--stats", f"{out}/s.json"]
    cmd += os.environ.get("QSMESH_ARGS", "").split()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    d = json.load(open(f"{out}/s.json"))
    d["peak_mb"] = int(open(f"{out}/mem").read().split()[-1]) / 1024
    return d
# v ~ f^-a: start at 0.02, then secant steps in log space (a = 2 until two runs tell more).
f, runs = 0.02, []
for _ in range(8):
    d = run(f)
    runs.append((f, d["vertices"], d))
    if abs(d["vertices"] - target) <= 0.01 * target:
        break
    if len(runs) >= 2 and runs[-1][1] != runs[-2][1]:
        a = -math.log(runs[-1][1] / runs[-2][1]) / math.log(runs[-1][0] / runs[-2][0])
        a = min(max(a, 0.5), 4.0)
    else:
        a = 2.0
    f = f * (d["vertices"] / target) ** (1.0 / a)
f, v, d = min(runs, key=lambda r: abs(r[1] - target))
irr = 100.0 * d["irregular_interior"] / v
within = "" if abs(v - target) <= 0.1 * target else " (not within 10%)"
print(f"| {model} | {f:.6g} | {v}{within} ({target}) | {d['irregular_interior']} = {irr:.2f}% ({ref.irregular} = {100.0 * ref.irregular / target:.2f}%) | "
      f"{d['sicn_min']:.3f} / {d['sicn_avg']:.3f} ({ref.sicn_min:.3f} / {ref.sicn_avg:.3f}) | {d.get('faces_meshed_by_pattern', '-')} / {d['faces']} | "
      f"{d['seconds']['total']:.1f} ({ref.seconds}) | {d['peak_mb']:.0f} ({ref.mb}) |")
PY
done
