#include <gtest/gtest.h>

#include "qsmesh/core/adjacency.hpp"

namespace qsmesh {
namespace {

TEST(Adjacency, FromPairsAndTranspose) {
  const Adjacency a2b = Adjacency::from_pairs(3, {{2, 0}, {0, 1}, {0, 3}, {2, 1}});
  ASSERT_EQ(a2b.size(), 3);
  EXPECT_EQ(std::vector<LO>(a2b[0].begin(), a2b[0].end()), (std::vector<LO>{1, 3}));
  EXPECT_TRUE(a2b[1].empty());
  EXPECT_EQ(std::vector<LO>(a2b[2].begin(), a2b[2].end()), (std::vector<LO>{0, 1}));
  const Adjacency b2a = a2b.transpose(4);
  ASSERT_EQ(b2a.size(), 4);
  EXPECT_EQ(std::vector<LO>(b2a[1].begin(), b2a[1].end()), (std::vector<LO>{0, 2}));
  EXPECT_EQ(std::vector<LO>(b2a[3].begin(), b2a[3].end()), (std::vector<LO>{0}));
  EXPECT_TRUE(b2a[2].empty());
}

}  // namespace
}  // namespace qsmesh
