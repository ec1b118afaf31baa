// The given field on the face's triangulation: reference frame (Sec. 4), Eq. 2, compatibility
// (Eqs. 11, 16, 17), hole correction (Eqs. 18-20) and alignment (Eq. 14).
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <tuple>

#include "internal.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::fieldmesh {

using detail::kPi;
using detail::wrap;

namespace {

Vec3 uv_normal(const cad::FaceGeometry& surface, const Vec2& uv) {
  const cad::SurfaceEval e = surface.eval(uv);
  return normalized(cross(e.du, e.dv));
}

// Cotangent weights of the triangulation in 3D, as (i, j, w) per edge of each triangle.
template <class F>
void for_cotangent_weights(const mesh::FaceMesh& tri, F&& visit) {
  for (const auto& t : tri.triangles)
    for (int k = 0; k < 3; ++k) {
      const LO i = t[k], j = t[(k + 1) % 3], o = t[(k + 2) % 3];
      const Vec3 a = tri.points[i] - tri.points[o], b = tri.points[j] - tri.points[o];
      const double s = norm(cross(a, b));
      const double w = s > 1e-300 ? std::clamp(0.5 * dot(a, b) / s, -1e3, 1e3) : 0.0;
      visit(i, j, w);
    }
}

std::unique_ptr<linalg::LinearSolver> factorized(const linalg::SparseMatrix& A,
                                                 const linalg::SolverOptions& options,
                                                 linalg::SolverLane* lane) {
  auto solver = linalg::make_solver(A.size(), options, lane);
  solver->analyze(A);
  solver->factorize(A);
  return solver;
}

}  // namespace

Frame face_frame(const mesh::FaceMesh& tri, const cad::FaceGeometry& surface,
                 linalg::SolverLane* lane) {
  const LO n = tri.num_vertices();
  QSMESH_CHECK(n > 0, "face " << tri.face << ": empty triangulation");
  Frame frame;
  frame.normal.resize(n);
  for (LO v = 0; v < n; ++v) frame.normal[v] = uv_normal(surface, tri.uv[v]);
  bool planar = true;
  for (LO v = 0; v < n && planar; ++v) planar = norm(frame.normal[v] - frame.normal[0]) < 1e-6;
  const Vec3 w0 = normalized(surface.eval(tri.uv[0]).du);
  frame.ref.assign(n, w0);
  if (!planar) {
    // Sec. 4, Eq. 21: heat flow of a tangent vector put at vertex 0, with the connection
    // Laplacian (tangent vectors as complex numbers in per-vertex bases e1 = du projected, e2 =
    // n x e1; each edge carries the rotation between its two bases), one implicit step
    // (M + t H) z = M z0 delta_0. H is Hermitian; it is assembled as the real symmetric system of
    // twice the size and factorized as complex (linalg::SolverOptions::complex_pairs). A long time
    // t = diagonal^2 gives the smoothest field (parallel where the surface is developable);
    // normalised, it is the global frame.
    Box3 box;
    for (const auto& p : tri.points) box.add(p);
    const double t = box.diagonal() * box.diagonal();
    std::vector<Vec3> e1(n);
    for (LO v = 0; v < n; ++v) {
      const Vec3 du = surface.eval(tri.uv[v]).du;
      e1[v] = normalized(du - frame.normal[v] * dot(du, frame.normal[v]));
      if (!(norm(e1[v]) > 0))
        detail::refuse("face ", tri.face, ": no tangent basis at vertex ", v, " (pole)");
    }
    std::vector<double> mass(n, 0.0);
    for (const auto& tr : tri.triangles) {
      const double a = 0.5 * norm(cross(tri.points[tr[1]] - tri.points[tr[0]],
                                        tri.points[tr[2]] - tri.points[tr[0]]));
      for (LO v : tr) mass[v] += a / 3;
    }
    std::vector<linalg::SparseMatrix::Triplet> trip;
    auto block = [&](LO i, LO j, double a, double b) {  // H_ij += a + i b
      trip.push_back({2 * i, 2 * j, a});
      trip.push_back({2 * i, 2 * j + 1, -b});
      trip.push_back({2 * i + 1, 2 * j, b});
      trip.push_back({2 * i + 1, 2 * j + 1, a});
    };
    for (LO v = 0; v < n; ++v) block(v, v, mass[v], 0);
    // Edge weights summed over the edge's triangles and clamped at 0: an edge whose opposite
    // angles sum past 180 degrees (the triangulation is Delaunay in the parameter plane, not in
    // 3D) has a negative weight, and with t this large one such edge makes M + t H indefinite
    // (A319 faces 1, 3 and 50: 'not positive definite'). Nonnegative weights keep H a sum of
    // positive semidefinite edge terms w |z_i - r_ij z_j|^2.
    std::map<std::pair<LO, LO>, double> weight;
    for_cotangent_weights(tri, [&](LO i, LO j, double w) { weight[std::minmax(i, j)] += w; });
    for (const auto& [e, w] : weight) {
      if (w <= 0) continue;
      const auto [i, j] = e;
      const Vec3 d = tri.points[j] - tri.points[i];
      const double rho = detail::frame_angle(d, e1[j], frame.normal[j]) -
                         detail::frame_angle(d, e1[i], frame.normal[i]);
      block(i, i, t * w, 0);
      block(j, j, t * w, 0);
      block(i, j, -t * w * std::cos(rho), t * w * std::sin(rho));
      block(j, i, -t * w * std::cos(rho), -t * w * std::sin(rho));
    }
    const linalg::SparseMatrix A(2 * n, trip);
    linalg::SolverOptions hermitian;
    hermitian.complex_pairs = true;  // factorized as the complex matrix it is
    auto solver = factorized(A, hermitian, lane);
    std::vector<double> b(2 * n, 0.0), x(2 * n);
    b[0] = mass[0];
    solver->solve(b, x);
    for (LO v = 0; v < n; ++v) {
      const Vec3 wv = e1[v] * x[2 * v] + cross(frame.normal[v], e1[v]) * x[2 * v + 1];
      if (!(norm(wv) > 0))
        detail::refuse("face ", tri.face, ": the heat-method frame vanishes at vertex ", v);
      frame.ref[v] = normalized(wv);
    }
  } else {
    for (LO v = 0; v < n; ++v)
      frame.ref[v] = normalized(w0 - frame.normal[v] * dot(w0, frame.normal[v]));
  }
  return frame;
}

