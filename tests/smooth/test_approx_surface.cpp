#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepTools.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <cmath>
#include <cstdint>
#include <gp_Ax3.hxx>
#include <gp_Cylinder.hxx>
#include <gp_Pln.hxx>
#include <gp_Sphere.hxx>
#include <limits>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>

#include "face_case.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/smooth/approx_surface.hpp"
#include "qsmesh/smooth/smooth.hpp"

namespace qsmesh::smooth {
namespace {

using Case = test::FaceCase;
using test::load_face;

// n x n quads over the uv box (boundary dim 1, corners dim 0); interior uv perturbed by `amp`.
mesh::FaceMesh grid(const cad::FaceGeometry& g, Box2 box, int n, double amp) {
  mesh::FaceMesh m;
  m.face = 0;
  std::uint64_t s = 12345;
  auto rnd = [&] {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(s >> 11) / static_cast<double>(1ULL << 53) * 2.0 - 1.0;
  };
  const double hu = (box.hi.u - box.lo.u) / n, hv = (box.hi.v - box.lo.v) / n;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      Vec2 uv{box.lo.u + hu * i, box.lo.v + hv * j};
      mesh::VertexClass c;
      const bool bi = i == 0 || i == n, bj = j == 0 || j == n;
      if (bi && bj) {
        c.dim = 0;
        c.entity = 0;
      } else if (bi || bj) {
        c.dim = 1;
        c.entity = 0;
        c.index = j * (n + 1) + i;
      } else {
        uv += Vec2{amp * hu * rnd(), amp * hv * rnd()};
        c.param = {uv.u, uv.v};
      }
      m.uv.push_back(uv);
      m.points.push_back(g.eval(uv).p);
      m.vclass.push_back(c);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const auto id = [&](int a, int b) { return static_cast<LO>(b * (n + 1) + a); };
      m.quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

// Closest points do not depend on the hint, and the surface at the interpolated uv agrees with
// the CAD projection to the triangulation's error (O(h^2) on the surface, O(h * distance) off it).
void expect_agrees_with_cad(const Case& c, int n, double offset, double tol, const char* what) {
  const Box2 box = c.model.faces()[0].uv_box;
  const auto m = grid(*c.geometry, box, n, 0.0);
  const auto approx = ApproxSurface::from_mesh(m);
  ASSERT_EQ(approx.num_triangles(), 2 * n * n);
  double worst = 0;
  for (int j = 0; j < 17; ++j)
    for (int i = 0; i < 17; ++i) {
      const Vec2 uv{box.lo.u + (box.hi.u - box.lo.u) * (i + 0.37) / 17.4,
                    box.lo.v + (box.hi.v - box.lo.v) * (j + 0.61) / 17.4};
      const Vec3 p = c.geometry->eval(uv).p + c.geometry->normal(uv) * (offset * ((i + j) % 3 - 1));
      const auto hit = approx.closest(p);
      ASSERT_NE(hit.triangle, kNoIndex);
      // A hint changes the search, not the answer.
      const auto hinted = approx.closest(p, (i * 31 + j) % approx.num_triangles());
      EXPECT_EQ(hinted.triangle, hit.triangle);
      EXPECT_NEAR(hit.distance, distance(hit.point, p), 1e-12);
      Vec3 foot;
      const Vec2 exact = c.geometry->project(p, uv, &foot);
      (void)exact;
      worst = std::max(worst, distance(c.geometry->eval(hit.uv).p, foot));
    }
  std::printf("%s: %d x %d quads, largest |S(uv_approx) - CAD foot| = %.3g (tolerance %.3g)\n",
              what, n, n, worst, tol);
  EXPECT_LT(worst, tol);
}

TEST(ApproxSurface, PlaneIsExact) {
  const Case c = load_face(
      BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 0.0, 5.0, 0.0, 3.0).Face(),
      "approx_plane.brep");
  expect_agrees_with_cad(c, 6, 0.3, 1e-12, "plane");
}

TEST(ApproxSurface, CylinderAgreesWithCadProjection) {
  const Case c =
      load_face(BRepBuilderAPI_MakeFace(gp_Cylinder(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2.0),
                                        0.0, std::numbers::pi, 0.0, 3.0)
                    .Face(),
                "approx_cyl.brep");
  // Chord sag of a 2 pi / 40 arc of radius 2: about 0.012; the uv error is of that order.
  expect_agrees_with_cad(c, 20, 0.2, 0.03, "cylinder 20");
  expect_agrees_with_cad(c, 40, 0.2, 0.008, "cylinder 40");
}

TEST(ApproxSurface, SpherePatchAgreesWithCadProjection) {
  const Case c =
      load_face(BRepBuilderAPI_MakeFace(gp_Sphere(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 3.0),
                                        0.2, 2.0, -0.8, 0.9)
                    .Face(),
                "approx_sphere.brep");
  expect_agrees_with_cad(c, 24, 0.3, 0.03, "sphere patch");
}

TEST(ApproxSurface, SmoothingWithItKeepsPointsOnTheSurface) {
  const Case c =
      load_face(BRepBuilderAPI_MakeFace(gp_Cylinder(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2.0),
                                        0.0, std::numbers::pi, 0.0, 3.0)
                    .Face(),
                "approx_smooth.brep");
  const auto in = grid(*c.geometry, c.model.faces()[0].uv_box, 14, 0.35);
  SmoothOptions o;
  o.laplacian_uv = false;
  o.iterations = 20;
  o.approximate_projection = true;
  SmoothStats st;
  const auto out = smooth_face(in, *c.geometry, o, &st);
  std::printf(
      "cylinder, approximate projection: SICN min %.4f -> %.4f, avg %.4f -> %.4f, %d passes\n",
      st.before.sicn_min, st.after.sicn_min, st.before.sicn_avg, st.after.sicn_avg, st.iterations);
  // Same quality as with Gauss-Newton on the CAD surface (cells of aspect 2: SICN 0.8 at best).
  o.approximate_projection = false;
  SmoothStats exact;
  (void)smooth_face(in, *c.geometry, o, &exact);
  std::printf("cylinder, exact projection: SICN min %.4f avg %.4f\n", exact.after.sicn_min,
              exact.after.sicn_avg);
  EXPECT_GT(st.after.sicn_min, st.before.sicn_min);
  EXPECT_GT(st.after.sicn_min, 0.7);
  EXPECT_NEAR(st.after.sicn_avg, exact.after.sicn_avg, 0.01);
  for (std::size_t v = 0; v < out.points.size(); ++v) {
    EXPECT_NEAR(std::hypot(out.points[v].x, out.points[v].y), 2.0, 1e-9);
    EXPECT_LT(distance(c.geometry->eval(out.uv[v]).p, out.points[v]), 1e-9);
  }
}

}  // namespace
}  // namespace qsmesh::smooth
