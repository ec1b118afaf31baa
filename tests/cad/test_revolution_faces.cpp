// cad::revolution_axis and cad::iso_line_revolution_axis: the faces the crossfield stage's
// revolution shortcut takes, known from the CAD alone (the partition's cross-field estimate).
#include <gtest/gtest.h>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCone.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <cmath>
#include <gp_Ax2.hxx>
#include <numbers>

#include "helpers.hpp"
#include "qsmesh/cad/model.hpp"

namespace qsmesh::cad {
namespace {

// Distance of point p from the line through the axis.
double off_axis(const RevolutionAxis& axis, const Vec3& p) {
  const Vec3 d = p - axis.point;
  return norm(d - axis.direction * dot(d, axis.direction));
}

TEST(RevolutionFaces, DrilledHoleWallQualifiesAndThePlanesDoNot) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(10, 10, 3).Shape();
  const TopoDS_Shape drill =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(5, 5, -1), gp_Dir(0, 0, 1)), 2, 5).Shape();
  const CadModel m = test::round_trip(BRepAlgoAPI_Cut(box, drill).Shape(), "rev_drilled_box");
  int walls = 0;
  for (LO f = 0; f < m.num_faces(); ++f) {
    const auto axis = revolution_axis(m, f);
    if (m.faces()[f].type == SurfaceType::Plane) {
      // The sides have no circle, so no axis; the top and bottom have the hole's, but their
      // square sides are neither parallels nor meridians of it.
      EXPECT_EQ(axis.has_value(), m.faces()[f].loops.size() == 2) << "face " << f;
      EXPECT_FALSE(iso_line_revolution_axis(m, f).has_value()) << "face " << f;
      continue;
    }
    ASSERT_TRUE(axis.has_value()) << "face " << f;
    EXPECT_TRUE(axis->cylinder);
    EXPECT_NEAR(std::abs(axis->direction.z), 1.0, 1e-12);
    EXPECT_NEAR(off_axis(*axis, {5, 5, 0}), 0.0, 1e-9);
    EXPECT_TRUE(iso_line_revolution_axis(m, f).has_value()) << "face " << f;
    ++walls;
  }
  EXPECT_GE(walls, 1);
}

TEST(RevolutionFaces, ConeTorusAndSphereBeltQualify) {
  const gp_Ax2 z(gp_Pnt(1, 2, 3), gp_Dir(0, 1, 0));
  const double quarter = std::numbers::pi / 2;
  struct Case {
    TopoDS_Shape shape;
    SurfaceType type;
    const char* name;
  };
  const Case cases[] = {
      {BRepPrimAPI_MakeCone(z, 3, 1, 4).Shape(), SurfaceType::Cone, "rev_cone"},
      {BRepPrimAPI_MakeTorus(z, 4, 1.5, quarter).Shape(), SurfaceType::Torus, "rev_torus"},
      // Between latitudes -30 and 45 degrees: no pole.
      {BRepPrimAPI_MakeSphere(z, 3, -quarter / 3, quarter / 2).Shape(), SurfaceType::Sphere,
       "rev_belt"},
  };
  for (const Case& c : cases) {
    const CadModel m = test::round_trip(c.shape, c.name);
    int found = 0;
    for (LO f = 0; f < m.num_faces(); ++f) {
      if (m.faces()[f].type != c.type) continue;
      const auto axis = revolution_axis(m, f);
      ASSERT_TRUE(axis.has_value()) << c.name;
      EXPECT_FALSE(axis->cylinder) << c.name;
      EXPECT_NEAR(std::abs(axis->direction.y), 1.0, 1e-12) << c.name;
      EXPECT_NEAR(off_axis(*axis, {1, 7, 3}), 0.0, 1e-9) << c.name;
      EXPECT_TRUE(iso_line_revolution_axis(m, f).has_value()) << c.name;
      ++found;
    }
    EXPECT_EQ(found, 1) << c.name;
  }
}

TEST(RevolutionFaces, WasherQualifiesAboutItsCentre) {
  // A flat ring between two concentric circles, and a disc with an off-centre hole.
  const gp_Ax2 z(gp_Pnt(1, 2, 3), gp_Dir(0, 0, 1));
  const TopoDS_Shape ring = BRepAlgoAPI_Cut(BRepPrimAPI_MakeCylinder(z, 4, 1).Shape(),
                                            BRepPrimAPI_MakeCylinder(z, 2, 1).Shape())
                                .Shape();
  const CadModel m = test::round_trip(ring, "rev_washer");
  int flat = 0;
  for (LO f = 0; f < m.num_faces(); ++f) {
    if (m.faces()[f].type != SurfaceType::Plane) continue;
    const auto axis = revolution_axis(m, f);
    ASSERT_TRUE(axis.has_value()) << "face " << f;
    EXPECT_FALSE(axis->cylinder);
    EXPECT_NEAR(off_axis(*axis, {1, 2, 0}), 0.0, 1e-9);
    EXPECT_TRUE(iso_line_revolution_axis(m, f).has_value()) << "face " << f;
    ++flat;
  }
  EXPECT_EQ(flat, 2);
  const TopoDS_Shape holed =
      BRepAlgoAPI_Cut(
          BRepPrimAPI_MakeCylinder(z, 4, 1).Shape(),
          BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(2, 2, 3), gp_Dir(0, 0, 1)), 1, 1).Shape())
          .Shape();
  const CadModel h = test::round_trip(holed, "rev_off_centre");
  for (LO f = 0; f < h.num_faces(); ++f) {
    if (h.faces()[f].type == SurfaceType::Plane) {
      EXPECT_FALSE(revolution_axis(h, f).has_value()) << "face " << f;
    }
  }
}

TEST(RevolutionFaces, PoleOrSlantedCutDoesNot) {
  // A sphere octant: its pole is a degenerate curve. A cylinder cut by an oblique plane: an
  // ellipse across the parallels.
  const double quarter = std::numbers::pi / 2;
  const CadModel octant =
      test::round_trip(BRepPrimAPI_MakeSphere(3.0, 0.0, quarter, quarter).Shape(), "rev_octant");
  const TopoDS_Shape cut = BRepAlgoAPI_Cut(
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2, 5).Shape(),
      BRepPrimAPI_MakeBox(gp_Ax2(gp_Pnt(-5, -5, 3), gp_Dir(0.3, 0, 1)), 10, 10, 10).Shape());
  const CadModel slanted = test::round_trip(cut, "rev_slanted");
  for (const CadModel* m : {&octant, &slanted}) {
    int curved = 0;
    for (LO f = 0; f < m->num_faces(); ++f) {
      if (m->faces()[f].type == SurfaceType::Plane) continue;
      EXPECT_TRUE(revolution_axis(*m, f).has_value());
      EXPECT_FALSE(iso_line_revolution_axis(*m, f).has_value()) << "face " << f;
      ++curved;
    }
    EXPECT_EQ(curved, 1);
  }
}

}  // namespace
}  // namespace qsmesh::cad
