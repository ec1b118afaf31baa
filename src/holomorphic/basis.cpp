// Poly-annulus detection and the holomorphic 1-form basis (paper 004 Sec. 4).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <queue>
#include <tuple>

#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/holomorphic/holomorphic.hpp"

namespace qsmesh::holomorphic {
namespace {

using Key = std::tuple<int, LO, LO>;

// Copies of one CAD vertex (the two banks of a seam) carry the same classification; interior
// vertices are unique.
Key merge_key(const mesh::VertexClass& c, LO vertex) {
  if (c.dim == 0) return {0, c.entity, 0};
  if (c.dim == 1) return {1, c.entity, c.index};
  return {2, vertex, 0};
}

double cot_at(const Vec3& apex, const Vec3& p, const Vec3& q) {
  const Vec3 a = p - apex, b = q - apex;
  const double s = norm(cross(a, b));
  return s > 0 ? dot(a, b) / s : 0.0;
}

}  // namespace

PolyAnnulus poly_annulus(const mesh::FaceMesh& mesh) {
  PolyAnnulus s;
  std::map<Key, LO> ids;
  s.face2merged.resize(mesh.points.size());
  for (LO v = 0; v < mesh.num_vertices(); ++v) {
    const auto [it, added] =
        ids.try_emplace(merge_key(mesh.vclass[static_cast<std::size_t>(v)], v), s.num_vertices());
    if (added) s.points.push_back(mesh.points[static_cast<std::size_t>(v)]);
    s.face2merged[static_cast<std::size_t>(v)] = it->second;
  }
  if (mesh.triangles.empty()) {
    s.reason = "no triangle";
    return s;
  }
  std::map<std::pair<LO, LO>, LO> edge_ids;
  for (const auto& t : mesh.triangles) {
    std::array<LO, 3> m{};
    for (int k = 0; k < 3; ++k) m[k] = s.face2merged[static_cast<std::size_t>(t[k])];
    if (m[0] == m[1] || m[1] == m[2] || m[0] == m[2]) {
      s.reason = "a triangle collapses when seam copies are merged";
      return s;
    }
    const LO ti = static_cast<LO>(s.triangles.size());
    s.triangles.push_back(m);
    std::array<LO, 3> te{};
    for (int k = 0; k < 3; ++k) {
      const LO a = m[k], b = m[(k + 1) % 3];
      const auto key = std::minmax(a, b);
      const auto [it, added] = edge_ids.try_emplace({key.first, key.second}, s.num_edges());
      if (added) {
        s.edges.push_back({key.first, key.second});
        s.edge_tris.push_back({ti, kNoIndex});
      } else {
        auto& et = s.edge_tris[static_cast<std::size_t>(it->second)];
        if (et[1] != kNoIndex) {
          s.reason = "an edge has more than two triangles";
          return s;
        }
        et[1] = ti;
      }
      te[k] = it->second;
    }
    s.tri_edges.push_back(te);
  }
  // Boundary edges, directed as in their triangle: the surface lies on their left.
  std::vector<LO> next(s.points.size(), kNoIndex);
  std::vector<LO> next_edge(s.points.size(), kNoIndex);
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const LO e = s.tri_edges[t][k];
      if (s.edge_tris[static_cast<std::size_t>(e)][1] != kNoIndex) continue;
      const LO a = s.triangles[t][k], b = s.triangles[t][(k + 1) % 3];
      if (next[static_cast<std::size_t>(a)] != kNoIndex) {
        s.reason = "a boundary vertex is not manifold";
        return s;
      }
      next[static_cast<std::size_t>(a)] = b;
      next_edge[static_cast<std::size_t>(a)] = e;
    }
  s.edge_loop.assign(s.edges.size(), kNoIndex);
  std::vector<std::vector<LO>> loops;
  std::vector<double> lengths;
  for (LO v = 0; v < s.num_vertices(); ++v) {
    if (next[static_cast<std::size_t>(v)] == kNoIndex ||
        s.edge_loop[static_cast<std::size_t>(next_edge[static_cast<std::size_t>(v)])] != kNoIndex)
      continue;
    std::vector<LO> loop;
    double length = 0;
    LO w = v;
    do {
      loop.push_back(w);
      const LO e = next_edge[static_cast<std::size_t>(w)];
      s.edge_loop[static_cast<std::size_t>(e)] = static_cast<LO>(loops.size());
      const LO u = next[static_cast<std::size_t>(w)];
      length +=
          distance(s.points[static_cast<std::size_t>(w)], s.points[static_cast<std::size_t>(u)]);
      w = u;
      if (w == kNoIndex) {
        s.reason = "an open boundary chain";
        return s;
      }
    } while (w != v && loop.size() <= s.points.size());
    loops.push_back(std::move(loop));
    lengths.push_back(length);
  }
  // Connectivity: one component.
  std::vector<char> seen(s.triangles.size(), 0);
  std::vector<LO> stack{0};
  seen[0] = 1;
  std::size_t reached = 1;
  while (!stack.empty()) {
    const LO t = stack.back();
    stack.pop_back();
    for (const LO e : s.tri_edges[static_cast<std::size_t>(t)])
      for (const LO u : s.edge_tris[static_cast<std::size_t>(e)])
        if (u != kNoIndex && seen[static_cast<std::size_t>(u)] == 0) {
          seen[static_cast<std::size_t>(u)] = 1;
          ++reached;
          stack.push_back(u);
        }
  }
  s.euler = s.num_vertices() - s.num_edges() + static_cast<int>(s.triangles.size());
  const int b = static_cast<int>(loops.size());
  // Exterior first (the longest loop), then the others in the order found (vertex order: data
  // only).
  std::vector<std::size_t> order(loops.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t x, std::size_t y) { return lengths[x] > lengths[y]; });
  if (!order.empty()) std::stable_sort(order.begin() + 1, order.end());
  std::vector<LO> renumber(loops.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    s.loops.push_back(loops[order[i]]);
    s.loop_length.push_back(lengths[order[i]]);
    renumber[order[i]] = static_cast<LO>(i);
  }
  for (LO& l : s.edge_loop)
    if (l != kNoIndex) l = renumber[static_cast<std::size_t>(l)];
  if (reached != s.triangles.size())
    s.reason = "several components";
  else if (b < 2)
    s.reason = "fewer than 2 boundary loops (" + std::to_string(b) + ")";
  else if (s.euler != 2 - b)
    s.reason = "genus > 0 (Euler characteristic " + std::to_string(s.euler) + " with " +
               std::to_string(b) + " boundary loops)";
  else
    s.ok = true;
  return s;
}

