#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <span>
#include <utility>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/qstruct/patterns.hpp"

namespace qsmesh::qstruct {

namespace {

using Int = std::int64_t;

// Divides a row by the gcd of its entries.
void reduce_row(std::span<Int> row) {
  Int g = 0;
  for (const Int x : row) g = std::gcd(g, x);
  if (g > 1)
    for (Int& x : row) x /= g;
}

// The buffers of one solve, kept by match_patterns across its patterns and rotations (it solves
// 2m systems per pattern for every side counts it is asked about, and these few small vectors,
// allocated anew per solve, were half of its time on Block.stp).
struct ChordWork {
  std::vector<Int> slots, upper, rows, s, best;
  std::vector<double> ideal;
  std::vector<LO> pivots;
  std::vector<char> fixed;
  struct Step {
    LO var;
    LO pivot_row;  ///< kNoIndex: a free variable to enumerate
  };
  std::vector<Step> steps;
};

// Depth-first search over the integer echelon form, bottom row first (paper 000 Sec. 6.1.1).
// rows: the echelon rows, each c + 1 entries ([w | N]), flat.
class EchelonSearch {
 public:
  EchelonSearch(ChordWork& k, std::span<const int> w, std::span<const LO> rhs, int max_attempts)
      : k_(k),
        rows_(k.rows),
        pivots_(k.pivots),
        ideal_(k.ideal),
        upper_(k.upper),
        w_(w),
        rhs_(rhs),
        max_attempts_(max_attempts),
        c_(static_cast<LO>(k.ideal.size())),
        s_(k.s),
        steps_(k.steps) {
    s_.assign(ideal_.size(), 0);
    steps_.clear();
    k_.best.clear();
    // Steps: for each row from the bottom, its not yet fixed free variables, then its pivot.
    std::vector<char>& fixed = k_.fixed;
    fixed.assign(static_cast<std::size_t>(c_), 0);
    for (LO r = static_cast<LO>(pivots_.size()) - 1; r >= 0; --r) {
      for (LO j = pivots_[r] + 1; j < c_; ++j)
        if (!fixed[j] && row(r)[j] != 0) {
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
  [[nodiscard]] bool found() const { return !k_.best.empty(); }
  [[nodiscard]] double best_energy() const { return best_energy_; }
  [[nodiscard]] int attempts() const { return attempts_; }

 private:
  [[nodiscard]] const Int* row(LO r) const {
    return rows_.data() + static_cast<std::size_t>(r) * (c_ + 1);
  }

  // Returns false when the attempt budget is spent.
  bool descend(std::size_t k) {
    if (k == steps_.size()) {
      leaf();
      return true;
    }
    const ChordWork::Step& st = steps_[k];
    if (st.pivot_row != kNoIndex) {
      const Int* r = row(st.pivot_row);
      Int sum = r[c_];
      for (LO j = st.var + 1; j < c_; ++j) sum -= r[j] * s_[j];
      const Int a = r[st.var];
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
    if (k_.best.empty() || e < best_energy_) {
      k_.best = s_;
      best_energy_ = e;
    }
  }

  ChordWork& k_;
  const std::vector<Int>& rows_;
  const std::vector<LO>& pivots_;
  const std::vector<double>& ideal_;
  const std::vector<Int>& upper_;
  std::span<const int> w_;
  std::span<const LO> rhs_;
  int max_attempts_;
  LO c_;
  std::vector<Int>& s_;
  std::vector<ChordWork::Step>& steps_;
  double best_energy_ = std::numeric_limits<double>::max();
  int attempts_ = 0;
};

// solve_chords in the buffers of `k`: the ideal goes to k.ideal, the solution (when found) to
// k.best; returns (found, energy, attempts).
struct ChordResult {
  bool found = false;
  double energy = 0;
  int attempts = 0;
};

ChordResult solve_chords_in(ChordWork& k, std::span<const int> w, int num_sides, LO num_chords,
                            std::span<const LO> side_edges, const MatchOptions& options) {
  const int m = num_sides;
  const LO c = num_chords;
  ChordResult out;
  k.best.clear();

  // Balanced ideal: each side's edges shared equally among its chord slots.
  std::vector<Int>& slots = k.slots;
  slots.assign(static_cast<std::size_t>(m), 0);
  for (int i = 0; i < m; ++i)
    for (LO j = 0; j < c; ++j) slots[i] += w[i * c + j];
  k.ideal.assign(static_cast<std::size_t>(c), 1.0);
  std::vector<Int>& upper = k.upper;
  upper.assign(static_cast<std::size_t>(c), std::numeric_limits<Int>::max());
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
    if (count > 0) k.ideal[j] = sum / static_cast<double>(count);
    if (count == 0) upper[j] = 1;
    if (upper[j] < 1) return out;
  }

  // Integer row echelon form of [w | N], fraction-free; rows of c + 1 entries, flat.
  const std::size_t width = static_cast<std::size_t>(c) + 1;
  std::vector<Int>& rows = k.rows;
  rows.resize(static_cast<std::size_t>(m) * width);
  const auto row = [&](int i) { return std::span<Int>(rows.data() + i * width, width); };
  for (int i = 0; i < m; ++i) {
    for (LO j = 0; j < c; ++j) rows[i * width + j] = w[i * c + j];
    rows[i * width + c] = side_edges[i];
  }
  std::vector<LO>& pivots = k.pivots;
  pivots.clear();
  int r = 0;
  for (LO col = 0; col < c && r < m; ++col) {
    int best = -1;
    for (int i = r; i < m; ++i)
      if (rows[i * width + col] != 0 &&
          (best < 0 || std::llabs(rows[i * width + col]) < std::llabs(rows[best * width + col])))
        best = i;
    if (best < 0) continue;
    if (best != r) std::swap_ranges(row(r).begin(), row(r).end(), row(best).begin());
    const std::span<Int> pr = row(r);
    if (pr[col] < 0)
      for (Int& x : pr) x = -x;
    for (int i = r + 1; i < m; ++i) {
      const std::span<Int> ri = row(i);
      if (ri[col] == 0) continue;
      const Int g = std::gcd(pr[col], ri[col]);
      const Int fr = ri[col] / g, fi = pr[col] / g;
      for (std::size_t j = 0; j < width; ++j) ri[j] = ri[j] * fi - pr[j] * fr;
      reduce_row(ri);
    }
    pivots.push_back(col);
    ++r;
  }
  for (int i = r; i < m; ++i)
    if (rows[i * width + c] != 0) return out;  // 0 = nonzero: inconsistent counts
  rows.resize(static_cast<std::size_t>(r) * width);

  EchelonSearch search(k, w, side_edges, options.max_attempts);
  search.run();
  out.attempts = search.attempts();
  if (!search.found()) return out;
  out.found = true;
  out.energy = search.best_energy();
  return out;
}

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
  ChordWork k;
  const ChordResult r = solve_chords_in(k, w, m, c, side_edges, options);
  ChordSolution out;
  out.ideal = std::move(k.ideal);
  out.attempts = r.attempts;
  if (!r.found) return out;
  out.found = true;
  out.s.assign(k.best.begin(), k.best.end());
  out.energy = r.energy;
  return out;
}

std::vector<PatternMatch> match_patterns(std::span<const Pattern> patterns,
                                         std::span<const LO> side_edges,
                                         const MatchOptions& options, bool cornerless) {
  const int m = static_cast<int>(side_edges.size());
  std::vector<PatternMatch> out;
  if (m == 0 || (cornerless && m != 1)) return out;
  ChordWork work;
  std::vector<LO> counts(static_cast<std::size_t>(m));
  std::vector<LO> seen;
  std::vector<std::size_t> seen_at;
  for (LO p = 0; p < static_cast<LO>(patterns.size()); ++p) {
    const Pattern& pat = patterns[p];
    if (pat.num_sides() != m || pat.cornerless() != cornerless) continue;
    QSMESH_CHECK(
        pat.num_chords >= 1 && pat.w.size() == static_cast<std::size_t>(m) * pat.num_chords,
        "solve_chords: w has " << pat.w.size() << " entries, not " << m << " x " << pat.num_chords);
    // Subdivisions seen along each cavity side, in cavity order: equal ones give the same mesh.
    // Each key flat (per cavity side, its length then its subdivisions), the keys one after the
    // other in `seen` from the offsets in `seen_at`: at most 2m of them, compared in turn.
    seen.clear();
    seen_at.clear();
    std::vector<PatternMatch> found;
    const LO nb = static_cast<LO>(pat.boundary.size());
    for (const bool reversed : {false, true})
      for (int start = 0; start < m; ++start) {
        for (int i = 0; i < m; ++i)
          counts[i] = side_edges[(((reversed ? start - i : start + i) % m) + m) % m];
        const ChordResult sol = solve_chords_in(work, pat.w, m, pat.num_chords, counts, options);
        if (!sol.found) continue;
        const std::size_t at = seen.size();
        for (int side = 0; side < m; ++side) {
          // The pattern side on this cavity side: side = start + i (reversed: start - i) mod m.
          const int i = ((reversed ? start - side : side - start) % m + m) % m;
          const LO first = pat.side_start[i];
          const LO end = i + 1 < m ? pat.side_start[i + 1] : nb;
          seen.push_back(end - first);
          for (LO k = first; k < end; ++k)
            seen.push_back(static_cast<LO>(
                work.best
                    [pat.edge_chord[pat.boundary_edge[reversed ? end - 1 - (k - first) : k]]]));
        }
        bool repeat = false;
        for (std::size_t e = 0; e < seen_at.size() && !repeat; ++e) {
          const std::size_t b = seen_at[e], n = (e + 1 < seen_at.size() ? seen_at[e + 1] : at) - b;
          repeat =
              n == seen.size() - at && std::equal(seen.begin() + static_cast<std::ptrdiff_t>(b),
                                                  seen.begin() + static_cast<std::ptrdiff_t>(b + n),
                                                  seen.begin() + static_cast<std::ptrdiff_t>(at));
        }
        if (repeat) {
          seen.resize(at);
          continue;
        }
        seen_at.push_back(at);
        PatternMatch match;
        match.pattern = p;
        match.start = start;
        match.reversed = reversed;
        match.chords.assign(work.best.begin(), work.best.end());
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
