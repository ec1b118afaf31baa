#include "qsmesh/layout/coarse_layout.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <sstream>
#include <unordered_map>
#include <utility>
#include <vector>

#include "grid.hpp"
#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/cad/smooth.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/mesh/edges.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/smooth/smooth.hpp"
#include "qsmesh/smooth/untangle.hpp"
#include "quad_topology.hpp"

namespace qsmesh::layout {

namespace {

constexpr LO kNever = std::numeric_limits<LO>::max();
// Fine meshes built again with the curve sides of bad coarse quads back at the uniform spacing,
// before every side is uniform.
constexpr int kMaxSpacingRounds = 3;
constexpr int kMaxRounds = 40;
// A bound against a loop that keeps finding new folds. Growing arcs one unit a repair
// (Repairs::Grow) takes more repairs than restoring input lengths: Block at size
// factor 0.0035 completes after 51 (local repairs: 38, with 134,695 blocks against 55,315;
// docs/benchmarks.md, stop 50).
constexpr int kMaxRepairs = 60;
// Rings of patches around the bad coarse quads' own that a repair may reach (repair_patches).
constexpr int kMaxRings = 3;

// Transfinite (Coons) interpolation at grid node (i, j) of an n0 x n1 grid from its boundary
// nodes P(i, 0), P(n0, j), P(i, n1), P(0, j).
template <class Boundary>
Vec3 coons_point(const Boundary& P, LO i, LO j, LO n0, LO n1) {
  const double s = static_cast<double>(i) / n0, t = static_cast<double>(j) / n1;
  return (1 - t) * P(i, 0) + t * P(i, n1) + (1 - s) * P(0, j) + s * P(n0, j) -
         ((1 - s) * (1 - t) * P(0, 0) + s * (1 - t) * P(n0, 0) + (1 - s) * t * P(0, n1) +
          s * t * P(n0, n1));
}

// Thrown inside the stage when the result cannot be built; turned into CoarseResult::failure.
struct Reject {
  std::string why;
};

struct Dsu {
  std::vector<GO> parent;
  GO add() {
    parent.push_back(static_cast<GO>(parent.size()));
    return parent.back();
  }
  void resize(GO n) {
    const auto old = static_cast<GO>(parent.size());
    parent.resize(static_cast<std::size_t>(n));
    for (GO i = old; i < n; ++i) parent[static_cast<std::size_t>(i)] = i;
  }
  GO find(GO x) {
    while (parent[static_cast<std::size_t>(x)] != x) {
      parent[static_cast<std::size_t>(x)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
      x = parent[static_cast<std::size_t>(x)];
    }
    return x;
  }
  // The smaller root stays: groups do not depend on the order of the unions.
  void unite(GO a, GO b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (b < a) std::swap(a, b);
    parent[static_cast<std::size_t>(b)] = a;
  }
};

struct EdgeRec {
  std::array<GO, 2> q{-1, -1};
  int count = 0;
  LO curve = kNoIndex;  // a bar of this curve
  bool traced = false;
};

// A trace through the mesh: path[0] its origin, path[s] the vertex reached after s edges.
struct Trace {
  std::vector<GO> path;
  double tan_alpha = 1;
  // Crossings met: (step of this trace there, true when the other trace's origin lies in the pi/4
  // cone of this one, true when the two origins form a 3-5 pair).
  struct Hit {
    LO step;
    bool in_quarter_cone;
    bool pair35;
  };
  std::vector<Hit> hits;
  LO separate = kNever;  // the prefix up to this step must keep a length >= 1 (constraints 3, 4)
};

struct Passage {
  LO trace;
  LO step;
  GO prev;
};

// A T-mesh patch: a grid of ni x nj input quads of one face.
using detail::Grid;

struct Arc {
  std::vector<GO> verts;  // input mesh vertices, node to node
  LO curve = kNoIndex;
  [[nodiscard]] LO length() const { return static_cast<LO>(verts.size()) - 1; }
};

struct SideArc {
  LO arc;
  bool forward;
};

// A unit quad of the split patches (Sec. IV.A): lattice cell (x, y) of a patch of a x b.
struct Cell {
  std::array<GO, 4> pts;  // lattice points, counter-clockwise
  LO patch;
  LO x, y, a, b;
};

class Builder {
 public:
  Builder(const mesh::SurfaceMesh& m, const cad::CadModel& model, const CoarseOptions& o)
      : m_(m), model_(model), opt_(o), nv_(m.num_vertices()), v2q_(m) {
    input_points_.reserve(m.points.size());
    for (std::size_t v = 0; v < m.points.size(); ++v)
      input_points_.emplace(point_key(m.points[v]), static_cast<GO>(v));
  }

  CoarseResult run() {
    CoarseResult out;
    Stopwatch clock;
    try {
      if (!m_.triangles.empty()) throw Reject{"the mesh has triangles"};
      if (m_.quads.empty()) throw Reject{"the mesh has no quad"};
      adjacency();
      smooth_curves();
      out.stats.smooth_curves = std::count(smooth_.begin(), smooth_.end(), 1);
      std::vector<char> extra(static_cast<std::size_t>(std::max<LO>(m_.num_cad_faces, 1)), 0);
      std::vector<LO> failed = tmesh(extra);
      if (!failed.empty()) {
        // A patch that is not a grid (an annulus between two closed curves, say): those faces are
        // traced again with traces from their CAD corners too.
        for (LO f : failed) extra[static_cast<std::size_t>(f)] = 1;
        failed = tmesh(extra);
        if (!failed.empty())
          throw Reject{cat("a T-mesh patch of face ", failed.front(), " is not a grid")};
      }
      arcs();
      out.stats.traces = static_cast<std::int64_t>(traces_.size());
      out.stats.traces_across_curves = traces_across_;
      out.stats.tmesh_patches = static_cast<std::int64_t>(grids_.size());
      out.stats.tmesh_arcs = static_cast<std::int64_t>(arcs_.size());
      out.stats.tmesh_nodes = std::count(node_.begin(), node_.end(), 1);
      IntegerProgram ilp = program();
      // CAD compliance the constraints of the paper do not ensure (two CAD corners or curves
      // merged, an irregular vertex collapsed on a curve, a unit quad with a repeated corner): each
      // such merge found in a solution adds "the zero-length path between them is >= 1" and the
      // program is solved again.
      for (int repair = 0;; ++repair) {
        for (int round = 0;; ++round) {
          IlpOptions ilp_options = opt_.ilp;
          if (opt_.traces_across_smooth_curves) ilp_options.preprocess = false;
          const IlpResult sol = solve_integer_program(ilp, ilp_options);
          out.stats.ilp_seconds += sol.seconds;
          out.stats.ilp_status = sol.status;
          ++out.stats.ilp_rounds;
          if (!sol.feasible) throw Reject{cat("the ILP gave no solution (", sol.status, ")")};
          q_ = sol.x;
          split_and_merge();
          auto rows = conflicts();
          if (rows.empty()) {
            coarse_mesh();
            rows = flat_corners();
            if (rows.empty()) break;
          }
          // A row the solution already meets would not change the next solve: stop here.
          for (const auto& r : rows) {
            double sum = 0;
            for (const auto& [a, c] : r.terms)
              sum += c * static_cast<double>(q_[static_cast<std::size_t>(a)]);
            if (sum >= r.lo) throw Reject{"a CAD merge that no row on the arc lengths cuts"};
          }
          if (round + 1 >= kMaxRounds)
            throw Reject{cat("CAD entities still merge after ", kMaxRounds, " ILP rounds")};
          for (const auto& r : rows) ilp.rows.push_back(r);
        }
        out.stats.ilp_variables = ilp.num_variables();
        out.stats.ilp_constraints = static_cast<std::int64_t>(ilp.rows.size());
        out.mesh = {};
        out.layout = {};
        fine_mesh(out);
        if (bad_cquads_.empty()) break;
        // Where the fine mesh is invalid, the patches that made those coarse quads are kept from
        // collapsing, and all is solved again (Repairs::Local): first those patches, then up to
        // kMaxRings rings of patches around them (every patch touching a corner group of a coarse
        // quad cut from the last ones), the first set whose rows the last solution does not
        // meet; only when every ring is already kept from collapsing, the same patches are
        // restored to their input lengths (the input layout is valid), ring by ring. Restoring
        // input lengths first spreads along chains of patches (an arc at its input length forces
        // its patch's opposite side, and so on), which on Block kept most of the model at its
        // input lengths (docs/benchmarks.md, branch coarse10).
        std::vector<IntegerProgram::Row> rows;
        bool fresh = false;
        if (opt_.repairs != Repairs::Restore) {
          LocalRepair next = local_repair_rows();
          rows = std::move(next.rows);
          fresh = !rows.empty();
          if (fresh && next.kind == RowKind::Grow) ++out.stats.repairs_grown;
          if (fresh && next.kind == RowKind::Bound) ++out.stats.repairs_restored;
        } else {
          // The former repairs: a patch's first repair keeps its arcs from collapsing, its next
          // ones restore its input lengths; when every such row is already there, solving again
          // would give the same layout and the same folds (Block: a reflex CAD corner whose cells
          // were single input quads and still folded), so the rows reach rings further out.
          rows = restore_rows(0);
          fresh = new_rows(ilp, rows);
          for (int ring = 1; !fresh && ring <= kMaxRings; ++ring) {
            rows = restore_rows(ring);
            fresh = new_rows(ilp, rows);
          }
        }
        if (!fresh)
          throw Reject{cat(bad_quads_, " fine quads invalid or folded on patches already at ",
                           "their input lengths, and ", kMaxRings,
                           " rings of patches around them")};
        if (repair + 1 >= kMaxRepairs)
          throw Reject{
              cat(bad_quads_, " fine quads invalid or folded after ", kMaxRepairs, " repairs")};
        for (const auto& r : rows) ilp.rows.push_back(r);
        out.stats.repairs = repair + 1;
      }
      out.stats.coarse_quads = static_cast<std::int64_t>(out.layout.blocks.size());
      out.stats.cells = static_cast<std::int64_t>(cquads_.size());
      out.stats.irregular_coarse_vertices = irregular_coarse_;
      out.stats.chords_removed = chord_counts_[0];
      out.stats.chords_closed_kept = chord_counts_[1];
      out.stats.chords_open_at_irregular = chord_counts_[2];
      out.stats.chords_open_elsewhere = chord_counts_[3];
      out.stats.blocks_across_curves = blocks_across_;
      out.stats.smooth_curve_vertices_not_four = stuck_on_smooth_;
      out.stats.fine_quads = static_cast<std::int64_t>(out.mesh.quads.size());
      out.ok = true;
    } catch (const Reject& r) {
      out.ok = false;
      out.failure = r.why;
      out.mesh = {};
      out.layout = {};
    }
    out.stats.seconds = clock.seconds();
    return out;
  }

 private:
  template <typename... A>
  static std::string cat(const A&... a) {
    std::ostringstream s;
    (s << ... << a);
    return s.str();
  }

  // ---------------------------------------------------------------- adjacency
  void adjacency() {
    const auto nq = static_cast<GO>(m_.quads.size());
    edges_.reserve(static_cast<std::size_t>(2 * nq + static_cast<GO>(m_.bars.size())));
    for (GO q = 0; q < nq; ++q) {
      const auto& quad = m_.quads[static_cast<std::size_t>(q)];
      for (int k = 0; k < 4; ++k) {
        EdgeRec& e = edges_[mesh::edge_key(quad[k], quad[(k + 1) % 4])];
        if (e.count < 2) e.q[static_cast<std::size_t>(e.count)] = q;
        ++e.count;
      }
    }
    for (std::size_t b = 0; b < m_.bars.size(); ++b) {
      const auto it = edges_.find(mesh::edge_key(m_.bars[b][0], m_.bars[b][1]));
      if (it != edges_.end()) it->second.curve = m_.bar_curve[b];
    }
  }

  [[nodiscard]] LO valence(GO v) const { return v2q_.valence(v); }
  [[nodiscard]] const mesh::VertexClass& vc(GO v) const {
    return m_.vclass[static_cast<std::size_t>(v)];
  }
  [[nodiscard]] bool regular_interior(GO v) const { return vc(v).dim == 2 && valence(v) == 4; }
  [[nodiscard]] const EdgeRec& edge(GO a, GO b) const { return edges_.at(mesh::edge_key(a, b)); }
  [[nodiscard]] EdgeRec& edge(GO a, GO b) { return edges_.at(mesh::edge_key(a, b)); }

  // An edge inside one face: traces follow it, patches are crossed through it.
  [[nodiscard]] bool interior(const EdgeRec& e) const {
    return e.curve == kNoIndex && e.count == 2 &&
           m_.quad_face[static_cast<std::size_t>(e.q[0])] ==
               m_.quad_face[static_cast<std::size_t>(e.q[1])];
  }
  [[nodiscard]] bool crossable(const EdgeRec& e) const { return interior(e) && !e.traced; }

  [[nodiscard]] std::array<GO, 2> neighbours_in_quad(GO q, GO v) const {
    std::array<GO, 2> nb{};
    if (!detail::neighbours_in_quad(m_.quads[static_cast<std::size_t>(q)], v, nb))
      throw Reject{cat("vertex ", v, " not in quad ", q)};
    return nb;
  }

  // At a regular vertex c reached from prev: the vertex across c on the same grid line, and the
  // two across it (left first: the side of the quads' interior when they run c -> next).
  struct Cross {
    GO next, left, right;
  };
  [[nodiscard]] Cross cross_at(GO c, GO prev) const {
    std::vector<GO> nb;
    for (GO q : v2q_[c])
      for (GO w : neighbours_in_quad(q, c))
        if (std::find(nb.begin(), nb.end(), w) == nb.end()) nb.push_back(w);
    if (nb.size() != 4) throw Reject{cat("vertex ", c, " has ", nb.size(), " neighbours")};
    const EdgeRec& e = edge(c, prev);
    std::array<GO, 2> side{-1, -1};
    for (int s = 0; s < 2; ++s) {
      const auto n = neighbours_in_quad(e.q[static_cast<std::size_t>(s)], c);
      side[static_cast<std::size_t>(s)] = n[0] == prev ? n[1] : n[0];
    }
    GO next = -1;
    for (GO w : nb)
      if (w != prev && w != side[0] && w != side[1]) next = w;
    if (next < 0) throw Reject{cat("no straight continuation at vertex ", c)};
    // The quad with c followed by next: its vertex before c is on the left.
    GO left = side[0];
    for (GO q : v2q_[c]) {
      const auto& quad = m_.quads[static_cast<std::size_t>(q)];
      for (int k = 0; k < 4; ++k)
        if (quad[k] == c && quad[(k + 1) % 4] == next) left = quad[(k + 3) % 4];
    }
    return {next, left, left == side[0] ? side[1] : side[0]};
  }

  // Smooth curves (CoarseOptions::cross_smooth_curves).
  void smooth_curves() {
    smooth_.assign(static_cast<std::size_t>(std::max<LO>(m_.num_cad_curves, 0)), 0);
    if (!opt_.cross_smooth_curves) return;
    for (LO c = 0; c < m_.num_cad_curves && c < model_.num_curves(); ++c)
      smooth_[static_cast<std::size_t>(c)] = cad::smooth_across(model_, c, opt_.smooth_angle_deg);
  }
  [[nodiscard]] bool smooth_curve(LO c) const {
    return c >= 0 && static_cast<std::size_t>(c) < smooth_.size() &&
           smooth_[static_cast<std::size_t>(c)] != 0;
  }

