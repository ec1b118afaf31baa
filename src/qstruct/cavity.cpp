#include "qsmesh/qstruct/cavity.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/smooth/quad_tools.hpp"

namespace qsmesh::qstruct {

// ---------------------------------------------------------------------------------- topology

QuadTopology::QuadTopology(const mesh::FaceMesh& mesh) {
  const LO n = mesh.num_vertices();
  const LO nq = static_cast<LO>(mesh.quads.size());
  std::vector<std::pair<LO, LO>> pairs;
  pairs.reserve(4 * static_cast<std::size_t>(nq));
  for (LO q = 0; q < nq; ++q)
    for (const LO v : mesh.quads[q]) {
      QSMESH_CHECK(v >= 0 && v < n, "quad " << q << " uses vertex " << v << " of " << n);
      pairs.emplace_back(v, q);
    }
  v2q_ = Adjacency::from_pairs(n, std::move(pairs));
  q2q_.assign(static_cast<std::size_t>(nq), {kNoIndex, kNoIndex, kNoIndex, kNoIndex});
  on_boundary_.assign(static_cast<std::size_t>(n), 0);
  // The uses of each edge, found among the quads of its first vertex (a handful): no sort of
  // the 4 nq edge uses, as this runs after every committed cavity.
  for (LO q = 0; q < nq; ++q)
    for (int k = 0; k < 4; ++k) {
      const LO a = mesh.quads[q][k], b = mesh.quads[q][(k + 1) % 4];
      int uses = 0;
      LO other = kNoIndex;
      bool other_forward = false;
      LO previous = kNoIndex;
      for (const LO p : v2q_[a]) {
        if (p == previous) continue;  // a vertex twice in one quad
        previous = p;
        for (int k2 = 0; k2 < 4; ++k2) {
          const LO x = mesh.quads[p][k2], y = mesh.quads[p][(k2 + 1) % 4];
          if (!((x == a && y == b) || (x == b && y == a))) continue;
          ++uses;
          if (p != q || k2 != k) {
            other = p;
            other_forward = x < y;
          }
        }
      }
      QSMESH_CHECK(uses <= 2, "edge (" << std::min(a, b) << ", " << std::max(a, b)
                                       << ") is used by " << uses << " quads");
      if (uses == 1) {
        on_boundary_[a] = 1;
        on_boundary_[b] = 1;
      } else {
        QSMESH_CHECK((a < b) != other_forward, "edge (" << std::min(a, b) << ", " << std::max(a, b)
                                                        << ") is used twice in one direction");
        q2q_[q][k] = other;
      }
    }
}

namespace {

int irregularity(const mesh::FaceMesh& m, const QuadTopology& t, LO v, LO valence) {
  if (m.vclass[v].dim == 0) return 0;
  return std::abs(valence - (t.on_boundary(v) ? 2 : 4));
}

bool interior_vertex(const mesh::FaceMesh& m, const QuadTopology& t, LO v) {
  return m.vclass[v].dim == 2 && !t.on_boundary(v) && t.valence(v) > 0;
}

Vec3 centroid(const mesh::FaceMesh& m, LO q) {
  const auto& qd = m.quads[q];
  return (m.points[qd[0]] + m.points[qd[1]] + m.points[qd[2]] + m.points[qd[3]]) * 0.25;
}

// The valences of a refined pattern.
std::vector<LO> refined_valence(const RefinedPattern& r) {
  std::vector<LO> val(static_cast<std::size_t>(r.num_vertices), 0);
  for (const auto& q : r.quads)
    for (const LO v : q) ++val[v];
  return val;
}

// Cavity boundary position of refined boundary position p (same convention as face_pattern.cpp:
// a mirrored match walks the cavity boundary backwards from the end of side `start`).
LO boundary_position(const PatternMatch& match, std::span<const LO> corners, LO nb, LO p) {
  const LO m = static_cast<LO>(corners.size());
  const LO first = match.reversed ? corners[(match.start + 1) % m] : corners[match.start];
  return (((match.reversed ? first - p : first + p) % nb) + nb) % nb;
}

class Grower {
 public:
  Grower(const mesh::FaceMesh& m, const QuadTopology& t, LO seed, std::span<const char> singular,
         const GrowOptions& o)
      : m_(m), t_(t), seed_(seed), singular_(singular), o_(o) {
    in_.assign(static_cast<std::size_t>(t.num_quads()), 0);
    forbidden_.assign(static_cast<std::size_t>(o.max_backtracks > 0 ? t.num_quads() : 0), 0);
    frontier_flag_.assign(static_cast<std::size_t>(t.num_quads()), 0);
    n_in_.assign(static_cast<std::size_t>(t.num_vertices()), 0);
    next_.assign(static_cast<std::size_t>(t.num_vertices()), kNoIndex);
    seed_point_ = m.points[seed];
    for (const auto& p : o.patterns)
      has_sides_[static_cast<std::size_t>(std::min<LO>(p.num_sides(), kMaxSides))] = 1;
  }

  GrowResult run() {
    GrowResult res;
    if (!interior_vertex(m_, t_, seed_)) return res;
    // The seed fan, quad by quad in an order that keeps it a disk.
    const auto fan = t_.quads_of(seed_);
    add(fan[0]);
    for (std::size_t added = 1; added < fan.size();) {
      bool progress = false;
      for (const LO q : fan)
        if (!in_[q] && can_add(q)) {
          add(q);
          ++added;
          progress = true;
        }
      if (!progress) {
        res.stop = GrowResult::Stop::Fan;
        res.reach = reach();
        return res;
      }
    }
    std::size_t last_convex = quads_.size();
    int backtracks = 0;
    while (true) {
      if (concave_.empty()) last_convex = quads_.size();
      if (!concave_.empty()) {
        // A concave vertex has exactly one outside quad; the cavity cannot become convex without
        // it.
        const LO v = *concave_.begin();
        LO out = kNoIndex;
        for (const LO q : t_.quads_of(v))
          if (!in_[q]) out = q;
        if (out == kNoIndex || static_cast<LO>(quads_.size()) >= o_.max_quads || !can_add(out)) {
          if (static_cast<LO>(quads_.size()) < o_.max_quads && backtracks < o_.max_backtracks &&
              quads_.size() > last_convex) {
            // The quad that left the last convex state leads nowhere: undo the excursion, never
            // add that quad again, and grow on elsewhere (the isotropic order otherwise ends the
            // growth at the first blocked concave vertex, e.g. next to a singularity).
            ++backtracks;
            const LO culprit = quads_[last_convex];
            while (quads_.size() > last_convex) remove_last();
            forbidden_[culprit] = 1;
            checked_irregular_ = std::min(checked_irregular_, irregular_inside_);
            continue;
          }
          res.stop = static_cast<LO>(quads_.size()) >= o_.max_quads ? GrowResult::Stop::MaxQuads
                                                                    : GrowResult::Stop::Concave;
          break;
        }
        add(out);
        continue;
      }
      if (irregular_inside_ > checked_irregular_ ||
          (o_.check_every_step && irregular_inside_ > 0)) {
        checked_irregular_ = irregular_inside_;
        if (!o_.seed_is_singularity || irregular_inside_ >= 2) {
          ++res.checks;
          Cavity c;
          if (evaluate(c, res)) {
            res.remeshable.push_back(std::move(c));
            if (!o_.maximal &&
                static_cast<int>(res.remeshable.size()) >= std::max(1, o_.max_remeshable)) {
              res.stop = GrowResult::Stop::Found;
              break;
            }
          }
        }
      }
      if (static_cast<LO>(quads_.size()) >= o_.max_quads) {
        res.stop = GrowResult::Stop::MaxQuads;
        break;
      }
      // The nearest addable frontier quad (ties to the smaller id, so the scan order does not
      // matter); quads the cavity took are dropped from the list on the way.
      LO best = kNoIndex;
      double best_d = std::numeric_limits<double>::max();
      std::size_t kept = 0;
      for (std::size_t r = 0; r < frontier_.size(); ++r) {
        const LO q = frontier_[r];
        if (in_[q]) {
          frontier_flag_[q] = 0;
          continue;
        }
        const double d = frontier_d_[r];
        frontier_[kept] = q;
        frontier_d_[kept] = d;
        ++kept;
        if (d < best_d || (d == best_d && q < best)) {
          if (!can_add(q)) continue;
          best = q;
          best_d = d;
        }
      }
      frontier_.resize(kept);
      frontier_d_.resize(kept);
      if (best == kNoIndex) {
        res.stop = GrowResult::Stop::NoFrontier;
        break;
      }
      add(best);
    }
    res.grown_quads = static_cast<LO>(quads_.size());
    res.reach = reach();
    return res;
  }

