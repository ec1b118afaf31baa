#include "qsmesh/quad/subdivide.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>
#include <tuple>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/quality.hpp"

namespace qsmesh::quad {
namespace {

struct EdgeUse {
  LO a, b;  // sorted vertex pair
  LO elem;
  int local;
  bool operator<(const EdgeUse& o) const {
    return std::tie(a, b, elem, local) < std::tie(o.a, o.b, o.elem, o.local);
  }
};

// Where a boundary edge lies: curve `curve`, between its halved vertices i and i+1.
struct CurveSpot {
  LO curve = kNoIndex;
  LO i = kNoIndex;
  bool a_first = true;  // vertex a is halved vertex i
};

class BoundaryResolver {
 public:
  BoundaryResolver(const mesh::FaceMesh& m, std::span<const mesh::CurveMesh> curves)
      : m_(m), curves_(curves) {}

  // Resolves boundary edge (a, b); returns false for an edge of a degenerate curve (two copies of
  // one corner at the same point).
  bool resolve(LO a, LO b, CurveSpot* spot) const {
    const auto& ca = m_.vclass[a];
    const auto& cb = m_.vclass[b];
    const Vec3 mid = 0.5 * (m_.points[a] + m_.points[b]);
    QSMESH_CHECK(ca.dim <= 1 && cb.dim <= 1, "face " << m_.face << ": boundary edge " << a << "-"
                                                     << b << " has a vertex inside the face");
    if (ca.dim == 1 && cb.dim == 1) {
      QSMESH_CHECK(ca.entity == cb.entity && std::abs(ca.index - cb.index) == 1,
                   "face " << m_.face << ": boundary edge " << a << "-" << b
                           << " joins two curves or non-consecutive curve vertices");
      const LO c = ca.entity;
      check_curve(c);
      *spot = {c, std::min(ca.index, cb.index), ca.index < cb.index};
      return true;
    }
    if (ca.dim == 1 || cb.dim == 1) {
      const bool a_curve = ca.dim == 1;
      const auto& cv = a_curve ? ca : cb;
      const LO c = cv.entity;
      check_curve(c);
      const LO n = curves_[c].num_edges() / 2;
      // The corner is halved vertex 0 (edge 0) or n (edge n-1); a curve of 2 halved edges that
      // closes on one corner allows both: the nearer full midpoint decides.
      CurveSpot best;
      double best_d = std::numeric_limits<double>::infinity();
      if (cv.index == 1) consider(c, 0, /*curve vertex first=*/false, a_curve, mid, &best, &best_d);
      if (cv.index == n - 1) consider(c, n - 1, true, a_curve, mid, &best, &best_d);
      QSMESH_CHECK(best.curve != kNoIndex, "face " << m_.face << ": boundary edge " << a << "-" << b
                                                   << " from a corner to vertex " << cv.index
                                                   << " of curve " << c << " (" << n
                                                   << " halved edges)");
      *spot = best;
      return true;
    }
    // Two corners.
    const Vec3& pa = m_.points[a];
    const Vec3& pb = m_.points[b];
    if (ca.entity == cb.entity) {
      const double scale = std::max({std::abs(pa.x), std::abs(pa.y), std::abs(pa.z), 1.0});
      if (distance(pa, pb) <= 1e-12 * scale) return false;
    }
    double best_d = std::numeric_limits<double>::infinity();
    CurveSpot best;
    for (std::size_t c = 0; c < curves_.size(); ++c) {
      const auto& cm = curves_[c];
      if (cm.num_edges() != 2) continue;
      const Vec3& s = cm.points.front();
      const Vec3& e = cm.points.back();
      const double tol = 1e-9 * std::max(distance(s, e), distance(s, cm.points[1]));
      const bool forward = distance(s, pa) <= tol && distance(e, pb) <= tol;
      const bool backward = distance(s, pb) <= tol && distance(e, pa) <= tol;
      if (!forward && !backward) continue;
      const double d = distance(cm.points[1], mid);
      if (d < best_d) {
        best_d = d;
        best = {static_cast<LO>(c), 0, forward};
      }
    }
    QSMESH_CHECK(best.curve != kNoIndex, "face " << m_.face
                                                 << ": no curve of one halved edge joins corners "
                                                 << ca.entity << " and " << cb.entity);
    *spot = best;
    return true;
  }

