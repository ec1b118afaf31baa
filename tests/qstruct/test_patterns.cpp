#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/qstruct/patterns.hpp"

namespace qsmesh::qstruct {
namespace {

const Pattern& by_name(const std::vector<Pattern>& all, const std::string& name) {
  for (const auto& p : all)
    if (p.name == name) return p;
  throw std::runtime_error("no pattern " + name);
}

LO index_of(const std::vector<Pattern>& all, const std::string& name) {
  for (LO i = 0; i < static_cast<LO>(all.size()); ++i)
    if (all[i].name == name) return i;
  return kNoIndex;
}

// Columns of w as vectors, sorted: w up to a renumbering of the chords.
std::vector<std::vector<int>> columns(const std::vector<int>& w, int rows, int cols) {
  std::vector<std::vector<int>> out(cols, std::vector<int>(rows));
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) out[j][i] = w[i * cols + j];
  std::sort(out.begin(), out.end());
  return out;
}

TEST(Patterns, BuiltinPatternsAreValidDisks) {
  const auto all = builtin_patterns();
  // name -> {sides, chords, irregular vertices}
  const std::map<std::string, std::array<int, 3>> expected = {{"grid", {4, 2, 0}},
                                                              {"transition_1", {4, 5, 2}},
                                                              {"transition_2", {4, 7, 4}},
                                                              {"triangle", {3, 3, 1}},
                                                              {"transition_2_joined", {4, 6, 3}},
                                                              {"transition_aligned", {4, 6, 2}},
                                                              {"chord_uturn", {4, 6, 4}},
                                                              {"pentagon", {5, 5, 1}},
                                                              {"l_shape", {5, 4, 1}},
                                                              {"hexagon", {6, 6, 1}},
                                                              {"half_disk", {2, 3, 2}},
                                                              {"one_corner", {1, 3, 3}},
                                                              {"disk", {1, 3, 4}}};
  ASSERT_EQ(all.size(), expected.size());
  for (const auto& p : all) {
    SCOPED_TRACE(p.name);
    ASSERT_TRUE(expected.count(p.name));
    const auto& e = expected.at(p.name);
    EXPECT_EQ(p.num_sides(), e[0]);
    EXPECT_EQ(p.num_chords, e[1]);
    EXPECT_EQ(p.irregular, e[2]);
    // Counter-clockwise in the drawing of the data file.
    for (const auto& q : p.quads) {
      double area = 0;
      for (int k = 0; k < 4; ++k) area += cross(p.xy[q[k]], p.xy[q[(k + 1) % 4]]);
      EXPECT_GT(area, 0);
    }
    // Every side count equals its chord weights; w entries are 0, 1 or 2; each chord reaches
    // the boundary exactly twice, or never (a closed chord).
    std::vector<int> per_chord(p.num_chords, 0);
    for (int i = 0; i < p.num_sides(); ++i)
      for (LO j = 0; j < p.num_chords; ++j) {
        EXPECT_GE(p.weight(i, j), 0);
        EXPECT_LE(p.weight(i, j), 2);
        per_chord[j] += p.weight(i, j);
      }
    for (LO j = 0; j < p.num_chords; ++j) EXPECT_EQ(per_chord[j], p.closed_chord(j) ? 0 : 2);
    // Sides start at a corner, except in the pattern without corner.
    EXPECT_EQ(p.valence[p.boundary[p.side_start[0]]], p.name == "disk" ? 2 : 1);
    EXPECT_EQ(p.cornerless(), p.name == "disk");
  }
  // Only the disk's ring is closed; it is numbered last, after the chords reaching the side.
  for (const auto& p : all)
    for (LO j = 0; j < p.num_chords; ++j)
      EXPECT_EQ(p.closed_chord(j), p.name == "disk" && j == p.num_chords - 1) << p.name << " " << j;
  // The half disk has chords turning inside a side (w = 2).
  const auto& hd = by_name(all, "half_disk");
  EXPECT_EQ(*std::max_element(hd.w.begin(), hd.w.end()), 2);
}

TEST(Patterns, ThirdPatternGivesThePapersSystem) {
  const auto all = builtin_patterns();
  const auto& p = by_name(all, "transition_1");
  // a + b + c = N1, d + e = N2, a + c = N3, b + d + e = N4 (paper 000 Sec. 6.1.1), columns a..e.
  const std::vector<int> paper = {1, 1, 1, 0, 0,  //
                                  0, 0, 0, 1, 1,  //
                                  1, 0, 1, 0, 0,  //
                                  0, 1, 0, 1, 1};
  ASSERT_EQ(p.num_sides(), 4);
  ASSERT_EQ(p.num_chords, 5);
  EXPECT_EQ(columns(p.w, 4, 5), columns(paper, 4, 5));
  // Chords are numbered along side 1 first: a, b, c.
  EXPECT_EQ(p.weight(0, 0) + p.weight(0, 1) + p.weight(0, 2), 3);
}

// chord_moves: the kernel of w, in integers. The grid has none (its sides fix both chords); the
// paper's third pattern has two (a + b + c = N1, a + c = N3 and b + d + e = N4, d + e = N2 leave
// a against c and d against e free); every pattern's moves keep all side counts.
TEST(Patterns, ChordMovesKeepEverySideCount) {
  const auto all = builtin_patterns();
  EXPECT_TRUE(chord_moves(by_name(all, "grid")).empty());
  EXPECT_EQ(chord_moves(by_name(all, "transition_1")).size(), 2u);
  for (const auto& p : all) {
    const auto moves = chord_moves(p);
    for (const auto& v : moves) {
      ASSERT_EQ(static_cast<LO>(v.size()), p.num_chords) << p.name;
      bool nonzero = false;
      for (const LO x : v) nonzero = nonzero || x != 0;
      EXPECT_TRUE(nonzero) << p.name;
      for (int i = 0; i < p.num_sides(); ++i) {
        long sum = 0;
        for (LO j = 0; j < p.num_chords; ++j) sum += static_cast<long>(p.weight(i, j)) * v[j];
        EXPECT_EQ(sum, 0) << p.name << " side " << i;
      }
    }
    // As many moves as free chords: a random positive solution plus any combination stays a
    // solution, and the moves are independent (checked by their count against the rank).
    EXPECT_LE(static_cast<LO>(moves.size()), p.num_chords - 1) << p.name;
  }
}

// One side: 2 a + 2 b + 2 c = N1 for the teardrop, 2 a + 2 b = N1 for the disk. A face with one
// corner fits only the first, a face without corner only the second, and only with an even count.
TEST(Match, OneSidedPatternsFitByCorners) {
  const auto all = builtin_patterns();
  const std::vector<LO> n24 = {24};
  const auto one = match_patterns(all, n24);
  ASSERT_FALSE(one.empty());
  for (const auto& m : one) EXPECT_EQ(all[m.pattern].name, "one_corner");
  EXPECT_EQ(one.front().chords, (std::vector<LO>{4, 4, 4}));
  const auto none = match_patterns(all, n24, {}, /*cornerless=*/true);
  ASSERT_FALSE(none.empty());
  for (const auto& m : none) EXPECT_EQ(all[m.pattern].name, "disk");
  // The two crossing chords share the side; the ring is left to the caller (1 here).
  EXPECT_EQ(none.front().chords, (std::vector<LO>{6, 6, 1}));
  const std::vector<LO> n23 = {23};
  EXPECT_TRUE(match_patterns(all, n23).empty());
  EXPECT_TRUE(match_patterns(all, n23, {}, true).empty());
  // Cornerless input takes one side only, and the sides of the disk fit nothing with corners.
  EXPECT_TRUE(match_patterns(all, std::vector<LO>{6, 6, 6, 6}, {}, true).empty());
  EXPECT_TRUE(match_patterns(all, std::vector<LO>{12, 12}, {}, true).empty());
  // The disk's ring layers are a move of their own (it changes no side).
  const auto moves = chord_moves(by_name(all, "disk"));
  EXPECT_NE(std::find(moves.begin(), moves.end(), std::vector<LO>{0, 0, 1}), moves.end());
}

TEST(Patterns, InvalidPatternsAreRejected) {
  // Two quads with inconsistent orientation.
  EXPECT_THROW((void)make_pattern("bad", {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {2, 0}, {2, 1}},
                                  {{0, 1, 2, 3}, {1, 2, 5, 4}}),
               Error);
  // An annulus (not a disk).
  std::vector<Vec2> xy(8);
  EXPECT_THROW(
      (void)make_pattern("ring", xy, {{0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}}),
      Error);
  // Index out of range.
  EXPECT_THROW((void)make_pattern("range", {{0, 0}, {1, 0}, {1, 1}}, {{0, 1, 2, 3}}), Error);
}

TEST(Match, SolveChordsSmallSystems) {
  const auto all = builtin_patterns();
  const auto& tri = by_name(all, "triangle");
  const std::vector<LO> n6 = {6, 6, 6};
  auto s = solve_chords(tri.w, 3, tri.num_chords, n6);
  ASSERT_TRUE(s.found);
  EXPECT_EQ(s.s, (std::vector<LO>{3, 3, 3}));
  EXPECT_DOUBLE_EQ(s.energy, 0);
  // a + b, b + c, c + a with an odd total: no integer solution.
  const std::vector<LO> odd = {6, 6, 5};
  EXPECT_FALSE(solve_chords(tri.w, 3, tri.num_chords, odd).found);
  // [4, 6, 8]: a = 3, b = 1, c = 5 in some chord order; strictly positive.
  const std::vector<LO> skew = {4, 6, 8};
  s = solve_chords(tri.w, 3, tri.num_chords, skew);
  ASSERT_TRUE(s.found);
  // [2, 10, 2]: c + a = 2 forces a = c = 1 but then b = 1 and b + c = 2 != 10.
  const std::vector<LO> none = {2, 10, 2};
  EXPECT_FALSE(solve_chords(tri.w, 3, tri.num_chords, none).found);

  // In the hexagon each chord joins sides two apart: sides 0, 2, 4 and sides 1, 3, 5 form two
  // triangle systems, each needing an even total.
  const auto& hex = by_name(all, "hexagon");
  const std::vector<LO> h = {4, 4, 4, 4, 4, 4};
  s = solve_chords(hex.w, 6, hex.num_chords, h);
  ASSERT_TRUE(s.found);
  EXPECT_EQ(s.s, std::vector<LO>(6, 2));
  const std::vector<LO> h_even = {4, 4, 4, 4, 4, 6};
  EXPECT_TRUE(solve_chords(hex.w, 6, hex.num_chords, h_even).found);
  const std::vector<LO> h_odd = {4, 4, 4, 4, 4, 5};
  EXPECT_FALSE(solve_chords(hex.w, 6, hex.num_chords, h_odd).found);

  // An undetermined system (one pair: 5 chords, rank 3): the balanced solution wins.
  const auto& t1 = by_name(all, "transition_1");
  const std::vector<LO> n = {12, 4, 10, 6};  // a + b + c, d + e, a + c, b + d + e
  s = solve_chords(t1.w, 4, t1.num_chords, n);
  ASSERT_TRUE(s.found);
  std::vector<LO> sorted = s.s;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, (std::vector<LO>{2, 2, 2, 5, 5}));  // b = 2, a = c = 5, d = e = 2

