// triangulate_face: boundary Delaunay triangulation, boundary recovery by flips, removal of the
// outside, then frontal Delaunay refinement (Rebay) measured with the surface metric, and a final
// edge-flip pass on 3D angles. Paper 000 Sec. 3.1 (background mesh) and Sec. 5.1 (insertion
// kernel).
#include "qsmesh/mesh/delaunay.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <queue>
#include <tuple>

#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/predicates.hpp"
#include "triangulation.hpp"

namespace qsmesh::mesh {
namespace {

using detail::Cavity;
using detail::Location;
using detail::LocKind;
using detail::next3;
using detail::prev3;
using detail::Tri;
using detail::Triangulation;

constexpr double kMaxEdge = 1.4142135623730951;  // refine triangles with a longer 3D edge (x size)
constexpr double kTooClose = 0.5;                // reject points closer than this (x size)
constexpr double kPi = 3.14159265358979323846;
constexpr std::uint8_t kWaiting = 0;
constexpr std::uint8_t kAccepted = 1;

// Upper-triangular factor F of the metric M = F^T F: |F x| is the first-order 3D length of x.
struct Frame {
  double f00 = 1, f01 = 0, f11 = 1;
  [[nodiscard]] Vec2 map(const Vec2& x) const { return {f00 * x.u + f01 * x.v, f11 * x.v}; }
  [[nodiscard]] Vec2 unmap(const Vec2& y) const {
    const double xv = y.v / f11;
    return {(y.u - f01 * xv) / f00, xv};
  }
};

Frame frame_of(const cad::SurfaceEval& e) {
  double a = dot(e.du, e.du), b = dot(e.du, e.dv), c = dot(e.dv, e.dv);
  // A singular parametrisation (pole) has a rank-deficient metric; regularise relative to it.
  const double eps = 1e-12 * (a + c) + 1e-300;
  a += eps;
  c += eps;
  Frame f;
  f.f00 = std::sqrt(a);
  f.f01 = b / f.f00;
  f.f11 = std::sqrt(std::max(c - f.f01 * f.f01, eps));
  return f;
}

double signed_area(const std::vector<Vec2>& poly) {
  double a = 0;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) a += cross(poly[i], poly[(i + 1) % n]);
  return 0.5 * a;
}

// Smallest angle (radians) of the 3D triangle with edge lengths l[0..2]; collapsed triangles
// (a zero edge: two vertices at a pole) count as ideal since they disappear from the output.
double min_angle(double l0, double l1, double l2) {
  const double lmax = std::max({l0, l1, l2});
  double a = l0, b = l1, c = l2;  // a: shortest
  if (b < a) std::swap(a, b);
  if (c < a) std::swap(a, c);
  if (a <= 1e-12 * lmax || lmax == 0) return kPi / 3;
  const double cs = std::clamp((b * b + c * c - a * a) / (2 * b * c), -1.0, 1.0);
  return std::acos(cs);
}

class FaceMesher {
 public:
  FaceMesher(const cad::FaceGeometry& surface, std::span<const BoundaryLoop> loops,
             const SizeFunction& size, const TriangulateOptions& options, TriangulateStats& stats)
      : surf_(surface), loops_(loops), size_(size), opt_(options), stats_(stats) {}

  FaceMesh run(bool reversed) {
    setup_boundary();
    insert_boundary();
    recover_segments();
    remove_outside();
    insert_given();
    if (opt_.refine) refine();
    optimize();
    return output(reversed);
  }

 private:
  struct Segment {
    LO a, b;
    bool degenerate;
  };

  const cad::FaceGeometry& surf_;
  std::span<const BoundaryLoop> loops_;
  const SizeFunction& size_;
  const TriangulateOptions& opt_;
  TriangulateStats& stats_;

  Triangulation tr_;
  std::vector<Vec3> xyz_;   // per internal vertex
  std::vector<double> h_;   // target size per internal vertex
  std::vector<LO> out_;     // output index of boundary internal vertices (kNoIndex: interior)
  std::vector<LO> in2v_;    // input point (flattened) -> internal vertex
  std::vector<LO> in_out_;  // input point (flattened) -> output index
  std::vector<Segment> segs_;
  std::vector<double> loop_area_;
  LO num_out_boundary_ = 0;
  LO first_real_ = 3;  // internal vertices 0..2 are the super triangle
  double cos_min_angle_ = 0;
  Cavity cav_;
  std::vector<LO> created_;

  // ---------------------------------------------------------------- boundary
  void setup_boundary() {
    QSMESH_CHECK(!loops_.empty(), "triangulate_face: no boundary loop");
    LO flat = 0;
    for (std::size_t l = 0; l < loops_.size(); ++l) {
      const BoundaryLoop& L = loops_[l];
      QSMESH_CHECK(L.points.size() >= 2, "triangulate_face: loop " << l << " has "
                                                                   << L.points.size()
                                                                   << " points (need >= 2)");
      QSMESH_CHECK(L.degenerate.empty() || L.degenerate.size() == L.points.size(),
                   "triangulate_face: loop " << l << " degenerate flags size mismatch");
      std::vector<Vec2> poly;
      for (const BoundaryPoint& p : L.points) {
        QSMESH_CHECK(std::isfinite(p.uv.u) && std::isfinite(p.uv.v),
                     "triangulate_face: loop " << l << " has a non-finite (u, v)");
        poly.push_back(p.uv);
      }
      loop_area_.push_back(signed_area(poly));
      flat += static_cast<LO>(L.points.size());
    }
    in2v_.assign(flat, kNoIndex);
    in_out_.assign(flat, kNoIndex);
    // Merge targets: each chain of degenerate segments collapses onto its first point.
    std::vector<LO> target(flat);
    LO base = 0;
    for (const BoundaryLoop& L : loops_) {
      const LO n = static_cast<LO>(L.points.size());
      auto deg = [&](LO i) { return !L.degenerate.empty() && L.degenerate[(i % n + n) % n] != 0; };
      LO s = -1;
      for (LO i = 0; i < n && s < 0; ++i)
        if (!deg(i - 1)) s = i;
      QSMESH_CHECK(s >= 0, "triangulate_face: a loop made only of degenerate segments");
      for (LO k = 0; k < n; ++k) {
        const LO i = (s + k) % n;
        target[base + i] = (k > 0 && deg(i - 1)) ? target[base + (i - 1 + n) % n] : base + i;
      }
      base += n;
    }
    for (LO i = 0; i < flat; ++i)
      if (target[i] == i) in_out_[i] = num_out_boundary_++;
    for (LO i = 0; i < flat; ++i) in_out_[i] = in_out_[target[i]];
    target_ = std::move(target);
  }
  std::vector<LO> target_;

