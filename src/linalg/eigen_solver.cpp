// Eigen backend: sparse Cholesky (LDL^T, AMD ordering) for the small per-face systems, where
// PETSc's per-call overhead and its one lane would cost more than the factorization itself.
//
// The ordering and the permuted upper triangle are computed here rather than inside
// Eigen::SimplicialLDLT: Eigen builds the full symmetric matrix from one triangle, then A^T + A of
// that for AMD, and twists the matrix again at every factorization. The matrices here are stored
// full (SparseMatrix), so AMD runs on a copy of the matrix itself when its pattern is symmetric,
// and the values of the permuted triangle are gathered through an index map. The ordering, the
// permuted matrix and the factorization are bit for bit those of SimplicialLDLT<Lower, AMD> on the
// same matrix (same AMD input arrays, same twisted triangle), at a fraction of the analysis cost
// (the small Laplace systems of the cavity candidates: docs/benchmarks.md, issue 27).
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cmath>
#include <complex>
#include <limits>
#include <numeric>

#include "backends.hpp"

namespace qsmesh::linalg::detail {
namespace {

using EigenMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using Permutation = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>;

// True when the pattern of the CSR matrix A equals that of its transpose.
bool symmetric_pattern(const SparseMatrix& A) {
  const auto& off = A.row_offsets();
  const auto& col = A.columns();
  std::vector<std::int64_t> next(off.begin(), off.end() - 1);
  // Walking the rows in order, the entries (c, r) with r ascending must come next in row c.
  for (LO r = 0; r < A.size(); ++r)
    for (auto k = off[static_cast<std::size_t>(r)]; k < off[static_cast<std::size_t>(r) + 1]; ++k) {
      const LO c = col[static_cast<std::size_t>(k)];
      auto& at = next[static_cast<std::size_t>(c)];
      if (at >= off[static_cast<std::size_t>(c) + 1] || col[static_cast<std::size_t>(at)] != r)
        return false;
      ++at;
    }
  return true;
}

// The checks after a numeric factorization, for both Eigen solvers: Eigen's status, then the
// pivots. LDL^T runs on indefinite matrices too; a non-positive pivot means A is not SPD (the
// pivots of a Hermitian matrix are real: their real parts are read).
template <class Ldlt>
void check_factorization(const Ldlt& ldlt, LO n, const char* backend) {
  QSMESH_CHECK(ldlt.info() == Eigen::Success,
               backend << ": numeric factorization failed (zero pivot): the matrix of size " << n
                       << " is singular or not positive definite");
  const auto& d = ldlt.vectorD();
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    const double pivot = std::real(d[i]);
    QSMESH_CHECK(pivot > 0 && std::isfinite(pivot),
                 backend << ": the matrix of size " << n << " is not positive definite (pivot "
                         << pivot << " at elimination step " << i << ")");
  }
}

// AMD's inverse permutation as AMDOrdering computes it for SimplicialLDLT<Lower, AMDOrdering>:
// on the full matrix built from `lower`, symmetrised again. For patterns that are not symmetric;
// a symmetric one gives the same from its own sorted pattern (minimum_degree_ordering on it).
template <class Matrix>
Permutation amd_of_lower(const Matrix& lower) {
  Matrix full;
  full = lower.template selfadjointView<Eigen::Lower>();
  Permutation pinv;
  Eigen::AMDOrdering<int>()(full, pinv);
  return pinv;
}

// The upper triangle of P A P^T from A's lower triangle `lower` (SimplicialCholeskyBase::
// ordering's twist; no permutation: A's upper triangle), into `upper`.
template <class Matrix>
void twist_to_upper(const Matrix& lower, const Permutation& perm, Matrix& upper) {
  upper.resize(lower.rows(), lower.cols());
  if (perm.size() > 0)
    upper.template selfadjointView<Eigen::Upper>() =
        lower.template selfadjointView<Eigen::Lower>().twistedBy(perm);
  else
    upper.template selfadjointView<Eigen::Upper>() = lower.template selfadjointView<Eigen::Lower>();
}

// SimplicialLDLT on a matrix already ordered (its upper triangle permuted by the solver itself),
// analysed without Eigen's ordering step. With a natural ordering that step still copies the
// matrix twice (Eigen tests for NaturalOrdering<Index>, not the NaturalOrdering<int> its storage
// index needs), which costs the many small systems of the cavity candidates. The symbolic
// analysis reads the pattern only: the same factor as analyzePattern's.
template <class Matrix>
class PreorderedLdlt
    : public Eigen::SimplicialLDLT<Matrix, Eigen::Upper, Eigen::NaturalOrdering<int>> {
 public:
  void analyze_preordered(const Matrix& upper) { this->analyzePattern_preordered(upper, true); }
};

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
    EigenMatrix a(n, n);
    a.resizeNonZeros(static_cast<Eigen::Index>(A.nonzeros()));
    for (LO i = 0; i <= n; ++i)
      a.outerIndexPtr()[i] = static_cast<int>(A.row_offsets()[static_cast<std::size_t>(i)]);
    std::copy(A.columns().begin(), A.columns().end(), a.innerIndexPtr());
    // AMD's inverse permutation, as SimplicialLDLT<Lower, AMDOrdering> computes it: on the full
    // symmetric matrix built from the lower triangle, symmetrised again (A^T + A). With a symmetric
    // pattern both are the pattern of `a` itself, sorted, so AMD gets the same arrays from a copy.
    Permutation pinv;
    if (symmetric_pattern(A)) {
      EigenMatrix c = a;
      Eigen::internal::minimum_degree_ordering(c, pinv);
    } else {
      pinv = amd_of_lower(a);
    }
    perm_ = pinv.size() > 0 ? Permutation(pinv.inverse()) : Permutation();
    perm_inv_ = pinv;
    // The permuted upper triangle (SimplicialCholeskyBase::ordering), its values traced back to
    // A's: each entry carries its index into A.values() through the twist.
    for (std::int64_t k = 0; k < A.nonzeros(); ++k) a.valuePtr()[k] = static_cast<double>(k);
    twist_to_upper(a, perm_, upper_);
    source_.resize(static_cast<std::size_t>(upper_.nonZeros()));
    for (Eigen::Index k = 0; k < upper_.nonZeros(); ++k)
      source_[static_cast<std::size_t>(k)] = static_cast<std::int64_t>(upper_.valuePtr()[k]);
    ldlt_.analyze_preordered(upper_);
    QSMESH_CHECK(ldlt_.info() == Eigen::Success,
                 "eigen: symbolic analysis failed for a matrix of size " << n);
  }

  void factorize(const SparseMatrix& A) override {
    pattern_.check(A, "eigen");
    factorized_ = false;
    const std::vector<double>& v = A.values();
    double* dst = upper_.valuePtr();
    for (std::size_t k = 0; k < source_.size(); ++k)
      dst[k] = v[static_cast<std::size_t>(source_[k])];
    ldlt_.factorize(upper_);
    check_factorization(ldlt_, A.size(), "eigen");
    factorized_ = true;
  }

  void solve(std::span<const double> b, std::span<double> x) override {
    const std::size_t n = pattern_.check_solve(factorized_, b, x, "eigen");
    const Eigen::Map<const Eigen::VectorXd> bm(b.data(), static_cast<Eigen::Index>(n));
    Eigen::Map<Eigen::VectorXd> xm(x.data(), static_cast<Eigen::Index>(n));
    // SimplicialLDLT's solve with its permutation: P b, the triangular and diagonal solves, P^-1.
    if (perm_.size() > 0) {
      work_ = perm_ * bm;
      const bool has_l = ldlt_.matrixL().nestedExpression().nonZeros() > 0;
      if (has_l) ldlt_.matrixL().solveInPlace(work_);
      if (ldlt_.vectorD().size() > 0) work_ = ldlt_.vectorD().asDiagonal().inverse() * work_;
      if (has_l) ldlt_.matrixU().solveInPlace(work_);
      xm = perm_inv_ * work_;
    } else {
      xm = ldlt_.solve(bm);
    }
  }

  [[nodiscard]] const char* name() const override { return "eigen/simplicial-ldlt"; }

 private:
  Pattern pattern_;
  bool factorized_ = false;
  Permutation perm_, perm_inv_;
  EigenMatrix upper_;                 // the permuted upper triangle, factorized in place
  std::vector<std::int64_t> source_;  // upper_'s values: their indices in A.values()
  Eigen::VectorXd work_;
  PreorderedLdlt<EigenMatrix> ldlt_;
};