std::vector<double> field_from_points(const mesh::FaceMesh& tri, const cad::FaceGeometry& surface,
                                      std::span<const SingularPoint> points) {
  // Boundary singular points do not enter Eq. 2: the field turns there by the alignment (Eq. 14
  // with the jump of Eq. 15), not by a factor of the product.
  const std::vector<SingularPoint> interior = detail::split_points(tri, surface, points).interior;
  std::vector<Vec2> a;
  for (const auto& p : interior) a.push_back(surface.project(p.position, tri.uv[0], nullptr));
  std::vector<double> theta(tri.uv.size(), 0.0);
  for (std::size_t v = 0; v < tri.uv.size(); ++v)
    for (std::size_t i = 0; i < a.size(); ++i) {
      const Vec2 d = tri.uv[v] - a[i];
      if (norm(d) > 0) theta[v] += interior[i].d / 4.0 * std::atan2(d.v, d.u);
    }
  return theta;
}

std::vector<double> field_from_directions(const Frame& frame, std::span<const Vec3> directions) {
  QSMESH_CHECK(directions.size() == frame.ref.size(), "one direction per vertex expected");
  std::vector<double> theta(directions.size(), 0.0);
  for (std::size_t v = 0; v < directions.size(); ++v)
    if (norm(directions[v]) > 0)
      theta[v] = detail::frame_angle(directions[v], frame.ref[v], frame.normal[v]);
  return theta;
}

