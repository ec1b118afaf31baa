#!/usr/bin/env bash
# ctest: meshes the built-in wing-body example twice with the same arguments, once to a
# block-structured CGNS file and once to PLOT3D (Fortran records, then C stream), and checks with
# scripts/check_plot3d.py that both hold the same blocks, coordinates and connections; that the
# checker fails on a changed coordinate and on a missing interface; and, where VTK's Python module
# is installed, that VTK's PLOT3D reader (ParaView's) opens both forms with the CGNS file's block
# and point counts. Exit 77 (skipped) only when numpy or h5py is absent.
# Usage: test_check_plot3d.sh QSMESH_EXE SOURCE_DIR WORK_DIR
set -euo pipefail
exe=$1 src=$2 work=$3
py=/usr/bin/python3
if ! "$py" -c "import numpy, h5py" 2>/dev/null; then
  echo "SKIP: numpy or h5py is absent (Debian python3-numpy, python3-h5py; scripts/setup.sh)"
  exit 77
fi
mkdir -p "$work"
cd "$work"
rm -f wing_body.step blocks.* stream.* bad.* cut.*
"$exe" example wing-body -o wing_body.step >/dev/null
args=(--size-factor 0.05 -q --threads 2)
"$exe" mesh wing_body.step -o blocks.cgns --block-structured "${args[@]}"
"$exe" mesh wing_body.step -o blocks.xyz "${args[@]}"
"$exe" mesh wing_body.step -o stream.xyz --plot3d-stream "${args[@]}"
"$py" "$src/scripts/check_plot3d.py" blocks.xyz blocks.cgns
"$py" "$src/scripts/check_plot3d.py" stream.xyz blocks.cgns

# The checker fails on a coordinate moved and on an interface missing from the sidecar.
"$py" - <<'PY'
import json, shutil
data = bytearray(open("blocks.xyz", "rb").read())
data[-6] ^= 0x08  # the last block's last z (before its record length): its high mantissa bits
open("bad.xyz", "wb").write(data)
shutil.copy("blocks.xyz.json", "bad.xyz.json")
shutil.copy("blocks.xyz", "cut.xyz")
side = json.load(open("blocks.xyz.json"))
block = next(b for b in side["blocks"] if b["interfaces"])
block["interfaces"].pop()
json.dump(side, open("cut.xyz.json", "w"))
PY
for broken in bad cut; do
  if "$py" "$src/scripts/check_plot3d.py" $broken.xyz blocks.cgns >/dev/null; then
    echo "check_plot3d.py accepted $broken.xyz" >&2
    exit 1
  fi
done

if "$py" -c "import vtkmodules.vtkIOParallel, vtkmodules.vtkIOCGNSReader" 2>/dev/null; then
  "$py" "$src/scripts/check_vtk_readers.py" blocks.cgns blocks.xyz stream.xyz | tee vtk.log
  "$py" - <<'PY'
import re, sys
counts = [re.search(r": (\d+) block\(s\), (\d+) cells .*, (\d+) points", l).groups()
          for l in open("vtk.log")]
if len(counts) != 3 or len(set(counts)) != 1:
    sys.exit(f"VTK reads different blocks / cells / points: {counts}")
print("VTK's PLOT3D reader reads what its CGNS reader reads:", counts[0])
PY
else
  echo "VTK's Python module is absent: the PLOT3D reader check is skipped"
fi
echo "check_plot3d test passed"
