#!/usr/bin/python3
"""Checks that a PNG written by scripts/render_mesh.py or scripts/plot_table.py shows something:
the file reads back (vtkPNGReader), has the expected size, more than --min-colours distinct colours,
and at least --min-drawn of its pixels differ from the most common colour (the background).
Exit 0 when it does, 1 (with the reason) when it does not, 77 when VTK or numpy is absent.
Usage: /usr/bin/python3 tests/scripts/check_png.py FILE.png [--size WxH] [--min-colours N]
                                                   [--min-drawn FRACTION]"""
import argparse
import os
import sys

try:
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOImage import vtkPNGReader
except ImportError as e:
    print(f"SKIP: {e} (Debian python3-vtk9, python3-numpy)")
    sys.exit(77)

p = argparse.ArgumentParser()
p.add_argument("png")
p.add_argument("--size")
p.add_argument("--min-colours", type=int, default=2)
p.add_argument("--min-drawn", type=float, default=0.0)
a = p.parse_args()


def fail(msg):
    print(f"check_png: {a.png}: {msg}")
    sys.exit(1)


if not os.path.isfile(a.png) or os.path.getsize(a.png) == 0:
    fail("missing or empty")
reader = vtkPNGReader()
if not reader.CanReadFile(a.png):
    fail("not a PNG file")
reader.SetFileName(a.png)
reader.Update()
image = reader.GetOutput()
w, h, _ = image.GetDimensions()
if a.size and f"{w}x{h}" != a.size:
    fail(f"size {w}x{h}, expected {a.size}")
scalars = image.GetPointData().GetScalars()
if scalars is None or w * h == 0:
    fail("no pixels")
pixels = vtk_to_numpy(scalars).reshape(w * h, -1)[:, :3].astype(np.uint32)
codes = (pixels[:, 0] << 16) | (pixels[:, 1] << 8) | pixels[:, 2]
values, counts = np.unique(codes, return_counts=True)
drawn = 1.0 - counts.max() / len(codes)
print(f"check_png: {a.png}: {w}x{h}, {len(values)} colours, {100 * drawn:.1f}% of the pixels drawn"
      f" (background #{values[counts.argmax()]:06x})")
if len(values) <= a.min_colours:
    fail(f"{len(values)} distinct colours, expected more than {a.min_colours}")
if drawn < a.min_drawn:
    fail(f"only {100 * drawn:.1f}% of the pixels differ from the background, expected"
         f" {100 * a.min_drawn:.0f}% or more")
