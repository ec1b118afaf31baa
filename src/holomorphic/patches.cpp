// Quad mesh of a poly-annulus with b >= 3 boundary loops from its optimised holomorphic 1-form
// (paper 004 Sec. 4, "Quad-mesh generation"): the critical horizontal trajectories through the
// zeros cut the surface into flat cylinders, each meshed as a grid; the zeros become the
// valence-8 vertices where the grids meet.
#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <numbers>
#include <numeric>

#include "detail.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/holomorphic/holomorphic.hpp"

namespace qsmesh::holomorphic {
namespace {

using detail::C;
using detail::FinalBoundary;
using detail::grid_u;
using detail::merge_final;
using detail::wrap;

// The surface's triangles between two levels of v, one connected component: a flat cylinder of
// the form (no zero inside), whose u is integrated on its own triangles so that it is single
// valued up to the cylinder's one period.
struct Cylinder {
  double lo = 0, hi = 0;
  std::vector<LO> triangles;        // sorted
  std::vector<std::array<C, 3>> U;  // per entry of triangles: u + i v at the corners
  double period = 0;
  LO count = 0;                       // grid columns (0: not known yet)
  int side_group[2] = {-1, -1};       // lo and hi side: a cut group, or -1 for a boundary loop
  LO loop[2] = {kNoIndex, kNoIndex};  // the boundary loop of a side (PolyAnnulus loop index)
  // The side's grid points: output vertex ids and their u in this cylinder's chart, increasing.
  std::array<std::vector<LO>, 2> ids;
  std::array<std::vector<double>, 2> u;
};

// A point of a level curve: on the background edge (a, b) of triangle t at fraction w from a.
struct LevelPoint {
  LO t = kNoIndex;
  LO a = kNoIndex, b = kNoIndex;
  double w = 0;
  double u = 0;  // unwrapped along the curve
};

class PatchMesher {
 public:
  PatchMesher(const PolyAnnulus& s, const mesh::FaceMesh& background,
              const detail::Placement& place, std::span<const C> phi, std::vector<double> V)
      : s_(s), bg_(background), place_(place), phi_(phi), V_(std::move(V)) {}

  // The triangles with some part strictly between lo and hi, split into components across the
  // edges with some part there.
  std::vector<Cylinder> cylinders(double lo, double hi) const {
    const std::size_t nt = s_.triangles.size();
    std::vector<char> in(nt, 0);
    for (std::size_t t = 0; t < nt; ++t) {
      const auto& c = s_.triangles[t];
      const double a = V_[c[0]], b = V_[c[1]], d = V_[c[2]];
      in[t] = std::min({a, b, d}) < hi && std::max({a, b, d}) > lo ? 1 : 0;
    }
    std::vector<char> seen(nt, 0);
    std::vector<Cylinder> out;
    for (std::size_t t0 = 0; t0 < nt; ++t0) {
      if (in[t0] == 0 || seen[t0] != 0) continue;
      Cylinder cyl;
      cyl.lo = lo;
      cyl.hi = hi;
      std::vector<std::size_t> queue{t0};
      seen[t0] = 1;
      for (std::size_t head = 0; head < queue.size(); ++head) {
        const std::size_t t = queue[head];
        for (int k = 0; k < 3; ++k) {
          const LO e = s_.tri_edges[t][k];
          if (!edge_in(e, lo, hi)) continue;
          const auto& et = s_.edge_tris[static_cast<std::size_t>(e)];
          if (et[1] == kNoIndex) continue;
          const auto u =
              static_cast<std::size_t>(static_cast<std::size_t>(et[0]) == t ? et[1] : et[0]);
          if (in[u] == 0 || seen[u] != 0) continue;
          seen[u] = 1;
          queue.push_back(u);
        }
      }
      for (const std::size_t t : queue) cyl.triangles.push_back(static_cast<LO>(t));
      std::sort(cyl.triangles.begin(), cyl.triangles.end());
      integrate(cyl);
      out.push_back(std::move(cyl));
    }
    return out;
  }

  // The level curve v = level inside cylinder c as one closed curve, oriented so that u
  // increases; empty when it is not one closed curve.
  std::vector<LevelPoint> level_curve(const Cylinder& c, double level) const {
    // Crossed edges of each triangle of c, then a walk across the shared edges.
    std::map<LO, std::vector<std::size_t>> by_edge;  // edge -> local triangles crossing it
    std::vector<std::array<LO, 2>> crossed(c.triangles.size(), {kNoIndex, kNoIndex});
    for (std::size_t i = 0; i < c.triangles.size(); ++i) {
      const auto t = static_cast<std::size_t>(c.triangles[i]);
      int n = 0;
      for (int k = 0; k < 3; ++k) {
        const LO e = s_.tri_edges[t][k];
        if (!crosses(e, level)) continue;
        if (n < 2) crossed[i][static_cast<std::size_t>(n)] = e;
        ++n;
        by_edge[e].push_back(i);
      }
      if (n != 0 && n != 2) return {};
    }
    std::size_t start = c.triangles.size();
    for (std::size_t i = 0; i < c.triangles.size(); ++i)
      if (crossed[i][0] != kNoIndex) {
        start = i;
        break;
      }
    if (start == c.triangles.size()) return {};
    std::vector<LevelPoint> out;
    std::size_t i = start;
    LO e = crossed[i][0];
    std::size_t steps = 0;
    out.push_back(point_on(c, i, e, level));
    while (true) {
      const LO next_e = crossed[i][0] == e ? crossed[i][1] : crossed[i][0];
      const LevelPoint from = point_on(c, i, e, level);
      LevelPoint to = point_on(c, i, next_e, level);
      to.u = out.back().u + (to.u - from.u);
      const auto& ts = by_edge[next_e];
      if (ts.size() != 2) return {};  // a boundary edge crossed, or a non-manifold curve
      const std::size_t j = ts[0] == i ? ts[1] : ts[0];
      e = next_e;
      i = j;
      if (i == start && e == crossed[start][0]) {
        out.push_back(to);  // the first point again, one period on
        break;
      }
      out.push_back(point_on(c, i, e, level));
      out.back().u = to.u;
      if (++steps > 4 * c.triangles.size()) return {};
    }
    // Every crossing triangle visited: one closed curve.
    std::size_t crossing = 0;
    for (const auto& x : crossed)
      if (x[0] != kNoIndex) ++crossing;
    if (out.size() - 1 != crossing) return {};
    if (out.back().u < out.front().u) {
      std::reverse(out.begin(), out.end());
    }
    return out;
  }

