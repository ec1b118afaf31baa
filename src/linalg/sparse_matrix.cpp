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

SparseMatrix SparseMatrix::from_elements(LO n, int m, std::span<const LO> dofs,
                                         std::span<const double> blocks) {
  QSMESH_CHECK(n >= 0 && m > 0,
               "SparseMatrix::from_elements: size " << n << ", " << m << " unknowns an element");
  const auto mm = static_cast<std::size_t>(m);
  QSMESH_CHECK(dofs.size() % mm == 0 && blocks.size() == dofs.size() * mm,
               "SparseMatrix::from_elements: " << dofs.size() << " unknowns and " << blocks.size()
                                               << " values for elements of " << m);
  // Each row's incidences in element order, a counting sort of the element unknowns (a sixth of
  // the triplets of a CR triangle): where the element's unknowns start (k m) and the row's place
  // among them (a).
  std::vector<std::int64_t> start(static_cast<std::size_t>(n) + 1, 0);
  for (const LO d : dofs) {
    if (d == kNoIndex) continue;
    QSMESH_CHECK(d >= 0 && d < n, "SparseMatrix::from_elements: unknown "
                                      << d << " outside a " << n << " x " << n << " matrix");
    ++start[static_cast<std::size_t>(d) + 1];
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::int64_t> element(static_cast<std::size_t>(start.back()));
  std::vector<int> local(element.size());
  {
    std::vector<std::int64_t> next(start.begin(), start.end() - 1);
    for (std::size_t base = 0; base < dofs.size(); base += mm)
      for (std::size_t a = 0; a < mm; ++a)
        if (const LO d = dofs[base + a]; d != kNoIndex) {
          const auto p = static_cast<std::size_t>(next[static_cast<std::size_t>(d)]++);
          element[p] = static_cast<std::int64_t>(base);
          local[p] = static_cast<int>(a);
        }
  }
  SparseMatrix A;
  A.n_ = n;
  A.offsets_.assign(static_cast<std::size_t>(n) + 1, 0);
  A.cols_.reserve(static_cast<std::size_t>(start.back()) * mm / 2);
  A.values_.reserve(A.cols_.capacity());
  // slot[c]: where column c sits in the values of the current row, -1 off the row.
  std::vector<std::int64_t> slot(static_cast<std::size_t>(n), -1);
  std::size_t previous_begin = 0, previous_first = 0, previous_last = 0;
  for (LO r = 0; r < n; ++r) {
    const auto first = static_cast<std::size_t>(start[static_cast<std::size_t>(r)]);
    const auto last = static_cast<std::size_t>(start[static_cast<std::size_t>(r) + 1]);
    const std::size_t row_begin = A.cols_.size();
    // A row in the same elements as the row before (the unknowns of one node) has its columns.
    if (r > 0 && last - first == previous_last - previous_first &&
        std::equal(element.begin() + static_cast<std::ptrdiff_t>(first),
                   element.begin() + static_cast<std::ptrdiff_t>(last),
                   element.begin() + static_cast<std::ptrdiff_t>(previous_first))) {
      for (std::size_t k = previous_begin; k < row_begin; ++k) {
        const LO c = A.cols_[k];  // a copy: push_back may reallocate
        A.cols_.push_back(c);
      }
    } else {
      for (std::size_t p = first; p < last; ++p) {
        const auto base = static_cast<std::size_t>(element[p]);
        for (std::size_t b = 0; b < mm; ++b)
          if (const LO c = dofs[base + b]; c != kNoIndex && slot[static_cast<std::size_t>(c)] < 0) {
            slot[static_cast<std::size_t>(c)] = 0;
            A.cols_.push_back(c);
          }
      }
      // A row holds a few columns (about 10 for a CR triangle mesh): an insertion sort.
      for (std::size_t k = row_begin + 1; k < A.cols_.size(); ++k) {
        const LO c = A.cols_[k];
        std::size_t j = k;
        for (; j > row_begin && A.cols_[j - 1] > c; --j) A.cols_[j] = A.cols_[j - 1];
        A.cols_[j] = c;
      }
    }
    for (std::size_t k = row_begin; k < A.cols_.size(); ++k)
      slot[static_cast<std::size_t>(A.cols_[k])] = static_cast<std::int64_t>(k);
    A.values_.resize(A.cols_.size(), 0.0);
    for (std::size_t p = first; p < last; ++p) {
      const auto base = static_cast<std::size_t>(element[p]);
      const double* row = blocks.data() + (base + static_cast<std::size_t>(local[p])) * mm;
      for (std::size_t b = 0; b < mm; ++b)
        if (const LO c = dofs[base + b]; c != kNoIndex)
          A.values_[static_cast<std::size_t>(slot[static_cast<std::size_t>(c)])] += row[b];
    }
    for (std::size_t k = row_begin; k < A.cols_.size(); ++k)
      slot[static_cast<std::size_t>(A.cols_[k])] = -1;
    A.offsets_[static_cast<std::size_t>(r) + 1] = static_cast<std::int64_t>(A.cols_.size());
    previous_begin = row_begin, previous_first = first, previous_last = last;
  }
  return A;
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
