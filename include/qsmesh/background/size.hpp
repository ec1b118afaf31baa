// Size field of the background mesh: a cap from the user and a curvature adaptation
// (paper 000 Sec. 3.1: the cross field is computed on "meshes adapted to the geometric features").
// The small-feature and cross-field size maps of Sec. 4 come later and replace this as the
// size map of the final mesh; the background mesh keeps this one.
#pragma once

#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/core/types.hpp"

namespace qsmesh::background {

struct SizeOptions {
  /// Largest edge length (model units). Must be > 0.
  double size = 0;
  /// Smallest edge length the curvature adaptation may ask for (model units); 0 means size / 20.
  double min_size = 0;
  /// Edges per full turn on curved geometry: a radius of curvature R gives edges of 2 pi R / n.
  double edges_per_turn = 16;
  /// Largest growth of the size per unit distance (paper 000 Eq. 10: 0.25 is a progression ratio
  /// of 1.25 between neighbouring edges).
  double gradation = 0.25;
  /// Cap the size on curves by the distance to the nearest non-adjacent curve (small CAD features,
  /// paper 000 Sec. 4.1), so that narrow faces get edges as short as they are wide.
  bool feature_size = true;
  /// Fields at the geometry's resolution: when > 0, the background of a face is not capped by
  /// `size` but by field_cap(), the larger of `size` and the diagonal of the face's bounding box
  /// divided by this number; curvature, small features and the gradation from the boundary refine
  /// it as before. The cross field, its singularities, the conformal scaling and the size map are
  /// smooth and computed on this mesh; the quad stages sample them. Its vertex count then depends
  /// on the geometry, not on the target size, and the field stages cost little next to the quads.
  /// 0: the background follows `size`, as in paper 000 Sec. 3.1.
  double field_divisions = 0;

  [[nodiscard]] double effective_min_size() const { return min_size > 0 ? min_size : size / 20; }
  /// The size for a radius of curvature 1/kappa (kappa >= 0, 1/model units), within the bounds.
  [[nodiscard]] double from_curvature(double kappa) const;
  /// The background's largest edge length on a face whose 3D bounding box has diagonal `diagonal`
  /// (model units): `size`, or max(size, diagonal / field_divisions) when field_divisions > 0.
  [[nodiscard]] double field_cap(double diagonal) const;
  /// These options with the largest size raised to `cap` (>= size) and the smallest kept: the
  /// sizes of one face or curve of a background at the geometry's resolution.
  [[nodiscard]] SizeOptions capped(double cap) const;
};

/// Size field of one face: the curvature size of the face, graded from the boundary: at a point x
/// it is at most h_b + gradation * |x - b| for every boundary vertex b with local edge length h_b.
/// Without the grading, a curve meshed finely (for the curvature of a neighbouring face, say) next
/// to a face of large size forces long thin triangles along it.
class FaceSizeField {
 public:
  /// boundary: the face's boundary vertices (3D) and the mean length of their two boundary edges.
  FaceSizeField(const cad::FaceGeometry& surface, const SizeOptions& sizes,
                std::vector<Vec3> boundary_points, std::vector<double> boundary_sizes);
  /// Target edge length at (uv, xyz) of the face (model units).
  [[nodiscard]] double operator()(const Vec2& uv, const Vec3& xyz) const;

 private:
  const cad::FaceGeometry& surface_;
  const SizeOptions& sizes_;
  std::vector<Vec3> points_;
  std::vector<double> sizes_at_;
};

/// Largest absolute principal curvature of `surface` at uv (1/model units), 0 where it cannot
/// be computed (singular parametrization).
[[nodiscard]] double max_principal_curvature(const cad::FaceGeometry& surface, const Vec2& uv);

/// Curvature of a curve at t (1/model units); 0 for a degenerate curve.
[[nodiscard]] double curve_curvature(const cad::CurveGeometry& curve, double t);

}  // namespace qsmesh::background