  void check_curve(LO c) const {
    QSMESH_CHECK(c >= 0 && static_cast<std::size_t>(c) < curves_.size(),
                 "face " << m_.face << ": curve " << c << " has no full mesh");
    QSMESH_CHECK(curves_[c].num_edges() >= 2 && curves_[c].num_edges() % 2 == 0,
                 "face " << m_.face << ": full mesh of curve " << c << " has "
                         << curves_[c].num_edges() << " edges (an even count >= 2 is needed)");
  }

 private:
  void consider(LO c, LO i, bool curve_vertex_first, bool a_curve, const Vec3& mid, CurveSpot* best,
                double* best_d) const {
    const double d = distance(curves_[c].points[2 * i + 1], mid);
    if (d < *best_d) {
      *best_d = d;
      *best = {c, i, curve_vertex_first == a_curve};
    }
  }

  const mesh::FaceMesh& m_;
  std::span<const mesh::CurveMesh> curves_;
};


// A boundary vertex X whose only element is a triangle (A, X, B) with both XA and XB on the
// boundary keeps a single sub-quad after subdivision, with the boundary's angle at X: about 180
// degrees where the boundary is straight, a quad that no smoothing can make valid (its corners
// on the curve are fixed). Such triangles come in strips along slightly concave boundaries
// (every vertex of the strip on the boundary). The strip is grown across its one interior edge
// until a triangle with a vertex Z inside the face is reached, and the polygon is triangulated
// again as a fan from Z: every boundary vertex of the strip then has two elements. Only done when
// every fan triangle is oriented like the old ones in (u, v); the triangle count does not change.
constexpr double kFlatBoundaryAngle = 2.8;  // radians (about 160 degrees)
constexpr int kMaxStrip = 8;

double uv_area(const mesh::FaceMesh& m, LO a, LO b, LO c) {
  return cross(m.uv[b] - m.uv[a], m.uv[c] - m.uv[a]);
}

std::int64_t refan_flat_boundary_strips(const mesh::FaceMesh& m, const std::vector<std::array<LO, 4>>& quads,
                                        std::vector<std::array<LO, 3>>& tris) {
  using Edge = std::pair<LO, LO>;
  std::map<Edge, int> uses;  // over all elements
  for (const auto& q : quads)
    for (int k = 0; k < 4; ++k) ++uses[std::minmax(q[k], q[(k + 1) % 4])];
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) ++uses[std::minmax(t[k], t[(k + 1) % 3])];
  std::map<Edge, std::vector<LO>> e2t;  // directed edge -> triangle
  auto index = [&] {
    e2t.clear();
    for (LO t = 0; t < static_cast<LO>(tris.size()); ++t)
      for (int k = 0; k < 3; ++k) e2t[{tris[t][k], tris[t][(k + 1) % 3]}].push_back(t);
  };
  index();
  auto boundary = [&](LO a, LO b) { return uses[std::minmax(a, b)] == 1; };
  std::int64_t done = 0;
  for (LO t0 = 0; t0 < static_cast<LO>(tris.size()); ++t0) {
    for (int k = 0; k < 3; ++k) {
      const auto& t = tris[t0];
      const LO a = t[k], x = t[(k + 1) % 3], b = t[(k + 2) % 3];
      if (m.vclass[x].dim > 1 || !boundary(a, x) || !boundary(x, b)) continue;
      const Vec3 xa = m.points[a] - m.points[x], xb = m.points[b] - m.points[x];
      if (std::atan2(norm(cross(xa, xb)), dot(xa, xb)) < kFlatBoundaryAngle) continue;
      const double sign = uv_area(m, a, x, b) > 0 ? 1.0 : -1.0;
      // Grow the strip: polygon kept as a cycle; its one interior edge (p, q) is crossed.
      std::vector<LO> strip{t0};
      std::vector<LO> cycle{a, x, b};  // b -> a is the interior edge
      LO z = kNoIndex;
      while (static_cast<int>(strip.size()) < kMaxStrip) {
        const LO p = cycle.back(), q = cycle.front();
        const auto it = e2t.find({q, p});  // the neighbour runs the edge the other way
        if (it == e2t.end() || it->second.size() != 1) break;
        const LO tn = it->second.front();
        const auto& tt = tris[tn];
        int j = 0;
        while (tt[j] != q) ++j;
        const LO apex = tt[(j + 2) % 3];
        strip.push_back(tn);
        if (m.vclass[apex].dim == 2) {
          z = apex;
          break;
        }
        // A boundary apex: the strip goes on across whichever of its two new edges is interior.
        const bool qa_in = !boundary(q, apex), ap_in = !boundary(apex, p);
        if (qa_in == ap_in) break;
        if (qa_in)
          cycle.push_back(apex);  // ... p, apex | q ...: interior edge apex -> q
        else
          cycle.insert(cycle.begin(), apex);  // interior edge p -> apex
      }
      if (z == kNoIndex) continue;
      // Fan from z over the cycle (q ... p), which closes through z.
      std::vector<std::array<LO, 3>> fan;
      bool ok = true;
      for (std::size_t i = 0; i + 1 < cycle.size(); ++i) {
        const std::array<LO, 3> f{cycle[i], cycle[i + 1], z};
        if (!(sign * uv_area(m, f[0], f[1], f[2]) > 0)) ok = false;
        fan.push_back(f);
      }
      if (!ok || fan.size() != strip.size()) continue;
      std::sort(strip.begin(), strip.end());
      for (std::size_t i = 0; i < strip.size(); ++i) tris[strip[i]] = fan[i];
      // Interior edge counts: recount from scratch (strips are rare and small).
      uses.clear();
      for (const auto& q : quads)
        for (int e = 0; e < 4; ++e) ++uses[std::minmax(q[e], q[(e + 1) % 4])];
      for (const auto& tr : tris)
        for (int e = 0; e < 3; ++e) ++uses[std::minmax(tr[e], tr[(e + 1) % 3])];
      index();
      ++done;
      break;
    }
  }
  return done;
}

}  // namespace

