// Quad mesh of a topological annulus from its holomorphic 1-form (paper 004 Sec. 4, "Quad-mesh
// generation", in the case without zeros: one patch, the whole face), and the per-face method.
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <tuple>

#include "detail.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/holomorphic/holomorphic.hpp"

namespace qsmesh::holomorphic {

using detail::C;
using detail::FinalBoundary;
using detail::grid_u;
using detail::integrate;
using detail::Locator;
using detail::merge_final;
using detail::wrap;

mesh::FaceMesh detail::mesh_annulus_of(const PolyAnnulus& s, const mesh::FaceMesh& background,
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
    R.boundaries = static_cast<LO>(s.loops.size());
    if (!s.ok) return fail("not a poly-annulus: " + s.reason);
    if (s.loops.size() != 2)
      return fail("b = " + std::to_string(s.loops.size()) +
                  " boundary loops: not an annulus (mesh_poly_annulus meshes b >= 3)");
    const HolomorphicBasis B = holomorphic_basis(s, options.basis, nullptr);
    R.basis_seconds = B.seconds;
    const EnergyResult E = minimize_area_distortion(s, B, options.energy);
    R.energy = E.energy;
    R.energy_seconds = E.seconds;
    const auto phi = combine(B, E.lambda);
    const ZeroReport Z = find_zeros(s, phi);
    R.zeros = static_cast<LO>(Z.interior.size());
    if (!Z.interior.empty())
      return fail("the form has " + std::to_string(Z.interior.size()) + " interior zeros (" +
                  std::to_string(Z.flipped) + " in flipped triangles)");
    const auto U = integrate(s, phi);

    // Period around the annulus, and the level of v on each background loop.
    double period = 0;
    // Boundary edge -> (triangle, corner of its start), for the values along the loops.
    std::vector<std::pair<LO, int>> bedge(s.edges.size(), {kNoIndex, 0});
    for (std::size_t t = 0; t < s.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k)
        if (s.edge_tris[static_cast<std::size_t>(s.tri_edges[t][k])][1] == kNoIndex)
          bedge[static_cast<std::size_t>(s.tri_edges[t][k])] = {static_cast<LO>(t), k};
    for (std::size_t e = 0; e < s.edges.size(); ++e) {
      if (bedge[e].first == kNoIndex) continue;
      const auto [t, k] = bedge[e];
      const C d = U[static_cast<std::size_t>(t)][(k + 1) % 3] - U[static_cast<std::size_t>(t)][k];
      if (s.edge_loop[e] == 1) period += d.real();
    }
    period = std::abs(period);
    if (!(period > 0)) return fail("the form has no period around the annulus");

    std::string why;
    FinalBoundary F = merge_final(loops, &why);
    if (!why.empty()) return fail(why);
    // A group's inner curves are traversed both ways like a seam, but cross no column.
    if (placement.group()) F.seam_edges.clear();
    if (F.cycles.size() != 2)
      return fail("the final boundary has " + std::to_string(F.cycles.size()) + " cycles, not 2");
    // Each loop is a horizontal trajectory, straight in the form's flat metric.
    if (std::string sharp = sharp_corner_on_a_loop(F, options.max_corner_turn_deg); !sharp.empty())
      return fail(sharp);

    // (u, v) of every final boundary point: on the nearest background boundary edge.
    std::vector<C> uv_of(F.points.size());
    for (std::size_t p = 0; p < F.points.size(); ++p) {
      const Vec3& x = F.points[p].xyz;
      double best = 1e300;
      for (std::size_t e = 0; e < s.edges.size(); ++e) {
        if (bedge[e].first == kNoIndex) continue;
        const auto [t, k] = bedge[e];
        const auto& c = s.triangles[static_cast<std::size_t>(t)];
        const Vec3& a = s.points[static_cast<std::size_t>(c[k])];
        const Vec3& b = s.points[static_cast<std::size_t>(c[(k + 1) % 3])];
        const Vec3 ab = b - a;
        const double l2 = dot(ab, ab);
        const double w = l2 > 0 ? std::clamp(dot(x - a, ab) / l2, 0.0, 1.0) : 0.0;
        const double d = norm2(a + ab * w - x);
        if (d < best) {
          best = d;
          const auto& z = U[static_cast<std::size_t>(t)];
          uv_of[p] = z[k] + (z[(k + 1) % 3] - z[k]) * w;
        }
      }
    }
    // Unwrap u along each cycle; make u increase; cycle 0 at the lower v.
    std::array<std::vector<LO>, 2> cyc{F.cycles[0], F.cycles[1]};
    std::array<double, 2> v{};
    for (int c = 0; c < 2; ++c) {
      const auto& cy = cyc[static_cast<std::size_t>(c)];
      double total = 0;
      for (std::size_t i = 0; i < cy.size(); ++i)
        total += wrap(uv_of[static_cast<std::size_t>(cy[(i + 1) % cy.size()])].real() -
                          uv_of[static_cast<std::size_t>(cy[i])].real(),
                      period);
      if (std::abs(std::abs(total) - period) > 1e-6 * period)
        return fail("a final loop does not go once around the annulus");
      if (total < 0)
        std::reverse(cyc[static_cast<std::size_t>(c)].begin(),
                     cyc[static_cast<std::size_t>(c)].end());
      v[static_cast<std::size_t>(c)] =
          uv_of[static_cast<std::size_t>(cyc[static_cast<std::size_t>(c)][0])].imag();
    }
    if (v[0] > v[1]) {
      std::swap(cyc[0], cyc[1]);
      std::swap(v[0], v[1]);
    }
    const std::size_t N = cyc[0].size();
    if (cyc[1].size() != N)
      return fail("loop counts differ (" + std::to_string(cyc[0].size()) + " and " +
                  std::to_string(cyc[1].size()) +
                  "): a grid without singularity needs equal counts");
    const double height = v[1] - v[0];
    if (!(height > 0)) return fail("the two loops are at the same level");

    // Columns: the seam (when there is one) is column 0 and fixes the rows; else the rotation of
    // the second loop with the least twist, and rows from the modulus.
    std::size_t M = 0;
    std::size_t start0 = 0, start1 = 0;
    std::vector<LO> seam_chain;
    if (!F.seam_edges.empty()) {
      std::map<LO, std::vector<LO>> adj;
      for (const auto& [a, b] : F.seam_edges) {
        adj[a].push_back(b);
        adj[b].push_back(a);
      }
      const auto on0 =
          std::find_if(cyc[0].begin(), cyc[0].end(), [&](LO p) { return adj.count(p) != 0; });
      if (on0 == cyc[0].end()) return fail("the seam does not start on a loop");
      LO prev = kNoIndex, cur = *on0;
      seam_chain.push_back(cur);
      while (true) {
        const auto& nb = adj[cur];
        LO nxt = kNoIndex;
        for (const LO w : nb)
          if (w != prev) nxt = w;
        if (nxt == kNoIndex || seam_chain.size() > F.points.size()) break;
        seam_chain.push_back(nxt);
        prev = cur;
        cur = nxt;
        if (adj[cur].size() == 1) break;
      }
      const auto on1 = std::find(cyc[1].begin(), cyc[1].end(), seam_chain.back());
      if (on1 == cyc[1].end() || adj[seam_chain.back()].size() != 1)
        return fail("the seam does not join the two loops");
      start0 = static_cast<std::size_t>(on0 - cyc[0].begin());
      start1 = static_cast<std::size_t>(on1 - cyc[1].begin());
      M = seam_chain.size() - 1;
    } else {
      double best = 1e300;
      for (std::size_t sh = 0; sh < N; ++sh) {
        double cost = 0;
        for (std::size_t i = 0; i < N; ++i) {
          const double d = wrap(uv_of[static_cast<std::size_t>(cyc[1][(i + sh) % N])].real() -
                                    uv_of[static_cast<std::size_t>(cyc[0][i])].real(),
                                period);
          cost += d * d;
        }
        if (cost < best) {
          best = cost;
          start1 = sh;
        }
      }
      M = std::max<std::size_t>(1,
                                static_cast<std::size_t>(std::lround(height * double(N) / period)));
    }
    std::rotate(cyc[0].begin(), cyc[0].begin() + static_cast<long>(start0), cyc[0].end());
    std::rotate(cyc[1].begin(), cyc[1].begin() + static_cast<long>(start1), cyc[1].end());
    std::array<std::vector<double>, 2> uu;
    for (int c = 0; c < 2; ++c) {
      auto& out = uu[static_cast<std::size_t>(c)];
      const auto& cy = cyc[static_cast<std::size_t>(c)];
      out.push_back(uv_of[static_cast<std::size_t>(cy[0])].real());
      for (std::size_t i = 1; i <= N; ++i)
        out.push_back(out.back() + wrap(uv_of[static_cast<std::size_t>(cy[i % N])].real() -
                                            uv_of[static_cast<std::size_t>(cy[i - 1])].real(),
                                        period));
    }
    const double shift = uu[1][0] - wrap(uu[1][0] - uu[0][0], period) - uu[0][0];
    for (double& x : uu[1]) x -= shift;

    R.rows = static_cast<int>(M);
    R.columns = static_cast<int>(N);
    const bool seam = !seam_chain.empty();
    const std::size_t ncol = seam ? N + 1 : N;
    Locator locator(U, period, v[0], v[1]);
    mesh::FaceMesh out;
    out.face = background.face;
    std::vector<LO> grid((M + 1) * (N + 1), kNoIndex);
    auto at = [&](std::size_t i, std::size_t j) -> LO& { return grid[j * (N + 1) + i]; };
    auto add_point = [&](const Vec3& x, const Vec2& uv, const mesh::VertexClass& vc) {
      out.points.push_back(x);
      out.uv.push_back(uv);
      out.vclass.push_back(vc);
      return static_cast<LO>(out.points.size() - 1);
    };
    // u of the grid points: rows are the levels of v (horizontal trajectories), columns start
    // straight between the two loops' points, then u is made discrete-harmonic over the grid
    // (boundary rows and the seam column fixed), which spreads a difference between the two
    // loops' spacings over the rows instead of shearing each column.
    // Row levels: equal steps of v, or the seam's vertices' levels (its curve mesh is graded as
    // the quantization placed it, and a row must pass through each of its vertices).
    std::vector<double> rows(M + 1), seam_u;
    for (std::size_t j = 0; j <= M; ++j) rows[j] = v[0] + height * double(j) / double(M);
    if (seam) {
      const LO seam_curve =
          F.points[static_cast<std::size_t>(seam_chain[1 % seam_chain.size()])].vclass.entity;
      std::vector<char> on_seam(s.points.size(), 0);
      for (std::size_t w = 0; w < background.vclass.size(); ++w) {
        const auto& vc = background.vclass[w];
        if (vc.dim == 0 || (vc.dim == 1 && vc.entity == seam_curve))
          on_seam[static_cast<std::size_t>(s.face2merged[w])] = 1;
      }
      for (std::size_t j = 1; j < M; ++j) {
        const Vec3& x = F.points[static_cast<std::size_t>(seam_chain[j])].xyz;
        double best = 1e300, useam = 0;
        for (std::size_t e = 0; e < s.edges.size(); ++e) {
          const auto& ed = s.edges[e];
          if (on_seam[static_cast<std::size_t>(ed[0])] == 0 ||
              on_seam[static_cast<std::size_t>(ed[1])] == 0)
            continue;
          const Vec3& p = s.points[static_cast<std::size_t>(ed[0])];
          const Vec3 ab = s.points[static_cast<std::size_t>(ed[1])] - p;
          const double l2 = dot(ab, ab);
          const double w = l2 > 0 ? std::clamp(dot(x - p, ab) / l2, 0.0, 1.0) : 0.0;
          const double d = norm2(p + ab * w - x);
          if (d < best) {
            best = d;
            // Both ends' values from one triangle of the edge: one branch of u.
            const auto t = static_cast<std::size_t>(s.edge_tris[e][0]);
            const auto& c = s.triangles[t];
            const auto k0 =
                static_cast<std::size_t>(std::find(c.begin(), c.end(), ed[0]) - c.begin());
            const auto k1 =
                static_cast<std::size_t>(std::find(c.begin(), c.end(), ed[1]) - c.begin());
            const C z = U[t][k0] + w * (U[t][k1] - U[t][k0]);
            rows[j] = z.imag();
            useam = z.real();
          }
        }
        seam_u.push_back(useam);
        if (!(rows[j] > rows[j - 1])) return fail("the seam's vertices are not in order along it");
      }
      if (!(rows[M] > rows[M - 1])) return fail("the seam's vertices are not in order along it");
      // The seam's u on the branch of the loops' column 0, continued along it.
      seam_u.insert(seam_u.begin(), uu[0][0]);
      for (std::size_t j = 1; j < M; ++j)
        seam_u[j] = seam_u[j - 1] + wrap(seam_u[j] - seam_u[j - 1], period);
      seam_u.push_back(seam_u.back() + wrap(uu[1][0] - seam_u.back(), period));
      if (std::abs(seam_u.back() - uu[1][0]) > 1e-6 * period)
        return fail("the seam does not end where the second loop's column 0 is");
    }
    const std::vector<double> ugrid = grid_u(uu[0], uu[1], rows, period, seam_u, options.grid);
    auto u_at = [&](std::size_t i, std::size_t j) { return ugrid[j * (N + 1) + i]; };
    // Interior grid points first (the seam column's copies take their uv from them).
    for (std::size_t j = 1; j < M; ++j) {
      for (std::size_t i = seam ? 1 : 0; i < N; ++i) {
        const double uq = u_at(i, j);
        const double vq = rows[j];
        const auto [t, b] = locator.locate(uq, vq);
        if (t == kNoIndex) return fail("a grid point could not be located");
        const auto& ft = background.triangles[static_cast<std::size_t>(t)];
        Vec3 x{0, 0, 0};
        Vec2 guess{0, 0};
        for (int k = 0; k < 3; ++k) {
          x = x + background.points[static_cast<std::size_t>(ft[k])] * b[k];
          guess = guess + background.uv[static_cast<std::size_t>(ft[k])] * b[k];
        }
        Vec3 foot;
        Vec2 uv;
        mesh::VertexClass vc;
        placement.place(t, x, guess, &foot, &uv, &vc);
        at(i, j) = add_point(foot, uv, vc);
      }
    }
    // Boundary rows and the seam column: the final boundary's points, the copy of uv nearest the
    // neighbouring column on that side.
    auto place = [&](LO p, std::size_t i, std::size_t j) {
      const auto& bp = F.points[static_cast<std::size_t>(p)];
      Vec2 uv = bp.uv;
      const auto& copies = F.uv_copies[static_cast<std::size_t>(p)];
      if (seam && copies.size() > 1) {
        const std::size_t ni = i == 0 ? 1 : N - 1;
        const std::size_t nj = std::clamp<std::size_t>(j, 1, std::max<std::size_t>(1, M - 1));
        const LO nb = M > 1 ? at(ni, nj) : kNoIndex;
        if (nb != kNoIndex) {
          const Vec2 ref = out.uv[static_cast<std::size_t>(nb)];
          uv = *std::min_element(copies.begin(), copies.end(), [&](const Vec2& a, const Vec2& c) {
            return norm(a - ref) < norm(c - ref);
          });
        } else {
          uv = i == 0 ? copies.front() : copies.back();
        }
      }
      at(i, j) = add_point(bp.xyz, uv, bp.vclass);
    };
    for (std::size_t i = 0; i < ncol; ++i) {
      place(cyc[0][i % N], i, 0);
      place(cyc[1][i % N], i, M);
    }
    if (seam)
      for (std::size_t j = 1; j < M; ++j) {
        place(seam_chain[j], 0, j);
        place(seam_chain[j], N, j);
      }
    if (!seam)
      for (std::size_t j = 0; j <= M; ++j) at(N, j) = at(0, j);
    // Counter-clockwise in (u, v) with v increasing upwards: the background's orientation, since
    // phi preserves it (no flipped triangle).
    for (std::size_t j = 0; j < M; ++j)
      for (std::size_t i = 0; i < N; ++i)
        out.quads.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
    R.ok = true;
    R.seconds = clock.seconds();
    return out;
  } catch (const std::exception& e) {
    return fail(std::string("holomorphic: ") + e.what());
  }
}

