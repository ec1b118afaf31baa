#!/usr/bin/env bash
# Sets up a fresh Debian machine, builds qsmesh and runs every test (unit, MPI at 1/2/4 ranks,
# end-to-end). This is what .ci/run calls.
# Usage: scripts/test.sh              Release build in build/, then ctest
#        scripts/test.sh --sanitize   AddressSanitizer + UndefinedBehaviorSanitizer build in
#                                     build-asan/, every ctest there, then the fuzz targets
#                                     (scripts/fuzz.sh, 60 s each)
set -euo pipefail
cd "$(dirname "$0")/.."
sanitize=0
case "${1:-}" in
  "") ;;
  --sanitize) sanitize=1 ;;
  *) echo "usage: scripts/test.sh [--sanitize]" >&2; exit 2 ;;
esac
jobs=$(nproc 2>/dev/null || echo 2)
# OpenMPI refuses to start as root unless told; CI runs as root.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

bash scripts/setup.sh
if [ "$sanitize" -eq 0 ]; then
  bash scripts/build.sh
  cd build
  ctest --output-on-failure -j "$jobs"
  exit 0
fi

# The sanitizer job. The options are exported before the build too: gtest_discover_tests runs
# every test executable at build time to list its tests.
source scripts/sanitizers/env.sh
start=$SECONDS
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DQSMESH_SANITIZE=ON
cmake --build build-asan -j "$jobs"
built=$SECONDS
(cd build-asan && ctest --output-on-failure -j "$jobs")
tested=$SECONDS
bash scripts/fuzz.sh 60
echo "test.sh --sanitize: build $((built - start)) s, ctest $((tested - built)) s," \
     "fuzz $((SECONDS - tested)) s, total $((SECONDS - start)) s"
