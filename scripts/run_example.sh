#!/usr/bin/env bash
# Sets up a fresh Debian machine, builds qsmesh, writes the built-in wing-body CAD model and meshes
# it on 2 MPI ranks, and draws the mesh (scripts/render_mesh.py). Results land in example_output/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mkdir -p example_output
./build/drivers/qsmesh example wing-body -o example_output/wing_body.step
./build/drivers/qsmesh info example_output/wing_body.step
ranks=2
mpiexec --oversubscribe --bind-to none -n "$ranks" ./build/drivers/qsmesh mesh example_output/wing_body.step \
  -o example_output/wing_body.cgns --stats example_output/wing_body_stats.json
./build/drivers/qsmesh mesh example_output/wing_body.step -o example_output/wing_body.vtu -q
mpiexec --oversubscribe --bind-to none -n "$ranks" ./build/drivers/qsmesh mesh example_output/wing_body.step \
  -o example_output/wing_body.h5 -q
mpiexec --oversubscribe --bind-to none -n "$ranks" ./build/drivers/qsmesh mesh example_output/wing_body.step \
  -o example_output/wing_body_blocks.cgns --block-structured -q --stats example_output/wing_body_blocks_stats.json
if command -v cgnscheck >/dev/null; then
  cgnscheck example_output/wing_body.cgns | tail -n 3
fi
/usr/bin/python3 scripts/render_mesh.py example_output/wing_body.vtu -o example_output/wing_body.png \
  --title "wing-body example"
echo "outputs: example_output/wing_body.cgns (CGNS), example_output/wing_body_blocks.cgns (block-structured"
echo "CGNS), example_output/wing_body.h5 + wing_body.xdmf (HDF5; the .xdmf opens in ParaView),"
echo "example_output/wing_body.vtu (ParaView), example_output/wing_body_stats.json,"
echo "example_output/wing_body.png (four views: SICN, irregular vertices, CAD curves)"
