// Robust geometric predicates on the parameter plane: orientation and in-circle tests whose sign
// is exact for every double input (a floating-point filter, then exact expansion arithmetic when
// the filter cannot decide). Used by the parametric Delaunay kernel (paper 000 Sec. 3.1, 5.1) so
// that point location, cavity star-shapedness and boundary recovery never go wrong on nearly
// degenerate configurations.
#pragma once

#include "qsmesh/core/types.hpp"

namespace qsmesh::mesh {

/// Orientation of (a, b, c): positive when counterclockwise, negative when clockwise, zero when
/// collinear. The sign is exact; the magnitude approximates twice the signed area.
[[nodiscard]] double orient2d(const Vec2& a, const Vec2& b, const Vec2& c);

/// In-circle test: positive when d lies strictly inside the circle through a, b, c (given
/// counterclockwise; the sign flips for a clockwise triangle), negative outside, zero when the four
/// points are cocircular. The sign is exact; the magnitude is an approximation of the determinant.
[[nodiscard]] double incircle(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d);

/// The same determinants in plain floating point (no exactness); for tests and comparisons.
[[nodiscard]] double orient2d_naive(const Vec2& a, const Vec2& b, const Vec2& c);
[[nodiscard]] double incircle_naive(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d);

}  // namespace qsmesh::mesh
