// Private to src/linalg: the concrete backends behind make_solver.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/linalg/solver.hpp"

namespace qsmesh::linalg::detail {

/// The pattern a solver analysed, kept to reject a factorize() on another pattern (a silent
/// mismatch would give a wrong factorization, not an error).
class Pattern {
 public:
  Pattern() = default;
  explicit Pattern(const SparseMatrix& A)
      : n_(A.size()), offsets_(A.row_offsets()), cols_(A.columns()) {}
  [[nodiscard]] LO size() const { return n_; }
  [[nodiscard]] bool empty() const { return offsets_.empty(); }
  void check(const SparseMatrix& A, const char* backend) const {
    QSMESH_CHECK(!offsets_.empty(), backend << ": factorize() before analyze()");
    QSMESH_CHECK(
        A.size() == n_ && A.row_offsets() == offsets_ && A.columns() == cols_,
        backend << ": factorize() on a matrix whose pattern differs from the analysed one ("
                << A.size() << " unknowns, " << A.nonzeros() << " nonzeros; analysed " << n_ << ", "
                << cols_.size() << ")");
  }
  /// The checks before a solve: a successful factorization (`ready`), and b and x of the analysed
  /// size. Returns that size.
  std::size_t check_solve(bool ready, std::span<const double> b, std::span<const double> x,
                          const char* backend) const {
    QSMESH_CHECK(ready, backend << ": solve() without a successful factorize()");
    const auto n = static_cast<std::size_t>(n_);
    QSMESH_CHECK(b.size() == n && x.size() == n, backend << ": solve() with vectors of " << b.size()
                                                         << " and " << x.size()
                                                         << " entries for a system of size " << n);
    return n;
  }

 private:
  LO n_ = 0;
  std::vector<std::int64_t> offsets_;
  std::vector<LO> cols_;
};

/// Eigen::SimplicialLDLT (AMD ordering) on a copy of the matrix in Eigen's storage.
std::unique_ptr<LinearSolver> make_eigen_solver();

/// Eigen::SimplicialLDLT (AMD ordering) of the complex Hermitian matrix whose real form is A
/// (SolverOptions::complex_pairs).
std::unique_ptr<LinearSolver> make_eigen_complex_solver();

/// PETSc SeqAIJ on PETSC_COMM_SELF factorized by MUMPS (Cholesky; LU, then PETSc's own
/// factorization, as fallbacks). Every PETSc call is made while holding lane.mutex().
std::unique_ptr<LinearSolver> make_petsc_solver(SolverLane& lane);

/// PETSc SeqAIJ on PETSC_COMM_SELF solved by CG with GAMG to relative residual `rtol`: analyze
/// builds the matrix and the Krylov solver, factorize sets the values up the multigrid hierarchy,
/// solve iterates (throws when CG does not converge). `block_size` unknowns per node (>= 1).
std::unique_ptr<LinearSolver> make_petsc_multigrid_solver(SolverLane& lane, double rtol,
                                                          int block_size);

/// MUMPS Cholesky (LU as fallback) of a system split over the ranks of `lane`'s group: an MPIAIJ
/// matrix of which each rank sets its contiguous block of rows, the solution gathered on every
/// rank and refined to the correctly rounded one. Collective over the group (see SolverLane).
std::unique_ptr<LinearSolver> make_petsc_distributed_solver(SolverLane& lane);

}  // namespace qsmesh::linalg::detail
