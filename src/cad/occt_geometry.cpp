// OpenCASCADE evaluators of curves and faces. Each object owns its adaptors, so objects can be
// used concurrently from different threads (one object per thread).
#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <BRep_Tool.hxx>
#include <Extrema_ExtPC.hxx>
#include <Geom2dAdaptor_Curve.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_Surface.hxx>
#include <Precision.hxx>
#include <ShapeAnalysis_Surface.hxx>
#include <Standard_Failure.hxx>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "impl.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::cad {

namespace {

Vec3 to_vec(const gp_Pnt& p) { return {p.X(), p.Y(), p.Z()}; }
Vec3 to_vec(const gp_Vec& v) { return {v.X(), v.Y(), v.Z()}; }

class OcctCurve final : public CurveGeometry {
 public:
  OcctCurve(const TopoDS_Edge& edge, const Curve& curve, const Vec3& corner_point, LO id)
      : t0_(curve.t0), t1_(curve.t1), degenerate_(curve.degenerate), pole_(corner_point) {
    if (degenerate_) return;
    try {
      adaptor_.Initialize(edge);
    } catch (const Standard_Failure&) {
      QSMESH_CHECK(false, "curve " << id << " has no usable geometry");
    }
  }

  Vec3 point(double t) const override {
    if (degenerate_) return pole_;
    return to_vec(adaptor_.Value(t));
  }
  Vec3 derivative(double t) const override {
    if (degenerate_) return {};
    gp_Pnt p;
    gp_Vec d1;
    adaptor_.D1(t, p, d1);
    return to_vec(d1);
  }
  Vec3 second_derivative(double t) const override {
    if (degenerate_) return {};
    gp_Pnt p;
    gp_Vec d1, d2;
    adaptor_.D2(t, p, d1, d2);
    return to_vec(d2);
  }

  double project(const Vec3& p, double t_guess, Vec3* foot) const override {
    if (degenerate_) {
      if (foot) *foot = pole_;
      return std::clamp(t_guess, t0_, t1_);
    }
    double t = std::clamp(t_guess, t0_, t1_);
    bool converged = false;
    const double span = t1_ - t0_;
    // Newton on f(t) = (C(t) - p).C'(t), clamped to the range.
    for (int it = 0; it < 40; ++it) {
      gp_Pnt c;
      gp_Vec d1, d2;
      adaptor_.D2(t, c, d1, d2);
      const Vec3 r = to_vec(c) - p;
      const Vec3 v1 = to_vec(d1), v2 = to_vec(d2);
      const double f = dot(r, v1);
      double fp = dot(v1, v1) + dot(r, v2);
      if (!(fp > 0)) fp = dot(v1, v1);  // Gauss-Newton when the curvature term makes it indefinite
      if (!(fp > 0)) break;
      double tn = std::clamp(t - f / fp, t0_, t1_);
      const double step = std::abs(tn - t);
      t = tn;
      if (step <= 1e-12 * std::abs(span) + 1e-15 * std::abs(t)) {
        // Accept a minimum of the distance only (or a clamped end); a maximum goes to the
        // global search.
        gp_Pnt c2;
        gp_Vec e1, e2;
        adaptor_.D2(t, c2, e1, e2);
        const Vec3 r2 = to_vec(c2) - p;
        converged = t == t0_ || t == t1_ || dot(to_vec(e1), to_vec(e1)) + dot(r2, to_vec(e2)) > 0;
        break;
      }
    }
    double best_t = t;
    double best_d = norm2(point(t) - p);
    if (!converged) {
      // Global search as a fallback, plus both ends.
      try {
        Extrema_ExtPC ext(gp_Pnt(p.x, p.y, p.z), adaptor_, t0_, t1_, 1e-12 * std::max(1.0, span));
        if (ext.IsDone())
          for (int i = 1; i <= ext.NbExt(); ++i)
            if (ext.SquareDistance(i) < best_d) {
              best_d = ext.SquareDistance(i);
              best_t = ext.Point(i).Parameter();
            }
      } catch (const Standard_Failure&) {
      }
      for (double te : {t0_, t1_}) {
        const double d = norm2(point(te) - p);
        if (d < best_d) {
          best_d = d;
          best_t = te;
        }
      }
    }
    best_t = std::clamp(best_t, t0_, t1_);
    if (foot) *foot = point(best_t);
    return best_t;
  }

