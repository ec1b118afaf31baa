// Geometry interfaces of CAD curves and faces. No OpenCASCADE type appears here: the OpenCASCADE
// implementations live in src/cad, and tests may implement these interfaces analytically.
//
// An evaluator object is used from one thread at a time (it may cache projection data);
// CadModel hands out a new one per call, so each task makes its own.
#pragma once

#include "qsmesh/core/types.hpp"

namespace qsmesh::cad {

/// Point and first derivatives of a surface at (u, v).
struct SurfaceEval {
  Vec3 p;   ///< position (model units)
  Vec3 du;  ///< dS/du
  Vec3 dv;  ///< dS/dv
};

/// Point, first and second derivatives of a surface at (u, v).
struct SurfaceEval2 : SurfaceEval {
  Vec3 duu, duv, dvv;
};

/// A CAD curve C(t), t in [t0, t1].
class CurveGeometry {
 public:
  virtual ~CurveGeometry() = default;
  /// C(t). A degenerate curve returns its single point for every t.
  [[nodiscard]] virtual Vec3 point(double t) const = 0;
  /// dC/dt (zero for a degenerate curve).
  [[nodiscard]] virtual Vec3 derivative(double t) const = 0;
  /// d2C/dt2 (zero for a degenerate curve).
  [[nodiscard]] virtual Vec3 second_derivative(double t) const = 0;
  /// Parameter of the point of the curve nearest to p, searched from t_guess first; the result is
  /// clamped to [t0, t1]. foot, when not null, receives C(t).
  [[nodiscard]] virtual double project(const Vec3& p, double t_guess, Vec3* foot) const = 0;
};

/// A CAD face: its surface S(u, v) and the parameter curves (pcurves) of its boundary.
class FaceGeometry {
 public:
  virtual ~FaceGeometry() = default;
  [[nodiscard]] virtual SurfaceEval eval(const Vec2& uv) const = 0;
  [[nodiscard]] virtual SurfaceEval2 eval2(const Vec2& uv) const = 0;
  /// Unit normal at (u, v), oriented as the face (outward for a closed solid); zero at a
  /// singular point of the parametrization (pole).
  [[nodiscard]] virtual Vec3 normal(const Vec2& uv) const = 0;
  /// (u, v) of the point of the surface nearest to p, searched from uv_guess; foot, when not null,
  /// receives S(u, v).
  [[nodiscard]] virtual Vec2 project(const Vec3& p, const Vec2& uv_guess, Vec3* foot) const = 0;
  /// Parameter-plane point of the face's boundary curve use `use` of loop `loop` at curve
  /// parameter t (the face's pcurve). For a seam curve, its two uses give its two images.
  [[nodiscard]] virtual Vec2 boundary_uv(LO loop, LO use, double t) const = 0;
  /// True when uv lies inside the face's trimmed domain (on the boundary counts as inside).
  /// Throws qsmesh::Error when the evaluator was made without a classifier.
  [[nodiscard]] virtual bool contains(const Vec2& uv) const = 0;
};

}  // namespace qsmesh::cad
