#include <gtest/gtest.h>

#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/linalg/solver.hpp"

namespace qsmesh::linalg {
namespace {

using T = SparseMatrix::Triplet;

TEST(SparseMatrix, SumsDuplicatesAndSortsColumns) {
  const std::vector<T> t{{0, 2, 1.0},  {0, 0, 2.0}, {1, 1, 3.0}, {0, 2, 0.5},
                         {2, 0, -1.0}, {1, 1, 1.0}, {2, 2, 4.0}};
  const SparseMatrix A(3, t);
  EXPECT_EQ(A.size(), 3);
  EXPECT_EQ(A.nonzeros(), 5);
  EXPECT_EQ(A.row_offsets(), (std::vector<std::int64_t>{0, 2, 3, 5}));
  EXPECT_EQ(A.columns(), (std::vector<LO>{0, 2, 1, 0, 2}));
  EXPECT_EQ(A.values(), (std::vector<double>{2.0, 1.5, 4.0, -1.0, 4.0}));
}

TEST(SparseMatrix, FindsEntries) {
  const std::vector<T> t{{0, 1, 1.0}, {1, 0, 2.0}, {1, 2, 3.0}, {2, 2, 4.0}};
  const SparseMatrix A(3, t);
  ASSERT_GE(A.find(1, 2), 0);
  EXPECT_EQ(A.values()[static_cast<std::size_t>(A.find(1, 2))], 3.0);
  EXPECT_EQ(A.values()[static_cast<std::size_t>(A.find(0, 1))], 1.0);
  EXPECT_EQ(A.find(0, 0), -1);
  EXPECT_EQ(A.find(2, 1), -1);
  EXPECT_EQ(A.find(3, 0), -1);
  EXPECT_EQ(A.find(-1, 0), -1);
}

TEST(SparseMatrix, Multiplies) {
  // [2 -1 0; -1 2 -1; 0 -1 2] * [1 2 3] = [0 0 4]
  std::vector<T> t;
  for (LO i = 0; i < 3; ++i) {
    t.push_back({i, i, 2.0});
    if (i > 0) t.push_back({i, i - 1, -1.0});
    if (i < 2) t.push_back({i, i + 1, -1.0});
  }
  const SparseMatrix A(3, t);
  const std::vector<double> x{1, 2, 3};
  std::vector<double> y(3, 99.0);
  A.multiply(x, y);
  EXPECT_EQ(y, (std::vector<double>{0, 0, 4}));
  std::vector<double> short_y(2);
  EXPECT_THROW(A.multiply(x, short_y), Error);
}

TEST(SparseMatrix, EmptyRowsAndEmptyMatrix) {
  const std::vector<T> t{{2, 0, 1.0}};
  const SparseMatrix A(4, t);
  EXPECT_EQ(A.row_offsets(), (std::vector<std::int64_t>{0, 0, 0, 1, 1}));
  const SparseMatrix E(0, std::span<const T>{});
  EXPECT_EQ(E.size(), 0);
  EXPECT_EQ(E.nonzeros(), 0);
  const SparseMatrix D;
  EXPECT_EQ(D.row_offsets(), (std::vector<std::int64_t>{0}));
}

TEST(SparseMatrix, RejectsEntriesOutsideTheMatrix) {
  const std::vector<T> t{{0, 3, 1.0}};
  EXPECT_THROW(SparseMatrix(3, t), Error);
  const std::vector<T> neg{{-1, 0, 1.0}};
  EXPECT_THROW(SparseMatrix(3, neg), Error);
}

}  // namespace
}  // namespace qsmesh::linalg
