// PETSc backend for one system split over the ranks of a group (SolverLane's group lanes): MUMPS
// Cholesky on an MPIAIJ matrix, each rank setting its contiguous block of rows. Also home of
// SolverGroup, the opaque communicator that src/parallel hands over.
//
// Every rank of the group holds the whole system (its callers build it alike on every rank), sets
// its own rows into PETSc and gets the whole solution back (a scatter to all).
//
// The same bits at any rank count: MUMPS's rounding depends on how it split the work, so the
// solution is refined (x += A^{-1} (b - A x), x kept as a sum of two doubles, the residual summed
// in twice the working precision: Dot2 of Ogita, Rump and Oishi) until a correction is below 2^-40
// of the largest entry; the error left is then about the square of that, far below the grid of
// 2^-40 of the largest entry to which the solution is finally rounded. Two runs on different rank
// counts give different bits only where an entry lies within that error of a grid midpoint: with
// the usual error (1e-13 relative after the first solve, 1e-26 after one correction), a chance of
// about 1e-14 per entry. The rounding costs at most 2^-41 of the largest entry. Usually one
// correction: twice the solves of a one-rank factorization, plus the residual.
#include <mpi.h>
#include <petscmat.h>
#include <petscsys.h>
#include <petscvec.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "backends.hpp"
#include "petsc_common.hpp"

namespace qsmesh::linalg {

struct SolverGroup::Impl {
  MPI_Comm comm = MPI_COMM_SELF;
};

SolverGroup::SolverGroup(const void* mpi_comm, int rank, int size)
    : impl_(std::make_unique<Impl>()), rank_(rank), size_(size) {
  QSMESH_CHECK(mpi_comm != nullptr && size >= 1 && rank >= 0 && rank < size,
               "SolverGroup: rank " << rank << " of " << size << " is not a place in a group");
  impl_->comm = *static_cast<const MPI_Comm*>(mpi_comm);
}

SolverGroup::~SolverGroup() = default;

const void* SolverGroup::native() const { return &impl_->comm; }

namespace detail {
namespace {

// Rows [first(r), first(r + 1)) belong to rank r: even blocks, the same on every rank.
LO first_row(LO n, int rank, int size) {
  return static_cast<LO>(static_cast<std::int64_t>(n) * rank / size);
}

// Error-free transformations (Dot2): a + b = s + e and a * b = p + e exactly.
void two_sum(double a, double b, double& s, double& e) {
  s = a + b;
  const double z = s - a;
  e = (a - (s - z)) + (b - z);
}

// The grid of the final solution: 2^-kGridBits of its largest entry. The refinement stops once a
// correction is below 2^-kContraction of it.
constexpr int kGridBits = 40;
constexpr int kContraction = 40;

// b - A (x + lo), each row summed as if in twice the working precision, then rounded once (lo is
// the refinement's low part, below the last bit of x: its products need no compensation).
void exact_residual(const SparseMatrix& A, std::span<const double> b, std::span<const double> x,
                    std::span<const double> lo, std::span<double> r) {
  const auto& offsets = A.row_offsets();
  const auto& cols = A.columns();
  const auto& values = A.values();
  for (LO i = 0; i < A.size(); ++i) {
    double s = b[i], c = 0;
    for (std::int64_t k = offsets[i]; k < offsets[i + 1]; ++k) {
      const double p = -values[k] * x[cols[k]];
      const double pe = std::fma(-values[k], x[cols[k]], -p);
      double e = 0;
      two_sum(s, p, s, e);
      c += e + pe - values[k] * lo[cols[k]];
    }
    r[i] = s + c;
  }
}

// x + lo rounded to the nearest multiple of `grid`, a power of two (so x / grid is exact).
void round_to_grid(std::span<double> x, std::span<const double> lo, double grid) {
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double q = x[i] / grid;
    const double whole = std::floor(q);
    const double fraction = (q - whole) + lo[i] / grid;  // q - whole is exact
    x[i] = (whole + std::floor(fraction + 0.5)) * grid;
  }
}

class PetscDistributedSolver final : public LinearSolver {
 public:
  explicit PetscDistributedSolver(SolverLane& lane)
      : lane_(&lane),
        comm_(*static_cast<const MPI_Comm*>(lane.group()->native())),
        rank_(lane.group()->rank()),
        size_(lane.group()->size()),
        name_("petsc/mumps-cholesky-mpi" + std::to_string(size_)) {}
  ~PetscDistributedSolver() override {
    std::lock_guard lock(lane_->mutex());
    destroy_all();
  }
  PetscDistributedSolver(const PetscDistributedSolver&) = delete;
  PetscDistributedSolver& operator=(const PetscDistributedSolver&) = delete;

  void analyze(const SparseMatrix& A) override {
    std::lock_guard lock(lane_->mutex());
    destroy_all();
    pattern_ = Pattern();
    factorized_ = false;
    try {
      build(A);
    } catch (const Error&) {
      destroy_all();
      throw;
    }
    pattern_ = Pattern(A);
  }

