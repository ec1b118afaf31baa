// PETSc backend: MUMPS sparse Cholesky on a SeqAIJ matrix (PETSC_COMM_SELF), for the large
// per-face systems where a multifrontal factorization (BLAS-3 on supernodes) beats Eigen's
// simplicial one. Also home of SolverLane.
//
// The factor matrix is driven directly (MatGetFactor / MatCholeskyFactorSymbolic / ...Numeric /
// MatSolve) rather than through KSPPREONLY + PCCHOLESKY: that is exactly what the PC does
// internally, and the direct calls map one to one onto analyze / factorize / solve, so the
// symbolic analysis runs once per pattern and never depends on the values of the pattern matrix.
#include <mpi.h>
#include <petscksp.h>
#include <petscmat.h>
#include <petscsys.h>

#include <algorithm>
#include <array>
#include <limits>
#include <mutex>
#include <sstream>

#include "backends.hpp"
#include "petsc_common.hpp"

namespace qsmesh::linalg {
namespace {

// Error handler pushed by the lane: records PETSc's message (the initial one and the call chain
// it travels up) instead of printing it, so that the throwing site can put it into qsmesh::Error.
// Only ever runs inside a PETSc call, hence under the lane's mutex.
PetscErrorCode record_petsc_error(MPI_Comm /*comm*/, int line, const char* fun, const char* file,
                                  PetscErrorCode code, PetscErrorType type, const char* message,
                                  void* context) {
  auto& text = *static_cast<std::string*>(context);
  std::ostringstream os;
  if (type == PETSC_ERROR_INITIAL) {
    const char* generic = nullptr;
    PetscErrorMessage(code, &generic, nullptr);
    os << (generic != nullptr ? generic : "PETSc error");
    if (message != nullptr && message[0] != '\0') os << ": " << message;
    os << " (in " << (fun != nullptr ? fun : "?") << " at " << (file != nullptr ? file : "?") << ":"
       << line << ")";
    text = os.str();
  } else {
    os << text << " <- " << (fun != nullptr ? fun : "?");
    text = os.str();
  }
  // Newlines would break the one-line contract of qsmesh::Error.
  std::replace(text.begin(), text.end(), '\n', ' ');
  return code;
}

}  // namespace

SolverLane::SolverLane() {
  std::lock_guard lock(own_mutex_);
  PetscBool petsc_up = PETSC_FALSE;
  QSMESH_CHECK(
      PetscInitialized(&petsc_up) == 0 && petsc_up == PETSC_FALSE,
      "SolverLane: PETSc is already initialised in this process (only one lane at a time)");
  int mpi_up = 0;
  QSMESH_CHECK(MPI_Initialized(&mpi_up) == MPI_SUCCESS, "SolverLane: MPI_Initialized failed");
  if (mpi_up == 0) PETSC_MPI_THREAD_REQUIRED = MPI_THREAD_SERIALIZED;
  // No options files: results must not depend on a user's ~/.petscrc. No signal handler either.
  static char arg0[] = "qsmesh";
  static char arg1[] = "-skip_petscrc";
  static char arg2[] = "-no_signal_handler";
  std::array<char*, 4> argv{arg0, arg1, arg2, nullptr};
  const PetscErrorCode init = PetscInitializeNoPointers(3, argv.data(), nullptr, nullptr);
  QSMESH_CHECK(init == 0, "SolverLane: PetscInitialize failed with PETSc error code " << init);
  const PetscErrorCode pop = PetscPopSignalHandler();
  const PetscErrorCode push = PetscPushErrorHandler(record_petsc_error, &own_error_);
  if (pop != 0 || push != 0) {
    PetscFinalize();
    QSMESH_CHECK(false, "SolverLane: could not set PETSc's signal/error handlers (error codes "
                            << pop << ", " << push << ")");
  }
}

SolverLane::SolverLane(SolverLane& rank_lane, const SolverGroup& group)
    : owns_petsc_(false),
      mutex_(&rank_lane.mutex()),
      last_error_(&rank_lane.last_error()),
      group_(&group) {}

SolverLane::~SolverLane() {
  if (!owns_petsc_) return;
  std::lock_guard lock(own_mutex_);
  // Destructors cannot throw; a failing finalisation at exit has nothing left to protect.
  PetscPopErrorHandler();
  PetscFinalize();
}

namespace detail {

[[noreturn]] void petsc_failed(SolverLane& lane, PetscErrorCode code, const char* call,
                               const char* file, int line) {
  std::ostringstream os;
  os << "petsc: " << call << " failed with error " << code;
  if (!lane.last_error().empty()) os << ": " << lane.last_error();
  os << " (at " << file << ":" << line << ")";
  lane.last_error().clear();
  throw Error(os.str());
}

PetscInt to_petsc_int(std::int64_t value, const char* what) {
  QSMESH_CHECK(value >= 0 && value <= std::numeric_limits<PetscInt>::max(),
               "petsc: " << what << " " << value << " does not fit PETSc's " << 8 * sizeof(PetscInt)
                         << "-bit indices");
  return static_cast<PetscInt>(value);
}

void set_spd_options(SolverLane& lane, Mat matrix) {
  SolverLane* const lane_ = &lane;  // QSMESH_PETSC_CALL's lane
  QSMESH_PETSC_CALL(MatSetOption(matrix, MAT_SYMMETRIC, PETSC_TRUE));
  QSMESH_PETSC_CALL(MatSetOption(matrix, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  QSMESH_PETSC_CALL(MatSetOption(matrix, MAT_SPD, PETSC_TRUE));
  QSMESH_PETSC_CALL(MatSetOption(matrix, MAT_SPD_ETERNAL, PETSC_TRUE));
}

void check_factorization(SolverLane& lane, Mat factor, bool mumps, MatFactorType type,
                         const std::string& name, LO n, const char* who) {
  SolverLane* const lane_ = &lane;  // QSMESH_PETSC_CALL's lane
  MatFactorError error = MAT_FACTOR_NOERROR;
  QSMESH_PETSC_CALL(MatFactorGetError(factor, &error));
  PetscInt infog1 = 0;
  PetscInt negative_pivots = 0;
  if (mumps) {
    QSMESH_PETSC_CALL(MatMumpsGetInfog(factor, 1, &infog1));
    QSMESH_PETSC_CALL(MatMumpsGetInfog(factor, 12, &negative_pivots));
  }
  QSMESH_CHECK(error == MAT_FACTOR_NOERROR && infog1 >= 0,
               who << ": numeric factorization (" << name << ") failed for a matrix of size " << n
                   << ": the matrix is singular or not positive definite (PETSc factor error "
                   << static_cast<int>(error) << (mumps ? ", MUMPS INFOG(1) " : "")
                   << (mumps ? std::to_string(infog1) : std::string()) << ")");
  QSMESH_CHECK(type != MAT_FACTOR_CHOLESKY || negative_pivots == 0,
               who << ": the matrix of size " << n << " is not positive definite ("
                   << negative_pivots << " negative pivots in " << name << ")");
}

namespace {

// The SeqAIJ matrix of one pattern (PETSC_COMM_SELF) and its right-hand side and solution
// vectors, as both PETSc backends hold them. Every method runs under the lane's lock.
struct SeqSystem {
  SolverLane* lane_;
  Mat matrix = nullptr;
  Vec b = nullptr;
  Vec x = nullptr;

  // Preallocates exactly and assembles the pattern of A with its values; marks it SPD (MUMPS then
  // runs its SPD variant, SYM=1, no pivoting, reading only the upper triangle).
  void create(const SparseMatrix& A, int block_size) {
    const LO n = A.size();
    std::vector<PetscInt> ia(static_cast<std::size_t>(n) + 1);
    for (std::size_t i = 0; i < ia.size(); ++i)
      ia[i] = to_petsc_int(A.row_offsets()[i], "nonzero count");
    const std::vector<PetscInt> ja(A.columns().begin(), A.columns().end());
    QSMESH_PETSC_CALL(MatCreate(PETSC_COMM_SELF, &matrix));
    QSMESH_PETSC_CALL(MatSetSizes(matrix, n, n, n, n));
    QSMESH_PETSC_CALL(MatSetType(matrix, MATSEQAIJ));
    QSMESH_PETSC_CALL(MatSetBlockSize(matrix, block_size));
    QSMESH_PETSC_CALL(
        MatSeqAIJSetPreallocationCSR(matrix, ia.data(), ja.data(), A.values().data()));
    QSMESH_PETSC_CALL(MatSetOption(matrix, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_TRUE));
    set_spd_options(*lane_, matrix);
    QSMESH_PETSC_CALL(MatCreateVecs(matrix, &x, &b));
  }

  // New values of the same pattern: sorted columns, so SeqAIJ stores them in exactly our CSR order.
  void set_values(const SparseMatrix& A) {
    PetscScalar* values = nullptr;
    QSMESH_PETSC_CALL(MatSeqAIJGetArray(matrix, &values));
    std::copy(A.values().begin(), A.values().end(), values);
    QSMESH_PETSC_CALL(MatSeqAIJRestoreArray(matrix, &values));
  }

  void load(std::span<const double> rhs) {
    PetscScalar* bp = nullptr;
    QSMESH_PETSC_CALL(VecGetArrayWrite(b, &bp));
    std::copy(rhs.begin(), rhs.end(), bp);
    QSMESH_PETSC_CALL(VecRestoreArrayWrite(b, &bp));
  }

  void store(std::span<double> solution) {
    const PetscScalar* xp = nullptr;
    QSMESH_PETSC_CALL(VecGetArrayRead(x, &xp));
    std::copy(xp, xp + solution.size(), solution.begin());
    QSMESH_PETSC_CALL(VecRestoreArrayRead(x, &xp));
  }

  // Never throws (runs in destructors); a failing destroy leaks at worst.
  void destroy() noexcept {
    VecDestroy(&b);
    VecDestroy(&x);
    MatDestroy(&matrix);
  }
};

class PetscSolver final : public LinearSolver {
 public:
  explicit PetscSolver(SolverLane& lane) : lane_(&lane), sys_{&lane} {}
  ~PetscSolver() override {
    std::lock_guard lock(lane_->mutex());
    destroy_all();
  }
  PetscSolver(const PetscSolver&) = delete;
  PetscSolver& operator=(const PetscSolver&) = delete;

  void analyze(const SparseMatrix& A) override {
    std::lock_guard lock(lane_->mutex());
    destroy_all();
    pattern_ = Pattern();
    factorized_ = false;
    try {
      build(A);
    } catch (const Error&) {
      destroy_all();  // a half-built solver must not be factorized
      throw;
    }
    pattern_ = Pattern(A);
  }

  void factorize(const SparseMatrix& A) override {
    pattern_.check(A, "petsc");
    std::lock_guard lock(lane_->mutex());
    factorized_ = false;
    if (A.size() == 0) {
      factorized_ = true;
      return;
    }
    // A failed MUMPS factorization leaves MUMPS in an error state that PETSc does not reset:
    // redo the symbolic phase on a fresh factor before trying new values.
    if (factor_ == nullptr) symbolic();
    sys_.set_values(A);
    try {
      if (type_ == MAT_FACTOR_CHOLESKY)
        QSMESH_PETSC_CALL(MatCholeskyFactorNumeric(factor_, sys_.matrix, &info_));
      else
        QSMESH_PETSC_CALL(MatLUFactorNumeric(factor_, sys_.matrix, &info_));
      check_factor(A.size());
    } catch (const Error&) {
      MatDestroy(&factor_);  // rebuilt by the next factorize(); its own error would add nothing
      throw;
    }
    factorized_ = true;
  }

  // Under the lock: matrix, vectors and symbolic factorization for the pattern of A.
  void build(const SparseMatrix& A) {
    if (A.size() == 0) return;
    sys_.create(A, 1);

    // MUMPS Cholesky; MUMPS LU when a PETSc build lacks the Cholesky path; PETSc's own
    // factorizations when MUMPS is missing altogether.
    static constexpr std::array<std::pair<const char*, MatFactorType>, 4> kChoices{{
        {MATSOLVERMUMPS, MAT_FACTOR_CHOLESKY},
        {MATSOLVERMUMPS, MAT_FACTOR_LU},
        {MATSOLVERPETSC, MAT_FACTOR_CHOLESKY},
        {MATSOLVERPETSC, MAT_FACTOR_LU},
    }};
    bool found = false;
    for (const auto& [package, type] : kChoices) {
      PetscBool available = PETSC_FALSE;
      QSMESH_PETSC_CALL(MatGetFactorAvailable(sys_.matrix, package, type, &available));
      if (available == PETSC_TRUE) {
        package_ = package;
        type_ = type;
        found = true;
        break;
      }
    }
    QSMESH_CHECK(found, "petsc: no direct factorization (MUMPS or PETSc) is available for SeqAIJ");
    name_ = std::string("petsc/") + package_ + (type_ == MAT_FACTOR_CHOLESKY ? "-cholesky" : "-lu");
    // MUMPS orders the matrix itself; PETSc's own factorization needs a fill-reducing ordering.
    QSMESH_PETSC_CALL(MatGetOrdering(
        sys_.matrix, package_ == std::string(MATSOLVERMUMPS) ? MATORDERINGNATURAL : MATORDERINGND,
        &row_order_, &col_order_));
    symbolic();
  }

  void solve(std::span<const double> b, std::span<double> x) override {
    const std::size_t n = pattern_.check_solve(factorized_, b, x, "petsc");
    if (n == 0) return;
    std::lock_guard lock(lane_->mutex());
    sys_.load(b);
    QSMESH_PETSC_CALL(MatSolve(factor_, sys_.b, sys_.x));
    sys_.store(x);
  }

  [[nodiscard]] const char* name() const override { return name_.c_str(); }

 private:
  // Under the lock: a fresh factor matrix and its symbolic analysis of the matrix's pattern.
  void symbolic() {
    QSMESH_PETSC_CALL(MatGetFactor(sys_.matrix, package_, type_, &factor_));
    if (package_ == std::string(MATSOLVERMUMPS)) {
      // Quiet: no MUMPS diagnostics on stdout (ICNTL 1-4), whatever PETSC_OPTIONS says.
      QSMESH_PETSC_CALL(MatMumpsSetIcntl(factor_, 4, 0));
    }
    QSMESH_PETSC_CALL(MatFactorInfoInitialize(&info_));
    if (type_ == MAT_FACTOR_CHOLESKY)
      QSMESH_PETSC_CALL(MatCholeskyFactorSymbolic(factor_, sys_.matrix, row_order_, &info_));
    else
      QSMESH_PETSC_CALL(MatLUFactorSymbolic(factor_, sys_.matrix, row_order_, col_order_, &info_));
  }

  void check_factor(LO n) {
    check_factorization(*lane_, factor_, package_ == std::string(MATSOLVERMUMPS), type_, name_, n,
                        "petsc");
  }

  // Under the lock. Never throws (runs in the destructor); a failing destroy leaks at worst.
  void destroy_all() noexcept {
    MatDestroy(&factor_);
    ISDestroy(&row_order_);
    ISDestroy(&col_order_);
    sys_.destroy();
    lane_->last_error().clear();
  }

  SolverLane* lane_;
  SeqSystem sys_;
  Pattern pattern_;
  bool factorized_ = false;
  std::string name_ = "petsc";
  const char* package_ = MATSOLVERMUMPS;
  MatFactorType type_ = MAT_FACTOR_CHOLESKY;
  Mat factor_ = nullptr;
  IS row_order_ = nullptr;
  IS col_order_ = nullptr;
  MatFactorInfo info_{};
};

// CG + GAMG: the iterative alternative measured against the factorizations.
class PetscMultigridSolver final : public LinearSolver {
 public:
  PetscMultigridSolver(SolverLane& lane, double rtol, int block_size)
      : lane_(&lane), rtol_(rtol), block_size_(block_size), sys_{&lane} {
    QSMESH_CHECK(block_size >= 1, "petsc multigrid: block size " << block_size << " is below 1");
    QSMESH_CHECK(rtol > 0 && rtol < 1,
                 "petsc multigrid: relative tolerance " << rtol << " is not in (0, 1)");
  }
  ~PetscMultigridSolver() override {
    std::lock_guard lock(lane_->mutex());
    destroy_all();
  }
  PetscMultigridSolver(const PetscMultigridSolver&) = delete;
  PetscMultigridSolver& operator=(const PetscMultigridSolver&) = delete;

  void analyze(const SparseMatrix& A) override {
    std::lock_guard lock(lane_->mutex());
    destroy_all();
    pattern_ = Pattern();
    ready_ = false;
    try {
      build(A);
    } catch (const Error&) {
      destroy_all();
      throw;
    }
    pattern_ = Pattern(A);
  }

  void factorize(const SparseMatrix& A) override {
    pattern_.check(A, "petsc multigrid");
    std::lock_guard lock(lane_->mutex());
    ready_ = false;
    if (A.size() == 0) {
      ready_ = true;
      return;
    }
    sys_.set_values(A);
    // New values: the hierarchy is rebuilt here, once per level, not at the first solve.
    QSMESH_PETSC_CALL(KSPSetOperators(ksp_, sys_.matrix, sys_.matrix));
    QSMESH_PETSC_CALL(KSPSetUp(ksp_));
    ready_ = true;
  }

  void solve(std::span<const double> b, std::span<double> x) override {
    const std::size_t n = pattern_.check_solve(ready_, b, x, "petsc multigrid");
    if (n == 0) return;
    std::lock_guard lock(lane_->mutex());
    sys_.load(b);
    QSMESH_PETSC_CALL(KSPSolve(ksp_, sys_.b, sys_.x));
    KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
    QSMESH_PETSC_CALL(KSPGetConvergedReason(ksp_, &reason));
    PetscInt iterations = 0;
    QSMESH_PETSC_CALL(KSPGetIterationNumber(ksp_, &iterations));
    QSMESH_CHECK(reason > 0, "petsc multigrid: CG did not converge on a system of size "
                                 << n << " (reason " << static_cast<int>(reason) << " after "
                                 << iterations << " iterations)");
    sys_.store(x);
  }

  [[nodiscard]] const char* name() const override { return "petsc/cg-gamg"; }

 private:
  void build(const SparseMatrix& A) {
    const LO n = A.size();
    if (n == 0) return;
    QSMESH_CHECK(n % block_size_ == 0, "petsc multigrid: system size "
                                           << n << " is not a multiple of the block size "
                                           << block_size_);
    sys_.create(A, block_size_);
    QSMESH_PETSC_CALL(KSPCreate(PETSC_COMM_SELF, &ksp_));
    QSMESH_PETSC_CALL(KSPSetType(ksp_, KSPCG));
    PC pc = nullptr;
    QSMESH_PETSC_CALL(KSPGetPC(ksp_, &pc));
    QSMESH_PETSC_CALL(PCSetType(pc, PCGAMG));
    // The true residual, so the tolerance means the same as the direct solvers' residuals.
    QSMESH_PETSC_CALL(KSPSetNormType(ksp_, KSP_NORM_UNPRECONDITIONED));
    QSMESH_PETSC_CALL(KSPSetTolerances(ksp_, rtol_, 0.0, PETSC_DEFAULT, 10000));
  }

  void destroy_all() noexcept {
    KSPDestroy(&ksp_);
    sys_.destroy();
    lane_->last_error().clear();
  }

  SolverLane* lane_;
  double rtol_;
  int block_size_;
  SeqSystem sys_;
  Pattern pattern_;
  bool ready_ = false;
  KSP ksp_ = nullptr;
};

}  // namespace

std::unique_ptr<LinearSolver> make_petsc_solver(SolverLane& lane) {
  return std::make_unique<PetscSolver>(lane);
}

std::unique_ptr<LinearSolver> make_petsc_multigrid_solver(SolverLane& lane, double rtol,
                                                          int block_size) {
  return std::make_unique<PetscMultigridSolver>(lane, rtol, block_size);
}

}  // namespace detail
}  // namespace qsmesh::linalg