 private:
  bool can_add(LO q) const {
    if (in_[q] || (!forbidden_.empty() && forbidden_[q])) return false;
    const auto& qd = m_.quads[q];
    std::array<bool, 4> shared{};
    int count = 0;
    for (int k = 0; k < 4; ++k) {
      const LO nb = t_.neighbour(q, k);
      shared[k] = nb != kNoIndex && in_[nb];
      count += shared[k] ? 1 : 0;
    }
    if (!quads_.empty()) {
      if (count == 0 || count == 4) return false;
      int starts = 0;
      for (int k = 0; k < 4; ++k) starts += (shared[k] && !shared[(k + 3) % 4]) ? 1 : 0;
      if (starts != 1) return false;  // two separate chains would enclose a hole or pinch
      for (int i = 0; i < 4; ++i) {
        const bool on_chain = shared[i] || shared[(i + 3) % 4];  // edges i and i-1 touch vertex i
        if (!on_chain && n_in_[qd[i]] > 0) return false;  // touching the cavity at a vertex only
      }
    }
    for (int i = 0; i < 4; ++i) {
      const LO v = qd[i];
      if (n_in_[v] + 1 != t_.valence(v)) continue;
      const auto& c = m_.vclass[v];
      if (c.dim == 0 && t_.valence(v) >= 3) return false;  // a concave CAD corner, fully surrounded
      if (t_.on_boundary(v)) continue;
      if (c.dim < 2) return false;
      if (singular_[v] && !(o_.seed_is_singularity && v == seed_)) return false;
    }
    return true;
  }

  void add(LO q) {
    in_[q] = 1;
    quads_.push_back(q);
    for (const LO v : m_.quads[q]) {
      if (n_in_[v] == 1) --corners_;
      ++n_in_[v];
      if (n_in_[v] == 1) ++corners_;
      const LO val = t_.valence(v);
      if (n_in_[v] == val && !t_.on_boundary(v)) {
        interior_.push_back(v);
        if (val != 4) ++irregular_inside_;
      }
      set_concave(v, !t_.on_boundary(v) && val - n_in_[v] == 1);
    }
    for (int k = 0; k < 4; ++k) {
      const LO nb = t_.neighbour(q, k);
      if (nb != kNoIndex && !in_[nb] && !frontier_flag_[nb]) push_frontier(nb);
    }
  }

  // concave_ is a sorted vector (a handful of vertices): a std::set allocated a node on every
  // insertion, and add() and remove_last() update it for every vertex of every quad.
  void set_concave(LO v, bool concave) {
    const auto it = std::lower_bound(concave_.begin(), concave_.end(), v);
    const bool held = it != concave_.end() && *it == v;
    if (concave && !held)
      concave_.insert(it, v);
    else if (!concave && held)
      concave_.erase(it);
  }

  // Centroids do not move during a growth: each quad's distance to the seed is computed once.
  void push_frontier(LO q) {
    frontier_flag_[q] = 1;
    frontier_.push_back(q);
    frontier_d_.push_back(distance(centroid(m_, q), seed_point_));
  }

  // Farthest vertex from the seed of the quads the growth looked at (added, undone or frontier).
  double reach() const {
    double r = 0;
    const auto visit = [&](LO q) {
      for (const LO v : m_.quads[q]) r = std::max(r, distance(m_.points[v], seed_point_));
    };
    for (const LO q : t_.quads_of(seed_)) visit(q);
    for (const LO q : quads_) visit(q);
    for (const LO q : frontier_) visit(q);
    return r;
  }

  // Undoes the last add() (the growth is LIFO: the vertices it made interior are the last ones).
  void remove_last() {
    const LO q = quads_.back();
    quads_.pop_back();
    in_[q] = 0;
    if (!frontier_flag_[q]) push_frontier(q);  // the frontier scan dropped it when it was taken
    for (int i = 3; i >= 0; --i) {
      const LO v = m_.quads[q][i];
      const LO val = t_.valence(v);
      if (n_in_[v] == val && !t_.on_boundary(v)) {
        QSMESH_CHECK(!interior_.empty() && interior_.back() == v, "cavity undo out of order");
        interior_.pop_back();
        if (val != 4) --irregular_inside_;
      }
      if (n_in_[v] == 1) --corners_;
      --n_in_[v];
      if (n_in_[v] == 1) ++corners_;
      set_concave(v, !t_.on_boundary(v) && n_in_[v] > 0 && val - n_in_[v] == 1);
    }
  }

