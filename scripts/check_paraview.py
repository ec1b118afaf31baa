"""Opens qsmesh outputs in ParaView itself (its Python shell, pvpython) and checks what it reads.

Usage: pvpython scripts/check_paraview.py [--stats STATS.json] FILE...

Each file is opened with paraview.simple.OpenDataFile, which picks the reader the ParaView GUI
picks for that extension (.cgns: the CGNS reader, .xdmf: the XDMF3 reader, .vtu: the XML reader);
the data are fetched and their cells counted by type over every block. With --stats (the JSON of
`qsmesh mesh --stats`, from the run that wrote the files), the quads (first or second order) must
equal its "quads" and the edges its "curve_edges" where the format carries edges. ParaView is not
installed by scripts/setup.sh (Debian: paraview, python3-paraview); this is a developer check.
Exit status 1 when a file cannot be opened, gives no cells or disagrees with the stats.
"""
import argparse
import json
import sys
from collections import Counter

from paraview import servermanager
from paraview.simple import Delete, OpenDataFile, UpdatePipeline

QUADS = {9: "quad", 28: "biquadratic quad"}
EDGES = {3: "line", 4: "polyline", 21: "quadratic edge"}
NAMES = {5: "triangle", 22: "quadratic triangle", **QUADS, **EDGES}


def leaves(data):
    """The datasets of a (possibly multiblock) data object."""
    if data.IsA("vtkCompositeDataSet"):
        it = data.NewIterator()
        it.InitTraversal()
        while not it.IsDoneWithTraversal():
            yield it.GetCurrentDataObject()
            it.GoToNextItem()
    else:
        yield data


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--stats")
    parser.add_argument("files", nargs="+")
    args = parser.parse_args()
    stats = json.load(open(args.stats)) if args.stats else None
    status = 0
    for path in args.files:
        reader = OpenDataFile(path)
        if reader is None:
            print(f"{path}: ParaView has no reader for it")
            status = 1
            continue
        if hasattr(reader, "Bases"):  # CGNS: every base and zone, as a user would tick them
            reader.Bases = reader.GetProperty("BaseInfo")[::2]
        UpdatePipeline(proxy=reader)
        data = servermanager.Fetch(reader)
        types, points, blocks = Counter(), 0, 0
        for d in leaves(data):
            if d is None or not d.IsA("vtkDataSet"):
                continue
            blocks += 1
            points += d.GetNumberOfPoints()
            if d.IsA("vtkStructuredGrid"):
                types["structured cell"] += d.GetNumberOfCells()
                continue
            for i in range(d.GetNumberOfCells()):
                types[NAMES.get(d.GetCellType(i), str(d.GetCellType(i)))] += 1
        cells = sum(types.values())
        line = (f"{path}: {reader.GetXMLName()}, {blocks} block(s), {cells} cells "
                f"({dict(sorted(types.items()))}), {points} points")
        bad = []
        if cells == 0:
            bad.append("no cells")
        if stats is not None:
            quads = sum(types[n] for n in QUADS.values()) + types["structured cell"]
            if quads != stats["quads"]:
                bad.append(f"{quads} quads, the run made {stats['quads']}")
            edges = sum(types[n] for n in EDGES.values())
            if edges and edges != stats["curve_edges"]:
                bad.append(f"{edges} edges, the run made {stats['curve_edges']}")
        print(line + ("" if not bad else "  <-- " + "; ".join(bad)))
        status |= 1 if bad else 0
        Delete(reader)
    sys.exit(status)


if __name__ == "__main__":
    main()
