#!/usr/bin/env python3
"""Opens qsmesh outputs with the VTK readers ParaView uses (vtkCGNSReader for .cgns,
vtkXMLUnstructuredGridReader for .vtu, vtkMultiBlockPLOT3DReader for .xyz / .p3d with its format
detection on, as ParaView's "Auto Detect Format") and prints, per file, the blocks, cells, points and cell
types VTK sees. Needs VTK's Python module (Debian: python3-vtk9; not installed by scripts/setup.sh,
this is a developer check). Exit 1 when a file gives no cells.
Usage: scripts/check_vtk_readers.py FILE...   (with /usr/bin/python3)"""
import sys
from collections import Counter

try:
    from vtkmodules.vtkIOCGNSReader import vtkCGNSReader
    from vtkmodules.vtkIOParallel import vtkMultiBlockPLOT3DReader
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
except ImportError:
    sys.exit("check_vtk_readers: VTK's Python module is missing (Debian package python3-vtk9)")

NAMES = {3: "line", 5: "triangle", 9: "quad", 21: "quadratic edge", 28: "biquadratic quad"}


def datasets(path):
    if path.endswith(".vtu"):
        r = vtkXMLUnstructuredGridReader()
        r.SetFileName(path)
        r.Update()
        return [r.GetOutput()]
    if path.lower().endswith((".xyz", ".p3d")):
        r = vtkMultiBlockPLOT3DReader()
        r.SetXYZFileName(path)
        r.AutoDetectFormatOn()
        r.Update()
        out = r.GetOutput()
        return [out.GetBlock(i) for i in range(out.GetNumberOfBlocks()) if out.GetBlock(i)]
    r = vtkCGNSReader()
    r.SetFileName(path)
    r.UpdateInformation()
    r.EnableAllBases()
    r.Update()
    out, it = [], r.GetOutput().NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        out.append(it.GetCurrentDataObject())
        it.GoToNextItem()
    return out


status = 0
for path in sys.argv[1:]:
    blocks = datasets(path)
    types = Counter()
    for d in blocks:
        for i in range(d.GetNumberOfCells()):
            types[NAMES.get(d.GetCellType(i), d.GetCellType(i))] += 1
    cells = sum(types.values())
    points = sum(d.GetNumberOfPoints() for d in blocks)
    print(f"{path}: {len(blocks)} block(s), {cells} cells ({dict(types)}), {points} points")
    status |= cells == 0
sys.exit(status)
