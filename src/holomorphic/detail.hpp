// Helpers shared by the annulus grid (annulus.cpp) and the patch meshing of poly-annuli with
// b >= 3 loops (patches.cpp): integration of a 1-form over the triangles, point location in the
// form's coordinates, the final boundary with seam copies merged, and the grid's harmonic u.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <map>
#include <numbers>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "qsmesh/holomorphic/holomorphic.hpp"

namespace qsmesh::holomorphic::detail {

using Key = std::tuple<int, LO, LO>;
inline Key point_key(const mesh::VertexClass& c) {
  return c.dim == 0 ? Key{0, c.entity, 0} : Key{1, c.entity, c.index};
}

using C = std::complex<double>;

// The integral of phi on each triangle corner: a spanning tree of the triangles carries the
// values across shared edges; across the other edges they differ by a period.
inline std::vector<std::array<C, 3>> integrate(const PolyAnnulus& s, std::span<const C> phi) {
  const std::size_t nt = s.triangles.size();
  std::vector<std::array<C, 3>> U(nt);
  std::vector<char> done(nt, 0);
  auto dir = [&](LO from, LO e) {
    return s.edges[static_cast<std::size_t>(e)][0] == from ? phi[static_cast<std::size_t>(e)]
                                                           : -phi[static_cast<std::size_t>(e)];
  };
  auto fill_from = [&](std::size_t t, int k0, C value) {
    // corner k0 has `value`; the others follow along the triangle's edges.
    const auto& c = s.triangles[t];
    U[t][k0] = value;
    const int k1 = (k0 + 1) % 3, k2 = (k0 + 2) % 3;
    U[t][k1] = value + dir(c[k0], s.tri_edges[t][k0]);
    U[t][k2] = U[t][k1] + dir(c[k1], s.tri_edges[t][k1]);
  };
  fill_from(0, 0, C{0, 0});
  done[0] = 1;
  std::vector<std::size_t> queue{0};
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t t = queue[head];
    for (int k = 0; k < 3; ++k) {
      const auto& et = s.edge_tris[static_cast<std::size_t>(s.tri_edges[t][k])];
      if (et[1] == kNoIndex) continue;
      const auto u = static_cast<std::size_t>(static_cast<std::size_t>(et[0]) == t ? et[1] : et[0]);
      if (done[u] != 0) continue;
      const LO a = s.triangles[t][k];
      const int ka = static_cast<int>(std::find(s.triangles[u].begin(), s.triangles[u].end(), a) -
                                      s.triangles[u].begin());
      fill_from(u, ka, U[t][k]);
      done[u] = 1;
      queue.push_back(u);
    }
  }
  return U;
}

inline double wrap(double x, double period) { return x - period * std::round(x / period); }

// Point location in the integrated (multi-valued in u) parameter plane.
class Locator {
 public:
  Locator(const std::vector<std::array<C, 3>>& U, double period, double vmin, double vmax)
      : U_(U), P_(period), vmin_(vmin), vmax_(vmax) {
    nu_ = nv_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::sqrt(double(U.size()) / 2)));
    cells_.resize(nu_ * nv_);
    for (std::size_t t = 0; t < U.size(); ++t) {
      const double shift = -P_ * std::floor(U[t][0].real() / P_);
      double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
      for (const C& z : U[t]) {
        u0 = std::min(u0, z.real() + shift);
        u1 = std::max(u1, z.real() + shift);
        v0 = std::min(v0, z.imag());
        v1 = std::max(v1, z.imag());
      }
      const long iu0 = std::lround(std::floor(u0 / P_ * double(nu_))),
                 iu1 = std::lround(std::floor(u1 / P_ * double(nu_)));
      const std::size_t iv0 = vcell(v0), iv1 = vcell(v1);
      for (long iu = iu0; iu <= iu1; ++iu)
        for (std::size_t iv = iv0; iv <= iv1; ++iv)
          cells_[ucell_wrap(iu) * nv_ + iv].push_back(static_cast<LO>(t));
    }
  }
  // Triangle and barycentric coordinates of (u, v); the triangle whose smallest coordinate is
  // largest when none contains it (a point a rounding error outside).
  std::pair<LO, std::array<double, 3>> locate(double u, double v) const {
    const double un = u - P_ * std::floor(u / P_);
    const auto& cell =
        cells_[ucell_wrap(std::lround(std::floor(un / P_ * double(nu_)))) * nv_ + vcell(v)];
    LO best = kNoIndex;
    std::array<double, 3> best_bary{};
    double best_min = -1e300;
    auto test = [&](LO t) {
      const auto& z = U_[static_cast<std::size_t>(t)];
      const double mean = (z[0].real() + z[1].real() + z[2].real()) / 3;
      const double q = u + P_ * std::round((mean - u) / P_);
      const C p{q, v};
      const double area = cross2(z[1] - z[0], z[2] - z[0]);
      if (area == 0) return;
      const std::array<double, 3> b{cross2(z[1] - p, z[2] - p) / area,
                                    cross2(z[2] - p, z[0] - p) / area,
                                    cross2(z[0] - p, z[1] - p) / area};
      const double m = std::min({b[0], b[1], b[2]});
      if (m > best_min) {
        best_min = m;
        best = t;
        best_bary = b;
      }
    };
    for (const LO t : cell) test(t);
    if (best_min < -1e-9)
      for (LO t = 0; t < static_cast<LO>(U_.size()); ++t) test(t);
    return {best, best_bary};
  }
  double worst_outside = 0;

 private:
  static double cross2(C a, C b) { return a.real() * b.imag() - a.imag() * b.real(); }
  std::size_t vcell(double v) const {
    const double x = (v - vmin_) / (vmax_ - vmin_) * double(nv_);
    return static_cast<std::size_t>(std::clamp<long>(std::lround(std::floor(x)), 0, long(nv_) - 1));
  }
  std::size_t ucell_wrap(long iu) const {
    const long n = static_cast<long>(nu_);
    return static_cast<std::size_t>(((iu % n) + n) % n);
  }
  const std::vector<std::array<C, 3>>& U_;
  double P_, vmin_, vmax_;
  std::size_t nu_ = 1, nv_ = 1;
  std::vector<std::vector<LO>> cells_;
};

