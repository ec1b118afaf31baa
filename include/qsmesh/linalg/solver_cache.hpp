// Analysed sparse direct solvers kept for sparsity patterns that come again.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "qsmesh/linalg/solver.hpp"

namespace qsmesh::linalg {

/// Keeps the symbolic analysis (ordering, elimination tree) of the small Eigen systems whose
/// sparsity pattern repeats: the Laplace layouts of cavity candidates and pattern fills are made
/// of the same refined patterns again and again, and for those small systems AMD and the symbolic
/// analysis cost more than the numeric factorization (docs/benchmarks.md, issue 27). The analysis
/// depends on the pattern alone, so a cached solver gives bit for bit the solutions of a fresh
/// one. A kept solver is not factorized again for the very values (bytes) it was last factorized
/// with: smooth_face's uv Laplacian has unit weights, so there the same pattern is the same matrix.
///
/// One object per thread of work: not thread-safe, and the solver it returns is valid until the
/// next call. Never share one between tasks that may run on different threads.
class SolverCache {
 public:
  /// Holds patterns of at most `max_nonzeros` nonzeros in all; the least recently used go first.
  /// Larger systems are solved by a fresh solver, not kept.
  explicit SolverCache(std::int64_t max_nonzeros = 250000);
  ~SolverCache();
  SolverCache(const SolverCache&) = delete;
  SolverCache& operator=(const SolverCache&) = delete;

  /// An Eigen solver analysed for A's pattern and factorized with A's values (throws as
  /// LinearSolver::factorize does). Valid until the next call on this cache.
  LinearSolver& factorized(const SparseMatrix& A);

  [[nodiscard]] std::int64_t hits() const { return hits_; }
  [[nodiscard]] std::int64_t misses() const { return misses_; }
  /// Numeric factorizations done (a hit with the values of its last one does none).
  [[nodiscard]] std::int64_t factorizations() const { return factorizations_; }

 private:
  struct Entry;
  std::int64_t max_nonzeros_;
  std::int64_t held_ = 0;  // nonzeros of the patterns held
  std::int64_t clock_ = 0;
  std::int64_t hits_ = 0, misses_ = 0, factorizations_ = 0;
  std::vector<std::unique_ptr<Entry>> entries_;
  std::unique_ptr<LinearSolver> uncached_;
};

/// `cache` may be null: then a fresh Eigen solver, analysed and factorized. Otherwise
/// cache->factorized(A).
[[nodiscard]] LinearSolver& factorized_eigen(const SparseMatrix& A, SolverCache* cache,
                                             std::unique_ptr<LinearSolver>& owner);

}  // namespace qsmesh::linalg
