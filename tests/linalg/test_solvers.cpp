#include <gtest/gtest.h>

#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <complex>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/linalg/solver.hpp"

namespace qsmesh::linalg {

// Readable parameter values in test listings (found by argument-dependent lookup).
void PrintTo(Backend backend, std::ostream* os) {
  *os << (backend == Backend::Eigen ? "Eigen" : "Petsc");
}

namespace {

// One lane for the whole test process: PETSc initialises MPI here and finalises it with the lane,
// and MPI cannot be initialised twice in a process.
class LaneEnvironment : public ::testing::Environment {
 public:
  void SetUp() override { lane_ = std::make_unique<SolverLane>(); }
  void TearDown() override { lane_.reset(); }
  static SolverLane* lane() { return lane_.get(); }

 private:
  static inline std::unique_ptr<SolverLane> lane_;
};
[[maybe_unused]] auto* const kLaneEnvironment =
    ::testing::AddGlobalTestEnvironment(new LaneEnvironment);

SolverLane& lane() {
  SolverLane* l = LaneEnvironment::lane();
  if (l == nullptr) throw Error("test: no SolverLane");
  return *l;
}

// 5-point Laplacian on an m x m grid (Dirichlet boundary folded in) plus shift * identity.
SparseMatrix poisson(LO m, double shift) {
  std::vector<SparseMatrix::Triplet> t;
  const auto id = [m](LO i, LO j) { return i * m + j; };
  for (LO i = 0; i < m; ++i)
    for (LO j = 0; j < m; ++j) {
      const LO r = id(i, j);
      t.push_back({r, r, 4.0 + shift});
      if (i > 0) t.push_back({r, id(i - 1, j), -1.0});
      if (i + 1 < m) t.push_back({r, id(i + 1, j), -1.0});
      if (j > 0) t.push_back({r, id(i, j - 1), -1.0});
      if (j + 1 < m) t.push_back({r, id(i, j + 1), -1.0});
    }
  return SparseMatrix(m * m, t);
}

std::vector<double> rhs(LO n, int seed) {
  std::vector<double> b(static_cast<std::size_t>(n));
  for (LO i = 0; i < n; ++i)
    b[static_cast<std::size_t>(i)] = std::sin(0.37 * i + seed) + 0.1 * seed;
  return b;
}

double norm(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return std::sqrt(s);
}

double relative_residual(const SparseMatrix& A, const std::vector<double>& x,
                         const std::vector<double>& b) {
  std::vector<double> r(b.size());
  A.multiply(x, r);
  for (std::size_t i = 0; i < r.size(); ++i) r[i] -= b[i];
  return norm(r) / norm(b);
}

std::unique_ptr<LinearSolver> make(Backend backend) {
  SolverOptions options;
  options.backend = backend;
  return make_solver(100, options, backend == Backend::Petsc ? &lane() : nullptr);
}

class BothBackends : public ::testing::TestWithParam<Backend> {};

TEST_P(BothBackends, SolvesPoisson) {
  const SparseMatrix A = poisson(30, 0.5);
  auto solver = make(GetParam());
  solver->analyze(A);
  solver->factorize(A);
  const auto b = rhs(A.size(), 1);
  std::vector<double> x(b.size());
  solver->solve(b, x);
  EXPECT_LT(relative_residual(A, x, b), 1e-10) << solver->name();
}

TEST_P(BothBackends, AnalyzeOnceFactorizeTwiceSolveThreeTimes) {
  SparseMatrix A = poisson(25, 0.0);
  auto solver = make(GetParam());
  solver->analyze(A);  // values of the pattern matrix (singular-ish Laplacian) do not matter
  for (double shift : {0.01, 10.0}) {
    for (LO i = 0; i < A.size(); ++i)
      A.values()[static_cast<std::size_t>(A.find(i, i))] = 4.0 + shift;
    solver->factorize(A);
    for (int k = 0; k < 3; ++k) {
      const auto b = rhs(A.size(), k);
      std::vector<double> x(b.size());
      solver->solve(b, x);
      EXPECT_LT(relative_residual(A, x, b), 1e-10) << solver->name() << " shift " << shift;
    }
  }
}

TEST_P(BothBackends, RejectsNonSpdAndRecovers) {
  const SparseMatrix good = poisson(10, 0.1);
  auto solver = make(GetParam());
  solver->analyze(good);
  // Smallest eigenvalue of the 10 x 10 Laplacian: 4 - 4 cos(pi / 11) = 0.16. A shift of -3 meets
  // an exactly zero pivot; -0.5 gives negative pivots but no zero one.
  for (double shift : {-3.0, -0.5}) {
    const SparseMatrix indefinite = poisson(10, shift);
    try {
      solver->factorize(indefinite);
      ADD_FAILURE() << solver->name() << " accepted an indefinite matrix, shift " << shift;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("positive definite"), std::string::npos) << e.what();
      std::cout << "[ message  ] " << e.what() << "\n";
    }
  }
  std::vector<double> x(static_cast<std::size_t>(good.size()));
  const auto b = rhs(good.size(), 2);
  EXPECT_THROW(solver->solve(b, x), Error);  // no valid factorization
  solver->factorize(good);
  solver->solve(b, x);
  EXPECT_LT(relative_residual(good, x, b), 1e-10) << solver->name();
}

TEST_P(BothBackends, RejectsMisuse) {
  const SparseMatrix A = poisson(5, 1.0);
  auto solver = make(GetParam());
  EXPECT_THROW(solver->factorize(A), Error);  // before analyze
  solver->analyze(A);
  std::vector<double> x(static_cast<std::size_t>(A.size()));
  EXPECT_THROW(solver->solve(rhs(A.size(), 0), x), Error);  // before factorize
  EXPECT_THROW(solver->factorize(poisson(6, 1.0)), Error);  // another pattern
  solver->factorize(A);
  std::vector<double> short_x(3);
  EXPECT_THROW(solver->solve(rhs(A.size(), 0), short_x), Error);
}

TEST_P(BothBackends, FourThreadsEachWithItsOwnSolver) {
  constexpr int kThreads = 4;
  std::vector<double> residual(kThreads, 1.0);
  std::vector<std::string> failure(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      try {
        for (int round = 0; round < 3; ++round) {
          const SparseMatrix A = poisson(20 + 3 * t, 0.1 * (t + 1) + round);
          auto solver = make(GetParam());
          solver->analyze(A);
          solver->factorize(A);
          double worst = 0;
          for (int k = 0; k < 3; ++k) {
            const auto b = rhs(A.size(), t + k);
            std::vector<double> x(b.size());
            solver->solve(b, x);
            worst = std::max(worst, relative_residual(A, x, b));
          }
          residual[static_cast<std::size_t>(t)] = worst;
        }
      } catch (const std::exception& e) {
        failure[static_cast<std::size_t>(t)] = e.what();
      }
    });
  for (auto& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t) {
    EXPECT_EQ(failure[static_cast<std::size_t>(t)], "") << "thread " << t;
    EXPECT_LT(residual[static_cast<std::size_t>(t)], 1e-10) << "thread " << t;
  }
}

