#include "qsmesh/quad/subdivide.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>
#include <utility>
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

// What lies at the middle of a boundary edge of the halved mesh: segment `k` of loop `loop` of
// the halved boundary, and whether vertex a of the edge is the segment's first end.
struct Spot {
  LO loop = kNoIndex;
  LO k = kNoIndex;
  bool a_first = true;
};

// Boundary vertices are known by their classification: a corner by its id, a curve vertex by its
// curve and index in the full curve mesh.
using Key = std::tuple<int, LO, LO>;
Key key_of(const mesh::VertexClass& vc) {
  return {vc.dim, vc.entity, vc.dim == 0 ? kNoIndex : vc.index};
}

class BoundaryResolver {
 public:
  BoundaryResolver(const mesh::FaceMesh& m, const background::HalvedBoundary& boundary)
      : m_(m), b_(boundary) {
    for (LO l = 0; l < static_cast<LO>(b_.loops.size()); ++l) {
      const auto& pts = b_.loops[l].points;
      const auto n = static_cast<LO>(pts.size());
      for (LO k = 0; k < n; ++k)
        by_ends_[std::minmax(key_of(pts[k].vclass), key_of(pts[(k + 1) % n].vclass))].push_back(
            {l, k, true});
    }
  }

  // The halved segment under boundary edge (a, b). Where several segments join vertices of the
  // same classification (the two banks of a seam, two curves of two halved edges joining the
  // same corners) the one nearest in (u, v) is taken.
  Spot resolve(LO a, LO b) const {
    const auto& ca = m_.vclass[a];
    const auto& cb = m_.vclass[b];
    QSMESH_CHECK(ca.dim <= 1 && cb.dim <= 1, "face " << m_.face << ": boundary edge " << a << "-"
                                                     << b << " has a vertex inside the face");
    const auto it = by_ends_.find(std::minmax(key_of(ca), key_of(cb)));
    QSMESH_CHECK(it != by_ends_.end(), "face " << m_.face << ": boundary edge " << a << "-" << b
                                               << " is no segment of the halved boundary");
    Spot best;
    double best_d = std::numeric_limits<double>::infinity();
    for (const Spot& s : it->second) {
      const auto& pts = b_.loops[s.loop].points;
      const Vec2& p = pts[s.k].uv;
      const Vec2& q = pts[(s.k + 1) % pts.size()].uv;
      const double fwd = norm(m_.uv[a] - p) + norm(m_.uv[b] - q);
      const double bwd = norm(m_.uv[a] - q) + norm(m_.uv[b] - p);
      const bool same_keys = key_of(ca) == key_of(cb);
      // The classification decides the direction unless both ends have the same one.
      const bool a_first = same_keys ? fwd <= bwd : key_of(ca) == key_of(pts[s.k].vclass);
      const double d = a_first ? fwd : bwd;
      if (d < best_d) {
        best_d = d;
        best = {s.loop, s.k, a_first};
      }
    }
    return best;
  }

 private:
  const mesh::FaceMesh& m_;
  const background::HalvedBoundary& b_;
  std::map<std::pair<Key, Key>, std::vector<Spot>> by_ends_;
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

std::int64_t refan_flat_boundary_strips(const mesh::FaceMesh& m,
                                        const std::vector<std::array<LO, 4>>& quads,
                                        std::vector<std::array<LO, 3>>& tris,
                                        const std::map<std::pair<LO, LO>, Vec3>& corner_mids) {
  // The sub-quad at X runs to the corner that subdivision puts at the middle of XA (odd counts).
  const auto toward = [&](LO x, LO a) -> Vec3 {
    const auto it = corner_mids.find(std::minmax(x, a));
    return it != corner_mids.end() ? it->second : m.points[a];
  };
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
      const Vec3 xa = toward(x, a) - m.points[x], xb = toward(x, b) - m.points[x];
      // A curve vertex beside a corner at a midpoint is flat whatever the halved mesh shows: its
      // sub-quad runs along its smooth curve to the corner on one side, to the next full vertex
      // on the other.
      const bool beside_corner = m.vclass[x].dim == 1 && (corner_mids.contains(std::minmax(x, a)) ||
                                                          corner_mids.contains(std::minmax(x, b)));
      if (!beside_corner && std::atan2(norm(cross(xa, xb)), dot(xa, xb)) < kFlatBoundaryAngle)
        continue;
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

// Boundary edges of a quad-dominant mesh: sorted vertex pairs used by one element.
std::vector<std::pair<LO, LO>> boundary_edges(const mesh::FaceMesh& m,
                                              const std::vector<std::array<LO, 3>>& tris) {
  std::map<std::pair<LO, LO>, int> uses;
  for (const auto& q : m.quads)
    for (int k = 0; k < 4; ++k) ++uses[std::minmax(q[k], q[(k + 1) % 4])];
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) ++uses[std::minmax(t[k], t[(k + 1) % 3])];
  std::vector<std::pair<LO, LO>> out;
  for (const auto& [e, n] : uses)
    if (n == 1) out.push_back(e);
  return out;
}

bool has_corner_mids(const background::HalvedBoundary& boundary) {
  for (std::size_t l = 0; l < boundary.segments.size(); ++l)
    for (std::size_t k = 0; k < boundary.segments[l].size(); ++k)
      if (boundary.segments[l][k].mid.vclass.dim == 0 && boundary.loops[l].degenerate[k] == 0)
        return true;
  return false;
}

// Below this SICN a sub-quad at a pole is worth a second centre placement (see subdivide).
constexpr double kPoleCentreSicn = 0.1;
// A parameter line is degenerate when its image moves less than this fraction of what a step
// across it moves: CAD poles (coincident control points) are points only to the model's
// tolerance, and the placement only needs to know which way the element lies.
constexpr double kDegenerateRatio = 1e-3;

}  // namespace