  // Whether a trace reaching vertex cur from prev runs on across a smooth curve: cur lies on one,
  // with two quads on each side (four in all), so that the straight continuation is the edge into
  // the other face and the curve's two edges at cur are the ones left and right.
  [[nodiscard]] bool crosses_smooth_curve(GO cur, GO prev) const {
    const auto& k = vc(cur);
    if (!opt_.traces_across_smooth_curves) return false;
    if (k.dim != 1 || !smooth_curve(k.entity) || valence(cur) != 4) return false;
    const EdgeRec& in = edge(cur, prev);
    if (!interior(in)) return false;
    const Cross c = cross_at(cur, prev);
    const auto out = edges_.find(mesh::edge_key(cur, c.next));
    const auto l = edges_.find(mesh::edge_key(cur, c.left));
    const auto r = edges_.find(mesh::edge_key(cur, c.right));
    if (out == edges_.end() || l == edges_.end() || r == edges_.end()) return false;
    return interior(out->second) &&
           m_.quad_face[static_cast<std::size_t>(out->second.q[0])] !=
               m_.quad_face[static_cast<std::size_t>(in.q[0])] &&
           l->second.curve == k.entity && r->second.curve == k.entity;
  }

  // ---------------------------------------------------------------- T-mesh (Sec. III.A)
  struct Start {
    GO v, w;
    auto operator<=>(const Start&) const = default;
  };