// SolverOptions::complex_pairs: the real form of a Hermitian matrix factorized as the complex
// matrix itself. Each complex entry stands for a 2 x 2 block of the real form, so the graph the
// ordering and the elimination see has a quarter of the edges, the factor half the memory, and
// each flop of the complex factor does the work of four real ones in one pass over memory: the
// simplicial factorization is bound by memory traffic, not by flops.
class ComplexEigenSolver final : public LinearSolver {
 public:
  using Complex = std::complex<double>;
  using ComplexMatrix = Eigen::SparseMatrix<Complex, Eigen::ColMajor, int>;

  void analyze(const SparseMatrix& A) override {
    const LO n = A.size();
    QSMESH_CHECK(n % 2 == 0, "eigen (complex pairs): odd system size " << n);
    pattern_ = Pattern(A);
    factorized_ = false;
    const LO m = n / 2;
    // The lower triangle of the complex matrix: the blocks (I, J), J <= I, met at the even
    // entries (2I, 2J) of the real form. Walking the rows I in order appends each column J's
    // entries in row order, the compressed columns' own order: counted first, then filled.
    const auto& off = A.row_offsets();
    const auto& col = A.columns();
    std::int64_t full = 0;  // complex entries of both triangles
    std::vector<int> column_start(static_cast<std::size_t>(m) + 1, 0);
    for (LO I = 0; I < m; ++I) {
      const std::size_t row = 2 * static_cast<std::size_t>(I);
      for (auto k = off[row]; k < off[row + 1]; ++k) {
        const LO c = col[static_cast<std::size_t>(k)];
        if (c % 2 != 0) continue;
        ++full;
        if (c / 2 <= I) ++column_start[static_cast<std::size_t>(c / 2) + 1];
      }
    }
    QSMESH_CHECK(4 * full == A.nonzeros(),
                 "eigen (complex pairs): the pattern of the matrix of size "
                     << n << " is not made of whole 2 x 2 blocks (" << A.nonzeros() << " nonzeros, "
                     << full << " blocks)");
    std::partial_sum(column_start.begin(), column_start.end(), column_start.begin());
    lower_.resize(m, m);
    lower_.resizeNonZeros(column_start.back());
    std::copy(column_start.begin(), column_start.end(), lower_.outerIndexPtr());
    sources_.resize(static_cast<std::size_t>(column_start.back()));
    {
      std::vector<int> next(column_start.begin(), column_start.end() - 1);
      // Where (row, column) sits in A.values(): rows 2I and 2I+1 of a whole-block pattern hold the
      // same columns, so the same offset from the row's start, checked before it is trusted.
      const auto at = [&](LO row, std::int64_t offset, LO column) -> std::int64_t {
        const auto k = off[static_cast<std::size_t>(row)] + offset;
        if (k < off[static_cast<std::size_t>(row) + 1] &&
            col[static_cast<std::size_t>(k)] == column)
          return k;
        return A.find(row, column);
      };
      for (LO I = 0; I < m; ++I) {
        const std::size_t row = 2 * static_cast<std::size_t>(I);
        for (auto k = off[row]; k < off[row + 1]; ++k) {
          const LO c = col[static_cast<std::size_t>(k)];
          if (c % 2 != 0 || c / 2 > I) continue;
          const auto slot = static_cast<std::size_t>(next[static_cast<std::size_t>(c / 2)]++);
          lower_.innerIndexPtr()[slot] = I;
          const std::int64_t offset = k - off[row];
          const Sources src{k, at(2 * I + 1, offset, c), at(2 * I, offset + 1, c + 1),
                            at(2 * I + 1, offset + 1, c + 1)};
          QSMESH_CHECK(src.im >= 0 && src.minus_im >= 0 && src.re2 >= 0,
                       "eigen (complex pairs): the 2 x 2 block ("
                           << I << ", " << c / 2 << ") is not whole in the pattern");
          sources_[slot] = src;
        }
      }
    }
    // AMD and the permuted upper triangle, as SimplicialLDLT<Lower, AMDOrdering> computes them
    // (SimplicialCholeskyBase::ordering), once here instead of at every factorization. Each entry
    // carries its index into lower_ through the twist, and the sign of its imaginary part says
    // whether the twist conjugated it (an entry that crosses the diagonal).
    Permutation pinv;
    if (symmetric_pattern(A)) {
      // AMDOrdering's input is the full matrix symmetrised again (A^T + A), its columns sorted:
      // with a symmetric pattern that is column J = the even columns of row 2J of A, halved. AMD
      // reads the pattern only, so it runs on that, as reals, without the two complex copies.
      EigenMatrix c(m, m);
      c.resizeNonZeros(static_cast<Eigen::Index>(full));
      int at = 0;
      for (LO J = 0; J < m; ++J) {
        c.outerIndexPtr()[J] = at;
        const std::size_t row = 2 * static_cast<std::size_t>(J);
        for (auto k = off[row]; k < off[row + 1]; ++k)
          if (const LO cc = col[static_cast<std::size_t>(k)]; cc % 2 == 0)
            c.innerIndexPtr()[at++] = cc / 2;
      }
      c.outerIndexPtr()[m] = at;
      Eigen::internal::minimum_degree_ordering(c, pinv);
    } else {
      pinv = amd_of_lower(lower_);
    }
    perm_ = pinv.size() > 0 ? Permutation(pinv.inverse()) : Permutation();
    perm_inv_ = pinv;
    for (Eigen::Index k = 0; k < lower_.nonZeros(); ++k)
      lower_.valuePtr()[k] = Complex(static_cast<double>(k), 1.0);
    twist_to_upper(lower_, perm_, upper_);
    twist_.resize(static_cast<std::size_t>(upper_.nonZeros()));
    for (Eigen::Index k = 0; k < upper_.nonZeros(); ++k) {
      const Complex code = upper_.valuePtr()[k];
      twist_[static_cast<std::size_t>(k)] = {static_cast<std::int64_t>(code.real()),
                                             code.imag() < 0};
    }
    ldlt_.analyze_preordered(upper_);
    QSMESH_CHECK(ldlt_.info() == Eigen::Success,
                 "eigen (complex pairs): symbolic analysis failed for a matrix of size " << n);
  }

