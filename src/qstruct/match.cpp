#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <set>
#include <utility>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/qstruct/patterns.hpp"

namespace qsmesh::qstruct {

namespace {

using Int = std::int64_t;

void reduce_row(std::vector<Int>& row) {
  Int g = 0;
  for (const Int x : row) g = std::gcd(g, x);
  if (g > 1)
    for (Int& x : row) x /= g;
}

// Depth-first search over the integer echelon form, bottom row first (paper 000 Sec. 6.1.1).
class EchelonSearch {
 public:
  EchelonSearch(std::vector<std::vector<Int>> rows, std::vector<LO> pivots,
                std::vector<double> ideal, std::vector<Int> upper, std::span<const int> w,
                std::span<const LO> rhs, int max_attempts)
      : rows_(std::move(rows)),
        pivots_(std::move(pivots)),
        ideal_(std::move(ideal)),
        upper_(std::move(upper)),
        w_(w),
        rhs_(rhs),
        max_attempts_(max_attempts),
        c_(static_cast<LO>(ideal_.size())),
        s_(ideal_.size(), 0) {
    // Steps: for each row from the bottom, its not yet fixed free variables, then its pivot.
    std::vector<char> fixed(c_, 0);
    for (LO r = static_cast<LO>(pivots_.size()) - 1; r >= 0; --r) {
      for (LO j = pivots_[r] + 1; j < c_; ++j)
        if (!fixed[j] && rows_[r][j] != 0) {
          steps_.push_back({j, kNoIndex});
          fixed[j] = 1;
        }
      steps_.push_back({pivots_[r], r});
      fixed[pivots_[r]] = 1;
    }
    // A variable in no row (a zero column) is not constrained: it keeps its ideal value.
    for (LO j = 0; j < c_; ++j)
      if (!fixed[j])
        s_[j] = std::clamp<Int>(std::llround(ideal_[j]), 1, std::max<Int>(1, upper_[j]));
  }

  void run() { descend(0); }
  [[nodiscard]] bool found() const { return !best_.empty(); }
  [[nodiscard]] const std::vector<Int>& best() const { return best_; }
  [[nodiscard]] double best_energy() const { return best_energy_; }
  [[nodiscard]] int attempts() const { return attempts_; }

 private:
  struct Step {
    LO var;
    LO pivot_row;  ///< kNoIndex: a free variable to enumerate
  };

  // Returns false when the attempt budget is spent.
  bool descend(std::size_t k) {
    if (k == steps_.size()) {
      leaf();
      return true;
    }
    const Step& st = steps_[k];
    if (st.pivot_row != kNoIndex) {
      const auto& row = rows_[st.pivot_row];
      Int sum = row[c_];
      for (LO j = st.var + 1; j < c_; ++j) sum -= row[j] * s_[j];
      const Int a = row[st.var];
      if (sum % a != 0) return true;
      const Int v = sum / a;
      if (v < 1 || v > upper_[st.var]) return true;
      s_[st.var] = v;
      return descend(k + 1);
    }
    // Values in order of distance to the ideal, the nearer side first at equal steps.
    const LO j = st.var;
    const Int hi = upper_[j];
    const Int centre = std::clamp<Int>(std::llround(ideal_[j]), 1, hi);
    const bool up_first = ideal_[j] >= static_cast<double>(centre);
    for (Int d = 0; centre - d >= 1 || centre + d <= hi; ++d) {
      for (int side = 0; side < (d == 0 ? 1 : 2); ++side) {
        const Int v = (side == 0) == up_first ? centre + d : centre - d;
        if (v < 1 || v > hi) continue;
        if (attempts_ >= max_attempts_) return false;
        ++attempts_;
        s_[j] = v;
        if (!descend(k + 1)) return false;
      }
    }
    return true;
  }