  // Trace starts: edges leaving irregular interior vertices, and the interior edges of the sides
  // of other than two quads of boundary vertices (as quad_layout.cpp); in the faces of `extra`,
  // every interior edge at a CAD corner too.
  [[nodiscard]] std::vector<Start> starts(const std::vector<char>& extra) const {
    std::vector<Start> out;
    for (GO v = 0; v < nv_; ++v) {
      const auto& c = vc(v);
      const auto quads = v2q_[v];
      if (quads.empty() || (c.dim == 2 && quads.size() == 4)) continue;
      auto across = [&](GO w, GO q) -> GO {
        const EdgeRec& e = edge(v, w);
        if (!interior(e)) return -1;
        return e.q[0] == q ? e.q[1] : e.q[0];
      };
      for (const auto& [w, a, irregular_side] : detail::side_edges(m_, v, quads, across)) {
        const LO f = m_.quad_face[static_cast<std::size_t>(quads[a])];
        if (c.dim == 2 || irregular_side || (c.dim == 0 && extra[static_cast<std::size_t>(f)]))
          out.push_back({v, w});
      }
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  [[nodiscard]] bool pair35(GO a, GO b) const {
    if (vc(a).dim != 2 || vc(b).dim != 2) return false;
    const LO x = valence(a), y = valence(b);
    return (x == 3 && y == 5) || (x == 5 && y == 3);
  }

  // Motorcycle traces with the cone stopping rule: a trace stops when it has crossed, on each of
  // its sides, a trace whose origin lies in its cone of half-angle alpha (l_ji <= tan(alpha) l_ij),
  // at an irregular or boundary vertex, or where its line is traced already. All traces advance
  // one edge per round in a fixed order. Returns the faces with a patch that is not a grid.
  std::vector<LO> tmesh(const std::vector<char>& extra) {
    for (auto& [k, e] : edges_) e.traced = false;
    traces_.clear();
    crossed_.clear();
    traces_across_ = 0;
    std::vector<std::vector<Passage>> pass(static_cast<std::size_t>(nv_));
    const double tan_alpha = std::tan(opt_.alpha);
    std::vector<LO> live;
    for (const auto& [v, w] : starts(extra)) {
      EdgeRec& e = edge(v, w);
      if (e.traced) continue;
      e.traced = true;
      Trace t;
      t.path = {v, w};
      t.tan_alpha = tan_alpha;
      traces_.push_back(std::move(t));
      crossed_.push_back(0);
      live.push_back(static_cast<LO>(traces_.size()) - 1);
    }
    std::vector<LO> next_live;
    auto hit = [&](LO t, LO step, LO other, LO other_step) {
      Trace& a = traces_[static_cast<std::size_t>(t)];
      const Trace& b = traces_[static_cast<std::size_t>(other)];
      a.hits.push_back({step, other_step <= step, pair35(a.path[0], b.path[0])});
      // Geometric consistency (4): b's origin outside a's cone separates b from the crossing.
      if (static_cast<double>(other_step) > a.tan_alpha * step)
        traces_[static_cast<std::size_t>(other)].separate =
            std::min(traces_[static_cast<std::size_t>(other)].separate, other_step);
    };
    while (!live.empty()) {
      next_live.clear();
      for (LO t : live) {
        Trace& tr = traces_[static_cast<std::size_t>(t)];
        const GO cur = tr.path.back(), prev = tr.path[tr.path.size() - 2];
        const auto step = static_cast<LO>(tr.path.size()) - 1;
        const bool across = crosses_smooth_curve(cur, prev);
        if (across && !crossed_[static_cast<std::size_t>(t)]) {
          crossed_[static_cast<std::size_t>(t)] = 1;
          ++traces_across_;
        }
        if (!regular_interior(cur) && !across) {
          // The end: another irregular vertex (in the cone at distance 0) or a CAD curve, which
          // the origin must not reach (a face cannot pinch, an interior vertex stays inside).
          if (vc(cur).dim == 2)
            tr.hits.push_back({step, true, pair35(tr.path[0], cur)});
          else
            tr.separate = std::min(tr.separate, step);
          continue;
        }
        const Cross c = cross_at(cur, prev);
        bool stop = false, left = false, right = false;
        for (const Passage& p : pass[static_cast<std::size_t>(cur)]) {
          if (p.prev == prev || p.prev == c.next) {
            stop = true;  // the same line, traced already
            continue;
          }
          hit(t, step, p.trace, p.step);
          hit(p.trace, p.step, t, step);
          if (static_cast<double>(p.step) <= tr.tan_alpha * step)
            (p.prev == c.left ? left : right) = true;
        }
        if (stop || (left && right)) continue;
        EdgeRec& e = edge(cur, c.next);
        if (e.traced) continue;
        e.traced = true;
        pass[static_cast<std::size_t>(cur)].push_back({t, step, prev});
        tr.path.push_back(c.next);
        next_live.push_back(t);
      }
      live.swap(next_live);
    }
    // Validity (3): the first crossing with an origin in the pi/4 cone is separated, unless the
    // two origins are a 3-5 pair (their collapse leaves a regular vertex).
    for (Trace& t : traces_) {
      std::stable_sort(t.hits.begin(), t.hits.end(),
                       [](const Trace::Hit& a, const Trace::Hit& b) { return a.step < b.step; });
      for (const Trace::Hit& h : t.hits)
        if (h.in_quarter_cone) {
          if (!h.pair35) t.separate = std::min(t.separate, h.step);
          break;
        }
    }
    return patches();
  }

  // Patches: quads joined across untraced interior edges, each as a grid.
  std::vector<LO> patches() {
    grids_.clear();
    const auto nq = static_cast<GO>(m_.quads.size());
    std::vector<char> seen(static_cast<std::size_t>(nq), 0);
    std::vector<GO> members, stack;
    std::vector<LO> failed;
    for (GO seed = 0; seed < nq; ++seed) {
      if (seen[static_cast<std::size_t>(seed)]) continue;
      members.clear();
      stack.assign(1, seed);
      seen[static_cast<std::size_t>(seed)] = 1;
      while (!stack.empty()) {
        const GO q = stack.back();
        stack.pop_back();
        members.push_back(q);
        const auto& quad = m_.quads[static_cast<std::size_t>(q)];
        for (int k = 0; k < 4; ++k) {
          const EdgeRec& e = edge(quad[k], quad[(k + 1) % 4]);
          if (!crossable(e)) continue;
          const GO other = e.q[0] == q ? e.q[1] : e.q[0];
          if (seen[static_cast<std::size_t>(other)]) continue;
          seen[static_cast<std::size_t>(other)] = 1;
          stack.push_back(other);
        }
      }
      std::sort(members.begin(), members.end());
      const LO f = m_.quad_face[static_cast<std::size_t>(seed)];
      if (auto g = grid(members, f)) {
        grids_.push_back(std::move(*g));
      } else {
        failed.push_back(f);
      }
    }
    std::sort(failed.begin(), failed.end());
    failed.erase(std::unique(failed.begin(), failed.end()), failed.end());
    return failed;
  }

  // The patch `members` (sorted quad ids) as an ni x nj grid; none when it is not one.
  [[nodiscard]] std::optional<Grid> grid(const std::vector<GO>& members, LO face) const {
    auto in_patch = [&](GO q) { return std::binary_search(members.begin(), members.end(), q); };
    auto across = [&](GO q, GO a, GO b) -> GO {
      const EdgeRec& e = edge(a, b);
      if (!crossable(e)) return -1;
      const GO other = e.q[0] == q ? e.q[1] : e.q[0];
      return in_patch(other) ? other : -1;
    };
    return detail::patch_grid(m_, members, face, across);
  }

  // Nodes (irregular and boundary-turning vertices, trace crossings and ends, patch corners) and
  // the arcs between them, with each patch's four sides as arc sequences.
  void arcs() {
    node_.assign(static_cast<std::size_t>(nv_), 0);
    std::vector<LO> degree(static_cast<std::size_t>(nv_), 0);
    for (const auto& [k, e] : edges_) {
      if (interior(e) && !e.traced) continue;
      ++degree[static_cast<std::size_t>(k >> 32)];
      ++degree[static_cast<std::size_t>(k & 0xffffffffULL)];
    }
    for (GO v = 0; v < nv_; ++v)
      if (vc(v).dim == 0 || (vc(v).dim == 2 && valence(v) != 4) ||
          (degree[static_cast<std::size_t>(v)] != 0 && degree[static_cast<std::size_t>(v)] != 2))
        node_[static_cast<std::size_t>(v)] = 1;
    for (const Grid& g : grids_)
      for (GO c : {g.at(0, 0), g.at(g.ni, 0), g.at(g.ni, g.nj), g.at(0, g.nj)})
        node_[static_cast<std::size_t>(c)] = 1;
    arcs_.clear();
    edge_arc_.clear();
    sides_.assign(grids_.size(), {});
    for (std::size_t p = 0; p < grids_.size(); ++p)
      for (int s = 0; s < 4; ++s) {
        const std::vector<GO> seq = grids_[p].side(s);
        std::size_t k0 = 0;
        for (std::size_t k = 1; k < seq.size(); ++k) {
          if (!node_[static_cast<std::size_t>(seq[k])] && k + 1 < seq.size()) continue;
          const std::uint64_t key = mesh::edge_key(seq[k0], seq[k0 + 1]);
          auto it = edge_arc_.find(key);
          LO a;
          if (it == edge_arc_.end()) {
            a = static_cast<LO>(arcs_.size());
            Arc arc;
            arc.verts.assign(seq.begin() + static_cast<std::ptrdiff_t>(k0),
                             seq.begin() + static_cast<std::ptrdiff_t>(k) + 1);
            arc.curve = edge(seq[k0], seq[k0 + 1]).curve;
            for (std::size_t i = k0; i < k; ++i) edge_arc_[mesh::edge_key(seq[i], seq[i + 1])] = a;
            arcs_.push_back(std::move(arc));
          } else {
            a = it->second;
          }
          const Arc& arc = arcs_[static_cast<std::size_t>(a)];
          if (arc.length() != static_cast<LO>(k - k0))
            throw Reject{cat("arc of ", arc.length(), " edges met as ", k - k0)};
          const bool fwd = arc.verts[0] == seq[k0] && arc.verts[1] == seq[k0 + 1];
          sides_[p][static_cast<std::size_t>(s)].push_back({a, fwd});
          k0 = k;
        }
      }
  }

  // Arcs of trace t over its first `steps` edges.
  [[nodiscard]] std::vector<LO> prefix_arcs(const Trace& t, LO steps) const {
    std::vector<LO> out;
    for (LO s = 0; s < steps && s + 1 < static_cast<LO>(t.path.size()); ++s) {
      const auto it = edge_arc_.find(mesh::edge_key(t.path[static_cast<std::size_t>(s)],
                                                    t.path[static_cast<std::size_t>(s) + 1]));
      if (it != edge_arc_.end() && (out.empty() || out.back() != it->second))
        out.push_back(it->second);
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  // ---------------------------------------------------------------- ILP (Sec. III.B-C)
  [[nodiscard]] IntegerProgram program() const {
    IntegerProgram p;
    const auto na = arcs_.size();
    const double inf = std::numeric_limits<double>::infinity();
    for (const Arc& a : arcs_) {
      p.objective.push_back(1.0 / a.length());  // (6)
      p.lower.push_back(0);                     // (1)
      // At most the input length: then the split points of an arc or patch (Sec. IV.A) stand on
      // distinct input vertices strictly inside it, which places them (Sec. IV.C).
      p.upper.push_back(a.length());
    }
    std::vector<double> coef(na, 0);
    std::vector<int> used;
    auto flush = [&](double lo, double hi) {
      IntegerProgram::Row r;
      std::sort(used.begin(), used.end());
      used.erase(std::unique(used.begin(), used.end()), used.end());
      for (int v : used)
        if (coef[static_cast<std::size_t>(v)] != 0)
          r.terms.emplace_back(v, coef[static_cast<std::size_t>(v)]);
      for (int v : used) coef[static_cast<std::size_t>(v)] = 0;
      used.clear();
      if (!r.terms.empty()) {
        r.lo = lo;
        r.hi = hi;
        p.rows.push_back(std::move(r));
      }
    };
    for (const auto& sides : sides_)  // (2)
      for (int s = 0; s < 2; ++s) {
        for (const SideArc& x : sides[static_cast<std::size_t>(s)]) {
          coef[static_cast<std::size_t>(x.arc)] += 1;
          used.push_back(x.arc);
        }
        for (const SideArc& x : sides[static_cast<std::size_t>(s) + 2]) {
          coef[static_cast<std::size_t>(x.arc)] -= 1;
          used.push_back(x.arc);
        }
        flush(0, 0);
      }
    for (const Trace& t : traces_) {  // (3), (4) and the ends on CAD curves
      if (t.separate == kNever) continue;
      for (LO a : prefix_arcs(t, t.separate)) {
        coef[static_cast<std::size_t>(a)] = 1;
        used.push_back(a);
      }
      flush(1, inf);
    }
    // A curve cannot vanish (a closed one keeps three edges, so that its coarse edges join
    // distinct vertices).
    std::map<LO, std::vector<int>> by_curve;
    for (std::size_t a = 0; a < na; ++a)
      if (arcs_[a].curve != kNoIndex) by_curve[arcs_[a].curve].push_back(static_cast<int>(a));
    for (const auto& [c, list] : by_curve) {
      for (int a : list) {
        coef[static_cast<std::size_t>(a)] = 1;
        used.push_back(a);
      }
      const auto& ends = m_.curve_corners[static_cast<std::size_t>(c)];
      flush(ends[0] == ends[1] ? 3 : 1, inf);
    }
    return p;
  }

  // ---------------------------------------------------------------- Sec. IV.A-B
  [[nodiscard]] GO arc_point(LO a, LO t) const {
    const Arc& arc = arcs_[static_cast<std::size_t>(a)];
    const long q = q_[static_cast<std::size_t>(a)];
    if (t == 0) return node_point_.at(arc.verts.front());
    if (t == q) return node_point_.at(arc.verts.back());
    return arc_base_[static_cast<std::size_t>(a)] + t - 1;
  }

  // Lattice points of side s of patch p, from its first corner to its last.
  [[nodiscard]] std::vector<GO> side_points(std::size_t p, int s,
                                            std::vector<LO>* from_arc = nullptr) const {
    std::vector<GO> out;
    for (const SideArc& x : sides_[p][static_cast<std::size_t>(s)]) {
      const auto q = static_cast<LO>(q_[static_cast<std::size_t>(x.arc)]);
      if (out.empty()) out.push_back(arc_point(x.arc, x.forward ? 0 : q));
      for (LO t = 1; t <= q; ++t) {
        out.push_back(arc_point(x.arc, x.forward ? t : q - t));
        if (from_arc != nullptr) from_arc->push_back(x.arc);
      }
    }
    if (out.empty()) {
      const SideArc& x = sides_[p][static_cast<std::size_t>(s)].front();
      out.push_back(arc_point(x.arc, 0));
    }
    return out;
  }

  [[nodiscard]] std::vector<LO> side_arcs(std::size_t p, int s) const {
    std::vector<LO> out;
    for (const SideArc& x : sides_[p][static_cast<std::size_t>(s)]) out.push_back(x.arc);
    return out;
  }

  // The arcs of side s of patch p after its last arc of nonzero length in the solution (all of
  // them when the side has length 0).
  [[nodiscard]] std::vector<LO> trailing_zero_arcs(std::size_t p, int s) const {
    std::vector<LO> out;
    for (const SideArc& x : sides_[p][static_cast<std::size_t>(s)]) {
      if (q_[static_cast<std::size_t>(x.arc)] != 0)
        out.clear();
      else
        out.push_back(x.arc);
    }
    return out;
  }

  // Points x and y are one (zero distance); the distance between them is the sum of `arcs`.
  void link(GO x, GO y, std::vector<LO> arcs) {
    if (x == y) return;
    dsu_.unite(x, y);
    const auto l = static_cast<LO>(labels_.size());
    labels_.push_back(std::move(arcs));
    links_[static_cast<std::size_t>(x)].emplace_back(y, l);
    links_[static_cast<std::size_t>(y)].emplace_back(x, l);
  }

  // The row "the zero-length path from x to y keeps a length >= 1" (breadth-first over links).
  [[nodiscard]] IntegerProgram::Row separation(GO x, GO y) const {
    std::vector<std::pair<GO, LO>> from(rep_.size(), {-1, -1});
    std::vector<GO> queue{x};
    from[static_cast<std::size_t>(x)] = {x, -1};
    for (std::size_t h = 0; h < queue.size() && from[static_cast<std::size_t>(y)].first < 0; ++h)
      for (const auto& [z, l] : links_[static_cast<std::size_t>(queue[h])])
        if (from[static_cast<std::size_t>(z)].first < 0) {
          from[static_cast<std::size_t>(z)] = {queue[h], l};
          queue.push_back(z);
        }
    if (from[static_cast<std::size_t>(y)].first < 0) throw Reject{"no zero-length path to cut"};
    std::vector<LO> arcs;
    for (GO z = y; z != x; z = from[static_cast<std::size_t>(z)].first) {
      const auto& l = labels_[static_cast<std::size_t>(from[static_cast<std::size_t>(z)].second)];
      arcs.insert(arcs.end(), l.begin(), l.end());
    }
    std::sort(arcs.begin(), arcs.end());
    arcs.erase(std::unique(arcs.begin(), arcs.end()), arcs.end());
    if (arcs.empty()) throw Reject{"a merge no arc length can undo"};
    IntegerProgram::Row r;
    for (LO a : arcs) r.terms.emplace_back(a, 1.0);
    r.lo = 1;
    r.hi = std::numeric_limits<double>::infinity();
    return r;
  }

  // Merges of the current solution that break the CAD (see run()), as rows that forbid them.
  [[nodiscard]] std::vector<IntegerProgram::Row> conflicts() {
    std::vector<IntegerProgram::Row> rows;
    const auto np = static_cast<GO>(rep_.size());
    // Per group: its first corner, first curve point, first irregular interior point.
    std::unordered_map<GO, std::array<GO, 3>> first;
    auto irregular = [&](GO v) { return vc(v).dim == 2 && valence(v) != 4; };
    for (GO x = 0; x < np; ++x) {
      const GO r = dsu_.find(x);
      const GO v = rep_[static_cast<std::size_t>(x)];
      const auto it = first.try_emplace(r, std::array<GO, 3>{-1, -1, -1}).first;
      auto& f = it->second;
      const int d = vc(v).dim;
      if (d == 0) {
        if (f[0] >= 0 && rep_[static_cast<std::size_t>(f[0])] != v)
          rows.push_back(separation(f[0], x));
        else if (f[0] < 0)
          f[0] = x;
      } else if (d == 1) {
        if (f[1] >= 0 && vc(rep_[static_cast<std::size_t>(f[1])]).entity != vc(v).entity &&
            f[0] < 0)
          rows.push_back(separation(f[1], x));
        else if (f[1] < 0)
          f[1] = x;
      } else if (irregular(v) && f[2] < 0) {
        f[2] = x;
      }
    }
    for (const auto& [r, f] : first) {
      const GO b = f[0] >= 0 ? f[0] : f[1];
      if (f[2] >= 0 && b >= 0) rows.push_back(separation(f[2], b));
    }
    for (const Cell& c : cells_)
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
          if (dsu_.find(c.pts[static_cast<std::size_t>(i)]) ==
              dsu_.find(c.pts[static_cast<std::size_t>(j)]))
            rows.push_back(
                separation(c.pts[static_cast<std::size_t>(i)], c.pts[static_cast<std::size_t>(j)]));
    // A CAD corner in no unit quad (every patch at it collapsed): the first patch with a corner
    // there keeps both its sides at the corner (so an area >= 1).
    std::vector<char> in_cell(static_cast<std::size_t>(np), 0);
    for (const Cell& c : cells_)
      for (GO x : c.pts) in_cell[static_cast<std::size_t>(dsu_.find(x))] = 1;
    for (const auto& [v, x] : node_point_) {
      if (vc(v).dim != 0 || in_cell[static_cast<std::size_t>(dsu_.find(x))]) continue;
      bool done = false;
      for (std::size_t p = 0; p < grids_.size() && !done; ++p) {
        const Grid& g = grids_[p];
        const std::array<GO, 4> corner{g.at(0, 0), g.at(g.ni, 0), g.at(g.ni, g.nj), g.at(0, g.nj)};
        for (int k = 0; k < 4 && !done; ++k) {
          if (corner[static_cast<std::size_t>(k)] != v) continue;
          for (int s = k; s <= k + 1; ++s) {
            IntegerProgram::Row r;
            for (LO a : side_arcs(p, s % 4)) r.terms.emplace_back(a, 1.0);
            std::sort(r.terms.begin(), r.terms.end());
            r.terms.erase(std::unique(r.terms.begin(), r.terms.end()), r.terms.end());
            r.lo = 1;
            r.hi = std::numeric_limits<double>::infinity();
            rows.push_back(std::move(r));
          }
          done = true;
        }
      }
      if (!done) throw Reject{cat("CAD corner ", vc(v).entity, " is no patch corner")};
    }
    // Distinct rows only, in a fixed order.
    std::sort(rows.begin(), rows.end(),
              [](const auto& a, const auto& b) { return a.terms < b.terms; });
    rows.erase(std::unique(rows.begin(), rows.end(),
                           [](const auto& a, const auto& b) { return a.terms == b.terms; }),
               rows.end());
    return rows;
  }

  // The patches a repair acts on: every patch touching a corner group of a bad coarse quad, and
  // the patch it was cut from; `rings` times more, also every patch touching a corner group of a
  // coarse quad cut from those patches. Sorted, distinct.
  [[nodiscard]] std::vector<LO> repair_patches(int rings) const {
    std::vector<char> bad_group(static_cast<std::size_t>(ng_), 0);
    std::vector<LO> patches;
    for (std::size_t k : bad_cquads_) {
      for (GO g : cquads_[k].v) bad_group[static_cast<std::size_t>(g)] = 1;
      patches.push_back(cells_[static_cast<std::size_t>(cquads_[k].cell)].patch);
    }
    for (std::size_t x = 0; x < rep_.size(); ++x)
      if (bad_group[static_cast<std::size_t>(group_[x])])
        patches.insert(patches.end(), point_patches_[x].begin(), point_patches_[x].end());
    std::sort(patches.begin(), patches.end());
    patches.erase(std::unique(patches.begin(), patches.end()), patches.end());
    for (int ring = 0; ring < rings; ++ring) {
      std::vector<char> in(grids_.size(), 0);
      for (LO p : patches) in[static_cast<std::size_t>(p)] = 1;
      for (const CQuad& q : cquads_)
        if (in[static_cast<std::size_t>(cells_[static_cast<std::size_t>(q.cell)].patch)])
          for (GO g : q.v) bad_group[static_cast<std::size_t>(g)] = 1;
      for (std::size_t x = 0; x < rep_.size(); ++x)
        if (bad_group[static_cast<std::size_t>(group_[x])])
          patches.insert(patches.end(), point_patches_[x].begin(), point_patches_[x].end());
      std::sort(patches.begin(), patches.end());
      patches.erase(std::unique(patches.begin(), patches.end()), patches.end());
    }
    return patches;
  }

  // Single-arc rows q_a >= lo(a) for the side arcs of `patches`, one per arc, by arc.
  template <class Lower>
  [[nodiscard]] std::vector<IntegerProgram::Row> arc_rows(const std::vector<LO>& patches,
                                                          Lower lower) const {
    std::map<LO, double> arcs;  // arc -> lower bound
    for (LO p : patches)
      for (int s = 0; s < 4; ++s)
        for (LO a : side_arcs(static_cast<std::size_t>(p), s)) {
          const double lo = lower(p, a);
          auto [it, fresh] = arcs.emplace(a, lo);
          if (!fresh) it->second = std::max(it->second, lo);
        }
    std::vector<IntegerProgram::Row> rows;
    for (const auto& [a, lo] : arcs) {
      IntegerProgram::Row r;
      r.terms.emplace_back(a, 1.0);
      r.lo = lo;
      r.hi = std::numeric_limits<double>::infinity();
      rows.push_back(std::move(r));
    }
    return rows;
  }

  // No-collapse rows q_a >= 1 for the side arcs of `patches` (Repairs::Grow and Local).
  [[nodiscard]] std::vector<IntegerProgram::Row> keep_rows(const std::vector<LO>& patches) const {
    return arc_rows(patches, [](LO, LO) { return 1.0; });
  }

  // Rows q_a >= l_a (the input lengths) for the side arcs of `patches`.
  [[nodiscard]] std::vector<IntegerProgram::Row> bound_rows(const std::vector<LO>& patches) const {
    return arc_rows(patches, [this](LO, LO a) {
      return static_cast<double>(arcs_[static_cast<std::size_t>(a)].length());
    });
  }

  // Whether the last solution meets every row of `rows`: solving again with them added would
  // give the same layout (CBC is deterministic), so a repair made of them changes nothing.
  [[nodiscard]] bool met(const std::vector<IntegerProgram::Row>& rows) const {
    for (const auto& r : rows) {
      double sum = 0;
      for (const auto& [a, c] : r.terms)
        sum += c * static_cast<double>(q_[static_cast<std::size_t>(a)]);
      if (sum < r.lo || sum > r.hi) return false;
    }
    return true;
  }

  // Rows q_a >= min(l_a, q_a + 1) for the side arcs of `patches`: each arc one coarse unit longer
  // than in the last solution, up to its input length (Repairs::Grow).
  [[nodiscard]] std::vector<IntegerProgram::Row> grow_rows(const std::vector<LO>& patches) const {
    return arc_rows(patches, [this](LO, LO a) {
      const auto i = static_cast<std::size_t>(a);
      return std::min(static_cast<double>(arcs_[i].length()), static_cast<double>(q_[i] + 1));
    });
  }

  // The three kinds of rows a local repair adds, in the order they are tried.
  enum class RowKind { Keep, Grow, Bound };
  struct LocalRepair {
    std::vector<IntegerProgram::Row> rows;
    RowKind kind = RowKind::Keep;
  };

  // The rows of the next repair (Repairs::Grow and Local): for each kind of rows in turn (no
  // collapse; one unit longer, with Repairs::Grow only; the input lengths), on the bad coarse
  // quads' patches, then on up to kMaxRings rings of patches around them, the first set the last
  // solution does not meet. Empty rows when every such set is met.
  [[nodiscard]] LocalRepair local_repair_rows() const {
    std::vector<std::vector<LO>> rings;
    for (int ring = 0; ring <= kMaxRings; ++ring) rings.push_back(repair_patches(ring));
    for (const RowKind kind : {RowKind::Keep, RowKind::Grow, RowKind::Bound}) {
      if (kind == RowKind::Grow && opt_.repairs != Repairs::Grow) continue;
      for (const auto& patches : rings) {
        auto rows = kind == RowKind::Keep   ? keep_rows(patches)
                    : kind == RowKind::Grow ? grow_rows(patches)
                                            : bound_rows(patches);
        if (!met(rows)) return {std::move(rows), kind};
      }
    }
    return {};
  }

  // Rows of the former repairs (Repairs::Restore): q_a >= 1 on a patch's first repair, q_a >= l_a
  // on its next ones, for the patches of repair_patches(rings).
  [[nodiscard]] std::vector<IntegerProgram::Row> restore_rows(int rings) {
    const std::vector<LO> patches = repair_patches(rings);
    repair_level_.resize(grids_.size(), 0);
    std::vector<int> level(grids_.size(), 0);
    for (LO p : patches)
      level[static_cast<std::size_t>(p)] = ++repair_level_[static_cast<std::size_t>(p)];
    return arc_rows(patches, [&](LO p, LO a) {
      return level[static_cast<std::size_t>(p)] == 1
                 ? 1.0
                 : static_cast<double>(arcs_[static_cast<std::size_t>(a)].length());
    });
  }

  // Whether a row of `rows` (single-arc lower bounds, restore_rows) is not yet in the program:
  // no row of the program on the same arc with a bound as high.
  [[nodiscard]] static bool new_rows(const IntegerProgram& ilp,
                                     const std::vector<IntegerProgram::Row>& rows) {
    std::map<LO, double> have;
    for (const auto& r : ilp.rows)
      if (r.terms.size() == 1 && r.terms.front().second == 1.0 &&
          r.hi == std::numeric_limits<double>::infinity()) {
        auto [it, fresh] = have.emplace(r.terms.front().first, r.lo);
        if (!fresh) it->second = std::max(it->second, r.lo);
      }
    for (const auto& r : rows) {
      const auto it = have.find(r.terms.front().first);
      if (it == have.end() || it->second < r.lo) return true;
    }
    return false;
  }

  // A coarse quad corner between two edges on CAD curves away from a CAD corner is flat (an
  // interior node merged onto the curve made it): the row separating them.
  [[nodiscard]] std::vector<IntegerProgram::Row> flat_corners() {
    std::vector<IntegerProgram::Row> rows;
    std::vector<char> flat(static_cast<std::size_t>(ng_), 0);
    for (const CQuad& q : cquads_)
      for (int k = 0; k < 4; ++k) {
        const GO g = q.v[static_cast<std::size_t>(k)];
        if (vc(center_[static_cast<std::size_t>(g)]).dim == 0) continue;
        if (cedges_[static_cast<std::size_t>(q.e[static_cast<std::size_t>(k)])].curve != kNoIndex &&
            cedges_[static_cast<std::size_t>(q.e[static_cast<std::size_t>((k + 3) % 4)])].curve !=
                kNoIndex)
          flat[static_cast<std::size_t>(g)] = 1;
      }
    std::vector<GO> inner(static_cast<std::size_t>(ng_), -1),
        on_curve(static_cast<std::size_t>(ng_), -1);
    for (const auto& [v, x] : node_point_) {
      const GO g = group_[static_cast<std::size_t>(x)];
      if (!flat[static_cast<std::size_t>(g)]) continue;
      GO& slot = vc(v).dim == 2 ? inner[static_cast<std::size_t>(g)]
                                : on_curve[static_cast<std::size_t>(g)];
      if (slot < 0 || x < slot) slot = x;
    }
    for (GO g = 0; g < ng_; ++g) {
      if (!flat[static_cast<std::size_t>(g)]) continue;
      // Only curve vertices in the group and the input has the same flat corner there (a quad
      // of the face whose two edges at one of them lie on curves: wing_fuselage has one): no row
      // can separate it and it is the input's own. Kept; the fold check of the fine mesh still
      // stands behind it.
      if (inner[static_cast<std::size_t>(g)] < 0 && on_curve[static_cast<std::size_t>(g)] >= 0 &&
          input_flat_corner(g))
        continue;
      if (inner[static_cast<std::size_t>(g)] < 0 || on_curve[static_cast<std::size_t>(g)] < 0)
        throw Reject{"a coarse quad has a flat corner on a CAD curve"};
      rows.push_back(
          separation(inner[static_cast<std::size_t>(g)], on_curve[static_cast<std::size_t>(g)]));
    }
    return rows;
  }

  // Whether a member of group g is a curve vertex where an input quad has both its edges at it
  // on CAD curves (a flat corner of the input mesh).
  [[nodiscard]] bool input_flat_corner(GO g) const {
    for (std::size_t x = 0; x < rep_.size(); ++x) {
      if (group_[x] != g) continue;
      const GO v = rep_[x];
      if (vc(v).dim != 1) continue;
      for (GO q : v2q_[v]) {
        const auto nb = neighbours_in_quad(q, v);
        if (edge(v, nb[0]).curve != kNoIndex && edge(v, nb[1]).curve != kNoIndex) return true;
      }
    }
    return false;
  }

  void split_and_merge() {
    // Points: nodes, then the inner points of arcs of length >= 2, then the inner points of the
    // patches, each with a representative input vertex.
    node_point_.clear();
    rep_.clear();
    for (const Arc& a : arcs_)
      for (GO v : {a.verts.front(), a.verts.back()})
        if (node_point_.emplace(v, static_cast<GO>(rep_.size())).second) rep_.push_back(v);
    arc_base_.assign(arcs_.size(), 0);
    for (std::size_t a = 0; a < arcs_.size(); ++a) {
      arc_base_[a] = static_cast<GO>(rep_.size());
      const long q = q_[a];
      const LO l = arcs_[a].length();
      for (long t = 1; t < q; ++t)
        rep_.push_back(arcs_[a].verts[static_cast<std::size_t>(
            std::lround(static_cast<double>(t) * l / static_cast<double>(q)))]);
    }
    dsu_ = {};
    dsu_.resize(static_cast<GO>(rep_.size()));
    links_.assign(rep_.size(), {});
    point_patches_.assign(rep_.size(), {});
    labels_.clear();
    for (std::size_t a = 0; a < arcs_.size(); ++a)
      if (q_[a] == 0)
        link(node_point_.at(arcs_[a].verts.front()), node_point_.at(arcs_[a].verts.back()),
             {static_cast<LO>(a)});
    cells_.clear();
    for (std::size_t p = 0; p < grids_.size(); ++p) {
      std::array<std::vector<GO>, 4> sp;
      for (int s = 0; s < 4; ++s) sp[static_cast<std::size_t>(s)] = side_points(p, s);
      for (const auto& side : sp)
        for (GO x : side) point_patches_[static_cast<std::size_t>(x)].push_back(static_cast<LO>(p));
      const auto a = static_cast<LO>(sp[0].size()) - 1, b = static_cast<LO>(sp[1].size()) - 1;
      if (a != static_cast<LO>(sp[2].size()) - 1 || b != static_cast<LO>(sp[3].size()) - 1)
        throw Reject{cat("patch ", p, " is not consistent in the solution")};
      // Sides meet at the corners (a side of length 0 is a single point). The last point of side
      // k is the end of its last arc of nonzero length, so the distance from it to the corner is
      // the sum of the arcs after that one only: a label with the whole side would make a row that
      // the solution already meets, which cuts nothing.
      for (int k = 0; k < 4; ++k)
        link(sp[static_cast<std::size_t>(k)].back(),
             sp[static_cast<std::size_t>((k + 1) % 4)].front(), trailing_zero_arcs(p, k));
      if (a == 0 || b == 0) {
        // A patch of zero area: its opposite sides' points merge (Sec. IV.A-B).
        for (LO k = 0; a == 0 && k <= b; ++k)
          link(sp[1][static_cast<std::size_t>(k)], sp[3][static_cast<std::size_t>(b - k)],
               side_arcs(p, 0));
        for (LO k = 0; b == 0 && k <= a; ++k)
          link(sp[0][static_cast<std::size_t>(k)], sp[2][static_cast<std::size_t>(a - k)],
               side_arcs(p, 1));
        continue;
      }
      const Grid& g = grids_[p];
      std::vector<GO> lat(static_cast<std::size_t>(a + 1) * static_cast<std::size_t>(b + 1), -1);
      auto at = [&](LO x, LO y) -> GO& {
        return lat[static_cast<std::size_t>(y) * static_cast<std::size_t>(a + 1) +
                   static_cast<std::size_t>(x)];
      };
      for (LO x = 0; x <= a; ++x) {
        at(x, 0) = sp[0][static_cast<std::size_t>(x)];
        at(a - x, b) = sp[2][static_cast<std::size_t>(x)];
      }
      for (LO y = 0; y <= b; ++y) {
        at(a, y) = sp[1][static_cast<std::size_t>(y)];
        at(0, b - y) = sp[3][static_cast<std::size_t>(y)];
      }
      for (LO y = 1; y < b; ++y)
        for (LO x = 1; x < a; ++x) {
          at(x, y) = dsu_.add();
          links_.emplace_back();
          point_patches_.emplace_back();
          rep_.push_back(g.at(static_cast<LO>(std::lround(static_cast<double>(x) * g.ni / a)),
                              static_cast<LO>(std::lround(static_cast<double>(y) * g.nj / b))));
        }
      for (LO y = 0; y < b; ++y)
        for (LO x = 0; x < a; ++x)
          cells_.push_back({{at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)},
                            static_cast<LO>(p),
                            x,
                            y,
                            a,
                            b});
    }
  }

  // ---------------------------------------------------------------- Sec. IV.B-D
  void coarse_mesh() {
    // Groups, numbered in the order of their smallest point.
    const auto np = static_cast<GO>(rep_.size());
    group_.assign(static_cast<std::size_t>(np), -1);
    std::vector<GO> root_group(static_cast<std::size_t>(np), -1);
    ng_ = 0;
    for (GO x = 0; x < np; ++x) {
      const GO r = dsu_.find(x);
      if (root_group[static_cast<std::size_t>(r)] < 0)
        root_group[static_cast<std::size_t>(r)] = ng_++;
      group_[static_cast<std::size_t>(x)] = root_group[static_cast<std::size_t>(r)];
    }
    // Only the groups used by a cell are coarse vertices.
    std::vector<char> used(static_cast<std::size_t>(ng_), 0);
    for (const Cell& c : cells_)
      for (GO x : c.pts) used[static_cast<std::size_t>(group_[static_cast<std::size_t>(x)])] = 1;
    // Centres (Sec. IV.C): a CAD corner, else a vertex on a curve, else the member nearest the
    // group's centroid.
    center_.assign(static_cast<std::size_t>(ng_), -1);
    std::vector<Vec3> sum(static_cast<std::size_t>(ng_), Vec3{0, 0, 0});
    std::vector<double> cnt(static_cast<std::size_t>(ng_), 0);
    std::vector<LO> curve_of(static_cast<std::size_t>(ng_), kNoIndex);
    for (GO x = 0; x < np; ++x) {
      const GO g = group_[static_cast<std::size_t>(x)];
      const GO v = rep_[static_cast<std::size_t>(x)];
      sum[static_cast<std::size_t>(g)] += m_.points[static_cast<std::size_t>(v)];
      cnt[static_cast<std::size_t>(g)] += 1;
      GO& c = center_[static_cast<std::size_t>(g)];
      const int dv = vc(v).dim;
      if (dv == 0) {
        if (c >= 0 && vc(c).dim == 0 && c != v && used[static_cast<std::size_t>(g)])
          throw Reject{cat("CAD corners ", c, " and ", v, " merge")};
        c = v;
      } else if (dv == 1) {
        LO& cv = curve_of[static_cast<std::size_t>(g)];
        if (cv != kNoIndex && cv != vc(v).entity) cv = -2;  // two curves
        if (cv == kNoIndex) cv = vc(v).entity;
        if (c < 0 || vc(c).dim == 2) c = v;
      }
    }
    for (GO g = 0; g < ng_; ++g) {
      GO& c = center_[static_cast<std::size_t>(g)];
      if (used[static_cast<std::size_t>(g)] && curve_of[static_cast<std::size_t>(g)] == -2 &&
          (c < 0 || vc(c).dim != 0))
        throw Reject{"two CAD curves merge away from a corner"};
    }
    for (GO x = 0; x < np; ++x) {
      const GO g = group_[static_cast<std::size_t>(x)];
      const GO v = rep_[static_cast<std::size_t>(x)];
      GO& c = center_[static_cast<std::size_t>(g)];
      if (c >= 0 && vc(c).dim < 2) continue;
      const Vec3 centroid = sum[static_cast<std::size_t>(g)] / cnt[static_cast<std::size_t>(g)];
      if (c < 0 || distance(m_.points[static_cast<std::size_t>(v)], centroid) <
                       distance(m_.points[static_cast<std::size_t>(c)], centroid))
        c = v;
    }
    // Coarse quads and edges.
    cquads_.clear();
    edge_id_.clear();
    cedges_.clear();
    for (std::size_t k = 0; k < cells_.size(); ++k) {
      std::array<GO, 4> v{};
      for (int i = 0; i < 4; ++i)
        v[static_cast<std::size_t>(i)] =
            group_[static_cast<std::size_t>(cells_[k].pts[static_cast<std::size_t>(i)])];
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
          if (v[static_cast<std::size_t>(i)] == v[static_cast<std::size_t>(j)])
            throw Reject{"a coarse quad has a repeated corner"};
      CQuad cq;
      cq.v = v;
      cq.face = grids_[static_cast<std::size_t>(cells_[k].patch)].face;
      cq.cell = static_cast<LO>(k);
      for (int e = 0; e < 4; ++e) {
        const GO a = v[static_cast<std::size_t>(e)], b = v[static_cast<std::size_t>((e + 1) % 4)];
        const std::uint64_t key = mesh::edge_key(a, b);
        auto [it, fresh] = edge_id_.emplace(key, static_cast<GO>(cedges_.size()));
        if (fresh) cedges_.push_back({std::min(a, b), std::max(a, b)});
        CEdge& ce = cedges_[static_cast<std::size_t>(it->second)];
        ce.uses.emplace_back(static_cast<GO>(cquads_.size()), e);
        const Grid& g = grids_[static_cast<std::size_t>(cells_[k].patch)];
        ce.target += e % 2 == 0 ? static_cast<double>(g.ni) / cells_[k].a
                                : static_cast<double>(g.nj) / cells_[k].b;
        ce.target_count += 1;
        cq.e[static_cast<std::size_t>(e)] = it->second;
      }
      cquads_.push_back(cq);
    }
    // Curves of the coarse edges: those of the arcs their lattice steps came from.
    for (std::size_t p = 0; p < grids_.size(); ++p)
      for (int s = 0; s < 4; ++s) {
        std::vector<LO> from;
        const std::vector<GO> pts = side_points(p, s, &from);
        for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
          const LO c = arcs_[static_cast<std::size_t>(from[k])].curve;
          if (c == kNoIndex) continue;
          const GO a = group_[static_cast<std::size_t>(pts[k])],
                   b = group_[static_cast<std::size_t>(pts[k + 1])];
          const auto it = edge_id_.find(mesh::edge_key(a, b));
          if (a != b && it != edge_id_.end())
            cedges_[static_cast<std::size_t>(it->second)].curve = c;
        }
      }
    for (const CEdge& e : cedges_) {
      if (e.curve == kNoIndex && e.uses.size() != 2)
        throw Reject{cat("a coarse edge off the curves has ", e.uses.size(), " quads")};
      if (e.uses.size() == 2 && e.curve == kNoIndex) {
        const CQuad& a = cquads_[static_cast<std::size_t>(e.uses[0].first)];
        const CQuad& b = cquads_[static_cast<std::size_t>(e.uses[1].first)];
        if (a.v[static_cast<std::size_t>(e.uses[0].second)] ==
            b.v[static_cast<std::size_t>(e.uses[1].second)])
          throw Reject{"two coarse quads run the same way along an edge"};
      }
    }
    // Quad loops (Sec. IV.D): opposite edges of a coarse quad share a width, the rounded mean
    // of the loop's target lengths, at least 1.
    Dsu loops;
    loops.resize(static_cast<GO>(cedges_.size()));
    for (const CQuad& q : cquads_) {
      if (q.e[0] == q.e[2] || q.e[1] == q.e[3] || q.e[0] == q.e[1] || q.e[1] == q.e[2])
        throw Reject{"a coarse quad uses an edge twice"};
      loops.unite(q.e[0], q.e[2]);
      loops.unite(q.e[1], q.e[3]);
    }
    std::vector<double> lsum(cedges_.size(), 0), lcnt(cedges_.size(), 0);
    for (std::size_t e = 0; e < cedges_.size(); ++e) {
      const auto r = static_cast<std::size_t>(loops.find(static_cast<GO>(e)));
      lsum[r] += cedges_[e].target / cedges_[e].target_count;
      lcnt[r] += 1;
    }
    for (std::size_t e = 0; e < cedges_.size(); ++e) {
      const auto r = static_cast<std::size_t>(loops.find(static_cast<GO>(e)));
      cedges_[e].n = std::max<LO>(1, static_cast<LO>(std::lround(lsum[r] / lcnt[r])));
    }
    if (opt_.fit_loop_widths) fit_loops(loops);
    if (opt_.loop_balance > 0) balance_loops(loops);
  }

  // CoarseOptions::fit_loop_widths: each loop's width fitted to the extents of its cells in
  // their input patch grids (fit_loop_width).
  void fit_loops(Dsu& loops) {
    std::vector<std::vector<LoopCrossing>> cross(cedges_.size());
    for (std::size_t k = 0; k < cquads_.size(); ++k) {
      const std::array<Vec2, 4> C = cell_grid_corners(k);
      const double e0 = 0.5 * (std::abs(C[1].u - C[0].u) + std::abs(C[2].u - C[3].u));
      const double e1 = 0.5 * (std::abs(C[3].v - C[0].v) + std::abs(C[2].v - C[1].v));
      const double area = std::max(e0, 0.5) * std::max(e1, 0.5);
      const CQuad& q = cquads_[k];
      cross[static_cast<std::size_t>(loops.find(q.e[0]))].push_back({e0, area});
      cross[static_cast<std::size_t>(loops.find(q.e[1]))].push_back({e1, area});
    }
    std::vector<LO> width(cedges_.size(), 0);
    for (std::size_t e = 0; e < cedges_.size(); ++e) {
      const auto r = static_cast<std::size_t>(loops.find(static_cast<GO>(e)));
      if (width[r] == 0) width[r] = fit_loop_width(cross[r]);
      cedges_[e].n = width[r];
    }
  }

  // CoarseOptions::loop_balance: each edge's target blended with the width that would make the
  // fine quads of its coarse quad square at their current size (the geometric mean of the two
  // fine edge lengths there), then each loop's width the rounded mean again.
  void balance_loops(Dsu& loops) {
    const double beta = std::min(1.0, opt_.loop_balance);
    auto p = [&](GO g) {
      return m_.points[static_cast<std::size_t>(center_[static_cast<std::size_t>(g)])];
    };
    std::vector<double> lsum(cedges_.size(), 0), lcnt(cedges_.size(), 0);
    for (const CQuad& q : cquads_) {
      // Mean lengths of the two pairs of opposite edges (straight, between the centres).
      const double l0 = 0.5 * (distance(p(q.v[0]), p(q.v[1])) + distance(p(q.v[3]), p(q.v[2])));
      const double l1 = 0.5 * (distance(p(q.v[1]), p(q.v[2])) + distance(p(q.v[0]), p(q.v[3])));
      const LO n0 = cedges_[static_cast<std::size_t>(q.e[0])].n;
      const LO n1 = cedges_[static_cast<std::size_t>(q.e[1])].n;
      const double h = std::sqrt((l0 / n0) * (l1 / n1));
      for (int k = 0; k < 4; ++k) {
        const auto e = static_cast<std::size_t>(q.e[static_cast<std::size_t>(k)]);
        const double input = cedges_[e].target / cedges_[e].target_count;
        const double square = h > 0 ? (k % 2 == 0 ? l0 : l1) / h : input;
        const auto r = static_cast<std::size_t>(loops.find(static_cast<GO>(e)));
        lsum[r] += (1 - beta) * input + beta * square;
        lcnt[r] += 1;
      }
    }
    for (std::size_t e = 0; e < cedges_.size(); ++e) {
      const auto r = static_cast<std::size_t>(loops.find(static_cast<GO>(e)));
      if (lcnt[r] > 0)
        cedges_[e].n = std::max<LO>(1, static_cast<LO>(std::lround(lsum[r] / lcnt[r])));
    }
  }

  // ---------------------------------------------------------------- fine mesh (Sec. IV.D-E)
  cad::FaceGeometry& face_geom(LO f) {
    auto& g = face_geom_[f];
    if (!g) g = model_.face_geometry(f);
    return *g;
  }
  cad::CurveGeometry& curve_geom(LO c) {
    auto& g = curve_geom_[c];
    if (!g) g = model_.curve_geometry(c);
    return *g;
  }

  // Parameter of coarse vertex g on curve c.
  double param_on(GO g, LO c, double other) const {
    const auto& k = vc(center_[static_cast<std::size_t>(g)]);
    if (k.dim == 1 && k.entity == c) return k.param[0];
    const cad::Curve& cc = model_.curves()[static_cast<std::size_t>(c)];
    if (k.dim == 0 && (cc.corners[0] == k.entity || cc.corners[1] == k.entity)) {
      if (cc.corners[0] != cc.corners[1]) return cc.corners[0] == k.entity ? cc.t0 : cc.t1;
      return std::abs(other - cc.t0) < std::abs(other - cc.t1) ? cc.t0 : cc.t1;
    }
    throw Reject{cat("a coarse edge along curve ", c, " ends off it")};
  }

  // (u, v) guesses of coarse quad k: the face vertices of its cell's part of the input patch.
  std::vector<std::pair<Vec3, Vec2>> guesses(std::size_t k) const {
    const Cell& c = cells_[static_cast<std::size_t>(cquads_[k].cell)];
    const Grid& g = grids_[static_cast<std::size_t>(c.patch)];
    std::vector<std::pair<Vec3, Vec2>> out;
    auto collect = [&](LO i0, LO i1, LO j0, LO j1) {
      for (int sj = 0; sj <= 4; ++sj)
        for (int si = 0; si <= 4; ++si) {
          const LO i = i0 + (i1 - i0) * si / 4, j = j0 + (j1 - j0) * sj / 4;
          const GO v = g.at(i, j);
          if (vc(v).dim == 2)
            out.emplace_back(m_.points[static_cast<std::size_t>(v)],
                             Vec2{vc(v).param[0], vc(v).param[1]});
        }
    };
    collect(static_cast<LO>(std::floor(static_cast<double>(c.x) * g.ni / c.a)),
            static_cast<LO>(std::ceil(static_cast<double>(c.x + 1) * g.ni / c.a)),
            static_cast<LO>(std::floor(static_cast<double>(c.y) * g.nj / c.b)),
            static_cast<LO>(std::ceil(static_cast<double>(c.y + 1) * g.nj / c.b)));
    if (out.empty()) collect(0, g.ni, 0, g.nj);
    if (out.empty())
      for (GO v = 0; v < nv_ && out.size() < 64; ++v)
        if (vc(v).dim == 2 && vc(v).entity == g.face)
          out.emplace_back(m_.points[static_cast<std::size_t>(v)],
                           Vec2{vc(v).param[0], vc(v).param[1]});
    if (out.empty()) out.emplace_back(Vec3{0, 0, 0}, Vec2{0, 0});
    return out;
  }

  // Input edges from the start of side s of patch p to its lattice point k: where side_points
  // took that point's input vertex (arc_point, split_and_merge).
  [[nodiscard]] double side_offset(std::size_t p, int s, LO k) const {
    if (k == 0) return 0;
    LO done = 0, off = 0;
    for (const SideArc& x : sides_[p][static_cast<std::size_t>(s)]) {
      const auto q = static_cast<LO>(q_[static_cast<std::size_t>(x.arc)]);
      const LO l = arcs_[static_cast<std::size_t>(x.arc)].length();
      if (q > 0 && k <= done + q) {
        const LO t = k - done;
        const auto at = [&](LO u) {
          return static_cast<LO>(std::lround(static_cast<double>(u) * l / static_cast<double>(q)));
        };
        return off + (x.forward ? at(t) : l - at(q - t));
      }
      done += q;
      off += l;
    }
    return off;
  }

  // Grid coordinates (i, j) in its patch's input grid of the four corners of coarse quad k's
  // cell, counter-clockwise as the coarse quad's corners.
  [[nodiscard]] std::array<Vec2, 4> cell_grid_corners(std::size_t k) const {
    const Cell& c = cells_[static_cast<std::size_t>(cquads_[k].cell)];
    const auto p = static_cast<std::size_t>(c.patch);
    const Grid& g = grids_[p];
    auto at = [&](LO X, LO Y) -> Vec2 {
      const auto ni = static_cast<double>(g.ni), nj = static_cast<double>(g.nj);
      if (Y == 0) return {side_offset(p, 0, X), 0};
      if (X == c.a) return {ni, side_offset(p, 1, Y)};
      if (Y == c.b) return {ni - side_offset(p, 2, c.a - X), nj};
      if (X == 0) return {0, nj - side_offset(p, 3, c.b - Y)};
      return {static_cast<double>(std::lround(X * ni / c.a)),
              static_cast<double>(std::lround(Y * nj / c.b))};
    };
    return {at(c.x, c.y), at(c.x + 1, c.y), at(c.x + 1, c.y + 1), at(c.x, c.y + 1)};
  }

  // The input patch of coarse quad k at fractional position (s, t) of the coarse quad: its grid
  // coordinates bilinear between the cell's corners, the point bilinear in the input quad there.
  // `guess` gets the uv of a face vertex of that input quad (left as is when it has none).
  [[nodiscard]] Vec3 patch_point(std::size_t k, const std::array<Vec2, 4>& C, double s, double t,
                                 Vec2& guess) const {
    const Grid& g =
        grids_[static_cast<std::size_t>(cells_[static_cast<std::size_t>(cquads_[k].cell)].patch)];
    const double gi =
        (1 - s) * (1 - t) * C[0].u + s * (1 - t) * C[1].u + s * t * C[2].u + (1 - s) * t * C[3].u;
    const double gj =
        (1 - s) * (1 - t) * C[0].v + s * (1 - t) * C[1].v + s * t * C[2].v + (1 - s) * t * C[3].v;
    const LO i0 = std::clamp<LO>(static_cast<LO>(std::floor(gi)), 0, std::max<LO>(g.ni - 1, 0));
    const LO j0 = std::clamp<LO>(static_cast<LO>(std::floor(gj)), 0, std::max<LO>(g.nj - 1, 0));
    const LO i1 = std::min(i0 + 1, g.ni), j1 = std::min(j0 + 1, g.nj);
    const double fi = std::clamp(gi - i0, 0.0, 1.0), fj = std::clamp(gj - j0, 0.0, 1.0);
    const std::array<GO, 4> v{g.at(i0, j0), g.at(i1, j0), g.at(i1, j1), g.at(i0, j1)};
    const std::array<double, 4> w{(1 - fi) * (1 - fj), fi * (1 - fj), fi * fj, (1 - fi) * fj};
    Vec3 out{0, 0, 0};
    double best = -1;
    for (int c = 0; c < 4; ++c) {
      const GO x = v[static_cast<std::size_t>(c)];
      out += w[static_cast<std::size_t>(c)] * m_.points[static_cast<std::size_t>(x)];
      if (vc(x).dim == 2 && vc(x).entity == cquads_[k].face &&
          w[static_cast<std::size_t>(c)] > best) {
        best = w[static_cast<std::size_t>(c)];
        guess = {vc(x).param[0], vc(x).param[1]};
      }
    }
    return out;
  }

  static Vec2 nearest_guess(const std::vector<std::pair<Vec3, Vec2>>& gs, const Vec3& p) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < gs.size(); ++i)
      if (norm2(gs[i].first - p) < norm2(gs[best].first - p)) best = i;
    return gs[best].second;
  }