namespace {

// Dense unit-free linear solve (n <= a few tens) by Gaussian elimination with partial pivoting.
std::vector<double> dense_solve(std::vector<std::vector<double>> A, std::vector<double> b) {
  const std::size_t n = b.size();
  double scale = 0;
  for (const auto& row : A)
    for (const double v : row) scale = std::max(scale, std::abs(v));
  for (std::size_t c = 0; c < n; ++c) {
    std::size_t p = c;
    for (std::size_t r = c + 1; r < n; ++r)
      if (std::abs(A[r][c]) > std::abs(A[p][c])) p = r;
    QSMESH_CHECK(std::abs(A[p][c]) > 1e-12 * scale,
                 "singular conjugate system (column " << c << ")");
    std::swap(A[p], A[c]);
    std::swap(b[p], b[c]);
    for (std::size_t r = c + 1; r < n; ++r) {
      const double m = A[r][c] / A[c][c];
      for (std::size_t k = c; k < n; ++k) A[r][k] -= m * A[c][k];
      b[r] -= m * b[c];
    }
  }
  std::vector<double> x(n);
  for (std::size_t r = n; r-- > 0;) {
    double v = b[r];
    for (std::size_t k = r + 1; k < n; ++k) v -= A[r][k] * x[k];
    x[r] = v / A[r][r];
  }
  return x;
}

// The Poincare dual of the shortest path in the dual graph (triangle centroids) from the triangles
// on loop `from` to a triangle on loop 0: +1 on each edge crossed, counted in the direction the
// edge has in the triangle the path leaves. Closed: a triangle the path crosses sees +1 on the
// edge it leaves by and -1 on the one it enters by (its boundary edges where the path starts and
// ends count as crossings from and to outside).
std::vector<double> cut_cocycle(const PolyAnnulus& s, LO from) {
  const std::size_t nt = s.triangles.size();
  std::vector<Vec3> centroid(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& c = s.triangles[t];
    centroid[t] =
        (s.points[static_cast<std::size_t>(c[0])] + s.points[static_cast<std::size_t>(c[1])] +
         s.points[static_cast<std::size_t>(c[2])]) *
        (1.0 / 3.0);
  }
  auto boundary_edge_on = [&](std::size_t t, LO loop) -> int {
    for (int k = 0; k < 3; ++k)
      if (s.edge_loop[static_cast<std::size_t>(s.tri_edges[t][k])] == loop) return k;
    return -1;
  };
  std::vector<double> dist(nt, std::numeric_limits<double>::infinity());
  std::vector<LO> parent(nt, kNoIndex);
  using Item = std::pair<double, LO>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  for (std::size_t t = 0; t < nt; ++t)
    if (boundary_edge_on(t, from) >= 0) {
      dist[t] = 0;
      queue.emplace(0.0, static_cast<LO>(t));
    }
  LO target = kNoIndex;
  while (!queue.empty()) {
    const auto [d, t] = queue.top();
    queue.pop();
    if (d > dist[static_cast<std::size_t>(t)]) continue;
    if (boundary_edge_on(static_cast<std::size_t>(t), 0) >= 0) {
      target = t;
      break;
    }
    for (const LO e : s.tri_edges[static_cast<std::size_t>(t)]) {
      const auto& et = s.edge_tris[static_cast<std::size_t>(e)];
      if (et[1] == kNoIndex) continue;
      const LO u = et[0] == t ? et[1] : et[0];
      const double nd = d + distance(centroid[static_cast<std::size_t>(t)],
                                     centroid[static_cast<std::size_t>(u)]);
      if (nd < dist[static_cast<std::size_t>(u)]) {
        dist[static_cast<std::size_t>(u)] = nd;
        parent[static_cast<std::size_t>(u)] = t;
        queue.emplace(nd, u);
      }
    }
  }
  QSMESH_CHECK(target != kNoIndex, "no dual path from boundary " << from << " to the exterior");
  std::vector<double> eta(s.edges.size(), 0.0);
  // +1 in the direction edge k has in triangle t.
  auto add = [&](LO t, int k, double value) {
    const auto& c = s.triangles[static_cast<std::size_t>(t)];
    const LO e = s.tri_edges[static_cast<std::size_t>(t)][k];
    const double sign = c[k] == s.edges[static_cast<std::size_t>(e)][0] ? 1.0 : -1.0;
    eta[static_cast<std::size_t>(e)] += sign * value;
  };
  add(target, boundary_edge_on(static_cast<std::size_t>(target), 0), 1.0);
  LO t = target;
  while (parent[static_cast<std::size_t>(t)] != kNoIndex) {
    const LO p = parent[static_cast<std::size_t>(t)];
    for (int k = 0; k < 3; ++k) {
      const auto& et =
          s.edge_tris[static_cast<std::size_t>(s.tri_edges[static_cast<std::size_t>(p)][k])];
      if ((et[0] == p && et[1] == t) || (et[1] == p && et[0] == t)) {
        add(p, k, 1.0);
        break;
      }
    }
    t = p;
  }
  add(t, boundary_edge_on(static_cast<std::size_t>(t), from), -1.0);
  return eta;
}

double edge_value(const PolyAnnulus& s, std::span<const double> form, LO a, LO e) {
  return s.edges[static_cast<std::size_t>(e)][0] == a ? form[static_cast<std::size_t>(e)]
                                                      : -form[static_cast<std::size_t>(e)];
}

// Integral of a 1-form along loop l (traversed with the surface on its left).
double period(const PolyAnnulus& s, const std::vector<double>& form,
              const std::map<std::pair<LO, LO>, LO>& edge_of, LO l) {
  const auto& loop = s.loops[static_cast<std::size_t>(l)];
  double sum = 0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const LO a = loop[i], b = loop[(i + 1) % loop.size()];
    sum += edge_value(s, form, a, edge_of.at(std::minmax(a, b)));
  }
  return sum;
}

}  // namespace