INSTANTIATE_TEST_SUITE_P(Linalg, BothBackends, ::testing::Values(Backend::Eigen, Backend::Petsc),
                         [](const auto& param_info) {
                           return std::string(param_info.param == Backend::Eigen ? "Eigen"
                                                                                 : "Petsc");
                         });

TEST(Solvers, BackendsAgree) {
  const SparseMatrix A = poisson(40, 0.2);
  const auto b = rhs(A.size(), 3);
  std::vector<double> xe(b.size()), xp(b.size());
  auto eigen = make(Backend::Eigen);
  auto petsc = make(Backend::Petsc);
  for (auto* s : {eigen.get(), petsc.get()}) {
    s->analyze(A);
    s->factorize(A);
  }
  eigen->solve(b, xe);
  petsc->solve(b, xp);
  std::vector<double> diff(b.size());
  for (std::size_t i = 0; i < b.size(); ++i) diff[i] = xe[i] - xp[i];
  EXPECT_LT(norm(diff) / norm(xe), 1e-12);
}

TEST(Solvers, PetscWithoutLaneThrows) {
  SolverOptions options;
  options.backend = Backend::Petsc;
  EXPECT_THROW((void)make_solver(10, options, nullptr), Error);
}

TEST(Solvers, AutomaticPicksBySize) {
  SolverOptions options;
  options.petsc_threshold = 100;
  EXPECT_EQ(std::string(make_solver(99, options, &lane())->name()).rfind("eigen", 0), 0u);
  auto big = make_solver(100, options, &lane());
  big->analyze(poisson(10, 1.0));
  EXPECT_EQ(std::string(big->name()).rfind("petsc/mumps-cholesky", 0), 0u) << big->name();
  EXPECT_EQ(std::string(make_solver(1000, options, nullptr)->name()).rfind("eigen", 0), 0u);
  // Complex pairs have their own threshold.
  options.complex_pairs = true;
  options.petsc_threshold_complex = 200;
  EXPECT_STREQ(make_solver(100, options, &lane())->name(), "eigen/simplicial-ldlt-complex");
  auto big_complex = make_solver(200, options, &lane());
  big_complex->analyze(poisson(10, 1.0));
  big_complex->factorize(poisson(10, 1.0));
  EXPECT_EQ(std::string(big_complex->name()).rfind("petsc/mumps-cholesky", 0), 0u);
}

