#include <cmath>
#include <set>

#include "internal.hpp"
#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/smooth/quad_tools.hpp"
#include "qsmesh/smooth/smooth.hpp"

namespace qsmesh::smooth {

double quad_orientation(const mesh::FaceMesh& m, const cad::FaceGeometry& surface) {
  double votes = 0;
  for (const auto& q : m.quads) {
    Vec3 s{};
    for (int k = 0; k < 4; ++k)
      s += cross(m.points[q[k]] - m.points[q[(k + 3) % 4]],
                 m.points[q[(k + 1) % 4]] - m.points[q[k]]);
    // The centroid uv of a quad along a seam may be meaningless; a vertex uv is not.
    const Vec3 n = surface.normal(m.uv[q[0]]);
    const double d = dot(s, n);
    votes += d > 0 ? 1 : (d < 0 ? -1 : 0);
  }
  return votes >= 0 ? 1.0 : -1.0;
}

double oriented_sicn(const std::array<Vec3, 4>& x, const Vec3& normal, double sign) {
  Vec3 sum{};
  for (int k = 0; k < 4; ++k) sum += cross(x[k] - x[(k + 3) % 4], x[(k + 1) % 4] - x[k]);
  if (norm2(normal) > 0 && sign * dot(sum, normal) <= 0) return -1.0;
  return mesh::quad_sicn(x);
}

bool laplace_uv(const std::vector<std::array<LO, 4>>& quads, LO num_fixed, std::vector<Vec2>& uv) {
  const LO n = static_cast<LO>(uv.size());
  const LO nu = n - num_fixed;
  if (nu == 0) return true;
  std::vector<std::set<LO>> nbr(static_cast<std::size_t>(n));
  for (const auto& q : quads)
    for (int k = 0; k < 4; ++k) {
      nbr[q[k]].insert(q[(k + 1) % 4]);
      nbr[q[(k + 1) % 4]].insert(q[k]);
    }
  std::vector<linalg::SparseMatrix::Triplet> trip;
  std::vector<double> bu(static_cast<std::size_t>(nu), 0.0), bv(static_cast<std::size_t>(nu), 0.0);
  for (LO v = num_fixed; v < n; ++v) {
    const LO i = v - num_fixed;
    trip.push_back({i, i, static_cast<double>(nbr[v].size())});
    for (const LO w : nbr[v]) {
      if (w >= num_fixed) {
        trip.push_back({i, w - num_fixed, -1.0});
      } else {
        bu[i] += uv[w].u;
        bv[i] += uv[w].v;
      }
    }
  }
  const linalg::SparseMatrix A(nu, trip);
  std::vector<double> xu(static_cast<std::size_t>(nu)), xv(static_cast<std::size_t>(nu));
  auto solver = linalg::make_solver(nu, linalg::SolverOptions{linalg::Backend::Eigen}, nullptr);
  solver->analyze(A);
  solver->factorize(A);
  solver->solve(bu, xu);
  solver->solve(bv, xv);
  for (LO i = 0; i < nu; ++i) {
    if (!std::isfinite(xu[i]) || !std::isfinite(xv[i])) return false;
    uv[num_fixed + i] = {xu[i], xv[i]};
  }
  return true;
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
