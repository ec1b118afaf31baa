// cad::planar_with_right_angle_lines: the faces the crossfield stage's exact-uniform shortcut
// takes, known from the CAD alone (the partition's cross-field estimate).
#include <gtest/gtest.h>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <gp_Ax2.hxx>
#include <gp_Trsf.hxx>
#include <numbers>

#include "helpers.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::cad {
namespace {

TEST(UniformFaces, EveryFaceOfARotatedBoxQualifies) {
  // Turned 30 degrees about z and 10 about x: the lines are at right angles of each other, not
  // of the axes.
  gp_Trsf a, b;
  a.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), std::numbers::pi / 6);
  b.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(1, 0, 0)), std::numbers::pi / 18);
  const TopoDS_Shape box =
      BRepBuilderAPI_Transform(BRepPrimAPI_MakeBox(10, 4, 2).Shape(), a.Multiplied(b), true)
          .Shape();
  const CadModel m = test::round_trip(box, "uniform_rotated_box");
  ASSERT_EQ(m.num_faces(), 6);
  for (LO f = 0; f < m.num_faces(); ++f) EXPECT_TRUE(planar_with_right_angle_lines(m, f)) << f;
}

TEST(UniformFaces, RoundHoleAndItsWallDoNot) {
  // A box drilled through along z: the top and bottom faces have a circle in a second loop, the
  // hole's wall is a cylinder; the four sides keep their rectangles.
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(10, 10, 3).Shape();
  const TopoDS_Shape drill =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(5, 5, -1), gp_Dir(0, 0, 1)), 2, 5).Shape();
  const CadModel m = test::round_trip(BRepAlgoAPI_Cut(box, drill).Shape(), "uniform_drilled_box");
  int yes = 0, no = 0;
  for (LO f = 0; f < m.num_faces(); ++f) {
    const Face& face = m.faces()[f];
    const bool expected = face.type == SurfaceType::Plane && face.loops.size() == 1;
    EXPECT_EQ(planar_with_right_angle_lines(m, f), expected) << "face " << f;
    (expected ? yes : no) += 1;
  }
  EXPECT_EQ(yes, 4);
  EXPECT_GE(no, 3);  // top, bottom, the wall (maybe in two halves)
}

TEST(UniformFaces, ALineAt45DegreesDoesNot) {
  // A prism on a right isosceles triangle: its two triangles have the hypotenuse at 45 degrees
  // of the legs; its three rectangles qualify (the long sides are at 90 degrees of the short).
  BRepBuilderAPI_MakePolygon poly(gp_Pnt(0, 0, 0), gp_Pnt(4, 0, 0), gp_Pnt(0, 4, 0), true);
  const TopoDS_Face tri = BRepBuilderAPI_MakeFace(poly.Wire(), true).Face();
  const TopoDS_Shape prism = BRepPrimAPI_MakePrism(tri, gp_Vec(0, 0, 3)).Shape();
  const CadModel m = test::round_trip(prism, "uniform_triangle_prism");
  ASSERT_EQ(m.num_faces(), 5);
  int yes = 0;
  for (LO f = 0; f < m.num_faces(); ++f) {
    std::size_t uses = 0;
    for (const Loop& l : m.faces()[f].loops) uses += l.uses.size();
    EXPECT_EQ(planar_with_right_angle_lines(m, f), uses == 4) << "face " << f;
    yes += planar_with_right_angle_lines(m, f) ? 1 : 0;
  }
  EXPECT_EQ(yes, 3);
  EXPECT_THROW((void)planar_with_right_angle_lines(m, m.num_faces()), Error);
}

}  // namespace
}  // namespace qsmesh::cad