  [[nodiscard]] const BoundaryPoint& input_point(LO flat) const {
    for (const BoundaryLoop& L : loops_) {
      if (flat < static_cast<LO>(L.points.size())) return L.points[flat];
      flat -= static_cast<LO>(L.points.size());
    }
    QSMESH_CHECK(false, "bad boundary index");
    std::abort();
  }

  // Inserts a boundary point by isotropic Delaunay (exact predicates). Returns the internal
  // vertex, or an existing one with the same (u, v) (only allowed inside a degenerate chain).
  LO insert_boundary_point(const Vec2& uv, const Vec3& xyz, LO out, LO& hint) {
    const Location loc = tr_.locate(uv, hint, false);
    QSMESH_CHECK(loc.kind != LocKind::kFailed && loc.kind != LocKind::kBlocked,
                 "triangulate_face: point location failed for boundary point (" << uv.u << ", "
                                                                                << uv.v << ")");
    if (loc.kind == LocKind::kOnVertex) {
      const LO w = tr_.tris[loc.tri].v[loc.index];
      QSMESH_CHECK(w >= first_real_ && out_[w] == out,
                   "triangulate_face: two boundary points share (u, v) = ("
                       << uv.u << ", " << uv.v << ") outside a degenerate segment");
      return w;
    }
    auto crit = [&](LO t) {
      const Tri& T = tr_.tris[t];
      return incircle(tr_.pts[T.v[0]], tr_.pts[T.v[1]], tr_.pts[T.v[2]], uv) > 0;
    };
    QSMESH_CHECK(
        tr_.build_cavity(uv, loc, crit, cav_),
        "triangulate_face: invalid cavity for boundary point (" << uv.u << ", " << uv.v << ")");
    const LO v = tr_.add_vertex(uv);
    xyz_.push_back(xyz);
    h_.push_back(size_(uv, xyz));
    out_.push_back(out);
    created_.clear();
    tr_.fill_cavity(v, cav_, &created_);
    hint = created_.front();
    return v;
  }

  // Number of pieces for a degenerate segment: the ring at distance size from the pole should
  // be cut into edges of about that size, so the fan of triangles around the pole is regular.
  int degenerate_pieces(const Vec2& a, const Vec2& b, const Vec3& pole, double h, bool left) {
    const Vec2 d = b - a;
    const double len = norm(d);
    Vec2 n{-d.v / len, d.u / len};
    if (!left) n = n * -1.0;
    const Vec2 m = (a + b) * 0.5;
    const cad::SurfaceEval e = surf_.eval(m);
    const double speed = norm(e.du * n.u + e.dv * n.v);
    double t = speed > 0 ? h / speed : 0.1 * len;
    for (int it = 0; it < 3; ++it) {
      const double dist = distance(surf_.eval(m + n * t).p, pole);
      if (!(dist > 0)) break;
      t *= h / dist;
    }
    constexpr int kSamples = 64;
    double ring = 0;
    Vec3 prev = surf_.eval(a + n * t).p;
    for (int k = 1; k <= kSamples; ++k) {
      const Vec3 cur = surf_.eval(a + d * (static_cast<double>(k) / kSamples) + n * t).p;
      ring += distance(prev, cur);
      prev = cur;
    }
    if (!std::isfinite(ring)) return 1;
    return std::clamp(static_cast<int>(std::lround(ring / h)), 1, 4096);
  }

  void insert_boundary() {
    Box2 box;
    for (const BoundaryLoop& L : loops_)
      for (const BoundaryPoint& p : L.points) box.add(p.uv);
    const Vec2 c = (box.lo + box.hi) * 0.5;
    const double r = std::max({box.hi.u - box.lo.u, box.hi.v - box.lo.v, 1e-30}) * 50.0;
    for (int k = 0; k < 3; ++k) {
      const double ang = kPi / 2 + 2 * kPi * k / 3;
      tr_.add_vertex({c.u + r * std::cos(ang), c.v + r * std::sin(ang)});
      xyz_.push_back({});
      h_.push_back(1);
      out_.push_back(kNoIndex);
    }
    LO hint = tr_.new_tri(0, 1, 2);
    for (LO k = 0; k < 3; ++k) tr_.v2t[k] = hint;

    LO flat = 0;
    for (std::size_t l = 0; l < loops_.size(); ++l) {
      const BoundaryLoop& L = loops_[l];
      const LO n = static_cast<LO>(L.points.size());
      const bool left = (l == 0) == (loop_area_[l] > 0);  // domain on the left of the loop
      std::vector<LO> ring;  // internal vertices of the loop in order, extras included
      std::vector<std::uint8_t> ring_deg;
      for (LO i = 0; i < n; ++i) {
        const BoundaryPoint& p = L.points[i];
        const LO v = insert_boundary_point(p.uv, p.xyz, in_out_[flat + i], hint);
        in2v_[flat + i] = v;
        ring.push_back(v);
        const bool deg = !L.degenerate.empty() && L.degenerate[i] != 0;
        ring_deg.push_back(deg ? 1 : 0);
        if (deg) {
          const BoundaryPoint& q = L.points[(i + 1) % n];
          if (p.uv == q.uv) continue;
          const int pieces = degenerate_pieces(p.uv, q.uv, p.xyz, h_[v], left);
          for (int k = 1; k < pieces; ++k) {
            const double s = static_cast<double>(k) / pieces;
            const Vec2 uv = p.uv * (1 - s) + q.uv * s;
            ring.push_back(insert_boundary_point(uv, p.xyz, in_out_[flat + i], hint));
            ring_deg.push_back(1);
          }
        }
      }
      for (std::size_t k = 0; k < ring.size(); ++k) {
        const LO a = ring[k], b = ring[(k + 1) % ring.size()];
        if (a != b) segs_.push_back({a, b, ring_deg[k] != 0});
      }
      flat += n;
    }
  }