  // Every solution satisfies the system exactly and is strictly positive.
  const auto& hd = by_name(all, "half_disk");
  const std::vector<LO> d = {7, 5};
  s = solve_chords(hd.w, 2, hd.num_chords, d);
  ASSERT_TRUE(s.found);
  for (int i = 0; i < 2; ++i) {
    LO sum = 0;
    for (LO j = 0; j < hd.num_chords; ++j) sum += hd.weight(i, j) * s.s[j];
    EXPECT_EQ(sum, d[i]);
  }
  for (const LO x : s.s) EXPECT_GE(x, 1);
}

TEST(Match, SearchIsAbandonedAfterTheAttemptBudget) {
  // 2 a + 2 b = 2001 has no integer solution but every b in [1, 999] must be tried to see it.
  const std::vector<int> w = {2, 2};
  const std::vector<LO> n = {2001};
  MatchOptions o;
  o.max_attempts = 300;
  const auto s = solve_chords(w, 1, 2, n, o);
  EXPECT_FALSE(s.found);
  EXPECT_EQ(s.attempts, o.max_attempts);
  // 2 a + 2 b = 2000: found at once near the ideal a = b = 500.
  const std::vector<LO> even = {2000};
  const auto t = solve_chords(w, 1, 2, even, o);
  ASSERT_TRUE(t.found);
  EXPECT_EQ(t.s, (std::vector<LO>{500, 500}));
  EXPECT_LE(t.attempts, o.max_attempts);
}