  // Boundary, sides and matches of the current (convex) cavity; true when remeshable.
  bool evaluate(Cavity& c, GrowResult& res) {
    // The corners are the vertices in one cavity quad (kept count of): when no pattern has that
    // many sides, the boundary need not be walked (growths check often, and big cavities are
    // mostly between two matching shapes).
    if (!has_sides_[static_cast<std::size_t>(std::min<LO>(corners_, kMaxSides))]) {
      ++res.no_pattern;
      return false;
    }
    std::vector<LO>& starts = starts_;
    starts.clear();
    bool simple = true;
    for (const LO q : quads_)
      for (int k = 0; k < 4; ++k) {
        const LO nb = t_.neighbour(q, k);
        if (nb != kNoIndex && in_[nb]) continue;
        const LO a = m_.quads[q][k], b = m_.quads[q][(k + 1) % 4];
        if (next_[a] != kNoIndex) simple = false;
        next_[a] = b;
        starts.push_back(a);
      }
    std::vector<LO>& cycle = cycle_;
    cycle.clear();
    if (simple && !starts.empty()) {
      LO v0 = kNoIndex;
      for (const LO v : starts)
        if (n_in_[v] == 1 && (v0 == kNoIndex || v < v0)) v0 = v;
      if (v0 != kNoIndex) {
        LO v = v0;
        do {
          cycle.push_back(v);
          v = next_[v];
        } while (v != v0 && v != kNoIndex && cycle.size() <= starts.size());
        if (v != v0 || cycle.size() != starts.size()) cycle.clear();
      }
    }
    for (const LO v : starts) next_[v] = kNoIndex;
    if (cycle.empty()) return false;

    const LO nb = static_cast<LO>(cycle.size());
    c.boundary = cycle;
    c.n_in.resize(nb);
    for (LO i = 0; i < nb; ++i) {
      c.n_in[i] = n_in_[cycle[i]];
      if (c.n_in[i] == 1) c.corners.push_back(i);
    }
    const LO m = static_cast<LO>(c.corners.size());
    if (m < 2) {
      ++res.no_pattern;
      return false;
    }
    for (LO k = 0; k < m; ++k)
      c.side_edges.push_back((k + 1 < m ? c.corners[k + 1] : c.corners[0] + nb) - c.corners[k]);
    bool any = false;
    for (const auto& p : o_.patterns) any = any || p.num_sides() == m;
    if (!any) {
      ++res.no_pattern;
      return false;
    }
    std::vector<PatternMatch> fresh;
    if (o_.match_cache == nullptr) fresh = match_patterns(o_.patterns, c.side_edges, o_.match);
    const std::vector<PatternMatch>& matches =
        o_.match_cache != nullptr ? o_.match_cache->matches(o_.patterns, c.side_edges, o_.match)
                                  : fresh;
    if (matches.empty()) {
      ++res.no_match;
      return false;
    }

    int before = 0;
    for (LO i = 0; i < nb; ++i) before += irregularity(m_, t_, cycle[i], t_.valence(cycle[i]));
    for (const LO v : interior_) before += irregularity(m_, t_, v, t_.valence(v));
    int best_after = std::numeric_limits<int>::max();
    for (const auto& match : matches) {
      const RefinedPattern r = refine_pattern(o_.patterns[match.pattern], match.chords);
      if (static_cast<LO>(r.boundary.size()) != nb) continue;
      const std::vector<LO> rval = refined_valence(r);
      std::vector<char> on_b(static_cast<std::size_t>(r.num_vertices), 0);
      int after = 0;
      bool ok = true;
      for (LO p = 0; p < nb && ok; ++p) {
        on_b[r.boundary[p]] = 1;
        const LO i = boundary_position(match, c.corners, nb, p);
        const LO v = cycle[i];
        const LO val = t_.valence(v) - c.n_in[i] + rval[r.boundary[p]];
        if (val != t_.valence(v) && (m_.vclass[v].dim == 0 || singular_[v])) ok = false;
        after += irregularity(m_, t_, v, val);
      }
      int irregular_new = 0;
      bool seed_valence = false;
      for (LO v = 0; v < r.num_vertices && ok; ++v) {
        if (on_b[v] || rval[v] == 4) continue;
        ++irregular_new;
        after += std::abs(rval[v] - 4);
        seed_valence = rval[v] == t_.valence(seed_);
      }
      if (!ok || after >= before) continue;
      const double nq = static_cast<double>(quads_.size());
      if (o_.max_quad_change >= 0 &&
          std::abs(static_cast<double>(r.quads.size()) - nq) > o_.max_quad_change * nq)
        continue;
      if (o_.seed_is_singularity && !(irregular_new == 1 && seed_valence)) continue;
      c.matches.push_back(match);
      best_after = std::min(best_after, after);
      if (static_cast<int>(c.matches.size()) >= std::max(1, o_.max_candidates)) break;
    }
    if (c.matches.empty()) {
      ++res.not_better;
      return false;
    }
    c.irregularity_before = before;
    c.irregularity_after = best_after;
    c.quads = quads_;
    c.interior = interior_;
    return true;
  }