  // ---------------------------------------------------------------- recovery
  [[noreturn]] void fail_on_segment(LO a, LO b, const char* why) const {
    QSMESH_CHECK(false, "triangulate_face: cannot recover boundary segment ("
                            << tr_.pts[a].u << ", " << tr_.pts[a].v << ") - (" << tr_.pts[b].u
                            << ", " << tr_.pts[b].v << "): " << why);
    std::abort();
  }

  void lock_edge(LO a, LO b) {
    auto [t, i] = tr_.find_edge(a, b);
    if (t == kNoIndex) std::tie(t, i) = tr_.find_edge(b, a);
    if (t == kNoIndex) fail_on_segment(a, b, "edge missing after flips");
    tr_.tris[t].locked |= static_cast<std::uint8_t>(1U << i);
    const LO u = tr_.tris[t].n[i];
    if (u != kNoIndex) tr_.tris[u].locked |= static_cast<std::uint8_t>(1U << tr_.edge_to(u, t));
  }

  void recover_segment(LO a, LO b) {
    if (tr_.find_edge(a, b).first != kNoIndex || tr_.find_edge(b, a).first != kNoIndex) {
      lock_edge(a, b);
      return;
    }
    const Vec2 A = tr_.pts[a], B = tr_.pts[b];
    auto on_segment = [&](LO w) {
      return dot(tr_.pts[w] - A, B - A) > 0 && dot(tr_.pts[w] - B, A - B) > 0;
    };
    // Find the first crossed edge around a.
    std::vector<LO> star;
    tr_.star(a, star);
    LO cur = kNoIndex;
    int e = -1;
    LO right = kNoIndex, left = kNoIndex;
    for (LO t : star) {
      const int k = tr_.slot_of(t, a);
      const LO p = tr_.tris[t].v[next3(k)], q = tr_.tris[t].v[prev3(k)];
      const double op = orient2d(A, B, tr_.pts[p]), oq = orient2d(A, B, tr_.pts[q]);
      if ((op == 0 && on_segment(p)) || (oq == 0 && on_segment(q)))
        fail_on_segment(a, b, "another boundary point lies on it (touching or overlapping loops)");
      if (op < 0 && oq > 0) {
        cur = t;
        e = k;
        right = p;
        left = q;
        break;
      }
    }
    if (cur == kNoIndex) fail_on_segment(a, b, "no triangle around its start crosses it");
    std::deque<std::pair<LO, LO>> queue;
    for (;;) {
      if (tr_.tris[cur].is_locked(e))
        fail_on_segment(a, b, "it crosses another boundary segment (self-intersecting loops)");
      queue.emplace_back(right, left);
      const LO nxt = tr_.tris[cur].n[e];
      if (nxt == kNoIndex) fail_on_segment(a, b, "walk left the triangulation");
      const int j = tr_.edge_to(nxt, cur);
      const LO w = tr_.tris[nxt].v[j];
      if (w == b) break;
      const double ow = orient2d(A, B, tr_.pts[w]);
      if (ow == 0) fail_on_segment(a, b, "another boundary point lies on it");
      if (ow < 0) {
        e = tr_.slot_of(nxt, right);
        right = w;
      } else {
        e = tr_.slot_of(nxt, left);
        left = w;
      }
      cur = nxt;
    }
    auto sgn = [](double x) { return (x > 0) - (x < 0); };
    const std::size_t cap = 100 * queue.size() * queue.size() + 1000;
    std::size_t iter = 0;
    while (!queue.empty()) {
      if (++iter > cap) fail_on_segment(a, b, "flip iteration limit reached");
      const auto [x, y] = queue.front();
      queue.pop_front();
      auto [t, i] = tr_.find_edge(x, y);
      if (t == kNoIndex) std::tie(t, i) = tr_.find_edge(y, x);
      if (t == kNoIndex) continue;  // already gone
      const LO u = tr_.tris[t].n[i];
      const LO p = tr_.tris[t].v[i];
      const LO d = u == kNoIndex ? kNoIndex : tr_.tris[u].v[tr_.edge_to(u, t)];
      if (!tr_.flip(t, i)) {
        queue.emplace_back(x, y);
        continue;
      }
      ++stats_.boundary_flips;
      if (p == a || p == b || d == a || d == b) continue;
      const Vec2 P = tr_.pts[p], D = tr_.pts[d];
      if (sgn(orient2d(A, B, P)) * sgn(orient2d(A, B, D)) < 0 &&
          sgn(orient2d(P, D, A)) * sgn(orient2d(P, D, B)) < 0)
        queue.emplace_back(p, d);
    }
    lock_edge(a, b);
  }

