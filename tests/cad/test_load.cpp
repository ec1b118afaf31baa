// Loading files and building the topology of simple solids.
#include <gtest/gtest.h>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <cmath>
#include <fstream>
#include <gp_Ax2.hxx>
#include <numbers>
#include <string>

#include "helpers.hpp"
#include "load_shape.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::cad {
namespace {

using test::tmp_path;

void check_box(const CadModel& m) {
  ASSERT_EQ(m.num_corners(), 8);
  ASSERT_EQ(m.num_curves(), 12);
  ASSERT_EQ(m.num_faces(), 6);
  double area = 0;
  for (LO f = 0; f < 6; ++f) {
    const Face& face = m.faces()[f];
    ASSERT_EQ(face.loops.size(), 1u);
    EXPECT_TRUE(face.loops[0].outer);
    EXPECT_EQ(face.loops[0].uses.size(), 4u);
    EXPECT_EQ(face.type, SurfaceType::Plane);
    EXPECT_TRUE(face.seams.empty());
    EXPECT_EQ(m.face2faces()[f].size(), 4u);
    area += face.area;
  }
  EXPECT_NEAR(area, 2 * (10 * 20 + 20 * 30 + 10 * 30), 1e-6);
  test::expect_closed_loops(m);
  for (LO c = 0; c < 12; ++c) {
    EXPECT_EQ(m.curve2faces()[c].size(), 2u);
    EXPECT_EQ(m.curves()[c].type, CurveType::Line);
    EXPECT_FALSE(m.curves()[c].degenerate);
    EXPECT_LT(m.curves()[c].t0, m.curves()[c].t1);
    const double len = m.curves()[c].length;
    EXPECT_TRUE(std::abs(len - 10) < 1e-9 || std::abs(len - 20) < 1e-9 || std::abs(len - 30) < 1e-9)
        << len;
  }
  for (LO v = 0; v < 8; ++v) EXPECT_EQ(m.corner2curves()[v].size(), 3u);
  EXPECT_NEAR(m.diagonal(), std::sqrt(100.0 + 400 + 900), 1e-3);
}

TEST(CadLoad, BoxBrepStepIges) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(10, 20, 30).Shape();
  test::write_brep(box, tmp_path("box.brep"));
  test::write_step(box, tmp_path("box.step"));
  test::write_iges(box, tmp_path("box.igs"));
  for (const char* name : {"box.brep", "box.step", "box.igs"}) {
    SCOPED_TRACE(name);
    const CadModel m = load_cad(tmp_path(name));
    EXPECT_EQ(m.source(), tmp_path(name));
    check_box(m);
  }
}

TEST(CadLoad, ExtensionIsCaseInsensitive) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(10, 20, 30).Shape();
  test::write_step(box, tmp_path("BOX_UPPER.STP"));
  check_box(load_cad(tmp_path("BOX_UPPER.STP")));
}

TEST(CadLoad, SewingKeepsAClosedBox) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(10, 20, 30).Shape();
  test::write_brep(box, tmp_path("box_sew.brep"));
  LoadOptions o;
  o.sew = true;
  check_box(load_cad(tmp_path("box_sew.brep"), o));
}

// Six faces copied apart (no shared edges) are sewn back into a closed box.
TEST(CadLoad, SewingJoinsSeparateFaces) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(10, 20, 30).Shape();
  TopoDS_Compound loose;
  BRep_Builder b;
  b.MakeCompound(loose);
  for (TopExp_Explorer ex(box, TopAbs_FACE); ex.More(); ex.Next())
    b.Add(loose, BRepBuilderAPI_Copy(ex.Current()).Shape());
  test::write_brep(loose, tmp_path("loose_faces.brep"));
  const CadModel apart = load_cad(tmp_path("loose_faces.brep"));
  EXPECT_EQ(apart.num_faces(), 6);
  EXPECT_EQ(apart.num_curves(), 24);
  EXPECT_EQ(apart.num_corners(), 24);
  LoadOptions o;
  o.sew = true;
  check_box(load_cad(tmp_path("loose_faces.brep"), o));
}