  const mesh::FaceMesh& m_;
  const QuadTopology& t_;
  LO seed_;
  std::span<const char> singular_;
  const GrowOptions& o_;
  Vec3 seed_point_;
  std::vector<char> in_, frontier_flag_, forbidden_;
  std::vector<LO> n_in_, next_, quads_, frontier_, interior_;
  std::vector<LO> starts_, cycle_;  // evaluate()'s boundary walk, kept for their capacity
  std::vector<double> frontier_d_;  // distance from each frontier_ quad's centroid to the seed
  LO corners_ = 0;                  // vertices in exactly one cavity quad
  static constexpr LO kMaxSides = 16;
  std::array<char, kMaxSides + 1> has_sides_{};  // a pattern has that many sides (last: or more)
  std::vector<LO> concave_;                      // sorted: the concave vertices, smallest first
  int irregular_inside_ = 0, checked_irregular_ = 0;
};

// ------------------------------------------------------------------------- replacement

// SICN of a quad, -1 when it faces against the face; the normal is taken at the first corner
// that is not a pole, and a quad with all its corners at poles counts as flipped.
double quad_quality(const std::vector<Vec3>& pts, const std::vector<Vec2>& uv,
                    const std::array<LO, 4>& q, const cad::FaceGeometry& surface, double sign) {
  Vec3 n{};
  for (int k = 0; k < 4 && norm2(n) == 0; ++k) n = surface.normal(uv[q[k]]);  // skip a pole corner
  if (norm2(n) == 0) return -1.0;
  return smooth::oriented_sicn({pts[q[0]], pts[q[1]], pts[q[2]], pts[q[3]]}, n, sign);
}

// The Laplace layout of the cavity's new vertices; a solver failure counts as a failed layout.
bool laplace_uv(const std::vector<std::array<LO, 4>>& quads, LO num_fixed, std::vector<Vec2>& uv,
                linalg::SolverCache& cache) {
  try {
    return smooth::chord_laplace_uv(quads, num_fixed, uv, &cache);
  } catch (const Error&) {
    return false;
  }
}

struct Replacement {
  std::vector<std::array<LO, 4>> quads;  // in work ids (new vertices from work.num_vertices())
  std::vector<Vec2> new_uv;
  std::vector<Vec3> new_points;
  std::vector<LO> moved;  // old vertices moved by the smoothing
  std::vector<Vec2> moved_uv;
  std::vector<Vec3> moved_points;
  LO new_irregular = kNoIndex;  // work id of the one irregular new vertex (if one)
};

// What the layout and smoothing of a candidate gave (CavityMemo).
struct MemoRecord {
  bool layout_failed = false;
  bool reached_screen = false;  // the screen's pass ran: previous and now are its measures
  std::pair<double, double> previous{0, 0}, now{0, 0};
  bool completed = false;  // the smoothing ran to its end: after, after_avg
  double after = 0, after_avg = 0;
};

template <class T>
void append_bytes(std::string& key, const T& x) {
  key.append(reinterpret_cast<const char*>(&x), sizeof(T));
}

// The local problem of a candidate, as bytes: everything its layout, smoothing and measures read.
std::string memo_key(const mesh::FaceMesh& lm, LO nold, LO n_new_quads, double before,
                     double before_sum, std::size_t cavity_quads) {
  std::string key;
  key.reserve(64 + lm.points.size() * 64 + lm.quads.size() * 16);
  append_bytes(key, nold);
  append_bytes(key, n_new_quads);
  append_bytes(key, lm.num_vertices());
  append_bytes(key, before);
  append_bytes(key, before_sum);
  append_bytes(key, static_cast<std::uint64_t>(cavity_quads));
  for (LO i = 0; i < lm.num_vertices(); ++i) {
    const Vec3& p = lm.points[i];
    const Vec2& uv = lm.uv[i];
    const mesh::VertexClass& vc = lm.vclass[i];
    for (const double x : {p.x, p.y, p.z, uv.u, uv.v, vc.param[0], vc.param[1]})
      append_bytes(key, x);
    append_bytes(key, vc.dim);
    append_bytes(key, vc.entity);
    append_bytes(key, vc.index);
  }
  for (const auto& q : lm.quads)
    for (const LO v : q) append_bytes(key, v);
  return key;
}

// Corners have valence 1, other boundary vertices valence 2: the pattern fits convex cavities.
bool convex_pattern(const Pattern& p) {
  std::vector<char> corner(static_cast<std::size_t>(p.num_vertices()), 0);
  for (const LO s : p.side_start) corner[p.boundary[s]] = 1;
  for (const LO v : p.boundary)
    if (!corner[v] && p.valence[v] != 2) return false;
  return true;
}

std::vector<Pattern> select(std::span<const Pattern> patterns, int sides, bool regular_only) {
  std::vector<Pattern> out;
  for (const auto& p : patterns)
    if (p.num_sides() == sides && convex_pattern(p) && (!regular_only || p.irregular == 0))
      out.push_back(p);
  return out;
}

// The lists the steps grow with: the regular four-sided patterns (grid), all four-sided ones, the
// three- and five-sided ones, each in the order of the pattern list.
struct PatternLists {
  std::vector<Pattern> grid, four, tri, pent;
  explicit PatternLists(std::span<const Pattern> patterns)
      : grid(select(patterns, 4, true)),
        four(select(patterns, 4, false)),
        tri(select(patterns, 3, false)),
        pent(select(patterns, 5, false)) {}
};

// Whether two pattern lists are the same patterns (every other field of a Pattern follows from
// its name, drawing and quads: make_pattern).
bool same_patterns(std::span<const Pattern> a, std::span<const Pattern> b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].name != b[i].name || a[i].xy != b[i].xy || a[i].quads != b[i].quads) return false;
  return true;
}

}  // namespace

struct CavityMemo::Impl {
  std::int64_t max_bytes = 0, bytes = 0, hits = 0;
  // The smoothing options the records were made under.
  bool have_options = false;
  int iterations = 0, screen_passes = 0;
  bool laplacian_uv = false, winslow = false, approximate_projection = false;
  std::unordered_map<std::string, MemoRecord> records;
  // Kept across the calls of one face, whatever their options: the pattern lists, match_patterns'
  // results (a function of their arguments) and the solvers' analyses (of the pattern alone). The
  // first and second improvement passes grow the same cavities from the same mesh: a third of
  // the matches of Block.stp were repeats from an earlier call.
  std::vector<Pattern> source;  // the pattern list `lists` was selected from
  std::optional<PatternLists> lists;
  MatchCache matches;
  linalg::SolverCache solvers;

  // The lists selected from `patterns`, made again (and the match results forgotten: they are
  // kept per list address) when `patterns` is not the list of the last call.
  const PatternLists& lists_for(std::span<const Pattern> patterns) {
    if (!lists || !same_patterns(source, patterns)) {
      source.assign(patterns.begin(), patterns.end());
      lists.emplace(patterns);
      matches = MatchCache();
    }
    return *lists;
  }

  // Forgets the records made under other smoothing options.
  void adopt(const CavityOptions& o) {
    const auto& s = o.smooth;
    if (have_options && iterations == s.iterations && screen_passes == o.screen_passes &&
        laplacian_uv == s.laplacian_uv && winslow == s.winslow &&
        approximate_projection == s.approximate_projection)
      return;
    records.clear();
    bytes = 0;
    have_options = true;
    iterations = s.iterations;
    screen_passes = o.screen_passes;
    laplacian_uv = s.laplacian_uv;
    winslow = s.winslow;
    approximate_projection = s.approximate_projection;
  }
  [[nodiscard]] const MemoRecord* find(const std::string& key) const {
    const auto it = records.find(key);
    return it == records.end() ? nullptr : &it->second;
  }
  bool hit() {
    ++hits;
    return false;
  }
  void store(const std::string& key, const MemoRecord& r) {
    const auto it = records.find(key);
    if (it != records.end()) {
      it->second = r;
      return;
    }
    const auto size = static_cast<std::int64_t>(key.size() + sizeof(MemoRecord) + 64);
    if (bytes + size > max_bytes) return;
    bytes += size;
    records.emplace(key, r);
  }
};

CavityMemo::CavityMemo(std::int64_t max_bytes) : impl_(std::make_unique<Impl>()) {
  impl_->max_bytes = max_bytes;
}
CavityMemo::~CavityMemo() = default;
CavityMemo::CavityMemo(CavityMemo&&) noexcept = default;
CavityMemo& CavityMemo::operator=(CavityMemo&&) noexcept = default;
std::int64_t CavityMemo::hits() const { return impl_->hits; }
std::int64_t CavityMemo::records() const {
  return static_cast<std::int64_t>(impl_->records.size());
}

namespace {

class Remesher {
 public:
  Remesher(mesh::FaceMesh& work, const cad::FaceGeometry& surface, const CavityOptions& o,
           double sign, CavityMemo::Impl* memo, linalg::SolverCache& cache)
      : w_(work), s_(surface), o_(o), sign_(sign), memo_(memo), cache_(cache) {}

  // Why build() refused a replacement.
  enum class Refusal { None, Layout, Screened, Invalid, MinSicn, AvgSicn };