mesh::FaceMesh mesh_annulus(const mesh::FaceMesh& background,
                            std::span<const mesh::BoundaryLoop> loops,
                            const cad::FaceGeometry& surface, const HolomorphicOptions& options,
                            HolomorphicReport* report) {
  const cad::FaceGeometry* const one[] = {&surface};
  const LO face[] = {background.face};
  return detail::mesh_annulus_of(poly_annulus(background), background, loops,
                                 detail::Placement{one, face, {}}, options, report);
}

Method parse_method(const std::string& text) {
  if (text == "default") return Method::Default;
  if (text == "holomorphic") return Method::Holomorphic;
  if (text == "auto") return Method::Auto;
  throw InputError("--method: expected default, holomorphic or auto, got '" + text + "'");
}

bool keep_holomorphic(Method method, const HolomorphicReport& report,
                      const mesh::FaceQuadStats& holomorphic, const mesh::FaceQuadStats& by_default,
                      double sicn_tolerance) {
  if (method == Method::Default || !report.ok || holomorphic.quads == 0 ||
      holomorphic.triangles != 0 || !(holomorphic.sicn_min > 0))
    return false;
  if (method == Method::Holomorphic) return true;
  return holomorphic.irregular_interior < by_default.irregular_interior &&
         holomorphic.sicn_min >= by_default.sicn_min - sicn_tolerance &&
         holomorphic.sicn_avg >= by_default.sicn_avg - sicn_tolerance;
}

}  // namespace qsmesh::holomorphic
