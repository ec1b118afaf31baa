// Eigen backend: sparse Cholesky (LDL^T, AMD ordering) for the small per-face systems, where
// PETSc's per-call overhead and its one lane would cost more than the factorization itself.
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cmath>
#include <limits>

#include "backends.hpp"

namespace qsmesh::linalg::detail {
namespace {

class EigenSolver final : public LinearSolver {
 public:
  void analyze(const SparseMatrix& A) override {
    QSMESH_CHECK(A.nonzeros() <= std::numeric_limits<int>::max(),
                 "eigen: " << A.nonzeros() << " nonzeros do not fit Eigen's 32-bit indices");
    pattern_ = Pattern(A);
    factorized_ = false;
    // The CSR arrays of A, read as compressed columns, are A^T = A (A is symmetric). Only the
    // lower triangle of that is used by the factorization, i.e. the upper triangle of A, as in
    // the PETSc backend.
    const LO n = A.size();
    matrix_ = Eigen::SparseMatrix<double, Eigen::ColMajor, int>(n, n);
    matrix_.resizeNonZeros(static_cast<Eigen::Index>(A.nonzeros()));
    for (LO i = 0; i <= n; ++i)
      matrix_.outerIndexPtr()[i] = static_cast<int>(A.row_offsets()[static_cast<std::size_t>(i)]);
    std::copy(A.columns().begin(), A.columns().end(), matrix_.innerIndexPtr());
    std::copy(A.values().begin(), A.values().end(), matrix_.valuePtr());
    ldlt_.analyzePattern(matrix_);
    QSMESH_CHECK(ldlt_.info() == Eigen::Success,
                 "eigen: symbolic analysis failed for a matrix of size " << n);
  }

  void factorize(const SparseMatrix& A) override {
    pattern_.check(A, "eigen");
    factorized_ = false;
    std::copy(A.values().begin(), A.values().end(), matrix_.valuePtr());
    ldlt_.factorize(matrix_);
    QSMESH_CHECK(ldlt_.info() == Eigen::Success,
                 "eigen: numeric factorization failed (zero pivot): the matrix of size "
                     << A.size() << " is singular or not positive definite");
    // LDL^T runs on indefinite matrices too; a non-positive pivot means A is not SPD.
    const auto& d = ldlt_.vectorD();
    for (Eigen::Index i = 0; i < d.size(); ++i)
      QSMESH_CHECK(d[i] > 0 && std::isfinite(d[i]),
                   "eigen: the matrix of size " << A.size() << " is not positive definite (pivot "
                                                << d[i] << " at elimination step " << i << ")");
    factorized_ = true;
  }

  void solve(std::span<const double> b, std::span<double> x) override {
    QSMESH_CHECK(factorized_, "eigen: solve() without a successful factorize()");
    const auto n = static_cast<std::size_t>(pattern_.size());
    QSMESH_CHECK(b.size() == n && x.size() == n, "eigen: solve() with vectors of "
                                                     << b.size() << " and " << x.size()
                                                     << " entries for a system of size " << n);
    const Eigen::Map<const Eigen::VectorXd> bm(b.data(), static_cast<Eigen::Index>(n));
    Eigen::Map<Eigen::VectorXd> xm(x.data(), static_cast<Eigen::Index>(n));
    xm = ldlt_.solve(bm);
  }

  [[nodiscard]] const char* name() const override { return "eigen/simplicial-ldlt"; }

 private:
  Pattern pattern_;
  bool factorized_ = false;
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> matrix_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double, Eigen::ColMajor, int>, Eigen::Lower,
                        Eigen::AMDOrdering<int>>
      ldlt_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_eigen_solver() { return std::make_unique<EigenSolver>(); }

}  // namespace qsmesh::linalg::detail
