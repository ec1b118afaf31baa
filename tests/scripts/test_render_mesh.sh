#!/usr/bin/env bash
# ctest: meshes the built-in wing-body example, renders it with scripts/render_mesh.py and checks
# the picture (non-empty, the requested size, many colours, a good part of it drawn) and that the
# script's counts (quads, SICN min and mean, irregular interior vertices) are those of qsmesh's
# --stats. Also checks that check_png.py rejects a one-colour image. Exit 77 (skipped) only when
# VTK's Python module (Debian python3-vtk9) is absent.
# Usage: test_render_mesh.sh QSMESH_EXE SOURCE_DIR WORK_DIR
set -euo pipefail
exe=$1 src=$2 work=$3
py=/usr/bin/python3
if ! "$py" -c "import vtkmodules.vtkRenderingOpenGL2" 2>/dev/null; then
  echo "SKIP: VTK's Python module is absent (Debian python3-vtk9; scripts/setup.sh installs it)"
  exit 77
fi
mkdir -p "$work"
cd "$work"
rm -f wing_body.step wing_body.vtu wing_body.json wing_body.png uniform.png
"$exe" example wing-body -o wing_body.step >/dev/null
"$exe" mesh wing_body.step -o wing_body.vtu --size-factor 0.05 -q --stats wing_body.json
start=$(date +%s%N)
"$py" "$src/scripts/render_mesh.py" wing_body.vtu -o wing_body.png --size 800x600 | tee render.log
end=$(date +%s%N)
echo "render_mesh.py took $(((end - start) / 1000000)) ms (xvfb-run included)"
"$py" "$src/tests/scripts/check_png.py" wing_body.png --size 800x600 --min-colours 50 --min-drawn 0.15

# The picture's counts are the mesher's.
"$py" - render.log wing_body.json <<'PY'
import json, sys
words = open(sys.argv[1]).read().split()
got = {k: float(words[words.index(k) + 1]) for k in ("quads", "sicn_min", "sicn_avg", "irregular_interior")}
stats = json.load(open(sys.argv[2]))
bad = [f"{k}: render_mesh {got[k]} qsmesh {stats[k]}" for k in got if abs(got[k] - stats[k]) > 1e-5]
if bad:
    sys.exit("render_mesh.py and qsmesh --stats disagree: " + "; ".join(bad))
print("counts agree with --stats:", got)
PY

# The checker itself rejects a blank picture.
"$py" - <<'PY'
from vtkmodules.vtkImagingSources import vtkImageCanvasSource2D
from vtkmodules.vtkIOImage import vtkPNGWriter
c = vtkImageCanvasSource2D()
c.SetScalarTypeToUnsignedChar()
c.SetNumberOfScalarComponents(3)
c.SetExtent(0, 99, 0, 99, 0, 0)
c.SetDrawColor(255, 255, 255)
c.FillBox(0, 99, 0, 99)
w = vtkPNGWriter()
w.SetFileName("uniform.png")
w.SetInputConnection(c.GetOutputPort())
w.Write()
PY
if "$py" "$src/tests/scripts/check_png.py" uniform.png --min-colours 1; then
  echo "check_png.py accepted a one-colour image" >&2
  exit 1
fi
echo "render_mesh test passed"
