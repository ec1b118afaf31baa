#include "qsmesh/smooth/smooth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include "internal.hpp"
#include "qsmesh/core/adjacency.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/smooth/approx_surface.hpp"
#include "qsmesh/smooth/quad_tools.hpp"

namespace qsmesh::smooth {

QualityReport measure(const mesh::FaceMesh& mesh) {
  QualityReport r;
  if (mesh.quads.empty()) return r;
  double sum = 0;
  r.sicn_min = std::numeric_limits<double>::max();
  for (const auto& q : mesh.quads) {
    const double s = mesh::quad_sicn(
        {mesh.points[q[0]], mesh.points[q[1]], mesh.points[q[2]], mesh.points[q[3]]});
    r.sicn_min = std::min(r.sicn_min, s);
    sum += s;
    if (s <= 0) ++r.invalid;
  }
  r.quads = static_cast<std::int64_t>(mesh.quads.size());
  r.sicn_avg = sum / static_cast<double>(r.quads);
  return r;
}

namespace {

// Flat (CSR) per-vertex lists: smooth_face runs on every cavity of the improvement stage, most of
// them a few dozen quads, where one vector per vertex was a good part of the time (allocation).
struct Topology {
  std::vector<char> free;  // vertex may move
  Adjacency v2q;           // incident quads, increasing
  Adjacency v2v;           // edge neighbours, increasing
  Adjacency ring;          // ordered one-ring (edge, diagonal, edge, ...); empty: not a closed fan
};

Topology build_topology(const mesh::FaceMesh& m) {
  const LO n = m.num_vertices();
  const LO nq = static_cast<LO>(m.quads.size());
  Topology t;
  t.free.assign(static_cast<std::size_t>(n), 0);
  for (LO v = 0; v < n; ++v) t.free[v] = m.vclass[v].dim == 2 ? 1 : 0;
  // Triangles are not measured here, so their vertices stay where they are.
  for (const auto& tri : m.triangles)
    for (LO v : tri) t.free[v] = 0;
  // v2q in quad order (increasing), by counting.
  t.v2q.offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  for (const auto& qd : m.quads)
    for (const LO v : qd) ++t.v2q.offsets[v + 1];
  for (LO v = 0; v < n; ++v) t.v2q.offsets[v + 1] += t.v2q.offsets[v];
  t.v2q.targets.resize(static_cast<std::size_t>(t.v2q.offsets[n]));
  {
    std::vector<LO> fill(t.v2q.offsets.begin(), t.v2q.offsets.end() - 1);
    for (LO q = 0; q < nq; ++q)
      for (const LO v : m.quads[q]) t.v2q.targets[fill[v]++] = q;
  }
  // v2v: the two edge neighbours in each incident quad, sorted and made unique per vertex.
  t.v2v.offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  t.v2v.targets.clear();
  t.v2v.targets.reserve(t.v2q.targets.size() * 2);
  for (LO v = 0; v < n; ++v) {
    const auto begin = static_cast<std::ptrdiff_t>(t.v2v.targets.size());
    for (const LO q : t.v2q[v]) {
      const auto& qd = m.quads[q];
      for (int k = 0; k < 4; ++k)
        if (qd[k] == v) {
          t.v2v.targets.push_back(qd[(k + 1) % 4]);
          t.v2v.targets.push_back(qd[(k + 3) % 4]);
        }
    }
    const auto first = t.v2v.targets.begin() + begin;
    std::sort(first, t.v2v.targets.end());
    t.v2v.targets.erase(std::unique(first, t.v2v.targets.end()), t.v2v.targets.end());
    t.v2v.offsets[v + 1] = static_cast<LO>(t.v2v.targets.size());
  }
  t.ring.offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  t.ring.targets.clear();
  t.ring.targets.reserve(t.v2q.targets.size() * 2);
  std::vector<std::array<LO, 3>> seg;
  std::vector<LO> ring;
  std::vector<char> used;
  for (LO v = 0; v < n; ++v) {
    t.ring.offsets[v + 1] = t.ring.offsets[v];
    if (!t.free[v] || t.v2q[v].size() < 3) continue;
    // Fan segments (a, d, b) of quads (v, a, d, b); chained by b_i == a_{i+1}.
    seg.clear();
    for (LO q : t.v2q[v]) {
      const auto& qd = m.quads[q];
      int k = 0;
      while (qd[k] != v) ++k;
      seg.push_back({qd[(k + 1) % 4], qd[(k + 2) % 4], qd[(k + 3) % 4]});
    }
    ring.clear();
    used.assign(seg.size(), 0);
    std::size_t cur = 0;
    bool ok = true;
    for (std::size_t step = 0; step < seg.size(); ++step) {
      used[cur] = 1;
      ring.push_back(seg[cur][0]);
      ring.push_back(seg[cur][1]);
      if (step + 1 == seg.size()) {
        ok = seg[cur][2] == seg[0][0];
        break;
      }
      std::size_t next = seg.size();
      for (std::size_t j = 0; j < seg.size(); ++j)
        if (!used[j] && seg[j][0] == seg[cur][2]) {
          next = j;
          break;
        }
      if (next == seg.size()) {
        ok = false;
        break;
      }
      cur = next;
    }
    if (!ok) continue;
    t.ring.targets.insert(t.ring.targets.end(), ring.begin(), ring.end());
    t.ring.offsets[v + 1] = static_cast<LO>(t.ring.targets.size());
  }
  return t;
}

// Seam: a boundary vertex appearing twice with different uv; pole: the surface normal vanishes at
// a boundary vertex. Either way the boundary uv is not a continuous image of the boundary.
const char* uv_discontinuity(const mesh::FaceMesh& m, const cad::FaceGeometry& surface) {
  std::map<std::tuple<int, LO, LO>, Vec2> seen;
  for (LO v = 0; v < m.num_vertices(); ++v) {
    const auto& c = m.vclass[v];
    if (c.dim == 2) continue;
    const auto key = std::make_tuple(int(c.dim), c.entity, c.dim == 1 ? c.index : kNoIndex);
    const auto [it, inserted] = seen.emplace(key, m.uv[v]);
    if (!inserted && !(it->second == m.uv[v])) return "seam";
    if (norm2(surface.normal(m.uv[v])) == 0) return "pole";
  }
  return nullptr;
}

class Smoother {
 public:
  Smoother(mesh::FaceMesh& m, const cad::FaceGeometry& s, const Topology& t, double sign,
           const ApproxSurface* approx)
      : m_(m), s_(s), t_(t), sign_(sign), approx_(approx) {
    forget_geometry();
  }

