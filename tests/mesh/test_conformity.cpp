// mesh::check_conformity on a face the CAD gives twice (two faces on one surface, one boundary):
// each copy's mesh may have the same edge between two curve vertices, inside itself.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
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

}  // namespace
}  // namespace qsmesh::mesh
