#include "qsmesh/qstruct/balance.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <tuple>

#include "qsmesh/core/error.hpp"

namespace qsmesh::qstruct {

namespace {

// One target face: the curve of each loop use and the side it belongs to.
struct FaceSidesOfUses {
  int num_sides = 0;
  std::vector<std::pair<LO, int>> uses;  // (curve, side)
  bool rectangle = false;  // four sides, opposite lengths within BalanceOptions::grid_length_ratio
};

bool is_grid(const std::vector<LO>& n) { return n.size() == 4 && n[0] == n[2] && n[1] == n[3]; }

std::vector<LO> side_counts(const FaceSidesOfUses& f, const std::vector<int>& edges) {
  std::vector<LO> n(static_cast<std::size_t>(f.num_sides), 0);
  for (const auto& [c, s] : f.uses) n[s] += edges[c];
  return n;
}

// How far the sides are from fitting a pattern; 0 when one fits or when the face is not one we
// know how to steer (5 or 6 sides, 2 sides).
int misfit(const std::vector<LO>& n, bool fits) {
  if (fits) return 0;
  if (n.size() == 4) return std::abs(n[0] - n[2]) + std::abs(n[1] - n[3]);
  if (n.size() == 3) {
    const LO big = *std::max_element(n.begin(), n.end());
    const LO sum = n[0] + n[1] + n[2];
    return std::max(0, 2 * big - sum + 2);
  }
  return 0;
}

// An even step of about half of d (0 when d is 2 or less).
int half_step(int d) {
  const int h = 2 * static_cast<int>(std::lround(static_cast<double>(d) / 4.0));
  return h == d ? 0 : h;
}

}  // namespace

std::vector<int> balance_curve_counts(const cad::CadModel& model,
                                      std::span<const mesh::CurveMesh> curves,
                                      const quantize::Quantization& q,
                                      std::span<const Pattern> patterns, std::span<const LO> fixed,
                                      const BalanceOptions& options, BalanceReport* report) {
  const LO nc = model.num_curves();
  QSMESH_CHECK(static_cast<LO>(curves.size()) == nc && static_cast<LO>(q.edges.size()) == nc &&
                   static_cast<LO>(q.ideal.size()) == nc,
               "balance: " << curves.size() << " curve meshes and " << q.edges.size()
                           << " counts for " << nc << " curves");
  const auto& cads = model.curves();
  std::vector<int> edges = q.edges;
  BalanceReport rep;

  // Variables: a chord of q moves as one, other curves alone. Variable ids: curve ids for curves
  // outside chords, nc + chord otherwise.
  std::vector<std::vector<LO>> chord_members(static_cast<std::size_t>(q.num_chords));
  for (LO c = 0; c < nc; ++c)
    if (q.curve2chord[c] != kNoIndex) chord_members[q.curve2chord[c]].push_back(c);
  const auto var_of = [&](LO c) {
    return q.curve2chord[c] == kNoIndex ? c : nc + q.curve2chord[c];
  };
  const auto members = [&](LO v) -> std::vector<LO> {
    return v < nc ? std::vector<LO>{v} : chord_members[v - nc];
  };
  std::vector<char> frozen(static_cast<std::size_t>(nc + q.num_chords), 0);
  for (const LO c : fixed)
    if (c >= 0 && c < nc) frozen[var_of(c)] = 1;
  for (LO c = 0; c < nc; ++c)
    if (cads[c].degenerate || edges[c] <= 0) frozen[var_of(c)] = 1;

  // Target faces and their sides.
  std::vector<FaceSidesOfUses> targets;
  for (LO f = 0; f < model.num_faces(); ++f) {
    const cad::Face& face = model.faces()[f];
    if (face.loops.size() != 1 || !face.loops_closed) continue;
    const auto& uses = face.loops[0].uses;
    if (std::any_of(uses.begin(), uses.end(),
                    [&](const cad::CurveUse& u) { return cads[u.curve].degenerate; }))
      continue;
    FaceSides fs;
    try {
      const auto surface = model.face_geometry(f);
      fs = face_sides(model, f, *surface, curves, options.faces);
    } catch (const Error&) {
      continue;  // the pattern path refuses these faces too
    }
    const int m = static_cast<int>(fs.corners.size());
    if (m < 2 || m > 6) continue;
    FaceSidesOfUses t;
    t.num_sides = m;
    std::vector<double> length(static_cast<std::size_t>(m), 0.0);
    for (std::size_t u = 0; u < uses.size(); ++u) {
      t.uses.emplace_back(uses[u].curve, side_of(fs, fs.use_start[u]));
      length[t.uses.back().second] += cads[uses[u].curve].length;
    }
    const auto close = [&](double a, double b) {
      return options.grid_length_ratio >= 1 && a > 0 && b > 0 &&
             std::max(a, b) <= options.grid_length_ratio * std::min(a, b);
    };
    t.rectangle = m == 4 && close(length[0], length[2]) && close(length[1], length[3]);
    targets.push_back(std::move(t));
  }
  rep.faces_considered = static_cast<LO>(targets.size());
  std::vector<std::vector<LO>> curve2targets(static_cast<std::size_t>(nc));
  for (LO i = 0; i < static_cast<LO>(targets.size()); ++i)
    for (const auto& [c, s] : targets[i].uses)
      // Faces come in increasing i: a repeat is always the last entry (a seam used twice).
      if (curve2targets[c].empty() || curve2targets[c].back() != i) curve2targets[c].push_back(i);

  const auto fits = [&](const std::vector<LO>& n) {
    return !match_patterns(patterns, n, options.faces.match).empty();
  };
  std::vector<char> fit(targets.size());
  for (std::size_t i = 0; i < targets.size(); ++i) fit[i] = fits(side_counts(targets[i], edges));
  rep.fitting_before = static_cast<LO>(std::count(fit.begin(), fit.end(), 1));
  const auto count_grids = [&] {
    LO g = 0;
    for (const auto& t : targets) g += is_grid(side_counts(t, edges)) ? 1 : 0;
    return g;
  };
  rep.grids_before = count_grids();

  const auto allowed = [&](LO c, int n) {
    const int lo = (cads[c].corners[0] == cads[c].corners[1] ? 4 : 2) - edges[c] % 2;
    if (n < lo) return false;
    const double ideal = q.ideal[c];
    const double now = std::abs(edges[c] - ideal), next = std::abs(n - ideal);
    return next <= std::max(2.0, options.max_change * ideal) + 1e-9 || next < now;
  };

  // A move adds `delta` edges to every curve of one variable (its members).
  const auto move_allowed = [&](const std::vector<LO>& mem, int delta) {
    return std::all_of(mem.begin(), mem.end(), [&](LO c) { return allowed(c, edges[c] + delta); });
  };
  const auto relative_change = [&](const std::vector<LO>& mem, int delta) {
    double ideal_sum = 0;
    for (const LO c : mem) ideal_sum += std::max(1.0, q.ideal[c]);
    return std::abs(delta) * static_cast<double>(mem.size()) / ideal_sum;
  };
  // The targets a move of these curves touches, each once, in increasing order.
  const auto touched_by = [&](const std::vector<LO>& mem) {
    std::vector<LO> touched;
    for (const LO c : mem)
      touched.insert(touched.end(), curve2targets[c].begin(), curve2targets[c].end());
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    return touched;
  };
  // Side counts of target t once the move is made.
  const auto moved_counts = [&](LO t, const std::vector<LO>& mem, int delta) {
    std::vector<LO> n = side_counts(targets[t], edges);
    for (const auto& [c, s] : targets[t].uses)
      if (std::find(mem.begin(), mem.end(), c) != mem.end()) n[s] += delta;
    return n;
  };
  // The movable variables of a side of t, each once, in increasing order.
  const auto side_vars = [&](const FaceSidesOfUses& t, int side) {
    std::vector<LO> v;
    for (const auto& [c, s] : t.uses)
      if (s == side && !frozen[var_of(c)]) v.push_back(var_of(c));
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    return v;
  };

  struct Eval {
    bool ok = false;
    int gain = 0;     // fitting faces gained
    int dmisfit = 0;  // change of the misfit of the touched faces
    double rel = 0;   // relative size of the change
    std::vector<std::pair<LO, char>> fit_after;
  };
  const auto evaluate = [&](LO var, int delta) {
    Eval e;
    const std::vector<LO> mem = members(var);
    if (!move_allowed(mem, delta)) return e;
    for (const LO t : touched_by(mem)) {
      const auto n = moved_counts(t, mem, delta);
      const bool after = fits(n);
      e.fit_after.emplace_back(t, after ? 1 : 0);
      e.gain += (after ? 1 : 0) - fit[t];
      e.dmisfit += misfit(n, after) - misfit(side_counts(targets[t], edges), fit[t] != 0);
    }
    e.rel = relative_change(mem, delta);
    e.ok = e.gain > 0 || (e.gain == 0 && e.dmisfit < 0);
    return e;
  };

  for (int pass = 0; pass < options.max_passes; ++pass) {
    ++rep.passes;
    bool any = false;
    for (std::size_t i = 0; i < targets.size(); ++i) {
      if (fit[i]) continue;
      const FaceSidesOfUses& t = targets[i];
      const auto n = side_counts(t, edges);
      // Candidate moves: (variable, delta) pairs that shrink the failing differences.
      std::vector<std::pair<LO, int>> moves;
      // Only even moves: an odd one would make the loops of the moved curves odd.
      const auto add = [&](int side, int delta) {
        if (delta == 0 || delta % 2 != 0) return;
        for (const LO v : side_vars(t, side)) moves.emplace_back(v, delta);
      };
      if (t.num_sides == 4) {
        for (int a = 0; a < 2; ++a) {
          const int d = n[a] - n[a + 2];
          for (const int step : {d, half_step(d)}) {
            add(a, -step);
            add(a + 2, step);
          }
        }
      } else if (t.num_sides == 3) {
        const int big = static_cast<int>(std::max_element(n.begin(), n.end()) - n.begin());
        const int excess = misfit(n, false);
        for (const int step : {excess, half_step(excess)})
          for (int s = 0; s < 3; ++s) add(s, s == big ? -step : step);
      }
      if (moves.empty()) continue;
      std::sort(moves.begin(), moves.end());
      moves.erase(std::unique(moves.begin(), moves.end()), moves.end());
      Eval best;
      LO best_var = kNoIndex;
      int best_delta = 0;
      for (const auto& [v, delta] : moves) {
        Eval e = evaluate(v, delta);
        if (!e.ok) continue;
        const auto key = [](const Eval& x) { return std::make_tuple(-x.gain, x.dmisfit, x.rel); };
        if (best_var == kNoIndex || key(e) < key(best)) {
          best = std::move(e);
          best_var = v;
          best_delta = delta;
        }
      }
      if (best_var == kNoIndex) continue;
      for (const LO c : members(best_var)) edges[c] += best_delta;
      for (const auto& [tt, f] : best.fit_after) fit[tt] = f;
      any = true;
    }
    if (!any) break;
  }
  // Rectangles fitted only by a transition: their counts differ through the size map alone (the
  // sides are as long as each other), and a transition fill shears its rows to absorb that. Equal
  // counts give a grid. A move must not cost any face its fit or its grid, and must bring the
  // rectangles' opposite counts closer in total.
  const auto grid_misfit = [](const FaceSidesOfUses& t, const std::vector<LO>& n) {
    return t.rectangle ? static_cast<int>(std::abs(n[0] - n[2]) + std::abs(n[1] - n[3])) : 0;
  };
  for (int pass = 0; pass < options.max_passes; ++pass) {
    bool any = false;
    for (std::size_t i = 0; i < targets.size(); ++i) {
      const FaceSidesOfUses& t = targets[i];
      if (!t.rectangle || !fit[i]) continue;
      const auto n = side_counts(t, edges);
      if (is_grid(n)) continue;
      LO best_var = kNoIndex;
      int best_delta = 0, best_gain = 0, best_dmis = 0;
      double best_rel = 0;
      for (int a = 0; a < 2; ++a) {
        const int d = n[a] - n[a + 2];
        if (d == 0 || d % 2 != 0) continue;
        const std::array<std::pair<int, int>, 2> side_moves{{{a, -d}, {a + 2, d}}};
        for (const auto& [side, delta] : side_moves)
          for (const LO var : side_vars(t, side)) {
            const std::vector<LO> mem = members(var);
            if (!move_allowed(mem, delta)) continue;
            int gain = 0, dmis = 0;
            bool loses = false;
            for (const LO tt : touched_by(mem)) {
              const auto before = side_counts(targets[tt], edges);
              const auto after = moved_counts(tt, mem, delta);
              const bool was = is_grid(before), is = is_grid(after);
              loses = loses || (fit[tt] && !fits(after)) || (was && !is);
              gain += (is ? 1 : 0) - (was ? 1 : 0);
              dmis += grid_misfit(targets[tt], after) - grid_misfit(targets[tt], before);
            }
            if (loses || dmis >= 0) continue;
            const double rel = relative_change(mem, delta);
            const auto key = std::make_tuple(-gain, dmis, rel, var);
            if (best_var == kNoIndex ||
                key < std::make_tuple(-best_gain, best_dmis, best_rel, best_var)) {
              best_var = var;
              best_delta = delta;
              best_gain = gain;
              best_dmis = dmis;
              best_rel = rel;
            }
          }
      }
      if (best_var == kNoIndex) continue;
      const std::vector<LO> mem = members(best_var);
      for (const LO c : mem) edges[c] += best_delta;
      for (const LO tt : touched_by(mem)) fit[tt] = fits(side_counts(targets[tt], edges)) ? 1 : 0;
      any = true;
    }
    if (!any) break;
  }
  rep.grids_after = count_grids();
  rep.fitting_after = static_cast<LO>(std::count(fit.begin(), fit.end(), 1));
  for (LO c = 0; c < nc; ++c) rep.curves_changed += edges[c] != q.edges[c] ? 1 : 0;
  if (report != nullptr) *report = rep;
  return edges;
}

}  // namespace qsmesh::qstruct
