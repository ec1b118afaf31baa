// Parametric Delaunay kernel: triangulates one CAD face in its (u, v) parameter plane, measuring
// lengths with the surface metric, with the face boundary locked (paper 000 Sec. 2, Sec. 3.1: the
// background mesh; Sec. 5.1 reuses the same insertion kernel for frontal point placement).
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::mesh {

/// A vertex of a face boundary loop, as given by the curve meshes.
struct BoundaryPoint {
  Vec2 uv;             ///< image on the face's parameter plane (pcurve of the curve use)
  Vec3 xyz;            ///< position on the curve (the curve mesh's point, shared by all faces)
  VertexClass vclass;  ///< corner or curve classification
};

/// A closed boundary loop: segment i joins points[i] and points[(i + 1) % n].
/// degenerate[i] != 0 marks a segment lying on a degenerate curve (both ends are the same 3D point,
/// e.g. the pole of a sphere); the kernel may place extra uv points on it, all of which map to that
/// point, and merges them in the output.
struct BoundaryLoop {
  std::vector<BoundaryPoint> points;
  std::vector<std::uint8_t> degenerate;  ///< size points.size()
};

/// Target 3D edge length (model units, > 0) at a point of the face.
using SizeFunction = std::function<double(const Vec2& uv, const Vec3& xyz)>;

struct TriangulateOptions {
  /// Maximum number of interior points inserted (guards against runaway refinement).
  std::int64_t max_points = 5'000'000;
  /// Triangles whose smallest 3D angle is below this (degrees) are refined when possible.
  double min_angle_deg = 25.0;
  /// Interior points (u, v) inserted in this order after the boundary, before any refinement
  /// (paper 000 Sec. 5.1: the frontal points), each by a metric Delaunay cavity. A point outside
  /// the face, on an existing vertex or edge of the boundary, closer than half size(x) to a cavity
  /// vertex or hugging a boundary segment is skipped (counted in TriangulateStats::rejected).
  /// The span must stay valid during the call.
  std::span<const Vec2> interior_points;
  /// false: no size-driven refinement; the output has the boundary points, the accepted interior
  /// points and only the final quality clean-up (flips on 3D angles, moves of badly placed interior
  /// vertices). The size function then only sets the spacing tests and the pole fans.
  bool refine = true;
  /// Before the flips on 3D angles, flip every interior edge longer than twice the size at both
  /// ends whose other diagonal is shorter than shorten_ratio times it in 3D, when the flip is valid
  /// in (u, v) and the smaller 3D angle of the two triangles does not drop (0: off). Each flip
  /// shortens the total edge length, so the pass ends. It zips fans that the (u, v) Delaunay steps
  /// leave in strips narrower than the spacing where the parametrisation is stretched unevenly:
  /// the angle flips alone cannot undo them, since each zipping flip barely changes the smallest
  /// angle and the flips that would are invalid in (u, v).
  double shorten_ratio = 0;
};

/// Statistics of a triangulation run.
struct TriangulateStats {
  std::int64_t inserted = 0;        ///< interior points inserted
  std::int64_t rejected = 0;        ///< candidate points rejected (outside, too close, ...)
  std::int64_t boundary_flips = 0;  ///< flips used to recover the locked boundary
};

/// Triangulates the face bounded by `loops` (loops[0] outer, others holes; either orientation)
/// with interior points inserted until every edge is at most about size(x) long in 3D and the
/// triangles are well shaped. Boundary points are kept exactly as given (the boundary is locked)
/// and appear first in the output, loop by loop, in input order, except that extra points of
/// degenerate segments are merged with their corner. Interior vertices are classified on the face
/// (dim 2) with their (u, v). Triangles are counterclockwise in (u, v) when face_reversed is false
/// and clockwise when it is true, so that in 3D they are oriented along the face normal.
/// Deterministic: same input, same output, whatever the thread count. Degenerate segments: every
/// point of a chain of degenerate segments (both ends and the extra points) becomes one output
/// vertex, the chain's first input point (the other end is omitted from the output); triangles with
/// two vertices there are dropped. Triangles of the pole fan use that vertex's (u, v), so they are
/// valid in 3D but may be inverted in (u, v). Throws qsmesh::Error when the boundary cannot be
/// recovered or a loop is invalid.
[[nodiscard]] FaceMesh triangulate_face(const cad::FaceGeometry& surface, bool face_reversed,
                                        std::span<const BoundaryLoop> loops,
                                        const SizeFunction& size,
                                        const TriangulateOptions& options = {},
                                        TriangulateStats* stats = nullptr);

/// Whether `tri` has a flat triangle along its boundary: its three vertices are boundary vertices
/// (vclass.dim 0 or 1) and its (u, v) area is below flat_ratio times the square of its longest
/// (u, v) edge. triangulate_face leaves such triangles where a strip narrower than the spacing
/// (no interior point fits in it) is much wider in (u, v) than in 3D, e.g. a thin torus fillet
/// along a round edge: consecutive vertices of one curve become neighbours, and a midpoint
/// subdivision of the triangles puts inner vertices on the curve itself (folded quads).
[[nodiscard]] bool has_flat_boundary_triangle(const FaceMesh& tri, double flat_ratio = 1e-3);

/// Mean of |dS/du| and of |dS/dv| over the points of `loops` (model units per parameter unit):
/// the scale that gives the face's parameters their 3D proportions along its boundary, on average.
/// A component is 1 when its mean is not positive and finite.
[[nodiscard]] Vec2 mean_boundary_speeds(const cad::FaceGeometry& surface,
                                        std::span<const BoundaryLoop> loops);

/// triangulate_face in the scaled parameters (u scale.u, v scale.v): the Delaunay steps of the
/// kernel, which work in the parameter plane, then see the face with other proportions (with
/// mean_boundary_speeds: about its 3D ones). Inputs and output as for triangulate_face, all in
/// the face's own (u, v): loops, options.interior_points and the size function's argument; the
/// output's uv (boundary points: their input (u, v) up to the rounding of the scaling; their 3D
/// points exactly) and the params of its interior vertices. Preconditions: scale.u, scale.v > 0 and
/// finite (else qsmesh::Error).
[[nodiscard]] FaceMesh triangulate_face_scaled(const cad::FaceGeometry& surface, bool face_reversed,
                                               std::span<const BoundaryLoop> loops,
                                               const SizeFunction& size,
                                               const TriangulateOptions& options, Vec2 scale,
                                               TriangulateStats* stats = nullptr);

}  // namespace qsmesh::mesh