  // The surface normal at each vertex and the quality of each quad are kept until a vertex of
  // theirs moves: a move is judged by the quality of its quads before and after, and recomputing
  // both sides (with a surface normal per quad) was most of the smoothing time (A319.brep: the
  // normals alone a quarter of the cavity remeshing). Call after moving vertices behind the
  // smoother's back.
  void forget_geometry() {
    settled_.assign(m_.points.size(), 0);
    normal_ok_.assign(m_.points.size(), 0);
    normal_.resize(m_.points.size());
    quality_ok_.assign(m_.quads.size(), 0);
    quality_.resize(m_.quads.size());
  }

  // The orientation of the quads against the surface normal (quad_orientation); set before the
  // first quality is asked for (the cached qualities use it).
  void set_sign(double sign) { sign_ = sign; }
  [[nodiscard]] Vec3 normal_at(LO v) const { return vertex_normal(v); }

  // forget_geometry() for the vertices with moved[v] alone: their normals, the qualities of their
  // quads and every settled mark. A normal is a function of its (u, v) and a quality of its four
  // corners and that normal, so what the others had is what recomputing would give, bit for bit
  // (after the uv Laplacian, most of a cavity candidate's vertices are locked: recomputing their
  // normals was a tenth of the smoothing).
  void forget_moved(const std::vector<char>& moved) {
    settled_.assign(m_.points.size(), 0);
    for (LO v = 0; v < static_cast<LO>(moved.size()); ++v) {
      if (!moved[v]) continue;
      normal_ok_[v] = 0;
      for (const LO q : t_.v2q[v]) quality_ok_[q] = 0;
    }
  }