  struct FineNode {
    Vec3 p;
    mesh::VertexClass c;
  };

  // The curve parameters t_0..t_n of the fine nodes of coarse edge ce (along a CAD curve), from
  // its vertex a to b: uniform in the parameter, or (input_like) the input mesh's nodes on the
  // curve between the edge's ends, their parameters interpolated at n evenly spread fractional
  // positions (the input's grading along the side, at the coarse edge's node count).
  std::vector<double> side_params(std::size_t e, bool input_like) {
    const auto& ce = cedges_[e];
    const cad::Curve& cc = model_.curves()[static_cast<std::size_t>(ce.curve)];
    const GO cb = center_[static_cast<std::size_t>(ce.b)];
    const double tb0 = vc(cb).dim == 1 ? vc(cb).param[0] : 0.5 * (cc.t0 + cc.t1);
    const double ta = param_on(ce.a, ce.curve, tb0);
    const double tb = param_on(ce.b, ce.curve, ta);
    std::vector<double> ts(static_cast<std::size_t>(ce.n) + 1);
    for (LO k = 0; k <= ce.n; ++k) ts[static_cast<std::size_t>(k)] = ta + (tb - ta) * k / ce.n;
    ts.back() = tb;
    if (!input_like || ce.n < 2) return ts;
    const std::vector<double>& all = input_params(ce.curve);
    const double lo = std::min(ta, tb), hi = std::max(ta, tb);
    std::vector<double> s{ta};
    for (auto it = std::upper_bound(all.begin(), all.end(), lo); it != all.end() && *it < hi; ++it)
      s.push_back(*it);
    if (ta > tb) std::reverse(s.begin() + 1, s.end());
    s.push_back(tb);
    const auto m = static_cast<LO>(s.size()) - 1;
    if (m < 2) return ts;  // no input node inside: the same as uniform
    for (LO k = 1; k < ce.n; ++k) {
      const double x = static_cast<double>(k) * m / ce.n;
      const auto j = std::min<LO>(static_cast<LO>(std::floor(x)), m - 1);
      const double f = x - j;
      ts[static_cast<std::size_t>(k)] =
          s[static_cast<std::size_t>(j)] +
          f * (s[static_cast<std::size_t>(j) + 1] - s[static_cast<std::size_t>(j)]);
    }
    return ts;
  }