TEST(Match, RegularSidesMatchTheGrid) {
  const auto all = builtin_patterns();
  const std::vector<LO> n = {10, 4, 10, 4};
  const auto matches = match_patterns(all, n);
  ASSERT_FALSE(matches.empty());
  EXPECT_EQ(all[matches[0].pattern].name, "grid");
  // The grid's 8 placements are one mesh.
  EXPECT_EQ(std::count_if(matches.begin(), matches.end(),
                          [&](const PatternMatch& m) { return all[m.pattern].name == "grid"; }),
            1);
  auto chords = matches[0].chords;
  std::sort(chords.begin(), chords.end());
  EXPECT_EQ(chords, (std::vector<LO>{4, 10}));
}

TEST(Match, OnePairTransition) {
  const auto all = builtin_patterns();
  const LO grid = index_of(all, "grid"), t1 = index_of(all, "transition_1");
  const std::vector<LO> n = {11, 4, 9, 6};
  const auto matches = match_patterns(all, n);
  bool any_t1 = false;
  for (const auto& m : matches) {
    EXPECT_NE(m.pattern, grid);
    if (m.pattern != t1) continue;
    any_t1 = true;
    // The solution satisfies Eq. 14 on the rotated sides and b = N1 - N3 = N4 - N2 = 2.
    const auto& p = all[t1];
    for (int i = 0; i < 4; ++i) {
      const LO side = ((m.reversed ? m.start - i : m.start + i) % 4 + 4) % 4;
      LO sum = 0;
      for (LO j = 0; j < p.num_chords; ++j) sum += p.weight(i, j) * m.chords[j];
      EXPECT_EQ(sum, n[side]);
    }
    for (LO j = 0; j < p.num_chords; ++j) {
      // The chord on two adjacent sides is the turning one.
      int sides = 0;
      for (int i = 0; i < 4; ++i) sides += p.weight(i, j) > 0;
      bool adjacent = false;
      for (int i = 0; i < 4; ++i) adjacent |= p.weight(i, j) > 0 && p.weight((i + 1) % 4, j) > 0;
      if (adjacent) {
        EXPECT_EQ(m.chords[j], 2);
      }
    }
  }
  EXPECT_TRUE(any_t1);
  // N1 - N3 = 1 but N4 - N2 = 2: no placement of the one-pair pattern (nor of the grid) fits.
  const std::vector<LO> bad = {10, 4, 9, 6};
  for (const auto& m : match_patterns(all, bad)) {
    EXPECT_NE(m.pattern, grid);
    EXPECT_NE(m.pattern, t1);
  }
}

