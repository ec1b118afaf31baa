// Benchmark of the linear-solver backends (scripts/bench_solvers.sh): analyze, factorize and
// solve times of Eigen vs PETSc/MUMPS vs CG with PETSc's GAMG on SPD matrices of the kinds the
// cross-field stage builds. One rank, one thread (the script pins OMP/BLAS threads to 1). Prints
// markdown table rows.
//
// Usage: qsmesh_bench_solvers [N ...]   (default: 1000 10000 100000 500000)
//        mpirun -np P qsmesh_bench_solvers --split [N ...]: the cr matrices solved split over the
//        P ranks (a group lane, MUMPS on MPIAIJ, solutions refined to the correctly rounded one)
//        against rank 0 alone (one-rank MUMPS, and a group of one: the refinement's cost).
//   poisson: 5-point Laplacian on a sqrt(N) x sqrt(N) grid + 0.01 * identity;
//   cr:      Crouzeix-Raviart-like: 2 unknowns per edge of a triangulated grid (N/2 edges), the
//            P1-nonconforming Laplacian coupled by a 2x2 block [1 .5; .5 1] + 0.01 * identity.
//        qsmesh_bench_solvers --complex [N ...]: the cross field's kind of cr matrix, each pair of
//        edges coupled by a rotation (the real form of a complex Hermitian matrix), factorized in
//        real form and as complex (SolverOptions::complex_pairs), and by MUMPS in real form.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <string>
#include <vector>

#include "qsmesh/core/timer.hpp"
#include "qsmesh/linalg/solver.hpp"

namespace {

using qsmesh::LO;
using qsmesh::Stopwatch;
using qsmesh::linalg::Backend;
using qsmesh::linalg::SparseMatrix;
using Triplet = SparseMatrix::Triplet;

SparseMatrix poisson(LO target) {
  const LO m =
      std::max<LO>(2, static_cast<LO>(std::lround(std::sqrt(static_cast<double>(target)))));
  std::vector<Triplet> t;
  t.reserve(static_cast<std::size_t>(m) * m * 5);
  const auto id = [m](LO i, LO j) { return i * m + j; };
  for (LO i = 0; i < m; ++i)
    for (LO j = 0; j < m; ++j) {
      const LO r = id(i, j);
      t.push_back({r, r, 4.01});
      if (i > 0) t.push_back({r, id(i - 1, j), -1.0});
      if (i + 1 < m) t.push_back({r, id(i + 1, j), -1.0});
      if (j > 0) t.push_back({r, id(i, j - 1), -1.0});
      if (j + 1 < m) t.push_back({r, id(i, j + 1), -1.0});
    }
  return SparseMatrix(m * m, t);
}

SparseMatrix crouzeix_raviart(LO target, bool rotations = false) {
  // m x m grid vertices, each cell cut by its anti-diagonal: ~3 m^2 edges, 2 unknowns each.
  const LO m = std::max<LO>(2, static_cast<LO>(std::lround(std::sqrt(target / 6.0))) + 1);
  const LO nh = m * (m - 1), nv = (m - 1) * m;
  const auto h = [m](LO i, LO j) { return i * (m - 1) + j; };                    // (i,j)-(i,j+1)
  const auto v = [m, nh](LO i, LO j) { return nh + i * m + j; };                 // (i,j)-(i+1,j)
  const auto d = [m, nh, nv](LO i, LO j) { return nh + nv + i * (m - 1) + j; };  // (i,j+1)-(i+1,j)
  const LO edges = nh + nv + (m - 1) * (m - 1);
  // CR stiffness of a right isosceles triangle, edges ordered as the opposite vertices (right
  // angle first): 4 x the P1 stiffness.
  static constexpr double K[3][3] = {{4, -2, -2}, {-2, 2, 0}, {-2, 0, 2}};
  static constexpr double R[2][2] = {{1, 0.5}, {0.5, 1}};
  std::vector<Triplet> t;
  t.reserve(static_cast<std::size_t>(m - 1) * (m - 1) * 2 * 36 +
            2 * static_cast<std::size_t>(edges));
  const auto element = [&](const LO(&e)[3]) {
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        // With rotations, edge a sees edge b's frame turned by 0.3 (e[a] - e[b]) radians: a gauge
        // of the plain Laplacian, so the matrix stays positive definite, with the cross field's
        // [[cos, -sin], [sin, cos]] blocks.
        const double angle = 0.3 * static_cast<double>(e[a] - e[b]);
        const double Q[2][2] = {{std::cos(angle), -std::sin(angle)},
                                {std::sin(angle), std::cos(angle)}};
        for (int c = 0; c < 2; ++c)
          for (int k = 0; k < 2; ++k)
            t.push_back({2 * e[a] + c, 2 * e[b] + k, (rotations ? Q : R)[c][k] * K[a][b]});
      }
  };
  for (LO i = 0; i + 1 < m; ++i)
    for (LO j = 0; j + 1 < m; ++j) {
      element({d(i, j), v(i, j), h(i, j)});
      element({d(i, j), v(i, j + 1), h(i + 1, j)});
    }
  for (LO r = 0; r < 2 * edges; ++r) t.push_back({r, r, 0.01});
  return SparseMatrix(2 * edges, t);
}