std::vector<SingularPoint> detect_singularities(const mesh::FaceMesh& tri,
                                                std::span<const double> theta) {
  const LO nt = static_cast<LO>(tri.triangles.size());
  std::vector<int> d(nt, 0);
  for (LO t = 0; t < nt; ++t) {
    double turn = 0;
    for (int k = 0; k < 3; ++k)
      turn += wrap(theta[tri.triangles[t][(k + 1) % 3]] - theta[tri.triangles[t][k]], kPi / 2);
    d[t] = static_cast<int>(std::lround(turn / (kPi / 2)));
  }
  // Clusters of singular triangles sharing a vertex are one singular point (their sum).
  std::vector<LO> parent(nt);
  for (LO t = 0; t < nt; ++t) parent[t] = t;
  auto find = [&](LO x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::map<LO, LO> vertex_owner;
  for (LO t = 0; t < nt; ++t) {
    if (d[t] == 0) continue;
    for (LO v : tri.triangles[t]) {
      auto [it, fresh] = vertex_owner.emplace(v, t);
      if (!fresh) parent[find(t)] = find(it->second);
    }
  }
  std::map<LO, std::tuple<int, Vec3, int>> clusters;
  for (LO t = 0; t < nt; ++t) {
    if (d[t] == 0) continue;
    auto& [sum, pos, count] = clusters[find(t)];
    sum += d[t];
    for (LO v : tri.triangles[t]) pos += tri.points[v] / 3.0;
    ++count;
  }
  std::vector<SingularPoint> out;
  for (const auto& [root, c] : clusters)
    if (std::get<0>(c) != 0) out.push_back({std::get<1>(c) / std::get<2>(c), std::get<0>(c)});
  return out;
}

namespace detail {

SplitPoints split_points(const mesh::FaceMesh& tri, const cad::FaceGeometry& surface,
                         std::span<const SingularPoint> points) {
  SplitPoints out;
  if (points.empty()) return out;
  // Boundary edges: the edges of one triangle.
  std::map<std::pair<LO, LO>, int> uses;
  for (const auto& t : tri.triangles)
    for (int k = 0; k < 3; ++k) ++uses[std::minmax(t[k], t[(k + 1) % 3])];
  std::vector<std::pair<LO, LO>> edges;
  for (const auto& [e, n] : uses)
    if (n == 1) edges.push_back(e);
  std::vector<char> taken(tri.points.size(), 0);
  for (const auto& p : points) {
    const Vec3 x = surface.eval(surface.project(p.position, tri.uv[0], nullptr)).p;
    double best = 1e300;
    LO vertex = kNoIndex;
    for (const auto& [a, b] : edges) {
      const Vec3 pa = tri.points[a], e = tri.points[b] - pa;
      const double len2 = dot(e, e);
      if (len2 <= 0) continue;
      const double t = std::clamp(dot(x - pa, e) / len2, 0.0, 1.0);
      const double rel = distance(pa + e * t, x) / std::sqrt(len2);
      if (rel < best) {
        best = rel;
        vertex = t < 0.5 ? a : b;
      }
    }
    if (best >= 0.25) {
      out.interior.push_back(p);
      continue;
    }
    if (taken[vertex])
      refuse("face ", tri.face, ": two boundary singular points on the curve vertex at (",
             tri.points[vertex].x, ", ", tri.points[vertex].y, ", ", tri.points[vertex].z, ")");
    taken[vertex] = 1;
    out.boundary.push_back({vertex, p.d});
  }
  return out;
}

Loops face_loops(const cad::CadModel& model, LO f, std::span<const mesh::CurveMesh> curves,
                 const mesh::FaceMesh& tri, const Frame& frame,
                 std::span<const BoundaryPoint> boundary) {
  const auto surface = model.face_geometry(f);
  Loops L;
  L.loops = background::face_boundary(model, f, *surface, curves);
  std::map<std::tuple<int, LO, LO>, LO> key2tri;
  for (LO v = 0; v < tri.num_vertices(); ++v) {
    const auto& c = tri.vclass[v];
    if (c.dim == 2) continue;
    const auto key = std::make_tuple(int{c.dim}, c.entity, c.dim == 0 ? LO{0} : c.index);
    if (!key2tri.emplace(key, v).second)
      refuse("face ", f, ": a boundary vertex appears twice (seam or pole), not handled");
  }
  auto area = [](const mesh::BoundaryLoop& loop) {
    double a = 0;
    for (std::size_t i = 0; i < loop.points.size(); ++i)
      a += cross(loop.points[i].uv, loop.points[(i + 1) % loop.points.size()].uv);
    return a / 2;
  };
  QSMESH_CHECK(!L.loops.empty(), "face " << f << ": no boundary loop");
  L.uv_reversed = area(L.loops[0]) < 0;
  for (auto& loop : L.loops) {
    if (L.uv_reversed) {
      std::reverse(loop.points.begin(), loop.points.end());
      std::reverse(loop.degenerate.begin(), loop.degenerate.end());
    }
    for (std::uint8_t dg : loop.degenerate)
      if (dg != 0) refuse("face ", f, ": degenerate curve (pole), not handled");
  }
  const std::size_t nl = L.loops.size();
  L.tri.resize(nl);
  L.angle.resize(nl);
  L.quads.resize(nl);
  L.turn.resize(nl);
  L.transport.resize(nl);
  L.tangent.resize(nl);
  L.given.resize(nl);
  std::map<LO, int> given_d;
  for (const auto& b : boundary) given_d[b.vertex] = b.d;
  std::size_t num_given = 0;
  for (std::size_t l = 0; l < nl; ++l) {
    const auto& pts = L.loops[l].points;
    const std::size_t n = pts.size();
    QSMESH_CHECK(n >= 2, "face " << f << ": loop " << l << " has fewer than 2 points");
    for (const auto& p : pts) {
      const auto key = std::make_tuple(int{p.vclass.dim}, p.vclass.entity,
                                       p.vclass.dim == 0 ? LO{0} : p.vclass.index);
      const auto it = key2tri.find(key);
      QSMESH_CHECK(it != key2tri.end(),
                   "face " << f << ": boundary point missing from the triangulation");
      L.tri[l].push_back(it->second);
    }
    L.angle[l].resize(n);
    L.quads[l].assign(n, 0);
    L.turn[l].resize(n);
    L.transport[l].resize(n);
    L.tangent[l].resize(n);
    L.given[l].assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const LO v = L.tri[l][i];
      const Vec3 ein = pts[i].xyz - pts[(i + n - 1) % n].xyz,
                 eout = pts[(i + 1) % n].xyz - pts[i].xyz;
      const double ain = frame_angle(ein, frame.ref[v], frame.normal[v]);
      const double aout = frame_angle(eout, frame.ref[v], frame.normal[v]);
      L.turn[l][i] = wrap(aout - ain, 2 * kPi);
      L.angle[l][i] = kPi - L.turn[l][i];
      if (pts[i].vclass.dim == 0)
        L.quads[l][i] = std::max(1, static_cast<int>(std::lround(L.angle[l][i] / (kPi / 2))));
      if (const auto it = given_d.find(v); it != given_d.end()) {
        // Eq. 15 read backwards: index I leaves 2 - 4 I quads at the point, whatever its angle.
        if (it->second > 1)
          refuse("face ", f, ": a boundary singular point of index ", it->second,
                 "/4: at most 1/4 (one quad)");
        L.quads[l][i] = 2 - it->second;
        L.given[l][i] = 1;
        ++num_given;
      }
      // theta_N: the boundary cross at the point, halfway through the rotation that Eq. 15 leaves
      // to the corner (turn - 2 pi I(b); the whole turn on smooth points).
      L.tangent[l][i] = ain + 0.5 * (L.turn[l][i] - 2 * kPi * corner_index(L.quads[l][i]));
      const LO w = L.tri[l][(i + 1) % n];
      L.transport[l][i] = wrap(frame_angle(eout, frame.ref[w], frame.normal[w]) - aout, 2 * kPi);
    }
  }
  QSMESH_CHECK(num_given == given_d.size(),
               "face " << f << ": a boundary singular point is not on a boundary loop");
  return L;
}

// Change of theta_N from point i to i + 1 of loop l.
double tangent_step(const Loops& L, std::size_t l, std::size_t i) {
  const std::size_t n = L.loops[l].points.size(), j = (i + 1) % n;
  auto half = [&](std::size_t k) {
    return 0.5 * (L.turn[l][k] - 2 * kPi * corner_index(L.quads[l][k]));
  };
  return half(i) + L.transport[l][i] + half(j);
}

Compatibility compatibility(const Loops& L, std::span<const double> theta) {
  Compatibility c;
  double total_field = 0, total_aligned = 0, total_corners = 0;
  std::size_t num_given = 0;
  for (const auto& g : L.given)
    num_given += static_cast<std::size_t>(std::count(g.begin(), g.end(), 1));
  for (std::size_t l = 0; l < L.loops.size(); ++l) {
    const std::size_t n = L.loops[l].points.size();
    LoopDegree d;
    double field = 0, aligned = 0;
    for (std::size_t i = 0; i < n; ++i) {
      field += wrap(theta[L.tri[l][(i + 1) % n]] - theta[L.tri[l][i]], kPi / 2);
      aligned += tangent_step(L, l, i);
      d.corner_indices += corner_index(L.quads[l][i]);
    }
    // Degrees are multiples of 1/4 turn; the sums carry only round-off and discretisation error.
    d.field = std::round(field / (kPi / 2)) / 4;
    d.aligned = std::round(aligned / (kPi / 2)) / 4;
    total_field += d.field;
    total_aligned += d.aligned;
    total_corners += d.corner_indices;
    if (d.field != d.aligned) c.needs_hole_correction = true;
    c.loops.push_back(d);
  }
  std::ostringstream why;
  if (L.loops.size() == 1) {
    c.ok = total_field == total_aligned;
    if (!c.ok)
      why << "Eq. 11 violated: deg(u, boundary) = " << total_field
          << " but chi - sum of boundary indices = " << total_aligned
          << " (boundary indices from the corner angles, Table 1"
          << (num_given > 0 ? ", and the " + std::to_string(num_given) + " given boundary points"
                            : std::string())
          << ": " << total_corners << ")";
    c.needs_hole_correction = false;
  } else {
    c.ok = total_field == total_aligned;
    if (!c.ok)
      why << "Eq. 16 violated: the degrees of the field on the " << L.loops.size()
          << " boundary components sum to " << total_field
          << " but chi - sum of boundary indices = " << total_aligned;
  }
  c.reason = why.str();
  if (c.ok && c.needs_hole_correction) {
    std::ostringstream eq17;
    eq17 << "Eq. 17 does not hold on every boundary component (";
    for (std::size_t l = 0; l < c.loops.size(); ++l)
      eq17 << (l ? ", " : "") << "loop " << l << ": " << c.loops[l].field << " vs "
           << c.loops[l].aligned;
    eq17 << "): corrected around the holes (Eqs. 18-20)";
    c.reason = eq17.str();
  }
  return c;
}

std::vector<double> align_field(const mesh::FaceMesh& tri, const Loops& L,
                                std::span<const double> theta, const Compatibility& compat,
                                const linalg::SolverOptions& solver_options,
                                linalg::SolverLane* lane) {
  const LO n = tri.num_vertices();
  std::vector<double> out(theta.begin(), theta.end());
  // Eqs. 18-20: psi = sum over holes of k arg(z - c), built as Eq. 2 around a point of each hole,
  // so that each loop's degree matches the aligned one (k in quarter turns).
  for (std::size_t l = 1; l < L.loops.size(); ++l) {
    const double mismatch = compat.loops[l].aligned - compat.loops[l].field;
    if (mismatch == 0) continue;
    Vec2 c;
    for (const auto& p : L.loops[l].points)
      c += p.uv / static_cast<double>(L.loops[l].points.size());
    // The winding of arg(z - c) along this loop (-1 for a hole run clockwise).
    double winding = 0;
    const auto& pts = L.loops[l].points;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Vec2 a = pts[i].uv - c, b = pts[(i + 1) % pts.size()].uv - c;
      winding += std::atan2(cross(a, b), dot(a, b));
    }
    const double k = mismatch / std::round(winding / (2 * kPi));
    for (LO v = 0; v < n; ++v) {
      const Vec2 d = tri.uv[v] - c;
      out[v] += k * std::atan2(d.v, d.u);
    }
  }
  // Eq. 14 with Eq. 19: phi~ = theta_N - theta_u - psi along each loop, unwrapped continuously.
  std::vector<double> phi(n, 0.0);
  std::vector<char> fixed(n, 0);
  for (std::size_t l = 0; l < L.loops.size(); ++l) {
    const std::size_t m = L.loops[l].points.size();
    std::vector<double> b(m);
    b[0] = wrap(L.tangent[l][0] - out[L.tri[l][0]], kPi / 2);
    for (std::size_t i = 0; i + 1 < m; ++i)
      b[i + 1] = b[i] + detail::tangent_step(L, l, i) -
                 wrap(out[L.tri[l][i + 1]] - out[L.tri[l][i]], kPi / 2);
    // The branch of each loop (a multiple of pi/2) whose values stay nearest to no rotation.
    double mean = 0;
    for (double x : b) mean += x / static_cast<double>(m);
    const double shift = -kPi / 2 * std::round(mean / (kPi / 2));
    for (std::size_t i = 0; i < m; ++i) {
      phi[L.tri[l][i]] = b[i] + shift;
      fixed[L.tri[l][i]] = 1;
    }
  }
  std::vector<LO> unknown(n, kNoIndex);
  LO nu = 0;
  for (LO v = 0; v < n; ++v)
    if (!fixed[v]) unknown[v] = nu++;
  if (nu > 0) {
    std::vector<linalg::SparseMatrix::Triplet> trip;
    std::vector<double> rhs(nu, 0.0), x(nu, 0.0);
    for (LO v = 0; v < n; ++v)
      if (!fixed[v]) trip.push_back({unknown[v], unknown[v], 1e-14});
    for_cotangent_weights(tri, [&](LO i, LO j, double w) {
      for (auto [a, c] : {std::pair{i, j}, std::pair{j, i}}) {
        if (fixed[a]) continue;
        trip.push_back({unknown[a], unknown[a], w});
        if (fixed[c])
          rhs[unknown[a]] += w * phi[c];
        else
          trip.push_back({unknown[a], unknown[c], -w});
      }
    });
    const linalg::SparseMatrix A(nu, trip);
    auto solver = factorized(A, solver_options, lane);
    solver->solve(rhs, x);
    for (LO v = 0; v < n; ++v)
      if (!fixed[v]) phi[v] = x[unknown[v]];
  }
  for (LO v = 0; v < n; ++v) out[v] += phi[v];
  return out;
}

}  // namespace detail