std::vector<PoleLine> degenerate_lines(const cad::FaceGeometry& surface,
                                       std::span<const Vec2> poles, double reach) {
  std::vector<PoleLine> out;
  if (!(reach > 0)) return out;
  for (const Vec2& p : poles) {
    const cad::SurfaceEval e = surface.eval(p);
    // The surface does not move along the degenerate direction: du vanishes on a line v = const.
    const int fixed = norm(e.du) <= norm(e.dv) ? 1 : 0;
    const Vec2 along = fixed == 1 ? Vec2{reach, 0} : Vec2{0, reach};
    const Vec2 across = fixed == 1 ? Vec2{0, reach} : Vec2{reach, 0};
    double moved_along = 0;
    for (const double s : {-1.0, -0.5, 0.5, 1.0})
      moved_along = std::max(moved_along, distance(surface.eval(p + s * along).p, e.p));
    const double moved_across = std::max(distance(surface.eval(p + across).p, e.p),
                                         distance(surface.eval(p - across).p, e.p));
    if (!(moved_across > 0) || moved_along > kDegenerateRatio * moved_across) continue;
    const double value = fixed == 1 ? p.v : p.u;
    bool seen = false;
    for (const PoleLine& l : out)
      seen = seen || (l.fixed == fixed && std::abs(l.value - value) <= 1e-12 * reach);
    if (!seen) out.push_back({fixed, value, e.p});
  }
  return out;
}

Vec2 pole_image(const PoleLine& line, const Vec2& toward) {
  return line.fixed == 0 ? Vec2{line.value, toward.v} : Vec2{toward.u, line.value};
}

std::map<std::pair<LO, LO>, Vec3> corner_midpoints(const mesh::FaceMesh& mesh,
                                                   const background::HalvedBoundary& boundary) {
  std::map<std::pair<LO, LO>, Vec3> out;
  if (!has_corner_mids(boundary)) return out;
  const BoundaryResolver resolver(mesh, boundary);
  for (const auto& [a, b] : boundary_edges(mesh, mesh.triangles)) {
    const Spot s = resolver.resolve(a, b);
    const background::HalvedSegment& seg = boundary.segments[s.loop][s.k];
    if (seg.mid.vclass.dim == 0 && boundary.loops[s.loop].degenerate[s.k] == 0)
      out[{a, b}] = seg.mid.xyz;
  }
  return out;
}