  void recover_segments() {
    for (const Segment& s : segs_) recover_segment(s.a, s.b);
  }

  void remove_outside() {
    const std::size_t nt = tr_.tris.size();
    std::vector<int> level(nt, -1);
    std::deque<LO> dq;
    const LO start = tr_.v2t[0];
    level[start] = 0;
    dq.push_back(start);
    while (!dq.empty()) {  // 0-1 BFS: crossing a locked edge costs one level
      const LO t = dq.front();
      dq.pop_front();
      const Tri& T = tr_.tris[t];
      for (int i = 0; i < 3; ++i) {
        const LO u = T.n[i];
        if (u == kNoIndex) continue;
        const int lv = level[t] + (T.is_locked(i) ? 1 : 0);
        if (level[u] < 0 || lv < level[u]) {
          level[u] = lv;
          if (T.is_locked(i))
            dq.push_back(u);
          else
            dq.push_front(u);
        }
      }
    }
    double area = 0;
    for (LO t = 0; t < static_cast<LO>(nt); ++t) {
      Tri& T = tr_.tris[t];
      if (!T.alive) continue;
      QSMESH_CHECK(level[t] >= 0, "triangulate_face: disconnected triangulation");
      if (level[t] % 2 == 0) {
        for (int i = 0; i < 3; ++i) {
          const LO u = T.n[i];
          if (u != kNoIndex && level[u] % 2 == 1) tr_.tris[u].n[tr_.edge_to(u, t)] = kNoIndex;
        }
        tr_.kill_tri(t);
      } else {
        QSMESH_CHECK(T.v[0] >= first_real_ && T.v[1] >= first_real_ && T.v[2] >= first_real_,
                     "triangulate_face: inconsistent loops (domain reaches the bounding triangle)");
        area += 0.5 * orient2d(tr_.pts[T.v[0]], tr_.pts[T.v[1]], tr_.pts[T.v[2]]);
      }
    }
    double expected = std::fabs(loop_area_[0]);
    for (std::size_t l = 1; l < loop_area_.size(); ++l) expected -= std::fabs(loop_area_[l]);
    QSMESH_CHECK(
        expected > 0 && std::fabs(area - expected) <= 1e-9 * std::fabs(loop_area_[0]) + 1e-300,
        "triangulate_face: inconsistent loops (holes outside the outer loop or "
        "overlapping): triangulated area "
            << area << " vs expected " << expected);
    for (LO& t : tr_.v2t) t = kNoIndex;
    for (LO t = 0; t < static_cast<LO>(nt); ++t)
      if (tr_.tris[t].alive)
        for (LO v : tr_.tris[t].v) tr_.v2t[v] = t;
  }

  // ---------------------------------------------------------------- given points
  // The caller's points (Sec. 5.1 frontal points) in their order. The walk from the last
  // insertion is blocked by the locked boundary when the domain is not convex between two
  // consecutive points; it then restarts from the vertex nearest in (u, v), whose star sees it.
  void insert_given() {
    if (opt_.interior_points.empty()) return;
    LO hint = kNoIndex;
    for (LO t = 0; t < static_cast<LO>(tr_.tris.size()) && hint == kNoIndex; ++t)
      if (tr_.tris[t].alive) hint = t;
    if (hint == kNoIndex) return;
    for (const Vec2& x : opt_.interior_points) {
      if (stats_.inserted >= opt_.max_points) break;
      if (!std::isfinite(x.u) || !std::isfinite(x.v)) {
        ++stats_.rejected;
        continue;
      }
      Location loc = tr_.locate(x, hint, true);
      if (loc.kind == LocKind::kBlocked || loc.kind == LocKind::kFailed) {
        LO nearest = kNoIndex;
        double best = 1e300;
        for (LO v = first_real_; v < static_cast<LO>(tr_.pts.size()); ++v) {
          if (tr_.v2t[v] == kNoIndex || !tr_.tris[tr_.v2t[v]].alive) continue;
          const double d = norm(tr_.pts[v] - x);
          if (d < best) {
            best = d;
            nearest = v;
          }
        }
        if (nearest != kNoIndex) loc = tr_.locate(x, tr_.v2t[nearest], true);
      }
      const cad::SurfaceEval ex = surf_.eval(x);
      const double hx = size_(x, ex.p);
      const LO v = try_insert_at(loc, x, ex, hx, hx);
      if (v == kNoIndex) {
        ++stats_.rejected;
        continue;
      }
      ++stats_.inserted;
      hint = created_.front();
    }
  }

  // ---------------------------------------------------------------- refinement
  struct TriGeom {
    std::array<double, 3> l;  // 3D length of edge i (opposite v[i])
    double h;                 // mean target size
  };
  [[nodiscard]] TriGeom geom(LO t) const {
    const Tri& T = tr_.tris[t];
    TriGeom g;
    for (int i = 0; i < 3; ++i) g.l[i] = distance(xyz_[T.v[next3(i)]], xyz_[T.v[prev3(i)]]);
    g.h = (h_[T.v[0]] + h_[T.v[1]] + h_[T.v[2]]) / 3;
    return g;
  }
  [[nodiscard]] bool is_bad(LO t) const {
    const TriGeom g = geom(t);
    const double lmax = std::max({g.l[0], g.l[1], g.l[2]});
    if (lmax > kMaxEdge * g.h) return true;
    return min_angle(g.l[0], g.l[1], g.l[2]) < opt_.min_angle_deg * kPi / 180;
  }
  [[nodiscard]] bool is_front(LO t, int i) const {
    const Tri& T = tr_.tris[t];
    return T.n[i] == kNoIndex || T.is_locked(i) || tr_.tris[T.n[i]].state == kAccepted;
  }
  [[nodiscard]] bool is_active(LO t) const {
    const Tri& T = tr_.tris[t];
    if (!T.alive || T.state != kWaiting) return false;
    return is_front(t, 0) || is_front(t, 1) || is_front(t, 2);
  }

