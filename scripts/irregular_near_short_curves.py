#!/usr/bin/env python3
"""Where the interior irregular vertices of a quad mesh sit relative to the model's short curves.

Usage: irregular_near_short_curves.py MESH.msh [--shorter-than L] [--radii R1,R2,...]

Reads a first-order MSH 4.1 file written by `qsmesh mesh -o MESH.msh`, finds the CAD curves whose
mesh is shorter than L (model units, default 0.1) and counts the interior irregular vertices (nodes
classified on a face whose quad valence is not 4, the reference runs' definition) within each
radius of any vertex of those curves. Used for docs/benchmarks.md: on wing_fuselage.step the two
0.036-long curves at the wing roots set the size map over a radius of about 30 (rule (i) of paper
000 Sec. 4.1 graded by Eq. 10), and this tells how many irregular vertices that region holds.
Pure Python, no third-party module.
"""
import argparse
import math
import sys
from collections import Counter


def read_msh(path):
    """Returns (xyz by node tag, (dim, entity) by node tag, quads, bars by curve entity)."""
    with open(path) as f:
        lines = f.read().split("\n")
    xyz, where, quads, bars = {}, {}, [], {}
    i = 0
    while i < len(lines):
        s = lines[i].strip()
        if s == "$Nodes":
            blocks = int(lines[i + 1].split()[0])
            i += 2
            for _ in range(blocks):
                dim, tag, _param, count = map(int, lines[i].split())
                i += 1
                tags = [int(lines[i + k]) for k in range(count)]
                i += count
                for k in range(count):
                    xyz[tags[k]] = tuple(map(float, lines[i + k].split()[:3]))
                    where[tags[k]] = (dim, tag)
                i += count
            continue
        if s == "$Elements":
            blocks = int(lines[i + 1].split()[0])
            i += 2
            for _ in range(blocks):
                dim, tag, kind, count = map(int, lines[i].split())
                i += 1
                for k in range(count):
                    nodes = list(map(int, lines[i + k].split()))[1:]
                    if kind == 3:
                        quads.append(nodes)
                    elif kind == 1:
                        bars.setdefault(tag, []).append(nodes)
                    elif kind in (8, 10):
                        sys.exit("irregular_near_short_curves.py: second-order meshes are not read")
                i += count
            continue
        i += 1
    return xyz, where, quads, bars


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("mesh")
    parser.add_argument("--shorter-than", type=float, default=0.1)
    parser.add_argument("--radii", default="1.5,5,10,20,30,40")
    args = parser.parse_args()
    radii = [float(r) for r in args.radii.split(",")]
    xyz, where, quads, bars = read_msh(args.mesh)

    short = {}
    for curve, segments in sorted(bars.items()):
        length = sum(math.dist(xyz[a], xyz[b]) for a, b in segments)
        if length < args.shorter_than:
            short[curve] = length
    sources = sorted({v for c in short for seg in bars[c] for v in seg})
    print(f"curves shorter than {args.shorter_than}: "
          + (", ".join(f"{c} ({short[c]:.4g} long)" for c in short) or "none"))

    valence = Counter(v for q in quads for v in q)
    irregular = [v for v, n in valence.items() if where[v][0] == 2 and n != 4]
    print(f"interior irregular vertices: {len(irregular)} of {len(xyz)} vertices")
    if not sources:
        return
    dist = [min(math.dist(xyz[v], xyz[s]) for s in sources) for v in irregular]
    print("within distance of those curves: "
          + "; ".join(f"{r:g}: {sum(d < r for d in dist)}" for r in radii))


if __name__ == "__main__":
    main()
