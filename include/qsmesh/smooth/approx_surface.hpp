// Fast approximate surface of one CAD face (paper 000 Sec. 5.3, "Winslow kernel": projection on a
// triangulated representation of the CAD surface with a spatial index).
#pragma once

#include <array>
#include <vector>

#include "qsmesh/core/types.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::smooth {

/// A triangulation of a face with the (u, v) of its vertices, and a bounding-volume hierarchy over
/// its triangles for closest-point queries. Immutable once built; queries are const and may run
/// from several threads.
class ApproxSurface {
 public:
  /// Takes the points (model units), their (u, v) in the face's chart and triangles (indices into
  /// both). Each triangle must use consistent uv (at seams and poles: the copies of its element),
  /// which is what FaceMesh elements do. Throws qsmesh::Error on mismatched sizes or bad indices.
  ApproxSurface(std::vector<Vec3> points, std::vector<Vec2> uv,
                std::vector<std::array<LO, 3>> triangles);
  /// The triangles of a face mesh, each quad split along its shorter 3D diagonal.
  [[nodiscard]] static ApproxSurface from_mesh(const mesh::FaceMesh& mesh);

  struct Hit {
    Vec3 point;              ///< closest point on the triangulation
    Vec2 uv;                 ///< its (u, v), interpolated linearly in the triangle
    LO triangle = kNoIndex;  ///< kNoIndex when the triangulation is empty
    double distance = 0;     ///< |p - point|
  };
  /// Closest point of the triangulation to p (exact on the triangles; ties broken by the lowest
  /// triangle index, so the answer is deterministic). The uv approximates the CAD projection of p
  /// (for triangles of size h on a surface of curvature k: error O(k h^2) for p on the surface,
  /// O(k h d) at a distance d from it); evaluate the surface at it for a point on the CAD.
  /// `hint`: a triangle likely near p (e.g. the previous answer for a moving point), tried first
  /// to prune the search; it does not change the answer.
  [[nodiscard]] Hit closest(const Vec3& p, LO hint = kNoIndex) const;

  [[nodiscard]] LO num_triangles() const { return static_cast<LO>(tris_.size()); }

 private:
  struct Node {
    Box3 box;
    LO first = 0, count = 0;  // leaf: triangles order_[first, first + count)
    LO left = kNoIndex, right = kNoIndex;
  };
  LO build(LO first, LO count, std::vector<Vec3>& centres);

  std::vector<Vec3> points_;
  std::vector<Vec2> uv_;
  std::vector<std::array<LO, 3>> tris_;
  std::vector<LO> order_;
  std::vector<Node> nodes_;
};

}  // namespace qsmesh::smooth
