"""The Gmsh reference runs of ../shared/cad/README.md ("Reference runs" table), read from the README
itself so that the benchmark scripts (compare_reference.sh, bench_reference.sh) share one source.

runs() returns {model file name: Run}, e.g. runs()["Block.stp"].seconds == 183.4.
"""
import collections
import os

Run = collections.namedtuple("Run", "vertices irregular sicn_min sicn_avg seconds mb below_0_1")

_README = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "cad", "README.md")


def runs(readme=_README):
    out = {}
    in_table = False
    with open(readme) as f:
        for line in f:
            if line.startswith("## Reference runs"):
                in_table = True
                continue
            if in_table and line.startswith("## "):
                break
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            # model | vertices | quads | interior irregular | % | SICN min | SICN avg | < 0.1 | s | MB
            if not in_table or len(cells) != 10 or not cells[1].isdigit():
                continue
            out[cells[0]] = Run(int(cells[1]), int(cells[3]), float(cells[5]), float(cells[6]),
                                float(cells[8]), int(float(cells[9])), int(cells[7]))
    if not out:
        raise SystemExit(f"gmsh_reference: no reference table in {readme}")
    return out
