#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "internal.hpp"
#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/linalg/solver_cache.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/smooth/quad_tools.hpp"
#include "qsmesh/smooth/smooth.hpp"

namespace qsmesh::smooth {

double quad_orientation(const mesh::FaceMesh& m, const cad::FaceGeometry& surface) {
  return detail::quad_orientation_with(m, [&](LO v) { return surface.normal(m.uv[v]); });
}

double oriented_sicn(const std::array<Vec3, 4>& x, const Vec3& normal, double sign) {
  // The corner cross products give the area vector and the SICN both (mesh::quad_corners).
  const mesh::QuadCorners c = mesh::quad_corners(x);
  if (norm2(normal) > 0 && sign * dot(c.sum, normal) <= 0) return -1.0;
  return mesh::quad_sicn_from(c);
}

namespace {

// Unique edges of `quads` and, per quad, its four edge ids (edge k joins corners k and k+1).
struct QuadEdges {
  std::vector<std::array<LO, 2>> ends;
  std::vector<std::array<LO, 4>> quad2edges;
  std::vector<std::array<LO, 2>> edge2quads;  // kNoIndex where there is no second quad
  std::vector<int> num_quads;
};

QuadEdges quad_edges(const std::vector<std::array<LO, 4>>& quads) {
  // Edges numbered in order of first appearance (quad by quad, corner by corner). The (quad,
  // corner) positions are bucketed by the edge's lower vertex (counting sort), and each position
  // finds the first one of its edge among the few before it in its bucket: no sort and no hash
  // map (a node per edge), as this runs for every layout of every pattern and cavity.
  QuadEdges e;
  const auto nq = static_cast<LO>(quads.size());
  const auto np = static_cast<std::size_t>(nq) * 4;
  LO nv = 0;
  for (const auto& q : quads)
    for (const LO v : q) nv = std::max(nv, v + 1);
  std::vector<LO> start(static_cast<std::size_t>(nv) + 1, 0);
  const auto ends_at = [&](std::size_t p) {
    const auto& q = quads[p / 4];
    return std::minmax(q[p % 4], q[(p + 1) % 4]);
  };
  for (std::size_t p = 0; p < np; ++p) ++start[static_cast<std::size_t>(ends_at(p).first) + 1];
  for (std::size_t v = 0; v < static_cast<std::size_t>(nv); ++v) start[v + 1] += start[v];
  std::vector<LO> slot(np);
  {
    std::vector<LO> fill(start.begin(), start.end() - 1);
    for (std::size_t p = 0; p < np; ++p)
      slot[static_cast<std::size_t>(fill[static_cast<std::size_t>(ends_at(p).first)]++)] =
          static_cast<LO>(p);
  }
  std::vector<LO> group_of(np);  // the edge's first position
  for (std::size_t v = 0; v < static_cast<std::size_t>(nv); ++v)
    for (LO i = start[v]; i < start[v + 1]; ++i) {
      const auto p = static_cast<std::size_t>(slot[static_cast<std::size_t>(i)]);
      const LO hi = ends_at(p).second;
      group_of[p] = static_cast<LO>(p);
      for (LO j = start[v]; j < i; ++j) {
        const auto r = static_cast<std::size_t>(slot[static_cast<std::size_t>(j)]);
        if (ends_at(r).second == hi) {
          group_of[p] = group_of[r];
          break;
        }
      }
    }
  std::vector<LO> id_of(np, kNoIndex);
  e.quad2edges.resize(quads.size());
  for (LO q = 0; q < nq; ++q)
    for (int k = 0; k < 4; ++k) {
      LO& id = id_of[group_of[4 * q + k]];
      if (id == kNoIndex) {
        id = static_cast<LO>(e.ends.size());
        e.ends.push_back({quads[q][k], quads[q][(k + 1) % 4]});
        e.edge2quads.push_back({kNoIndex, kNoIndex});
        e.num_quads.push_back(0);
      }
      e.quad2edges[q][k] = id;
      if (e.num_quads[id] < 2) e.edge2quads[id][e.num_quads[id]] = q;
      ++e.num_quads[id];
    }
  return e;
}

// Minimises sum over edges of weight * |uv_a - uv_b|^2 over the free vertices (one sparse direct
// solve per coordinate).
bool weighted_laplace(const QuadEdges& e, const std::vector<double>& weight, LO num_fixed,
                      std::vector<Vec2>& uv, linalg::SolverCache* cache) {
  const LO n = static_cast<LO>(uv.size());
  const LO nu = n - num_fixed;
  if (nu == 0) return true;
  std::vector<double> diag(static_cast<std::size_t>(nu), 0.0);
  std::vector<linalg::SparseMatrix::Triplet> trip;
  std::vector<double> bu(static_cast<std::size_t>(nu), 0.0), bv(static_cast<std::size_t>(nu), 0.0);
  for (std::size_t i = 0; i < e.ends.size(); ++i) {
    const double w = weight[i];
    const auto [a, b] = e.ends[i];
    for (const auto& [v, o] : {std::pair{a, b}, std::pair{b, a}}) {
      if (v < num_fixed) continue;
      const LO r = v - num_fixed;
      diag[r] += w;
      if (o >= num_fixed) {
        trip.push_back({r, o - num_fixed, -w});
      } else {
        bu[r] += w * uv[o].u;
        bv[r] += w * uv[o].v;
      }
    }
  }
  for (LO r = 0; r < nu; ++r) trip.push_back({r, r, diag[r]});
  const linalg::SparseMatrix A(nu, trip);
  std::vector<double> xu(static_cast<std::size_t>(nu)), xv(static_cast<std::size_t>(nu));
  std::unique_ptr<linalg::LinearSolver> owner;
  linalg::LinearSolver& solver = linalg::factorized_eigen(A, cache, owner);
  solver.solve(bu, xu);
  solver.solve(bv, xv);
  for (LO i = 0; i < nu; ++i) {
    if (!std::isfinite(xu[i]) || !std::isfinite(xv[i])) return false;
    uv[num_fixed + i] = {xu[i], xv[i]};
  }
  return true;
}

}  // namespace

bool laplace_uv(const std::vector<std::array<LO, 4>>& quads, LO num_fixed, std::vector<Vec2>& uv,
                linalg::SolverCache* cache) {
  const QuadEdges e = quad_edges(quads);
  return weighted_laplace(e, std::vector<double>(e.ends.size(), 1.0), num_fixed, uv, cache);
}

bool chord_laplace_uv(const std::vector<std::array<LO, 4>>& quads, LO num_fixed,
                      std::vector<Vec2>& uv, linalg::SolverCache* cache) {
  const QuadEdges e = quad_edges(quads);
  const LO ne = static_cast<LO>(e.ends.size());
  std::vector<double> target(static_cast<std::size_t>(ne), -1.0);
  std::vector<char> seen(static_cast<std::size_t>(ne), 0);
  // Width of a chord where it ends: the (u, v) length of an edge whose two ends are fixed.
  const auto width = [&](LO edge) {
    const auto [a, b] = e.ends[edge];
    if (a >= num_fixed || b >= num_fixed) return -1.0;
    const Vec2 d{uv[a].u - uv[b].u, uv[a].v - uv[b].v};
    return std::sqrt(d.u * d.u + d.v * d.v);
  };
  std::vector<LO> strip;
  for (LO s = 0; s < ne; ++s) {
    if (seen[s] || e.num_quads[s] != 1) continue;
    // Walk the dual strip from boundary edge s through opposite edges to its other end.
    strip.assign(1, s);
    seen[s] = 1;
    LO edge = s, q = e.edge2quads[s][0];
    while (q != kNoIndex) {
      const auto& qe = e.quad2edges[q];
      const int k = static_cast<int>(std::find(qe.begin(), qe.end(), edge) - qe.begin());
      if (k == 4) break;
      edge = qe[(k + 2) % 4];
      if (seen[edge]) break;  // a degenerate quad or a strip closing on itself
      seen[edge] = 1;
      strip.push_back(edge);
      if (e.num_quads[edge] != 2) break;
      q = e.edge2quads[edge][0] == q ? e.edge2quads[edge][1] : e.edge2quads[edge][0];
    }
    double w0 = width(strip.front()), w1 = width(strip.back());
    if (w0 <= 0 && w1 <= 0) continue;
    if (w0 <= 0) w0 = w1;
    if (w1 <= 0) w1 = w0;
    const double last = std::max<double>(1, static_cast<double>(strip.size() - 1));
    for (std::size_t i = 0; i < strip.size(); ++i)
      target[strip[i]] = w0 + (w1 - w0) * static_cast<double>(i) / last;
  }
  double sum = 0;
  LO count = 0;
  for (const double t : target)
    if (t > 0) {
      sum += t;
      ++count;
    }
  const double mean = count > 0 ? sum / count : 1.0;
  std::vector<double> weight(static_cast<std::size_t>(ne));
  // A floor keeps the system well conditioned where a chord ends on a pole (zero width).
  for (LO i = 0; i < ne; ++i)
    weight[i] = 1.0 / std::max(target[i] > 0 ? target[i] : mean, 1e-3 * mean);
  return weighted_laplace(e, weight, num_fixed, uv, cache);
}

namespace detail {

std::vector<std::vector<LO>> vertex_quads(const mesh::FaceMesh& m) {
  std::vector<std::vector<LO>> v2q(m.points.size());
  for (LO q = 0; q < static_cast<LO>(m.quads.size()); ++q)
    for (const LO v : m.quads[q]) v2q[v].push_back(q);
  return v2q;
}

void sync_interior_params(mesh::FaceMesh& m) {
  for (LO v = 0; v < m.num_vertices(); ++v)
    if (m.vclass[v].dim == 2) m.vclass[v].param = {m.uv[v].u, m.uv[v].v};
}

bool keep_or_roll_back(mesh::FaceMesh& m, const mesh::FaceMesh& input, const QualityReport& before,
                       Accept accept, QualityReport& after) {
  after = measure(m);
  const bool worse = accept == Accept::kGain ? !(after.sicn_min > before.sicn_min)
                                             : after.sicn_min < before.sicn_min;
  if (!worse && after.invalid <= before.invalid) return false;
  m = input;
  after = before;
  return true;
}

}  // namespace detail
}  // namespace qsmesh::smooth
