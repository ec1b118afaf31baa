// Size field of the background mesh: a cap from the user and a curvature adaptation
// (paper 000 Sec. 3.1: the cross field is computed on "meshes adapted to the geometric features").
// The small-feature and cross-field size maps of Sec. 4 come later and replace this as the
// size map of the final mesh; the background mesh keeps this one.
#pragma once

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

  [[nodiscard]] double effective_min_size() const { return min_size > 0 ? min_size : size / 20; }
  /// The size for a radius of curvature 1/kappa (kappa >= 0, 1/model units), within the bounds.
  [[nodiscard]] double from_curvature(double kappa) const;
};

/// Largest absolute principal curvature of `surface` at uv (1/model units), 0 where it cannot
/// be computed (singular parametrization).
[[nodiscard]] double max_principal_curvature(const cad::FaceGeometry& surface, const Vec2& uv);

/// Curvature of a curve at t (1/model units); 0 for a degenerate curve.
[[nodiscard]] double curve_curvature(const cad::CurveGeometry& curve, double t);

}  // namespace qsmesh::background