TEST(Match, TwoPairTransitionTakesUnequalDifferences) {
  const auto all = builtin_patterns();
  // N1 - N3 = 4, N4 - N2 = 2: neither the grid nor one pair; two pairs with b = 3, f = 1.
  const std::vector<LO> n = {12, 4, 8, 6};
  const auto matches = match_patterns(all, n);
  ASSERT_FALSE(matches.empty());
  EXPECT_EQ(all[matches[0].pattern].name, "transition_2");
}

// Sums of the chord subdivisions of match m over each side of pattern p equal the cavity's counts
// (Eq. 14 on the rotated sides).
void expect_solves_eq14(const Pattern& p, const PatternMatch& m, const std::vector<LO>& n) {
  const int ns = p.num_sides();
  for (int i = 0; i < ns; ++i) {
    const LO side = ((m.reversed ? m.start - i : m.start + i) % ns + ns) % ns;
    LO sum = 0;
    for (LO j = 0; j < p.num_chords; ++j) sum += p.weight(i, j) * m.chords[j];
    EXPECT_EQ(sum, n[side]) << p.name << " side " << i;
  }
}

// The two four-sided patterns of Gmsh's implementation beside the paper's third one: a chord
// making a U-turn (w = 2 on one side) and a valence-3 / valence-5 pair side by side.
TEST(Match, UTurnAndAlignedPairGiveTheirSystems) {
  const auto all = builtin_patterns();
  const Pattern& u = by_name(all, "chord_uturn");
  // a + b + c = N1, d + e = N2, a + b + c + 2 f = N3, d + e = N4
  EXPECT_EQ(
      columns(u.w, 4, u.num_chords),
      (std::vector<std::vector<int>>{
          {0, 0, 2, 0}, {0, 1, 0, 1}, {0, 1, 0, 1}, {1, 0, 1, 0}, {1, 0, 1, 0}, {1, 0, 1, 0}}));
  EXPECT_EQ(u.irregular, 4);
  const Pattern& a = by_name(all, "transition_aligned");
  // a + b + c = N1, b + d + e + f = N2, a + c + e = N3, d + f = N4
  EXPECT_EQ(
      columns(a.w, 4, a.num_chords),
      (std::vector<std::vector<int>>{
          {0, 1, 0, 1}, {0, 1, 0, 1}, {0, 1, 1, 0}, {1, 0, 1, 0}, {1, 0, 1, 0}, {1, 1, 0, 0}}));
  EXPECT_EQ(a.irregular, 2);

  // [10, 2, 6, 2]: the sides between the unequal ones hold two edges, too few for two turning
  // chords (transition_2, transition_2_joined); only the U-turn fits, turning f = 2.
  const std::vector<LO> n = {10, 2, 6, 2};
  const auto matches = match_patterns(all, n);
  ASSERT_FALSE(matches.empty());
  for (const auto& m : matches) {
    EXPECT_EQ(all[m.pattern].name, "chord_uturn");
    expect_solves_eq14(all[m.pattern], m, n);
    for (LO j = 0; j < u.num_chords; ++j)
      if (u.weight(2, j) == 2) {
        EXPECT_EQ(m.chords[j], 2);
      }
  }
  // [12, 12, 12, 2]: N2 - N4 = b + e = 10, N1 - N3 = b - e = 0 fits the aligned pair, b = e = 5.
  const std::vector<LO> n2 = {12, 12, 12, 2};
  bool aligned = false;
  for (const auto& m : match_patterns(all, n2)) {
    EXPECT_NE(all[m.pattern].name, "grid");
    if (m.pattern != index_of(all, "transition_aligned")) continue;
    aligned = true;
    expect_solves_eq14(a, m, n2);
  }
  EXPECT_TRUE(aligned);
}

