// The one linear-solver interface of qsmesh. Eigen and PETSc stay behind it (src/linalg).
//
// Usage pattern of the per-face solves (paper 000 Algorithm 1): the sparsity pattern is analysed
// once, the matrix is factorized once per diffusion level, and each factorization serves many
// right-hand sides:
//     auto solver = make_solver(n, options, lane);
//     solver->analyze(pattern_matrix);          // once
//     solver->factorize(matrix_of_level);       // per level (same pattern)
//     solver->solve(rhs, x);                    // many times
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "qsmesh/core/types.hpp"

namespace qsmesh::linalg {

/// Square sparse matrix in compressed sparse row form (full storage, both triangles), built from
/// triplets. Duplicate entries are summed. Column indices are sorted within each row.
class SparseMatrix {
 public:
  struct Triplet {
    LO row, col;
    double value;
  };
  SparseMatrix() = default;
  /// Builds an n x n matrix from (row, col, value) triplets.
  SparseMatrix(LO n, std::span<const Triplet> triplets);

  [[nodiscard]] LO size() const { return n_; }
  [[nodiscard]] std::int64_t nonzeros() const { return static_cast<std::int64_t>(values_.size()); }
  [[nodiscard]] const std::vector<std::int64_t>& row_offsets() const { return offsets_; }
  [[nodiscard]] const std::vector<LO>& columns() const { return cols_; }
  [[nodiscard]] std::vector<double>& values() { return values_; }
  [[nodiscard]] const std::vector<double>& values() const { return values_; }
  /// Index into values() of entry (row, col); -1 when not in the pattern.
  [[nodiscard]] std::int64_t find(LO row, LO col) const;
  /// y = A x.
  void multiply(std::span<const double> x, std::span<double> y) const;

 private:
  LO n_ = 0;
  std::vector<std::int64_t> offsets_{0};
  std::vector<LO> cols_;
  std::vector<double> values_;
};

/// PETSc in Debian is not thread-safe: every PETSc call of a rank goes through its one lane, which
/// serialises them. Created once per process by the driver, after MPI and before any solve, and
/// passed down; it initialises PETSc on construction and finalises it on destruction.
///
/// - At most one lane exists at a time in a process (the constructor throws qsmesh::Error when
///   PETSc is already initialised). Every solver made with a lane must be destroyed before it.
/// - MPI: when MPI is already initialised (by the driver), PETSc uses it and the lane leaves it
///   running; the driver should ask for MPI_THREAD_SERIALIZED, since solver calls come from worker
///   threads (one at a time). When MPI is not initialised, PETSc initialises it (asking for
///   MPI_THREAD_SERIALIZED) and finalises it with the lane; MPI cannot be initialised twice, so
///   such a process (a test, a benchmark) can create only one lane in its lifetime.
/// - No options file is read (~/.petscrc, ./.petscrc); the PETSC_OPTIONS environment variable
///   still applies (debugging aid). PETSc's signal handler is removed so crashes are not hijacked,
///   and PETSc's error printing is replaced by qsmesh::Error exceptions carrying its message.
class PetscLane {
 public:
  PetscLane();
  ~PetscLane();
  PetscLane(const PetscLane&) = delete;
  PetscLane& operator=(const PetscLane&) = delete;
  [[nodiscard]] std::mutex& mutex() { return mutex_; }
  /// Message of the last PETSc error raised under this lane (for src/linalg's error reports).
  /// Read and written only while holding mutex().
  [[nodiscard]] std::string& last_error() { return last_error_; }

 private:
  std::mutex mutex_;
  std::string last_error_;
};

/// Eigen: sparse LDLT. Petsc: MUMPS Cholesky. PetscMultigrid: conjugate gradients preconditioned
/// by PETSc's algebraic multigrid (GAMG), to SolverOptions::multigrid_rtol: its cost per solve
/// grows linearly with n, a factorization's more than linearly, but every right-hand side pays the
/// iterations (docs/benchmarks.md, "Linear solvers", has where each wins).
enum class Backend { Automatic, Eigen, Petsc, PetscMultigrid };

struct SolverOptions {
  Backend backend = Backend::Automatic;
  /// Automatic: systems with at least this many unknowns go to PETSc (when a lane is given),
  /// smaller ones to Eigen. Chosen by measurement (docs/benchmarks.md, "Linear solvers"): on one
  /// thread, analyze + 2 factorizations + 10 solves cost the same in both at about 5e5-6.5e5
  /// unknowns (Eigen's solves are 2x faster; MUMPS factorizes faster from 2e5-3e5 unknowns).
  LO petsc_threshold = 500000;
  /// Backend::PetscMultigrid: relative residual (unpreconditioned 2-norm) at which CG stops.
  double multigrid_rtol = 1e-10;
  /// Backend::PetscMultigrid: unknowns per node (the cross field's 2 per edge), so that GAMG
  /// aggregates nodes rather than separate components. The system size must be a multiple of it.
  int block_size = 1;
};

/// A direct solver for symmetric positive definite systems.
class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  /// Symbolic analysis (ordering, memory) of the pattern of A. Call once per pattern.
  virtual void analyze(const SparseMatrix& A) = 0;
  /// Numeric factorization of A (same pattern as analysed). Throws qsmesh::Error when A is not
  /// positive definite or the backend fails.
  virtual void factorize(const SparseMatrix& A) = 0;
  /// Solves A x = b with the last factorization. b and x have A.size() entries.
  virtual void solve(std::span<const double> b, std::span<double> x) = 0;
  [[nodiscard]] virtual const char* name() const = 0;
};

/// A solver for an n x n system. `lane` may be null: then Eigen is used whatever the size (and
/// Backend::Petsc throws). Safe to call from many threads; each solver object is used by one.
[[nodiscard]] std::unique_ptr<LinearSolver> make_solver(LO n, const SolverOptions& options,
                                                        PetscLane* lane);

}  // namespace qsmesh::linalg
