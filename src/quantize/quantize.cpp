#include "qsmesh/quantize/quantize.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <queue>
#include <sstream>
#include <string>

#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/predicates.hpp"

namespace qsmesh::quantize {

namespace {

// ∫ dl / s over a straight segment of length len with s linear from s0 to s1: len/s0 * ln(1+r)/r,
// r = (s1 - s0)/s0. The series keeps it accurate when s barely varies (r -> 0).
double segment_integral(double len, double s0, double s1) {
  const double r = (s1 - s0) / s0;
  const double phi = std::abs(r) < 1e-4 ? 1 - r / 2 + r * r / 3 - r * r * r / 4 : std::log1p(r) / r;
  return len / s0 * phi;
}

// Inverse of the above: the fraction a/len of the segment where ∫_0^a dl / s reaches g.
double segment_fraction(double len, double s0, double s1, double g) {
  if (len <= 0) return 0;
  const double r = (s1 - s0) / s0;
  const double k = g * s0 / len;
  const double kr = k * r;
  const double f = std::abs(kr) < 1e-8 ? k * (1 + kr / 2) : std::expm1(kr) / r;
  return std::clamp(f, 0.0, 1.0);
}

void check_sizes(LO c, const mesh::CurveMesh& m, const std::vector<double>& s) {
  QSMESH_CHECK(s.size() == m.points.size(), "curve " << c << ": " << s.size() << " sizes for "
                                                     << m.points.size() << " background vertices");
  QSMESH_CHECK(m.t.size() == m.points.size() && m.points.size() >= 2,
               "curve " << c << ": background mesh has " << m.points.size() << " points and "
                        << m.t.size() << " parameters");
  for (std::size_t i = 0; i < s.size(); ++i)
    QSMESH_CHECK(std::isfinite(s[i]) && s[i] > 0,
                 "curve " << c << ": size " << s[i] << " at background vertex " << i);
}

// Cumulative ∫ dl / s at the background vertices of one curve.
std::vector<double> cumulative(const mesh::CurveMesh& m, const std::vector<double>& s) {
  std::vector<double> f(m.points.size(), 0.0);
  for (std::size_t i = 0; i + 1 < m.points.size(); ++i)
    f[i + 1] = f[i] + segment_integral(distance(m.points[i], m.points[i + 1]), s[i], s[i + 1]);
  return f;
}

struct UnionFind {
  std::vector<LO> parent;
  explicit UnionFind(LO n) : parent(static_cast<std::size_t>(n)) {
    std::iota(parent.begin(), parent.end(), 0);
  }
  LO find(LO a) {
    while (parent[a] != a) {
      parent[a] = parent[parent[a]];
      a = parent[a];
    }
    return a;
  }
  // The smaller id becomes the root: the result does not depend on the order of the unions.
  void join(LO a, LO b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (b < a) std::swap(a, b);
    parent[b] = a;
  }
};

// Arc length at the background vertices of one curve.
std::vector<double> arc_lengths(const mesh::CurveMesh& m) {
  std::vector<double> arc(m.points.size(), 0.0);
  for (std::size_t i = 0; i + 1 < m.points.size(); ++i)
    arc[i + 1] = arc[i] + distance(m.points[i], m.points[i + 1]);
  return arc;
}

// Normalised ∫ dl / s of a curve (0 at its start, 1 at its end) at the arc-length fractions
// k / samples, k = 0 .. samples. Empty when the curve has no length or no size integral.
std::vector<double> normalised_profile(const mesh::CurveMesh& m, const std::vector<double>& s,
                                       int samples) {
  const std::vector<double> f = cumulative(m, s);
  const std::vector<double> arc = arc_lengths(m);
  if (!(f.back() > 0) || !(arc.back() > 0)) return {};
  std::vector<double> g(static_cast<std::size_t>(samples) + 1);
  std::size_t j = 0;
  const std::size_t last = arc.size() - 2;
  for (int k = 0; k <= samples; ++k) {
    const double x = arc.back() * k / samples;
    while (j < last && arc[j + 1] < x) ++j;
    const double len = arc[j + 1] - arc[j];
    const double a = std::clamp(x - arc[j], 0.0, len);
    const double sx = len > 0 ? s[j] + (s[j + 1] - s[j]) * a / len : s[j];
    g[k] = (f[j] + segment_integral(a, s[j], sx)) / f.back();
  }
  g.front() = 0;
  g.back() = 1;
  return g;
}

// Per curve: the profile it shares with the curves it faces across four-sided faces whose two
// pairs of opposite sides are joined in chords and about as long (empty: the curve keeps its own
// size integral). Why only those faces: they are the ones a grid or a transition pattern fills,
// whose rows run from one side to the other and shear when the two sides are graded differently
// (two circles of Block.stp 0.8 apart, graded 3:1 toward one end at different rates, gave a
// 44 x 4 grid SICN avg 0.62). Joining the faces with one joined pair as well also blends, say,
// a wing's leading and trailing edges, whose sizes differ for good reasons: wing_fuselage.step
// went from 873 to 984 interior irregular vertices that way. Opposite sides of very different
// lengths (the built-in example's wing root and tip, 4296 and 1828 long) bound a tapered face
// that no pattern fills well anyway; blending them cost its unstructured mesh SICN avg 0.895 ->
// 0.878. The curves of a set are oriented through the faces (opposite uses of a loop run in
// opposite directions); a set the faces orient inconsistently (a twisted band) keeps its own
// profiles.
std::vector<std::vector<double>> shared_profiles(const cad::CadModel& model,
                                                 std::span<const mesh::CurveMesh> curves,
                                                 std::span<const std::vector<double>> sizes,
                                                 const Quantization& q,
                                                 const PlaceOptions& options) {
  const int samples = options.profile_samples;
  const LO nc = model.num_curves();
  const auto cv = model.curves();
  const auto joined = [&](LO a, LO b) {
    return q.curve2chord[a] != kNoIndex && q.curve2chord[a] == q.curve2chord[b];
  };
  // Opposite pairs of the four-sided faces whose both pairs are joined (the faces a grid or a
  // transition pattern fills), with 0 when the two curves run the same way.
  std::vector<std::vector<std::pair<LO, int>>> links(static_cast<std::size_t>(nc));
  for (const cad::Face& face : model.faces()) {
    if (face.loops.size() != 1 || face.loops[0].uses.size() != 4 || !face.loops_closed) continue;
    const auto& uses = face.loops[0].uses;
    if (!(joined(uses[0].curve, uses[2].curve) && joined(uses[1].curve, uses[3].curve))) continue;
    for (int k = 0; k < 2; ++k) {
      const LO a = uses[k].curve, b = uses[k + 2].curve;
      if (!joined(a, b)) continue;
      const double la = cv[a].length, lb = cv[b].length;
      if (std::max(la, lb) > options.align_length_ratio * std::min(la, lb)) continue;
      const int flip = uses[k].reversed == uses[k + 2].reversed ? 1 : 0;
      links[a].emplace_back(b, flip);
      links[b].emplace_back(a, flip);
    }
  }
  std::vector<int> flip(static_cast<std::size_t>(nc), -1);
  std::vector<std::vector<double>> out(static_cast<std::size_t>(nc));
  for (LO root = 0; root < nc; ++root) {
    if (flip[root] != -1 || links[root].empty()) continue;
    std::vector<LO> mem{root};
    bool consistent = true;
    std::vector<LO> stack{root};
    flip[root] = 0;
    while (!stack.empty()) {
      const LO c = stack.back();
      stack.pop_back();
      for (const auto& [o, f] : links[c]) {
        const int want = flip[c] ^ f;
        if (flip[o] == -1) {
          flip[o] = want;
          stack.push_back(o);
          mem.push_back(o);
        } else if (flip[o] != want) {
          consistent = false;
        }
      }
    }
    if (!consistent || mem.size() < 2) continue;
    // Chords never hold degenerate curves (quantize_curves), so every member has a polyline.
    std::vector<double> shared(static_cast<std::size_t>(samples) + 1, 0.0);
    for (const LO c : mem) {
      const std::vector<double> g = normalised_profile(curves[c], sizes[c], samples);
      if (g.empty()) {
        consistent = false;
        break;
      }
      for (int k = 0; k <= samples; ++k) shared[k] += flip[c] != 0 ? 1 - g[samples - k] : g[k];
    }
    if (!consistent) continue;
    for (double& v : shared) v /= static_cast<double>(mem.size());
    for (const LO c : mem) {
      auto& p = out[c];
      p.resize(shared.size());
      for (int k = 0; k <= samples; ++k) p[k] = flip[c] != 0 ? 1 - shared[samples - k] : shared[k];
    }
  }
  return out;
}

}  // namespace

std::vector<double> ideal_edge_counts(std::span<const mesh::CurveMesh> curves,
                                      std::span<const std::vector<double>> sizes) {
  QSMESH_CHECK(sizes.size() == curves.size(),
               sizes.size() << " size lists for " << curves.size() << " curves");
  std::vector<double> ideal(curves.size(), 0.0);
  for (std::size_t c = 0; c < curves.size(); ++c) {
    check_sizes(static_cast<LO>(c), curves[c], sizes[c]);
    ideal[c] = cumulative(curves[c], sizes[c]).back();
  }
  return ideal;
}

namespace {

// One parity condition of the halved boundaries (paper 000 Sec. 5.2): the curve uses of a loop,
// or of the stretch of a loop between two of its poles, whose counts must sum to an even number
// (background::halved_face_boundary keeps every pole on a halved vertex).
struct ParityRow {
  LO face = kNoIndex, loop = kNoIndex;
  bool between_poles = false;
  std::vector<LO> curves;  // one entry per use (a seam twice)
};

std::vector<ParityRow> parity_rows(const cad::CadModel& model) {
  std::vector<ParityRow> rows;
  for (LO f = 0; f < model.num_faces(); ++f) {
    const cad::Face& face = model.faces()[f];
    for (LO l = 0; l < static_cast<LO>(face.loops.size()); ++l) {
      const auto& uses = face.loops[l].uses;
      std::vector<std::size_t> poles;
      for (std::size_t u = 0; u < uses.size(); ++u)
        if (model.curves()[uses[u].curve].degenerate) poles.push_back(u);
      if (poles.size() <= 1) {
        ParityRow row{f, l, false, {}};
        for (const cad::CurveUse& use : uses)
          if (!model.curves()[use.curve].degenerate) row.curves.push_back(use.curve);
        rows.push_back(std::move(row));
        continue;
      }
      for (std::size_t i = 0; i < poles.size(); ++i) {
        ParityRow row{f, l, true, {}};
        const std::size_t from = poles[i], to = poles[(i + 1) % poles.size()];
        for (std::size_t u = (from + 1) % uses.size(); u != to; u = (u + 1) % uses.size())
          row.curves.push_back(uses[u].curve);
        rows.push_back(std::move(row));
      }
    }
  }
  return rows;
}

// Variables of the parity problem: groups of curves that share one count (a chord, or a curve
// alone), each with the rows where it appears an odd number of times and the cost of changing
// its parity.
struct ParityProblem {
  std::vector<ParityRow> rows;
  std::vector<char> odd;                  // per row: the parity of its sum now
  std::vector<std::vector<LO>> var_rows;  // per variable, sorted
  std::vector<double> cost;               // per variable, >= 0
};

// The variables to flip so that every row is even, or, when none can, the rows whose sum is a
// contradiction (every variable an even number of times, the fixed counts odd in total).
struct ParitySolution {
  std::vector<char> flip;
  std::vector<LO> conflict;  // non-empty: no solution
};

ParitySolution solve_parity(const ParityProblem& pb) {
  const auto nr = static_cast<LO>(pb.rows.size());
  const auto nv = static_cast<LO>(pb.var_rows.size());
  ParitySolution out;
  out.flip.assign(static_cast<std::size_t>(nv), 0);
  std::vector<char> odd = pb.odd;
  std::vector<std::vector<LO>> row_vars(static_cast<std::size_t>(nr));
  for (LO v = 0; v < nv; ++v)
    for (const LO r : pb.var_rows[v]) row_vars[r].push_back(v);
  const auto flip = [&](LO v) {
    out.flip[v] ^= 1;
    for (const LO r : pb.var_rows[v]) odd[r] ^= 1;
  };
  // A loop whose curves are all prescribed is the plainest contradiction to name (on a closed
  // shell, the other loops together contradict too).
  for (LO r = 0; r < nr; ++r)
    if (odd[r] != 0 && row_vars[r].empty()) {
      out.conflict = {r};
      return out;
    }
  // Each odd row is paired with the nearest other odd row, or with an open boundary (a variable
  // in one row only), along the cheapest chain of variables that each appear in two rows: a
  // shortest path, so the counts that change are few and near the prescriptions.
  const LO sink = nr;
  std::vector<double> dist(static_cast<std::size_t>(nr) + 1,
                           std::numeric_limits<double>::infinity());
  std::vector<LO> via(static_cast<std::size_t>(nr) + 1, kNoIndex),
      from(static_cast<std::size_t>(nr) + 1, kNoIndex);
  std::vector<LO> touched;
  for (LO t = 0; t < nr; ++t) {
    if (odd[t] == 0) continue;
    for (const LO x : touched) {
      dist[x] = std::numeric_limits<double>::infinity();
      via[x] = from[x] = kNoIndex;
    }
    touched.clear();
    using Item = std::pair<double, LO>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
    dist[t] = 0;
    touched.push_back(t);
    queue.push({0.0, t});
    LO target = kNoIndex;
    while (!queue.empty()) {
      const auto [d, r] = queue.top();
      queue.pop();
      if (d > dist[r]) continue;
      if (r == sink || (r != t && odd[r] != 0)) {
        target = r;
        break;
      }
      for (const LO v : row_vars[r]) {
        const auto& vr = pb.var_rows[v];
        if (vr.size() > 2) continue;  // a variable of three or more rows: the dense step
        const LO next = vr.size() == 1 ? sink : (vr[0] == r ? vr[1] : vr[0]);
        const double nd = d + pb.cost[v];
        if (nd < dist[next]) {
          if (std::isinf(dist[next])) touched.push_back(next);
          dist[next] = nd;
          via[next] = v;
          from[next] = r;
          queue.push({nd, next});
        }
      }
    }
    if (target != kNoIndex) {
      for (LO r = target; r != t; r = from[r]) flip(via[r]);
      continue;
    }
    // No chain: the rows reachable from t through any variable, solved exactly (Gaussian
    // elimination over GF(2), cheapest variables first as pivots), or shown contradictory.
    std::vector<LO> comp_rows{t}, comp_vars;
    std::vector<char> row_seen(static_cast<std::size_t>(nr), 0),
        var_seen(static_cast<std::size_t>(nv), 0);
    row_seen[t] = 1;
    for (std::size_t i = 0; i < comp_rows.size(); ++i)
      for (const LO v : row_vars[comp_rows[i]]) {
        if (var_seen[v] != 0) continue;
        var_seen[v] = 1;
        comp_vars.push_back(v);
        for (const LO r : pb.var_rows[v])
          if (row_seen[r] == 0) {
            row_seen[r] = 1;
            comp_rows.push_back(r);
          }
      }
    std::stable_sort(comp_vars.begin(), comp_vars.end(),
                     [&](LO a, LO b) { return pb.cost[a] < pb.cost[b]; });
    const std::size_t nvc = comp_vars.size(), nrc = comp_rows.size();
    const std::size_t bits = nvc + nrc + 1, words = (bits + 63) / 64;
    std::vector<std::vector<std::uint64_t>> m(nrc, std::vector<std::uint64_t>(words, 0));
    const auto set = [&](std::vector<std::uint64_t>& row, std::size_t b) {
      row[b / 64] ^= std::uint64_t{1} << (b % 64);
    };
    const auto get = [&](const std::vector<std::uint64_t>& row, std::size_t b) {
      return ((row[b / 64] >> (b % 64)) & 1U) != 0;
    };
    std::vector<std::size_t> col_of(static_cast<std::size_t>(nv), 0);
    for (std::size_t j = 0; j < nvc; ++j) col_of[comp_vars[j]] = j;
    std::vector<std::size_t> local_row(static_cast<std::size_t>(nr), 0);
    for (std::size_t i = 0; i < nrc; ++i) local_row[comp_rows[i]] = i;
    for (std::size_t j = 0; j < nvc; ++j)
      for (const LO r : pb.var_rows[comp_vars[j]]) set(m[local_row[r]], j);
    for (std::size_t i = 0; i < nrc; ++i) {
      set(m[i], nvc + i);
      if (odd[comp_rows[i]] != 0) set(m[i], bits - 1);
    }
    std::vector<std::size_t> pivot_row_of_col(nvc, nrc);
    std::size_t rank = 0;
    for (std::size_t j = 0; j < nvc && rank < nrc; ++j) {
      std::size_t p = rank;
      while (p < nrc && !get(m[p], j)) ++p;
      if (p == nrc) continue;
      std::swap(m[p], m[rank]);
      for (std::size_t i = 0; i < nrc; ++i)
        if (i != rank && get(m[i], j))
          for (std::size_t w = 0; w < words; ++w) m[i][w] ^= m[rank][w];
      pivot_row_of_col[j] = rank++;
    }
    for (std::size_t i = rank; i < nrc; ++i)
      if (get(m[i], bits - 1)) {
        for (std::size_t k = 0; k < nrc; ++k)
          if (get(m[i], nvc + k)) out.conflict.push_back(comp_rows[k]);
        std::sort(out.conflict.begin(), out.conflict.end());
        return out;
      }
    for (std::size_t j = 0; j < nvc; ++j)
      if (pivot_row_of_col[j] < nrc && get(m[pivot_row_of_col[j]], bits - 1)) flip(comp_vars[j]);
  }
  return out;
}

// The message for rows that no counts of the free curves can make even.
std::string parity_conflict_message(const cad::CadModel& model, const ParityProblem& pb,
                                    const std::vector<LO>& rows,
                                    const std::vector<int>& prescribed) {
  // The prescribed curves an odd number of times in these rows, with their counts.
  std::map<LO, int> times;
  for (const LO r : rows)
    for (const LO c : pb.rows[r].curves)
      if (prescribed[c] != 0) times[c] += 1;
  std::ostringstream os;
  const auto where = [&](const ParityRow& row) {
    os << "face " << row.face << " (loop " << row.loop
       << (row.between_poles ? ", between two poles" : "") << ")";
  };
  std::ostringstream curves;
  int total = 0, listed = 0;
  for (const auto& [c, k] : times) {
    if (k % 2 == 0) continue;
    total += prescribed[c];
    if (listed++ > 0) curves << ", ";
    curves << c << ":" << prescribed[c];
  }
  (void)model;
  if (rows.size() == 1) {
    where(pb.rows[rows[0]]);
    os << ": its prescribed curves " << curves.str() << " sum to " << total
       << " edges and no other curve of it can make the count even";
  } else {
    os << "the loops of ";
    for (std::size_t i = 0; i < rows.size() && i < 6; ++i) {
      if (i > 0) os << ", ";
      where(pb.rows[rows[i]]);
    }
    if (rows.size() > 6) os << " and " << rows.size() - 6 << " more";
    os << " cannot all have even counts: together they hold the prescribed curves " << curves.str()
       << " (" << total
       << " edges) an odd number of times and every other curve an even number of times";
  }
  os << "; all-quad meshing by midpoint subdivision needs an even count on every loop";
  return os.str();
}

// Thrown by quantize_level when the parities cannot be met with the chords it was given.
struct ParityConflict {
  std::string message;
};

}  // namespace

void check_prescription_parity(const cad::CadModel& model,
                               std::span<const std::pair<LO, int>> prescribed) {
  const LO nc = model.num_curves();
  std::vector<int> fixed(static_cast<std::size_t>(nc), 0);
  for (const auto& [c, n] : prescribed)
    if (c >= 0 && c < nc && n > 0 && fixed[c] == 0) fixed[c] = n;
  ParityProblem pb;
  pb.rows = parity_rows(model);
  // Every curve not prescribed is a variable of its own, starting even.
  std::vector<LO> var_of(static_cast<std::size_t>(nc), kNoIndex);
  for (LO c = 0; c < nc; ++c)
    if (fixed[c] == 0 && !model.curves()[c].degenerate) {
      var_of[c] = static_cast<LO>(pb.var_rows.size());
      pb.var_rows.emplace_back();
      pb.cost.push_back(1.0);
    }
  pb.odd.assign(pb.rows.size(), 0);
  for (LO r = 0; r < static_cast<LO>(pb.rows.size()); ++r) {
    std::map<LO, int> times;
    for (const LO c : pb.rows[r].curves) {
      if (var_of[c] != kNoIndex)
        times[var_of[c]] ^= 1;
      else
        pb.odd[r] ^= static_cast<char>(fixed[c] % 2);
    }
    for (const auto& [v, t] : times)
      if (t != 0) pb.var_rows[v].push_back(r);
  }
  const ParitySolution sol = solve_parity(pb);
  if (!sol.conflict.empty())
    throw InputError(parity_conflict_message(model, pb, sol.conflict, fixed));
}

namespace {

// quantize_curves with the chords of `level`: 0 all, 1 only those holding a prescribed curve,
// 2 none. Throws ParityConflict when the loops cannot all be even so.
Quantization quantize_level(const cad::CadModel& model, std::span<const double> ideal,
                            const QuantizeOptions& options, int level) {
  const LO nc = model.num_curves();
  const auto curves = model.curves();
  QSMESH_CHECK(static_cast<LO>(ideal.size()) == nc,
               ideal.size() << " ideal edge counts for " << nc << " curves");
  for (LO c = 0; c < nc; ++c)
    QSMESH_CHECK(std::isfinite(ideal[c]) && ideal[c] >= 0,
                 "curve " << c << ": ideal edge count " << ideal[c]);
  QSMESH_CHECK(options.chord_ratio_limit >= 1,
               "chord_ratio_limit " << options.chord_ratio_limit << " is below 1");
  QSMESH_CHECK(options.chord_length_ratio_limit >= 1,
               "chord_length_ratio_limit " << options.chord_length_ratio_limit << " is below 1");

  Quantization q;
  q.ideal.assign(ideal.begin(), ideal.end());
  q.edges.assign(static_cast<std::size_t>(nc), 0);
  q.curve2chord.assign(static_cast<std::size_t>(nc), kNoIndex);

  // Curves joining the same two corners: each needs 2 edges or the two meshes would coincide.
  std::vector<bool> parallel(static_cast<std::size_t>(nc), false);
  {
    std::map<std::pair<LO, LO>, LO> first;
    for (LO c = 0; c < nc; ++c) {
      const auto& cv = curves[c];
      if (cv.degenerate || cv.corners[0] == cv.corners[1]) continue;
      const std::pair<LO, LO> key = std::minmax(cv.corners[0], cv.corners[1]);
      const auto [it, inserted] = first.emplace(key, c);
      if (!inserted) parallel[c] = parallel[it->second] = true;
    }
  }
  const auto closed = [&](LO c) { return curves[c].corners[0] == curves[c].corners[1]; };
  // Smallest count the rounding may give.
  const auto minimum = [&](LO c) {
    const bool coarse = options.even && options.halved_minimums;
    if (closed(c)) return options.even ? (coarse ? 6 : 4) : 3;
    if (parallel[c]) return coarse ? 4 : 2;
    return options.even ? 2 : 1;
  };
  // Smallest count a prescription may ask for: what makes a valid curve mesh.
  const auto hard_minimum = [&](LO c) { return closed(c) ? 3 : (parallel[c] ? 2 : 1); };

  // Chords of conformal four-sided faces.
  UnionFind uf(nc);
  std::vector<bool> in_chord(static_cast<std::size_t>(nc), false);
  for (const cad::Face& face : model.faces()) {
    if (face.loops.size() != 1 || face.loops[0].uses.size() != 4 || !face.loops_closed) continue;
    const auto& uses = face.loops[0].uses;
    for (int k = 0; k < 2; ++k) {
      const LO a = uses[k].curve, b = uses[k + 2].curve;
      if (curves[a].degenerate || curves[b].degenerate) continue;
      const double lo = std::min(ideal[a], ideal[b]), hi = std::max(ideal[a], ideal[b]);
      if (hi > options.chord_ratio_limit * lo) continue;
      const double short_side = std::min(curves[a].length, curves[b].length);
      const double long_side = std::max(curves[a].length, curves[b].length);
      if (long_side > options.chord_length_ratio_limit * short_side) continue;
      uf.join(a, b);
      in_chord[a] = in_chord[b] = true;
    }
  }
  if (level > 0) {
    // Relaxed chords: a prescribed curve keeps its chord at level 1, nothing at level 2.
    std::vector<char> keep(static_cast<std::size_t>(nc), 0);
    if (level == 1)
      for (const auto& [c, n] : options.prescribed)
        if (c >= 0 && c < nc) keep[uf.find(c)] = 1;
    for (LO c = 0; c < nc; ++c)
      if (keep[uf.find(c)] == 0) in_chord[c] = false;
  }
  std::vector<LO> root2chord(static_cast<std::size_t>(nc), kNoIndex);
  std::vector<std::vector<LO>> chords;
  for (LO c = 0; c < nc; ++c) {
    if (!in_chord[c]) continue;
    LO& id = root2chord[uf.find(c)];
    if (id == kNoIndex) {
      id = static_cast<LO>(chords.size());
      chords.emplace_back();
    }
    q.curve2chord[c] = id;
    chords[id].push_back(c);
  }
  q.num_chords = static_cast<LO>(chords.size());
  const auto members = [&](LO c) -> std::vector<LO> {
    return q.curve2chord[c] == kNoIndex ? std::vector<LO>{c} : chords[q.curve2chord[c]];
  };

  // Prescriptions, checked in the order given; the first one of a chord fixes it.
  std::vector<int> fixed(static_cast<std::size_t>(nc), 0);
  std::vector<LO> fixed_by(static_cast<std::size_t>(nc), kNoIndex);
  for (const auto& [c, n] : options.prescribed) {
    if (c < 0 || c >= nc) {
      std::ostringstream os;
      os << "curve " << c
         << ": edge count prescribed for a curve that does not exist (the model has " << nc
         << " curves)";
      throw InputError(os.str());
    }
    if (curves[c].degenerate)
      throw InputError("curve " + std::to_string(c) + ": " + std::to_string(n) +
                       " edges prescribed on a degenerate curve (a pole), which has no length");
    if (n <= 0)
      throw InputError("curve " + std::to_string(c) + ": " + std::to_string(n) +
                       " edges prescribed, but a curve needs at least 1");
    for (const LO m : members(c)) {
      if (fixed[m] != 0 && fixed[m] != n) {
        const LO other = fixed_by[m];
        std::ostringstream os;
        if (other == c)
          os << "curve " << c << ": prescribed both " << fixed[m] << " and " << n << " edges";
        else
          os << "curves " << other << " and " << c
             << " are topologically parallel (one chord of four-sided faces) but are prescribed "
             << "different edge counts (" << fixed[m] << " and " << n << ")";
        throw InputError(os.str());
      }
      if (n < hard_minimum(m)) {
        std::ostringstream os;
        os << "curve " << c << ": " << n << " edges prescribed, but ";
        if (m != c) os << "curve " << m << ", in its chord, ";
        os << (closed(m) ? "is closed and needs at least 3"
                         : "shares both end corners with another curve and needs at least 2");
        throw InputError(os.str());
      }
      fixed[m] = n;
      fixed_by[m] = c;
    }
  }

  const auto round = [&](double x, int lo) {
    const long n = options.even ? 2 * std::lround(x / 2) : std::lround(x);
    return std::max(static_cast<int>(n), lo);
  };
  for (LO c = 0; c < nc; ++c) {
    if (curves[c].degenerate) continue;
    if (fixed[c] != 0) {
      q.edges[c] = fixed[c];
    } else if (q.curve2chord[c] == kNoIndex) {
      q.edges[c] = round(ideal[c], minimum(c));
    } else if (chords[q.curve2chord[c]].front() == c) {
      // Average the ideal values over the chord, each curve once, in increasing id (deterministic).
      const auto& chord = chords[q.curve2chord[c]];
      double sum = 0;
      int lo = 0;
      for (const LO m : chord) {
        sum += ideal[m];
        lo = std::max(lo, minimum(m));
      }
      const int n = round(sum / static_cast<double>(chord.size()), lo);
      for (const LO m : chord) q.edges[m] = n;
    }
  }
  if (options.even) {
    // Midpoint subdivision needs every loop even (and every stretch between two poles), not
    // every curve: the variables are the free chords and curves; each starts at its even count
    // (1 for a sliver with options.odd_slivers) and may move to the nearest odd one (or back).
    ParityProblem pb;
    pb.rows = parity_rows(model);
    std::vector<LO> var_of(static_cast<std::size_t>(nc), kNoIndex);
    std::vector<std::vector<LO>> var_members;
    for (LO c = 0; c < nc; ++c) {
      if (curves[c].degenerate || fixed[c] != 0) continue;
      const LO chord = q.curve2chord[c];
      if (chord != kNoIndex && chords[chord].front() != c) {
        var_of[c] = var_of[chords[chord].front()];
        continue;
      }
      var_of[c] = static_cast<LO>(var_members.size());
      var_members.push_back(members(c));
    }
    const auto nv = static_cast<LO>(var_members.size());
    std::vector<int> alternative(static_cast<std::size_t>(nv), 0);
    pb.var_rows.resize(static_cast<std::size_t>(nv));
    pb.cost.assign(static_cast<std::size_t>(nv), 0.0);
    for (LO v = 0; v < nv; ++v) {
      const auto& mem = var_members[v];
      const int now = q.edges[mem.front()];
      int lo = 0;
      for (const LO m : mem) lo = std::max(lo, minimum(m));
      int hard = 0;
      for (const LO m : mem) hard = std::max(hard, hard_minimum(m));
      // The count of the other parity nearest to the ideal (the members' mean), not below what
      // the members need.
      double mean = 0;
      for (const LO m : mem) mean += ideal[m];
      mean /= static_cast<double>(mem.size());
      const int down = now - 1, up = now + 1;
      const int other = (down >= std::max(hard, lo - 1) && mean - down < up - mean) ? down : up;
      const auto error = [&](int n) {
        double e = 0;
        for (const LO m : mem) e += std::abs(n - ideal[m]) / std::max(ideal[m], 1.0);
        return e;
      };
      // A sliver (options.odd_slivers): 1 edge rather than 2 when the ideal count is nearer 1
      // (in ratio: below sqrt 2), so that a strip is one quad across.
      // A curve shorter than options.sliver_length likewise, whatever its ideal count.
      bool sliver = options.sliver_length > 0 && now == 2;
      for (const LO m : mem)
        sliver = sliver && fixed[m] == 0 && model.curves()[m].length < options.sliver_length;
      if ((options.odd_slivers && other == 1 && mean < std::numbers::sqrt2) || sliver) {
        for (const LO m : mem) q.edges[m] = 1;
        alternative[v] = now;
      } else {
        alternative[v] = other;
      }
      pb.cost[v] = std::max(0.0, error(alternative[v]) - error(q.edges[mem.front()])) +
                   1e-6 * static_cast<double>(mem.size());
    }
    pb.odd.assign(pb.rows.size(), 0);
    for (LO r = 0; r < static_cast<LO>(pb.rows.size()); ++r) {
      std::map<LO, int> times;
      for (const LO c : pb.rows[r].curves) {
        pb.odd[r] ^= static_cast<char>(q.edges[c] % 2);
        if (var_of[c] != kNoIndex) times[var_of[c]] ^= 1;
      }
      for (const auto& [v, t] : times)
        if (t != 0) pb.var_rows[v].push_back(r);
    }
    const ParitySolution sol = solve_parity(pb);
    if (!sol.conflict.empty())
      throw ParityConflict{parity_conflict_message(model, pb, sol.conflict, fixed)};
    for (LO v = 0; v < nv; ++v)
      if (sol.flip[v] != 0)
        for (const LO m : var_members[v]) q.edges[m] = alternative[v];
  }
  q.total_edges = std::accumulate(q.edges.begin(), q.edges.end(), std::int64_t{0});
  return q;
}

}  // namespace

Quantization quantize_curves(const cad::CadModel& model, std::span<const double> ideal,
                             const QuantizeOptions& options) {
  // Chords are a preference; where they make the loops' parities impossible, first the chords
  // without a prescription, then all, are given up, so that what check_prescription_parity
  // accepts is always met.
  for (int level = 0;; ++level) {
    try {
      return quantize_level(model, ideal, options, level);
    } catch (const ParityConflict& e) {
      if (level == 2) throw InputError(e.message);
    }
  }
}

std::vector<mesh::CurveMesh> place_vertices(const cad::CadModel& model,
                                            std::span<const mesh::CurveMesh> curves,
                                            std::span<const std::vector<double>> sizes,
                                            const Quantization& q, bool halved,
                                            const TaskArena& tasks, const PlaceOptions& options) {
  const LO nc = model.num_curves();
  QSMESH_CHECK(static_cast<LO>(curves.size()) == nc,
               curves.size() << " background curve meshes for " << nc << " curves");
  QSMESH_CHECK(static_cast<LO>(sizes.size()) == nc, sizes.size()
                                                        << " size lists for " << nc << " curves");
  QSMESH_CHECK(static_cast<LO>(q.edges.size()) == nc,
               q.edges.size() << " edge counts for " << nc << " curves");
  std::vector<mesh::CurveMesh> out(static_cast<std::size_t>(nc));
  QSMESH_CHECK(!options.align_chords || options.profile_samples >= 2,
               "profile_samples " << options.profile_samples << " is below 2");
  QSMESH_CHECK(!options.align_chords || options.align_length_ratio >= 1,
               "align_length_ratio " << options.align_length_ratio << " is below 1");
  for (LO c = 0; c < nc; ++c)
    if (!model.curves()[c].degenerate) check_sizes(c, curves[c], sizes[c]);
  const std::vector<std::vector<double>> profiles =
      options.align_chords ? shared_profiles(model, curves, sizes, q, options)
                           : std::vector<std::vector<double>>{};
  tasks.parallel_for(nc, [&](std::int64_t ci) {
    const LO c = static_cast<LO>(ci);
    const cad::Curve& curve = model.curves()[c];
    const mesh::CurveMesh& bg = curves[c];
    mesh::CurveMesh& m = out[c];
    if (curve.degenerate) {
      m = bg;
      m.curve = c;
      return;
    }
    const int total_edges = q.edges[c];
    QSMESH_CHECK(!halved || total_edges % 2 == 0,
                 "curve " << c << ": " << total_edges << " edges cannot be halved");
    const int n = halved ? total_edges / 2 : total_edges;
    QSMESH_CHECK(n >= 1, "curve " << c << ": " << n << " edges asked for");

    const std::vector<double> f = cumulative(bg, sizes[c]);
    const double total = f.back();
    m.curve = c;
    m.t.resize(static_cast<std::size_t>(n) + 1);
    m.t.front() = bg.t.front();
    m.t.back() = bg.t.back();
    if (!profiles.empty() && !profiles[c].empty()) {
      // The shared profile: vertex i where it reaches i/n, at that arc-length fraction.
      const auto& g = profiles[c];
      const std::vector<double> arc = arc_lengths(bg);
      std::size_t k = 0, j = 0;
      const std::size_t last_k = g.size() - 2, last_j = arc.size() - 2;
      for (int i = 1; i < n; ++i) {
        const double target = static_cast<double>(i) / n;
        while (k < last_k && g[k + 1] < target) ++k;
        const double dg = g[k + 1] - g[k];
        const double u = (static_cast<double>(k) + (dg > 0 ? (target - g[k]) / dg : 0.0)) /
                         static_cast<double>(g.size() - 1);
        const double x = arc.back() * std::clamp(u, 0.0, 1.0);
        while (j < last_j && arc[j + 1] < x) ++j;
        const double len = arc[j + 1] - arc[j];
        const double frac = len > 0 ? std::clamp((x - arc[j]) / len, 0.0, 1.0) : 0.0;
        m.t[i] = bg.t[j] + frac * (bg.t[j + 1] - bg.t[j]);
      }
    } else if (!(total > 0)) {
      // A background polyline of zero length (a curve shorter than its tolerance): equal steps in
      // t.
      for (int i = 1; i < n; ++i) m.t[i] = bg.t.front() + (bg.t.back() - bg.t.front()) * i / n;
    } else {
      std::size_t j = 0;
      const std::size_t last = f.size() - 2;
      for (int i = 1; i < n; ++i) {
        const double target = total * i / n;
        while (j < last && f[j + 1] < target) ++j;
        const double len = distance(bg.points[j], bg.points[j + 1]);
        const double frac = segment_fraction(len, sizes[c][j], sizes[c][j + 1], target - f[j]);
        m.t[i] = bg.t[j] + frac * (bg.t[j + 1] - bg.t[j]);
      }
    }
    m.points.resize(m.t.size());
    m.points.front() = model.corners()[curve.corners[0]].point;
    m.points.back() = model.corners()[curve.corners[1]].point;
    if (n > 1) {
      const auto geometry = model.curve_geometry(c);
      for (int i = 1; i < n; ++i) m.points[i] = geometry->point(m.t[i]);
    }
  });
  if (options.thin_side_ratio > 0) {
    if (!halved) {
      (void)align_thin_sides(model, curves, q, out, tasks, options.thin_side_ratio);
    } else {
      // The aligned full meshes keep the parity of the vertices they align: the halved meshes of
      // the curves moved are their even vertices.
      PlaceOptions own = options;
      own.thin_side_ratio = 0;
      std::vector<mesh::CurveMesh> full =
          place_vertices(model, curves, sizes, q, /*halved=*/false, tasks, own);
      for (const LO c : align_thin_sides(model, curves, q, full, tasks, options.thin_side_ratio)) {
        auto& m = out[c];
        for (std::size_t i = 0; i < m.t.size(); ++i) {
          m.t[i] = full[c].t[2 * i];
          m.points[i] = full[c].points[2 * i];
        }
      }
    }
  }
  return out;
}

namespace {

// A boundary segment of a face in its parameter plane, with the curves it lies on (two for a
// halved segment across a corner) and its place in its loop.
struct Segment {
  Vec2 a, b;
  LO curve, curve2;
  LO loop, index, loop_size;
};

// The curves of crossing or overlapping segments, and those of loops of fewer than three
// segments (`small_loop_curves`), sorted, each once.
std::vector<LO> crossing_segments(const std::vector<Segment>& segments,
                                  std::vector<LO> small_loop_curves) {
  std::vector<LO> out = std::move(small_loop_curves);
  const auto sorted_once = [&] {
    out.erase(std::remove(out.begin(), out.end(), kNoIndex), out.end());
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  };
  if (segments.size() < 2) return sorted_once();
  // A uniform grid over the loops' box, about one segment per cell, keeps this near-linear.
  Vec2 lo = segments[0].a, hi = segments[0].a;
  for (const Segment& s : segments)
    for (const Vec2& p : {s.a, s.b}) {
      lo = {std::min(lo.u, p.u), std::min(lo.v, p.v)};
      hi = {std::max(hi.u, p.u), std::max(hi.v, p.v)};
    }
  const int cells = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(segments.size()))));
  const double wu = std::max(hi.u - lo.u, 1e-300) / cells,
               wv = std::max(hi.v - lo.v, 1e-300) / cells;
  const auto cell_u = [&](double u) {
    return std::clamp(static_cast<int>((u - lo.u) / wu), 0, cells - 1);
  };
  const auto cell_v = [&](double v) {
    return std::clamp(static_cast<int>((v - lo.v) / wv), 0, cells - 1);
  };
  std::vector<std::vector<std::size_t>> grid(static_cast<std::size_t>(cells) * cells);
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const Segment& s = segments[i];
    for (int cu = cell_u(std::min(s.a.u, s.b.u)); cu <= cell_u(std::max(s.a.u, s.b.u)); ++cu)
      for (int cv = cell_v(std::min(s.a.v, s.b.v)); cv <= cell_v(std::max(s.a.v, s.b.v)); ++cv)
        grid[static_cast<std::size_t>(cu) * cells + cv].push_back(i);
  }
  const auto neighbours = [](const Segment& x, const Segment& y) {
    if (x.loop != y.loop) return false;
    const LO d = std::abs(x.index - y.index);
    return d <= 1 || d == x.loop_size - 1;
  };
  const auto sign = [](double x) { return (x > 0) - (x < 0); };
  // Collinear segments overlapping over a length: the boundary runs back over itself.
  const auto overlap = [](const Segment& x, const Segment& y) {
    const Vec2 d = x.b - x.a;
    const double len2 = d.u * d.u + d.v * d.v;
    if (!(len2 > 0)) return false;
    const auto at = [&](const Vec2& p) {
      return ((p.u - x.a.u) * d.u + (p.v - x.a.v) * d.v) / len2;
    };
    const double from = std::max(0.0, std::min(at(y.a), at(y.b)));
    const double to = std::min(1.0, std::max(at(y.a), at(y.b)));
    return to - from > 1e-12;
  };
  for (const auto& cell : grid)
    for (std::size_t i = 0; i < cell.size(); ++i)
      for (std::size_t j = i + 1; j < cell.size(); ++j) {
        const Segment& x = segments[cell[i]];
        const Segment& y = segments[cell[j]];
        const int o1 = sign(mesh::orient2d(x.a, x.b, y.a)),
                  o2 = sign(mesh::orient2d(x.a, x.b, y.b));
        const int o3 = sign(mesh::orient2d(y.a, y.b, x.a)),
                  o4 = sign(mesh::orient2d(y.a, y.b, x.b));
        const bool crossing = !neighbours(x, y) && o1 * o2 < 0 && o3 * o4 < 0;
        const bool folded = o1 == 0 && o2 == 0 && o3 == 0 && o4 == 0 && overlap(x, y);
        if (crossing || folded) {
          for (const LO c : {x.curve, x.curve2, y.curve, y.curve2}) out.push_back(c);
        }
      }
  return sorted_once();
}

}  // namespace