  // Builds, lays out, smooths and measures the replacement of cavity c by `match` of `patterns`;
  // false with `why` set when it is refused.
  bool build(const QuadTopology& t, const Cavity& c, const PatternMatch& match,
             std::span<const Pattern> patterns, Replacement& out, Refusal& why) const {
    why = Refusal::Layout;
    const RefinedPattern r = refine_pattern(patterns[match.pattern], match.chords);
    const LO nb = static_cast<LO>(c.boundary.size());
    QSMESH_CHECK(static_cast<LO>(r.boundary.size()) == nb,
                 "refined boundary has " << r.boundary.size() << " vertices, the cavity " << nb);
    const LO n0 = w_.num_vertices();
    std::vector<LO> r2w(static_cast<std::size_t>(r.num_vertices), kNoIndex);
    for (LO p = 0; p < nb; ++p)
      r2w[r.boundary[p]] = c.boundary[boundary_position(match, c.corners, nb, p)];
    LO next = n0;
    for (LO v = 0; v < r.num_vertices; ++v)
      if (r2w[v] == kNoIndex) r2w[v] = next++;
    const LO n_new = next - n0;
    // The pattern's boundary runs with the cavity's (the cavity on the left, as the quads turn)
    // unless the match is mirrored.
    for (const auto& q : r.quads) {
      const std::array<LO, 4> m{r2w[q[0]], r2w[q[1]], r2w[q[2]], r2w[q[3]]};
      out.quads.push_back(match.reversed ? std::array<LO, 4>{m[0], m[3], m[2], m[1]} : m);
    }
    const std::vector<LO> rval = refined_valence(r);
    for (LO v = 0; v < r.num_vertices; ++v)
      if (r2w[v] >= n0 && rval[v] != 4)
        out.new_irregular = out.new_irregular == kNoIndex ? r2w[v] : kNoIndex - 1;
    if (out.new_irregular == kNoIndex - 1) out.new_irregular = kNoIndex;

    // Free vertices: the new ones, then rings of old ones around the cavity (never CAD vertices).
    std::vector<char> in_cavity(static_cast<std::size_t>(t.num_quads()), 0);
    for (const LO q : c.quads) in_cavity[q] = 1;
    // Sorted vectors rather than std::set: this runs for every candidate layout of every cavity,
    // and the node allocations of the sets were a visible share of the remeshing.
    std::vector<LO> free_old;
    std::vector<LO> ring(c.boundary.begin(), c.boundary.end());
    std::vector<LO> seen(ring.begin(), ring.end());
    seen.insert(seen.end(), c.interior.begin(), c.interior.end());
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
    const auto insert_sorted = [](std::vector<LO>& set, LO x) {
      const auto it = std::lower_bound(set.begin(), set.end(), x);
      if (it != set.end() && *it == x) return false;
      set.insert(it, x);
      return true;
    };
    for (int k = 1; k <= o_.smooth_rings; ++k) {
      for (const LO v : ring)
        if (w_.vclass[v].dim == 2 && !t.on_boundary(v)) insert_sorted(free_old, v);
      if (k == o_.smooth_rings) break;
      std::vector<LO> next_ring;
      for (const LO v : ring)
        for (const LO q : t.quads_of(v)) {
          if (in_cavity[q]) continue;
          for (const LO x : w_.quads[q])
            if (insert_sorted(seen, x)) next_ring.push_back(x);
        }
      std::sort(next_ring.begin(), next_ring.end());
      ring = std::move(next_ring);
    }
    const auto is_free_old = [&](LO v) {
      return std::binary_search(free_old.begin(), free_old.end(), v);
    };
    // Region: the new quads and the old ones around a free old vertex.
    std::vector<LO> old_quads;
    for (const LO v : free_old)
      for (const LO q : t.quads_of(v))
        if (!in_cavity[q]) old_quads.push_back(q);
    std::sort(old_quads.begin(), old_quads.end());
    old_quads.erase(std::unique(old_quads.begin(), old_quads.end()), old_quads.end());

    double before = std::numeric_limits<double>::max(), before_sum = 0;
    for (const LO q : c.quads) {
      const double x = quad_quality(w_.points, w_.uv, w_.quads[q], s_, sign_);
      before = std::min(before, x);
      before_sum += x;
    }
    for (const LO q : old_quads)
      before = std::min(before, quad_quality(w_.points, w_.uv, w_.quads[q], s_, sign_));

    // Local mesh: old vertices first (locked ones relabelled so that the smoother keeps them), new
    // ones after, in work order.
    std::vector<LO> verts;
    for (const auto& q : out.quads)
      for (const LO v : q)
        if (v < n0) verts.push_back(v);
    for (const LO q : old_quads)
      for (const LO v : w_.quads[q]) verts.push_back(v);
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
    const LO nold = static_cast<LO>(verts.size());
    const auto local = [&](LO v) -> LO {
      if (v >= n0) return nold + (v - n0);
      return static_cast<LO>(std::lower_bound(verts.begin(), verts.end(), v) - verts.begin());
    };
    mesh::FaceMesh lm;
    lm.face = w_.face;
    lm.points.resize(nold + n_new);
    lm.uv.resize(nold + n_new);
    lm.vclass.resize(nold + n_new);
    for (LO i = 0; i < nold; ++i) {
      const LO v = verts[i];
      lm.points[i] = w_.points[v];
      lm.uv[i] = w_.uv[v];
      lm.vclass[i] = w_.vclass[v];
      if (lm.vclass[i].dim == 2 && !is_free_old(v))
        lm.vclass[i] = mesh::VertexClass{1, -2, i, {0, 0}};
    }
    for (const auto& q : out.quads)
      lm.quads.push_back({local(q[0]), local(q[1]), local(q[2]), local(q[3])});
    const LO n_new_quads = static_cast<LO>(lm.quads.size());
    for (const LO q : old_quads) {
      const auto& qd = w_.quads[q];
      lm.quads.push_back({local(qd[0]), local(qd[1]), local(qd[2]), local(qd[3])});
    }
    const double need = std::max(o_.min_sicn, std::min(o_.good_sicn, o_.keep_ratio * before));
    const double avg_need = o_.keep_avg_ratio * (before_sum / static_cast<double>(c.quads.size()));
    const bool screen = o_.screen_passes >= 2 && o_.screen_passes < o_.smooth.iterations;
    // Each pass gains less than the one before it (measured, CavityOptions::screen_passes): the
    // passes left, each at the last pass's gain, bound what the candidate can reach.
    const auto passes_screen = [&](std::pair<double, double> previous,
                                   std::pair<double, double> now) {
      const double rest = o_.smooth.iterations - o_.screen_passes;
      const double reach_min = now.first + rest * std::max(0.0, now.first - previous.first);
      const double reach_avg = now.second + rest * std::max(0.0, now.second - previous.second);
      return reach_min + o_.screen_min_margin >= need &&
             reach_avg + o_.screen_avg_margin >= avg_need;
    };
    // The acceptance of a smoothed candidate (minimum over the touched quads, mean of the new).
    const auto refusal = [&](double after, double after_avg) {
      if (!(after > o_.min_sicn)) return Refusal::Invalid;
      if (after < need) return Refusal::MinSicn;
      if (after_avg < avg_need) return Refusal::AvgSicn;
      return Refusal::None;
    };

    // A candidate refused before with this very local problem (CavityMemo).
    std::string key;
    MemoRecord record;
    if (memo_ != nullptr) {
      key = memo_key(lm, nold, n_new_quads, before, before_sum, c.quads.size());
      if (const MemoRecord* m = memo_->find(key)) {
        why = Refusal::Layout;
        if (m->layout_failed) return memo_->hit();
        why = Refusal::Screened;
        if (screen && m->reached_screen && !passes_screen(m->previous, m->now)) return memo_->hit();
        if (m->completed) {
          why = refusal(m->after, m->after_avg);
          if (why != Refusal::None) return memo_->hit();
        }
        record = *m;  // not decided by the record: laid out and smoothed again
        why = Refusal::Layout;
      }
    }
    const auto remember = [&] {
      if (memo_ != nullptr) memo_->store(key, record);
    };

    // Laplace layout of the new vertices on the new quads only, the cavity boundary fixed.
    {
      std::vector<std::array<LO, 4>> nq(lm.quads.begin(), lm.quads.begin() + n_new_quads);
      if (!laplace_uv(nq, nold, lm.uv, cache_)) {
        record.layout_failed = true;
        remember();
        return false;
      }
    }
    for (LO i = nold; i < nold + n_new; ++i) {
      lm.points[i] = s_.eval(lm.uv[i]).p;
      lm.vclass[i] = mesh::VertexClass{2, w_.face, kNoIndex, {lm.uv[i].u, lm.uv[i].v}};
    }
    // (minimum over the touched quads, mean over the new ones) of a local mesh.
    const auto measure = [&](const mesh::FaceMesh& m) {
      double low = std::numeric_limits<double>::max(), sum = 0;
      for (LO q = 0; q < static_cast<LO>(m.quads.size()); ++q) {
        const double x = quad_quality(m.points, m.uv, m.quads[q], s_, sign_);
        low = std::min(low, x);
        if (q < n_new_quads) sum += x;
      }
      return std::pair{low, sum / static_cast<double>(n_new_quads)};
    };
    smooth::SmoothOptions so = o_.smooth;
    std::pair<double, double> previous{0, 0};
    if (screen)
      so.after_pass = [&](int pass, const mesh::FaceMesh& m) {
        if (pass + 1 < o_.screen_passes || pass > o_.screen_passes) return true;
        const auto now = measure(m);
        if (pass < o_.screen_passes) {
          previous = now;
          return true;
        }
        record.reached_screen = true;
        record.previous = previous;
        record.now = now;
        return passes_screen(previous, now);
      };
    smooth::SmoothStats ss;
    lm = smooth::smooth_face(lm, s_, so, &ss, &cache_);
    why = Refusal::Screened;
    if (ss.stopped_early) {
      remember();
      return false;
    }

    const auto [after, after_avg] = measure(lm);
    record.completed = true;
    record.after = after;
    record.after_avg = after_avg;
    why = refusal(after, after_avg);
    if (why != Refusal::None) {
      remember();
      return false;
    }

    for (LO i = nold; i < nold + n_new; ++i) {
      out.new_uv.push_back(lm.uv[i]);
      out.new_points.push_back(lm.points[i]);
    }
    for (LO i = 0; i < nold; ++i) {
      const LO v = verts[i];
      if (!is_free_old(v)) continue;
      if (lm.uv[i] == w_.uv[v] && lm.points[i] == w_.points[v]) continue;
      out.moved.push_back(v);
      out.moved_uv.push_back(lm.uv[i]);
      out.moved_points.push_back(lm.points[i]);
    }
    return true;
  }