void expect_input_error(const std::string& path, const std::string& word) {
  try {
    (void)load_cad(path);
    ADD_FAILURE() << "no exception for " << path;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(word), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// Sloppy CAD (A319.brep has 18 such curves): the line of one edge of a 10 x 10 square runs 1.5
// past its corner, inside the corner's tolerance. The loader trims that end of the range to the
// point nearest the corner, so curve meshes stay between their corners; the other ends and
// edges keep their ranges.
TEST(CadLoad, CurveRunningPastItsCornerIsTrimmed) {
  BRepBuilderAPI_MakePolygon poly(gp_Pnt(0, 0, 0), gp_Pnt(10, 0, 0), gp_Pnt(10, 10, 0),
                                  gp_Pnt(0, 10, 0), true);
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(poly.Wire(), true).Face();
  BRep_Builder b;
  bool extended = false;
  for (TopExp_Explorer ex(face, TopAbs_EDGE); ex.More() && !extended; ex.Next()) {
    const TopoDS_Edge e = TopoDS::Edge(ex.Current());
    TopoDS_Vertex v0, v1;
    TopExp::Vertices(e, v0, v1);
    if (BRep_Tool::Pnt(v0).Distance(gp_Pnt(0, 0, 0)) > 1e-9 ||
        BRep_Tool::Pnt(v1).Distance(gp_Pnt(10, 0, 0)) > 1e-9)
      continue;
    double t0 = 0, t1 = 0;
    BRep_Tool::Range(e, t0, t1);
    b.Range(e, t0, t1 + 1.5);  // the line goes on to x = 11.5
    b.UpdateVertex(v1, 2.0);
    extended = true;
  }
  ASSERT_TRUE(extended);
  const CadModel m = qsmesh::test::load_shape(face, "overshoot.brep");
  ASSERT_EQ(m.num_curves(), 4);
  int trimmed = 0;
  for (LO c = 0; c < m.num_curves(); ++c) {
    const Curve& curve = m.curves()[c];
    EXPECT_NEAR(curve.length, 10.0, 1e-6) << "curve " << c;
    const auto g = m.curve_geometry(c);
    for (int end = 0; end < 2; ++end) {
      const Vec3 p = g->point(end == 0 ? curve.t0 : curve.t1);
      EXPECT_LT(distance(p, m.corners()[curve.corners[end]].point), 1e-6) << "curve " << c;
      trimmed += curve.trimmed[end] ? 1 : 0;
    }
    // No point of the curve's range lies beyond x = 10.
    for (int k = 0; k <= 20; ++k)
      EXPECT_LE(g->point(curve.t0 + (curve.t1 - curve.t0) * k / 20).x, 10 + 1e-6);
  }
  EXPECT_EQ(trimmed, 1);
}

TEST(CadLoad, BadInput) {
  expect_input_error(tmp_path("does_not_exist.step"), "does not exist");
  { std::ofstream(tmp_path("empty.step")); }
  expect_input_error(tmp_path("empty.step"), "empty");
  for (const char* name : {"garbage.step", "garbage.igs", "garbage.brep"}) {
    std::ofstream(tmp_path(name)) << "this is not a CAD file\n1 2 3\n";
    expect_input_error(tmp_path(name), "garbage");
  }
  std::ofstream(tmp_path("model.obj")) << "v 0 0 0\n";
  expect_input_error(tmp_path("model.obj"), "unsupported");
}

TEST(CadLoad, CylinderSeam) {
  const TopoDS_Shape cyl = BRepPrimAPI_MakeCylinder(2, 5).Shape();
  const CadModel m = test::round_trip(cyl, "cylinder");
  ASSERT_EQ(m.num_faces(), 3);
  EXPECT_EQ(m.num_curves(), 3);
  EXPECT_EQ(m.num_corners(), 2);
  test::expect_closed_loops(m);
  LO side = kNoIndex;
  for (LO f = 0; f < 3; ++f)
    if (m.faces()[f].type == SurfaceType::Cylinder) side = f;
  ASSERT_NE(side, kNoIndex);
  const Face& face = m.faces()[side];
  EXPECT_NEAR(face.area, 2 * std::numbers::pi * 2 * 5, 1e-6);
  EXPECT_TRUE(face.u_periodic);
  EXPECT_NEAR(face.u_period, 2 * std::numbers::pi, 1e-12);
  ASSERT_EQ(face.seams.size(), 1u);
  ASSERT_EQ(face.loops.size(), 1u);
  ASSERT_EQ(face.loops[0].uses.size(), 4u);
  const LO seam = face.seams[0];
  EXPECT_EQ(m.curve2faces()[seam].size(), 1u);
  std::vector<LO> uses;
  for (LO k = 0; k < 4; ++k)
    if (face.loops[0].uses[k].curve == seam) uses.push_back(k);
  ASSERT_EQ(uses.size(), 2u);
  EXPECT_NE(face.loops[0].uses[uses[0]].reversed, face.loops[0].uses[uses[1]].reversed);
  const auto g = m.face_geometry(side);
  const Curve& c = m.curves()[seam];
  for (double s : {0.0, 0.3, 1.0}) {
    const double t = c.t0 + s * (c.t1 - c.t0);
    const Vec2 a = g->boundary_uv(0, uses[0], t), b = g->boundary_uv(0, uses[1], t);
    EXPECT_NEAR(std::abs(a.u - b.u), 2 * std::numbers::pi, 1e-9);
    EXPECT_NEAR(a.v, b.v, 1e-9);
  }
  EXPECT_GT(test::signed_area(test::loop_polygon(m, *g, side, 0)), 0);
  // Side normal points away from the axis (outward).
  const Vec2 uv{1.0, 2.5};
  const Vec3 p = g->eval(uv).p;
  EXPECT_GT(dot(g->normal(uv), Vec3{p.x, p.y, 0}), 0.99 * 2);
}

TEST(CadLoad, SpherePoles) {
  const TopoDS_Shape sph = BRepPrimAPI_MakeSphere(3).Shape();
  const CadModel m = test::round_trip(sph, "sphere");
  ASSERT_EQ(m.num_faces(), 1);
  EXPECT_EQ(m.faces()[0].type, SurfaceType::Sphere);
  test::expect_closed_loops(m);
  int degenerate = 0;
  for (const Curve& c : m.curves())
    if (c.degenerate) {
      ++degenerate;
      EXPECT_EQ(c.length, 0);
      EXPECT_EQ(c.type, CurveType::Degenerate);
      EXPECT_EQ(c.corners[0], c.corners[1]);
    }
  EXPECT_EQ(degenerate, 2);
  EXPECT_NEAR(m.faces()[0].area, 4 * std::numbers::pi * 9, 1e-6);
  const auto g = m.face_geometry(0);
  const Box2& b = m.faces()[0].uv_box;
  EXPECT_NEAR(b.hi.v - b.lo.v, std::numbers::pi, 1e-9);
  for (double v : {b.lo.v, b.hi.v}) {
    const Vec3 n = g->normal({0.5, v});
    EXPECT_EQ(norm(n), 0);
  }
  const Vec2 uv{1.0, 0.3};
  EXPECT_NEAR(dot(g->normal(uv), normalized(g->eval(uv).p)), 1, 1e-12);
  for (LO c = 0; c < m.num_curves(); ++c) {
    if (!m.curves()[c].degenerate) continue;
    const auto cg = m.curve_geometry(c);
    const Vec3 pole = m.corners()[m.curves()[c].corners[0]].point;
    EXPECT_EQ(cg->point(1.0), pole);
    EXPECT_EQ(norm(cg->derivative(1.0)), 0);
    EXPECT_NEAR(std::abs(pole.z), 3, 1e-12);
  }
}

// A 10 x 10 x 1 plate with a hole of radius 2: top and bottom faces have an outer loop and a hole;
// the bottom face is REVERSED in the solid.
TEST(CadLoad, PlateWithHoleLoopsAndOrientation) {
  const TopoDS_Shape plate = BRepPrimAPI_MakeBox(10, 10, 1).Shape();
  const TopoDS_Shape drill =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(5, 5, -1), gp::DZ()), 2, 3).Shape();
  BRepAlgoAPI_Cut cut(plate, drill);
  ASSERT_TRUE(cut.IsDone());
  const CadModel m = test::round_trip(cut.Shape(), "plate_hole");
  test::expect_closed_loops(m);
  int holed = 0, reversed_holed = 0;
  for (LO f = 0; f < m.num_faces(); ++f) {
    const Face& face = m.faces()[f];
    const auto g = m.face_geometry(f, true);
    // Normals point out of the solid (centre at (5, 5, 0.5)).
    const Vec2 mid = (face.uv_box.lo + face.uv_box.hi) * 0.5;
    if (face.type == SurfaceType::Plane) {
      const Vec3 p = g->eval(mid).p;
      const Vec3 n = g->normal(mid);
      const Vec3 out = p - Vec3{5, 5, 0.5};
      if (std::abs(p.z - 0.5) > 0.4) {
        EXPECT_GT(dot(n, out), 0) << "face " << f;
      }
    }
    EXPECT_GT(test::signed_area(test::loop_polygon(m, *g, f, 0)), 0) << "face " << f;
    if (face.loops.size() != 2) continue;
    ++holed;
    if (face.reversed) ++reversed_holed;
    EXPECT_FALSE(face.loops[1].outer);
    const double outer = test::signed_area(test::loop_polygon(m, *g, f, 0));
    const double hole = test::signed_area(test::loop_polygon(m, *g, f, 1, 256));
    EXPECT_NEAR(outer, 100, 1e-9);
    EXPECT_NEAR(hole, -std::numbers::pi * 4, 0.01);
    EXPECT_NEAR(face.area, 100 - std::numbers::pi * 4, 1e-6);
    // contains: the plate yes, the hole no, the boundary yes.
    const Vec3 centre{5, 5, face.box.lo.z};
    const Vec2 c_uv = g->project(centre, mid, nullptr);
    EXPECT_FALSE(g->contains(c_uv));
    EXPECT_TRUE(g->contains(g->project(Vec3{1, 1, face.box.lo.z}, mid, nullptr)));
    EXPECT_TRUE(g->contains(g->boundary_uv(1, 0, m.curves()[face.loops[1].uses[0].curve].t0)));
    EXPECT_FALSE(g->contains(g->project(Vec3{5, 5, face.box.lo.z}, mid, nullptr) + Vec2{100, 100}));
  }
  EXPECT_EQ(holed, 2);
  EXPECT_EQ(reversed_holed, 1);
}

}  // namespace
}  // namespace qsmesh::cad