  // Kernel targets go to the surface through the approximate surface when there is one, unless
  // `exact` (then by Gauss-Newton on the CAD surface from the current uv).
  void set_exact(bool exact) {
    if (exact != exact_) settled_.assign(m_.points.size(), 0);
    exact_ = exact;
  }

  // SICN of a quad, -1 when it turns against the face normal (quad_sicn alone cannot see a quad
  // flipped as a whole, its normal being the average of its own corners).
  double quality(LO q) const {
    if (!quality_ok_[q]) {
      quality_[q] = compute_quality(q);
      quality_ok_[q] = 1;
    }
    return quality_[q];
  }
  double compute_quality(LO q) const {
    const auto& qd = m_.quads[q];
    const std::array<Vec3, 4> p{m_.points[qd[0]], m_.points[qd[1]], m_.points[qd[2]],
                                m_.points[qd[3]]};
    // The corner cross products give the area vector and the SICN both.
    const mesh::QuadCorners c = mesh::quad_corners(p);
    Vec3 n{};
    for (int k = 0; k < 4 && norm2(n) == 0; ++k) n = vertex_normal(qd[k]);  // skip a pole corner
    if (sign_ * dot(c.sum, n) <= 0) return -1.0;
    return mesh::quad_sicn_from(c);
  }
  // (minimum, sum) of the quality of the quads around v.
  std::pair<double, double> local_quality(LO v) const {
    double w = std::numeric_limits<double>::max(), sum = 0;
    for (LO q : t_.v2q[v]) {
      const double s = quality(q);
      w = std::min(w, s);
      sum += s;
    }
    return {w, sum};
  }

  // One Gauss-Seidel pass; returns the largest accepted displacement.
  double pass() {
    double moved = 0;
    for (LO v = 0; v < m_.num_vertices(); ++v) {
      if (!t_.free[v] || t_.ring[v].empty() || settled_[v]) continue;
      // Until a vertex of its one-ring moves, a vertex whose move was refused (or had no target)
      // would get the same target and the same refusal: everything the pass reads for it (its
      // ring's points and normals, the quality of its quads) is unchanged. It is marked settled
      // here and cleared by the moves around it.
      settled_[v] = 1;
      const Vec2 uv0 = m_.uv[v];
      const Vec3 x0 = m_.points[v];
      const Vec3 n0 = vertex_normal(v);
      const Vec3 n = n0 * sign_;
      if (norm2(n) == 0) continue;
      Vec3 target;
      if (!kernel(v, x0, n, &target)) continue;
      Vec2 uv;
      if (approx_ != nullptr && !exact_) {
        if (hint_.empty()) hint_.assign(m_.points.size(), kNoIndex);
        const auto hit = approx_->closest(target, hint_[v]);
        if (hit.triangle == kNoIndex) continue;
        hint_[v] = hit.triangle;
        uv = hit.uv;
      } else if (!to_uv(uv0, target, &uv)) {
        continue;
      }
      const auto before = local_quality(v);
      saved_.clear();
      for (LO q : t_.v2q[v]) {
        saved_.push_back(quality_[q]);
        quality_ok_[q] = 0;
      }
      m_.uv[v] = uv;
      m_.points[v] = s_.eval(uv).p;
      normal_ok_[v] = 0;
      // The minimum must not drop; on a tie (a folded quad stuck at -1) the sum decides, so that
      // a move cannot spoil the other quads for free. A quad below the old minimum refuses the
      // move at once: the quads after it need not be measured.
      double after_min = std::numeric_limits<double>::max(), after_sum = 0;
      bool keep = true;
      for (const LO q : t_.v2q[v]) {
        const double s = quality(q);
        if (s < before.first) {
          keep = false;
          break;
        }
        after_min = std::min(after_min, s);
        after_sum += s;
      }
      keep = keep && (after_min > before.first ||
                      (after_min == before.first && after_sum >= before.second));
      if (!keep) {
        m_.uv[v] = uv0;
        m_.points[v] = x0;
        normal_[v] = n0;
        normal_ok_[v] = 1;
        for (std::size_t i = 0; i < saved_.size(); ++i) {
          quality_[t_.v2q[v][i]] = saved_[i];
          quality_ok_[t_.v2q[v][i]] = 1;
        }
        continue;
      }
      settled_[v] = 0;
      for (const LO w : t_.ring[v]) settled_[w] = 0;
      moved = std::max(moved, distance(x0, m_.points[v]));
    }
    return moved;
  }