  void commit(const Cavity& c, const Replacement& r) {
    for (std::size_t i = 0; i < r.new_uv.size(); ++i) {
      w_.points.push_back(r.new_points[i]);
      w_.uv.push_back(r.new_uv[i]);
      w_.vclass.push_back(mesh::VertexClass{2, w_.face, kNoIndex, {r.new_uv[i].u, r.new_uv[i].v}});
    }
    for (std::size_t i = 0; i < r.moved.size(); ++i) {
      const LO v = r.moved[i];
      w_.points[v] = r.moved_points[i];
      w_.uv[v] = r.moved_uv[i];
      w_.vclass[v].param = {r.moved_uv[i].u, r.moved_uv[i].v};
    }
    std::vector<char> gone(w_.quads.size(), 0);
    for (const LO q : c.quads) gone[q] = 1;
    std::vector<std::array<LO, 4>> quads;
    quads.reserve(w_.quads.size() - c.quads.size() + r.quads.size());
    for (std::size_t q = 0; q < w_.quads.size(); ++q)
      if (!gone[q]) quads.push_back(w_.quads[q]);
    quads.insert(quads.end(), r.quads.begin(), r.quads.end());
    w_.quads = std::move(quads);
  }

 private:
  mesh::FaceMesh& w_;
  const cad::FaceGeometry& s_;
  const CavityOptions& o_;
  double sign_;
  CavityMemo::Impl* memo_;
  // The candidates' layouts repeat the same refined patterns (the calls on one face, one
  // thread): their solvers' analyses are kept.
  linalg::SolverCache& cache_;
};

}  // namespace

GrowResult grow_cavity(const mesh::FaceMesh& mesh, const QuadTopology& topo, LO seed,
                       std::span<const char> singular, const GrowOptions& options) {
  QSMESH_CHECK(topo.num_vertices() == mesh.num_vertices() &&
                   topo.num_quads() == static_cast<LO>(mesh.quads.size()),
               "the topology does not belong to the mesh");
  QSMESH_CHECK(static_cast<LO>(singular.size()) == mesh.num_vertices(),
               "one singular flag per vertex");
  QSMESH_CHECK(seed >= 0 && seed < mesh.num_vertices(), "seed " << seed << " out of range");
  return Grower(mesh, topo, seed, singular, options).run();
}

std::int64_t count_irregular(const mesh::FaceMesh& mesh) {
  const QuadTopology t(mesh);
  std::int64_t n = 0;
  for (LO v = 0; v < mesh.num_vertices(); ++v)
    n += interior_vertex(mesh, t, v) && t.valence(v) != 4 ? 1 : 0;
  return n;
}