  // The parameters of the input mesh's vertices inside curve c, sorted.
  const std::vector<double>& input_params(LO c) {
    if (curve_params_.empty()) {
      curve_params_.resize(static_cast<std::size_t>(std::max<LO>(m_.num_cad_curves, 0)));
      for (GO v = 0; v < nv_; ++v)
        if (vc(v).dim == 1 && vc(v).entity >= 0 &&
            static_cast<std::size_t>(vc(v).entity) < curve_params_.size())
          curve_params_[static_cast<std::size_t>(vc(v).entity)].push_back(vc(v).param[0]);
      for (auto& list : curve_params_) std::sort(list.begin(), list.end());
    }
    return curve_params_[static_cast<std::size_t>(c)];
  }

  // Which coarse edges on curves take the input spacing (CoarseOptions::input_spacing_on_curves):
  // each coarse quad with a side on a curve is scored (SICN of its fine quads by transfinite
  // interpolation, not projected nor smoothed) with all its curve sides uniform and all at the
  // input spacing; an edge takes the input spacing when choose_side_spacing prefers it for every
  // coarse quad it bounds.
  std::vector<char> choose_spacing() {
    std::vector<char> input_like(cedges_.size(), 0);
    if (!opt_.input_spacing_on_curves) return input_like;
    std::vector<char> vote(cedges_.size(), 0);
    for (std::size_t e = 0; e < cedges_.size(); ++e)
      if (cedges_[e].curve != kNoIndex && cedges_[e].n >= 2) vote[e] = 1;
    // Side points of an edge walked from `from`, under one spacing.
    auto side_points = [&](GO e, GO from, bool input) {
      const CEdge& ce = cedges_[static_cast<std::size_t>(e)];
      const GO ca = center_[static_cast<std::size_t>(ce.a)];
      const GO cb = center_[static_cast<std::size_t>(ce.b)];
      const Vec3 pa = m_.points[static_cast<std::size_t>(ca)];
      const Vec3 pb = m_.points[static_cast<std::size_t>(cb)];
      std::vector<Vec3> pts(static_cast<std::size_t>(ce.n) + 1);
      if (ce.curve != kNoIndex) {
        const std::vector<double> ts = side_params(static_cast<std::size_t>(e), input);
        for (LO k = 1; k < ce.n; ++k)
          pts[static_cast<std::size_t>(k)] =
              curve_geom(ce.curve).point(ts[static_cast<std::size_t>(k)]);
      } else {
        for (LO k = 1; k < ce.n; ++k)
          pts[static_cast<std::size_t>(k)] = pa + (pb - pa) * (static_cast<double>(k) / ce.n);
      }
      pts.front() = pa;
      pts.back() = pb;
      if (from != ce.a) std::reverse(pts.begin(), pts.end());
      return pts;
    };
    auto score = [&](const CQuad& q, bool input) {
      const LO n0 = cedges_[static_cast<std::size_t>(q.e[0])].n;
      const LO n1 = cedges_[static_cast<std::size_t>(q.e[1])].n;
      const auto s0 = side_points(q.e[0], q.v[0], input), s1 = side_points(q.e[1], q.v[1], input);
      const auto s2 = side_points(q.e[2], q.v[2], input), s3 = side_points(q.e[3], q.v[3], input);
      auto P = [&](LO i, LO j) -> Vec3 {
        if (j == 0) return s0[static_cast<std::size_t>(i)];
        if (i == n0) return s1[static_cast<std::size_t>(j)];
        if (j == n1) return s2[static_cast<std::size_t>(n0 - i)];
        return s3[static_cast<std::size_t>(n1 - j)];
      };
      std::vector<Vec3> g(static_cast<std::size_t>(n0 + 1) * static_cast<std::size_t>(n1 + 1));
      auto at = [&](LO i, LO j) -> Vec3& {
        return g[static_cast<std::size_t>(j) * static_cast<std::size_t>(n0 + 1) +
                 static_cast<std::size_t>(i)];
      };
      for (LO j = 0; j <= n1; ++j)
        for (LO i = 0; i <= n0; ++i) {
          const bool side = i == 0 || j == 0 || i == n0 || j == n1;
          at(i, j) = side ? P(i, j) : coons_point(P, i, j, n0, n1);
        }
      SideScore sc{2, 0};
      for (LO j = 0; j < n1; ++j)
        for (LO i = 0; i < n0; ++i) {
          const double v =
              mesh::quad_sicn({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
          sc.sicn_min = std::min(sc.sicn_min, v);
          sc.sicn_avg += v;
        }
      sc.sicn_avg /= static_cast<double>(n0) * static_cast<double>(n1);
      return sc;
    };
    for (const CQuad& q : cquads_) {
      bool any = false;
      for (GO e : q.e) any = any || vote[static_cast<std::size_t>(e)] != 0;
      if (!any) continue;
      if (cedges_[static_cast<std::size_t>(q.e[2])].n !=
              cedges_[static_cast<std::size_t>(q.e[0])].n ||
          cedges_[static_cast<std::size_t>(q.e[3])].n !=
              cedges_[static_cast<std::size_t>(q.e[1])].n)
        continue;  // fine_mesh refuses it
      if (!choose_side_spacing(score(q, false), score(q, true)))
        for (GO e : q.e) vote[static_cast<std::size_t>(e)] = 0;
    }
    for (std::size_t e = 0; e < cedges_.size(); ++e) input_like[e] = vote[e];
    return input_like;
  }

  // The fine mesh with the spacing of choose_spacing; where fine quads fold or are invalid, the
  // curve sides of their coarse quads go back to the uniform spacing and it is built again, and
  // after kMaxSpacingRounds every side is uniform (the former placement). A repair changes the
  // quantization (restored input lengths, more blocks), so it comes only after that. Switching
  // the bad quads' uniform sides to the input spacing as well was tried: on Block it made new
  // folds next to them and the layout failed after 11 repairs (docs/benchmarks.md).
  void fine_mesh(CoarseResult& out) {
    std::vector<char> input_like = choose_spacing();
    for (int attempt = 0;; ++attempt) {
      out.mesh = {};
      out.layout = {};
      fine_mesh_with(out, input_like);
      if (bad_cquads_.empty()) break;
      bool changed = false;
      for (std::size_t k : bad_cquads_)
        for (GO e : cquads_[k].e)
          if (input_like[static_cast<std::size_t>(e)] != 0) {
            input_like[static_cast<std::size_t>(e)] = 0;
            changed = true;
          }
      if (!changed) break;
      ++out.stats.spacing_fallbacks;
      if (attempt + 1 >= kMaxSpacingRounds) std::fill(input_like.begin(), input_like.end(), 0);
    }
    out.stats.sides_input_spacing = std::count(input_like.begin(), input_like.end(), 1);
    out.stats.sides_uniform_spacing = 0;
    for (std::size_t e = 0; e < cedges_.size(); ++e)
      if (cedges_[e].curve != kNoIndex && input_like[e] == 0) ++out.stats.sides_uniform_spacing;
  }

  void fine_mesh_with(CoarseResult& out, const std::vector<char>& input_like) {
    std::vector<FineNode> nodes;
    // Coarse vertices.
    std::vector<GO> vnode(static_cast<std::size_t>(ng_), -1);
    for (const CQuad& q : cquads_)
      for (GO g : q.v) {
        GO& id = vnode[static_cast<std::size_t>(g)];
        if (id >= 0) continue;
        id = static_cast<GO>(nodes.size());
        const GO c = center_[static_cast<std::size_t>(g)];
        nodes.push_back({m_.points[static_cast<std::size_t>(c)], vc(c)});
      }
    // Edge nodes, from the edge's smaller vertex to its larger.
    std::vector<GO> ebase(cedges_.size(), -1);
    for (std::size_t e = 0; e < cedges_.size(); ++e) {
      const CEdge& ce = cedges_[e];
      ebase[e] = static_cast<GO>(nodes.size());
      const Vec3 pa = nodes[static_cast<std::size_t>(vnode[static_cast<std::size_t>(ce.a)])].p;
      const Vec3 pb = nodes[static_cast<std::size_t>(vnode[static_cast<std::size_t>(ce.b)])].p;
      if (ce.curve != kNoIndex) {
        const std::vector<double> ts = side_params(e, input_like[e] != 0);
        for (LO k = 1; k < ce.n; ++k) {
          const double t = ts[static_cast<std::size_t>(k)];
          nodes.push_back({curve_geom(ce.curve).point(t), {1, ce.curve, kNoIndex, {t, 0}}});
        }
      } else {
        const auto k = static_cast<std::size_t>(ce.uses.front().first);
        const int side = ce.uses.front().second;
        const LO f = cquads_[k].face;
        const auto gs = guesses(k);
        // With patch_placement, the input grid line of the first coarse quad on the edge, its
        // ends moved onto the edge's ends; else the straight chord.
        const std::array<Vec2, 4> C =
            opt_.patch_placement ? cell_grid_corners(k) : std::array<Vec2, 4>{};
        const bool from_a = cquads_[k].v[static_cast<std::size_t>(side)] == ce.a;
        auto on_side = [&](double r, Vec2& guess) {
          // Position r in [0, 1] along side `side` of coarse quad k, walked counter-clockwise.
          static constexpr std::array<std::array<double, 4>, 4> st{
              {{0, 0, 1, 0}, {1, 0, 0, 1}, {1, 1, -1, 0}, {0, 1, 0, -1}}};
          const auto& m = st[static_cast<std::size_t>(side)];
          return patch_point(k, C, m[0] + m[2] * r, m[1] + m[3] * r, guess);
        };
        Vec2 g0 = nearest_guess(gs, pa);
        const Vec3 xa = opt_.patch_placement ? on_side(from_a ? 0.0 : 1.0, g0) : pa;
        const Vec3 xb = opt_.patch_placement ? on_side(from_a ? 1.0 : 0.0, g0) : pb;
        for (LO i = 1; i < ce.n; ++i) {
          const double r = static_cast<double>(i) / ce.n;
          Vec3 target = pa + (pb - pa) * r;
          Vec2 guess = nearest_guess(gs, target);
          if (opt_.patch_placement)
            target = on_side(from_a ? r : 1 - r, guess) + (1 - r) * (pa - xa) + r * (pb - xb);
          Vec3 foot{};
          const Vec2 uv = face_geom(f).project(target, guess, &foot);
          nodes.push_back({foot, {2, f, kNoIndex, {uv.u, uv.v}}});
        }
      }
    }
    // Quad grids: boundary from the vertex and edge nodes, inside by transfinite interpolation
    // projected on the face.
    struct FineQuad {
      std::array<GO, 4> v;
      LO face;
      GO block;
    };
    std::vector<FineQuad> fq;
    std::vector<std::vector<GO>> block_grid(cquads_.size());
    for (std::size_t k = 0; k < cquads_.size(); ++k) {
      const CQuad& q = cquads_[k];
      const LO n0 = cedges_[static_cast<std::size_t>(q.e[0])].n;
      const LO n1 = cedges_[static_cast<std::size_t>(q.e[1])].n;
      if (cedges_[static_cast<std::size_t>(q.e[2])].n != n0 ||
          cedges_[static_cast<std::size_t>(q.e[3])].n != n1)
        throw Reject{"opposite coarse edges with different widths"};
      std::vector<GO>& G = block_grid[k];
      G.assign(static_cast<std::size_t>(n0 + 1) * static_cast<std::size_t>(n1 + 1), -1);
      auto at = [&](LO i, LO j) -> GO& {
        return G[static_cast<std::size_t>(j) * static_cast<std::size_t>(n0 + 1) +
                 static_cast<std::size_t>(i)];
      };
      // Node t (0..n) of coarse edge e walked from coarse vertex `from`.
      auto edge_node = [&](GO e, GO from, LO t) -> GO {
        const CEdge& ce = cedges_[static_cast<std::size_t>(e)];
        const LO s = from == ce.a ? t : ce.n - t;
        if (s == 0) return vnode[static_cast<std::size_t>(ce.a)];
        if (s == ce.n) return vnode[static_cast<std::size_t>(ce.b)];
        return ebase[static_cast<std::size_t>(e)] + s - 1;
      };
      for (LO i = 0; i <= n0; ++i) {
        at(i, 0) = edge_node(q.e[0], q.v[0], i);
        at(n0 - i, n1) = edge_node(q.e[2], q.v[2], i);
      }
      for (LO j = 0; j <= n1; ++j) {
        at(n0, j) = edge_node(q.e[1], q.v[1], j);
        at(0, n1 - j) = edge_node(q.e[3], q.v[3], j);
      }
      const auto gs = (n0 > 1 && n1 > 1) ? guesses(k) : std::vector<std::pair<Vec3, Vec2>>{};
      auto P = [&](LO i, LO j) { return nodes[static_cast<std::size_t>(at(i, j))].p; };
      // patch_placement: the input patch's map X at every node, and the sides' gap to it (P - X)
      // spread inside by transfinite interpolation.
      std::vector<Vec3> X;
      std::vector<Vec2> Xuv;
      if (opt_.patch_placement && n0 > 1 && n1 > 1) {
        const std::array<Vec2, 4> C = cell_grid_corners(k);
        X.resize(G.size());
        Xuv.resize(G.size());
        for (LO j = 0; j <= n1; ++j)
          for (LO i = 0; i <= n0; ++i) {
            const auto l = static_cast<std::size_t>(j) * static_cast<std::size_t>(n0 + 1) +
                           static_cast<std::size_t>(i);
            Xuv[l] = {std::numeric_limits<double>::quiet_NaN(), 0};
            X[l] =
                patch_point(k, C, static_cast<double>(i) / n0, static_cast<double>(j) / n1, Xuv[l]);
          }
      }
      auto gap = [&](LO i, LO j) {
        return P(i, j) - X[static_cast<std::size_t>(j) * static_cast<std::size_t>(n0 + 1) +
                           static_cast<std::size_t>(i)];
      };
      for (LO j = 1; j < n1; ++j)
        for (LO i = 1; i < n0; ++i) {
          Vec3 target{};
          Vec2 guess{};
          if (X.empty()) {
            target = coons_point(P, i, j, n0, n1);
            guess = nearest_guess(gs, target);
          } else {
            const auto l = static_cast<std::size_t>(j) * static_cast<std::size_t>(n0 + 1) +
                           static_cast<std::size_t>(i);
            target = X[l] + coons_point(gap, i, j, n0, n1);
            guess = std::isnan(Xuv[l].u) ? nearest_guess(gs, target) : Xuv[l];
          }
          Vec3 foot{};
          const Vec2 uv = face_geom(q.face).project(target, guess, &foot);
          at(i, j) = static_cast<GO>(nodes.size());
          nodes.push_back({foot, {2, q.face, kNoIndex, {uv.u, uv.v}}});
        }
      for (LO j = 0; j < n1; ++j)
        for (LO i = 0; i < n0; ++i)
          fq.push_back({{at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)},
                        q.face,
                        static_cast<GO>(k)});
    }
    smooth_nodes(nodes, fq);
    // SurfaceMesh numbering: corners (id = corner id), curve vertices by curve then parameter,
    // face vertices by face then creation.
    const auto nn = static_cast<GO>(nodes.size());
    std::vector<GO> order(static_cast<std::size_t>(nn));
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](GO x, GO y) {
      const auto& a = nodes[static_cast<std::size_t>(x)].c;
      const auto& b = nodes[static_cast<std::size_t>(y)].c;
      if (a.dim != b.dim) return a.dim < b.dim;
      if (a.entity != b.entity) return a.entity < b.entity;
      return a.dim == 1 && a.param[0] < b.param[0];
    });
    std::vector<GO> renum(static_cast<std::size_t>(nn));
    mesh::SurfaceMesh& sm = out.mesh;
    LO corners = 0;
    for (GO k = 0; k < nn; ++k) {
      const GO o = order[static_cast<std::size_t>(k)];
      renum[static_cast<std::size_t>(o)] = k;
      mesh::VertexClass c = nodes[static_cast<std::size_t>(o)].c;
      if (c.dim == 0) {
        if (c.entity != k) {
          throw Reject{cat("CAD corner ", k, " is missing")};
        }
        ++corners;
      }
      sm.points.push_back(nodes[static_cast<std::size_t>(o)].p);
      sm.vclass.push_back(c);
    }
    if (corners != m_.num_cad_corners) throw Reject{"a CAD corner is missing"};
    for (GO k = 0; k < nn;) {  // curve vertex indices: 1, 2, ... along each curve
      GO e = k;
      while (e < nn && sm.vclass[static_cast<std::size_t>(e)].dim == 1 &&
             sm.vclass[static_cast<std::size_t>(e)].entity ==
                 sm.vclass[static_cast<std::size_t>(k)].entity)
        sm.vclass[static_cast<std::size_t>(e)].index = static_cast<LO>(e - k + 1), ++e;
      k = e == k ? k + 1 : e;
    }
    std::vector<std::size_t> qorder(fq.size());
    std::iota(qorder.begin(), qorder.end(), 0);
    std::stable_sort(qorder.begin(), qorder.end(),
                     [&](std::size_t a, std::size_t b) { return fq[a].face < fq[b].face; });
    std::vector<std::size_t> cq_of_fine(fq.size(), 0);
    for (std::size_t i = 0; i < qorder.size(); ++i) {
      const FineQuad& f = fq[qorder[i]];
      std::array<GO, 4> v{};
      for (int c = 0; c < 4; ++c)
        v[static_cast<std::size_t>(c)] =
            renum[static_cast<std::size_t>(f.v[static_cast<std::size_t>(c)])];
      sm.quads.push_back(v);
      sm.quad_face.push_back(f.face);
      cq_of_fine[i] = static_cast<std::size_t>(f.block);
    }
    // Bars: the fine edges of the coarse edges on curves, by curve and parameter.
    struct BarRec {
      LO curve;
      double t;
      GO a, b;
    };
    std::vector<BarRec> bars;
    for (std::size_t e = 0; e < cedges_.size(); ++e) {
      const CEdge& ce = cedges_[e];
      if (ce.curve == kNoIndex) continue;
      GO prev = renum[static_cast<std::size_t>(vnode[static_cast<std::size_t>(ce.a)])];
      for (LO s = 1; s <= ce.n; ++s) {
        const GO node = s == ce.n ? vnode[static_cast<std::size_t>(ce.b)] : ebase[e] + s - 1;
        const GO cur = renum[static_cast<std::size_t>(node)];
        const auto& ka = sm.vclass[static_cast<std::size_t>(prev)];
        const auto& kb = sm.vclass[static_cast<std::size_t>(cur)];
        const double t = ka.dim == 1 ? ka.param[0] : kb.dim == 1 ? kb.param[0] : 0.0;
        bars.push_back({ce.curve, t, prev, cur});
        prev = cur;
      }
    }
    std::stable_sort(bars.begin(), bars.end(), [](const BarRec& a, const BarRec& b) {
      return a.curve != b.curve ? a.curve < b.curve : a.t < b.t;
    });
    for (const BarRec& b : bars) {
      sm.bars.push_back({b.a, b.b});
      sm.bar_curve.push_back(b.curve);
    }
    mesh::copy_cad_topology(m_, sm);
    // Validity: no quad folded against the face (normal at its corners) and SICN > 0.
    double smin = 2, ssum = 0;
    for (std::size_t i = 0; i < sm.quads.size(); ++i) {
      std::array<Vec3, 4> p{};
      for (int c = 0; c < 4; ++c)
        p[static_cast<std::size_t>(c)] =
            sm.points[static_cast<std::size_t>(sm.quads[i][static_cast<std::size_t>(c)])];
      const double s = mesh::quad_sicn(p);
      smin = std::min(smin, s);
      ssum += s;
    }
    out.stats.sicn_min = sm.quads.empty() ? 0 : smin;
    out.stats.sicn_avg = sm.quads.empty() ? 0 : ssum / static_cast<double>(sm.quads.size());
    bad_cquads_.clear();
    bad_quads_ = 0;
    for (std::size_t i = 0; i < sm.quads.size(); ++i) {
      std::array<Vec3, 4> p{};
      for (int c = 0; c < 4; ++c)
        p[static_cast<std::size_t>(c)] =
            sm.points[static_cast<std::size_t>(sm.quads[i][static_cast<std::size_t>(c)])];
      const std::size_t k = cq_of_fine[i];
      if (mesh::quad_sicn(p) <= 0 || bad_fine_cquad_[k]) {
        bad_cquads_.push_back(k);
        ++bad_quads_;
      }
    }
    std::sort(bad_cquads_.begin(), bad_cquads_.end());
    bad_cquads_.erase(std::unique(bad_cquads_.begin(), bad_cquads_.end()), bad_cquads_.end());
    if (!bad_cquads_.empty()) return;
    blocks(block_grid, renum, cq_of_fine, out.layout);
  }