 private:
  // New position in the tangent plane at x (normal n, unit).
  bool kernel(LO v, const Vec3& x, const Vec3& n, Vec3* out) const {
    const std::span<const LO> ring = t_.ring[v];
    std::vector<Vec3>& p = ring_;
    p.resize(ring.size());
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const Vec3 d = m_.points[ring[i]] - x;
      p[i] = d - n * dot(d, n);  // relative to x, in the tangent plane
    }
    if (ring.size() == 8) {
      // Winslow (paper 000 Eq. 13), x1..x8 = p[0..7], x at the origin.
      const Vec3 a = p[0] - p[4], b = p[2] - p[6];
      const double alpha0 = dot(b, b), alpha1 = dot(a, a), beta = dot(a, b);
      const double den = 2.0 * (alpha0 + alpha1);
      if (!(den > 0)) return false;
      const Vec3 num = (p[0] + p[4]) * alpha0 + (p[2] + p[6]) * alpha1 -
                       (p[1] + p[5] - p[3] - p[7]) * (0.5 * beta);
      *out = x + num / den;
      return true;
    }
    // Angle-based kernel: each edge neighbour proposes the point on the bisector of its angle in
    // the one-ring, at the current distance; the proposals are averaged.
    const Vec3 e1 = normalized(p[0]);
    if (norm2(e1) == 0) return false;
    const Vec3 e2 = cross(n, e1);
    auto ang = [&](const Vec3& d) { return std::atan2(dot(d, e2), dot(d, e1)); };
    const std::size_t k = ring.size();
    Vec3 sum{};
    int count = 0;
    for (std::size_t i = 0; i < k; i += 2) {
      const Vec3& nj = p[i];
      const Vec3& next = p[(i + 1) % k];
      const Vec3& prev = p[(i + k - 1) % k];
      const Vec3 toward = nj * -1.0;
      const double r = norm(toward);
      if (!(r > 0) || norm2(next - nj) == 0 || norm2(prev - nj) == 0) return false;
      const double an = ang(next - nj);
      double sweep = ang(prev - nj) - an;
      while (sweep < 0) sweep += 2 * std::numbers::pi;
      while (sweep >= 2 * std::numbers::pi) sweep -= 2 * std::numbers::pi;
      const double th = an + 0.5 * sweep;
      sum += nj + (e1 * std::cos(th) + e2 * std::sin(th)) * r;
      ++count;
    }
    *out = x + sum / count;
    return true;
  }

  // uv whose S(uv) is nearest to target, from uv0, by Gauss-Newton steps on (du, dv).
  bool to_uv(const Vec2& uv0, const Vec3& target, Vec2* out) const {
    Vec2 uv = uv0;
    for (int it = 0; it < 3; ++it) {
      const auto e = s_.eval(uv);
      const Vec3 r = target - e.p;
      const double g11 = dot(e.du, e.du), g12 = dot(e.du, e.dv), g22 = dot(e.dv, e.dv);
      const double det = g11 * g22 - g12 * g12;
      if (!(det > 1e-14 * g11 * g22) || !std::isfinite(det))
        return it > 0 ? (*out = uv, true) : false;
      const double b1 = dot(e.du, r), b2 = dot(e.dv, r);
      uv += Vec2{(g22 * b1 - g12 * b2) / det, (g11 * b2 - g12 * b1) / det};
    }
    if (!std::isfinite(uv.u) || !std::isfinite(uv.v)) return false;
    *out = uv;
    return true;
  }

