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
  /// Builds the n x n sum of element matrices: element k couples the m unknowns
  /// dofs[k m .. k m + m) (kNoIndex: a fixed unknown, whose row and column are left out) by the
  /// dense m x m block blocks[k m^2 ..), row-major. The result equals the triplet constructor's on
  /// the triplets of the elements in order (row a, column b within each element), entry for entry
  /// and bit for bit: each entry sums its contributions in element order. Finite element systems
  /// come this way; assembling them without the triplets' bucket sort costs a fraction of it.
  /// Preconditions: m > 0, dofs.size() a multiple of m, blocks.size() == dofs.size() * m, every dof
  /// in [0, n) or kNoIndex.
  [[nodiscard]] static SparseMatrix from_elements(LO n, int m, std::span<const LO> dofs,
                                                  std::span<const double> blocks);

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

/// Ranks that solve one system together: a communicator made by src/parallel
/// (parallel::Comm::solver_group) and handed to linalg opaque, so that neither MPI nor PETSc
/// reaches a kernel's signature. The communicator must outlive the group.
class SolverGroup {
 public:
  /// `mpi_comm` points at an MPI_Comm (src/parallel only); `rank` and `size` are this rank's place
  /// in it and its size.
  SolverGroup(const void* mpi_comm, int rank, int size);
  ~SolverGroup();
  SolverGroup(const SolverGroup&) = delete;
  SolverGroup& operator=(const SolverGroup&) = delete;
  [[nodiscard]] int rank() const { return rank_; }
  [[nodiscard]] int size() const { return size_; }
  /// The MPI_Comm, for src/linalg.
  [[nodiscard]] const void* native() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int rank_ = 0, size_ = 1;
};

/// What the distributed solves made with a group lane did (SolverLane's second constructor), for
/// reports and for tests that check the solve really was split.
struct DistributedReport {
  int ranks = 0;                  ///< size of the group (0: no system was solved distributed)
  int systems = 0;                ///< systems analysed distributed
  LO unknowns = 0;                ///< the largest of them
  std::vector<LO> rows_per_rank;  ///< of the largest: the rows each rank of the group assembled
  int solves = 0;                 ///< right-hand sides solved distributed
  int refinement_steps = 0;       ///< iterative-refinement solves on top of them (all solves)
};

/// Where a rank's solves run. PETSc in Debian is not thread-safe: every PETSc call of a rank goes
/// through its one lane, which serialises them. Kernels take a lane pointer and pass it to
/// make_solver; they see neither PETSc nor MPI.
///
/// The rank's lane (first constructor) is created once per process by the driver, after MPI and
/// before any solve, and passed down; it initialises PETSc on construction and finalises it on
/// destruction. Its systems are solved on the rank alone (PETSC_COMM_SELF).
/// - At most one rank lane exists at a time in a process (the constructor throws qsmesh::Error
///   when PETSc is already initialised). Every solver made with a lane must be destroyed before it.
/// - MPI: when MPI is already initialised (by the driver), PETSc uses it and the lane leaves it
///   running; the driver should ask for MPI_THREAD_SERIALIZED, since solver calls come from worker
///   threads (one at a time). When MPI is not initialised, PETSc initialises it (asking for
///   MPI_THREAD_SERIALIZED) and finalises it with the lane; MPI cannot be initialised twice, so
///   such a process (a test, a benchmark) can create only one lane in its lifetime.
/// - No options file is read (~/.petscrc, ./.petscrc); the PETSC_OPTIONS environment variable
///   still applies (debugging aid). PETSc's signal handler is removed so crashes are not hijacked,
///   and PETSc's error printing is replaced by qsmesh::Error exceptions carrying its message.
///
/// A group lane (second constructor) is for a collective phase: it shares the rank lane's PETSc
/// and lock, and a system of at least SolverOptions::distributed_threshold unknowns made with it
/// is solved by all ranks of the group together (MUMPS on a distributed matrix, each rank
/// assembling its contiguous block of rows). Every rank of the group must then make the same
/// solver calls, in the same order, with the same matrices and right-hand sides (each rank builds
/// the whole system: the callers are deterministic), and gets the whole solution. Solutions are
/// refined until they no longer change (residuals in twice the working precision), so that they
/// are the correctly rounded solution whatever the group's size: the same bits at 1, 2 or 4 ranks
/// (except, with a probability of about cond(A) 1e-16 per unknown, one last bit where the exact
/// solution lies halfway between two doubles).
class SolverLane {
 public:
  SolverLane();
  SolverLane(SolverLane& rank_lane, const SolverGroup& group);
  ~SolverLane();
  SolverLane(const SolverLane&) = delete;
  SolverLane& operator=(const SolverLane&) = delete;
  [[nodiscard]] std::mutex& mutex() { return *mutex_; }
  /// Message of the last PETSc error raised under this lane (for src/linalg's error reports).
  /// Read and written only while holding mutex().
  [[nodiscard]] std::string& last_error() { return *last_error_; }
  /// The group of a group lane; null for the rank's lane.
  [[nodiscard]] const SolverGroup* group() const { return group_; }
  /// The distributed solves made so far with this lane (group lanes only).
  [[nodiscard]] const DistributedReport& report() const { return report_; }
  [[nodiscard]] DistributedReport& report() { return report_; }