 private:
  double t0_, t1_;
  bool degenerate_;
  Vec3 pole_;
  BRepAdaptor_Curve adaptor_;
};

class OcctFace final : public FaceGeometry {
 public:
  OcctFace(const CadModel::Impl& impl, const Face& face, LO id, bool with_classifier)
      : reversed_(face.reversed),
        uv_box_(face.uv_box),
        u_periodic_(face.u_periodic),
        v_periodic_(face.v_periodic),
        id_(id) {
    const TopoDS_Face& ff = impl.faces[id];
    try {
      surface_.Initialize(ff, false);
      umin_ = surface_.FirstUParameter();
      umax_ = surface_.LastUParameter();
      vmin_ = surface_.FirstVParameter();
      vmax_ = surface_.LastVParameter();
      geom_ = BRep_Tool::Surface(ff);
      if (with_classifier)
        classifier_ = std::make_unique<BRepTopAdaptor_FClass2d>(ff, Precision::PConfusion());
      for (const auto& loop : impl.loop_edges[id]) {
        std::vector<Geom2dAdaptor_Curve> pl;
        for (const TopoDS_Edge& e : loop) {
          double a, b;
          Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(e, ff, a, b);
          pl.emplace_back();
          if (!pc.IsNull()) pl.back().Load(pc);
        }
        pcurves_.push_back(std::move(pl));
      }
    } catch (const Standard_Failure& e) {
      QSMESH_CHECK(false, "face " << id << " has no usable geometry: " << e.GetMessageString());
    }
  }

  SurfaceEval eval(const Vec2& uv) const override {
    // The smoother and the untangler evaluate a moved vertex, then its normal at the same (u, v):
    // the last evaluation is kept and returned for the same parameters, bit for bit (D1 is
    // deterministic, so this is what evaluating again would give).
    if (last_ok_ &&
        std::bit_cast<std::uint64_t>(uv.u) == std::bit_cast<std::uint64_t>(last_uv_.u) &&
        std::bit_cast<std::uint64_t>(uv.v) == std::bit_cast<std::uint64_t>(last_uv_.v))
      return last_;
    gp_Pnt p;
    gp_Vec du, dv;
    surface_.D1(uv.u, uv.v, p, du, dv);
    last_ = {to_vec(p), to_vec(du), to_vec(dv)};
    last_uv_ = uv;
    last_ok_ = true;
    return last_;
  }
  SurfaceEval2 eval2(const Vec2& uv) const override {
    gp_Pnt p;
    gp_Vec du, dv, duu, dvv, duv;
    surface_.D2(uv.u, uv.v, p, du, dv, duu, dvv, duv);
    SurfaceEval2 e;
    e.p = to_vec(p);
    e.du = to_vec(du);
    e.dv = to_vec(dv);
    e.duu = to_vec(duu);
    e.duv = to_vec(duv);
    e.dvv = to_vec(dvv);
    return e;
  }
  Vec3 normal(const Vec2& uv) const override {
    const SurfaceEval e = eval(uv);
    const Vec3 n = cross(e.du, e.dv);
    // A pole: du or dv vanishes (relative to the other), or they are parallel.
    const double scale = std::max(norm2(e.du), norm2(e.dv));
    if (!(norm(n) > 1e-10 * scale)) return {};
    const Vec3 u = normalized(n);
    return reversed_ ? u * -1.0 : u;
  }