  void factorize(const SparseMatrix& A) override {
    pattern_.check(A, "petsc distributed");
    std::lock_guard lock(lane_->mutex());
    factorized_ = false;
    if (A.size() == 0) {
      factorized_ = true;
      return;
    }
    if (factor_ == nullptr) symbolic();
    set_values(A);
    try {
      if (type_ == MAT_FACTOR_CHOLESKY)
        QSMESH_PETSC_CALL(MatCholeskyFactorNumeric(factor_, matrix_, &info_));
      else
        QSMESH_PETSC_CALL(MatLUFactorNumeric(factor_, matrix_, &info_));
      check_factor(A.size());
    } catch (const Error&) {
      MatDestroy(&factor_);
      throw;
    }
    factorized_ = true;
  }

  void solve(std::span<const double> b, std::span<double> x) override {
    const std::size_t n = pattern_.check_solve(factorized_, b, x, "petsc distributed");
    if (n == 0) return;
    std::lock_guard lock(lane_->mutex());
    solve_gathered(b, x);
    ++lane_->report().solves;
    // Refinement in twice the working precision, then rounding to a grid (see the file's head).
    // Every rank holds the same x, so every rank takes the same steps.
    std::vector<double> lo(n, 0.0), r(n), d(n);
    double largest = 0;
    for (const double v : x) largest = std::max(largest, std::abs(v));
    constexpr int kMaxSteps = 4;
    for (int step = 0; step < kMaxSteps && largest > 0; ++step) {
      exact_residual(residual_matrix_, b, x, lo, r);
      solve_gathered(r, d);
      ++lane_->report().refinement_steps;
      double change = 0;
      largest = 0;
      for (std::size_t i = 0; i < n; ++i) {
        double s = 0, e = 0;
        two_sum(x[i], d[i], s, e);
        two_sum(s, lo[i] + e, x[i], lo[i]);
        change = std::max(change, std::abs(d[i]));
        largest = std::max(largest, std::abs(x[i]));
      }
      // The error left is about the square of the relative correction (a backward-stable solve
      // contracts the error by the factor it started with).
      if (change <= std::ldexp(largest, -kContraction)) break;
    }
    if (largest > 0) round_to_grid(x, lo, std::ldexp(1.0, std::ilogb(largest) - kGridBits));
  }

  [[nodiscard]] const char* name() const override { return name_.c_str(); }

 private:
  // Under the lock: the MPIAIJ matrix of this rank's rows, the vectors and the factor's symbolic
  // analysis. Records the split in the lane's report.
  void build(const SparseMatrix& A) {
    const LO n = A.size();
    if (n == 0) return;
    row0_ = first_row(n, rank_, size_);
    row1_ = first_row(n, rank_ + 1, size_);
    const LO local = row1_ - row0_;
    const auto& offsets = A.row_offsets();
    std::vector<PetscInt> ia(static_cast<std::size_t>(local) + 1);
    for (LO i = 0; i <= local; ++i)
      ia[i] = to_petsc_int(offsets[row0_ + i] - offsets[row0_], "nonzero count");
    const std::vector<PetscInt> ja(A.columns().begin() + offsets[row0_],
                                   A.columns().begin() + offsets[row1_]);
    QSMESH_PETSC_CALL(MatCreate(comm_, &matrix_));
    QSMESH_PETSC_CALL(MatSetSizes(matrix_, local, local, n, n));
    QSMESH_PETSC_CALL(MatSetType(matrix_, MATMPIAIJ));
    QSMESH_PETSC_CALL(MatMPIAIJSetPreallocationCSR(matrix_, ia.data(), ja.data(),
                                                   A.values().data() + offsets[row0_]));
    QSMESH_PETSC_CALL(MatSetOption(matrix_, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_TRUE));
    set_spd_options(*lane_, matrix_);
    QSMESH_PETSC_CALL(MatCreateVecs(matrix_, &x_, &b_));
    QSMESH_PETSC_CALL(VecScatterCreateToAll(x_, &to_all_, &x_all_));

    PetscBool available = PETSC_FALSE;
    QSMESH_PETSC_CALL(
        MatGetFactorAvailable(matrix_, MATSOLVERMUMPS, MAT_FACTOR_CHOLESKY, &available));
    type_ = available == PETSC_TRUE ? MAT_FACTOR_CHOLESKY : MAT_FACTOR_LU;
    if (available != PETSC_TRUE) {
      QSMESH_PETSC_CALL(MatGetFactorAvailable(matrix_, MATSOLVERMUMPS, MAT_FACTOR_LU, &available));
      QSMESH_CHECK(available == PETSC_TRUE,
                   "petsc distributed: MUMPS is not available for MPIAIJ in this PETSc");
    }
    name_ = std::string("petsc/mumps-") + (type_ == MAT_FACTOR_CHOLESKY ? "cholesky" : "lu") +
            "-mpi" + std::to_string(size_);
    symbolic();

    // The split as PETSc holds it.
    const PetscInt* ranges = nullptr;
    QSMESH_PETSC_CALL(MatGetOwnershipRanges(matrix_, &ranges));
    DistributedReport& report = lane_->report();
    report.ranks = size_;
    ++report.systems;
    if (n >= report.unknowns) {
      report.unknowns = n;
      report.rows_per_rank.assign(static_cast<std::size_t>(size_), 0);
      for (int r = 0; r < size_; ++r)
        report.rows_per_rank[r] = static_cast<LO>(ranges[r + 1] - ranges[r]);
    }
    residual_matrix_ = A;
  }