 private:
  bool owns_petsc_ = true;
  std::mutex own_mutex_;
  std::string own_error_;
  std::mutex* mutex_ = &own_mutex_;
  std::string* last_error_ = &own_error_;
  const SolverGroup* group_ = nullptr;
  DistributedReport report_;
};

/// The former name of SolverLane.
using PetscLane = SolverLane;

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
  /// Automatic, for a complex_pairs system: its threshold instead of petsc_threshold. Factorized
  /// as complex, Eigen stays faster than one-rank MUMPS on the real form up to the largest size
  /// measured, 2e6 unknowns (analyze + 2 factorizations + 10 solves: 18 s against 36 s;
  /// docs/benchmarks.md, "Complex factorization").
  LO petsc_threshold_complex = 2000000;
  /// Backend::PetscMultigrid: relative residual (unpreconditioned 2-norm) at which CG stops.
  double multigrid_rtol = 1e-10;
  /// Backend::PetscMultigrid: unknowns per node (the cross field's 2 per edge), so that GAMG
  /// aggregates nodes rather than separate components. The system size must be a multiple of it.
  int block_size = 1;
  /// A group lane (SolverLane's second constructor): systems with at least this many unknowns are
  /// solved by the group's ranks together, smaller ones as by the rank's lane. A system must be
  /// large for the split to pay: the ranks exchange the factors' fronts, and every rank still
  /// assembles the whole system (docs/benchmarks.md, "A face's system split over ranks").
  LO distributed_threshold = 2000000;
  /// The system is the real form of a complex Hermitian positive definite one: its unknowns come
  /// in pairs (2i, 2i+1), the real and imaginary parts of z_i, and every 2 x 2 block (2i, 2j) is
  /// [[a, -c], [c, a]] for the complex entry a + ic (all four entries in the pattern, the values
  /// exactly so; factorize() throws otherwise). The Eigen backend then factorizes the complex
  /// matrix of n / 2 unknowns (L D L^H): half the fill of the real form, and on the cross field's
  /// Crouzeix-Raviart systems 1.5x faster factorizations and 2x faster solves (docs/benchmarks.md,
  /// "Complex factorization"). The solution agrees with the real form's to rounding, not bit for
  /// bit. The PETSc backends ignore it. n must be even.
  bool complex_pairs = false;
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
/// Backend::Petsc throws). A group lane and n >= options.distributed_threshold (Automatic or
/// Petsc): MUMPS Cholesky over the group's ranks, a collective object (see SolverLane). Safe to
/// call from many threads; each solver object is used by one.
[[nodiscard]] std::unique_ptr<LinearSolver> make_solver(LO n, const SolverOptions& options,
                                                        SolverLane* lane);

}  // namespace qsmesh::linalg
