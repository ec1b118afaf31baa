#!/usr/bin/env python3
"""ctest: scripts/poor_quads.py on two MSH 4.1 files written here by hand. A unit square and a
1 x 0.05 quad (SICN 0.1 x 0.05 x 2 / (1 + 0.0025) = 0.0998: just below 0.1) with no CAD corner:
one avoidable quad. A quad whose corner node is a CAD corner of 5 degrees: one quad below 0.1,
forced. --where and --ref run on both. Usage: test_poor_quads.py SCRIPTS_DIR WORK_DIR"""
import math
import os
import subprocess
import sys


def write_msh(path, corner_nodes, nodes, quads):
    """nodes: {tag: (x, y, z)}; corner_nodes: tags on CAD corners (dim 0), the rest in face 1."""
    lines = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$Entities",
             f"{len(corner_nodes)} 0 1 0"]
    for k, t in enumerate(corner_nodes):
        x, y, z = nodes[t]
        lines.append(f"{k + 1} {x} {y} {z} 0")
    lines.append("1 0 0 0 2 2 0 0 0")
    lines += ["$EndEntities", "$Nodes"]
    blocks = [(0, k + 1, [t]) for k, t in enumerate(corner_nodes)]
    blocks.append((2, 1, [t for t in sorted(nodes) if t not in corner_nodes]))
    lines.append(f"{len(blocks)} {len(nodes)} 1 {max(nodes)}")
    for dim, tag, tags in blocks:
        lines.append(f"{dim} {tag} 0 {len(tags)}")
        lines += [str(t) for t in tags]
        lines += [" ".join(map(str, nodes[t])) for t in tags]
    lines += ["$EndNodes", "$Elements", f"1 {len(quads)} 1 {len(quads)}", f"2 1 3 {len(quads)}"]
    lines += [f"{i + 1} " + " ".join(map(str, q)) for i, q in enumerate(quads)]
    lines.append("$EndElements")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def run(script, *args):
    r = subprocess.run([sys.executable, script, *args], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"poor_quads.py {' '.join(args)} failed: {r.stderr}")
    return r.stdout


def main():
    scripts, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    script = os.path.join(scripts, "poor_quads.py")
    flat = os.path.join(work, "flat.msh")
    write_msh(flat, [], {1: (0, 0, 0), 2: (1, 0, 0), 3: (1, 1, 0), 4: (0, 1, 0), 5: (2, 0, 0),
                         6: (2, 0.05, 0), 7: (1, 0.05, 0)},
              [(1, 2, 3, 4), (2, 5, 6, 7)])
    a = math.radians(5)
    sharp = os.path.join(work, "sharp.msh")
    write_msh(sharp, [1], {1: (0, 0, 0), 2: (1, 0, 0), 3: (1, 0.06, 0),
                           4: (math.cos(a), math.sin(a), 0)}, [(1, 2, 3, 4)])
    failures = []
    out = run(script, flat, "--where")
    if "2 quads, 1 below SICN 0.1 (0 forced" not in out or "  1: 1" not in out:
        failures.append("flat: " + out)
    if "sicn 0.100" not in out and "sicn 0.099" not in out:
        failures.append("flat --where: " + out)
    out = run(script, flat, "--threshold", "0.09")
    if "0 below SICN 0.09" not in out:
        failures.append("flat at 0.09: " + out)
    out = run(script, sharp, "--where", "--all", "--ref", flat)
    if "1 quads, 1 below SICN 0.1 (1 forced" not in out or "forced face 1" not in out:
        failures.append("sharp: " + out)
    if "  1: 0 / 1" not in out:
        failures.append("sharp --ref: " + out)
    for f in failures:
        print("FAIL", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