  void symbolic() {
    QSMESH_PETSC_CALL(MatGetFactor(matrix_, MATSOLVERMUMPS, type_, &factor_));
    QSMESH_PETSC_CALL(MatMumpsSetIcntl(factor_, 4, 0));  // quiet
    QSMESH_PETSC_CALL(MatFactorInfoInitialize(&info_));
    if (type_ == MAT_FACTOR_CHOLESKY)
      QSMESH_PETSC_CALL(MatCholeskyFactorSymbolic(factor_, matrix_, nullptr, &info_));
    else
      QSMESH_PETSC_CALL(MatLUFactorSymbolic(factor_, matrix_, nullptr, nullptr, &info_));
  }

  // This rank's rows of A, in the pattern set at analyze (sorted columns: MPIAIJ takes them in
  // any order, row by row).
  void set_values(const SparseMatrix& A) {
    const auto& offsets = A.row_offsets();
    for (LO i = row0_; i < row1_; ++i) {
      const PetscInt row = i;
      const auto count = static_cast<PetscInt>(offsets[i + 1] - offsets[i]);
      cols_.assign(A.columns().begin() + offsets[i], A.columns().begin() + offsets[i + 1]);
      QSMESH_PETSC_CALL(MatSetValues(matrix_, 1, &row, count, cols_.data(),
                                     A.values().data() + offsets[i], INSERT_VALUES));
    }
    QSMESH_PETSC_CALL(MatAssemblyBegin(matrix_, MAT_FINAL_ASSEMBLY));
    QSMESH_PETSC_CALL(MatAssemblyEnd(matrix_, MAT_FINAL_ASSEMBLY));
    residual_matrix_.values() = A.values();  // the refinement's residuals
  }

  // Under the lock: x = A^{-1} b with this rank's rows of b, the whole x on every rank.
  void solve_gathered(std::span<const double> b, std::span<double> x) {
    PetscScalar* bp = nullptr;
    QSMESH_PETSC_CALL(VecGetArrayWrite(b_, &bp));
    std::copy(b.begin() + row0_, b.begin() + row1_, bp);
    QSMESH_PETSC_CALL(VecRestoreArrayWrite(b_, &bp));
    QSMESH_PETSC_CALL(MatSolve(factor_, b_, x_));
    QSMESH_PETSC_CALL(VecScatterBegin(to_all_, x_, x_all_, INSERT_VALUES, SCATTER_FORWARD));
    QSMESH_PETSC_CALL(VecScatterEnd(to_all_, x_, x_all_, INSERT_VALUES, SCATTER_FORWARD));
    const PetscScalar* xp = nullptr;
    QSMESH_PETSC_CALL(VecGetArrayRead(x_all_, &xp));
    std::copy(xp, xp + x.size(), x.begin());
    QSMESH_PETSC_CALL(VecRestoreArrayRead(x_all_, &xp));
  }

  void check_factor(LO n) {
    check_factorization(*lane_, factor_, true, type_, name_, n, "petsc distributed");
  }

  void destroy_all() noexcept {
    MatDestroy(&factor_);
    VecScatterDestroy(&to_all_);
    VecDestroy(&x_all_);
    VecDestroy(&b_);
    VecDestroy(&x_);
    MatDestroy(&matrix_);
    lane_->last_error().clear();
  }

  SolverLane* lane_;
  MPI_Comm comm_;
  int rank_, size_;
  LO row0_ = 0, row1_ = 0;
  Pattern pattern_;
  SparseMatrix residual_matrix_;
  std::string name_;  // Cholesky until build() finds MUMPS without it
  std::vector<PetscInt> cols_;
  bool factorized_ = false;
  MatFactorType type_ = MAT_FACTOR_CHOLESKY;
  Mat matrix_ = nullptr;
  Mat factor_ = nullptr;
  Vec b_ = nullptr, x_ = nullptr, x_all_ = nullptr;
  VecScatter to_all_ = nullptr;
  MatFactorInfo info_{};
};

}  // namespace

std::unique_ptr<LinearSolver> make_petsc_distributed_solver(SolverLane& lane) {
  QSMESH_CHECK(lane.group() != nullptr, "petsc distributed: the lane has no group");
  return std::make_unique<PetscDistributedSolver>(lane);
}

}  // namespace detail
}  // namespace qsmesh::linalg