struct Times {
  double analyze = 0, factorize = 0, refactorize = 0, solve = 0, residual = 0;
  std::string name;
};

Times run(const SparseMatrix& A, Backend backend, qsmesh::linalg::SolverLane* lane,
          int block_size = 1, LO distributed_threshold = 2000000, bool complex_pairs = false) {
  qsmesh::linalg::SolverOptions options;
  options.backend = backend;
  options.complex_pairs = complex_pairs;
  options.block_size = block_size;
  options.distributed_threshold = distributed_threshold;
  auto solver = qsmesh::linalg::make_solver(A.size(), options, lane);
  Times t;
  Stopwatch w;
  solver->analyze(A);
  t.analyze = w.seconds();
  w.reset();
  solver->factorize(A);
  t.factorize = w.seconds();
  SparseMatrix B = A;  // a second level: same pattern, other values
  for (double& x : B.values()) x *= 1.5;
  w.reset();
  solver->factorize(B);
  t.refactorize = w.seconds();
  const auto n = static_cast<std::size_t>(A.size());
  std::vector<double> b(n), x(n), r(n);
  constexpr int kSolves = 5;
  for (int k = 0; k < kSolves; ++k) {
    for (std::size_t i = 0; i < n; ++i) b[i] = std::sin(0.1 * static_cast<double>(i) + k);
    w.reset();
    solver->solve(b, x);
    t.solve += w.seconds() / kSolves;
    B.multiply(x, r);
    double rr = 0, bb = 0;
    for (std::size_t i = 0; i < n; ++i) {
      rr += (r[i] - b[i]) * (r[i] - b[i]);
      bb += b[i] * b[i];
    }
    t.residual = std::max(t.residual, std::sqrt(rr / bb));
  }
  t.name = solver->name();
  return t;
}

double total(const Times& t) { return t.analyze + t.factorize + t.refactorize + 10 * t.solve; }

// Eigen vs one-rank MUMPS vs CG-GAMG on both kinds of matrix.
void backends_benchmark(const std::vector<LO>& sizes, qsmesh::linalg::SolverLane& lane) {
  std::printf(
      "| matrix | n | nonzeros | backend | analyze (s) | factorize (s) | refactorize (s) "
      "| solve (s) | rel. residual | Eigen/PETSc: factorize | refactorize | solve | "
      "analyze+2 fact.+10 solves | Eigen/CG-GAMG: analyze+2 fact.+10 solves |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const char* kind : {"poisson", "cr"}) {
    for (LO target : sizes) {
      const SparseMatrix A =
          std::string(kind) == "poisson" ? poisson(target) : crouzeix_raviart(target);
      const Times e = run(A, Backend::Eigen, &lane);
      const Times p = run(A, Backend::Petsc, &lane);
      // The CR matrices hold 2 unknowns per edge: GAMG is told so.
      const Times g = run(A, Backend::PetscMultigrid, &lane, std::string(kind) == "cr" ? 2 : 1);
      for (const Times* t : {&e, &p, &g}) {
        std::printf("| %s | %d | %lld | %s | %.4f | %.4f | %.4f | %.5f | %.1e |", kind, A.size(),
                    static_cast<long long>(A.nonzeros()), t->name.c_str(), t->analyze, t->factorize,
                    t->refactorize, t->solve, t->residual);
        if (t == &e)
          std::printf(" %.2f | %.2f | %.2f | %.2f | %.2f |\n", e.factorize / p.factorize,
                      e.refactorize / p.refactorize, e.solve / p.solve, total(e) / total(p),
                      total(e) / total(g));
        else
          std::printf("  |  |  |  |  |\n");
      }
      std::fflush(stdout);
    }
  }
}