  // Blocks: the coarse quads joined across the chords that can go (closed loops of coarse edges
  // off the CAD curves through vertices of four quads, away from CAD corners: removing one joins
  // the quads on its two sides pairwise, and the layout stays conforming), each as one grid.
  void blocks(const std::vector<std::vector<GO>>& block_grid, const std::vector<GO>& renum,
              const std::vector<std::size_t>& cq_of_fine, QuadLayout& lay) {
    const std::size_t nq = cquads_.size(), ne = cedges_.size();
    std::vector<std::vector<std::pair<std::size_t, int>>> at(static_cast<std::size_t>(ng_));
    for (std::size_t q = 0; q < nq; ++q)
      for (int k = 0; k < 4; ++k)
        at[static_cast<std::size_t>(cquads_[q].v[static_cast<std::size_t>(k)])].emplace_back(q, k);
    // The edge across vertex g from edge e (-1: g is no regular crossing). A CAD corner of four
    // coarse quads whose edges pair up is a crossing too, whatever its curves: a chord through it
    // crosses its curves (or runs along smooth ones, chord_edge), it never runs along a sharp one,
    // so the corner stays on block sides, now inside one (A319: 48 blocks fewer).
    auto opposite = [&](GO g, GO e) -> GO {
      const auto& list = at[static_cast<std::size_t>(g)];
      if (list.size() != 4) return -1;
      std::vector<GO> edges;
      std::vector<std::pair<GO, GO>> paired;
      for (const auto& [q, k] : list) {
        const GO a = cquads_[q].e[static_cast<std::size_t>(k)];
        const GO b = cquads_[q].e[static_cast<std::size_t>((k + 3) % 4)];
        edges.push_back(a);
        edges.push_back(b);
        paired.emplace_back(a, b);
      }
      std::sort(edges.begin(), edges.end());
      edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
      if (edges.size() != 4) return -1;
      GO out = -1;
      for (GO x : edges) {
        if (x == e) continue;
        bool with_e = false;
        for (const auto& [a, b] : paired)
          with_e = with_e || (a == e && b == x) || (a == x && b == e);
        if (!with_e) {
          if (out >= 0) return -1;
          out = x;
        }
      }
      return out;
    };
    // A chord may run along smooth curves (its two sides then lie on two faces), never along a
    // sharp one.
    auto chord_edge = [&](GO e) {
      const LO c = cedges_[static_cast<std::size_t>(e)].curve;
      return c == kNoIndex || smooth_curve(c);
    };
    std::vector<char> removed(ne, 0), seen(ne, 0);
    std::vector<std::vector<GO>> chords;  // the closed ones, each as its edges
    for (std::size_t e0 = 0; e0 < ne; ++e0) {
      if (seen[e0] || !chord_edge(static_cast<GO>(e0))) continue;
      std::vector<GO> chain{static_cast<GO>(e0)};
      std::vector<GO> verts{cedges_[e0].a};
      seen[e0] = 1;
      bool closed = false, ok = true;
      GO e = static_cast<GO>(e0), g = cedges_[e0].b;
      while (ok) {
        const GO next = opposite(g, e);
        if (next < 0 || !chord_edge(next)) {
          ok = false;
          break;
        }
        if (std::find(verts.begin(), verts.end(), g) != verts.end() && g != verts.front()) {
          ok = false;
          break;
        }
        verts.push_back(g);
        if (next == static_cast<GO>(e0)) {
          closed = g == verts.front();
          break;
        }
        if (seen[static_cast<std::size_t>(next)]) {
          ok = false;
          break;
        }
        seen[static_cast<std::size_t>(next)] = 1;
        chain.push_back(next);
        const CEdge& ce = cedges_[static_cast<std::size_t>(next)];
        g = ce.a == g ? ce.b : ce.a;
        e = next;
      }
      if (ok && closed) chords.push_back(std::move(chain));
    }
    struct Ori {
      std::size_t q;
      int k;
    };
    auto edge_of = [&](Ori o, int side) {
      return cquads_[o.q].e[static_cast<std::size_t>((o.k + side) % 4)];
    };
    auto across = [&](Ori o, int side, int new_side) -> std::optional<Ori> {
      const GO e = edge_of(o, side);
      if (!removed[static_cast<std::size_t>(e)]) return std::nullopt;
      const CEdge& ce = cedges_[static_cast<std::size_t>(e)];
      for (const auto& [q, m] : ce.uses)
        if (q != static_cast<GO>(o.q)) {
          const Ori n{static_cast<std::size_t>(q), ((m - new_side) % 4 + 4) % 4};
          // The shared edge runs the other way in the neighbour (consistent orientation).
          if (cquads_[n.q].v[static_cast<std::size_t>((n.k + new_side) % 4)] !=
              cquads_[o.q].v[static_cast<std::size_t>((o.k + side + 1) % 4)])
            return std::nullopt;
          return n;
        }
      return std::nullopt;
    };
    auto own = [](int k, LO il, LO jl, LO n0, LO n1) -> std::pair<LO, LO> {
      if (k == 0) return {il, jl};
      if (k == 1) return {n0 - jl, il};
      if (k == 2) return {n0 - il, n1 - jl};
      return {jl, n1 - il};
    };
    // The rows of the grid that the quads `list` (joined across removed edges) make, walked as
    // (quad, orientation); false when they make none (a band closed on itself, say).
    auto grid_rows = [&](const std::vector<std::size_t>& list,
                         std::vector<std::vector<Ori>>& rows) {
      for (std::size_t q : list)
        for (int k = 0; k < 4; ++k) {
          const Ori o{q, k};
          if (removed[static_cast<std::size_t>(edge_of(o, 0))] ||
              removed[static_cast<std::size_t>(edge_of(o, 3))])
            continue;
          rows.clear();
          std::size_t count = 0;
          bool bad = false;
          for (std::optional<Ori> row = o; row && !bad; row = across(*row, 2, 0)) {
            rows.emplace_back();
            for (std::optional<Ori> c = row; c && !bad; c = across(*c, 1, 3)) {
              rows.back().push_back(*c);
              if (++count > list.size()) bad = true;
            }
            if (rows.back().size() != rows.front().size()) bad = true;
          }
          if (!bad && count == list.size()) return true;
        }
      return false;
    };
    // Chords removed one by one, in order, each only when every component it joins is still a
    // grid (removing all at once could close bands on themselves, whose quads would then all be
    // blocks of their own).
    Dsu comp;
    comp.resize(static_cast<GO>(nq));
    std::map<GO, std::vector<std::size_t>> members;
    for (std::size_t q = 0; q < nq; ++q) members[static_cast<GO>(q)].push_back(q);
    std::vector<std::vector<Ori>> trial_rows;
    chord_counts_ = {};
    for (const std::vector<GO>& chord : chords) {
      const std::vector<GO> saved = comp.parent;
      std::vector<GO> old_roots;
      for (GO x : chord) {
        removed[static_cast<std::size_t>(x)] = 1;
        for (const auto& [q, k] : cedges_[static_cast<std::size_t>(x)].uses)
          old_roots.push_back(comp.find(q));
      }
      std::sort(old_roots.begin(), old_roots.end());
      old_roots.erase(std::unique(old_roots.begin(), old_roots.end()), old_roots.end());
      for (GO x : chord) {
        const CEdge& ce = cedges_[static_cast<std::size_t>(x)];
        if (ce.uses.size() == 2) comp.unite(ce.uses[0].first, ce.uses[1].first);
      }
      std::map<GO, std::vector<std::size_t>> joined;
      for (GO r : old_roots) {
        auto& to = joined[comp.find(r)];
        const auto& from = members[r];
        to.insert(to.end(), from.begin(), from.end());
      }
      bool all_grids = true;
      for (auto& [r, list] : joined) {
        std::sort(list.begin(), list.end());
        if (!grid_rows(list, trial_rows)) all_grids = false;
        if (!all_grids) break;
      }
      if (!all_grids) {
        for (GO x : chord) removed[static_cast<std::size_t>(x)] = 0;
        comp.parent = saved;
        continue;
      }
      for (GO r : old_roots) members.erase(r);
      for (auto& [r, list] : joined) members[r] = std::move(list);
      ++chord_counts_[0];
    }
    chord_counts_[1] = static_cast<std::int64_t>(chords.size()) - chord_counts_[0];
    // The chords left, walked both ways from each of their edges: those open at an irregular
    // coarse vertex and the other open ones (what keeps blocks from joining; docs/benchmarks.md).
    irregular_coarse_ = 0;
    for (GO g = 0; g < ng_; ++g)
      if (vc(center_[static_cast<std::size_t>(g)]).dim == 2 &&
          !at[static_cast<std::size_t>(g)].empty() && at[static_cast<std::size_t>(g)].size() != 4)
        ++irregular_coarse_;
    {
      std::vector<char> walked(ne, 0);
      for (std::size_t e0 = 0; e0 < ne; ++e0) {
        if (walked[e0] || removed[e0] || !chord_edge(static_cast<GO>(e0))) continue;
        walked[e0] = 1;
        bool closed = false, at_irregular = false;
        for (int dir = 0; dir < 2 && !closed; ++dir) {
          GO e = static_cast<GO>(e0), g = dir == 0 ? cedges_[e0].b : cedges_[e0].a;
          for (;;) {
            const GO next = opposite(g, e);
            if (next < 0 || !chord_edge(next)) {
              at_irregular = at_irregular || (vc(center_[static_cast<std::size_t>(g)]).dim == 2 &&
                                              at[static_cast<std::size_t>(g)].size() != 4);
              break;
            }
            if (next == static_cast<GO>(e0)) {
              closed = true;
              break;
            }
            if (walked[static_cast<std::size_t>(next)]) break;
            walked[static_cast<std::size_t>(next)] = 1;
            const CEdge& ce = cedges_[static_cast<std::size_t>(next)];
            g = ce.a == g ? ce.b : ce.a;
            e = next;
          }
        }
        if (!closed) ++chord_counts_[at_irregular ? 2 : 3];
      }
    }
    // Coarse vertices on smooth curves that no chord can run straight through (not four quads):
    // each stops the chords along its curve.
    stuck_on_smooth_ = 0;
    for (GO g = 0; g < ng_; ++g) {
      const auto& at_g = vc(center_[static_cast<std::size_t>(g)]);
      if (at_g.dim == 1 && smooth_curve(at_g.entity) && !at[static_cast<std::size_t>(g)].empty() &&
          at[static_cast<std::size_t>(g)].size() != 4)
        ++stuck_on_smooth_;
    }
    std::vector<GO> block_of(nq, -1);
    blocks_across_ = 0;
    std::vector<std::pair<LO, std::size_t>> order;  // (face, first quad) of each component
    for (const auto& [r, list] : members)
      order.emplace_back(cquads_[list.front()].face, list.front());
    std::sort(order.begin(), order.end());
    for (const auto& [face_of, first] : order) {
      const LO face = face_of;  // a lambda below names it (clang 14 cannot capture bindings)
      const std::vector<std::size_t>& list = members[comp.find(static_cast<GO>(first))];
      // Rows of the component's grid, or each quad alone when it is not one.
      std::vector<std::vector<Ori>> rows;
      const bool grid = grid_rows(list, rows);
      auto emit = [&](const std::vector<std::vector<Ori>>& g) {
        const auto b = static_cast<GO>(lay.blocks.size());
        std::vector<LO> widths_i, widths_j;
        for (const Ori& o : g.front())
          widths_i.push_back(cedges_[static_cast<std::size_t>(edge_of(o, 0))].n);
        for (const auto& row : g)
          widths_j.push_back(cedges_[static_cast<std::size_t>(edge_of(row.front(), 3))].n);
        Block blk;
        blk.face = face;
        blk.ni = std::accumulate(widths_i.begin(), widths_i.end(), 0);
        blk.nj = std::accumulate(widths_j.begin(), widths_j.end(), 0);
        blk.first = static_cast<std::int64_t>(lay.vertices.size());
        std::vector<GO> grid_v(static_cast<std::size_t>(blk.ni + 1) *
                               static_cast<std::size_t>(blk.nj + 1));
        LO j0 = 0;
        bool across_faces = false;
        for (std::size_t r = 0; r < g.size(); ++r) {
          LO i0 = 0;
          for (std::size_t c = 0; c < g[r].size(); ++c) {
            const Ori o = g[r][c];
            const CQuad& cq = cquads_[o.q];
            const LO n0 = cedges_[static_cast<std::size_t>(cq.e[0])].n;
            const LO n1 = cedges_[static_cast<std::size_t>(cq.e[1])].n;
            for (LO jl = 0; jl <= widths_j[r]; ++jl)
              for (LO il = 0; il <= widths_i[c]; ++il) {
                const auto [i, j] = own(o.k, il, jl, n0, n1);
                grid_v[static_cast<std::size_t>(j0 + jl) * static_cast<std::size_t>(blk.ni + 1) +
                       static_cast<std::size_t>(i0 + il)] =
                    renum[static_cast<std::size_t>(
                        block_grid[o.q]
                                  [static_cast<std::size_t>(j) * static_cast<std::size_t>(n0 + 1) +
                                   static_cast<std::size_t>(i)])];
              }
            block_of[o.q] = b;
            if (cq.face != face) across_faces = true;
            i0 += widths_i[c];
          }
          j0 += widths_j[r];
        }
        lay.vertices.insert(lay.vertices.end(), grid_v.begin(), grid_v.end());
        lay.blocks.push_back(blk);
        if (across_faces) ++blocks_across_;
      };
      if (grid) {
        emit(rows);
      } else {
        for (std::size_t q : list) emit({{Ori{q, 0}}});
      }
    }
    lay.quad2block.resize(cq_of_fine.size());
    for (std::size_t i = 0; i < cq_of_fine.size(); ++i) lay.quad2block[i] = block_of[cq_of_fine[i]];
  }

