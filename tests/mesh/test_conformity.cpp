// mesh::check_conformity on a face the CAD gives twice (two faces on one surface, one boundary):
// each copy's mesh may have the same edge between two curve vertices, inside itself; misoriented
// and degenerate elements. mesh::max_distance_to_cad split by dimension and by entity.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/validate.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::mesh {
namespace {

// The strip [0, 3] x [0, 0.5] meshed as one row of three quads on the vertices b0..b3 (y = 0)
// and t0..t3 (y = 0.5), ids 0-3 and 4-7; quad i goes to face face_of_quad[i] (three quads per
// entry of `faces`). Bars on the model's four curves.
SurfaceMesh strip_rows(const cad::CadModel& model, const std::vector<std::array<LO, 3>>& faces) {
  SurfaceMesh m;
  for (int row = 0; row < 2; ++row)
    for (int i = 0; i <= 3; ++i) {
      m.points.push_back({static_cast<double>(i), 0.5 * row, 0});
      m.vclass.push_back({});
    }
  auto curve_between = [&](GO a, GO b) {
    for (LO c = 0; c < model.num_curves(); ++c) {
      const auto& cc = model.curves()[c].corners;
      const Vec3 p = model.corners()[cc[0]].point, q = model.corners()[cc[1]].point;
      const Vec3 pa = m.points[static_cast<std::size_t>(a)],
                 pb = m.points[static_cast<std::size_t>(b)];
      if ((distance(p, pa) < 1e-9 && distance(q, pb) < 1e-9) ||
          (distance(p, pb) < 1e-9 && distance(q, pa) < 1e-9))
        return c;
    }
    return kNoIndex;
  };
  const LO bottom = curve_between(0, 3), top = curve_between(4, 7), left = curve_between(0, 4),
           right = curve_between(3, 7);
  EXPECT_TRUE(bottom >= 0 && top >= 0 && left >= 0 && right >= 0);
  for (GO i = 0; i < 3; ++i) {
    m.bars.push_back({i, i + 1});
    m.bar_curve.push_back(bottom);
    m.bars.push_back({i + 4, i + 5});
    m.bar_curve.push_back(top);
  }
  m.bars.push_back({0, 4});
  m.bar_curve.push_back(left);
  m.bars.push_back({3, 7});
  m.bar_curve.push_back(right);
  for (const auto& face_of_quad : faces)
    for (GO i = 0; i < 3; ++i) {
      m.quads.push_back({i, i + 1, i + 5, i + 4});
      m.quad_face.push_back(face_of_quad[static_cast<std::size_t>(i)]);
    }
  m.num_cad_faces = model.num_faces();
  m.num_cad_curves = model.num_curves();
  m.num_cad_corners = static_cast<LO>(model.corners().size());
  return m;
}

TEST(Conformity, AFaceGivenTwiceMayHaveItsCopysEdgesInside) {
  const cad::CadModel model = cad::load_cad(
      test::write_rectangle_given_twice(3.0, 0.5, test::tmp_dir() + "/strip_twice.brep"));
  ASSERT_EQ(model.num_faces(), 2);
  ASSERT_EQ(model.num_curves(), 4);
  // Both copies meshed alike: the cross edges b1-t1 and b2-t2 are inside face 0 and inside face 1.
  const ConformityReport same = check_conformity(strip_rows(model, {{0, 0, 0}, {1, 1, 1}}), model);
  EXPECT_TRUE(same.ok()) << same.summary();
  // Face 0 with the first quad only and face 1 with the last two meet at b1-t1, once each, off the
  // curves: that does not conform (and b2-t2 is then inside face 1 alone, which does).
  const ConformityReport split = check_conformity(strip_rows(model, {{0, 1, 1}}), model);
  EXPECT_EQ(split.interior_edges_bad, 1) << split.summary();
  EXPECT_EQ(split.curve_edges_bad, 8) << split.summary();  // each curve edge used once, not twice
}

TEST(Conformity, MisorientedAndDegenerateElementsAreCounted) {
  const cad::CadModel model = cad::load_cad(
      test::write_rectangle_given_twice(3.0, 0.5, test::tmp_dir() + "/strip_twice_orient.brep"));
  SurfaceMesh m = strip_rows(model, {{0, 0, 0}, {1, 1, 1}});
  ASSERT_TRUE(check_conformity(m, model).ok());
  // The middle quad reversed: its two cross edges b1-t1 and b2-t2 are then traversed the same way
  // as by its neighbours; the curve edges keep their counts.
  std::swap(m.quads[1][1], m.quads[1][3]);
  ConformityReport flipped = check_conformity(m, model);
  EXPECT_EQ(flipped.orientation_bad, 2) << flipped.summary();
  EXPECT_EQ(flipped.interior_edges_bad, 0) << flipped.summary();
  EXPECT_EQ(flipped.edges, 10) << flipped.summary();
  // A quad repeating a vertex is counted and its edges left out: b2-t2 is then once in face 0 and
  // twice in face 1 (bad), and the curve edges b2-b3, t2-t3, b3-t3 are used by face 1 alone.
  m = strip_rows(model, {{0, 0, 0}, {1, 1, 1}});
  m.quads[2][1] = m.quads[2][0];
  const ConformityReport degenerate = check_conformity(m, model);
  EXPECT_EQ(degenerate.degenerate_elements, 1) << degenerate.summary();
  EXPECT_EQ(degenerate.interior_edges_bad, 1) << degenerate.summary();
  EXPECT_EQ(degenerate.curve_edges_bad, 3) << degenerate.summary();
  EXPECT_EQ(degenerate.faces_without_elements, 0) << degenerate.summary();
}

// A vertex of each dimension on a cylinder (curved curves and face), each moved off its entity by
// a known distance: the whole mesh's maximum is the largest of the by-dimension maxima, and a
// curve mesh gives its interior vertices' distance.
TEST(DistanceToCad, ByDimensionSplitsTheMaximum) {
  const cad::CadModel model =
      cad::load_cad(test::write_cylinder(test::tmp_dir() + "/dist_cyl.brep"));
  ASSERT_GT(model.num_faces(), 0);
  LO curve = kNoIndex;
  for (LO c = 0; c < model.num_curves() && curve == kNoIndex; ++c)
    if (!model.curves()[c].degenerate) curve = c;
  ASSERT_NE(curve, kNoIndex);
  const cad::Curve& cc = model.curves()[curve];
  const double t = 0.3 * cc.t0 + 0.7 * cc.t1;
  const Box2 box = model.faces()[0].uv_box;
  const Vec2 uv{0.5 * (box.lo.u + box.hi.u), 0.5 * (box.lo.v + box.hi.v)};
  const Vec3 on_curve = model.curve_geometry(curve)->point(t);
  const Vec3 on_face = model.face_geometry(0)->eval(uv).p;
  SurfaceMesh m;
  m.points.push_back(model.corners()[0].point + Vec3{0, 0, 0.01});
  m.vclass.push_back({0, 0, kNoIndex, {0, 0}});
  m.points.push_back(on_curve + Vec3{0.02, 0, 0});
  m.vclass.push_back({1, curve, 1, {t, 0}});
  m.points.push_back(on_face + Vec3{0, 0.03, 0});
  m.vclass.push_back({2, 0, kNoIndex, {uv.u, uv.v}});
  EXPECT_NEAR(max_distance_to_cad(m.points, m.vclass, model, 0), 0.01, 1e-9);
  EXPECT_NEAR(max_distance_to_cad(m.points, m.vclass, model, 1), 0.02, 1e-9);
  EXPECT_NEAR(max_distance_to_cad(m.points, m.vclass, model, 2), 0.03, 1e-9);
  EXPECT_EQ(max_distance_to_cad(m, model), max_distance_to_cad(m.points, m.vclass, model, 2));
  // The face vertex back on its face: the curve vertex is then the farthest.
  m.points[2] = on_face;
  EXPECT_EQ(max_distance_to_cad(m, model), max_distance_to_cad(m.points, m.vclass, model, 1));
  EXPECT_NEAR(max_distance_to_cad(m, model), 0.02, 1e-9);
  // The same vertex as the interior vertex of a curve mesh (the ends are not counted).
  CurveMesh cm;
  cm.curve = curve;
  cm.t = {cc.t0, t, cc.t1};
  cm.points = {model.curve_geometry(curve)->point(cc.t0) + Vec3{1, 0, 0},
               on_curve + Vec3{0.02, 0, 0},
               model.curve_geometry(curve)->point(cc.t1) + Vec3{1, 0, 0}};
  EXPECT_NEAR(max_distance_to_cad(cm, model), 0.02, 1e-9);
  EXPECT_EQ(max_distance_to_cad(m.points, std::span<const VertexClass>(m.vclass), model, 1),
            max_distance_to_cad(cm, model));
}

}  // namespace
}  // namespace qsmesh::mesh