bool same_matches(const std::vector<PatternMatch>& a, const std::vector<PatternMatch>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].pattern != b[i].pattern || a[i].start != b[i].start ||
        a[i].reversed != b[i].reversed || a[i].chords != b[i].chords || a[i].energy != b[i].energy)
      return false;
  return true;
}

// MatchCache: the matches of match_patterns, for every list, side counts and option met, kept
// apart by list (a sub-list of the same patterns is another key) and by options.
TEST(Match, CacheGivesTheSameMatches) {
  const auto all = builtin_patterns();
  std::vector<Pattern> four;
  for (const auto& p : all)
    if (p.num_sides() == 4) four.push_back(p);
  const std::vector<std::vector<LO>> sides{{4, 4, 4, 4},    {3, 5, 4, 6}, {2, 3, 4}, {6, 2, 6, 3},
                                           {3, 3, 3, 3, 3}, {5, 5, 6},    {24},      {4, 4, 4, 4}};
  MatchCache cache;
  MatchOptions tight;
  tight.max_attempts = 3;
  std::int64_t calls = 0, nonempty = 0;
  for (int round = 0; round < 2; ++round)
    for (const auto& n : sides)
      for (const bool cornerless : {false, true}) {
        for (const std::vector<Pattern>* list :
             std::array<const std::vector<Pattern>*, 2>{&all, &four}) {
          const auto& got = cache.matches(*list, n, {}, cornerless);
          EXPECT_TRUE(same_matches(got, match_patterns(*list, n, {}, cornerless)));
          nonempty += got.empty() ? 0 : 1;
          ++calls;
        }
        EXPECT_TRUE(same_matches(cache.matches(all, n, tight, cornerless),
                                 match_patterns(all, n, tight, cornerless)));
        ++calls;
      }
  EXPECT_GT(nonempty, 8);
  EXPECT_EQ(cache.hits() + cache.misses(), calls);
  // 7 distinct side counts x 2 x 3 keys, each computed once.
  EXPECT_EQ(cache.misses(), 7 * 2 * 3);
  // Full: starts over, still the same matches.
  MatchCache small(2);
  for (const auto& n : sides)
    EXPECT_TRUE(same_matches(small.matches(all, n), match_patterns(all, n)));
}

