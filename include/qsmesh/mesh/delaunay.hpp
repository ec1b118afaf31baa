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
  Vec2 uv;            ///< image on the face's parameter plane (pcurve of the curve use)
  Vec3 xyz;           ///< position on the curve (the curve mesh's point, shared by all faces)
  VertexClass vclass; ///< corner or curve classification
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
};

/// Statistics of a triangulation run.
struct TriangulateStats {
  std::int64_t inserted = 0;          ///< interior points inserted
  std::int64_t rejected = 0;          ///< candidate points rejected (outside, too close, ...)
  std::int64_t boundary_flips = 0;    ///< flips used to recover the locked boundary
};

/// Triangulates the face bounded by `loops` (loops[0] outer, others holes; either orientation)
/// with interior points inserted until every edge is at most about size(x) long in 3D and the
/// triangles are well shaped. Boundary points are kept exactly as given (the boundary is locked)
/// and appear first in the output, loop by loop, in input order, except that extra points of
/// degenerate segments are merged with their corner. Interior vertices are classified on the face
/// (dim 2) with their (u, v). Triangles are counterclockwise in (u, v) when face_reversed is false
/// and clockwise when it is true, so that in 3D they are oriented along the face normal. Deterministic: same input, same output, whatever the thread count.
/// Degenerate segments: every point of a chain of degenerate segments (both ends and the extra
/// points) becomes one output vertex, the chain's first input point (the other end is omitted
/// from the output); triangles with two vertices there are dropped. Triangles of the pole fan use
/// that vertex's (u, v), so they are valid in 3D but may be inverted in (u, v).
/// Throws qsmesh::Error when the boundary cannot be recovered or a loop is invalid.
[[nodiscard]] FaceMesh triangulate_face(const cad::FaceGeometry& surface, bool face_reversed,
                                        std::span<const BoundaryLoop> loops,
                                        const SizeFunction& size,
                                        const TriangulateOptions& options = {},
                                        TriangulateStats* stats = nullptr);

}  // namespace qsmesh::mesh
