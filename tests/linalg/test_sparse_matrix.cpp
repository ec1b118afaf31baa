#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
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

// Elements of a triangle mesh of a strip, 2 unknowns a node (a block pattern, as the cross field's
// pairs), values of every magnitude and some unknowns fixed: the element assembly gives the
// triplets' matrix entry for entry, bit for bit, since each entry sums in element order.
TEST(SparseMatrix, ElementsGiveTheTripletsMatrixBitForBit) {
  constexpr int kAcross = 7, kAlong = 40, kM = 6;
  const auto node = [](int i, int j) { return j * kAcross + i; };
  std::mt19937 random(7);
  std::uniform_real_distribution<double> mantissa(-1, 1);
  std::uniform_int_distribution<int> exponent(-30, 30);
  std::vector<LO> unknown(static_cast<std::size_t>(kAcross) * kAlong);
  LO n = 0;
  for (std::size_t v = 0; v < unknown.size(); ++v) {
    unknown[v] = v % 11 == 3 ? kNoIndex : n;  // a fixed node now and then
    if (unknown[v] != kNoIndex) n += 2;
  }
  std::vector<LO> dofs;
  std::vector<double> blocks;
  std::vector<T> triplets;
  for (int j = 0; j + 1 < kAlong; ++j)
    for (int i = 0; i + 1 < kAcross; ++i)
      for (const auto& tri : {std::array<int, 3>{node(i, j), node(i + 1, j), node(i + 1, j + 1)},
                              std::array<int, 3>{node(i, j), node(i + 1, j + 1), node(i, j + 1)}}) {
        const std::size_t first = dofs.size();
        for (const int v : tri) {
          const LO u = unknown[static_cast<std::size_t>(v)];
          dofs.push_back(u);
          dofs.push_back(u == kNoIndex ? kNoIndex : u + 1);
        }
        for (int a = 0; a < kM; ++a)
          for (int b = 0; b < kM; ++b) {
            const double value = std::ldexp(mantissa(random), exponent(random));
            blocks.push_back(value);
            const LO r = dofs[first + a], c = dofs[first + b];
            if (r != kNoIndex && c != kNoIndex) triplets.push_back({r, c, value});
          }
      }
  const SparseMatrix expected(n, triplets);
  const SparseMatrix A = SparseMatrix::from_elements(n, kM, dofs, blocks);
  EXPECT_EQ(A.size(), n);
  EXPECT_EQ(A.row_offsets(), expected.row_offsets());
  EXPECT_EQ(A.columns(), expected.columns());
  ASSERT_EQ(A.values().size(), expected.values().size());
  for (std::size_t k = 0; k < A.values().size(); ++k)
    EXPECT_EQ(A.values()[k], expected.values()[k]) << k;  // exact: the same sums, same order

  EXPECT_THROW(static_cast<void>(SparseMatrix::from_elements(2, 2, std::vector<LO>{0, 2},
                                                             std::vector<double>(4, 1.0))),
               Error);
  EXPECT_THROW(static_cast<void>(SparseMatrix::from_elements(2, 2, std::vector<LO>{0, 1},
                                                             std::vector<double>(3, 1.0))),
               Error);
}

}  // namespace
}  // namespace qsmesh::linalg
