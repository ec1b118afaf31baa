#include "qsmesh/smooth/untangle.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <vector>

#include "internal.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/smooth/quad_tools.hpp"

namespace qsmesh::smooth {
namespace {

// Sharpness of the soft minimum driving the search: small enough to track the true minimum
// (about tau * log(corners) below it), large enough to give a smooth landscape where two quads
// compete for the minimum, which a plain max-min compass search cannot cross.
constexpr double kTau = 0.02;
constexpr int kLaplacianSweeps = 30;
// Progress check: every kStallSweeps sweeps the patch's worst quad must have gained kStallGain.
constexpr int kStallSweeps = 10;
constexpr double kStallGain = 1e-3;

struct Score {
  double soft = -std::numeric_limits<double>::infinity();  // soft minimum of the corner values
  double hard = -std::numeric_limits<double>::infinity();  // minimum oriented SICN of the quads
};

class Untangler {
 public:
  Untangler(mesh::FaceMesh& m, const cad::FaceGeometry& s, std::vector<std::vector<LO>> v2q,
            double sign)
      : m_(m), s_(s), v2q_(std::move(v2q)), sign_(sign), normal_(m.points.size()) {
    for (LO v = 0; v < m_.num_vertices(); ++v) normal_[v] = s_.normal(m_.uv[v]) * sign_;
    for (const auto& uv : m_.uv) box_.add(uv);
  }

  [[nodiscard]] double quad_quality(LO q) const {
    const auto& qd = m_.quads[q];
    Vec3 n{};
    for (const LO w : qd) n += normal_[w];
    return oriented_sicn({m_.points[qd[0]], m_.points[qd[1]], m_.points[qd[2]], m_.points[qd[3]]},
                         n, 1.0);
  }

  // Corner values of Eq. 12 (what mesh::quad_sicn takes the minimum of: against the quad's own
  // mean normal), soft minimum over the quads of v, and the hard minimum. A quad turned against the
  // surface is measured against the surface normal instead, so that all its corners score negative
  // and unfolding it raises the score.
  // With `floor`: a score whose soft minimum cannot exceed it (its lowest corner value is at or
  // below it, and the soft minimum is never above the lowest value) comes back as soft = -inf
  // without the exponentials: the search only asks whether a trial beats its best so far.
  [[nodiscard]] Score score(LO v, double floor = -std::numeric_limits<double>::infinity()) const {
    corner_.clear();
    Score sc;
    sc.hard = std::numeric_limits<double>::infinity();
    for (const LO q : v2q_[v]) {
      const auto& qd = m_.quads[q];
      const mesh::QuadCorners c = mesh::quad_corners(
          {m_.points[qd[0]], m_.points[qd[1]], m_.points[qd[2]], m_.points[qd[3]]});
      Vec3 ref{};
      for (int k = 0; k < 4; ++k) ref += normal_[qd[k]];
      const bool flipped = norm2(ref) > 0 && dot(c.sum, ref) <= 0;
      const Vec3 nq = flipped ? normalized(ref) : normalized(c.sum);
      // Unflipped, the corner values are those quad_sicn takes the minimum of, so the quad's
      // oriented SICN (quad_quality) is their minimum, -1 flipped: one evaluation, not two.
      double worst = std::numeric_limits<double>::max();
      for (int k = 0; k < 4; ++k) {
        const double value =
            c.denom[k] > 0 && norm2(nq) > 0 ? 2.0 * dot(c.n[k], nq) / c.denom[k] : -1.0;
        corner_.push_back(value);
        worst = std::min(worst, value);
      }
      sc.hard = std::min(sc.hard, flipped ? -1.0 : worst);
    }
    const double lo = *std::min_element(corner_.begin(), corner_.end());
    if (lo <= floor) {
      sc.soft = -std::numeric_limits<double>::infinity();
      return sc;
    }
    double sum = 0;
    for (const double c : corner_) sum += std::exp(-(c - lo) / kTau);
    sc.soft = lo - kTau * std::log(sum);
    return sc;
  }