  // Winslow smoothing face by face (smooth::smooth_face: boundary locked, every move kept only
  // when the local minimum SICN does not drop, nodes on the CAD surface), then a count of the
  // quads folded against their face's normal.
  template <typename FQ>
  void smooth_nodes(std::vector<FineNode>& nodes, const std::vector<FQ>& fq) {
    std::map<LO, std::vector<std::size_t>> by_face;
    for (std::size_t i = 0; i < fq.size(); ++i) by_face[fq[i].face].push_back(i);
    bad_fine_cquad_.assign(cquads_.size(), 0);
    std::vector<LO> local(nodes.size(), -1);
    for (const auto& [f, list] : by_face) {
      mesh::FaceMesh fm;
      fm.face = f;
      const cad::Face& face = model_.faces()[static_cast<std::size_t>(f)];
      auto seam = [&](LO c) {
        return std::find(face.seams.begin(), face.seams.end(), c) != face.seams.end();
      };
      std::vector<GO> global;
      std::vector<Vec2> gs_uv;
      for (std::size_t i : list) {
        std::array<LO, 4> lq{};
        for (int c = 0; c < 4; ++c) {
          const GO g = fq[i].v[static_cast<std::size_t>(c)];
          if (local[static_cast<std::size_t>(g)] < 0) {
            local[static_cast<std::size_t>(g)] = static_cast<LO>(global.size());
            global.push_back(g);
          }
          lq[static_cast<std::size_t>(c)] = local[static_cast<std::size_t>(g)];
        }
        fm.quads.push_back(lq);
      }
      // uv: a face node's own; a boundary node's is its projection from a face node of a quad of
      // its.
      fm.points.resize(global.size());
      fm.uv.resize(global.size());
      fm.vclass.resize(global.size());
      std::vector<char> has(global.size(), 0);
      for (std::size_t l = 0; l < global.size(); ++l) {
        const FineNode& n = nodes[static_cast<std::size_t>(global[l])];
        fm.points[l] = n.p;
        fm.vclass[l] = n.c;
        // Each curve node its own index: the smoother reads a (dim, entity, index) met twice with
        // two uv as a seam and skips its uv Laplacian. With the index left kNoIndex every curve
        // node of a curve shared that key, so every face looked like a seam. Nodes on the face's
        // own seam curves keep the shared key: there the face is periodic and one node stands for
        // two uv, which the Laplacian must not see.
        if (n.c.dim == 1 && !seam(n.c.entity)) fm.vclass[l].index = static_cast<LO>(global[l]);
        if (n.c.dim == 2) {
          fm.uv[l] = {n.c.param[0], n.c.param[1]};
          has[l] = 1;
        }
      }
      for (int round = 0; round < 4; ++round)
        for (std::size_t qi = 0; qi < fm.quads.size(); ++qi) {
          const auto& lq = fm.quads[qi];
          int src = -1;
          for (int c = 0; c < 4; ++c)
            if (has[static_cast<std::size_t>(lq[static_cast<std::size_t>(c)])]) src = c;
          if (src < 0) continue;
          for (int c = 0; c < 4; ++c) {
            const auto l = static_cast<std::size_t>(lq[static_cast<std::size_t>(c)]);
            if (has[l]) continue;
            Vec3 foot{};
            fm.uv[l] = face_geom(f).project(
                fm.points[l], fm.uv[static_cast<std::size_t>(lq[static_cast<std::size_t>(src)])],
                &foot);
            has[l] = 2;
          }
        }
      for (std::size_t l = 0; l < global.size(); ++l)
        if (!has[l]) {
          Vec3 foot{};
          fm.uv[l] = face_geom(f).project(fm.points[l], Vec2{0, 0}, &foot);
        }
      // A repair changes a few patches; every other face gets the same face mesh as in the last
      // fine mesh, and smoothing it again would give the same result (the smoother and the
      // untangler are deterministic and read the curve nodes' indices only as a pattern), so the
      // last result is taken (Block: 32 fine meshes, most of the coarse stage's time).
      SmoothedFace& memo = smoothed_[f];
      std::vector<LO> pattern = curve_node_pattern(fm);
      if (!same_face_mesh(memo, fm, pattern)) {
        smooth::SmoothOptions so;
        so.iterations = opt_.smoothing_iterations;
        // The uv Laplacian first (a direct solve, kept only when the face's minimum SICN does not
        // drop), not on faces with a seam, where a node on the seam has one uv for two sides.
        so.laplacian_uv = opt_.laplacian_uv && face.seams.empty();
        mesh::FaceMesh out =
            opt_.smoothing_iterations > 0 ? smooth::smooth_face(fm, face_geom(f), so) : fm;
        // Concave corners may leave folded quads (paper 002 Sec. IV.E): local untangling there.
        if (smooth::measure(out).invalid > 0 || folded(out, f) > 0)
          out = smooth::untangle_face(out, face_geom(f), smooth::UntangleOptions{});
        memo.folded.assign(out.quads.size(), 0);
        for (std::size_t qi = 0; qi < out.quads.size(); ++qi)
          memo.folded[qi] = folded_quad(out, f, qi) && !input_quad(out, qi) ? 1 : 0;
        memo.in = std::move(fm);
        memo.pattern = std::move(pattern);
        memo.out = std::move(out);
        memo.valid = true;
      }
      const mesh::FaceMesh& sm = memo.out;
      for (std::size_t l = 0; l < global.size(); ++l) {
        FineNode& n = nodes[static_cast<std::size_t>(global[l])];
        if (n.c.dim == 2) {
          n.p = sm.points[l];
          n.c.param = {sm.uv[l].u, sm.uv[l].v};
        }
        local[static_cast<std::size_t>(global[l])] = -1;
      }
      for (std::size_t qi = 0; qi < sm.quads.size(); ++qi)
        if (memo.folded[qi] != 0) bad_fine_cquad_[static_cast<std::size_t>(fq[list[qi]].block)] = 1;
    }
  }

