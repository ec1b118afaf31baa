// Small tools on the quads of one face mesh shared by the smoothing kernels, the untangler and the
// quasi-structured stage (paper 000 Secs. 5.3 and 6): orientation against the face, SICN with a
// flip test, and the uniform-weight Laplacian layout of a small quad mesh in (u, v).
#pragma once

#include <array>
#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::smooth {

/// Orientation of the quads against the face normal: +1 when most quads turn counter-clockwise
/// around it (majority vote of the summed corner normals against the normal at each quad's first
/// vertex; a tie or no quad gives +1), -1 otherwise.
[[nodiscard]] double quad_orientation(const mesh::FaceMesh& m, const cad::FaceGeometry& surface);

/// SICN (mesh::quad_sicn) of the quad (x0..x3), or -1 when its summed corner normal points
/// against `normal` times `sign` (quad_sicn alone cannot see a quad flipped as a whole: it
/// measures against the quad's own average normal). `normal` zero (pole) skips that test.
[[nodiscard]] double oriented_sicn(const std::array<Vec3, 4>& x, const Vec3& normal, double sign);

/// Uniform-weight Laplace layout in the parameter plane: the vertices [0, num_fixed) of `uv` keep
/// their values (Dirichlet), each vertex >= num_fixed is set to the arithmetic mean of its edge
/// neighbours in `quads` (vertex ids index `uv`), by one sparse direct solve (Eigen) of u and v.
/// For a grid with evenly spaced sides this is the bilinear grid; the layout is invariant under
/// affine maps of the parameter plane. Returns false, leaving the free uv unspecified, when a
/// solved value is not finite; errors of the solver (a free vertex with no path to a fixed one)
/// propagate as qsmesh::Error.
[[nodiscard]] bool laplace_uv(const std::vector<std::array<LO, 4>>& quads, LO num_fixed,
                              std::vector<Vec2>& uv);

}  // namespace qsmesh::smooth