mesh::FaceMesh subdivide(const mesh::FaceMesh& mesh, const cad::FaceGeometry& surface,
                         std::span<const mesh::CurveMesh> full_curves,
                         const background::HalvedBoundary& boundary, SubdivideStats* stats) {
  // Elements: quads first, then triangles.
  const std::vector<std::array<LO, 4>>& in_quads = mesh.quads;
  std::vector<std::array<LO, 3>> in_tris = mesh.triangles;
  const std::int64_t flat_splits =
      refan_flat_boundary_strips(mesh, in_quads, in_tris, corner_midpoints(mesh, boundary));
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
  // Curve vertices: the full mesh's t and point (the same values by construction, taken from the
  // full mesh so that every face agrees bit for bit).
  for (LO v = 0; v < mesh.num_vertices(); ++v) {
    auto& vc = out.vclass[v];
    if (vc.dim != 1) continue;
    QSMESH_CHECK(vc.entity >= 0 && static_cast<std::size_t>(vc.entity) < full_curves.size(),
                 "face " << mesh.face << ": curve " << vc.entity << " has no full mesh");
    const auto& cm = full_curves[vc.entity];
    QSMESH_CHECK(vc.index > 0 && vc.index < cm.num_edges(),
                 "face " << mesh.face << ": vertex " << v << " index " << vc.index << " of curve "
                         << vc.entity << " outside its full mesh");
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

  const BoundaryResolver resolver(mesh, boundary);
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
    const Spot spot = j - i == 1 ? resolver.resolve(a, b) : Spot{};
    const background::HalvedSegment* seg =
        spot.loop == kNoIndex ? nullptr : &boundary.segments[spot.loop][spot.k];
    if (seg != nullptr && seg->mid.vclass.dim == 1) {
      const LO c = seg->mid.vclass.entity;
      QSMESH_CHECK(c >= 0 && static_cast<std::size_t>(c) < full_curves.size(),
                   "face " << mesh.face << ": curve " << c << " has no full mesh");
      const auto& cm = full_curves[c];
      const LO k = seg->mid.vclass.index;
      QSMESH_CHECK(k > 0 && k < cm.num_edges(), "face " << mesh.face << ": midpoint " << k
                                                        << " of curve " << c
                                                        << " outside its full mesh");
      const bool a_first = spot.a_first == seg->forward;  // vertex a is full vertex k - 1
      vc.dim = 1;
      vc.entity = c;
      vc.index = k;
      vc.param = {cm.t[k], 0};
      p = cm.points[k];
      // uv along the edge in proportion of t (exact for linear pcurves), then projected.
      const Vec2 uv0 = a_first ? mesh.uv[a] : mesh.uv[b];
      const Vec2 uv1 = a_first ? mesh.uv[b] : mesh.uv[a];
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
    } else if (seg != nullptr && !boundary.loops[spot.loop].degenerate[spot.k]) {
      // A corner where its loop takes an odd count up to it: the corner itself, at its pcurve
      // image of the loop.
      vc = seg->mid.vclass;
      p = seg->mid.xyz;
      uv = seg->mid.uv;
    } else if (seg != nullptr) {
      // Edge of a degenerate curve (pole): another copy of the corner.
      vc = mesh.vclass[a];
      p = out.points[a];
    } else {
      if (pole[a] != 0 || pole[b] != 0)
        uv = surface.project(0.5 * (mesh.points[a] + mesh.points[b]),
                             pole[a] != 0 ? mesh.uv[b] : mesh.uv[a], nullptr);
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
    if (regular > 0 && regular < n) {
      const Vec2 toward = guess / regular;
      uv = surface.project(g, toward, nullptr);
      const auto worst_sub_quad = [&](const Vec2& at) {
        const Vec3 pc = surface.eval(at).p;
        double s = std::numeric_limits<double>::infinity();
        for (int k = 0; k < n; ++k)
          s = std::min(s, mesh::quad_sicn({out.points[elems[e][k]], out.points[elem_mid[e][k]], pc,
                                           out.points[elem_mid[e][(k + n - 1) % n]]}));
        return s;
      };
      const double projected = worst_sub_quad(uv);
      if (projected < kPoleCentreSicn) {
        // The 3D centroid can lie off the surface's side the element is on (on the axis of a
        // half of revolution), and its projection then lands on the boundary: place the centre
        // in (u, v) instead, each pole at the point of its degenerate line facing the element.
        double reach = 0;
        for (int k = 0; k < n; ++k) reach = std::max(reach, norm(mesh.uv[elems[e][k]] - toward));
        Vec2 alt{0, 0};
        bool placed = true;
        for (int k = 0; k < n && placed; ++k) {
          const LO v = elems[e][k];
          if (pole[v] == 0) {
            alt += mesh.uv[v];
            continue;
          }
          const std::vector<PoleLine> lines =
              degenerate_lines(surface, std::span<const Vec2>(&mesh.uv[v], 1), reach);
          placed = !lines.empty();
          if (placed) alt += pole_image(lines.front(), toward);
        }
        if (placed) {
          alt = alt / n;
          if (worst_sub_quad(alt) > projected) uv = alt;
        }
      }
    }
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
