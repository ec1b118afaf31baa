#!/usr/bin/env bash
# Eigen vs PETSc/MUMPS: analyze, factorize, refactorize (same pattern, new values) and solve times
# on 2D Poisson (5-point) and Crouzeix-Raviart-like (2 unknowns per edge) SPD matrices, one rank,
# one thread. Prints a markdown table (ratios are Eigen time / PETSc time, measured in one run).
# Usage: scripts/bench_solvers.sh [--complex] [N ...]   (default: 1e3 1e4 1e5 5e5; run after
# scripts/build.sh). --complex: the cross field's rotation-coupled matrices, real form against
# complex (linalg::SolverOptions::complex_pairs).
# QSMESH_BENCH_SOLVERS_EXE overrides the executable (default build/drivers/qsmesh_bench_solvers).
set -euo pipefail
cd "$(dirname "$0")/.."
exe=${QSMESH_BENCH_SOLVERS_EXE:-./build/drivers/qsmesh_bench_solvers}
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(1000 10000 100000 500000)
# One thread everywhere: MUMPS's BLAS and any OpenMP region, like Eigen's simplicial code.
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
echo "$(date -u +%Y-%m-%d), $(git rev-parse --short HEAD 2>/dev/null || echo '?') + working tree," \
     "$(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
echo
"$exe" "${sizes[@]}"
