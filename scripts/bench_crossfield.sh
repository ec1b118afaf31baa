#!/usr/bin/env bash
# Cross-field stage (paper 000 Sec. 3) on one model at one size: total time, factorizations and
# solves per face, and the speed-up from 1 to 2 threads and from 1 to 2 ranks; then the size map
# and quantization (Sec. 4) timed beside the cross field. Markdown on stdout.
# Usage: scripts/bench_crossfield.sh [MODEL] [SIZE_FACTOR]   (run after scripts/build.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
model=${1:-../shared/cad/Block.stp}
factor=${2:-0.01}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
exe=./build/drivers/qsmesh
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
run() {  # ranks threads json
  mpiexec --oversubscribe --bind-to none -n "$1" $exe crossfield "$model" --check --size-factor "$factor" \
    --threads "$2" -q --stats "$3" >/dev/null
}
run 1 1 "$out/t1.json"
run 1 2 "$out/t2.json"
run 2 1 "$out/r2.json"
sizemap() {  # ranks threads method json
  mpiexec --oversubscribe --bind-to none -n "$1" $exe sizemap "$model" -o "$out/s.vtu" --size-factor "$factor" \
    --threads "$2" --sizemap "$3" -q --stats "$4" >/dev/null
}
sizemap 1 1 crossfield "$out/s11.json"
sizemap 1 2 crossfield "$out/s12.json"
sizemap 2 1 crossfield "$out/s21.json"
sizemap 1 1 features "$out/f11.json"
python3 - "$out" "$model" "$factor" <<'PY'
import json, sys, statistics
d = sys.argv[1]
t1, t2, r2 = (json.load(open(f"{d}/{n}.json")) for n in ("t1", "t2", "r2"))
faces = t1["face_list"]
fac = [f["factorizations"] for f in faces if f["ok"]]
sol = [f["solves"] for f in faces if f["ok"]]
print(f"model {sys.argv[2]}, --size-factor {sys.argv[3]}: {t1['faces']} faces, "
      f"{t1['euler_consistent']} Euler-consistent, {t1['singularities_plus']} singularities +1, "
      f"{t1['singularities_minus']} -1\n")
print("| run | background (s) | crossfield (s) | total (s) |")
print("|---|---|---|---|")
for name, r in (("1 rank x 1 thread", t1), ("1 rank x 2 threads", t2), ("2 ranks x 1 thread", r2)):
    s = r["seconds"]
    print(f"| {name} | {s['background']:.3f} | {s['crossfield']:.3f} | {s['total']:.3f} |")
print()
print(f"- factorizations per face: min {min(fac)}, mean {statistics.mean(fac):.2f}, max {max(fac)}")
print(f"- solves per face: min {min(sol)}, mean {statistics.mean(sol):.1f}, median {statistics.median(sol)}, max {max(sol)}")
print(f"- speed-up of the cross-field stage: 1 -> 2 threads {t1['seconds']['crossfield'] / t2['seconds']['crossfield']:.2f}x, "
      f"1 -> 2 ranks {t1['seconds']['crossfield'] / r2['seconds']['crossfield']:.2f}x")
print()
print("Size map and quantization (`qsmesh sizemap`), beside the cross field of the same run:")
print()
print("| run | method | crossfield (s) | sizemap (s) | quantize (s) | chords | edges |")
print("|---|---|---|---|---|---|---|")
for name, fn, method in (("1 rank x 1 thread", "s11", "crossfield"), ("1 rank x 2 threads", "s12", "crossfield"),
                         ("2 ranks x 1 thread", "s21", "crossfield"), ("1 rank x 1 thread", "f11", "features")):
    r = json.load(open(f"{d}/{fn}.json")); s = r["seconds"]
    print(f"| {name} | {method} | {s.get('crossfield', 0):.3f} | {s['sizemap']:.3f} | {s['quantize']:.4f} | {r['chords']} | {r['edges']} |")
PY