  // The point of a closed level curve at u (modulo its period), as a 3D point on the surface.
  // Both ends of the segment are evaluated in the one background triangle that holds it, so
  // that the parameter guess is interpolated between copies on one side of a seam, on one face
  // of a group.
  void point_at(const std::vector<LevelPoint>& curve, double u, Vec3* xyz, Vec2* uv,
                mesh::VertexClass* vc = nullptr) const {
    const double u0 = curve.front().u, period = curve.back().u - u0;
    const double q = u0 + (u - u0) - period * std::floor((u - u0) / period);
    std::size_t k = 0;
    while (k + 2 < curve.size() && curve[k + 1].u <= q) ++k;
    const double du = curve[k + 1].u - curve[k].u;
    const double w = du > 0 ? std::clamp((q - curve[k].u) / du, 0.0, 1.0) : 0.0;
    const LO t = holds(curve[k].t, curve[k + 1]) ? curve[k].t : curve[k + 1].t;
    Vec3 x0, x1;
    Vec2 g0, g1;
    position(curve[k], t, &x0, &g0);
    position(curve[k + 1], t, &x1, &g1);
    const Vec3 x = x0 * (1 - w) + x1 * w;
    const Vec2 guess = g0 * (1 - w) + g1 * w;
    Vec3 foot;
    mesh::VertexClass klass;
    place_.place(t, x, guess, &foot, uv, &klass);
    *xyz = foot;
    if (vc != nullptr) *vc = klass;
  }

  // u of the curve at its point nearest to x (3D).
  static std::size_t nearest(const std::vector<LevelPoint>& curve, const std::vector<Vec3>& at,
                             const Vec3& x) {
    std::size_t best = 0;
    double d = 1e300;
    for (std::size_t k = 0; k + 1 < curve.size(); ++k) {
      const double dk = norm2(at[k] - x);
      if (dk < d) {
        d = dk;
        best = k;
      }
    }
    return best;
  }

  std::vector<Vec3> positions(const std::vector<LevelPoint>& curve) const {
    std::vector<Vec3> out;
    for (const auto& p : curve) {
      Vec3 x;
      Vec2 g;
      position(p, &x, &g);
      out.push_back(x);
    }
    return out;
  }

  // u of corner v of triangle t (a triangle of c) in c's chart.
  double corner_u(const Cylinder& c, LO t, LO v) const {
    const std::size_t i = local(c, t);
    const auto& tri = s_.triangles[static_cast<std::size_t>(t)];
    const auto k = static_cast<std::size_t>(std::find(tri.begin(), tri.end(), v) - tri.begin());
    return c.U[i][k].real();
  }

  static std::size_t local(const Cylinder& c, LO t) {
    return static_cast<std::size_t>(std::lower_bound(c.triangles.begin(), c.triangles.end(), t) -
                                    c.triangles.begin());
  }
  static bool contains(const Cylinder& c, LO t) {
    return std::binary_search(c.triangles.begin(), c.triangles.end(), t);
  }

