#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <functional>
#include <map>
#include <set>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/remesh/disk_table.hpp"

namespace qsmesh::remesh {
namespace {

// Canonical code of entry e seen from boundary vertex r, turning forward or backward: the boundary
// gets labels 0..b-1 from r, interior vertices are labelled in the order a fixed rule discovers
// them (the unlabelled vertex after the smallest labelled directed edge (a, c) whose quad continues
// to it: a directed edge lies in one quad at most), then the quads, relabelled, each rotated to its
// smallest label, sorted. Independent of nauty; equal codes <=> the meshes are isomorphic.
std::vector<int> code(const DiskQuadTable& t, LO e, int r, bool reversed) {
  const int b = t.boundary_size(e), n = t.interior_size(e);
  std::vector<std::array<int, 4>> quads;
  for (const auto& q : t.quads(e)) {
    std::array<int, 4> a{q[0], q[1], q[2], q[3]};
    if (reversed) std::swap(a[1], a[3]);
    quads.push_back(a);
  }
  std::vector<int> label(b + n, -1);
  for (int v = 0; v < b; ++v) label[v] = reversed ? ((r - v) % b + b) % b : ((v - r) % b + b) % b;
  for (int next = b; next < b + n; ++next) {
    std::array<int, 3> best{1 << 30, 1 << 30, -1};
    for (const auto& q : quads)
      for (int k = 0; k < 4; ++k) {
        const int a = q[k], c = q[(k + 1) % 4], x = q[(k + 2) % 4];
        if (label[a] >= 0 && label[c] >= 0 && label[x] < 0)
          best = std::min(best, std::array<int, 3>{label[a], label[c], x});
      }
    EXPECT_GE(best[2], 0) << "traversal stuck in entry " << e;
    if (best[2] < 0) return {};
    label[best[2]] = next;
  }
  std::vector<std::array<int, 4>> relabelled;
  for (const auto& q : quads) {
    std::array<int, 4> l{label[q[0]], label[q[1]], label[q[2]], label[q[3]]};
    std::rotate(l.begin(), std::min_element(l.begin(), l.end()), l.end());
    relabelled.push_back(l);
  }
  std::sort(relabelled.begin(), relabelled.end());
  std::vector<int> out{b, n};
  for (const auto& l : relabelled) out.insert(out.end(), l.begin(), l.end());
  return out;
}

std::vector<int> canonical(const DiskQuadTable& t, LO e) {
  std::vector<int> best;
  for (int r = 0; r < t.boundary_size(e); ++r)
    for (bool rev : {false, true}) {
      auto c = code(t, e, r, rev);
      if (best.empty() || c < best) best = c;
    }
  return best;
}

// Labelled quadrangulations of a b-gon without interior vertex whose vertices all have quad
// valence <= 3, counted by brute force: the quad on edge (p0, p_last) is (p0, p_i, p_j, p_last),
// splitting the polygon into three even-sided ones, recursively.
long count_polygon_dissections(int b) {
  std::vector<int> valence(b, 0);
  long count = 0;
  std::function<void(std::vector<std::vector<int>>)> rec = [&](std::vector<std::vector<int>> todo) {
    while (!todo.empty() && todo.back().size() == 2) todo.pop_back();
    if (todo.empty()) {
      count += std::all_of(valence.begin(), valence.end(), [](int v) { return v >= 1 && v <= 3; });
      return;
    }
    const std::vector<int> p = todo.back();
    todo.pop_back();
    const int m = static_cast<int>(p.size());
    for (int i = 1; i < m - 2; i += 2)
      for (int j = i + 1; j < m - 1; j += 2) {
        for (int v : {p[0], p[i], p[j], p[m - 1]}) ++valence[v];
        auto next = todo;
        next.emplace_back(p.begin(), p.begin() + i + 1);
        next.emplace_back(p.begin() + i, p.begin() + j + 1);
        next.emplace_back(p.begin() + j, p.end());
        rec(next);
        for (int v : {p[0], p[i], p[j], p[m - 1]}) --valence[v];
      }
  };
  std::vector<int> all(b);
  for (int v = 0; v < b; ++v) all[v] = v;
  rec({all});
  return count;
}

TEST(DiskTable, SmallCountsDerivedByHand) {
  const DiskQuadTable t = DiskQuadTable::builtin();
  // Euler: quads F = b/2 + n - 1.
  // b=4, n=0: the quad itself.
  EXPECT_EQ(t.count(4, 0), 1);
  // b=4, n=1: F=2, the interior vertex would be in 2 quads (valence 2 < 3).
  EXPECT_EQ(t.count(4, 1), 0);
  // b=4, n=2: F=3, E=8, 4 interior edges. Interior vertices P, Q need >= 6 edge ends; an edge PQ
  // leaves 3 edges with at most one end each on P or Q (no double edge): 2 + 3 < 6. Without PQ: 4
  // < 6.
  EXPECT_EQ(t.count(4, 2), 0);
  // b=4, n=3: F=4, E=10, 6 interior edges, >= 9 ends on P, Q, R: x edges among them and 6-x others
  // give 2x + (6-x) >= 9, so x = 3: a triangle, impossible in a quad mesh (its graph is bipartite).
  EXPECT_EQ(t.count(4, 3), 0);
  // b=4, n=4: the square with an inner square (all interior valences 3); the only one with F=5.
  EXPECT_EQ(t.count(4, 4), 1);
  // b=6, n=0: two quads split by a long diagonal (3 labelled ways, one class).
  EXPECT_EQ(t.count(6, 0), 1);
  // b=6, n=1: F=3, the interior vertex is in all three quads: the three-quad fan.
  EXPECT_EQ(t.count(6, 1), 1);
  // b=8, n=0: three quads, their two diagonals share a vertex (fan) or not (strip).
  EXPECT_EQ(t.count(8, 0), 2);
  // Odd boundaries do not exist; the table stops at b = 12.
  EXPECT_EQ(t.count(5, 0), 0);
  EXPECT_EQ(t.max_boundary(), 12);
}

TEST(DiskTable, EntriesAreValidAndWithinTheRanges) {
  const DiskQuadTable t = DiskQuadTable::builtin();
  ASSERT_GT(t.size(), 700);
  for (LO e = 0; e < t.size(); ++e) {
    const int b = t.boundary_size(e), n = t.interior_size(e);
    ASSERT_EQ(static_cast<int>(t.quads(e).size()), b / 2 + n - 1);
    const auto val = t.valences(e);
    for (int v = 0; v < b; ++v) EXPECT_TRUE(val[v] >= 1 && val[v] <= 3) << "entry " << e;
    for (int v = b; v < b + n; ++v) EXPECT_TRUE(val[v] >= 3 && val[v] <= 5) << "entry " << e;
  }
}

TEST(DiskTable, NoTwoEntriesIsomorphicBySecondCanonicalForm) {
  const DiskQuadTable t = DiskQuadTable::builtin();
  std::set<std::vector<int>> seen;
  for (LO e = 0; e < t.size(); ++e)
    EXPECT_TRUE(seen.insert(canonical(t, e)).second) << "entry " << e;
}

TEST(DiskTable, PolygonClassesAccountForEveryLabelledDissection) {
  // Each class of b-gon quadrangulations stands for 2b / |Aut| labelled ones; summed, they must
  // give the brute-force count (Fuss-Catalan numbers 1, 3, 12, 55, 273 before the valence bound).
  const DiskQuadTable t = DiskQuadTable::builtin();
  EXPECT_EQ(count_polygon_dissections(6), 3);
  EXPECT_EQ(count_polygon_dissections(8), 12);
  for (int b = 4; b <= 12; b += 2) {
    long labelled = 0;
    for (LO e : t.with_boundary(b)) {
      if (t.interior_size(e) != 0) continue;
      const auto c0 = code(t, e, 0, false);
      int automorphisms = 0;
      for (int r = 0; r < b; ++r)
        for (bool rev : {false, true}) automorphisms += code(t, e, r, rev) == c0 ? 1 : 0;
      labelled += 2 * b / automorphisms;
    }
    EXPECT_EQ(labelled, count_polygon_dissections(b)) << "b = " << b;
  }
}

TEST(DiskTable, ParseRejectsMalformedEntries) {
  EXPECT_EQ(DiskQuadTable::parse("# comment\n4 0 0 1 2 3\n").size(), 1);
  EXPECT_THROW((void)DiskQuadTable::parse("4 0 0 1 2\n"), Error);            // short quad
  EXPECT_THROW((void)DiskQuadTable::parse("4 0 0 2 1 3\n"), Error);          // boundary not 0..3
  EXPECT_THROW((void)DiskQuadTable::parse("6 0 0 1 2 3 0 5 4 3\n"), Error);  // edge 3->0 twice
  EXPECT_THROW((void)DiskQuadTable::parse("4 0 0 1 2 9\n"), Error);          // id out of range
}

}  // namespace
}  // namespace qsmesh::remesh