TEST(Solvers, MultigridSolvesToItsToleranceAndAgreesWithTheFactorization) {
  SolverOptions options;
  options.backend = Backend::PetscMultigrid;
  options.multigrid_rtol = 1e-10;
  auto gamg = make_solver(1600, options, &lane());
  EXPECT_STREQ(gamg->name(), "petsc/cg-gamg");
  EXPECT_THROW((void)make_solver(10, options, nullptr), Error);  // no lane
  SparseMatrix A = poisson(40, 0.2);
  std::vector<double> x(static_cast<std::size_t>(A.size()));
  EXPECT_THROW(gamg->factorize(A), Error);  // before analyze
  gamg->analyze(A);
  EXPECT_THROW(gamg->solve(rhs(A.size(), 0), x), Error);  // before factorize
  auto eigen = make(Backend::Eigen);
  eigen->analyze(A);
  for (double shift : {0.2, 5.0}) {  // two levels: new values, same pattern
    for (LO i = 0; i < A.size(); ++i)
      A.values()[static_cast<std::size_t>(A.find(i, i))] = 4.0 + shift;
    gamg->factorize(A);
    eigen->factorize(A);
    for (int k = 0; k < 2; ++k) {
      const auto b = rhs(A.size(), k);
      std::vector<double> xe(b.size());
      gamg->solve(b, x);
      eigen->solve(b, xe);
      EXPECT_LT(relative_residual(A, x, b), 1e-9) << "shift " << shift;
      double diff = 0, size = 0;
      for (std::size_t i = 0; i < x.size(); ++i) {
        diff = std::max(diff, std::abs(x[i] - xe[i]));
        size = std::max(size, std::abs(xe[i]));
      }
      EXPECT_LT(diff, 1e-8 * size) << "shift " << shift;
    }
  }
  // CG cannot converge on an indefinite matrix: an error, not a wrong answer.
  const SparseMatrix indefinite = poisson(40, -1.0);
  EXPECT_THROW(
      {
        gamg->factorize(indefinite);
        gamg->solve(rhs(indefinite.size(), 1), x);
      },
      Error);
}

// The real form of a magnetic Laplacian on an m x m grid (a discrete connection turning by
// `twist` radians per edge, as the cross field's Crouzeix-Raviart systems do) plus shift * I:
// complex Hermitian positive definite, unknowns (2i, 2i+1) = (Re z_i, Im z_i).
SparseMatrix magnetic_laplacian(LO m, double shift, double twist) {
  std::vector<SparseMatrix::Triplet> t;
  const auto id = [m](LO i, LO j) { return i * m + j; };
  // Complex entry a + ic at (r, s) in real form: [[a, -c], [c, a]].
  const auto add = [&t](LO r, LO s, double a, double c) {
    t.push_back({2 * r, 2 * s, a});
    t.push_back({2 * r, 2 * s + 1, -c});
    t.push_back({2 * r + 1, 2 * s, c});
    t.push_back({2 * r + 1, 2 * s + 1, a});
  };
  for (LO i = 0; i < m; ++i)
    for (LO j = 0; j < m; ++j) {
      const LO r = id(i, j);
      add(r, r, 4.0 + shift, 0.0);
      // Hermitian: the entry (s, r) is the conjugate of (r, s).
      const auto link = [&](LO s, double angle) {
        add(r, s, -std::cos(angle), -std::sin(angle));
        add(s, r, -std::cos(angle), std::sin(angle));
      };
      if (i + 1 < m) link(id(i + 1, j), twist * (1 + i + 2 * j));
      if (j + 1 < m) link(id(i, j + 1), -twist * (3 + j));
    }
  return SparseMatrix(2 * m * m, t);
}