  void leaf() {
    const std::size_t m = rhs_.size();
    for (std::size_t i = 0; i < m; ++i) {
      Int sum = 0;
      for (LO j = 0; j < c_; ++j) sum += static_cast<Int>(w_[i * c_ + j]) * s_[j];
      if (sum != rhs_[i]) return;  // cannot happen with exact elimination; kept as a guard
    }
    double e = 0;
    for (LO j = 0; j < c_; ++j)
      e += (static_cast<double>(s_[j]) - ideal_[j]) * (static_cast<double>(s_[j]) - ideal_[j]);
    if (best_.empty() || e < best_energy_) {
      best_ = s_;
      best_energy_ = e;
    }
  }

  std::vector<std::vector<Int>> rows_;
  std::vector<LO> pivots_;
  std::vector<double> ideal_;
  std::vector<Int> upper_;
  std::span<const int> w_;
  std::span<const LO> rhs_;
  int max_attempts_;
  LO c_;
  std::vector<Int> s_;
  std::vector<Step> steps_;
  std::vector<Int> best_;
  double best_energy_ = std::numeric_limits<double>::max();
  int attempts_ = 0;
};

}  // namespace

ChordSolution solve_chords(std::span<const int> w, int num_sides, LO num_chords,
                           std::span<const LO> side_edges, const MatchOptions& options) {
  const int m = num_sides;
  const LO c = num_chords;
  QSMESH_CHECK(m >= 1 && c >= 1, "solve_chords: " << m << " sides, " << c << " chords");
  QSMESH_CHECK(w.size() == static_cast<std::size_t>(m) * c,
               "solve_chords: w has " << w.size() << " entries, not " << m << " x " << c);
  QSMESH_CHECK(static_cast<int>(side_edges.size()) == m,
               "solve_chords: " << side_edges.size() << " side counts for " << m << " sides");
  ChordSolution out;

  // Balanced ideal: each side's edges shared equally among its chord slots.
  std::vector<Int> slots(m, 0);
  for (int i = 0; i < m; ++i)
    for (LO j = 0; j < c; ++j) slots[i] += w[i * c + j];
  out.ideal.assign(c, 1.0);
  std::vector<Int> upper(c, std::numeric_limits<Int>::max());
  for (LO j = 0; j < c; ++j) {
    double sum = 0;
    Int count = 0;
    for (int i = 0; i < m; ++i) {
      const int wij = w[i * c + j];
      if (wij == 0) continue;
      sum += wij * static_cast<double>(side_edges[i]) / static_cast<double>(slots[i]);
      count += wij;
      // The other slots of the side take at least one edge each.
      upper[j] = std::min(upper[j], (side_edges[i] - (slots[i] - wij)) / wij);
    }
    if (count > 0) out.ideal[j] = sum / static_cast<double>(count);
    if (count == 0) upper[j] = 1;
    if (upper[j] < 1) return out;
  }

  // Integer row echelon form of [w | N], fraction-free.
  std::vector<std::vector<Int>> rows(m, std::vector<Int>(c + 1));
  for (int i = 0; i < m; ++i) {
    for (LO j = 0; j < c; ++j) rows[i][j] = w[i * c + j];
    rows[i][c] = side_edges[i];
  }
  std::vector<LO> pivots;
  int r = 0;
  for (LO col = 0; col < c && r < m; ++col) {
    int best = -1;
    for (int i = r; i < m; ++i)
      if (rows[i][col] != 0 && (best < 0 || std::llabs(rows[i][col]) < std::llabs(rows[best][col])))
        best = i;
    if (best < 0) continue;
    std::swap(rows[r], rows[best]);
    if (rows[r][col] < 0)
      for (Int& x : rows[r]) x = -x;
    for (int i = r + 1; i < m; ++i) {
      if (rows[i][col] == 0) continue;
      const Int g = std::gcd(rows[r][col], rows[i][col]);
      const Int fr = rows[i][col] / g, fi = rows[r][col] / g;
      for (LO j = 0; j <= c; ++j) rows[i][j] = rows[i][j] * fi - rows[r][j] * fr;
      reduce_row(rows[i]);
    }
    pivots.push_back(col);
    ++r;
  }
  for (int i = r; i < m; ++i)
    if (rows[i][c] != 0) return out;  // 0 = nonzero: inconsistent counts
  rows.resize(r);

  EchelonSearch search(std::move(rows), std::move(pivots), out.ideal, std::move(upper), w,
                       side_edges, options.max_attempts);
  search.run();
  out.attempts = search.attempts();
  if (!search.found()) return out;
  out.found = true;
  out.s.assign(search.best().begin(), search.best().end());
  out.energy = search.best_energy();
  return out;
}

std::vector<PatternMatch> match_patterns(std::span<const Pattern> patterns,
                                         std::span<const LO> side_edges,
                                         const MatchOptions& options, bool cornerless) {
  const int m = static_cast<int>(side_edges.size());
  std::vector<PatternMatch> out;
  if (m == 0 || (cornerless && m != 1)) return out;
  for (LO p = 0; p < static_cast<LO>(patterns.size()); ++p) {
    const Pattern& pat = patterns[p];
    if (pat.num_sides() != m || pat.cornerless() != cornerless) continue;
    // Subdivisions seen along each cavity side, in cavity order: equal ones give the same mesh.
    std::set<std::vector<std::vector<LO>>> seen;
    std::vector<PatternMatch> found;
    for (const bool reversed : {false, true})
      for (int start = 0; start < m; ++start) {
        std::vector<LO> counts(m);
        for (int i = 0; i < m; ++i)
          counts[i] = side_edges[(((reversed ? start - i : start + i) % m) + m) % m];
        ChordSolution sol = solve_chords(pat.w, m, pat.num_chords, counts, options);
        if (!sol.found) continue;
        std::vector<std::vector<LO>> key(m);
        const LO nb = static_cast<LO>(pat.boundary.size());
        for (int i = 0; i < m; ++i) {
          const int side = (((reversed ? start - i : start + i) % m) + m) % m;
          const LO end = i + 1 < m ? pat.side_start[i + 1] : nb;
          for (LO k = pat.side_start[i]; k < end; ++k)
            key[side].push_back(sol.s[pat.edge_chord[pat.boundary_edge[k]]]);
          if (reversed) std::reverse(key[side].begin(), key[side].end());
        }
        if (!seen.insert(std::move(key)).second) continue;
        PatternMatch match;
        match.pattern = p;
        match.start = start;
        match.reversed = reversed;
        match.chords = std::move(sol.s);
        match.energy = sol.energy;
        found.push_back(std::move(match));
      }
    std::stable_sort(found.begin(), found.end(), [](const PatternMatch& a, const PatternMatch& b) {
      return a.energy < b.energy;
    });
    for (auto& f : found) out.push_back(std::move(f));
  }
  return out;
}

std::size_t MatchCache::KeyHash::operator()(const Key& k) const {
  std::size_t h = std::hash<const void*>()(k.list) ^ (k.size * 0x9e3779b97f4a7c15ULL);
  h ^= static_cast<std::size_t>(k.max_attempts) * 31 + (k.cornerless ? 17 : 0);
  for (const LO x : k.sides) h = h * 1000003 ^ static_cast<std::size_t>(x);
  return h;
}

const std::vector<PatternMatch>& MatchCache::matches(std::span<const Pattern> patterns,
                                                     std::span<const LO> side_edges,
                                                     const MatchOptions& options, bool cornerless) {
  Key key{patterns.data(), patterns.size(), options.max_attempts, cornerless,
          std::vector<LO>(side_edges.begin(), side_edges.end())};
  const auto it = results_.find(key);
  if (it != results_.end()) {
    ++hits_;
    return it->second;
  }
  ++misses_;
  if (results_.size() >= max_entries_) results_.clear();
  return results_.emplace(std::move(key), match_patterns(patterns, side_edges, options, cornerless))
      .first->second;
}

}  // namespace qsmesh::qstruct
