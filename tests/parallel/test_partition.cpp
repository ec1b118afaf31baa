#include <gtest/gtest.h>

#include <numeric>

#include "qsmesh/parallel/partition.hpp"

namespace qsmesh::parallel {
namespace {

/// A grid graph of nx x ny faces, each adjacent to its 4 neighbours.
Adjacency grid(LO nx, LO ny) {
  std::vector<std::pair<LO, LO>> pairs;
  for (LO j = 0; j < ny; ++j)
    for (LO i = 0; i < nx; ++i) {
      const LO f = j * nx + i;
      if (i > 0) pairs.emplace_back(f, f - 1);
      if (i + 1 < nx) pairs.emplace_back(f, f + 1);
      if (j > 0) pairs.emplace_back(f, f - nx);
      if (j + 1 < ny) pairs.emplace_back(f, f + nx);
    }
  return Adjacency::from_pairs(nx * ny, std::move(pairs));
}

TEST(Partition, OnePartTakesEverything) {
  const auto g = grid(4, 4);
  const std::vector<double> w(16, 1.0);
  const auto p = partition_faces(g, w, 1);
  for (int x : p) EXPECT_EQ(x, 0);
}

TEST(Partition, BalancedAndDeterministic) {
  const auto g = grid(20, 10);
  std::vector<double> w(200);
  for (LO i = 0; i < 200; ++i) w[i] = 1.0 + (i % 7);  // uneven costs
  const double total = std::accumulate(w.begin(), w.end(), 0.0);
  for (int parts : {2, 3, 4}) {
    const auto p = partition_faces(g, w, parts);
    EXPECT_EQ(p, partition_faces(g, w, parts)) << "METIS must be deterministic";
    std::vector<double> load(static_cast<std::size_t>(parts), 0.0);
    for (LO i = 0; i < 200; ++i) {
      ASSERT_GE(p[i], 0);
      ASSERT_LT(p[i], parts);
      load[p[i]] += w[i];
    }
    for (double l : load) EXPECT_LT(l, 1.1 * total / parts) << parts << " parts";
  }
}

TEST(Partition, MorePartsThanFaces) {
  const auto g = grid(2, 1);
  const std::vector<double> w(2, 1.0);
  const auto p = partition_faces(g, w, 4);
  EXPECT_EQ(p, (std::vector<int>{0, 1}));
}

// The greedy longest-first rule, worked by hand: the largest weight first, each to the rank with
// the least so far, ties to the lower index and the lower rank.
TEST(Partition, DealByWeightIsGreedyLongestFirst) {
  const std::vector<double> w{1, 5, 3, 3, 2};
  // 5 -> 0 (5); 3 (item 2) -> 1 (3); 3 (item 3) -> 1 (6); 2 -> 0 (7); 1 -> 1 (7).
  EXPECT_EQ(deal_by_weight(w, 2), (std::vector<int>{1, 0, 1, 1, 0}));
  EXPECT_EQ(deal_by_weight(w, 1), (std::vector<int>(5, 0)));
  // More ranks than items: one each, largest to rank 0; ties by index.
  EXPECT_EQ(deal_by_weight(w, 8), (std::vector<int>{4, 0, 1, 2, 3}));
  EXPECT_TRUE(deal_by_weight({}, 3).empty());
}

}  // namespace
}  // namespace qsmesh::parallel