Compatibility check_compatibility(const cad::CadModel& model, LO f,
                                  std::span<const mesh::CurveMesh> curves,
                                  const mesh::FaceMesh& tri, const Frame& frame,
                                  std::span<const double> theta,
                                  std::span<const SingularPoint> given) {
  const auto surface = model.face_geometry(f);
  const auto split = detail::split_points(tri, *surface, given);
  return detail::compatibility(detail::face_loops(model, f, curves, tri, frame, split.boundary),
                               theta);
}

namespace detail {

Locator::Locator(const mesh::FaceMesh& tri) : tri_(tri) {
  Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
  for (const auto& p : tri.uv) {
    lo = {std::min(lo.u, p.u), std::min(lo.v, p.v)};
    hi = {std::max(hi.u, p.u), std::max(hi.v, p.v)};
  }
  const double side = std::sqrt(std::max(1.0, static_cast<double>(tri.triangles.size())));
  nu_ = nv_ = static_cast<int>(std::clamp(side, 1.0, 512.0));
  lo_ = lo;
  cell_ = {std::max((hi.u - lo.u) / nu_, 1e-300), std::max((hi.v - lo.v) / nv_, 1e-300)};
  bins_.resize(static_cast<std::size_t>(nu_) * nv_);
  for (LO t = 0; t < static_cast<LO>(tri.triangles.size()); ++t) {
    Vec2 a{1e300, 1e300}, b{-1e300, -1e300};
    for (LO v : tri.triangles[t]) {
      a = {std::min(a.u, tri.uv[v].u), std::min(a.v, tri.uv[v].v)};
      b = {std::max(b.u, tri.uv[v].u), std::max(b.v, tri.uv[v].v)};
    }
    const int i0 = std::clamp(static_cast<int>((a.u - lo_.u) / cell_.u), 0, nu_ - 1);
    const int i1 = std::clamp(static_cast<int>((b.u - lo_.u) / cell_.u), 0, nu_ - 1);
    const int j0 = std::clamp(static_cast<int>((a.v - lo_.v) / cell_.v), 0, nv_ - 1);
    const int j1 = std::clamp(static_cast<int>((b.v - lo_.v) / cell_.v), 0, nv_ - 1);
    for (int i = i0; i <= i1; ++i)
      for (int j = j0; j <= j1; ++j) bins_[static_cast<std::size_t>(j) * nu_ + i].push_back(t);
  }
}

LO Locator::locate(const Vec2& uv, std::array<double, 3>& bary) const {
  const double fu = (uv.u - lo_.u) / cell_.u, fv = (uv.v - lo_.v) / cell_.v;
  if (fu < -1e-9 || fv < -1e-9 || fu > nu_ + 1e-9 || fv > nv_ + 1e-9) return kNoIndex;
  const int i = std::clamp(static_cast<int>(fu), 0, nu_ - 1),
            j = std::clamp(static_cast<int>(fv), 0, nv_ - 1);
  LO best = kNoIndex;
  double best_min = -1e300;
  for (LO t : bins_[static_cast<std::size_t>(j) * nu_ + i]) {
    const auto& tr = tri_.triangles[t];
    const Vec2 a = tri_.uv[tr[0]], b = tri_.uv[tr[1]], c = tri_.uv[tr[2]];
    const double area = cross(b - a, c - a);
    if (std::abs(area) < 1e-300) continue;
    const std::array<double, 3> l{cross(b - uv, c - uv) / area, cross(c - uv, a - uv) / area,
                                  cross(a - uv, b - uv) / area};
    const double mn = std::min({l[0], l[1], l[2]});
    if (mn > best_min) {
      best_min = mn;
      best = t;
      bary = l;
    }
  }
  // A small tolerance keeps points on the boundary inside.
  return best_min >= -1e-9 ? best : kNoIndex;
}

FieldSample sample_field(const Locator& locator, const mesh::FaceMesh& tri, const Frame& frame,
                         std::span<const double> theta, const Vec2& uv) {
  FieldSample s;
  std::array<double, 3> l{};
  const LO t = locator.locate(uv, l);
  if (t == kNoIndex) return s;
  s.inside = true;
  // The representation vector (cos 4 theta, sin 4 theta) is what varies smoothly (Sec. 2.1).
  double c = 0, sn = 0;
  for (int k = 0; k < 3; ++k) {
    const LO v = tri.triangles[t][k];
    c += l[k] * std::cos(4 * theta[v]);
    sn += l[k] * std::sin(4 * theta[v]);
    s.ref += frame.ref[v] * l[k];
    s.normal += frame.normal[v] * l[k];
  }
  s.theta = std::atan2(sn, c) / 4;
  s.magnitude = std::hypot(c, sn);
  s.normal = normalized(s.normal);
  s.ref = normalized(s.ref - s.normal * dot(s.ref, s.normal));
  return s;
}

Vec2 uv_direction(const cad::FaceGeometry& surface, const Vec2& uv, const Vec3& w) {
  const cad::SurfaceEval e = surface.eval(uv);
  const double a = dot(e.du, e.du), b = dot(e.du, e.dv), c = dot(e.dv, e.dv);
  const double r0 = dot(e.du, w), r1 = dot(e.dv, w), det = a * c - b * b;
  if (std::abs(det) < 1e-300) return {};
  return {(c * r0 - b * r1) / det, (a * r1 - b * r0) / det};
}

}  // namespace detail
}  // namespace qsmesh::fieldmesh