  const Vec3& vertex_normal(LO v) const {
    if (!normal_ok_[v]) {
      normal_[v] = s_.normal(m_.uv[v]);
      normal_ok_[v] = 1;
    }
    return normal_[v];
  }

  mesh::FaceMesh& m_;
  const cad::FaceGeometry& s_;
  const Topology& t_;
  mutable std::vector<Vec3> normal_;
  mutable std::vector<char> normal_ok_;
  mutable std::vector<double> quality_;
  mutable std::vector<char> quality_ok_;
  std::vector<double> saved_;       // qualities of the quads around the vertex being moved
  std::vector<char> settled_;       // refused since the last move in its one-ring (pass)
  mutable std::vector<Vec3> ring_;  // the kernel's one-ring in the tangent plane
  double sign_;
  const ApproxSurface* approx_;
  bool exact_ = false;
  std::vector<LO> hint_;  // last triangle of the approximate surface found for each vertex
};

// Minimum quality (with flip detection) over all quads.
double min_quality_all(const Smoother& sm, LO nquads) {
  double w = std::numeric_limits<double>::max();
  for (LO q = 0; q < nquads; ++q) w = std::min(w, sm.quality(q));
  return w;
}

// Unweighted Laplacian of u and v over the free vertices, locked ones as Dirichlet values.
bool laplacian_uv(mesh::FaceMesh& m, const Topology& t, linalg::SolverCache* cache) {
  const LO n = m.num_vertices();
  std::vector<LO> unknown(static_cast<std::size_t>(n), kNoIndex);
  LO nu = 0;
  for (LO v = 0; v < n; ++v)
    if (t.free[v] && !t.v2v[v].empty()) unknown[v] = nu++;
  if (nu == 0) return false;
  std::vector<linalg::SparseMatrix::Triplet> trip;
  std::vector<double> bu(static_cast<std::size_t>(nu), 0.0), bv(static_cast<std::size_t>(nu), 0.0);
  for (LO v = 0; v < n; ++v) {
    const LO i = unknown[v];
    if (i == kNoIndex) continue;
    trip.push_back({i, i, static_cast<double>(t.v2v[v].size())});
    for (LO w : t.v2v[v]) {
      if (unknown[w] != kNoIndex) {
        trip.push_back({i, unknown[w], -1.0});
      } else {
        bu[i] += m.uv[w].u;
        bv[i] += m.uv[w].v;
      }
    }
  }
  const linalg::SparseMatrix A(nu, trip);
  std::vector<double> xu(static_cast<std::size_t>(nu)), xv(static_cast<std::size_t>(nu));
  try {
    std::unique_ptr<linalg::LinearSolver> owner;
    // factorize throws when a component of free vertices touches no locked one
    linalg::LinearSolver& solver = linalg::factorized_eigen(A, cache, owner);
    solver.solve(bu, xu);
    solver.solve(bv, xv);
  } catch (const Error&) {
    return false;
  }
  for (LO v = 0; v < n; ++v) {
    const LO i = unknown[v];
    if (i == kNoIndex) continue;
    if (!std::isfinite(xu[i]) || !std::isfinite(xv[i])) return false;
  }
  for (LO v = 0; v < n; ++v)
    if (unknown[v] != kNoIndex) m.uv[v] = {xu[unknown[v]], xv[unknown[v]]};
  return true;
}

// The quad holding a CAD corner sharper than kCuspDeg alone (a cusp) has its minimum fixed by
// that corner, so the kernels, which only keep a move that does not lower the minimum of the
// quads around a vertex, let its inner vertex wander: ahead of the rung between the corner's two
// curve neighbours it leaves the quads behind the rung a sharp angle, behind it a flat one (the
// 5-degree corner of tests/drivers/test_thin_regions.cpp: 0.196 next to the corner's quad). The
// inner vertex goes where the other quads around it are best: on the line from the corner through
// the rung's middle, a little past the rung (a convex kite), the cusp quad kept valid and no
// worse.
constexpr double kCuspDeg = 10;

void place_cusp_apices(mesh::FaceMesh& m, const cad::FaceGeometry& surface) {
  // Most faces have no such corner: look before building the vertex-to-quad map.
  const auto sharp_at = [&](const std::array<LO, 4>& q, int k) {
    const LO c = q[k];
    if (m.vclass[c].dim != 0 || m.vclass[q[(k + 2) % 4]].dim != 2) return false;
    const Vec3 ea = m.points[q[(k + 1) % 4]] - m.points[c];
    const Vec3 eb = m.points[q[(k + 3) % 4]] - m.points[c];
    return std::atan2(norm(cross(ea, eb)), dot(ea, eb)) * 180 / std::numbers::pi < kCuspDeg;
  };
  bool any = false;
  for (const auto& q : m.quads)
    for (int k = 0; k < 4 && !any; ++k) any = sharp_at(q, k);
  if (!any) return;
  const auto v2q = detail::vertex_quads(m);
  std::vector<char> in_triangle(static_cast<std::size_t>(m.num_vertices()), 0);
  for (const auto& t : m.triangles)
    for (const LO v : t) in_triangle[v] = 1;
  const auto quad_points = [&](LO q) {
    const auto& c = m.quads[q];
    return std::array<Vec3, 4>{m.points[c[0]], m.points[c[1]], m.points[c[2]], m.points[c[3]]};
  };
  const auto oriented_sicn = [&](LO q, const Vec3& normal) {
    const auto corners = mesh::quad_corners(quad_points(q));
    return dot(corners.sum, normal) > 0 ? mesh::quad_sicn_from(corners) : -1.0;
  };
  for (LO tip = 0; tip < static_cast<LO>(m.quads.size()); ++tip)
    for (int k = 0; k < 4; ++k) {
      const auto& q = m.quads[tip];
      const LO c = q[k], a = q[(k + 1) % 4], x = q[(k + 2) % 4], b = q[(k + 3) % 4];
      if (!sharp_at(q, k) || v2q[c].size() != 1 || in_triangle[x] != 0) continue;
      const Vec2 mid = (m.uv[a] + m.uv[b]) * 0.5;
      const Vec2 axis = mid - m.uv[c];
      const double length = norm(axis), rung = norm(m.uv[a] - m.uv[b]);
      if (!(length > 0) || !(rung > 0)) continue;
      // The orientation of each quad around x, from the surface normal at x: a move never flips.
      const auto at_x = surface.eval(m.uv[x]);
      Vec3 normal = cross(at_x.du, at_x.dv);
      if (!(norm(normal) > 0)) continue;
      if (dot(mesh::quad_corners(quad_points(tip)).sum, normal) < 0) normal = normal * -1.0;
      const auto score = [&](double& tip_sicn) {
        double worst = std::numeric_limits<double>::infinity();
        for (const LO o : v2q[x]) {
          const double s = oriented_sicn(o, normal);
          if (o == tip)
            tip_sicn = s;
          else
            worst = std::min(worst, s);
        }
        return worst;
      };
      double tip_before = 0;
      double best = score(tip_before);
      const Vec2 uv0 = m.uv[x];
      const Vec3 p0 = m.points[x];
      Vec2 best_uv = uv0;
      Vec3 best_p = p0;
      for (const double f : {0.05, 0.1, 0.2, 0.35, 0.5}) {
        const Vec2 uv = mid + axis * (f * rung / length);
        m.uv[x] = uv;
        m.points[x] = surface.eval(uv).p;
        double tip_after = 0;
        const double s = score(tip_after);
        if (s > best && tip_after > 0 && tip_after >= std::min(tip_before, 0.0) &&
            (tip_before <= 0 || tip_after >= tip_before)) {
          best = s;
          best_uv = uv;
          best_p = m.points[x];
        }
      }
      m.uv[x] = best_uv;
      m.points[x] = best_p;
    }
}

}  // namespace