mesh::FaceMesh remesh_cavities(const mesh::FaceMesh& input, const cad::FaceGeometry& surface,
                               std::span<const crossfield::Singularity> singularities,
                               std::span<const Pattern> patterns, const CavityOptions& options,
                               CavityReport* report, CavityMemo* memo) {
  CavityReport local;
  CavityReport& rep = report != nullptr ? *report : local;
  rep = CavityReport{};
  for (const auto& s : singularities)
    if (crossfield::is_interior(s) && (s.index == 1 || s.index == -1)) ++rep.singularities;
  const auto q0 = smooth::measure(input);
  rep.sicn_min_before = rep.sicn_min_after = q0.sicn_min;
  rep.sicn_avg_before = rep.sicn_avg_after = q0.sicn_avg;
  if (!input.triangles.empty()) {
    rep.skipped = "the mesh has triangles";
    return input;
  }
  if (input.quads.empty()) {
    rep.skipped = "no quads";
    return input;
  }
  try {
    QSMESH_CHECK(
        input.uv.size() == input.points.size() && input.vclass.size() == input.points.size(),
        "points, uv and vclass sizes differ");
    mesh::FaceMesh work = input;
    QuadTopology topo(work);
    rep.irregular_before = count_irregular(work);
    const double sign = smooth::quad_orientation(work, surface);

    // Flag the singular vertices: nearest free vertex of the singularity's valence within the
    // bound.
    std::vector<char> singular(static_cast<std::size_t>(work.num_vertices()), 0);
    std::vector<LO> flagged;      // flagged vertex of each accepted singularity
    std::vector<LO> flagged_val;  // its valence
    for (const auto& s : singularities) {
      if (!crossfield::is_interior(s) || (s.index != 1 && s.index != -1)) continue;
      const LO want = s.index == 1 ? 3 : 5;
      LO best = kNoIndex;
      double best_d = std::numeric_limits<double>::max();
      for (LO v = 0; v < work.num_vertices(); ++v) {
        if (!interior_vertex(work, topo, v) || topo.valence(v) != want || singular[v]) continue;
        const double d = distance(work.points[v], s.position);
        if (!(d < best_d)) continue;
        double h = 0;
        int ne = 0;
        for (const LO q : topo.quads_of(v)) {
          const auto& qd = work.quads[q];
          int k = 0;
          while (qd[k] != v) ++k;
          h += distance(work.points[v], work.points[qd[(k + 1) % 4]]);
          ++ne;
        }
        if (d <= options.singularity_distance * h / ne) {
          best = v;
          best_d = d;
        }
      }
      if (best != kNoIndex) {
        singular[best] = 1;
        flagged.push_back(best);
        flagged_val.push_back(want);
      }
    }
    rep.flagged = static_cast<std::int64_t>(flagged.size());

    // Without a memo, the lists, match results and analyses of this call alone.
    std::optional<PatternLists> own_lists;
    std::optional<MatchCache> own_matches;
    std::optional<linalg::SolverCache> own_solvers;
    if (memo == nullptr) {
      own_lists.emplace(patterns);
      own_matches.emplace();
      own_solvers.emplace();
    }
    const PatternLists& lists = memo != nullptr ? memo->impl().lists_for(patterns) : *own_lists;
    MatchCache& match_cache = memo != nullptr ? memo->impl().matches : *own_matches;
    linalg::SolverCache& solvers = memo != nullptr ? memo->impl().solvers : *own_solvers;
    const std::vector<Pattern>& grid = lists.grid;
    const std::vector<Pattern>& four = lists.four;
    const std::vector<Pattern>& tri = lists.tri;
    const std::vector<Pattern>& pent = lists.pent;

    // The memo needs reproducible smoothing: no time budget, no caller's pass hook.
    CavityMemo::Impl* memo_impl = nullptr;
    if (memo != nullptr && options.smooth.time_budget_s <= 0 && !options.smooth.after_pass) {
      memo_impl = &memo->impl();
      memo_impl->adopt(options);
    }
    Remesher remesher(work, surface, options, sign, memo_impl, solvers);
    // The growths match the same side counts against the same lists (grid, four, tri, pent,
    // alive for the whole call and, with a memo, for the memo's calls) again and again:
    // match_cache.
    const Stopwatch clock;
    std::int64_t started = 0;
    bool stop = false;
    const auto out_of_budget = [&] {
      if (options.max_cavities > 0 && started >= options.max_cavities) {
        rep.work_bound_hit = true;
        return true;
      }
      if (options.time_budget_s > 0 && clock.seconds() > options.time_budget_s) {
        rep.time_budget_hit = true;
        return true;
      }
      return false;
    };

    // A growth depends only on the quads, points and flags within its reach (GrowResult::reach),
    // so one that found nothing finds nothing again until a commit changes something there: each
    // commit is kept as a ball holding the old points of its removed quads and of the vertices
    // it moved, and a growth of the same kind (grid maximal, Steps 1 and 3; transitions minimal,
    // Step 4) is skipped while no later ball meets its reach.
    struct Change {
      Vec3 centre;
      double radius;
    };
    std::vector<Change> changes;
    struct Futile {
      double reach = -1;  // < 0: no futile growth recorded
      std::size_t changes = 0;
    };
    // Per kind of growth: [0] maximal with the grid, [1] minimal with the four-sided patterns,
    // [2] maximal with the four-sided patterns (Step 3 with step3_transitions): a growth that
    // found nothing with the grid alone may still find a transition.
    std::array<std::vector<Futile>, 3> futile;
    const auto still_futile = [&](int kind, LO seed) {
      auto& f = futile[kind];
      if (seed >= static_cast<LO>(f.size()) || f[seed].reach < 0) return false;
      const Vec3& p = work.points[seed];
      for (std::size_t i = f[seed].changes; i < changes.size(); ++i)
        if (distance(p, changes[i].centre) <= f[seed].reach + changes[i].radius) {
          f[seed].reach = -1;
          return false;
        }
      f[seed].changes = changes.size();
      return true;
    };
    const auto record_change = [&](const Cavity& c, const Replacement& r) {
      std::vector<Vec3> pts;
      for (const LO q : c.quads)
        for (const LO v : work.quads[q]) pts.push_back(work.points[v]);
      for (const LO v : r.moved) pts.push_back(work.points[v]);
      Vec3 centre{};
      for (const auto& p : pts) centre = centre + p;
      centre = centre * (1.0 / static_cast<double>(pts.size()));
      double radius = 0;
      for (const auto& p : pts) radius = std::max(radius, distance(p, centre));
      changes.push_back({centre, radius * (1 + 1e-9) + 1e-12});
    };

    // Bound of the maximal growths, raised once the unnecessary irregular vertices are sparse.
    LO maximal_cap = options.max_quads_maximal;

    // One growth from `seed` and the geometric trials of what it found; true when committed.
    const auto grow_and_remesh = [&](int step, LO seed, std::span<const Pattern> pats, bool maximal,
                                     bool from_singularity, LO* new_singular) {
      const bool maximal_transitions = maximal && pats.data() != grid.data();
      const int kind = from_singularity || !options.skip_futile ? -1
                       : !maximal                               ? 1
                       : maximal_transitions                    ? 2
                                                                : 0;
      if (kind >= 0 && still_futile(kind, seed)) {
        ++rep.diagnostics[step].skipped_futile;
        return false;
      }
      ++started;
      ++rep.grown[step];
      GrowOptions go;
      go.maximal = maximal;
      go.patterns = pats;
      go.seed_is_singularity = from_singularity;
      go.max_quads = maximal ? maximal_cap : options.max_quads_minimal;
      // Maximal growths with the transitions match as the paper does, when new irregular vertices
      // came in: matching every convex state against all four-sided patterns doubled the time of
      // Step 3 for no fewer irregular vertices (Block.stp, mambo_s34 at the reference counts).
      go.check_every_step = !maximal_transitions;
      go.max_candidates = options.max_candidates;
      go.max_quad_change = options.max_quad_change;
      go.match = options.match;
      go.max_backtracks = options.max_backtracks;
      go.max_remeshable = maximal ? 0 : std::max(1, options.max_minimal_tries);
      go.match_cache = &match_cache;
      const GrowResult g = grow_cavity(work, topo, seed, singular, go);
      auto& d = rep.diagnostics[step];
      switch (g.stop) {
        case GrowResult::Stop::Concave:
          ++d.stop_concave;
          break;
        case GrowResult::Stop::MaxQuads:
          ++d.stop_max_quads;
          break;
        case GrowResult::Stop::NoFrontier:
          ++d.stop_no_frontier;
          break;
        case GrowResult::Stop::Fan:
          ++d.stop_fan;
          break;
        case GrowResult::Stop::Found:
          ++d.stop_found;
          break;
      }
      d.checks += g.checks;
      d.no_pattern += g.no_pattern;
      d.no_match += g.no_match;
      d.not_better += g.not_better;
      const int n = static_cast<int>(g.remeshable.size());
      if (n == 0 && kind >= 0) {
        auto& f = futile[kind];
        if (static_cast<LO>(f.size()) < work.num_vertices()) f.resize(work.points.size());
        f[seed] = Futile{g.reach, changes.size()};
      }
      const int tries = std::min(
          n, std::max(1, maximal ? options.max_geometric_tries : options.max_minimal_tries));
      for (int k = 0; k < tries; ++k) {
        // Maximal: largest first; minimal: smallest first, the larger ones spread the distortion
        // of a refused one over more quads.
        const Cavity& c = g.remeshable[maximal ? n - 1 - k : k];
        for (const auto& match : c.matches) {
          Replacement r;
          Remesher::Refusal why = Remesher::Refusal::None;
          if (!remesher.build(topo, c, match, pats, r, why)) {
            switch (why) {
              case Remesher::Refusal::Layout:
                ++d.refused_layout;
                break;
              case Remesher::Refusal::Screened:
                ++d.refused_screened;
                break;
              case Remesher::Refusal::Invalid:
                ++d.refused_invalid;
                break;
              case Remesher::Refusal::MinSicn:
                ++d.refused_min;
                break;
              default:
                ++d.refused_avg;
                break;
            }
            continue;
          }
          record_change(c, r);
          remesher.commit(c, r);
          singular.resize(work.points.size(), 0);
          topo = QuadTopology(work);
          ++rep.remeshed[step];
          if (new_singular != nullptr) *new_singular = r.new_irregular;
          return true;
        }
        ++rep.rejected_quality[step];
      }
      return false;
    };

    // An irregular interior vertex that no singularity asks for: the seeds of Steps 1, 3 and 4.
    const auto unnecessary = [&](LO v) {
      return interior_vertex(work, topo, v) && topo.valence(v) != 4 && !singular[v];
    };

    const auto unnecessary_step = [&](int step, std::span<const Pattern> pats, bool maximal) {
      if (pats.empty()) return false;
      bool changed = false;
      std::vector<LO> seeds;
      for (LO v = 0; v < work.num_vertices(); ++v)
        if (unnecessary(v)) seeds.push_back(v);
      for (const LO v : seeds) {
        if (!unnecessary(v)) continue;  // changed since
        if (out_of_budget()) {
          stop = true;
          break;
        }
        changed = grow_and_remesh(step, v, pats, maximal, false, nullptr) || changed;
      }
      return changed;
    };

    const auto singular_step = [&] {
      bool changed = false;
      for (std::size_t i = 0; i < flagged.size(); ++i) {
        const LO v = flagged[i];
        if (v == kNoIndex || !interior_vertex(work, topo, v)) continue;
        const std::vector<Pattern>& pats = flagged_val[i] == 3 ? tri : pent;
        if (pats.empty() || topo.valence(v) != flagged_val[i]) continue;
        if (out_of_budget()) {
          stop = true;
          break;
        }
        LO moved_to = kNoIndex;
        if (grow_and_remesh(1, v, pats, false, true, &moved_to)) {
          changed = true;
          singular[v] = 0;
          flagged[i] = moved_to;
          if (moved_to != kNoIndex) singular[moved_to] = 1;
        }
      }
      return changed;
    };

    // Unnecessary irregular vertices per quad at most sparse_irregular_ratio.
    const auto sparse = [&] {
      std::int64_t n = 0;
      for (LO v = 0; v < work.num_vertices(); ++v)
        if (unnecessary(v)) ++n;
      return static_cast<double>(n) <=
             options.sparse_irregular_ratio * static_cast<double>(work.quads.size());
    };

    for (int round = 0; round < options.max_rounds && !stop; ++round) {
      ++rep.rounds;
      // Where few unnecessary irregular vertices are left, the pairs are far apart and only larger
      // grid cavities reach across them; with few seeds the larger bound costs little. Dense faces
      // (size transitions everywhere) keep the small bound: larger cavities cost them 2-3x the
      // time for nothing. The futile marks of the maximal growths were made with the small bound.
      if (maximal_cap < options.max_quads_sparse && sparse()) {
        maximal_cap = options.max_quads_sparse;
        futile[0].clear();
        futile[2].clear();
        rep.escalated = 1;
      }
      const auto& on = options.steps;
      bool changed = on[0] && unnecessary_step(0, grid, true);
      if (!stop && on[1]) changed = singular_step() || changed;
      if (!stop && on[2])
        changed = unnecessary_step(2, options.step3_transitions ? four : grid, true) || changed;
      if (!stop && on[3]) changed = unnecessary_step(3, four, false) || changed;
      if (!changed) break;
    }

    for (std::size_t i = 0; i < flagged.size(); ++i)
      if (flagged[i] != kNoIndex && interior_vertex(work, topo, flagged[i]) &&
          topo.valence(flagged[i]) == flagged_val[i])
        ++rep.flagged_kept;

    // Compaction: drop the vertices no quad uses any more (face-interior ones only), keep order.
    mesh::FaceMesh out;
    out.face = work.face;
    std::vector<LO> old2new(static_cast<std::size_t>(work.num_vertices()), kNoIndex);
    for (LO v = 0; v < work.num_vertices(); ++v) {
      if (topo.valence(v) == 0 && work.vclass[v].dim == 2) continue;
      old2new[v] = out.num_vertices();
      out.points.push_back(work.points[v]);
      out.uv.push_back(work.uv[v]);
      out.vclass.push_back(work.vclass[v]);
    }
    out.quads.reserve(work.quads.size());
    for (const auto& q : work.quads)
      out.quads.push_back({old2new[q[0]], old2new[q[1]], old2new[q[2]], old2new[q[3]]});
    rep.irregular_after = count_irregular(out);
    const auto q1 = smooth::measure(out);
    rep.sicn_min_after = q1.sicn_min;
    rep.sicn_avg_after = q1.sicn_avg;
    return out;
  } catch (const Error& e) {
    rep.skipped = e.with_context(ErrorContext{"qstruct", 2, input.face}).what();
    rep.irregular_after = rep.irregular_before;
    return input;
  }
}

}  // namespace qsmesh::qstruct