  // Compass search for vertex v from step *h; returns true when v moved.
  bool search(LO v, double* h, double h_min) {
    bool moved = false;
    Score cur = score(v);
    for (int round = 0; round < 8 && *h > h_min; ++round) {
      const auto e = s_.eval(m_.uv[v]);
      const double g11 = dot(e.du, e.du), g12 = dot(e.du, e.dv), g22 = dot(e.dv, e.dv);
      const double det = g11 * g22 - g12 * g12;
      const bool metric_ok = det > 1e-12 * g11 * g22 && std::isfinite(det);
      Vec3 e1 = normalized(norm2(e.du) > 0 ? e.du : e.dv);
      Vec3 e2 = normalized(cross(normalized(cross(e.du, e.dv)), e1));
      const Vec2 uv0 = m_.uv[v];
      const Vec3 x0 = m_.points[v], n0 = normal_[v];
      Vec2 best_uv = uv0;
      Vec3 best_x = x0, best_n = n0;
      Score best = cur;
      for (int k = 0; k < 8; ++k) {
        const double th = k * std::numbers::pi / 4;
        Vec2 duv;
        if (metric_ok) {
          const Vec3 d = (e1 * std::cos(th) + e2 * std::sin(th)) * *h;
          const double b1 = dot(e.du, d), b2 = dot(e.dv, d);
          duv = {(g22 * b1 - g12 * b2) / det, (g11 * b2 - g12 * b1) / det};
        } else {
          // Near a singular point of the parametrization: steps straight in (u, v), scaled by the
          // longer derivative.
          const double scale = std::sqrt(std::max(g11, g22));
          if (!(scale > 0)) break;
          duv = Vec2{std::cos(th), std::sin(th)} * (*h / scale);
        }
        const Vec2 uv = uv0 + duv;
        if (!(uv.u >= box_.lo.u && uv.u <= box_.hi.u && uv.v >= box_.lo.v && uv.v <= box_.hi.v))
          continue;
        m_.uv[v] = uv;
        m_.points[v] = s_.eval(uv).p;
        normal_[v] = s_.normal(uv) * sign_;
        const Score sc = score(v, best.soft);
        const bool valid_kept = sc.hard > 0 || sc.hard >= cur.hard;
        if (valid_kept && sc.soft > best.soft) {
          best = sc;
          best_uv = uv;
          best_x = m_.points[v];
          best_n = normal_[v];
        }
      }
      m_.uv[v] = best_uv;
      m_.points[v] = best_x;
      normal_[v] = best_n;
      if (best.soft > cur.soft) {
        cur = best;
        moved = true;
        *h *= 1.5;
      } else {
        *h *= 0.5;
      }
    }
    return moved;
  }

  // One Gauss-Seidel step of v towards the mean of its edge neighbours, in the tangent plane at v
  // mapped to (u, v) through the first derivatives (3D, so seams in the patch do not matter).
  void relax(LO v) {
    Vec3 mean{};
    int count = 0;
    for (const LO q : v2q_[v]) {
      const auto& qd = m_.quads[q];
      int k = 0;
      while (qd[k] != v) ++k;
      mean += m_.points[qd[(k + 1) % 4]] + m_.points[qd[(k + 3) % 4]];
      count += 2;
    }
    if (count == 0) return;
    const auto e = s_.eval(m_.uv[v]);
    const Vec3 d = mean / count - m_.points[v];
    const double g11 = dot(e.du, e.du), g12 = dot(e.du, e.dv), g22 = dot(e.dv, e.dv);
    const double det = g11 * g22 - g12 * g12;
    if (!(det > 1e-12 * g11 * g22) || !std::isfinite(det)) return;
    const double b1 = dot(e.du, d), b2 = dot(e.dv, d);
    const Vec2 uv = m_.uv[v] + Vec2{(g22 * b1 - g12 * b2) / det, (g11 * b2 - g12 * b1) / det};
    if (!(uv.u >= box_.lo.u && uv.u <= box_.hi.u && uv.v >= box_.lo.v && uv.v <= box_.hi.v)) return;
    m_.uv[v] = uv;
    m_.points[v] = s_.eval(uv).p;
    normal_[v] = s_.normal(uv) * sign_;
  }

  void restore(LO v, const Vec2& uv, const Vec3& x) {
    m_.uv[v] = uv;
    m_.points[v] = x;
    normal_[v] = s_.normal(uv) * sign_;
  }

  [[nodiscard]] const std::vector<std::vector<LO>>& v2q() const { return v2q_; }

