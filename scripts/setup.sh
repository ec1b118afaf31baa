#!/usr/bin/env bash
# Installs every build and run dependency of qsmesh from Debian packages.
# Idempotent: packages already present are skipped by apt-get.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libocct-foundation-dev libocct-modeling-data-dev libocct-modeling-algorithms-dev
  libocct-data-exchange-dev libocct-ocaf-dev
  openmpi-bin libopenmpi-dev
  libtbb-dev
  petsc-dev libmumps-dev
  libeigen3-dev
  libmetis-dev
  libnauty2-dev
  coinor-libcbc-dev
  libhdf5-dev
  libcgns-dev cgns-convert
  libgtest-dev
  # the libFuzzer targets of scripts/fuzz.sh (llvm-14: llvm-symbolizer for their reports)
  clang-14 libclang-rt-14-dev llvm-14
  # scripts/check_style.sh (CI): formatting in check mode, clang-tidy on changed files
  clang-format-14 clang-tidy-14
  python3
  time
  # Pictures (scripts/render_mesh.py, scripts/plot_table.py): Debian's VTK renders through X even
  # offscreen, so a virtual X server (xvfb-run) with Mesa's software OpenGL.
  python3-vtk9 python3-numpy xvfb xauth libgl1-mesa-dri
  # scripts/check_plot3d.py reads the block-structured CGNS file (HDF5) to compare with PLOT3D
  python3-h5py
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
