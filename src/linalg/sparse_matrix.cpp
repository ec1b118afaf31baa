#include <algorithm>
#include <numeric>

#include "qsmesh/core/error.hpp"
#include "qsmesh/linalg/solver.hpp"

namespace qsmesh::linalg {

SparseMatrix::SparseMatrix(LO n, std::span<const Triplet> triplets) : n_(n) {
  QSMESH_CHECK(n >= 0, "SparseMatrix: negative size " << n);
  // Bucket the triplets by row (counting sort), keeping their input order within a row so that
  // duplicates are summed in a fixed order whatever the caller's threading.
  std::vector<std::int64_t> row_count(static_cast<std::size_t>(n) + 1, 0);
  for (const Triplet& t : triplets) {
    QSMESH_CHECK(t.row >= 0 && t.row < n && t.col >= 0 && t.col < n,
                 "SparseMatrix: entry (" << t.row << ", " << t.col << ") outside a " << n << " x "
                                         << n << " matrix");
    ++row_count[static_cast<std::size_t>(t.row) + 1];
  }
  std::partial_sum(row_count.begin(), row_count.end(), row_count.begin());
  // The entries themselves, not their indices, are bucketed: sorting and summing a row then reads
  // contiguous memory instead of gathering the triplets again (the per-face systems hold tens of
  // thousands of rows).
  struct Entry {
    LO col;
    double value;
  };
  std::vector<Entry> bucket(triplets.size());
  {
    std::vector<std::int64_t> next(row_count.begin(), row_count.end() - 1);
    for (const Triplet& t : triplets)
      bucket[static_cast<std::size_t>(next[static_cast<std::size_t>(t.row)]++)] = {t.col, t.value};
  }

  offsets_.assign(static_cast<std::size_t>(n) + 1, 0);
  cols_.clear();
  values_.clear();
  cols_.reserve(triplets.size());
  values_.reserve(triplets.size());
  for (LO r = 0; r < n; ++r) {
    const auto begin = bucket.begin() + row_count[static_cast<std::size_t>(r)];
    const auto end = bucket.begin() + row_count[static_cast<std::size_t>(r) + 1];
    // Rows hold a few entries (the Laplacians of the per-face systems: about 5-10): a stable
    // insertion sort, without std::stable_sort's buffer allocation. Same order.
    for (auto it = begin + (begin == end ? 0 : 1); it < end; ++it) {
      const Entry x = *it;
      auto j = it;
      for (; j != begin && (j - 1)->col > x.col; --j) *j = *(j - 1);
      *j = x;
    }
    for (auto it = begin; it != end; ++it) {
      const auto row_start = offsets_[static_cast<std::size_t>(r)];
      if (static_cast<std::int64_t>(cols_.size()) > row_start && cols_.back() == it->col) {
        values_.back() += it->value;
      } else {
        cols_.push_back(it->col);
        values_.push_back(it->value);
      }
    }
    offsets_[static_cast<std::size_t>(r) + 1] = static_cast<std::int64_t>(cols_.size());
  }
  cols_.shrink_to_fit();
  values_.shrink_to_fit();
}

std::int64_t SparseMatrix::find(LO row, LO col) const {
  if (row < 0 || row >= n_ || col < 0 || col >= n_) return -1;
  const auto first = cols_.begin() + offsets_[static_cast<std::size_t>(row)];
  const auto last = cols_.begin() + offsets_[static_cast<std::size_t>(row) + 1];
  const auto it = std::lower_bound(first, last, col);
  return (it != last && *it == col) ? static_cast<std::int64_t>(it - cols_.begin()) : -1;
}

void SparseMatrix::multiply(std::span<const double> x, std::span<double> y) const {
  QSMESH_CHECK(x.size() == static_cast<std::size_t>(n_) && y.size() == static_cast<std::size_t>(n_),
               "SparseMatrix::multiply: vectors of " << x.size() << " and " << y.size()
                                                     << " entries for a matrix of size " << n_);
  QSMESH_CHECK(x.data() != y.data() || n_ == 0, "SparseMatrix::multiply: x and y must not alias");
  for (LO r = 0; r < n_; ++r) {
    double sum = 0;
    for (auto k = offsets_[static_cast<std::size_t>(r)];
         k < offsets_[static_cast<std::size_t>(r) + 1]; ++k)
      sum += values_[static_cast<std::size_t>(k)] *
             x[static_cast<std::size_t>(cols_[static_cast<std::size_t>(k)])];
    y[static_cast<std::size_t>(r)] = sum;
  }
}

}  // namespace qsmesh::linalg