  using Entry = std::tuple<double, LO, std::uint32_t>;
  std::priority_queue<Entry> pq_;
  void push_if_active(LO t) {
    if (t == kNoIndex || !is_active(t)) return;
    const TriGeom g = geom(t);
    pq_.emplace(std::max({g.l[0], g.l[1], g.l[2]}) / g.h, t, tr_.tris[t].stamp);
  }

  // Candidate point for the front edge i of t (Rebay: on the metric perpendicular bisector of the
  // edge, at the distance giving an equilateral triangle of the target size, but never beyond the
  // circumcentre of t). Returns the spacing it aimed at.
  double frontal_point(LO t, int i, Vec2& x, cad::SurfaceEval& ex) const {
    const Tri& T = tr_.tris[t];
    const LO a = T.v[next3(i)], b = T.v[prev3(i)], c = T.v[i];
    const Vec2 ua = tr_.pts[a], ub = tr_.pts[b], uc = tr_.pts[c];
    const double L = distance(xyz_[a], xyz_[b]);
    const double h = 0.5 * (h_[a] + h_[b]);
    const Vec2 m = (ua + ub) * 0.5;
    const cad::SurfaceEval em = surf_.eval(m);
    Vec2 off;
    double target;   // wanted 3D distance between the point and `from`
    double spacing;  // local spacing aimed at (the too-close test is relative to it)
    Vec3 from;
    if (L <= 1e-9 * h) {
      // Degenerate (pole) edge: go straight into the domain until the point is h from the pole.
      const Vec2 d = ub - ua;
      const Vec2 n = Vec2{-d.v, d.u} / norm(d);
      const double speed = norm(em.du * n.u + em.dv * n.v);
      const double dist_uv = norm(uc - m);
      off = n * (speed > 0 ? h / speed : 0.5 * dist_uv);
      target = h;
      spacing = h;
      from = xyz_[a];
    } else {
      const Frame f = frame_of(em);
      const Vec2 e = f.map(ub - ua);
      const double lm = norm(e);
      const double p = 0.5 * lm;
      const Vec2 n{-e.v / lm, e.u / lm};
      const Vec2 cc = f.map(uc - m);
      const double nc = dot(n, cc);
      const double q = nc > 0 ? (dot(cc, cc) - p * p) / (2 * nc) : 0;  // circumcentre offset
      const double hn = std::min(h, 1.5 * lm);  // grade from short front edges
      double rho = std::max(hn / std::sqrt(3.0), p);
      if (q > 0) rho = std::min(rho, (p * p + q * q) / (2 * q));
      double d = rho + std::sqrt(std::max(0.0, rho * rho - p * p));
      if (q <= 0) d = std::min(d, 0.99 * (std::sqrt(p * p + q * q) + q));
      off = f.unmap(n * d);
      target = d;
      spacing = hn;
      from = (xyz_[a] + xyz_[b]) * 0.5;
    }
    x = m + off;
    ex = surf_.eval(x);
    for (int it = 0; it < 2; ++it) {  // correct the first-order metric distance on curved surfaces
      const double dist = distance(ex.p, from);
      if (!(dist > 0) || std::fabs(dist / target - 1) < 0.03) break;
      off = off * (target / dist);
      x = m + off;
      ex = surf_.eval(x);
    }
    return spacing;
  }

  // Tries to insert x (evaluated as ex) with a metric Delaunay cavity; spacing is the local
  // target used for the too-close test. Returns the new vertex or kNoIndex.
  LO try_insert(const Vec2& x, const cad::SurfaceEval& ex, double hx, double spacing, LO hint) {
    return try_insert_at(tr_.locate(x, hint, true), x, ex, hx, spacing);
  }
  LO try_insert_at(const Location& loc, const Vec2& x, const cad::SurfaceEval& ex, double hx,
                   double spacing) {
    if (loc.kind != LocKind::kInside && loc.kind != LocKind::kOnEdge) return kNoIndex;
    const Frame f = frame_of(ex);
    const Vec2 origin{0, 0};
    auto crit = [&](LO t) {
      const Tri& T = tr_.tris[t];
      return incircle(f.map(tr_.pts[T.v[0]] - x), f.map(tr_.pts[T.v[1]] - x),
                      f.map(tr_.pts[T.v[2]] - x), origin) > 0;
    };
    if (!tr_.build_cavity(x, loc, crit, cav_)) return kNoIndex;
    const double too_close = kTooClose * std::min(hx, spacing);
    for (const Cavity::Edge& e : cav_.boundary) {
      if (distance(xyz_[e.a], ex.p) < too_close) return kNoIndex;
      // A point hugging a locked edge would leave a sliver against the boundary.
      if (e.locked) {
        const Vec3 ab = xyz_[e.b] - xyz_[e.a];
        const double l2 = norm2(ab);
        const double s = l2 > 0 ? std::clamp(dot(ex.p - xyz_[e.a], ab) / l2, 0.0, 1.0) : 0.0;
        if (distance(ex.p, xyz_[e.a] + ab * s) < 0.6 * too_close) return kNoIndex;
      }
    }
    const LO v = tr_.add_vertex(x);
    xyz_.push_back(ex.p);
    h_.push_back(hx);
    out_.push_back(kNoIndex);
    created_.clear();
    tr_.fill_cavity(v, cav_, &created_);
    return v;
  }

  void after_insert() {
    for (LO t : created_) tr_.tris[t].state = is_bad(t) ? kWaiting : kAccepted;
    for (LO t : created_) {
      push_if_active(t);
      push_if_active(tr_.tris[t].n[0]);
    }
  }