TEST(Refine, GridAndTransitionTopology) {
  const auto all = builtin_patterns();
  const auto& grid = by_name(all, "grid");
  const std::vector<LO> s = {3, 2};
  const auto r = refine_pattern(grid, s);
  EXPECT_EQ(r.quads.size(), 6u);
  EXPECT_EQ(r.num_vertices, 12);
  EXPECT_EQ(r.boundary.size(), 10u);
  EXPECT_EQ(r.side_start, (std::vector<LO>{0, 3, 5, 8}));
  EXPECT_THROW((void)refine_pattern(grid, std::vector<LO>{3, 0}), Error);

  const auto& t1 = by_name(all, "transition_1");
  const std::vector<LO> c = {3, 2, 4, 2, 3};
  const auto t = refine_pattern(t1, c);
  std::vector<int> val(t.num_vertices, 0);
  std::map<std::pair<LO, LO>, int> edges;
  for (const auto& q : t.quads)
    for (int k = 0; k < 4; ++k) {
      ++val[q[k]];
      ++edges[{std::min(q[k], q[(k + 1) % 4]), std::max(q[k], q[(k + 1) % 4])}];
    }
  LO boundary_edges = 0;
  for (const auto& [e, n] : edges) {
    EXPECT_LE(n, 2);
    boundary_edges += n == 1;
  }
  EXPECT_EQ(boundary_edges, static_cast<LO>(t.boundary.size()));
  EXPECT_EQ(t.num_vertices - static_cast<LO>(edges.size()) + static_cast<LO>(t.quads.size()), 1);
  std::set<LO> on_boundary(t.boundary.begin(), t.boundary.end());
  EXPECT_EQ(on_boundary.size(), t.boundary.size());
  int v3 = 0, v5 = 0, other = 0;
  for (LO v = 0; v < t.num_vertices; ++v) {
    if (on_boundary.count(v)) continue;
    v3 += val[v] == 3;
    v5 += val[v] == 5;
    other += val[v] != 3 && val[v] != 4 && val[v] != 5;
  }
  EXPECT_EQ(v3, 1);
  EXPECT_EQ(v5, 1);
  EXPECT_EQ(other, 0);
  // Side lengths follow Eq. 14.
  const LO nb = static_cast<LO>(t.boundary.size());
  for (int i = 0; i < 4; ++i) {
    const LO len = (i + 1 < 4 ? t.side_start[i + 1] : nb) - t.side_start[i];
    LO sum = 0;
    for (LO j = 0; j < t1.num_chords; ++j) sum += t1.weight(i, j) * c[j];
    EXPECT_EQ(len, sum);
  }
}

}  // namespace
}  // namespace qsmesh::qstruct
