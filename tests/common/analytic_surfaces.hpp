// Analytic test surfaces implementing cad::FaceGeometry without OpenCASCADE: a plane, a cylinder,
// a sphere and the plane in polar coordinates. Shared by the mesh, smooth and qstruct tests.
#pragma once

#include "qsmesh/cad/geometry.hpp"

namespace qsmesh::test {

/// How AnalyticSurface::project finds (u, v).
enum class Projection {
  kNewton,  ///< Newton steps on the normal equations from the guess (smooth surfaces)
  kGuess,  ///< returns the guess unchanged and leaves foot untouched (for code that never projects)
};

/// Base of the analytic surfaces: subclasses give eval(); eval2 has zero second derivatives, the
/// normal is du x dv normalised (zero at a pole), there is no boundary (boundary_uv returns
/// (0, 0)) and every uv is inside.
class AnalyticSurface : public cad::FaceGeometry {
 public:
  explicit AnalyticSurface(Projection projection = Projection::kNewton) : projection_(projection) {}
  [[nodiscard]] cad::SurfaceEval2 eval2(const Vec2& uv) const override;
  [[nodiscard]] Vec3 normal(const Vec2& uv) const override;
  [[nodiscard]] Vec2 project(const Vec3& p, const Vec2& uv_guess, Vec3* foot) const override;
  [[nodiscard]] Vec2 boundary_uv(LO, LO, double) const override { return {}; }
  [[nodiscard]] bool contains(const Vec2&) const override { return true; }

 private:
  Projection projection_;
};

/// The plane z = 0, u = x, v = y.
class Plane : public AnalyticSurface {
 public:
  using AnalyticSurface::AnalyticSurface;
  [[nodiscard]] cad::SurfaceEval eval(const Vec2& uv) const override;
};

/// Cylinder of radius r around the z axis: u the angle (radians), v the height.
class Cylinder : public AnalyticSurface {
 public:
  explicit Cylinder(double r, Projection projection = Projection::kNewton)
      : AnalyticSurface(projection), r_(r) {}
  [[nodiscard]] cad::SurfaceEval eval(const Vec2& uv) const override;

 private:
  double r_;
};

/// Sphere of radius r at the origin: u the longitude, v the latitude (radians); poles at
/// v = +-pi/2.
class Sphere : public AnalyticSurface {
 public:
  explicit Sphere(double r, Projection projection = Projection::kNewton)
      : AnalyticSurface(projection), r_(r) {}
  [[nodiscard]] cad::SurfaceEval eval(const Vec2& uv) const override;

 private:
  double r_;
};

/// The plane z = 0 in polar coordinates, u the angle, v the radius: singular (a pole) at v = 0.
class Polar : public AnalyticSurface {
 public:
  using AnalyticSurface::AnalyticSurface;
  [[nodiscard]] cad::SurfaceEval eval(const Vec2& uv) const override;
};

}  // namespace qsmesh::test