  void refine() {
    for (LO t = 0; t < static_cast<LO>(tr_.tris.size()); ++t)
      if (tr_.tris[t].alive) tr_.tris[t].state = is_bad(t) ? kWaiting : kAccepted;
    for (LO t = 0; t < static_cast<LO>(tr_.tris.size()); ++t) push_if_active(t);
    while (!pq_.empty() && stats_.inserted < opt_.max_points) {
      const auto [key, t, stamp] = pq_.top();
      pq_.pop();
      if (!tr_.tris[t].alive || tr_.tris[t].stamp != stamp || !is_active(t)) continue;
      // Best front edge: the one whose 3D length is closest to the target.
      const TriGeom g = geom(t);
      int best = -1;
      double best_score = 1e300;
      for (int i = 0; i < 3; ++i) {
        if (!is_front(t, i)) continue;
        const double s = std::fabs(g.l[i] / g.h - 1);
        if (s < best_score) {
          best_score = s;
          best = i;
        }
      }
      Vec2 x;
      cad::SurfaceEval ex;
      const double spacing = frontal_point(t, best, x, ex);
      LO v = kNoIndex;
      if (std::isfinite(x.u) && std::isfinite(x.v)) {
        const double hx = size_(x, ex.p);
        v = try_insert(x, ex, hx, spacing, t);
      }
      if (v == kNoIndex) {
        ++stats_.rejected;
        tr_.tris[t].state = kAccepted;
        for (int i = 0; i < 3; ++i) push_if_active(tr_.tris[t].n[i]);
        continue;
      }
      ++stats_.inserted;
      if (tr_.tris[t].alive && tr_.tris[t].stamp == stamp) {  // t was not in the cavity
        tr_.tris[t].state = kAccepted;
        for (int i = 0; i < 3; ++i) push_if_active(tr_.tris[t].n[i]);
      }
      after_insert();
    }
    pq_ = {};
    cleanup_large();
  }

  // Triangles the front left too large (rejections where fronts met): insert at their metric
  // circumcentre, a few rounds.
  void cleanup_large() {
    for (int round = 0; round < 4 && stats_.inserted < opt_.max_points; ++round) {
      std::vector<LO> big;
      for (LO t = 0; t < static_cast<LO>(tr_.tris.size()); ++t) {
        if (!tr_.tris[t].alive) continue;
        const TriGeom g = geom(t);
        if (std::max({g.l[0], g.l[1], g.l[2]}) > 1.6 * g.h) big.push_back(t);
      }
      std::vector<std::uint32_t> stamps;
      for (LO t : big) stamps.push_back(tr_.tris[t].stamp);
      std::int64_t done = 0;
      for (std::size_t k = 0; k < big.size() && stats_.inserted < opt_.max_points; ++k) {
        const LO t = big[k];
        if (!tr_.tris[t].alive || tr_.tris[t].stamp != stamps[k]) continue;
        const Tri& T = tr_.tris[t];
        const Vec2 c = (tr_.pts[T.v[0]] + tr_.pts[T.v[1]] + tr_.pts[T.v[2]]) / 3.0;
        const Frame f = frame_of(surf_.eval(c));
        const Vec2 A = f.map(tr_.pts[T.v[0]] - c), B = f.map(tr_.pts[T.v[1]] - c),
                   C = f.map(tr_.pts[T.v[2]] - c);
        const Vec2 ab = B - A, ac = C - A;
        const double den = 2 * cross(ab, ac);
        if (!(den > 0)) continue;
        const Vec2 cc{(ac.v * dot(ab, ab) - ab.v * dot(ac, ac)) / den,
                      (ab.u * dot(ac, ac) - ac.u * dot(ab, ab)) / den};
        Vec2 x = c + f.unmap(A + cc);
        cad::SurfaceEval ex = surf_.eval(x);
        double hx = size_(x, ex.p);
        LO v = try_insert(x, ex, hx, hx, t);
        if (v == kNoIndex) {  // circumcentre outside or crowded: try the centroid
          x = c;
          ex = surf_.eval(x);
          hx = size_(x, ex.p);
          v = try_insert(x, ex, hx, hx, t);
        }
        if (v == kNoIndex) {
          ++stats_.rejected;
          continue;
        }
        ++stats_.inserted;
        ++done;
      }
      if (done == 0) break;
    }
  }

  // ---------------------------------------------------------------- optimisation
  double tri_min_angle(LO a, LO b, LO c) const {
    return min_angle(distance(xyz_[b], xyz_[c]), distance(xyz_[c], xyz_[a]),
                     distance(xyz_[a], xyz_[b]));
  }

  void optimize() {
    if (opt_.shorten_ratio > 0) flip_shorter(opt_.shorten_ratio);
    flip_for_angles();
    // Vertices the front placed badly (where fronts met, next to much finer boundary edges)
    // leave thin triangles that no flip removes; moving them helps, and new flips may follow.
    for (int round = 0; round < 3; ++round) {
      if (smooth_bad_vertices() == 0) break;
      flip_for_angles();
    }
  }