// The final boundary with seam copies merged: the points (all uv copies kept), the boundary
// cycles (edges used once) and the seam chains (edges used in both directions).
struct FinalBoundary {
  std::vector<mesh::BoundaryPoint> points;   // one per merged point (first copy)
  std::vector<std::vector<Vec2>> uv_copies;  // every uv the loops give it
  std::vector<std::vector<LO>> cycles;
  std::vector<std::pair<LO, LO>> seam_edges;  // undirected
};

inline FinalBoundary merge_final(std::span<const mesh::BoundaryLoop> loops, std::string* why) {
  FinalBoundary F;
  std::map<Key, LO> ids;
  std::map<std::pair<LO, LO>, int> directed;
  for (const auto& loop : loops) {
    std::vector<LO> m;
    for (const auto& p : loop.points) {
      const auto [it, added] =
          ids.try_emplace(point_key(p.vclass), static_cast<LO>(F.points.size()));
      if (added) {
        F.points.push_back(p);
        F.uv_copies.emplace_back();
      }
      F.uv_copies[static_cast<std::size_t>(it->second)].push_back(p.uv);
      m.push_back(it->second);
    }
    for (std::size_t i = 0; i < m.size(); ++i) {
      const LO a = m[i], b = m[(i + 1) % m.size()];
      if (a != b) ++directed[{a, b}];
    }
  }
  std::map<LO, LO> next;
  for (const auto& [e, count] : directed) {
    const bool back = directed.count({e.second, e.first}) != 0;
    if (back) {
      if (e.first < e.second) F.seam_edges.emplace_back(e.first, e.second);
      continue;
    }
    if (count != 1 || next.count(e.first) != 0) {
      *why = "the final boundary is not a set of simple cycles";
      return {};
    }
    next[e.first] = e.second;
  }
  std::map<LO, char> used;
  for (const auto& [start, unused] : next) {
    if (used.count(start) != 0) continue;
    std::vector<LO> cycle;
    LO v = start;
    do {
      cycle.push_back(v);
      used[v] = 1;
      const auto it = next.find(v);
      if (it == next.end()) {
        *why = "an open final boundary chain";
        return {};
      }
      v = it->second;
    } while (v != start && cycle.size() <= F.points.size());
    F.cycles.push_back(std::move(cycle));
  }
  return F;
}

// Why a grid with two quads at every boundary vertex would fold on F (a loop turning by more than
// max_turn_deg at a CAD corner: a level of the form is straight in its flat metric, so the corner
// is flattened and a sharp one needs one or three quads); empty when no corner does.
inline std::string sharp_corner_on_a_loop(const FinalBoundary& F, double max_turn_deg) {
  for (const auto& cycle : F.cycles)
    for (std::size_t i = 0; i < cycle.size(); ++i) {
      const auto& p = F.points[static_cast<std::size_t>(cycle[i])];
      if (p.vclass.dim != 0) continue;
      const Vec3& a =
          F.points[static_cast<std::size_t>(cycle[(i + cycle.size() - 1) % cycle.size()])].xyz;
      const Vec3& c = F.points[static_cast<std::size_t>(cycle[(i + 1) % cycle.size()])].xyz;
      const double turn =
          std::acos(std::clamp(dot(normalized(p.xyz - a), normalized(c - p.xyz)), -1.0, 1.0));
      if (turn > max_turn_deg * std::numbers::pi / 180)
        return "a loop turns by " + std::to_string(std::lround(turn * 180 / std::numbers::pi)) +
               " degrees at corner " + std::to_string(p.vclass.entity) +
               ": the grid would fold there";
    }
  return {};
}

