// Evaluation and projection on curves and faces.
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <GeomAPI_PointsToBSplineSurface.hxx>
#include <Geom_BSplineSurface.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <bit>
#include <cmath>
#include <cstdint>
#include <gp_Pln.hxx>
#include <numbers>
#include <thread>
#include <vector>

#include "helpers.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::cad {
namespace {

// Projection of surface points from a perturbed guess returns the parameters.
void check_round_trip(const CadModel& m, LO f) {
  const Face& face = m.faces()[f];
  const auto g = m.face_geometry(f);
  const Box2& b = face.uv_box;
  const double su = b.hi.u - b.lo.u, sv = b.hi.v - b.lo.v;
  int n = 0;
  for (int i = 1; i < 8; ++i)
    for (int j = 1; j < 8; ++j) {
      const Vec2 uv{b.lo.u + su * i / 8.0, b.lo.v + sv * j / 8.0};
      const Vec3 p = g->eval(uv).p;
      const Vec2 guess = uv + Vec2{0.03 * su * ((i % 3) - 1), 0.03 * sv * ((j % 3) - 1)};
      Vec3 foot;
      const Vec2 r = g->project(p, guess, &foot);
      EXPECT_NEAR(r.u, uv.u, 1e-9 * std::max(1.0, su)) << i << " " << j;
      EXPECT_NEAR(r.v, uv.v, 1e-9 * std::max(1.0, sv)) << i << " " << j;
      EXPECT_LT(distance(foot, p), 1e-9 * m.diagonal());
      // A point off the surface along the normal projects back to the same foot.
      const Vec3 n3 = g->normal(uv);
      if (norm(n3) > 0) {
        const Vec2 r2 = g->project(p + n3 * (1e-3 * m.diagonal()), guess, nullptr);
        EXPECT_NEAR(r2.u, uv.u, 1e-7 * std::max(1.0, su));
        EXPECT_NEAR(r2.v, uv.v, 1e-7 * std::max(1.0, sv));
      }
      ++n;
    }
  EXPECT_EQ(n, 49);
}

TEST(CadGeometry, TorusEvalAndProjection) {
  const CadModel m = test::round_trip(BRepPrimAPI_MakeTorus(5, 1.5).Shape(), "torus");
  ASSERT_EQ(m.num_faces(), 1);
  const Face& face = m.faces()[0];
  EXPECT_EQ(face.type, SurfaceType::Torus);
  EXPECT_TRUE(face.u_periodic && face.v_periodic);
  EXPECT_EQ(face.seams.size(), 2u);
  test::expect_closed_loops(m);
  check_round_trip(m, 0);
  // Derivatives against finite differences.
  const auto g = m.face_geometry(0);
  const Vec2 uv{0.7, 1.9};
  const SurfaceEval2 e = g->eval2(uv);
  const double h = 1e-6;
  const Vec3 du = (g->eval({uv.u + h, uv.v}).p - g->eval({uv.u - h, uv.v}).p) / (2 * h);
  const Vec3 dvv = (g->eval({uv.u, uv.v + h}).dv - g->eval({uv.u, uv.v - h}).dv) / (2 * h);
  EXPECT_LT(distance(du, e.du), 1e-6);
  EXPECT_LT(distance(dvv, e.dvv), 1e-5);
  // Outward normal: away from the tube's centre circle.
  const Vec3 p = e.p;
  const Vec3 centre = normalized(Vec3{p.x, p.y, 0}) * 5.0;
  EXPECT_NEAR(dot(g->normal(uv), normalized(p - centre)), 1, 1e-12);
}

TEST(CadGeometry, BSplineEvalAndProjection) {
  TColgp_Array2OfPnt pts(1, 9, 1, 9);
  for (int i = 1; i <= 9; ++i)
    for (int j = 1; j <= 9; ++j) {
      const double x = (i - 1) * 1.25, y = (j - 1) * 1.0;
      pts(i, j) = gp_Pnt(x, y, std::sin(0.6 * x) * std::cos(0.5 * y));
    }
  GeomAPI_PointsToBSplineSurface fit(pts);
  ASSERT_TRUE(fit.IsDone());
  BRepBuilderAPI_MakeFace mf(fit.Surface(), 1e-7);
  ASSERT_TRUE(mf.IsDone());
  const CadModel m = test::round_trip(mf.Face(), "bspline");
  ASSERT_EQ(m.num_faces(), 1);
  EXPECT_EQ(m.faces()[0].type, SurfaceType::BSpline);
  EXPECT_EQ(m.num_curves(), 4);
  test::expect_closed_loops(m);
  check_round_trip(m, 0);
  const auto g = m.face_geometry(0);
  EXPECT_GT(test::signed_area(test::loop_polygon(m, *g, 0, 0)), 0);
  // Every boundary use starts where the previous one ended, in (u, v) too.
  const Loop& loop = m.faces()[0].loops[0];
  for (LO k = 0; k < 4; ++k) {
    const CurveUse& a = loop.uses[k];
    const CurveUse& b = loop.uses[(k + 1) % 4];
    const Curve& ca = m.curves()[a.curve];
    const Curve& cb = m.curves()[b.curve];
    const Vec2 end = g->boundary_uv(0, k, a.reversed ? ca.t0 : ca.t1);
    const Vec2 start = g->boundary_uv(0, (k + 1) % 4, b.reversed ? cb.t1 : cb.t0);
    EXPECT_LT(norm(end - start), 1e-9);
  }
}

// The face evaluator keeps its last evaluation (the smoother evaluates a moved vertex, then the
// normal there): any sequence of eval, eval2, normal and project on one evaluator gives, bit for
// bit, what a fresh evaluator gives at the same parameters, +0 and -0 told apart.
TEST(CadGeometry, RepeatedEvaluationIsBitIdentical) {
  TColgp_Array2OfPnt pts(1, 7, 1, 7);
  for (int i = 1; i <= 7; ++i)
    for (int j = 1; j <= 7; ++j) {
      const double x = (i - 1) * 1.5, y = (j - 1) * 1.0;
      pts(i, j) = gp_Pnt(x, y, std::cos(0.7 * x) * std::sin(0.4 * y));
    }
  GeomAPI_PointsToBSplineSurface fit(pts);
  ASSERT_TRUE(fit.IsDone());
  BRepBuilderAPI_MakeFace mf(fit.Surface(), 1e-7);
  ASSERT_TRUE(mf.IsDone());
  const CadModel m = test::round_trip(mf.Face(), "bspline_cache");
  const Box2& b = m.faces()[0].uv_box;
  const auto same = [](const Vec3& x, const Vec3& y) {
    return std::bit_cast<std::uint64_t>(x.x) == std::bit_cast<std::uint64_t>(y.x) &&
           std::bit_cast<std::uint64_t>(x.y) == std::bit_cast<std::uint64_t>(y.y) &&
           std::bit_cast<std::uint64_t>(x.z) == std::bit_cast<std::uint64_t>(y.z);
  };
  const auto g = m.face_geometry(0);
  std::vector<Vec2> uvs;
  for (int k = 0; k < 40; ++k)
    uvs.push_back({b.lo.u + (b.hi.u - b.lo.u) * ((k * 7) % 11) / 10.0,
                   b.lo.v + (b.hi.v - b.lo.v) * ((k * 3) % 5) / 4.0});
  uvs.push_back({0.0, b.lo.v});
  uvs.push_back({-0.0, b.lo.v});
  for (std::size_t k = 0; k < uvs.size(); ++k) {
    const Vec2 uv = uvs[k];
    const auto fresh = m.face_geometry(0);
    const SurfaceEval e0 = fresh->eval(uv);
    const Vec3 n0 = m.face_geometry(0)->normal(uv);
    // eval twice, then normal, eval2 and eval again at the same uv; then a different uv.
    for (int rep = 0; rep < 2; ++rep) {
      const SurfaceEval e = g->eval(uv);
      EXPECT_TRUE(same(e.p, e0.p) && same(e.du, e0.du) && same(e.dv, e0.dv)) << k;
    }
    EXPECT_TRUE(same(g->normal(uv), n0)) << k;
    const SurfaceEval2 e2 = g->eval2(uv);
    EXPECT_TRUE(same(e2.p, m.face_geometry(0)->eval2(uv).p)) << k;
    EXPECT_TRUE(same(g->eval(uv).du, e0.du)) << k;
    (void)g->project(e0.p + Vec3{0.01, 0.02, 0.03}, uv, nullptr);
    EXPECT_TRUE(same(g->eval(uv).p, e0.p)) << k;
  }
}

TEST(CadGeometry, CurveProjection) {
  const CadModel m = test::round_trip(BRepPrimAPI_MakeCylinder(2, 5).Shape(), "cyl_curves");
  for (LO c = 0; c < m.num_curves(); ++c) {
    const Curve& cu = m.curves()[c];
    const auto g = m.curve_geometry(c);
    EXPECT_LT(distance(g->point(cu.t0), m.corners()[cu.corners[0]].point), 1e-7);
    EXPECT_LT(distance(g->point(cu.t1), m.corners()[cu.corners[1]].point), 1e-7);
    if (cu.type != CurveType::Circle) continue;
    EXPECT_NEAR(cu.length, 4 * std::numbers::pi, 1e-9);
    for (double s : {0.1, 0.45, 0.8}) {
      const double t = cu.t0 + s * (cu.t1 - cu.t0);
      const Vec3 p = g->point(t);
      const Vec3 off = p + normalized(Vec3{p.x, p.y, 0}) * 0.5 + Vec3{0, 0, 0.3};
      Vec3 foot;
      const double r = g->project(off, t + 0.2, &foot);
      EXPECT_NEAR(r, t, 1e-9);
      EXPECT_LT(distance(foot, p), 1e-9);
      // Derivatives against finite differences.
      const double h = 1e-6;
      EXPECT_LT(distance((g->point(t + h) - g->point(t - h)) / (2 * h), g->derivative(t)), 1e-6);
      EXPECT_LT(distance((g->derivative(t + h) - g->derivative(t - h)) / (2 * h),
                         g->second_derivative(t)),
                1e-5);
    }
    // Far guess and a point beyond the range: still the nearest point, clamped.
    const Vec3 q = g->point(cu.t0 + 0.25 * (cu.t1 - cu.t0)) * 3.0;
    const double r = g->project(q, cu.t0 + 0.75 * (cu.t1 - cu.t0), nullptr);
    EXPECT_GE(r, cu.t0);
    EXPECT_LE(r, cu.t1);
    EXPECT_LT(distance(g->point(r), g->point(cu.t0 + 0.25 * (cu.t1 - cu.t0))), 1e-6);
  }
  // A line edge: projection beyond the end clamps to the end.
  const CadModel ml =
      test::round_trip(BRepBuilderAPI_MakeFace(gp_Pln(gp::XOY()), 0, 4, 0, 1).Face(), "line_face");
  for (LO c = 0; c < ml.num_curves(); ++c) {
    const auto g = ml.curve_geometry(c);
    const Curve& cu = ml.curves()[c];
    const Vec3 beyond = g->point(cu.t1) + (g->point(cu.t1) - g->point(cu.t0));
    Vec3 foot;
    EXPECT_DOUBLE_EQ(g->project(beyond, cu.t0, &foot), cu.t1);
    EXPECT_LT(distance(foot, g->point(cu.t1)), 1e-12);
  }
}

// Many evaluators used at once from different threads give the same answers as one thread.
TEST(CadGeometry, ConcurrentEvaluators) {
  const CadModel m = test::round_trip(BRepPrimAPI_MakeTorus(5, 1.5).Shape(), "torus_mt");
  auto work = [&m](std::vector<double>* out) {
    const auto g = m.face_geometry(0);
    for (int i = 0; i < 200; ++i) {
      const Vec2 uv{0.03 * i, 0.02 * i + 0.1};
      const Vec2 r = g->project(g->eval(uv).p, uv + Vec2{0.05, -0.05}, nullptr);
      out->push_back(r.u);
      out->push_back(r.v);
    }
  };
  std::vector<double> ref;
  work(&ref);
  std::vector<std::vector<double>> res(4);
  std::vector<std::thread> threads;
  for (auto& r : res) threads.emplace_back(work, &r);
  for (auto& t : threads) t.join();
  for (const auto& r : res) EXPECT_EQ(r, ref);
}

}  // namespace
}  // namespace qsmesh::cad

namespace qsmesh::cad {
namespace {

TEST(FaceGeometry, ContainsNeedsAClassifier) {
  const CadModel m = test::round_trip(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(), "classifier_box");
  const auto plain = m.face_geometry(0);
  EXPECT_THROW((void)plain->contains({0, 0}), Error);
  const auto classified = m.face_geometry(0, true);
  const Face& face = m.faces()[0];
  EXPECT_TRUE(classified->contains((face.uv_box.lo + face.uv_box.hi) * 0.5));
}

}  // namespace
}  // namespace qsmesh::cad
