#!/usr/bin/env python3
"""Meshes one model at several size factors and prints one row per factor.

Columns: size factor, vertices, interior irregular vertices, SICN min / avg, quads with SICN < 0.1,
faces by pattern, and whether the row meets the criteria given with --max-irregular and
--min-avg (both by default: wing_fuselage's Gmsh reference, 84 and 0.918). With --faces, the
faces that carry interior irregular vertices follow each row: id:method:irregular (the method
"p" for a pattern fill, "u" for the unstructured path, with the pattern refusal after a slash).

Usage: scripts/sweep_factors.py [MODEL] [--factors F ...] [-- EXTRA QSMESH ARGS]
(after scripts/build.sh; MODEL defaults to ../shared/cad/wing_fuselage.step and the factors to
its 10% vertex window, 0.0058-0.0063). Issue 29: every factor must meet both criteria.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_FACTORS = ["0.0058", "0.00588", "0.0059", "0.006", "0.0061", "0.00612", "0.0062", "0.0063"]


def main():
    argv = sys.argv[1:]
    extra = []
    if "--" in argv:
        i = argv.index("--")
        argv, extra = argv[:i], argv[i + 1:]
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("model", nargs="?",
                    default=os.path.join(ROOT, "..", "shared", "cad", "wing_fuselage.step"))
    ap.add_argument("--factors", nargs="+", default=DEFAULT_FACTORS)
    ap.add_argument("--max-irregular", type=int, default=84)
    ap.add_argument("--min-avg", type=float, default=0.918)
    ap.add_argument("--threads", default="2")
    ap.add_argument("--faces", action="store_true", help="list the faces with irregular vertices")
    ap.add_argument("--qsmesh", default=os.path.join(ROOT, "build", "drivers", "qsmesh"))
    ap.add_argument("--keep", help="folder for the .json stats of every run (else temporary)")
    a = ap.parse_args(argv)
    out = a.keep or tempfile.mkdtemp(prefix="sweep_")
    os.makedirs(out, exist_ok=True)
    print("| F | vertices | interior irregular | SICN min / avg | SICN < 0.1 | by pattern | both |")
    print("|---|---|---|---|---|---|---|")
    met = 0
    for f in a.factors:
        stats = os.path.join(out, f"s_{f}.json")
        cmd = [a.qsmesh, "mesh", a.model, "-o", os.path.join(out, "m.msh"), "--size-factor", f,
               "--threads", a.threads, "-q", "--stats", stats] + extra
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        d = json.load(open(stats))
        irr = d["irregular_interior"]
        ok = irr <= a.max_irregular and d["sicn_avg"] >= a.min_avg
        met += ok
        print(f"| {f} | {d['vertices']} | {irr} | {d['sicn_min']:.3f} / {d['sicn_avg']:.3f} | "
              f"{d.get('quads_sicn_below_0_1', '')} | {d.get('faces_meshed_by_pattern', '')} | "
              f"{'yes' if ok else 'no'} |", flush=True)
        if a.faces:
            cells = []
            for fs in d.get("face_stats", []):
                n = fs.get("irregular_interior", 0)
                if n == 0:
                    continue
                m = fs.get("method", "")
                r = fs.get("pattern_refusal", "")
                cells.append(f"{fs['face']}:{m}{'/' + r if r else ''}:{n}")
            print("    " + " ".join(cells), flush=True)
    print(f"{met} of {len(a.factors)} factors meet both criteria")


if __name__ == "__main__":
    main()
