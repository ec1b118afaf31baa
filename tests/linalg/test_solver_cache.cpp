#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/linalg/solver_cache.hpp"

namespace qsmesh::linalg {
namespace {

// A graph Laplacian plus a diagonal shift on an irregular pattern (a grid with some diagonals
// and a few long-range links, so AMD has real choices to make); the pattern depends on m alone,
// the values on `seed` too.
SparseMatrix irregular_spd(LO m, int seed) {
  std::vector<SparseMatrix::Triplet> t;
  const LO n = m * m;
  std::vector<double> diag(static_cast<std::size_t>(n), 0.5);
  const auto link = [&](LO a, LO b, double w) {
    t.push_back({a, b, -w});
    t.push_back({b, a, -w});
    diag[static_cast<std::size_t>(a)] += w;
    diag[static_cast<std::size_t>(b)] += w;
  };
  for (LO i = 0; i < m; ++i)
    for (LO j = 0; j < m; ++j) {
      const LO r = i * m + j;
      const double w = 1.0 + 0.1 * ((r * 7 + seed * 13) % 11);
      if (j + 1 < m) link(r, r + 1, w);
      if (i + 1 < m) link(r, r + m, 1.0 / w);
      if (i + 1 < m && j + 1 < m && (r + m) % 3 == 0) link(r, r + m + 1, 0.3 * w);
      if (r % 17 == 5 && r + 3 * m + 2 < n) link(r, r + 3 * m + 2, 0.2);
    }
  for (LO r = 0; r < n; ++r) t.push_back({r, r, diag[static_cast<std::size_t>(r)]});
  return SparseMatrix(n, t);
}

std::vector<double> rhs(LO n, int seed) {
  std::vector<double> b(static_cast<std::size_t>(n));
  for (LO i = 0; i < n; ++i)
    b[static_cast<std::size_t>(i)] = std::sin(0.37 * i + seed) + 0.1 * seed;
  return b;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

std::vector<double> fresh_solution(const SparseMatrix& A, const std::vector<double>& b) {
  auto s = make_solver(A.size(), SolverOptions{Backend::Eigen}, nullptr);
  s->analyze(A);
  s->factorize(A);
  std::vector<double> x(b.size());
  s->solve(b, x);
  return x;
}

TEST(SolverCache, SameSolutionsAsAFreshSolver) {
  // Three patterns, their values changing with each use, cycled through a cache that holds
  // two of them (12 with 13 or with 14): hits, misses and evictions of the least recently used
  // all give the fresh solver's bits.
  const std::int64_t bound = irregular_spd(12, 0).nonzeros() + irregular_spd(14, 0).nonzeros() + 10;
  SolverCache cache(bound);
  int uses = 0;
  for (int round = 0; round < 3; ++round)
    for (const LO m : {12, 13, 12, 14, 12}) {
      const SparseMatrix A = irregular_spd(m, round * 5 + m);
      const std::vector<double> b = rhs(A.size(), round + m);
      std::vector<double> x(b.size());
      cache.factorized(A).solve(b, x);
      ++uses;
      EXPECT_TRUE(same_bits(x, fresh_solution(A, b))) << "m " << m << " round " << round;
    }
  EXPECT_EQ(cache.hits() + cache.misses(), uses);
  // 12 stays held throughout (2 + 3 + 3 hits); 14 and 13 evict each other.
  EXPECT_EQ(cache.hits(), 8);
  EXPECT_EQ(cache.misses(), 7);
  // Above the bound: solved, never held.
  SolverCache tiny(10);
  const SparseMatrix A = irregular_spd(6, 1);
  const std::vector<double> b = rhs(A.size(), 2);
  std::vector<double> x(b.size());
  tiny.factorized(A).solve(b, x);
  tiny.factorized(A).solve(b, x);
  EXPECT_EQ(tiny.hits(), 0);
  EXPECT_TRUE(same_bits(x, fresh_solution(A, b)));
}

TEST(SolverCache, SameValuesAreNotFactorizedAgain) {
  SolverCache cache;
  SparseMatrix A = irregular_spd(9, 4);
  const std::vector<double> orig = A.values();
  const std::vector<double> b = rhs(A.size(), 3);
  std::vector<double> x(b.size());
  cache.factorized(A).solve(b, x);
  cache.factorized(A).solve(b, x);
  EXPECT_EQ(cache.factorizations(), 1);
  EXPECT_TRUE(same_bits(x, fresh_solution(A, b)));
  // One value changed in its last bit: factorized again, the fresh solver's solution.
  A.values()[0] = std::nextafter(A.values()[0], 2 * A.values()[0]);
  cache.factorized(A).solve(b, x);
  EXPECT_EQ(cache.factorizations(), 2);
  EXPECT_TRUE(same_bits(x, fresh_solution(A, b)));
  A.values() = orig;
  cache.factorized(A).solve(b, x);
  EXPECT_EQ(cache.factorizations(), 3);
  EXPECT_TRUE(same_bits(x, fresh_solution(A, b)));
  EXPECT_EQ(cache.hits(), 3);
}

TEST(SolverCache, FailedFactorizationThrowsAndTheCacheStaysUsable) {
  SolverCache cache;
  SparseMatrix A = irregular_spd(5, 3);
  const std::vector<double> orig = A.values();
  for (double& v : A.values()) v = -v;
  EXPECT_THROW((void)cache.factorized(A), Error);
  A.values() = orig;
  const std::vector<double> b = rhs(A.size(), 1);
  std::vector<double> x(b.size());
  cache.factorized(A).solve(b, x);
  EXPECT_EQ(cache.hits(), 1);
  EXPECT_TRUE(same_bits(x, fresh_solution(A, b)));
}

// The Eigen backend orders and twists the matrix itself; its solutions must be bit for bit those
// of Eigen's SimplicialLDLT<Lower, AMDOrdering> on the same matrix, which it replaced (meshes
// byte-identical). Both with a symmetric pattern and with an explicit entry in one triangle only.
std::vector<double> simplicial_solution(const SparseMatrix& A, const std::vector<double>& b) {
  const LO n = A.size();
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> m(n, n);
  m.resizeNonZeros(static_cast<Eigen::Index>(A.nonzeros()));
  for (LO i = 0; i <= n; ++i)
    m.outerIndexPtr()[i] = static_cast<int>(A.row_offsets()[static_cast<std::size_t>(i)]);
  std::copy(A.columns().begin(), A.columns().end(), m.innerIndexPtr());
  std::copy(A.values().begin(), A.values().end(), m.valuePtr());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double, Eigen::ColMajor, int>, Eigen::Lower,
                        Eigen::AMDOrdering<int>>
      ldlt;
  ldlt.analyzePattern(m);
  ldlt.factorize(m);
  std::vector<double> x(b.size());
  Eigen::Map<Eigen::VectorXd>(x.data(), n) =
      ldlt.solve(Eigen::Map<const Eigen::VectorXd>(b.data(), n));
  return x;
}

TEST(SolverCache, EigenBackendGivesSimplicialLdltBits) {
  for (const LO m : {1, 3, 9, 20}) {
    const SparseMatrix A = irregular_spd(m, m);
    const std::vector<double> b = rhs(A.size(), m);
    EXPECT_TRUE(same_bits(fresh_solution(A, b), simplicial_solution(A, b))) << m;
  }
  // An explicit zero in the upper triangle only: the pattern is not symmetric.
  SparseMatrix S = irregular_spd(7, 2);
  std::vector<SparseMatrix::Triplet> t;
  for (LO r = 0; r < S.size(); ++r)
    for (auto k = S.row_offsets()[static_cast<std::size_t>(r)];
         k < S.row_offsets()[static_cast<std::size_t>(r) + 1]; ++k)
      t.push_back(
          {r, S.columns()[static_cast<std::size_t>(k)], S.values()[static_cast<std::size_t>(k)]});
  t.push_back({0, S.size() - 1, 0.0});
  const SparseMatrix U(S.size(), t);
  const std::vector<double> b = rhs(U.size(), 4);
  EXPECT_TRUE(same_bits(fresh_solution(U, b), simplicial_solution(U, b)));
}

}  // namespace
}  // namespace qsmesh::linalg