  /// Moves each interior vertex whose star has an angle below 25 degrees to the uv centroid of its
  /// neighbours (or halfway there) when every star triangle stays counterclockwise in uv (exact
  /// test) and the star's smallest 3D angle grows. Returns the number of vertices moved.
  std::int64_t smooth_bad_vertices() {
    constexpr double kBad = 25.0 * kPi / 180.0;
    constexpr double kGain = 1e-3;  // radians
    std::int64_t moved = 0;
    std::vector<LO> star;
    const LO nv = static_cast<LO>(tr_.pts.size());
    for (LO v = first_real_; v < nv; ++v) {
      if (out_[v] != kNoIndex || tr_.v2t[v] == kNoIndex) continue;  // boundary or removed
      tr_.star(v, star);
      if (star.size() < 3) continue;
      auto star_min = [&]() {
        double m = kPi;
        for (LO t : star) {
          const Tri& T = tr_.tris[t];
          m = std::min(m, tri_min_angle(T.v[0], T.v[1], T.v[2]));
        }
        return m;
      };
      const double before = star_min();
      if (before >= kBad) continue;
      Vec2 centroid{0, 0};
      int count = 0;
      bool closed = true;
      for (LO t : star) {
        const Tri& T = tr_.tris[t];
        for (int k = 0; k < 3; ++k) {
          if (T.v[k] == v) continue;
          if (T.v[k] < first_real_) closed = false;
          centroid += tr_.pts[T.v[k]];
          ++count;
        }
      }
      if (!closed || count == 0) continue;
      centroid = centroid / count;
      const Vec2 old_uv = tr_.pts[v];
      const Vec3 old_xyz = xyz_[v];
      bool accepted = false;
      for (const double w : {1.0, 0.5}) {
        const Vec2 x = old_uv + (centroid - old_uv) * w;
        bool valid = true;
        for (LO t : star) {
          const Tri& T = tr_.tris[t];
          std::array<Vec2, 3> q{tr_.pts[T.v[0]], tr_.pts[T.v[1]], tr_.pts[T.v[2]]};
          for (int k = 0; k < 3; ++k)
            if (T.v[k] == v) q[k] = x;
          if (orient2d(q[0], q[1], q[2]) <= 0) {
            valid = false;
            break;
          }
        }
        if (!valid) continue;
        tr_.pts[v] = x;
        xyz_[v] = surf_.eval(x).p;
        if (star_min() > before + kGain) {
          accepted = true;
          break;
        }
        tr_.pts[v] = old_uv;
        xyz_[v] = old_xyz;
      }
      moved += accepted ? 1 : 0;
    }
    return moved;
  }

  /// Sweeps over the interior edges (at most max_sweeps, until one flips nothing), flipping each
  /// edge (b, c) between triangles (a, b, c) and (d, c, b) for which flip(a, b, c, d) holds and
  /// the flip is valid in (u, v).
  template <class Rule>
  void flip_sweeps(int max_sweeps, const Rule& flip) {
    for (int sweep = 0; sweep < max_sweeps; ++sweep) {
      std::int64_t flips = 0;
      for (LO t = 0; t < static_cast<LO>(tr_.tris.size()); ++t) {
        for (int i = 0; i < 3; ++i) {
          const Tri& T = tr_.tris[t];
          if (!T.alive) break;
          const LO u = T.n[i];
          if (u == kNoIndex || T.is_locked(i)) continue;
          const LO a = T.v[i], b = T.v[next3(i)], c = T.v[prev3(i)];
          const LO d = tr_.tris[u].v[tr_.edge_to(u, t)];
          if (flip(a, b, c, d) && tr_.flip(t, i)) ++flips;
        }
      }
      if (flips == 0) break;
    }
  }

  /// The smaller 3D angle of the two triangles on each side of edge (b, c): as they are, and
  /// after the flip to (a, d).
  std::pair<double, double> angles_before_after(LO a, LO b, LO c, LO d) const {
    return {std::min(tri_min_angle(a, b, c), tri_min_angle(d, c, b)),
            std::min(tri_min_angle(a, b, d), tri_min_angle(d, c, a))};
  }

  /// TriangulateOptions::shorten_ratio.
  void flip_shorter(double ratio) {
    flip_sweeps(100, [&](LO a, LO b, LO c, LO d) {
      if (std::min({a, b, c, d}) < first_real_) return false;
      const double length = distance(xyz_[b], xyz_[c]);
      if (length <= 2 * std::min(h_[b], h_[c]) || distance(xyz_[a], xyz_[d]) >= ratio * length)
        return false;
      const auto [before, after] = angles_before_after(a, b, c, d);
      return after >= before;
    });
  }

  void flip_for_angles() {
    constexpr double kGain = 1e-3;  // radians
    flip_sweeps(6, [&](LO a, LO b, LO c, LO d) {
      const auto [before, after] = angles_before_after(a, b, c, d);
      return after > before + kGain;
    });
  }

  // ---------------------------------------------------------------- output
  FaceMesh output(bool reversed) {
    FaceMesh fm;
    const LO nv = static_cast<LO>(tr_.pts.size());
    std::vector<LO> map(nv, kNoIndex);
    fm.points.resize(num_out_boundary_);
    fm.uv.resize(num_out_boundary_);
    fm.vclass.resize(num_out_boundary_);
    for (LO i = 0; i < static_cast<LO>(in_out_.size()); ++i) {
      if (target_[i] != i) continue;
      const BoundaryPoint& p = input_point(i);
      fm.points[in_out_[i]] = p.xyz;
      fm.uv[in_out_[i]] = p.uv;
      fm.vclass[in_out_[i]] = p.vclass;
    }
    for (LO v = first_real_; v < nv; ++v) {
      if (out_[v] != kNoIndex) {
        map[v] = out_[v];
        continue;
      }
      map[v] = static_cast<LO>(fm.points.size());
      fm.points.push_back(xyz_[v]);
      fm.uv.push_back(tr_.pts[v]);
      VertexClass vc;
      vc.dim = 2;
      vc.param = {tr_.pts[v].u, tr_.pts[v].v};
      fm.vclass.push_back(vc);
    }
    for (const Tri& T : tr_.tris) {
      if (!T.alive) continue;
      const LO a = map[T.v[0]], b = map[T.v[1]], c = map[T.v[2]];
      if (a == b || b == c || c == a) continue;  // collapsed at a pole
      fm.triangles.push_back(reversed ? std::array<LO, 3>{a, c, b} : std::array<LO, 3>{a, b, c});
    }
    return fm;
  }
};

}  // namespace