TEST(Solvers, ComplexPairsAgreeWithTheRealForm) {
  const SparseMatrix A = magnetic_laplacian(25, 0.05, 0.3);
  const auto b = rhs(A.size(), 2);
  SolverOptions options;
  options.backend = Backend::Eigen;
  auto real = make_solver(A.size(), options, nullptr);
  options.complex_pairs = true;
  auto complex = make_solver(A.size(), options, nullptr);
  EXPECT_STREQ(complex->name(), "eigen/simplicial-ldlt-complex");
  // PETSc ignores the flag and solves the real form.
  options.backend = Backend::Petsc;
  auto petsc = make_solver(A.size(), options, &lane());
  std::vector<double> xr(b.size()), xc(b.size()), xp(b.size());
  for (auto* s : {real.get(), complex.get(), petsc.get()}) {
    s->analyze(A);
    s->factorize(A);
  }
  real->solve(b, xr);
  complex->solve(b, xc);
  petsc->solve(b, xp);
  EXPECT_LT(relative_residual(A, xc, b), 1e-12);
  std::vector<double> diff(b.size());
  for (std::size_t i = 0; i < b.size(); ++i) diff[i] = xc[i] - xr[i];
  EXPECT_LT(norm(diff) / norm(xr), 1e-12);
  for (std::size_t i = 0; i < b.size(); ++i) diff[i] = xp[i] - xr[i];
  EXPECT_LT(norm(diff) / norm(xr), 1e-12);
  // A second factorization with other values on the same pattern (the diffusion levels).
  SparseMatrix B = A;
  for (LO r = 0; r < B.size(); ++r) B.values()[static_cast<std::size_t>(B.find(r, r))] += 1.0;
  complex->factorize(B);
  complex->solve(b, xc);
  EXPECT_LT(relative_residual(B, xc, b), 1e-12);
}

// The complex solver runs Eigen's SimplicialLDLT<Lower, AMDOrdering> with the ordering and the
// permuted triangle computed once by analyze (AMD on the real form's pattern): its solutions are
// bit for bit those of Eigen's own solver on the complex matrix, at every factorization. This file
// is compiled with the library's complex-arithmetic rules (tests/linalg/CMakeLists.txt).
TEST(Solvers, ComplexPairsAreBitForBitEigensOwnFactorization) {
  using Complex = std::complex<double>;
  using ComplexMatrix = Eigen::SparseMatrix<Complex, Eigen::ColMajor, int>;
  const LO m = 23;
  SparseMatrix A = magnetic_laplacian(m, 0.05, 0.3);
  const auto b = rhs(A.size(), 3);
  SolverOptions options;
  options.backend = Backend::Eigen;
  options.complex_pairs = true;
  auto solver = make_solver(A.size(), options, nullptr);
  solver->analyze(A);
  for (int round = 0; round < 2; ++round) {
    // The complex lower triangle: entry (I, J) = A(2I, 2J) + i A(2I + 1, 2J).
    std::vector<Eigen::Triplet<Complex, int>> trip;
    for (LO I = 0; I < A.size() / 2; ++I)
      for (LO J = 0; J <= I; ++J)
        if (const auto k = A.find(2 * I, 2 * J); k >= 0)
          trip.emplace_back(
              I, J,
              Complex(A.values()[static_cast<std::size_t>(k)],
                      A.values()[static_cast<std::size_t>(A.find(2 * I + 1, 2 * J))]));
    ComplexMatrix lower(A.size() / 2, A.size() / 2);
    lower.setFromTriplets(trip.begin(), trip.end());
    Eigen::SimplicialLDLT<ComplexMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> reference(lower);
    ASSERT_EQ(reference.info(), Eigen::Success);
    Eigen::VectorXcd z(A.size() / 2);
    for (Eigen::Index i = 0; i < z.size(); ++i)
      z[i] = Complex(b[static_cast<std::size_t>(2 * i)], b[static_cast<std::size_t>(2 * i + 1)]);
    const Eigen::VectorXcd expected = reference.solve(z);
    solver->factorize(A);
    std::vector<double> x(b.size());
    solver->solve(b, x);
    for (Eigen::Index i = 0; i < z.size(); ++i) {
      EXPECT_EQ(x[static_cast<std::size_t>(2 * i)], expected[i].real()) << i;
      EXPECT_EQ(x[static_cast<std::size_t>(2 * i + 1)], expected[i].imag()) << i;
    }
    // Other values on the same pattern, as the diffusion levels have.
    for (LO r = 0; r < A.size(); ++r) A.values()[static_cast<std::size_t>(A.find(r, r))] += 0.7;
  }
}

