#include "analytic_surfaces.hpp"

#include <cmath>

namespace qsmesh::test {

cad::SurfaceEval2 AnalyticSurface::eval2(const Vec2& uv) const {
  cad::SurfaceEval2 e;
  static_cast<cad::SurfaceEval&>(e) = eval(uv);
  return e;
}

Vec3 AnalyticSurface::normal(const Vec2& uv) const {
  const auto e = eval(uv);
  return normalized(cross(e.du, e.dv));
}

Vec2 AnalyticSurface::project(const Vec3& p, const Vec2& uv_guess, Vec3* foot) const {
  if (projection_ == Projection::kGuess) return uv_guess;
  // A fixed number of steps: enough for the smooth surfaces here, and deterministic.
  Vec2 uv = uv_guess;
  for (int it = 0; it < 30; ++it) {
    const auto e = eval(uv);
    const Vec3 r = e.p - p;
    const double a = dot(e.du, e.du), b = dot(e.du, e.dv), c = dot(e.dv, e.dv);
    const double det = a * c - b * b;
    if (det <= 1e-300) break;
    const double gu = dot(r, e.du), gv = dot(r, e.dv);
    uv = uv - Vec2{(c * gu - b * gv) / det, (a * gv - b * gu) / det};
  }
  if (foot != nullptr) *foot = eval(uv).p;
  return uv;
}

cad::SurfaceEval Plane::eval(const Vec2& uv) const {
  return {{uv.u, uv.v, 0}, {1, 0, 0}, {0, 1, 0}};
}

cad::SurfaceEval Cylinder::eval(const Vec2& uv) const {
  const double c = std::cos(uv.u), s = std::sin(uv.u);
  return {{r_ * c, r_ * s, uv.v}, {-r_ * s, r_ * c, 0}, {0, 0, 1}};
}

cad::SurfaceEval Sphere::eval(const Vec2& uv) const {
  const double cu = std::cos(uv.u), su = std::sin(uv.u), cv = std::cos(uv.v), sv = std::sin(uv.v);
  return {{r_ * cv * cu, r_ * cv * su, r_ * sv},
          {-r_ * cv * su, r_ * cv * cu, 0},
          {-r_ * sv * cu, -r_ * sv * su, r_ * cv}};
}

cad::SurfaceEval Polar::eval(const Vec2& uv) const {
  const double c = std::cos(uv.u), s = std::sin(uv.u);
  return {{uv.v * c, uv.v * s, 0}, {-uv.v * s, uv.v * c, 0}, {c, s, 0}};
}

}  // namespace qsmesh::test
