#include "internal.hpp"
#include "qsmesh/mesh/quality.hpp"

namespace qsmesh::smooth::detail {

double orientation(const mesh::FaceMesh& m, const cad::FaceGeometry& surface) {
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

std::vector<std::vector<LO>> vertex_quads(const mesh::FaceMesh& m) {
  std::vector<std::vector<LO>> v2q(m.points.size());
  for (LO q = 0; q < static_cast<LO>(m.quads.size()); ++q)
    for (const LO v : m.quads[q]) v2q[v].push_back(q);
  return v2q;
}

}  // namespace qsmesh::smooth::detail