 private:
  bool edge_in(LO e, double lo, double hi) const {
    const auto& ed = s_.edges[static_cast<std::size_t>(e)];
    const double a = V_[static_cast<std::size_t>(ed[0])], b = V_[static_cast<std::size_t>(ed[1])];
    return std::min(a, b) < hi && std::max(a, b) > lo;
  }
  bool crosses(LO e, double level) const {
    const auto& ed = s_.edges[static_cast<std::size_t>(e)];
    const double a = V_[static_cast<std::size_t>(ed[0])] - level;
    const double b = V_[static_cast<std::size_t>(ed[1])] - level;
    return (a < 0) != (b < 0);
  }
  LevelPoint point_on(const Cylinder& c, std::size_t i, LO e, double level) const {
    const auto t = static_cast<std::size_t>(c.triangles[i]);
    const auto& ed = s_.edges[static_cast<std::size_t>(e)];
    LevelPoint p;
    p.t = c.triangles[i];
    p.a = ed[0];
    p.b = ed[1];
    const double va = V_[static_cast<std::size_t>(ed[0])], vb = V_[static_cast<std::size_t>(ed[1])];
    p.w = (level - va) / (vb - va);
    const auto& tri = s_.triangles[t];
    const auto ka =
        static_cast<std::size_t>(std::find(tri.begin(), tri.end(), ed[0]) - tri.begin());
    const auto kb =
        static_cast<std::size_t>(std::find(tri.begin(), tri.end(), ed[1]) - tri.begin());
    p.u = c.U[i][ka].real() + p.w * (c.U[i][kb].real() - c.U[i][ka].real());
    return p;
  }
  // 3D point and a parameter guess (from the background triangle's FaceMesh corners, so a
  // seam's copies are told apart by the triangle).
  void position(const LevelPoint& p, Vec3* x, Vec2* uv) const { position(p, p.t, x, uv); }
  // Whether triangle t has p's edge.
  bool holds(LO t, const LevelPoint& p) const {
    const auto& tri = s_.triangles[static_cast<std::size_t>(t)];
    return std::find(tri.begin(), tri.end(), p.a) != tri.end() &&
           std::find(tri.begin(), tri.end(), p.b) != tri.end();
  }
  // The same in triangle t, which has p's edge.
  void position(const LevelPoint& p, LO t, Vec3* x, Vec2* uv) const {
    const auto& tri = s_.triangles[static_cast<std::size_t>(t)];
    const auto& ft = bg_.triangles[static_cast<std::size_t>(t)];
    const auto ka = static_cast<std::size_t>(std::find(tri.begin(), tri.end(), p.a) - tri.begin());
    const auto kb = static_cast<std::size_t>(std::find(tri.begin(), tri.end(), p.b) - tri.begin());
    *x = bg_.points[static_cast<std::size_t>(ft[ka])] * (1 - p.w) +
         bg_.points[static_cast<std::size_t>(ft[kb])] * p.w;
    *uv = bg_.uv[static_cast<std::size_t>(ft[ka])] * (1 - p.w) +
          bg_.uv[static_cast<std::size_t>(ft[kb])] * p.w;
  }
  // The integral of phi over the cylinder's triangles, across the edges inside its band.
 public:
  void integrate(Cylinder& c) const {
    const std::size_t n = c.triangles.size();
    c.U.assign(n, {});
    std::vector<char> done(n, 0);
    auto dir = [&](LO from, LO e) {
      return s_.edges[static_cast<std::size_t>(e)][0] == from ? phi_[static_cast<std::size_t>(e)]
                                                              : -phi_[static_cast<std::size_t>(e)];
    };
    auto fill_from = [&](std::size_t i, int k0, C value) {
      const auto t = static_cast<std::size_t>(c.triangles[i]);
      const auto& tri = s_.triangles[t];
      c.U[i][static_cast<std::size_t>(k0)] = value;
      const int k1 = (k0 + 1) % 3, k2 = (k0 + 2) % 3;
      c.U[i][static_cast<std::size_t>(k1)] = value + dir(tri[k0], s_.tri_edges[t][k0]);
      c.U[i][static_cast<std::size_t>(k2)] =
          c.U[i][static_cast<std::size_t>(k1)] + dir(tri[k1], s_.tri_edges[t][k1]);
    };
    fill_from(
        0, 0,
        C{0,
          V_[static_cast<std::size_t>(s_.triangles[static_cast<std::size_t>(c.triangles[0])][0])]});
    done[0] = 1;
    std::vector<std::size_t> queue{0};
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const std::size_t i = queue[head];
      const auto t = static_cast<std::size_t>(c.triangles[i]);
      for (int k = 0; k < 3; ++k) {
        const LO e = s_.tri_edges[t][k];
        if (!edge_in(e, c.lo, c.hi)) continue;
        const auto& et = s_.edge_tris[static_cast<std::size_t>(e)];
        if (et[1] == kNoIndex) continue;
        const LO u = static_cast<std::size_t>(et[0]) == t ? et[1] : et[0];
        const std::size_t j = local(c, u);
        if (j == n || c.triangles[j] != u || done[j] != 0) continue;
        const LO a = s_.triangles[t][k];
        const auto& tu = s_.triangles[static_cast<std::size_t>(u)];
        const int ka = static_cast<int>(std::find(tu.begin(), tu.end(), a) - tu.begin());
        fill_from(j, ka, c.U[i][static_cast<std::size_t>(k)]);
        done[j] = 1;
        queue.push_back(j);
      }
    }
  }

 private:
  const PolyAnnulus& s_;
  const mesh::FaceMesh& bg_;
  const detail::Placement& place_;
  std::span<const C> phi_;
  std::vector<double> V_;
};

}  // namespace

mesh::FaceMesh mesh_poly_annulus(const mesh::FaceMesh& background,
                                 std::span<const mesh::BoundaryLoop> loops,
                                 const cad::FaceGeometry& surface,
                                 const HolomorphicOptions& options, HolomorphicReport* report) {
  const cad::FaceGeometry* const one[] = {&surface};
  const LO face[] = {background.face};
  return detail::mesh_poly_annulus_of(background, loops, detail::Placement{one, face, {}}, options,
                                      report);
}