// The real solver runs Eigen's SimplicialLDLT with the ordering, the permuted triangle and the
// symbolic analysis done by analyze (the last without Eigen's ordering step, which copies the
// matrix twice): its solutions are bit for bit those of Eigen's own SimplicialLDLT<Lower,
// AMDOrdering>, at every factorization.
TEST(Solvers, RealIsBitForBitEigensOwnFactorization) {
  using EigenMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
  SparseMatrix A = poisson(17, 0.01);
  const auto b = rhs(A.size(), 2);
  SolverOptions options;
  options.backend = Backend::Eigen;
  auto solver = make_solver(A.size(), options, nullptr);
  solver->analyze(A);
  for (int round = 0; round < 2; ++round) {
    std::vector<Eigen::Triplet<double, int>> trip;
    for (LO r = 0; r < A.size(); ++r)
      for (auto k = A.row_offsets()[static_cast<std::size_t>(r)];
           k < A.row_offsets()[static_cast<std::size_t>(r) + 1]; ++k)
        if (const LO c = A.columns()[static_cast<std::size_t>(k)]; c <= r)
          trip.emplace_back(r, c, A.values()[static_cast<std::size_t>(k)]);
    EigenMatrix lower(A.size(), A.size());
    lower.setFromTriplets(trip.begin(), trip.end());
    Eigen::SimplicialLDLT<EigenMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> reference(lower);
    ASSERT_EQ(reference.info(), Eigen::Success);
    const Eigen::VectorXd expected =
        reference.solve(Eigen::Map<const Eigen::VectorXd>(b.data(), A.size()));
    solver->factorize(A);
    std::vector<double> x(b.size());
    solver->solve(b, x);
    for (LO i = 0; i < A.size(); ++i) EXPECT_EQ(x[static_cast<std::size_t>(i)], expected[i]) << i;
    for (LO r = 0; r < A.size(); ++r) A.values()[static_cast<std::size_t>(A.find(r, r))] += 0.7;
  }
}

TEST(Solvers, ComplexPairsRejectWhatIsNotAHermitianRealForm) {
  SolverOptions options;
  options.backend = Backend::Eigen;
  options.complex_pairs = true;
  EXPECT_THROW((void)make_solver(7, options, nullptr), Error);  // odd size
  // A real Laplacian read in pairs: its 2 x 2 blocks are not whole.
  auto solver = make_solver(100, options, nullptr);
  EXPECT_THROW(solver->analyze(poisson(10, 1.0)), Error);
  // Whole blocks, but one is not of the form [[a, -c], [c, a]].
  SparseMatrix A = magnetic_laplacian(6, 0.5, 0.2);
  auto broken = make_solver(A.size(), options, nullptr);
  broken->analyze(A);
  broken->factorize(A);
  A.values()[static_cast<std::size_t>(A.find(2, 3))] += 0.25;
  EXPECT_THROW(broken->factorize(A), Error);
  // Not positive definite: the solver reports it, then recovers on a good matrix.
  SparseMatrix negative = magnetic_laplacian(6, 0.5, 0.2);
  for (double& v : negative.values()) v = -v;
  EXPECT_THROW(broken->factorize(negative), Error);
  std::vector<double> x(static_cast<std::size_t>(negative.size()));
  EXPECT_THROW(broken->solve(rhs(negative.size(), 1), x), Error);
  const SparseMatrix good = magnetic_laplacian(6, 0.5, 0.2);
  broken->factorize(good);
  const auto b = rhs(good.size(), 1);
  broken->solve(b, x);
  EXPECT_LT(relative_residual(good, x, b), 1e-12);
}

TEST(Solvers, SecondLaneIsRejected) { EXPECT_THROW(SolverLane second, Error); }

TEST(Solvers, EmptySystem) {
  const SparseMatrix A(0, std::span<const SparseMatrix::Triplet>{});
  for (Backend backend : {Backend::Eigen, Backend::Petsc}) {
    auto solver = make(backend);
    solver->analyze(A);
    solver->factorize(A);
    std::vector<double> b, x;
    solver->solve(b, x);
  }
}

}  // namespace
}  // namespace qsmesh::linalg
