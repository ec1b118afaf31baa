#include "qsmesh/background/size.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace qsmesh::background {

double SizeOptions::from_curvature(double kappa) const {
  const double lo = effective_min_size();
  if (!(kappa > 0) || !std::isfinite(kappa)) return size;
  const double h = 2.0 * std::numbers::pi / (edges_per_turn * kappa);
  return std::clamp(h, lo, size);
}

SizeOptions SizeOptions::capped(double cap) const {
  SizeOptions out = *this;
  out.min_size = effective_min_size();
  out.size = std::max(size, cap);
  return out;
}

double SizeOptions::field_cap(double diagonal) const {
  if (!(field_divisions > 0) || !(diagonal > 0) || !std::isfinite(diagonal)) return size;
  return std::max(size, diagonal / field_divisions);
}

FaceSizeField::FaceSizeField(const cad::FaceGeometry& surface, const SizeOptions& sizes,
                             std::vector<Vec3> boundary_points, std::vector<double> boundary_sizes)
    : surface_(surface),
      sizes_(sizes),
      points_(std::move(boundary_points)),
      sizes_at_(std::move(boundary_sizes)) {}

double FaceSizeField::operator()(const Vec2& uv, const Vec3& xyz) const {
  double h = sizes_.from_curvature(max_principal_curvature(surface_, uv));
  for (std::size_t i = 0; i < points_.size(); ++i) {
    // Compare squared distances first: most boundary vertices are too far to bind.
    const double reach = (h - sizes_at_[i]) / sizes_.gradation;
    if (reach <= 0) {
      h = std::min(h, sizes_at_[i]);
      continue;
    }
    const double d2 = norm2(xyz - points_[i]);
    if (d2 < reach * reach) h = sizes_at_[i] + sizes_.gradation * std::sqrt(d2);
  }
  // No lower clamp here: the curvature part is already bounded, and boundary edges shorter than
  // the smallest size (a curve shorter than it) must be matched inside the face.
  return h;
}

double max_principal_curvature(const cad::FaceGeometry& surface, const Vec2& uv) {
  const cad::SurfaceEval2 e = surface.eval2(uv);
  const Vec3 n_raw = cross(e.du, e.dv);
  const double n_len = norm(n_raw);
  const double E = dot(e.du, e.du), F = dot(e.du, e.dv), G = dot(e.dv, e.dv);
  const double det = E * G - F * F;
  // A vanishing first fundamental form means a pole or a degenerate patch: no usable curvature.
  if (!(n_len > 0) || !(det > 1e-24 * (E + G) * (E + G))) return 0.0;
  const Vec3 n = n_raw / n_len;
  const double L = dot(e.duu, n), M = dot(e.duv, n), N = dot(e.dvv, n);
  // Principal curvatures are the eigenvalues of the shape operator I^-1 II.
  const double H = (E * N - 2 * F * M + G * L) / (2 * det);
  const double K = (L * N - M * M) / det;
  const double disc = std::sqrt(std::max(0.0, H * H - K));
  const double k = std::max(std::abs(H + disc), std::abs(H - disc));
  return std::isfinite(k) ? k : 0.0;
}

double curve_curvature(const cad::CurveGeometry& curve, double t) {
  const Vec3 d1 = curve.derivative(t);
  const Vec3 d2 = curve.second_derivative(t);
  const double s = norm(d1);
  if (!(s > 0)) return 0.0;
  const double k = norm(cross(d1, d2)) / (s * s * s);
  return std::isfinite(k) ? k : 0.0;
}

}  // namespace qsmesh::background