mesh::FaceMesh detail::mesh_poly_annulus_of(const mesh::FaceMesh& background,
                                            std::span<const mesh::BoundaryLoop> loops,
                                            const Placement& placement,
                                            const HolomorphicOptions& options,
                                            HolomorphicReport* report) {
  const Stopwatch clock;
  HolomorphicReport local;
  HolomorphicReport& R = report != nullptr ? *report : local;
  R = HolomorphicReport{};
  auto fail = [&](std::string why) {
    R.ok = false;
    R.reason = std::move(why);
    R.seconds = clock.seconds();
    return mesh::FaceMesh{};
  };
  try {
    const PolyAnnulus s = poly_annulus(background);
    if (!s.ok) {
      R.boundaries = static_cast<LO>(s.loops.size());
      return fail("not a poly-annulus: " + s.reason);
    }
    if (s.loops.size() == 2)
      return detail::mesh_annulus_of(s, background, loops, placement, options, report);
    R.boundaries = static_cast<LO>(s.loops.size());
    const std::size_t b = s.loops.size();
    std::string why;
    const FinalBoundary F = merge_final(loops, &why);
    if (!why.empty()) return fail(why);
    // A group's inner curves (and its faces' seams) are traversed both ways like a seam; its
    // points are placed per background triangle, so they cross them.
    if (!F.seam_edges.empty() && !placement.group()) return fail("b >= 3 with a seam: not handled");
    if (F.cycles.size() != b)
      return fail("the final boundary has " + std::to_string(F.cycles.size()) + " cycles, not " +
                  std::to_string(b));
    // A loop is a level of v, straight in the form's flat metric (see mesh_annulus); a right
    // angle is split in two by the column from it.
    if (std::string sharp = sharp_corner_on_a_loop(F, options.max_patch_corner_turn_deg);
        !sharp.empty())
      return fail(sharp);

    const HolomorphicBasis B = holomorphic_basis(s, options.basis, nullptr);
    R.basis_seconds = B.seconds;
    const EnergyResult E = minimize_area_distortion(s, B, options.energy);
    R.energy = E.energy;
    R.energy_seconds = E.seconds;
    const auto phi = combine(B, E.lambda);
    // v = Im of the integral of phi is single valued: sum_k lambda_k sum_j conj[k][j] f_j (the
    // conjugates are exact, Eq. 4.7), constant on every loop, harmonic; its critical points are
    // the zeros of phi.
    const std::size_t nv = s.points.size();
    std::vector<double> V(nv, 0.0);
    for (std::size_t k = 0; k < static_cast<std::size_t>(B.n); ++k)
      for (std::size_t j = 0; j < static_cast<std::size_t>(B.n); ++j)
        for (std::size_t x = 0; x < nv; ++x) V[x] += E.lambda[k] * B.conj[k][j] * B.f[j][x];
    double vmin = *std::min_element(V.begin(), V.end());
    double vmax = *std::max_element(V.begin(), V.end());
    const double range = vmax - vmin;
    if (!(range > 0)) return fail("the form's v is constant");
    std::vector<LO> loop_of(nv, kNoIndex);
    std::vector<double> loop_level(b);
    for (std::size_t l = 0; l < b; ++l) {
      for (const LO x : s.loops[l]) loop_of[static_cast<std::size_t>(x)] = static_cast<LO>(l);
      loop_level[l] = V[static_cast<std::size_t>(s.loops[l][0])];
    }
    // Each loop is a local minimum or maximum of v: else v crosses its level next to it, a zero
    // of phi on the loop (the leaf turns back there), which the grids cannot follow.
    std::vector<std::vector<LO>> nbrs(nv);
    for (const auto& e : s.edges) {
      nbrs[static_cast<std::size_t>(e[0])].push_back(e[1]);
      nbrs[static_cast<std::size_t>(e[1])].push_back(e[0]);
    }
    std::vector<char> loop_is_max(b, 0);
    for (std::size_t l = 0; l < b; ++l) {
      int above = 0, below = 0;
      for (const LO x : s.loops[l])
        for (const LO y : nbrs[static_cast<std::size_t>(x)]) {
          if (loop_of[static_cast<std::size_t>(y)] == static_cast<LO>(l)) continue;
          if (V[static_cast<std::size_t>(y)] > loop_level[l])
            ++above;
          else
            ++below;
        }
      if (above > 0 && below > 0)
        return fail("the form has zeros on loop " + std::to_string(l) +
                    " (v crosses its level next to it)");
      loop_is_max[l] = above == 0 ? 1 : 0;
    }
    // Saddles of the piecewise-linear v: interior vertices whose link changes sign 4 times.
    std::vector<std::vector<LO>> vertex_tris(nv);
    for (std::size_t t = 0; t < s.triangles.size(); ++t)
      for (const LO x : s.triangles[t])
        vertex_tris[static_cast<std::size_t>(x)].push_back(static_cast<LO>(t));
    auto higher = [&](LO a, LO x) {
      const double da = V[static_cast<std::size_t>(a)], dx = V[static_cast<std::size_t>(x)];
      return da != dx ? da > dx : a > x;
    };
    std::vector<LO> saddles;
    for (std::size_t x = 0; x < nv; ++x) {
      if (loop_of[x] != kNoIndex) continue;
      int changes = 0;
      for (const LO t : vertex_tris[x]) {
        const auto& c = s.triangles[static_cast<std::size_t>(t)];
        std::array<LO, 2> o{};
        int n = 0;
        for (const LO y : c)
          if (y != static_cast<LO>(x)) o[static_cast<std::size_t>(n++)] = y;
        if (higher(o[0], static_cast<LO>(x)) != higher(o[1], static_cast<LO>(x))) ++changes;
      }
      if (changes == 2) continue;
      if (changes == 4) {
        saddles.push_back(static_cast<LO>(x));
        continue;
      }
      return fail(changes == 0 ? "v has an interior extremum (a degenerate form)"
                               : "the form has a zero of order " + std::to_string(changes / 2 - 1) +
                                     ": a valence " + std::to_string(2 * changes) + " vertex");
    }
    R.zeros = static_cast<LO>(saddles.size());
    if (saddles.size() != b - 2)
      return fail("v has " + std::to_string(saddles.size()) +
                  " saddles, not b - 2 = " + std::to_string(b - 2));
    // The levels that cut the surface: the saddles', between the lowest and highest loop.
    const double tol = 1e-9 * range;
    std::vector<double> levels{vmin, vmax};
    for (const LO x : saddles) {
      const double c = V[static_cast<std::size_t>(x)];
      for (const double l : levels)
        if (std::abs(l - c) < 1e-6 * range) return fail("two zeros at one level of v");
      for (const double l : loop_level)
        if (std::abs(l - c) < 1e-6 * range) return fail("a zero at the level of a loop");
      levels.push_back(c);
    }
    std::sort(levels.begin(), levels.end());

    PatchMesher P(s, background, placement, phi, V);
    std::vector<Cylinder> cyl;
    for (std::size_t k = 0; k + 1 < levels.size(); ++k)
      for (auto& c : P.cylinders(levels[k], levels[k + 1])) cyl.push_back(std::move(c));
    // A loop touching a cylinder is one of its ends (v has no extremum inside): its level
    // replaces the band's there.
    std::vector<LO> tri_loop(s.triangles.size(), kNoIndex);
    for (std::size_t t = 0; t < s.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        const LO e = s.tri_edges[t][k];
        if (s.edge_tris[static_cast<std::size_t>(e)][1] == kNoIndex)
          tri_loop[t] = s.edge_loop[static_cast<std::size_t>(e)];
      }
    for (auto& c : cyl)
      for (const LO t : c.triangles) {
        const LO l = tri_loop[static_cast<std::size_t>(t)];
        if (l == kNoIndex) continue;
        const auto li = static_cast<std::size_t>(l);
        if (loop_level[li] < c.lo - tol || loop_level[li] > c.hi + tol) continue;
        const int side = loop_is_max[li] != 0 ? 1 : 0;
        if (c.loop[side] != kNoIndex && c.loop[side] != l) return fail("two loops end one patch");
        c.loop[side] = l;
        (side == 0 ? c.lo : c.hi) = loop_level[li];
      }
    // The cut sides on one level, grouped: cylinders below and above it sharing a triangle.
    struct Group {
      double level = 0;
      std::vector<std::size_t> below, above;  // cylinders whose hi (lo) side it is
      LO saddle = kNoIndex;
    };
    std::vector<Group> groups;
    auto make_groups = [&] {
      groups.clear();
      std::map<LO, std::vector<std::pair<std::size_t, int>>> sides_of_tri;
      for (std::size_t c = 0; c < cyl.size(); ++c)
        for (int side = 0; side < 2; ++side)
          if (cyl[c].loop[side] == kNoIndex)
            for (const LO t : cyl[c].triangles) sides_of_tri[t].emplace_back(c, side);
      std::vector<int> parent(2 * cyl.size());
      std::iota(parent.begin(), parent.end(), 0);
      auto find = [&](int x) {
        while (parent[static_cast<std::size_t>(x)] != x)
          x = parent[static_cast<std::size_t>(x)] =
              parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
        return x;
      };
      for (const auto& [t, list] : sides_of_tri)
        for (const auto& [c1, s1] : list)
          for (const auto& [c2, s2] : list) {
            const double l1 = s1 == 0 ? cyl[c1].lo : cyl[c1].hi;
            const double l2 = s2 == 0 ? cyl[c2].lo : cyl[c2].hi;
            if (s1 != s2 && std::abs(l1 - l2) <= tol)
              parent[static_cast<std::size_t>(find(static_cast<int>(2 * c1) + s1))] =
                  find(static_cast<int>(2 * c2) + s2);
          }
      std::map<int, int> group_of_root;
      for (std::size_t c = 0; c < cyl.size(); ++c)
        for (int side = 0; side < 2; ++side) {
          if (cyl[c].loop[side] != kNoIndex) continue;
          const int root = find(static_cast<int>(2 * c) + side);
          const auto [it, added] = group_of_root.try_emplace(root, static_cast<int>(groups.size()));
          if (added) {
            groups.emplace_back();
            groups.back().level = side == 0 ? cyl[c].lo : cyl[c].hi;
          }
          cyl[c].side_group[side] = it->second;
          (side == 0 ? groups[static_cast<std::size_t>(it->second)].above
                     : groups[static_cast<std::size_t>(it->second)].below)
              .push_back(c);
        }
    };
    // A cut with one cylinder on each side passes no zero (another component's zero is at its
    // level): the two are one cylinder, merged so that no thin row is forced there.
    for (bool merged = true; merged;) {
      merged = false;
      make_groups();
      for (const auto& g : groups) {
        if (g.below.size() != 1 || g.above.size() != 1) continue;
        Cylinder& lo = cyl[g.below[0]];
        Cylinder& hi = cyl[g.above[0]];
        Cylinder m;
        m.lo = lo.lo;
        m.hi = hi.hi;
        m.loop[0] = lo.loop[0];
        m.loop[1] = hi.loop[1];
        std::set_union(lo.triangles.begin(), lo.triangles.end(), hi.triangles.begin(),
                       hi.triangles.end(), std::back_inserter(m.triangles));
        P.integrate(m);
        const std::size_t drop = std::max(g.below[0], g.above[0]);
        cyl[std::min(g.below[0], g.above[0])] = std::move(m);
        cyl.erase(cyl.begin() + static_cast<long>(drop));
        merged = true;
        break;
      }
    }
    std::vector<std::size_t> cylinder_of_loop(b, cyl.size());
    for (std::size_t c = 0; c < cyl.size(); ++c)
      for (int side = 0; side < 2; ++side)
        if (cyl[c].loop[side] != kNoIndex)
          cylinder_of_loop[static_cast<std::size_t>(cyl[c].loop[side])] = c;
    for (std::size_t l = 0; l < b; ++l)
      if (cylinder_of_loop[l] == cyl.size()) return fail("a loop borders no patch");
    // Each cylinder's period, from its middle level curve.
    for (auto& c : cyl) {
      const auto mid = P.level_curve(c, 0.5 * (c.lo + c.hi));
      if (mid.empty()) return fail("a patch between two critical levels is not one cylinder");
      c.period = mid.back().u - mid.front().u;
      if (!(c.period > 0)) return fail("a patch has no period");
    }
    for (const LO x : saddles) {
      // The saddle's group: the one whose cylinders hold its triangles, at its level.
      const double c = V[static_cast<std::size_t>(x)];
      bool found = false;
      for (auto& g : groups) {
        if (std::abs(g.level - c) > tol) continue;
        const std::size_t any = g.below.empty() ? g.above[0] : g.below[0];
        for (const LO t : vertex_tris[static_cast<std::size_t>(x)])
          if (PatchMesher::contains(cyl[any], t)) found = true;
        if (found) {
          if (g.saddle != kNoIndex) return fail("two zeros on one critical curve");
          g.saddle = x;
          break;
        }
      }
      if (!found) return fail("a zero on no cut");
    }
    for (const auto& g : groups) {
      const std::size_t nb = g.below.size(), na = g.above.size();
      const bool saddle = (nb == 1 && na == 2) || (nb == 2 && na == 1);
      if (g.saddle == kNoIndex || !saddle)
        return fail("a cut level joins " + std::to_string(nb) + " patches below and " +
                    std::to_string(na) + " above");
    }
    // Columns: each loop's count fixes its cylinder; across a cut the counts below and above sum
    // to the same (the sum of the periods is the same on every level of v, and the points on the
    // cut are shared).
    // Final cycles to PolyAnnulus loops: through the nearest background boundary edge.
    std::vector<std::size_t> cycle_of_loop(b, b);
    std::vector<LO> bedge_tri(s.edges.size(), kNoIndex);
    for (std::size_t t = 0; t < s.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        const LO e = s.tri_edges[t][k];
        if (s.edge_tris[static_cast<std::size_t>(e)][1] == kNoIndex)
          bedge_tri[static_cast<std::size_t>(e)] = static_cast<LO>(t);
      }
    // (loop, u in its cylinder) of a final boundary point.
    std::vector<std::size_t> boundary_edges;
    for (std::size_t e = 0; e < s.edges.size(); ++e)
      if (bedge_tri[e] != kNoIndex) boundary_edges.push_back(e);
    auto on_boundary = [&](const Vec3& x, LO* loop, double* u) {
      double best = 1e300;
      for (const std::size_t e : boundary_edges) {
        const Vec3& a = s.points[static_cast<std::size_t>(s.edges[e][0])];
        const Vec3 ab = s.points[static_cast<std::size_t>(s.edges[e][1])] - a;
        const double l2 = dot(ab, ab);
        const double w = l2 > 0 ? std::clamp(dot(x - a, ab) / l2, 0.0, 1.0) : 0.0;
        const double d = norm2(a + ab * w - x);
        if (d < best) {
          best = d;
          *loop = s.edge_loop[e];
          const auto& c = cyl[cylinder_of_loop[static_cast<std::size_t>(*loop)]];
          const LO t = bedge_tri[e];
          if (!PatchMesher::contains(c, t)) {
            *loop = kNoIndex;
            continue;
          }
          const double ua = P.corner_u(c, t, s.edges[e][0]);
          const double ub = P.corner_u(c, t, s.edges[e][1]);
          *u = ua + w * (ub - ua);
        }
      }
    };
    mesh::FaceMesh out;
    out.face = background.face;
    auto add_point = [&](const Vec3& x, const Vec2& uv, const mesh::VertexClass& vc) {
      out.points.push_back(x);
      out.uv.push_back(uv);
      out.vclass.push_back(vc);
      return static_cast<LO>(out.points.size() - 1);
    };
    for (std::size_t k = 0; k < F.cycles.size(); ++k) {
      const auto& cycle = F.cycles[k];
      std::vector<double> u(cycle.size());
      LO loop = kNoIndex;
      for (std::size_t i = 0; i < cycle.size(); ++i) {
        LO l = kNoIndex;
        on_boundary(F.points[static_cast<std::size_t>(cycle[i])].xyz, &l, &u[i]);
        if (l == kNoIndex || (loop != kNoIndex && l != loop))
          return fail("a final loop's points are not on one background loop");
        loop = l;
      }
      if (cycle_of_loop[static_cast<std::size_t>(loop)] != b)
        return fail("two final loops on one background loop");
      cycle_of_loop[static_cast<std::size_t>(loop)] = k;
      auto& c = cyl[cylinder_of_loop[static_cast<std::size_t>(loop)]];
      const int side = c.loop[0] == loop ? 0 : 1;
      std::vector<LO> ids;
      for (const LO p : cycle) {
        const auto& bp = F.points[static_cast<std::size_t>(p)];
        ids.push_back(add_point(bp.xyz, bp.uv, bp.vclass));
      }
      // Unwrapped u, increasing along the side.
      double total = 0;
      for (std::size_t i = 0; i < u.size(); ++i)
        total += wrap(u[(i + 1) % u.size()] - u[i], c.period);
      if (std::abs(std::abs(total) - c.period) > 1e-6 * c.period)
        return fail("a final loop does not go once around its patch");
      if (total < 0) {
        std::reverse(ids.begin(), ids.end());
        std::reverse(u.begin(), u.end());
      }
      std::vector<double> uu{u[0]};
      for (std::size_t i = 1; i < u.size(); ++i)
        uu.push_back(uu.back() + wrap(u[i] - u[i - 1], c.period));
      c.ids[static_cast<std::size_t>(side)] = std::move(ids);
      c.u[static_cast<std::size_t>(side)] = std::move(uu);
      c.count = static_cast<LO>(cycle.size());
    }
    // Propagate the counts over the cut groups (the Reeb graph of v is a tree).
    for (bool changed = true; changed;) {
      changed = false;
      for (const auto& g : groups) {
        LO known_below = 0, known_above = 0;
        std::vector<std::size_t> unknown;
        for (const std::size_t c : g.below) {
          if (cyl[c].count > 0)
            known_below += cyl[c].count;
          else
            unknown.push_back(c);
        }
        for (const std::size_t c : g.above) {
          if (cyl[c].count > 0)
            known_above += cyl[c].count;
          else
            unknown.push_back(c);
        }
        if (unknown.size() != 1) continue;
        const bool below = std::find(g.below.begin(), g.below.end(), unknown[0]) != g.below.end();
        const LO n = below ? known_above - known_below : known_below - known_above;
        std::string counts;
        for (std::size_t k = 0; k < F.cycles.size(); ++k)
          counts += (k > 0 ? ", " : "") + std::to_string(F.cycles[k].size());
        if (n <= 0)
          return fail("the loops' counts (" + counts +
                      ") do not add up across the form's critical curves");
        cyl[unknown[0]].count = n;
        changed = true;
      }
    }
    for (const auto& g : groups) {
      LO below = 0, above = 0;
      for (const std::size_t c : g.below) below += cyl[c].count;
      for (const std::size_t c : g.above) above += cyl[c].count;
      if (below != above || below == 0) {
        std::string counts;
        for (std::size_t k = 0; k < F.cycles.size(); ++k)
          counts += (k > 0 ? ", " : "") + std::to_string(F.cycles[k].size());
        return fail("the loops' counts (" + counts +
                    ") do not add up across the form's critical curves (" + std::to_string(below) +
                    " below a cut, " + std::to_string(above) + " above)");
      }
    }
    // The cut points. eps: the curves next to a saddle's level, inside each patch.
    const double eps = 1e-7 * range;
    std::vector<LO> saddle_ids;
    // Groups in an order where a lobe's cylinder has its far side placed already (a loop, or a
    // group done before), so that the columns run straight through it; where none is ready, the
    // first left gets equal steps of u on the lobes lacking it.
    std::vector<char> done(groups.size(), 0);
    auto far_known = [&](const Group& g) {
      const bool two_below = g.below.size() == 2;
      for (const std::size_t c : two_below ? g.below : g.above)
        if (cyl[c].ids[two_below ? 0 : 1].empty()) return false;
      return true;
    };
    for (std::size_t round = 0; round < groups.size(); ++round) {
      std::size_t next = groups.size();
      for (std::size_t k = 0; k < groups.size() && next == groups.size(); ++k)
        if (done[k] == 0 && far_known(groups[k])) next = k;
      for (std::size_t k = 0; k < groups.size() && next == groups.size(); ++k)
        if (done[k] == 0) next = k;
      done[next] = 1;
      const Group& g = groups[next];
      // Through a saddle: the two cylinders on one side each touch it once (the two lobes of
      // the figure eight), the one on the other side twice.
      const bool two_below = g.below.size() == 2;
      const auto& pair = two_below ? g.below : g.above;
      Cylinder& single = cyl[two_below ? g.above[0] : g.below[0]];
      const double pair_level = two_below ? g.level - eps : g.level + eps;
      const double single_level = two_below ? g.level + eps : g.level - eps;
      const Vec3 xs = s.points[static_cast<std::size_t>(g.saddle)];
      // The saddle's parameters: its copy in a triangle around it (the face of that triangle).
      const LO xs_t = vertex_tris[static_cast<std::size_t>(g.saddle)].front();
      const auto& xs_c = s.triangles[static_cast<std::size_t>(xs_t)];
      const Vec2 xs_uv = background.uv[static_cast<std::size_t>(
          background.triangles[static_cast<std::size_t>(xs_t)][static_cast<std::size_t>(
              std::find(xs_c.begin(), xs_c.end(), g.saddle) - xs_c.begin())])];
      const LO saddle_id = add_point(
          xs, xs_uv, placement.interior(static_cast<std::size_t>(placement.part(xs_t)), xs_uv));
      saddle_ids.push_back(saddle_id);
      const auto cs = P.level_curve(single, single_level);
      if (cs.empty()) return fail("a cut through a zero is not one closed curve");
      const auto xcs = P.positions(cs);
      const std::size_t start = PatchMesher::nearest(cs, xcs, xs);
      std::vector<LO> single_ids;
      std::vector<double> single_u;
      double us = cs[start].u;
      // Which lobe follows the saddle on the single side: the one whose midpoint is nearer its
      // curve's point half a lobe on.
      std::array<std::vector<LevelPoint>, 2> lobes;
      for (int k = 0; k < 2; ++k) {
        lobes[static_cast<std::size_t>(k)] =
            P.level_curve(cyl[pair[static_cast<std::size_t>(k)]], pair_level);
        if (lobes[static_cast<std::size_t>(k)].empty())
          return fail("a lobe of a cut through a zero is not one closed curve");
      }
      const double p0 = cyl[pair[0]].period, p1 = cyl[pair[1]].period;
      if (std::abs(p0 + p1 - single.period) > 1e-3 * single.period)
        return fail("the periods do not add up at a zero");
      std::array<std::size_t, 2> order{0, 1};
      {
        Vec3 a, m0, m1;
        Vec2 uv;
        P.point_at(cs, us + 0.5 * p0, &a, &uv);
        const auto x0 = P.positions(lobes[0]);
        const auto x1 = P.positions(lobes[1]);
        const double u0 = lobes[0][PatchMesher::nearest(lobes[0], x0, xs)].u;
        P.point_at(lobes[0], u0 + 0.5 * p0, &m0, &uv);
        Vec3 b2;
        P.point_at(cs, us + 0.5 * p1, &b2, &uv);
        const double u1 = lobes[1][PatchMesher::nearest(lobes[1], x1, xs)].u;
        P.point_at(lobes[1], u1 + 0.5 * p1, &m1, &uv);
        if (norm2(b2 - m1) < norm2(a - m0)) order = {1, 0};
      }
      for (const std::size_t k : order) {
        Cylinder& lc = cyl[pair[k]];
        const auto& curve = lobes[k];
        const auto xl = P.positions(curve);
        const double u0 = curve[PatchMesher::nearest(curve, xl, xs)].u;
        const LO n = lc.count;
        std::vector<LO> ids{saddle_id};
        std::vector<double> ul{u0};
        single_ids.push_back(saddle_id);
        single_u.push_back(us);
        // The lobe's points continue the columns from the cylinder's far side (a loop's points
        // are at equal steps of length, not of u), shifted so that the saddle is one.
        const std::size_t far = two_below ? 0 : 1;
        const std::vector<double>& fu = lc.u[far];
        const bool from_loop = static_cast<LO>(fu.size()) == n;
        std::size_t k0 = 0;
        if (from_loop)
          for (std::size_t q = 1; q < fu.size(); ++q)
            if (std::abs(wrap(fu[q] - u0, lc.period)) < std::abs(wrap(fu[k0] - u0, lc.period)))
              k0 = q;
        auto offset = [&](LO j) {
          if (!from_loop) return lc.period * double(j) / double(n);
          const std::size_t q = k0 + static_cast<std::size_t>(j);
          return q < fu.size() ? fu[q] - fu[k0] : fu[q - fu.size()] + lc.period - fu[k0];
        };
        for (LO j = 1; j < n; ++j) {
          const double du = offset(j);
          Vec3 x;
          Vec2 uv;
          mesh::VertexClass vc;
          P.point_at(curve, u0 + du, &x, &uv, &vc);
          ids.push_back(add_point(x, uv, vc));
          ul.push_back(u0 + du);
          single_ids.push_back(ids.back());
          single_u.push_back(us + du);
        }
        us += lc.period;
        const int side = two_below ? 1 : 0;
        lc.ids[static_cast<std::size_t>(side)] = std::move(ids);
        lc.u[static_cast<std::size_t>(side)] = std::move(ul);
      }
      const int side = two_below ? 0 : 1;
      single.ids[static_cast<std::size_t>(side)] = std::move(single_ids);
      single.u[static_cast<std::size_t>(side)] = std::move(single_u);
    }
    std::map<LO, LO> same;  // a point identified with another (collapsed patches)
    auto find_same = [&](LO x) {
      for (auto it = same.find(x); it != same.end(); it = same.find(x)) x = it->second;
      return x;
    };
    int collapsed = 0;
    // Each cylinder: a grid between its two sides (rotated for the least twist), rows at equal
    // steps of v, u harmonic over the grid, points on the level curves of the rows.
    for (auto& c : cyl) {
      const std::size_t N = c.ids[0].size();
      if (N == 0 || c.ids[1].size() != N || static_cast<LO>(N) != c.count)
        return fail("a patch's two sides have different counts");
      const double period = c.period;
      std::size_t shift = 0;
      double best = 1e300;
      for (std::size_t sh = 0; sh < N; ++sh) {
        double cost = 0;
        for (std::size_t i = 0; i < N; ++i) {
          const double d = wrap(c.u[1][(i + sh) % N] - c.u[0][i], period);
          cost += d * d;
        }
        if (cost < best) {
          best = cost;
          shift = sh;
        }
      }
      std::vector<LO> lo_ids = c.ids[0], hi_ids(N);
      std::vector<double> a(N + 1), bb(N + 1);
      for (std::size_t i = 0; i < N; ++i) hi_ids[i] = c.ids[1][(i + shift) % N];
      a[0] = c.u[0][0];
      for (std::size_t i = 1; i <= N; ++i)
        a[i] = a[i - 1] + wrap(c.u[0][i % N] - c.u[0][i - 1], period);
      bb[0] = c.u[1][shift];
      for (std::size_t i = 1; i <= N; ++i)
        bb[i] = bb[i - 1] + wrap(c.u[1][(i + shift) % N] - c.u[1][(i + shift - 1) % N], period);
      const double move = bb[0] - (a[0] + wrap(bb[0] - a[0], period));
      for (double& x : bb) x -= move;
      if (std::abs(a[N] - a[0] - period) > 1e-6 * period ||
          std::abs(bb[N] - bb[0] - period) > 1e-6 * period)
        return fail("a patch side does not go once around it");
      const double height = c.hi - c.lo;
      const long rows_wanted = std::lround(height * double(N) / period);
      if (rows_wanted == 0 && c.loop[0] == kNoIndex && c.loop[1] == kNoIndex) {
        // Thinner than half a row between two zeros' critical curves: one curve, the two sides'
        // points identified (a zero's point replaces the one it meets); a row there would be a
        // sliver.
        for (std::size_t i = 0; i < N; ++i) {
          const LO l = find_same(lo_ids[i]), h = find_same(hi_ids[i]);
          if (l == h) continue;
          const bool za = std::find(saddle_ids.begin(), saddle_ids.end(), l) != saddle_ids.end();
          const bool zh = std::find(saddle_ids.begin(), saddle_ids.end(), h) != saddle_ids.end();
          if (za && zh) return fail("two zeros meet across a thin patch");
          if (zh)
            same[l] = h;
          else
            same[h] = l;
        }
        ++collapsed;
        continue;
      }
      const auto M = std::max<std::size_t>(1, static_cast<std::size_t>(rows_wanted));
      std::vector<double> rows(M + 1);
      for (std::size_t j = 0; j <= M; ++j) rows[j] = c.lo + height * double(j) / double(M);
      const std::vector<double> ug = grid_u(a, bb, rows, period, {}, options.grid);
      std::vector<LO> grid((M + 1) * N, kNoIndex);
      for (std::size_t i = 0; i < N; ++i) {
        grid[i] = lo_ids[i];
        grid[M * N + i] = hi_ids[i];
      }
      for (std::size_t j = 1; j < M; ++j) {
        const auto curve = P.level_curve(c, rows[j]);
        if (curve.empty()) return fail("a row of a patch is not one closed curve");
        for (std::size_t i = 0; i < N; ++i) {
          Vec3 x;
          Vec2 uv;
          mesh::VertexClass vc;
          P.point_at(curve, ug[j * (N + 1) + i], &x, &uv, &vc);
          grid[j * N + i] = add_point(x, uv, vc);
        }
      }
      // Counter-clockwise in (u, v): the background's orientation (phi preserves it).
      for (std::size_t j = 0; j < M; ++j)
        for (std::size_t i = 0; i < N; ++i)
          out.quads.push_back({grid[j * N + i], grid[j * N + (i + 1) % N],
                               grid[(j + 1) * N + (i + 1) % N], grid[(j + 1) * N + i]});
      R.rows += static_cast<int>(M);
      R.columns = std::max(R.columns, static_cast<int>(N));
    }
    if (collapsed > 0) {
      // The identified points: every quad on the kept one, the others dropped.
      std::vector<LO> renum(out.points.size(), kNoIndex);
      mesh::FaceMesh kept;
      kept.face = out.face;
      for (auto& q : out.quads) {
        for (LO& x : q) {
          x = find_same(x);
          auto& r = renum[static_cast<std::size_t>(x)];
          if (r == kNoIndex) {
            r = static_cast<LO>(kept.points.size());
            kept.points.push_back(out.points[static_cast<std::size_t>(x)]);
            kept.uv.push_back(out.uv[static_cast<std::size_t>(x)]);
            kept.vclass.push_back(out.vclass[static_cast<std::size_t>(x)]);
          }
          x = r;
        }
        for (int i = 0; i < 4; ++i)
          for (int j = i + 1; j < 4; ++j)
            if (q[static_cast<std::size_t>(i)] == q[static_cast<std::size_t>(j)])
              return fail("a quad degenerates where a thin patch is collapsed");
        kept.quads.push_back(q);
      }
      out = std::move(kept);
    }
    if (options.smooth_patches && !placement.group())
      out = smooth::smooth_face(out, *placement.surfaces[0], options.smoothing);
    R.patches = static_cast<int>(cyl.size()) - collapsed;
    R.ok = true;
    R.seconds = clock.seconds();
    return out;
  } catch (const std::exception& e) {
    return fail(std::string("holomorphic: ") + e.what());
  }
}

}  // namespace qsmesh::holomorphic