mesh::FaceMesh smooth_face(const mesh::FaceMesh& input, const cad::FaceGeometry& surface,
                           const SmoothOptions& options, SmoothStats* stats,
                           linalg::SolverCache* cache) {
  QSMESH_CHECK(input.uv.size() == input.points.size() && input.vclass.size() == input.points.size(),
               "face " << input.face << ": points, uv and vclass sizes differ");
  SmoothStats st;
  st.before = measure(input);
  mesh::FaceMesh m = input;
  const Stopwatch clock;
  if (!m.quads.empty()) {
    const Topology topo = build_topology(m);
    // The approximate surface is the input mesh itself, triangulated: it lies on the CAD surface
    // at its vertices and is as fine as the mesh being smoothed.
    const std::optional<ApproxSurface> approx =
        options.approximate_projection
            ? std::optional<ApproxSurface>(ApproxSurface::from_mesh(input))
            : std::nullopt;
    // The orientation reads the normal at the first corner of each quad: the smoother's cache
    // computes them once for both.
    Smoother sm(m, surface, topo, 1.0, approx ? &*approx : nullptr);
    sm.set_sign(detail::quad_orientation_with(m, [&](LO v) { return sm.normal_at(v); }));
    const LO nq = static_cast<LO>(m.quads.size());

    if (options.laplacian_uv) {
      if (const char* why = uv_discontinuity(m, surface)) {
        st.method = std::string("uv_laplacian(skipped:") + why + ")";
      } else {
        const double q0 = min_quality_all(sm, nq);
        const std::vector<Vec2> uv0 = m.uv;
        const std::vector<Vec3> p0 = m.points;
        bool kept = laplacian_uv(m, topo, cache);
        std::vector<char> moved;
        if (kept) {
          moved.assign(m.points.size(), 0);
          for (LO v = 0; v < m.num_vertices(); ++v)
            if (!(m.uv[v] == uv0[v])) {
              m.points[v] = surface.eval(m.uv[v]).p;
              moved[v] = 1;
            }
          sm.forget_moved(moved);
          kept = min_quality_all(sm, nq) >= q0;
        }
        if (!kept) {
          m.uv = uv0;
          m.points = p0;
          if (moved.empty())
            sm.forget_geometry();
          else
            sm.forget_moved(moved);
        }
        st.method = kept ? "uv_laplacian" : "uv_laplacian(rejected)";
      }
    }
    if (options.winslow && options.iterations > 0) {
      const double size = [&] {
        Box3 b;
        for (const auto& p : m.points) b.add(p);
        return b.diagonal();
      }();
      for (int it = 0; it < options.iterations; ++it) {
        if (options.time_budget_s > 0 && clock.seconds() > options.time_budget_s) break;
        // With the approximate surface, the last pass projects exactly (it is also the pass after
        // convergence).
        const bool last = it + 1 == options.iterations;
        sm.set_exact(last);
        const double moved = sm.pass();
        ++st.iterations;
        if (options.after_pass && !options.after_pass(st.iterations, m)) {
          st.stopped_early = true;
          break;
        }
        if (last) break;
        if (moved <= 1e-9 * size) {
          if (approx) {
            sm.set_exact(true);
            sm.pass();
            ++st.iterations;
          }
          break;
        }
      }
      st.method += st.method.empty() ? "kernels" : "+kernels";
    }
    place_cusp_apices(m, surface);
    detail::sync_interior_params(m);
  }
  if (st.stopped_early) {
    st.after = measure(m);
    if (stats) *stats = st;
    return m;
  }
  st.rolled_back =
      detail::keep_or_roll_back(m, input, st.before, detail::Accept::kNoDrop, st.after);
  if (stats) *stats = st;
  return m;
}

}  // namespace qsmesh::smooth
