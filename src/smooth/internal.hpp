// Pieces shared by the smoothing kernels and the untangler of one face (not installed).
#pragma once

#include <array>
#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::smooth::detail {

/// +1 when most quads turn counter-clockwise around the face normal, -1 otherwise.
[[nodiscard]] double orientation(const mesh::FaceMesh& m, const cad::FaceGeometry& surface);

/// SICN of the quad (x0..x3), or -1 when its summed corner normal points against `normal` times
/// `sign` (mesh::quad_sicn alone cannot see a quad flipped as a whole: it measures against the
/// quad's own average normal). `normal` zero (pole) skips that test.
[[nodiscard]] double oriented_sicn(const std::array<Vec3, 4>& x, const Vec3& normal, double sign);

/// Incident quads of every vertex, in increasing order.
[[nodiscard]] std::vector<std::vector<LO>> vertex_quads(const mesh::FaceMesh& m);

}  // namespace qsmesh::smooth::detail