  // A face's mesh before smoothing and after (smoothing and untangling), with its folded quads:
  // the last fine mesh's, per face (smooth_nodes).
  struct SmoothedFace {
    bool valid = false;
    mesh::FaceMesh in, out;
    std::vector<LO> pattern;  // curve_node_pattern(in)
    std::vector<char> folded;
  };

  // For each node of fm on a curve, the first node of fm with the same (curve, index) key (the
  // smoother's seam test reads only which keys repeat); -1 for the others.
  [[nodiscard]] static std::vector<LO> curve_node_pattern(const mesh::FaceMesh& fm) {
    std::vector<LO> out(fm.vclass.size(), -1);
    std::map<std::pair<LO, LO>, LO> first;
    for (std::size_t l = 0; l < fm.vclass.size(); ++l) {
      const mesh::VertexClass& c = fm.vclass[l];
      if (c.dim != 1) continue;
      out[l] = first.emplace(std::make_pair(c.entity, c.index), static_cast<LO>(l)).first->second;
    }
    return out;
  }

  // Whether fm is the face mesh memo was smoothed from, up to the curve nodes' index values.
  [[nodiscard]] static bool same_face_mesh(const SmoothedFace& memo, const mesh::FaceMesh& fm,
                                           const std::vector<LO>& pattern) {
    if (!memo.valid || memo.in.face != fm.face || memo.in.quads != fm.quads ||
        memo.in.triangles != fm.triangles || memo.in.points != fm.points || memo.in.uv != fm.uv ||
        memo.pattern != pattern || memo.in.vclass.size() != fm.vclass.size())
      return false;
    for (std::size_t l = 0; l < fm.vclass.size(); ++l) {
      const mesh::VertexClass &a = memo.in.vclass[l], &b = fm.vclass[l];
      if (a.dim != b.dim || a.entity != b.entity || a.param != b.param ||
          (a.dim != 1 && a.index != b.index))
        return false;
    }
    return true;
  }

  // Quads of face mesh fm turning against the normal of face f (at their corners).
  bool folded_quad(const mesh::FaceMesh& fm, LO f, std::size_t qi) {
    const auto& lq = fm.quads[qi];
    Vec3 nsum{0, 0, 0};
    for (LO c : lq) nsum += face_geom(f).normal(fm.uv[static_cast<std::size_t>(c)]);
    const Vec3 d1 =
        fm.points[static_cast<std::size_t>(lq[2])] - fm.points[static_cast<std::size_t>(lq[0])];
    const Vec3 d2 =
        fm.points[static_cast<std::size_t>(lq[3])] - fm.points[static_cast<std::size_t>(lq[1])];
    return norm2(nsum) > 0 && dot(cross(d1, d2), nsum) <= 0;
  }

  // Whether quad qi of fm is a quad of the input mesh: its four corners at the very points of
  // the four corners of one input quad. Such a fine quad is taken as the input has it: a coarse
  // quad at its input lengths reproduces its input quads, and a repair can do no more (the far-
  // field example at size factor 0.01: a quad wrapping the wing's leading edge at its tip, whose
  // corner normals differ by more than a right angle, failed the fold test after every repair).
  [[nodiscard]] bool input_quad(const mesh::FaceMesh& fm, std::size_t qi) const {
    std::array<GO, 4> v{};
    for (std::size_t c = 0; c < 4; ++c) {
      const auto it =
          input_points_.find(point_key(fm.points[static_cast<std::size_t>(fm.quads[qi][c])]));
      if (it == input_points_.end()) return false;
      v[c] = it->second;
    }
    for (const GO q : v2q_[v[0]]) {
      const auto& iq = m_.quads[static_cast<std::size_t>(q)];
      if (std::all_of(v.begin(), v.end(),
                      [&](GO x) { return std::find(iq.begin(), iq.end(), x) != iq.end(); }))
        return true;
    }
    return false;
  }

  // A point's coordinates bit for bit, as a key of input_points_.
  struct PointKey {
    std::array<std::uint64_t, 3> bits;
    bool operator==(const PointKey&) const = default;
  };
  struct PointKeyHash {
    std::size_t operator()(const PointKey& k) const {
      std::uint64_t h = 0x9e3779b97f4a7c15ULL;
      for (const std::uint64_t b : k.bits) h = (h ^ b) * 0x100000001b3ULL;
      return static_cast<std::size_t>(h);
    }
  };
  [[nodiscard]] static PointKey point_key(const Vec3& p) {
    return {{std::bit_cast<std::uint64_t>(p.x), std::bit_cast<std::uint64_t>(p.y),
             std::bit_cast<std::uint64_t>(p.z)}};
  }

  std::int64_t folded(const mesh::FaceMesh& fm, LO f) {
    std::int64_t n = 0;
    for (std::size_t qi = 0; qi < fm.quads.size(); ++qi) n += folded_quad(fm, f, qi) ? 1 : 0;
    return n;
  }

  struct CQuad {
    std::array<GO, 4> v{};
    std::array<GO, 4> e{};
    LO face = kNoIndex;
    LO cell = kNoIndex;
  };
  struct CEdge {
    GO a, b;
    std::vector<std::pair<GO, int>> uses{};
    LO curve = kNoIndex;
    double target = 0, target_count = 0;
    LO n = 1;
  };

  const mesh::SurfaceMesh& m_;
  const cad::CadModel& model_;
  const CoarseOptions& opt_;
  GO nv_;
  detail::VertexQuads v2q_;
  std::unordered_map<PointKey, GO, PointKeyHash> input_points_;  // input point -> vertex
  std::unordered_map<std::uint64_t, EdgeRec> edges_;
  std::vector<Trace> traces_;
  std::vector<Grid> grids_;
  std::vector<char> node_;
  std::vector<Arc> arcs_;
  std::unordered_map<std::uint64_t, LO> edge_arc_;
  std::vector<std::array<std::vector<SideArc>, 4>> sides_;
  std::vector<long> q_;
  std::unordered_map<GO, GO> node_point_;
  std::vector<GO> arc_base_, rep_;
  Dsu dsu_;
  std::vector<std::vector<std::pair<GO, LO>>> links_;  // zero-length links of each point
  std::vector<std::vector<LO>> labels_;                // the arcs whose lengths make each link
  std::vector<Cell> cells_;
  std::vector<GO> group_, center_;
  GO ng_ = 0;
  std::vector<CQuad> cquads_;
  std::vector<CEdge> cedges_;
  std::unordered_map<std::uint64_t, GO> edge_id_;
  std::map<LO, std::unique_ptr<cad::FaceGeometry>> face_geom_;
  std::map<LO, std::unique_ptr<cad::CurveGeometry>> curve_geom_;
  std::vector<char> bad_fine_cquad_;
  std::vector<std::vector<double>> curve_params_;  // input_params, per CAD curve
  std::vector<int> repair_level_;
  std::map<LO, SmoothedFace> smoothed_;  // per face, the last fine mesh's (smooth_nodes)

  std::vector<std::size_t> bad_cquads_;
  std::int64_t bad_quads_ = 0;
  std::vector<std::vector<LO>> point_patches_;
  std::vector<char> smooth_;   // per CAD curve
  std::vector<char> crossed_;  // per trace: ran on across a smooth curve
  std::int64_t traces_across_ = 0, blocks_across_ = 0, stuck_on_smooth_ = 0;
  std::int64_t irregular_coarse_ = 0;
  // Chords removed, closed but kept, open at an irregular coarse vertex, open elsewhere.
  std::array<std::int64_t, 4> chord_counts_{};
};

}  // namespace

int fit_loop_width(const std::vector<LoopCrossing>& crossings) {
  if (crossings.empty()) return 1;
  // The cost is convex in ln w, so its integer minimum lies at the floor or the ceiling of the
  // weighted median of the extents, searched here over every integer up to the largest extent
  // (loops are short: a few cells, extents of a few input quads).
  double top = 1;
  for (const LoopCrossing& c : crossings) top = std::max(top, c.extent);
  const int wmax = static_cast<int>(std::ceil(top));
  int best = 1;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int w = 1; w <= wmax; ++w) {
    double cost = 0;
    for (const LoopCrossing& c : crossings)
      cost += std::max(c.weight, 0.0) * std::abs(std::log(w / std::max(c.extent, 0.5)));
    if (w == 1 || cost < best_cost - 1e-12 * std::max(1.0, best_cost)) {
      best_cost = cost;
      best = w;
    }
  }
  return best;
}

bool choose_side_spacing(const SideScore& uniform, const SideScore& input_like, double avg_slack) {
  if (input_like.sicn_min <= 0) return false;
  if (uniform.sicn_min <= 0) return true;
  return input_like.sicn_avg >= uniform.sicn_avg - avg_slack &&
         input_like.sicn_min >= 0.9 * uniform.sicn_min;
}

CoarseResult build_coarse_layout(const mesh::SurfaceMesh& input, const cad::CadModel& model,
                                 const CoarseOptions& options) {
  QSMESH_CHECK(input.quad_face.size() == input.quads.size() &&
                   input.vclass.size() == input.points.size() &&
                   input.bar_curve.size() == input.bars.size(),
               "coarse layout: inconsistent mesh arrays");
  Builder b(input, model, options);
  return b.run();
}

}  // namespace qsmesh::layout
