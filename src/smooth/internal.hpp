// Pieces shared by the smoothing kernels and the untangler of one face (not installed).
#pragma once

#include <array>
#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/smooth/smooth.hpp"

namespace qsmesh::smooth::detail {

/// Incident quads of every vertex, in increasing order.
[[nodiscard]] std::vector<std::vector<LO>> vertex_quads(const mesh::FaceMesh& m);

/// quad_orientation with the surface normal at a vertex given by normal_at(v) (the smoother passes
/// its cache of normals, which it would compute again at the same vertices): +1 when most quads
/// turn with the normal at their first corner, -1 otherwise.
template <class NormalAt>
[[nodiscard]] double quad_orientation_with(const mesh::FaceMesh& m, NormalAt&& normal_at) {
  double votes = 0;
  for (const auto& q : m.quads) {
    Vec3 s{};
    for (int k = 0; k < 4; ++k)
      s += cross(m.points[q[k]] - m.points[q[(k + 3) % 4]],
                 m.points[q[(k + 1) % 4]] - m.points[q[k]]);
    // The centroid uv of a quad along a seam may be meaningless; a vertex uv is not.
    const Vec3 n = normal_at(q[0]);
    const double d = dot(s, n);
    votes += d > 0 ? 1 : (d < 0 ? -1 : 0);
  }
  return votes >= 0 ? 1.0 : -1.0;
}

/// Sets the param of every dim-2 vertex to its uv.
void sync_interior_params(mesh::FaceMesh& m);

/// When an optimiser's output is accepted against its input's quality `before`.
enum class Accept {
  kGain,    ///< the minimum SICN must rise
  kNoDrop,  ///< the minimum SICN must not drop
};

/// Measures m into `after`; when it fails `accept` or has more invalid quads than `before`, m
/// becomes `input` and `after` becomes `before`. Returns true when it rolled back.
bool keep_or_roll_back(mesh::FaceMesh& m, const mesh::FaceMesh& input, const QualityReport& before,
                       Accept accept, QualityReport& after);

}  // namespace qsmesh::smooth::detail