FaceMesh triangulate_face(const cad::FaceGeometry& surface, bool face_reversed,
                          std::span<const BoundaryLoop> loops, const SizeFunction& size,
                          const TriangulateOptions& options, TriangulateStats* stats) {
  TriangulateStats local;
  FaceMesher mesher(surface, loops, size, options, stats ? *stats : local);
  return mesher.run(face_reversed);
}

namespace {

// The face's surface seen through the parameters (u su, v sv): S'(u', v') = S(u' / su, v' / sv).
class ScaledSurface final : public cad::FaceGeometry {
 public:
  ScaledSurface(const cad::FaceGeometry& s, Vec2 scale) : s_(s), su_(scale.u), sv_(scale.v) {}
  [[nodiscard]] Vec2 to_original(const Vec2& x) const { return {x.u / su_, x.v / sv_}; }
  [[nodiscard]] Vec2 to_scaled(const Vec2& x) const { return {x.u * su_, x.v * sv_}; }
  [[nodiscard]] cad::SurfaceEval eval(const Vec2& uv) const override {
    cad::SurfaceEval e = s_.eval(to_original(uv));
    e.du = e.du * (1 / su_);
    e.dv = e.dv * (1 / sv_);
    return e;
  }
  [[nodiscard]] cad::SurfaceEval2 eval2(const Vec2& uv) const override {
    cad::SurfaceEval2 e = s_.eval2(to_original(uv));
    e.du = e.du * (1 / su_);
    e.dv = e.dv * (1 / sv_);
    e.duu = e.duu * (1 / (su_ * su_));
    e.duv = e.duv * (1 / (su_ * sv_));
    e.dvv = e.dvv * (1 / (sv_ * sv_));
    return e;
  }
  [[nodiscard]] Vec3 normal(const Vec2& uv) const override { return s_.normal(to_original(uv)); }
  [[nodiscard]] Vec2 project(const Vec3& p, const Vec2& guess, Vec3* foot) const override {
    return to_scaled(s_.project(p, to_original(guess), foot));
  }
  [[nodiscard]] Vec2 boundary_uv(LO loop, LO use, double t) const override {
    return to_scaled(s_.boundary_uv(loop, use, t));
  }
  [[nodiscard]] bool contains(const Vec2& uv) const override {
    return s_.contains(to_original(uv));
  }

 private:
  const cad::FaceGeometry& s_;
  double su_, sv_;
};

}  // namespace

bool has_flat_boundary_triangle(const FaceMesh& tri, double flat_ratio) {
  for (const auto& t : tri.triangles) {
    if (tri.vclass[t[0]].dim > 1 || tri.vclass[t[1]].dim > 1 || tri.vclass[t[2]].dim > 1) continue;
    double longest = 0;
    for (int k = 0; k < 3; ++k) {
      const Vec2 d = tri.uv[t[(k + 1) % 3]] - tri.uv[t[k]];
      longest = std::max(longest, dot(d, d));
    }
    const double area =
        0.5 * std::abs(cross(tri.uv[t[1]] - tri.uv[t[0]], tri.uv[t[2]] - tri.uv[t[0]]));
    if (area < flat_ratio * longest) return true;
  }
  return false;
}

Vec2 mean_boundary_speeds(const cad::FaceGeometry& surface, std::span<const BoundaryLoop> loops) {
  double su = 0, sv = 0;
  std::int64_t n = 0;
  for (const auto& loop : loops)
    for (const auto& p : loop.points) {
      const cad::SurfaceEval e = surface.eval(p.uv);
      su += norm(e.du);
      sv += norm(e.dv);
      ++n;
    }
  const auto mean = [&](double sum) {
    const double m = n > 0 ? sum / static_cast<double>(n) : 0.0;
    return std::isfinite(m) && m > 0 ? m : 1.0;
  };
  return {mean(su), mean(sv)};
}

FaceMesh triangulate_face_scaled(const cad::FaceGeometry& surface, bool face_reversed,
                                 std::span<const BoundaryLoop> loops, const SizeFunction& size,
                                 const TriangulateOptions& options, Vec2 scale,
                                 TriangulateStats* stats) {
  QSMESH_CHECK(std::isfinite(scale.u) && std::isfinite(scale.v) && scale.u > 0 && scale.v > 0,
               "triangulate_face_scaled: scale (" << scale.u << ", " << scale.v << ")");
  const ScaledSurface scaled(surface, scale);
  std::vector<BoundaryLoop> scaled_loops(loops.begin(), loops.end());
  for (auto& loop : scaled_loops)
    for (auto& p : loop.points) p.uv = scaled.to_scaled(p.uv);
  std::vector<Vec2> points(options.interior_points.begin(), options.interior_points.end());
  for (Vec2& x : points) x = scaled.to_scaled(x);
  TriangulateOptions o = options;
  o.interior_points = points;
  const SizeFunction scaled_size = [&](const Vec2& uv, const Vec3& xyz) {
    return size(scaled.to_original(uv), xyz);
  };
  FaceMesh fm = triangulate_face(scaled, face_reversed, scaled_loops, scaled_size, o, stats);
  for (std::size_t v = 0; v < fm.uv.size(); ++v) {
    fm.uv[v] = scaled.to_original(fm.uv[v]);
    if (fm.vclass[v].dim == 2) fm.vclass[v].param = {fm.uv[v].u, fm.uv[v].v};
  }
  return fm;
}

}  // namespace qsmesh::mesh