std::vector<LO> crossing_curves(const cad::CadModel& model, LO f,
                                std::span<const mesh::CurveMesh> curves) {
  const auto surface = model.face_geometry(f);
  const auto loops = background::face_boundary(model, f, *surface, curves);
  // Segments of every loop, with their curve (face_boundary gives each use its curve mesh's
  // edges in order) and their loop position (neighbours share a vertex and are not tested).
  std::vector<Segment> segments;
  const cad::Face& face = model.faces()[f];
  for (LO l = 0; l < static_cast<LO>(loops.size()); ++l) {
    const auto& pts = loops[l].points;
    const auto n = static_cast<LO>(pts.size());
    LO k = 0;
    for (const cad::CurveUse& use : face.loops[l].uses)
      for (LO e = 0; e < curves[use.curve].num_edges() && k < n; ++e, ++k)
        segments.push_back({pts[k].uv, pts[(k + 1) % n].uv, use.curve, kNoIndex, l, k, n});
  }
  // A loop of one or two segments encloses nothing (two curves joining the same corners, one
  // edge each on the halved meshes).
  std::vector<LO> small;
  for (std::size_t l = 0; l < loops.size(); ++l)
    if (!loops[l].points.empty() && loops[l].points.size() < 3)
      for (const cad::CurveUse& use : face.loops[l].uses) small.push_back(use.curve);
  return crossing_segments(segments, std::move(small));
}