// u at grid point (i, j), i in [0, N], j in [0, M], row-major by j: the rows' ends on the two
// loops (a and b, N + 1 unwrapped values each, the last one period beyond the first), rows at the
// levels `rows` (M + 1 increasing values of v), interior values solved from the 5-point Laplacian
// of the grid with column spacing period / N and the rows' spacings (SOR; u of column N is u of
// column 0 plus the period; `seam_u`, when not empty, fixes column 0: the seam's vertices).
inline std::vector<double> grid_u(const std::vector<double>& a, const std::vector<double>& b,
                                  const std::vector<double>& rows, double period,
                                  const std::vector<double>& seam_u, const GridOptions& options) {
  const std::size_t N = a.size() - 1, M = rows.size() - 1;
  const bool seam = !seam_u.empty();
  const double height = rows.back() - rows.front();
  std::vector<double> u((M + 1) * (N + 1));
  for (std::size_t j = 0; j <= M; ++j)
    for (std::size_t i = 0; i <= N; ++i) {
      const double t = (rows[j] - rows.front()) / height;
      u[j * (N + 1) + i] = a[i] + t * (b[i] - a[i]);
    }
  if (seam)
    for (std::size_t j = 0; j <= M; ++j) {
      u[j * (N + 1)] = seam_u[j];
      u[j * (N + 1) + N] = seam_u[j] + period;
    }
  if (M < 2 || options.max_sweeps <= 0) return u;
  const double du = period / double(N);
  const double wi = 1 / (du * du);
  const double omega = options.relaxation;
  for (int sweep = 0; sweep < options.max_sweeps; ++sweep) {
    double change = 0;
    for (std::size_t j = 1; j < M; ++j) {
      const double hm = rows[j] - rows[j - 1], hp = rows[j + 1] - rows[j];
      const double wm = 2 / (hm * (hm + hp)), wp = 2 / (hp * (hm + hp));
      for (std::size_t i = seam ? 1 : 0; i < N; ++i) {
        const double left = i > 0 ? u[j * (N + 1) + i - 1] : u[j * (N + 1) + N - 1] - period;
        const double right = u[j * (N + 1) + i + 1];
        const double target =
            (wi * (left + right) + wm * u[(j - 1) * (N + 1) + i] + wp * u[(j + 1) * (N + 1) + i]) /
            (2 * wi + wm + wp);
        const double delta = omega * (target - u[j * (N + 1) + i]);
        u[j * (N + 1) + i] += delta;
        change = std::max(change, std::abs(delta));
        if (i == 0 && !seam) u[j * (N + 1) + N] = u[j * (N + 1)] + period;
      }
    }
    if (change < options.tolerance * du) break;
  }
  return u;
}

// Where the meshers put a point they found inside background triangle t: projected on the CAD
// face of that triangle. One face (one surface, triangle_part empty), or a glued group of faces
// (group.hpp), whose triangles come from several faces.
struct Placement {
  std::span<const cad::FaceGeometry* const> surfaces;  // per part
  std::span<const LO> faces;                           // CAD face of each part
  std::span<const LO> triangle_part;                   // per triangle; empty: all on part 0
  [[nodiscard]] bool group() const { return !triangle_part.empty(); }
  [[nodiscard]] LO part(LO t) const {
    return triangle_part.empty() ? 0 : triangle_part[static_cast<std::size_t>(t)];
  }
  // x projected on the face of triangle t, searched from guess (a parameter point of that face).
  void place(LO t, const Vec3& x, const Vec2& guess, Vec3* foot, Vec2* uv,
             mesh::VertexClass* vc) const {
    const auto p = static_cast<std::size_t>(part(t));
    *uv = surfaces[p]->project(x, guess, foot);
    *vc = interior(p, *uv);
  }
  [[nodiscard]] mesh::VertexClass interior(std::size_t p, const Vec2& uv) const {
    mesh::VertexClass vc;
    vc.dim = 2;
    vc.entity = faces[p];
    vc.param = {uv.u, uv.v};
    return vc;
  }
};

// mesh_annulus on the poly-annulus `s` of `background` already found (mesh_poly_annulus finds
// it to count the loops). With a group placement, curves traversed both ways by the final loops
// are the group's inner curves (and seams), not a seam joining the two loops: no seam column.
mesh::FaceMesh mesh_annulus_of(const PolyAnnulus& s, const mesh::FaceMesh& background,
                               std::span<const mesh::BoundaryLoop> loops, const Placement& place,
                               const HolomorphicOptions& options, HolomorphicReport* report);

// mesh_poly_annulus with its points placed by `place`; a group's patches are not smoothed (the
// smoother works in one face's parameter plane), and its inner curves are allowed where a single
// face's seam is refused.
mesh::FaceMesh mesh_poly_annulus_of(const mesh::FaceMesh& background,
                                    std::span<const mesh::BoundaryLoop> loops,
                                    const Placement& place, const HolomorphicOptions& options,
                                    HolomorphicReport* report);

}  // namespace qsmesh::holomorphic::detail
