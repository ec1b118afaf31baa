// Small tools on the quads of one face mesh shared by the smoothing kernels, the untangler and the
// quasi-structured stage (paper 000 Secs. 5.3 and 6): orientation against the face, SICN with a
// flip test, and the uniform-weight Laplacian layout of a small quad mesh in (u, v).
#pragma once

#include <array>
#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/linalg/solver_cache.hpp"
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
/// propagate as qsmesh::Error. `cache` (optional, this thread's): the solver's analysis is reused
/// when the same quads come again; the layout is the same with or without it.
[[nodiscard]] bool laplace_uv(const std::vector<std::array<LO, 4>>& quads, LO num_fixed,
                              std::vector<Vec2>& uv, linalg::SolverCache* cache = nullptr);

/// Laplace layout that keeps the grading of the fixed boundary (paper 000 Sec. 6.1.2: the patterns
/// are filled "with a layout following the boundary sizes"). Same inputs, outputs and errors as
/// laplace_uv, but each edge is a spring of stiffness 1 / w, w being its target length: the edges
/// are grouped in chords (dual strips: a quad's opposite edges are in one chord), each chord that
/// starts and ends on edges of two fixed vertices gets the (u, v) lengths of these two end edges
/// and interpolates them linearly along the strip. Chords closed or ending on a free vertex take
/// the mean target of the others (all 1 when there is none: laplace_uv). On a grid whose opposite
/// sides carry the same graded spacing this reproduces the spacing exactly (straight grid lines,
/// as transfinite interpolation), where the uniform Laplacian pulls it towards even spacing and
/// skews the quads near the fine end.
[[nodiscard]] bool chord_laplace_uv(const std::vector<std::array<LO, 4>>& quads, LO num_fixed,
                                    std::vector<Vec2>& uv, linalg::SolverCache* cache = nullptr);

}  // namespace qsmesh::smooth