 private:
  mesh::FaceMesh& m_;
  const cad::FaceGeometry& s_;
  std::vector<std::vector<LO>> v2q_;
  double sign_;
  std::vector<Vec3> normal_;  // oriented unit surface normal at each vertex (zero at a pole)
  Box2 box_;
  mutable std::vector<double> corner_;
};

// The quads and vertices within `rings` rings of quads around the quads `seeds`: the seeds and
// their vertices, then ring by ring every quad of a vertex reached last, and its vertices. Both
// lists sorted. `vertex_mark` (one per vertex) and `quad_mark` (one per quad) are all 0 on entry
// and are left so.
void grow_patch(const mesh::FaceMesh& m, const std::vector<std::vector<LO>>& v2q,
                std::span<const LO> seeds, int rings, std::vector<char>& vertex_mark,
                std::vector<char>& quad_mark, std::vector<LO>& quads, std::vector<LO>& verts) {
  quads.clear();
  verts.clear();
  for (const LO q : seeds) {
    if (quad_mark[q]) continue;
    quad_mark[q] = 1;
    quads.push_back(q);
    for (const LO v : m.quads[q])
      if (!vertex_mark[v]) {
        vertex_mark[v] = 1;
        verts.push_back(v);
      }
  }
  std::vector<LO> front = verts;
  for (int r = 0; r < rings; ++r) {
    std::vector<LO> next;
    for (const LO v : front)
      for (const LO q : v2q[v]) {
        if (quad_mark[q]) continue;
        quad_mark[q] = 1;
        quads.push_back(q);
        for (const LO w : m.quads[q])
          if (!vertex_mark[w]) {
            vertex_mark[w] = 1;
            next.push_back(w);
            verts.push_back(w);
          }
      }
    front = std::move(next);
  }
  for (const LO q : quads) quad_mark[q] = 0;
  for (const LO v : verts) vertex_mark[v] = 0;
  std::sort(quads.begin(), quads.end());
  std::sort(verts.begin(), verts.end());
}

}  // namespace

mesh::FaceMesh untangle_face(const mesh::FaceMesh& input, const cad::FaceGeometry& surface,
                             const UntangleOptions& options, UntangleStats* stats) {
  QSMESH_CHECK(input.uv.size() == input.points.size() && input.vclass.size() == input.points.size(),
               "face " << input.face << ": points, uv and vclass sizes differ");
  QSMESH_CHECK(options.rings >= 0 && options.max_rings >= options.rings && options.sweeps >= 0,
               "untangle: rings, max_rings and sweeps must be >= 0 with max_rings >= rings");
  UntangleStats st;
  st.before = measure(input);
  st.after = st.before;
  mesh::FaceMesh m = input;
  const Stopwatch clock;
  const LO nv = m.num_vertices();
  const LO nq = static_cast<LO>(m.quads.size());
  if (nq == 0) {
    if (stats) *stats = st;
    return m;
  }
  std::vector<char> free(static_cast<std::size_t>(nv), 0);
  for (LO v = 0; v < nv; ++v) free[v] = m.vclass[v].dim == 2 ? 1 : 0;
  for (const auto& t : m.triangles)
    for (const LO v : t) free[v] = 0;

  Untangler un(m, surface, detail::vertex_quads(m), quad_orientation(m, surface));
  const auto& v2q = un.v2q();
  auto seeds = [&] {
    std::vector<LO> s;
    for (LO q = 0; q < nq; ++q)
      if (un.quad_quality(q) <= options.target) s.push_back(q);
    return s;
  };
  std::vector<LO> seed = seeds();
  st.seeds = static_cast<std::int64_t>(seed.size());

  // Per-vertex initial step: a quarter of the shortest incident edge (reset for each patch, kept
  // across the sweeps of a patch).
  std::vector<double> step0(static_cast<std::size_t>(nv), 0.0), step_min(step0);
  for (LO v = 0; v < nv; ++v) {
    double shortest = std::numeric_limits<double>::infinity();
    for (const LO q : v2q[v]) {
      const auto& qd = m.quads[q];
      int k = 0;
      while (qd[k] != v) ++k;
      shortest = std::min({shortest, distance(m.points[v], m.points[qd[(k + 1) % 4]]),
                           distance(m.points[v], m.points[qd[(k + 3) % 4]])});
    }
    if (std::isfinite(shortest)) {
      step0[v] = 0.25 * shortest;
      step_min[v] = 1e-7 * shortest;
    }
  }

  std::vector<char> vertex_mark(static_cast<std::size_t>(nv), 0),
      quad_mark(static_cast<std::size_t>(nq), 0);
  std::vector<LO> patch_quads, patch_verts;
  for (int rings = options.rings; !seed.empty() && !st.timed_out;
       rings += std::max(options.rings, 1)) {
    // Patch: vertices of the seeds grown by `rings` rings of quads.
    grow_patch(m, v2q, seed, rings, vertex_mark, quad_mark, patch_quads, patch_verts);
    std::vector<LO> patch;
    for (const LO v : patch_verts)
      if (free[v] && step0[v] > 0) patch.push_back(v);
    // A vertex stuck at its smallest step in a smaller patch may move again with new neighbours.
    std::vector<double> step = step0;
    st.rings = rings;
    st.patch_vertices = static_cast<std::int64_t>(patch.size());
    // Start from the tangent-plane Laplacian of the patch (its boundary fixed), which unfolds most
    // tangles inside a patch of reasonable shape, unless it makes the patch's worst quad worse.
    int valid_sweeps = 0;
    double last_worst = -std::numeric_limits<double>::infinity();
    std::vector<LO> pq;  // quads of the patch
    for (const LO v : patch) pq.insert(pq.end(), v2q[v].begin(), v2q[v].end());
    std::sort(pq.begin(), pq.end());
    pq.erase(std::unique(pq.begin(), pq.end()), pq.end());
    if (options.laplacian_start) {
      const auto worst = [&] {
        double w = std::numeric_limits<double>::infinity();
        for (const LO q : pq) w = std::min(w, un.quad_quality(q));
        return w;
      };
      const double w0 = worst();
      std::vector<Vec2> uv0(patch.size());
      std::vector<Vec3> x0(patch.size());
      for (std::size_t i = 0; i < patch.size(); ++i) {
        uv0[i] = m.uv[patch[i]];
        x0[i] = m.points[patch[i]];
      }
      for (int it = 0; it < kLaplacianSweeps; ++it)
        for (const LO v : patch) un.relax(v);
      if (!(worst() > w0))
        for (std::size_t i = 0; i < patch.size(); ++i) un.restore(patch[i], uv0[i], x0[i]);
    }
    for (int sweep = 0; sweep < options.sweeps; ++sweep) {
      if (options.time_budget_s > 0 && clock.seconds() > options.time_budget_s) {
        st.timed_out = true;
        break;
      }
      bool moved = false;
      for (const LO v : patch) moved = un.search(v, &step[v], step_min[v]) || moved;
      ++st.sweeps;
      if (!moved) break;
      // Once the patch is above the target, a few more sweeps lift its minimum; the rest is the
      // smoother's job.
      bool above = true;
      for (const LO q : pq) above = above && un.quad_quality(q) > options.target;
      valid_sweeps = above ? valid_sweeps + 1 : 0;
      if (valid_sweeps > options.polish_sweeps) break;
      // A patch whose worst quad stalls is left: a tangle that small moves cannot undo (e.g. quads
      // wrapped around an edge too sharp for their size) would otherwise use every sweep.
      if ((sweep + 1) % kStallSweeps == 0) {
        double worst = std::numeric_limits<double>::infinity();
        for (const LO q : pq) worst = std::min(worst, un.quad_quality(q));
        if (!(worst > last_worst + kStallGain)) break;
        last_worst = worst;
      }
    }
    seed = seeds();
    if (rings >= options.max_rings) break;
  }

  detail::sync_interior_params(m);
  st.rolled_back = detail::keep_or_roll_back(m, input, st.before, detail::Accept::kGain, st.after);
  if (stats) *stats = st;
  return m;
}

mesh::FaceMesh lift_poor_quads(const mesh::FaceMesh& input, const cad::FaceGeometry& surface,
                               const LiftOptions& options, LiftStats* stats) {
  QSMESH_CHECK(options.rings >= 1 && options.max_rings >= options.rings,
               "lift_poor_quads: rings must be >= 1 and max_rings >= rings");
  LiftStats st;
  st.before = measure(input);
  st.after = st.before;
  mesh::FaceMesh m = input;
  const LO nv = m.num_vertices();
  const auto nq = static_cast<LO>(m.quads.size());
  if (nq == 0 || !(options.target > 0) || !(st.before.sicn_min < options.target)) {
    if (stats) *stats = st;
    return m;
  }
  const std::vector<std::vector<LO>> v2q = detail::vertex_quads(m);
  std::vector<char> movable(static_cast<std::size_t>(nv), 0);
  for (LO v = 0; v < nv; ++v) movable[v] = m.vclass[v].dim == 2 ? 1 : 0;
  for (const auto& t : m.triangles)
    for (const LO v : t) movable[v] = 0;
  const auto sicn = [&](LO q) {
    const auto& qd = m.quads[q];
    return mesh::quad_sicn({m.points[qd[0]], m.points[qd[1]], m.points[qd[2]], m.points[qd[3]]});
  };

  std::vector<char> in_patch(static_cast<std::size_t>(nq), 0),
      seen(static_cast<std::size_t>(nv), 0);
  std::vector<LO> local(static_cast<std::size_t>(nv), kNoIndex), quads, verts;
  // One patch of `rings` rings around `seed`; true when no larger patch is worth trying.
  const auto lift = [&](LO seed, int rings) {
    // The patch: the seed grown ring by ring through the vertices' quads.
    const std::array<LO, 1> seeds{seed};
    grow_patch(m, v2q, seeds, rings, seen, in_patch, quads, verts);
    for (const LO q : quads) in_patch[q] = 1;
    // The patch as a mesh of its own: a vertex with a quad outside stays, held by a degenerate
    // triangle (untangle_face never moves triangle vertices).
    mesh::FaceMesh sub;
    sub.face = m.face;
    for (const LO v : verts) {
      local[v] = sub.num_vertices();
      sub.points.push_back(m.points[v]);
      sub.uv.push_back(m.uv[v]);
      sub.vclass.push_back(m.vclass[v]);
    }
    std::vector<LO> moving;
    std::vector<char> moves(verts.size(), 0);
    for (std::size_t i = 0; i < verts.size(); ++i) {
      const LO v = verts[i];
      bool inside = movable[v] != 0;
      for (const LO q : v2q[v]) inside = inside && in_patch[q];
      if (inside) {
        moving.push_back(v);
        moves[i] = 1;
      } else {
        sub.triangles.push_back({local[v], local[v], local[v]});
      }
    }
    // Only the quads that can change are measured: a poor quad of fixed vertices (a cusp's, or
    // one held between curves) must not make the patch's minimum unreachable.
    for (const LO q : quads) {
      std::array<LO, 4> lq{};
      bool changes = false;
      for (int k = 0; k < 4; ++k) {
        lq[k] = local[m.quads[q][k]];
        changes = changes || moves[static_cast<std::size_t>(lq[k])] != 0;
      }
      if (changes) sub.quads.push_back(lq);
    }
    for (const LO q : quads) in_patch[q] = 0;
    if (moving.empty()) {
      for (const LO v : verts) local[v] = kNoIndex;
      return false;
    }
    UntangleOptions uo;
    uo.target = options.target;
    uo.rings = 2 * rings + 2;  // the whole patch at once
    uo.max_rings = uo.rings;
    uo.polish_sweeps = options.polish_sweeps;
    uo.laplacian_start = options.laplacian_start;
    UntangleStats us;
    const mesh::FaceMesh out = untangle_face(sub, surface, uo, &us);
    // A lift that leaves the patch below the target is worth keeping only when it costs the
    // patch nothing on average: a quad held by a short curve edge (a sliver's) rises by a few
    // thousandths while the search reshapes its neighbours for them.
    const bool reached = us.after.sicn_min >= options.target;
    const bool free_gain = us.after.sicn_avg >= us.before.sicn_avg || !options.partial_only_free;
    if (!us.rolled_back && (reached || free_gain)) {
      ++st.lifted;
      for (const LO v : moving) {
        const LO l = local[v];
        m.points[v] = out.points[l];
        m.uv[v] = out.uv[l];
        m.vclass[v].param = out.vclass[l].param;
      }
    }
    for (const LO v : verts) local[v] = kNoIndex;
    // Worth a larger patch only when this one got a tenth of the way: one that barely moves is
    // held by its fixed vertices (a sliver's short curve edge), not short of room.
    const double before = us.before.sicn_min;
    return reached || us.after.sicn_min - before < 0.1 * (options.target - before);
  };
  for (LO seed = 0; seed < nq; ++seed) {
    if (!(sicn(seed) < options.target)) continue;
    ++st.seeds;
    // A larger patch only where the smaller one made some way toward the target: more room, more
    // cost.
    for (int rings = options.rings; rings <= options.max_rings; rings += options.rings)
      if (lift(seed, rings)) break;
  }
  st.after = measure(m);
  if (stats) *stats = st;
  return m;
}

}  // namespace qsmesh::smooth