std::vector<LO> crossing_curves_halved(const cad::CadModel& model, LO f,
                                       std::span<const mesh::CurveMesh> full) {
  const auto surface = model.face_geometry(f);
  const background::HalvedBoundary halved =
      background::halved_face_boundary(model, f, *surface, full);
  std::vector<Segment> segments;
  std::vector<LO> small;
  const cad::Face& face = model.faces()[f];
  for (LO l = 0; l < static_cast<LO>(halved.loops.size()); ++l) {
    const auto& pts = halved.loops[l].points;
    const auto n = static_cast<LO>(pts.size());
    for (LO k = 0; k < n; ++k) {
      const background::HalvedSegment& s = halved.segments[l][k];
      segments.push_back({pts[k].uv, pts[(k + 1) % n].uv, s.curve_before,
                          s.curve_after == s.curve_before ? kNoIndex : s.curve_after, l, k, n});
    }
    if (n > 0 && n < 3)
      for (const cad::CurveUse& use : face.loops[l].uses) small.push_back(use.curve);
  }
  return crossing_segments(segments, std::move(small));
}

void refine_curves(Quantization& q, std::span<const LO> curves, std::span<const LO> fixed) {
  const auto nc = static_cast<LO>(q.edges.size());
  const bool chords = q.curve2chord.size() == q.edges.size();
  std::vector<char> frozen(q.edges.size(), 0);
  std::vector<char> frozen_chord(static_cast<std::size_t>(std::max<LO>(q.num_chords, 0)), 0);
  for (const LO c : fixed) {
    if (c < 0 || c >= nc) continue;
    frozen[c] = 1;
    if (chords && q.curve2chord[c] >= 0 && q.curve2chord[c] < q.num_chords)
      frozen_chord[q.curve2chord[c]] = 1;
  }
  std::vector<int> target(q.edges.size(), 0);
  std::map<LO, int> chord_target;  // chord -> largest doubled count among its flagged curves
  for (const LO c : curves) {
    if (c < 0 || c >= nc || q.edges[c] <= 0 || frozen[c] != 0) continue;
    if (chords && q.curve2chord[c] >= 0 && q.curve2chord[c] < q.num_chords &&
        frozen_chord[q.curve2chord[c]] != 0)
      continue;
    // An odd count stays odd: the loops through the curve keep their parity.
    const int doubled = 2 * q.edges[c] + q.edges[c] % 2;
    target[c] = std::max(target[c], doubled);
    if (chords && q.curve2chord[c] != kNoIndex) {
      int& t = chord_target[q.curve2chord[c]];
      t = std::max(t, doubled);
    }
  }
  q.total_edges = 0;
  for (LO c = 0; c < nc; ++c) {
    int e = std::max(q.edges[c], target[c]);
    if (chords && q.curve2chord[c] != kNoIndex) {
      const auto it = chord_target.find(q.curve2chord[c]);
      if (it != chord_target.end() && q.edges[c] > 0) e = std::max(e, it->second);
    }
    q.edges[c] = e;
    q.total_edges += e;
  }
}

}  // namespace qsmesh::quantize
