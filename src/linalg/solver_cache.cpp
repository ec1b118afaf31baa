#include "qsmesh/linalg/solver_cache.hpp"

#include <algorithm>
#include <cstring>

#include "backends.hpp"

namespace qsmesh::linalg {

namespace {

std::uint64_t pattern_hash(const SparseMatrix& A) {
  std::uint64_t h = 1469598103934665603ULL ^ static_cast<std::uint64_t>(A.size());
  const auto mix = [&h](std::uint64_t x) { h ^= x + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2); };
  for (const std::int64_t o : A.row_offsets()) mix(static_cast<std::uint64_t>(o));
  for (const LO c : A.columns()) mix(static_cast<std::uint64_t>(c));
  return h;
}

}  // namespace

struct SolverCache::Entry {
  std::uint64_t hash = 0;
  std::int64_t used = 0;  // clock_ at the last use
  LO n = 0;
  std::vector<std::int64_t> offsets;
  std::vector<LO> cols;
  std::unique_ptr<LinearSolver> solver;
  std::vector<double> values;  // of the last factorization; empty when it failed
  [[nodiscard]] bool same_values(const SparseMatrix& A) const {
    // Bytes, not ==: 0.0 and -0.0 must not count as the same (they may round differently).
    return !values.empty() && values.size() == A.values().size() &&
           std::memcmp(values.data(), A.values().data(), values.size() * sizeof(double)) == 0;
  }
  // Factorizes with A's values unless the last factorization had the very same ones (smooth_face's
  // uv Laplacian has unit weights: the same pattern is the same matrix).
  // Returns whether it factorized.
  bool factorize(const SparseMatrix& A) {
    if (same_values(A)) return false;
    values.clear();
    solver->factorize(A);  // throws: values stay empty
    values = A.values();
    return true;
  }
  [[nodiscard]] bool same_pattern(const SparseMatrix& A) const {
    return A.size() == n && A.row_offsets() == offsets && A.columns() == cols;
  }
};

SolverCache::SolverCache(std::int64_t max_nonzeros) : max_nonzeros_(max_nonzeros) {}
SolverCache::~SolverCache() = default;

LinearSolver& SolverCache::factorized(const SparseMatrix& A) {
  const std::int64_t nnz = A.nonzeros();
  if (nnz > max_nonzeros_) {
    ++misses_;
    uncached_ = detail::make_eigen_solver();
    uncached_->analyze(A);
    uncached_->factorize(A);
    ++factorizations_;
    return *uncached_;
  }
  const std::uint64_t h = pattern_hash(A);
  ++clock_;
  for (auto& e : entries_)
    if (e->hash == h && e->same_pattern(A)) {
      ++hits_;
      e->used = clock_;
      if (e->factorize(A)) ++factorizations_;
      return *e->solver;
    }
  ++misses_;
  while (!entries_.empty() && held_ + nnz > max_nonzeros_) {
    const auto oldest =
        std::min_element(entries_.begin(), entries_.end(),
                         [](const std::unique_ptr<Entry>& a, const std::unique_ptr<Entry>& b) {
                           return a->used < b->used;
                         });
    held_ -= static_cast<std::int64_t>((*oldest)->cols.size());
    entries_.erase(oldest);
  }
  auto e = std::make_unique<Entry>();
  e->hash = h;
  e->used = clock_;
  e->n = A.size();
  e->offsets = A.row_offsets();
  e->cols = A.columns();
  e->solver = detail::make_eigen_solver();
  e->solver->analyze(A);  // throws before the entry is kept
  held_ += nnz;
  entries_.push_back(std::move(e));
  Entry& kept = *entries_.back();
  kept.factorize(A);
  ++factorizations_;
  return *kept.solver;
}

LinearSolver& factorized_eigen(const SparseMatrix& A, SolverCache* cache,
                               std::unique_ptr<LinearSolver>& owner) {
  if (cache != nullptr) return cache->factorized(A);
  owner = make_solver(A.size(), SolverOptions{Backend::Eigen}, nullptr);
  owner->analyze(A);
  owner->factorize(A);
  return *owner;
}

}  // namespace qsmesh::linalg