mesh::FaceMesh subdivide(const mesh::FaceMesh& mesh, const cad::FaceGeometry& surface,
                         std::span<const mesh::CurveMesh> full_curves, SubdivideStats* stats) {
  // Elements: quads first, then triangles.
  const std::vector<std::array<LO, 4>>& in_quads = mesh.quads;
  std::vector<std::array<LO, 3>> in_tris = mesh.triangles;
  const std::int64_t flat_splits = refan_flat_boundary_strips(mesh, in_quads, in_tris);
  std::vector<std::array<LO, 4>> elems;
  std::vector<int> sides;
  for (const auto& q : in_quads) {
    elems.push_back(q);
    sides.push_back(4);
  }
  for (const auto& t : in_tris) {
    elems.push_back({t[0], t[1], t[2], kNoIndex});
    sides.push_back(3);
  }
  const auto ne = static_cast<LO>(elems.size());

  std::vector<EdgeUse> uses;
  for (LO e = 0; e < ne; ++e)
    for (int k = 0; k < sides[e]; ++k) {
      const LO a = elems[e][k], b = elems[e][(k + 1) % sides[e]];
      uses.push_back({std::min(a, b), std::max(a, b), e, k});
    }
  std::sort(uses.begin(), uses.end());

  mesh::FaceMesh out;
  out.face = mesh.face;
  out.points = mesh.points;
  out.uv = mesh.uv;
  out.vclass = mesh.vclass;
  // Curve vertices: index doubled, and the full mesh's t and point (the same values by
  // construction, taken from the full mesh so that every face agrees bit for bit).
  for (LO v = 0; v < mesh.num_vertices(); ++v) {
    auto& vc = out.vclass[v];
    if (vc.dim != 1) continue;
    QSMESH_CHECK(vc.entity >= 0 && static_cast<std::size_t>(vc.entity) < full_curves.size(),
                 "face " << mesh.face << ": curve " << vc.entity << " has no full mesh");
    const auto& cm = full_curves[vc.entity];
    QSMESH_CHECK(2 * vc.index < cm.num_edges(), "face " << mesh.face << ": vertex " << v
                                                        << " index " << vc.index << " of curve "
                                                        << vc.entity << " outside the halved mesh");
    vc.index *= 2;
    vc.param = {cm.t[vc.index], 0};
    out.points[v] = cm.points[vc.index];
  }

  // What each new vertex falls back to when its uv placement folds a quad.
  struct Snap {
    LO vertex;
    Vec3 fallback;  // 3D midpoint / centroid
    Vec2 guess;
  };
  std::vector<Snap> snaps;

  const BoundaryResolver resolver(mesh, full_curves);
  // Poles (a corner where the parametrization is singular) have an arbitrary uv on their
  // degenerate line: what touches them is placed in 3D and projected, guided by the other vertices.
  std::vector<char> pole(mesh.vclass.size(), 0);
  for (std::size_t v = 0; v < mesh.vclass.size(); ++v)
    pole[v] = mesh.vclass[v].dim == 0 && norm(surface.normal(mesh.uv[v])) < 0.5 ? 1 : 0;

  // elem_mid[e][k]: new vertex at the middle of edge k of element e.
  std::vector<std::array<LO, 4>> elem_mid(elems.size(), {kNoIndex, kNoIndex, kNoIndex, kNoIndex});
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].a == uses[i].a && uses[j].b == uses[i].b) ++j;
    const LO a = uses[i].a, b = uses[i].b;
    const LO v = out.num_vertices();
    const Vec2 uv_mid = 0.5 * (mesh.uv[a] + mesh.uv[b]);
    mesh::VertexClass vc;
    Vec3 p;
    Vec2 uv = uv_mid;
    CurveSpot spot;
    if (j - i == 1 && resolver.resolve(a, b, &spot)) {
      const auto& cm = full_curves[spot.curve];
      const LO k = 2 * spot.i + 1;
      vc.dim = 1;
      vc.entity = spot.curve;
      vc.index = k;
      vc.param = {cm.t[k], 0};
      p = cm.points[k];
      // uv along the edge in proportion of t (exact for linear pcurves), then projected.
      const Vec2 uv0 = spot.a_first ? mesh.uv[a] : mesh.uv[b];
      const Vec2 uv1 = spot.a_first ? mesh.uv[b] : mesh.uv[a];
      const double dt = cm.t[k + 1] - cm.t[k - 1];
      const double s = dt != 0 ? (cm.t[k] - cm.t[k - 1]) / dt : 0.5;
      uv = uv0 + s * (uv1 - uv0);
      const Vec2 proj = surface.project(p, uv, nullptr);
      if (norm(proj - uv) <= 0.25 * norm(uv1 - uv0)) uv = proj;
      // A pole's uv is an arbitrary point of its degenerate line, so the interpolation is off
      // along that line: search from the other end instead, keeping whichever uv lands nearer.
      if (pole[a] != pole[b]) {
        const Vec2 from = pole[a] != 0 ? mesh.uv[b] : mesh.uv[a];
        const Vec2 alt = surface.project(p, from, nullptr);
        if (distance(surface.eval(alt).p, p) < distance(surface.eval(uv).p, p)) uv = alt;
      }
    } else if (j - i == 1) {
      // Edge of a degenerate curve (pole): another copy of the corner.
      vc = mesh.vclass[a];
      p = out.points[a];
    } else {
      if (pole[a] != 0 || pole[b] != 0)
        uv = surface.project(0.5 * (mesh.points[a] + mesh.points[b]), pole[a] != 0 ? mesh.uv[b] : mesh.uv[a], nullptr);
      vc.dim = 2;
      vc.entity = mesh.face;
      vc.param = {uv.u, uv.v};
      p = surface.eval(uv).p;
      snaps.push_back({v, 0.5 * (mesh.points[a] + mesh.points[b]), uv});
    }
    out.points.push_back(p);
    out.uv.push_back(uv);
    out.vclass.push_back(vc);
    for (std::size_t k = i; k < j; ++k) elem_mid[uses[k].elem][uses[k].local] = v;
    i = j;
  }

  // Centres and the sub-quads: corner, midpoint of its outgoing edge, centre, midpoint of its
  // incoming edge (same orientation as the element).
  for (LO e = 0; e < ne; ++e) {
    const int n = sides[e];
    Vec2 uv{0, 0};
    Vec3 g{0, 0, 0};
    for (int k = 0; k < n; ++k) {
      uv += mesh.uv[elems[e][k]];
      g += mesh.points[elems[e][k]];
    }
    uv = uv / n;
    g = g / n;
    Vec2 guess{0, 0};
    int regular = 0;
    for (int k = 0; k < n; ++k)
      if (pole[elems[e][k]] == 0) {
        guess += mesh.uv[elems[e][k]];
        ++regular;
      }
    if (regular > 0 && regular < n) uv = surface.project(g, guess / regular, nullptr);
    const LO c = out.num_vertices();
    mesh::VertexClass vc;
    vc.dim = 2;
    vc.entity = mesh.face;
    vc.param = {uv.u, uv.v};
    out.points.push_back(surface.eval(uv).p);
    out.uv.push_back(uv);
    out.vclass.push_back(vc);
    snaps.push_back({c, g, uv});
    for (int k = 0; k < n; ++k)
      out.quads.push_back({elems[e][k], elem_mid[e][k], c, elem_mid[e][(k + n - 1) % n]});
  }

  // Revert snaps that fold an adjacent quad, in vertex order (deterministic).
  std::vector<std::vector<LO>> v2q(out.points.size());
  for (LO q = 0; q < static_cast<LO>(out.quads.size()); ++q)
    for (const LO v : out.quads[q]) v2q[v].push_back(q);
  const auto min_sicn = [&](LO v) {
    double s = std::numeric_limits<double>::infinity();
    for (const LO q : v2q[v]) {
      const auto& Q = out.quads[q];
      s = std::min(s, mesh::quad_sicn({out.points[Q[0]], out.points[Q[1]], out.points[Q[2]],
                                       out.points[Q[3]]}));
    }
    return s;
  };
  std::int64_t reverted = 0;
  for (const Snap& snap : snaps) {
    const double before = min_sicn(snap.vertex);
    if (before > 0) continue;
    const Vec3 p_old = out.points[snap.vertex];
    const Vec2 uv_old = out.uv[snap.vertex];
    Vec3 foot;
    const Vec2 uv = surface.project(snap.fallback, snap.guess, &foot);
    out.points[snap.vertex] = foot;
    out.uv[snap.vertex] = uv;
    if (min_sicn(snap.vertex) > before) {
      out.vclass[snap.vertex].param = {uv.u, uv.v};
      ++reverted;
    } else {
      out.points[snap.vertex] = p_old;
      out.uv[snap.vertex] = uv_old;
    }
  }

  if (stats) {
    stats->quads = static_cast<std::int64_t>(out.quads.size());
    stats->snaps_reverted = reverted;
    stats->flat_boundary_splits = flat_splits;
  }
  return out;
}

}  // namespace qsmesh::quad