  void factorize(const SparseMatrix& A) override {
    pattern_.check(A, "eigen (complex pairs)");
    factorized_ = false;
    const std::vector<double>& v = A.values();
    Complex* dst = lower_.valuePtr();
    for (std::size_t k = 0; k < sources_.size(); ++k) {
      const Sources& s = sources_[k];
      const double a = v[static_cast<std::size_t>(s.re)];
      const double c = v[static_cast<std::size_t>(s.im)];
      QSMESH_CHECK(
          v[static_cast<std::size_t>(s.re2)] == a && v[static_cast<std::size_t>(s.minus_im)] == -c,
          "eigen (complex pairs): a 2 x 2 block of the matrix of size "
              << A.size() << " is not of the form [[a, -c], [c, a]]");
      dst[k] = Complex(a, c);
    }
    Complex* twisted = upper_.valuePtr();
    for (std::size_t k = 0; k < twist_.size(); ++k) {
      const Complex value = dst[static_cast<std::size_t>(twist_[k].source)];
      twisted[k] = twist_[k].conjugate ? std::conj(value) : value;
    }
    ldlt_.factorize(upper_);
    check_factorization(ldlt_, A.size(), "eigen (complex pairs)");
    factorized_ = true;
  }

  void solve(std::span<const double> b, std::span<double> x) override {
    const std::size_t n = pattern_.check_solve(factorized_, b, x, "eigen (complex pairs)");
    const auto m = static_cast<Eigen::Index>(n / 2);
    rhs_.resize(m);
    for (Eigen::Index i = 0; i < m; ++i)
      rhs_[i] = Complex(b[static_cast<std::size_t>(2 * i)], b[static_cast<std::size_t>(2 * i + 1)]);
    // SimplicialLDLT's solve with its permutation: P b, the triangular and diagonal solves, P^-1.
    if (perm_.size() > 0) {
      work_ = perm_ * rhs_;
      rhs_ = ldlt_.solve(work_);
      work_ = perm_inv_ * rhs_;
    } else {
      work_ = ldlt_.solve(rhs_);
    }
    for (Eigen::Index i = 0; i < m; ++i) {
      x[static_cast<std::size_t>(2 * i)] = work_[i].real();
      x[static_cast<std::size_t>(2 * i + 1)] = work_[i].imag();
    }
  }

  [[nodiscard]] const char* name() const override { return "eigen/simplicial-ldlt-complex"; }

 private:
  // Where a complex entry (I, J) of the lower triangle reads its real form in A.values(): a at
  // (2I, 2J) and (2I+1, 2J+1), c at (2I+1, 2J), -c at (2I, 2J+1).
  struct Sources {
    std::int64_t re, im, minus_im, re2;
  };
  // Where an entry of the permuted upper triangle comes from: its index in lower_, conjugated or
  // not.
  struct Twist {
    std::int64_t source;
    bool conjugate;
  };
  Pattern pattern_;
  bool factorized_ = false;
  ComplexMatrix lower_;  // the complex matrix's lower triangle, in A's order
  ComplexMatrix upper_;  // its permuted upper triangle, factorized in place
  std::vector<Sources> sources_;
  std::vector<Twist> twist_;
  Permutation perm_, perm_inv_;
  Eigen::VectorXcd rhs_, work_;
  PreorderedLdlt<ComplexMatrix> ldlt_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_eigen_solver() { return std::make_unique<EigenSolver>(); }

std::unique_ptr<LinearSolver> make_eigen_complex_solver() {
  return std::make_unique<ComplexEigenSolver>();
}

}  // namespace qsmesh::linalg::detail