HolomorphicBasis holomorphic_basis(const PolyAnnulus& s, const BasisOptions& options,
                                   linalg::SolverLane* lane) {
  QSMESH_CHECK(s.ok, "holomorphic_basis on a surface that is not a poly-annulus: " << s.reason);
  const Stopwatch clock;
  HolomorphicBasis B;
  B.n = s.num_interior_loops();
  const LO nv = s.num_vertices();
  const std::size_t ne = s.edges.size();
  B.weights.assign(ne, 0.0);
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      // Edge k joins corners k and k+1; the corner opposite is k+2.
      const auto& c = s.triangles[t];
      B.weights[static_cast<std::size_t>(s.tri_edges[t][k])] +=
          0.5 * cot_at(s.points[static_cast<std::size_t>(c[(k + 2) % 3])],
                       s.points[static_cast<std::size_t>(c[k])],
                       s.points[static_cast<std::size_t>(c[(k + 1) % 3])]);
    }
  std::vector<LO> on_loop(static_cast<std::size_t>(nv), kNoIndex);
  for (LO l = 0; l < static_cast<LO>(s.loops.size()); ++l)
    for (const LO v : s.loops[static_cast<std::size_t>(l)])
      on_loop[static_cast<std::size_t>(v)] = l;

  // Dirichlet system on the interior vertices (Eq. 4.3), factorized once for the n loops.
  std::vector<LO> interior_id(static_cast<std::size_t>(nv), kNoIndex);
  LO ni = 0;
  for (LO v = 0; v < nv; ++v)
    if (on_loop[static_cast<std::size_t>(v)] == kNoIndex)
      interior_id[static_cast<std::size_t>(v)] = ni++;
  B.f.assign(static_cast<std::size_t>(B.n), std::vector<double>(static_cast<std::size_t>(nv), 0.0));
  for (LO j = 0; j < B.n; ++j)
    for (const LO v : s.loops[static_cast<std::size_t>(j + 1)])
      B.f[static_cast<std::size_t>(j)][static_cast<std::size_t>(v)] = 1.0;
  if (ni > 0) {
    std::vector<linalg::SparseMatrix::Triplet> trip;
    std::vector<std::vector<double>> rhs(static_cast<std::size_t>(B.n),
                                         std::vector<double>(static_cast<std::size_t>(ni), 0.0));
    for (std::size_t e = 0; e < ne; ++e) {
      const LO a = s.edges[e][0], b = s.edges[e][1];
      const double w = B.weights[e];
      const LO ia = interior_id[static_cast<std::size_t>(a)],
               ib = interior_id[static_cast<std::size_t>(b)];
      if (ia != kNoIndex) trip.push_back({ia, ia, w});
      if (ib != kNoIndex) trip.push_back({ib, ib, w});
      if (ia != kNoIndex && ib != kNoIndex) {
        trip.push_back({ia, ib, -w});
        trip.push_back({ib, ia, -w});
      } else if (ia != kNoIndex || ib != kNoIndex) {
        const LO in = ia != kNoIndex ? ia : ib;
        const LO out = ia != kNoIndex ? b : a;
        const LO l = on_loop[static_cast<std::size_t>(out)];
        if (l >= 1) rhs[static_cast<std::size_t>(l - 1)][static_cast<std::size_t>(in)] += w;
      }
    }
    const linalg::SparseMatrix K(ni, trip);
    auto solver = linalg::make_solver(ni, options.solver, lane);
    solver->analyze(K);
    solver->factorize(K);
    ++B.factorizations;
    std::vector<double> x(static_cast<std::size_t>(ni));
    for (LO j = 0; j < B.n; ++j) {
      solver->solve(rhs[static_cast<std::size_t>(j)], x);
      ++B.solves;
      for (LO v = 0; v < nv; ++v)
        if (interior_id[static_cast<std::size_t>(v)] != kNoIndex)
          B.f[static_cast<std::size_t>(j)][static_cast<std::size_t>(v)] =
              x[static_cast<std::size_t>(interior_id[static_cast<std::size_t>(v)])];
    }
  }
  B.exact.assign(static_cast<std::size_t>(B.n), std::vector<double>(ne));
  for (LO j = 0; j < B.n; ++j)
    for (std::size_t e = 0; e < ne; ++e)
      B.exact[static_cast<std::size_t>(j)][e] =
          B.f[static_cast<std::size_t>(j)][static_cast<std::size_t>(s.edges[e][1])] -
          B.f[static_cast<std::size_t>(j)][static_cast<std::size_t>(s.edges[e][0])];

  // Neumann system (Eq. 4.5) on all vertices but the last (pinned: h is defined up to a constant).
  std::map<std::pair<LO, LO>, LO> edge_of;
  for (std::size_t e = 0; e < ne; ++e) edge_of[{s.edges[e][0], s.edges[e][1]}] = static_cast<LO>(e);
  const LO nn = nv - 1;
  std::vector<linalg::SparseMatrix::Triplet> trip;
  for (std::size_t e = 0; e < ne; ++e) {
    const LO a = s.edges[e][0], b = s.edges[e][1];
    const double w = B.weights[e];
    if (a < nn) trip.push_back({a, a, w});
    if (b < nn) trip.push_back({b, b, w});
    if (a < nn && b < nn) {
      trip.push_back({a, b, -w});
      trip.push_back({b, a, -w});
    }
  }
  const linalg::SparseMatrix K(nn, trip);
  auto solver = linalg::make_solver(nn, options.solver, lane);
  solver->analyze(K);
  solver->factorize(K);
  ++B.factorizations;
  B.omega.assign(static_cast<std::size_t>(B.n), {});
  std::vector<double> rhs(static_cast<std::size_t>(nn)), h(static_cast<std::size_t>(nn));
  for (LO k = 0; k < B.n; ++k) {
    std::vector<double> eta = cut_cocycle(s, k + 1);
    std::fill(rhs.begin(), rhs.end(), 0.0);
    for (std::size_t e = 0; e < ne; ++e) {
      const LO a = s.edges[e][0], b = s.edges[e][1];
      const double flux = B.weights[e] * eta[e];  // w * eta(a -> b)
      if (a < nn) rhs[static_cast<std::size_t>(a)] += flux;
      if (b < nn) rhs[static_cast<std::size_t>(b)] -= flux;
    }
    solver->solve(rhs, h);
    ++B.solves;
    auto hv = [&](LO v) { return v < nn ? h[static_cast<std::size_t>(v)] : 0.0; };
    for (std::size_t e = 0; e < ne; ++e) eta[e] += hv(s.edges[e][1]) - hv(s.edges[e][0]);
    const double p = period(s, eta, edge_of, k + 1);
    QSMESH_CHECK(std::abs(p) > 0.5, "cut cocycle of boundary " << k + 1 << " has period " << p);
    for (double& v : eta) v /= p;
    B.omega[static_cast<std::size_t>(k)] = std::move(eta);
  }

  // Conjugates (Eq. 4.7): *omega_k = sum_j conj[k][j] df_j, from
  // integral omega_m ^ *omega_k = <omega_m, omega_k> (Eq. 4.2) = sum_j conj[k][j] integral omega_m
  // ^ df_j (Eq. 4.1).
  const std::size_t n = static_cast<std::size_t>(B.n);
  B.wedge.assign(n, std::vector<double>(n, 0.0));
  std::vector<std::vector<double>> gram(n, std::vector<double>(n, 0.0));
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const auto& c = s.triangles[t];
    for (std::size_t m = 0; m < n; ++m) {
      std::array<double, 3> w1{};
      for (int k = 0; k < 3; ++k) w1[k] = edge_value(s, B.omega[m], c[k], s.tri_edges[t][k]);
      for (std::size_t j = 0; j < n; ++j) {
        std::array<double, 3> w2{};
        for (int k = 0; k < 3; ++k) w2[k] = edge_value(s, B.exact[j], c[k], s.tri_edges[t][k]);
        // (1/6) det [[w1], [w2], [1 1 1]]
        const double det =
            w1[0] * (w2[1] - w2[2]) - w1[1] * (w2[0] - w2[2]) + w1[2] * (w2[0] - w2[1]);
        B.wedge[m][j] += det / 6.0;
      }
    }
  }
  for (std::size_t e = 0; e < ne; ++e)
    for (std::size_t m = 0; m < n; ++m)
      for (std::size_t k = m; k < n; ++k) {
        const double v = B.weights[e] * B.omega[m][e] * B.omega[k][e];
        gram[m][k] += v;
        if (k != m) gram[k][m] += v;
      }
  B.conj.assign(n, {});
  B.star_omega.assign(n, std::vector<double>(ne, 0.0));
  for (std::size_t k = 0; k < n; ++k) {
    std::vector<double> g(n);
    for (std::size_t m = 0; m < n; ++m) g[m] = gram[m][k];
    B.conj[k] = dense_solve(B.wedge, g);
    for (std::size_t j = 0; j < n; ++j)
      for (std::size_t e = 0; e < ne; ++e) B.star_omega[k][e] += B.conj[k][j] * B.exact[j][e];
  }
  B.phi.assign(n, std::vector<std::complex<double>>(ne));
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t e = 0; e < ne; ++e) B.phi[k][e] = {B.omega[k][e], B.star_omega[k][e]};
  B.seconds = clock.seconds();
  return B;
}

std::vector<std::complex<double>> combine(const HolomorphicBasis& basis,
                                          std::span<const double> lambda) {
  QSMESH_CHECK(static_cast<LO>(lambda.size()) == basis.n,
               "combine: " << lambda.size() << " coefficients for " << basis.n << " forms");
  std::vector<std::complex<double>> phi(basis.n > 0 ? basis.phi[0].size() : 0);
  for (std::size_t k = 0; k < lambda.size(); ++k)
    for (std::size_t e = 0; e < phi.size(); ++e) phi[e] += lambda[k] * basis.phi[k][e];
  return phi;
}

}  // namespace qsmesh::holomorphic