  Vec2 project(const Vec3& p, const Vec2& uv_guess, Vec3* foot) const override {
    Vec2 uv = clamp(uv_guess);
    bool converged = false;
    const double su = std::max(uv_box_.valid() ? uv_box_.hi.u - uv_box_.lo.u : 1.0, 1e-300);
    const double sv = std::max(uv_box_.valid() ? uv_box_.hi.v - uv_box_.lo.v : 1.0, 1e-300);
    double d2 = norm2(eval(uv).p - p);
    // Newton on the gradient of |S - p|^2 / 2 (Gauss-Newton when the Hessian is indefinite),
    // with step halving so the distance never grows.
    for (int it = 0; it < 60 && !converged; ++it) {
      const SurfaceEval2 e = eval2(uv);
      const Vec3 r = e.p - p;
      const double gu = dot(r, e.du), gv = dot(r, e.dv);
      double a = dot(e.du, e.du), b = dot(e.du, e.dv), c = dot(e.dv, e.dv);
      const double ah = a + dot(r, e.duu), bh = b + dot(r, e.duv), ch = c + dot(r, e.dvv);
      if (ah > 0 && ah * ch - bh * bh > 1e-14 * (a * c + 1e-300)) {
        a = ah;
        b = bh;
        c = ch;
      }
      const double det = a * c - b * b;
      if (!(det > 1e-30 * (a * c + 1e-300)) || !(a > 0) || !(c > 0)) break;
      Vec2 step{-(c * gu - b * gv) / det, -(a * gv - b * gu) / det};
      bool accepted = false;
      for (int h = 0; h < 30; ++h) {
        const Vec2 cand = clamp(uv + step);
        const double dc = norm2(eval(cand).p - p);
        if (dc <= d2 * (1 + 1e-15) + 1e-300) {
          const Vec2 moved = cand - uv;
          uv = cand;
          d2 = dc;
          accepted = true;
          if (std::abs(moved.u) <= 1e-15 * su + 1e-15 * std::abs(uv.u) &&
              std::abs(moved.v) <= 1e-15 * sv + 1e-15 * std::abs(uv.v))
            converged = true;
          break;
        }
        step = step * 0.5;
      }
      if (!accepted) {
        converged = true;  // no descent step left: a (possibly constrained) minimum
      }
    }
    if (!converged && !geom_.IsNull()) {
      try {
        if (!analysis_) analysis_ = new ShapeAnalysis_Surface(geom_);
        const gp_Pnt2d q = analysis_->ValueOfUV(gp_Pnt(p.x, p.y, p.z), Precision::Confusion());
        const Vec2 cand = clamp(Vec2{q.X(), q.Y()});
        const double dc = norm2(eval(cand).p - p);
        if (dc < d2) {
          uv = cand;
          d2 = dc;
        }
      } catch (const Standard_Failure&) {
      }
    }
    if (foot) *foot = eval(uv).p;
    return uv;
  }

  Vec2 boundary_uv(LO loop, LO use, double t) const override {
    QSMESH_CHECK(loop >= 0 && loop < static_cast<LO>(pcurves_.size()),
                 "face " << id_ << ": no loop " << loop);
    const auto& pl = pcurves_[loop];
    QSMESH_CHECK(use >= 0 && use < static_cast<LO>(pl.size()),
                 "face " << id_ << " loop " << loop << ": no use " << use);
    QSMESH_CHECK(!pl[use].Curve().IsNull(),
                 "face " << id_ << " loop " << loop << " use " << use << " has no pcurve");
    const gp_Pnt2d q = pl[use].Value(t);
    return {q.X(), q.Y()};
  }

  bool contains(const Vec2& uv) const override {
    QSMESH_CHECK(classifier_ != nullptr,
                 "face " << id_ << ": contains() needs an evaluator made with a classifier");
    const TopAbs_State s = classifier_->Perform(gp_Pnt2d(uv.u, uv.v));
    return s == TopAbs_IN || s == TopAbs_ON;
  }

 private:
  // Keeps uv in the surface's parameter domain; periodic directions are free.
  Vec2 clamp(Vec2 uv) const {
    if (!u_periodic_) uv.u = std::clamp(uv.u, umin_, umax_);
    if (!v_periodic_) uv.v = std::clamp(uv.v, vmin_, vmax_);
    return uv;
  }

  bool reversed_;
  Box2 uv_box_;
  bool u_periodic_, v_periodic_;
  LO id_;
  double umin_ = -Precision::Infinite(), umax_ = Precision::Infinite();
  double vmin_ = -Precision::Infinite(), vmax_ = Precision::Infinite();
  BRepAdaptor_Surface surface_;
  Handle(Geom_Surface) geom_;
  mutable Handle(ShapeAnalysis_Surface) analysis_;
  mutable Vec2 last_uv_;  // parameters of the last eval, and its result (eval)
  mutable SurfaceEval last_;
  mutable bool last_ok_ = false;
  std::unique_ptr<BRepTopAdaptor_FClass2d> classifier_;
  std::vector<std::vector<Geom2dAdaptor_Curve>> pcurves_;
};

}  // namespace

std::unique_ptr<CurveGeometry> make_curve_geometry(const CadModel::Impl& impl, const Curve& curve,
                                                   const Vec3& corner_point, LO c) {
  return std::make_unique<OcctCurve>(impl.edges[c], curve, corner_point, c);
}

std::unique_ptr<FaceGeometry> make_face_geometry(const CadModel::Impl& impl, const Face& face, LO f,
                                                 bool with_classifier) {
  return std::make_unique<OcctFace>(impl, face, f, with_classifier);
}

}  // namespace qsmesh::cad