// --complex: the rotation-coupled cr matrices in real form and as complex (Eigen), and MUMPS.
void complex_benchmark(const std::vector<LO>& sizes, qsmesh::linalg::SolverLane& lane) {
  std::printf(
      "| n | nonzeros | solver | analyze (s) | factorize (s) | refactorize (s) | solve (s) | rel. "
      "residual | real / complex: factorize | solve | analyze+2 fact.+10 solves |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const LO target : sizes) {
    const SparseMatrix A = crouzeix_raviart(target, true);
    const Times r = run(A, Backend::Eigen, &lane);
    const Times c = run(A, Backend::Eigen, &lane, 1, 2000000, true);
    const Times p = run(A, Backend::Petsc, &lane);
    for (const Times* t : {&r, &c, &p}) {
      std::printf("| %d | %lld | %s | %.4f | %.4f | %.4f | %.5f | %.1e |", A.size(),
                  static_cast<long long>(A.nonzeros()), t->name.c_str(), t->analyze, t->factorize,
                  t->refactorize, t->solve, t->residual);
      if (t == &r)
        std::printf(" %.2f | %.2f | %.2f |\n", r.refactorize / c.refactorize, r.solve / c.solve,
                    total(r) / total(c));
      else
        std::printf("  |  |  |\n");
    }
    std::fflush(stdout);
  }
}

// --split: the cr matrices split over every rank against rank 0 alone. Wall seconds (the ranks
// start together); CPU seconds summed over the ranks that took part.
void split_benchmark(const std::vector<LO>& sizes, qsmesh::linalg::SolverLane& lane) {
  using qsmesh::linalg::SolverGroup;
  using qsmesh::linalg::SolverLane;
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  MPI_Comm world = MPI_COMM_WORLD, self = MPI_COMM_SELF;
  const SolverGroup all(&world, rank, size), alone(&self, 0, 1);
  if (rank == 0) {
    std::printf(
        "| n | nonzeros | solver | ranks | analyze (s) | factorize (s) | refactorize (s) | solve "
        "(s) | refinement solves per solve | analyze+2 fact.+10 solves (s) | CPU s, all ranks | "
        "rel. residual |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  }
  const auto row = [&](const SparseMatrix& A, const Times& t, int ranks, double refinements,
                       double cpu) {
    std::printf("| %d | %lld | %s | %d | %.3f | %.3f | %.3f | %.4f | %.2f | %.2f | %.2f | %.1e |\n",
                A.size(), static_cast<long long>(A.nonzeros()), t.name.c_str(), ranks, t.analyze,
                t.factorize, t.refactorize, t.solve, refinements, total(t), cpu, t.residual);
    std::fflush(stdout);
  };
  for (const LO target : sizes) {
    const SparseMatrix A = crouzeix_raviart(target);
    // Split over every rank.
    MPI_Barrier(MPI_COMM_WORLD);
    std::clock_t cpu0 = std::clock();
    SolverLane group_lane(lane, all);
    const Times d = run(A, Backend::Automatic, &group_lane, 1, 0);
    double cpu = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC, cpu_all = 0;
    MPI_Reduce(&cpu, &cpu_all, 1, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
    const auto& rep = group_lane.report();
    if (rank == 0)
      row(A, d, size, static_cast<double>(rep.refinement_steps) / std::max(1, rep.solves), cpu_all);
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank == 0) {
      // Rank 0 alone: MUMPS on one rank, then the same split path on a group of one.
      cpu0 = std::clock();
      const Times p = run(A, Backend::Petsc, &lane);
      row(A, p, 1, 0, static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC);
      cpu0 = std::clock();
      SolverLane one(lane, alone);
      const Times g = run(A, Backend::Automatic, &one, 1, 0);
      row(A, g, 1,
          static_cast<double>(one.report().refinement_steps) / std::max(1, one.report().solves),
          static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC);
    }
    MPI_Barrier(MPI_COMM_WORLD);
  }
}

}  // namespace

int main(int argc, char** argv) {
  // As a driver would: MPI first (serialised threads), then the lane, which leaves MPI running.
  int provided = 0;
  if (MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS) return 1;
  int status = 0;
  try {
    std::vector<LO> sizes;
    bool split = false, complex = false;
    for (int i = 1; i < argc; ++i) {
      if (std::string(argv[i]) == "--split")
        split = true;
      else if (std::string(argv[i]) == "--complex")
        complex = true;
      else
        sizes.push_back(static_cast<LO>(std::atof(argv[i])));
    }
    if (sizes.empty()) sizes = {1000, 10000, 100000, 500000};
    qsmesh::linalg::SolverLane lane;
    if (split)
      split_benchmark(sizes, lane);
    else if (complex)
      complex_benchmark(sizes, lane);
    else
      backends_benchmark(sizes, lane);
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "bench_solvers: %s\n", ex.what());
    status = 1;
  }
  MPI_Finalize();
  return status;
}
