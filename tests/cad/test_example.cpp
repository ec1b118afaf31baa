// The built-in examples: wing-body, far-field, perforated-plate.
#include <gtest/gtest.h>

#include <BRepCheck_Analyzer.hxx>
#include <STEPControl_Reader.hxx>
#include <TopExp_Explorer.hxx>
#include <algorithm>
#include <cstdio>
#include <string>

#include "helpers.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::cad {
namespace {

TEST(CadExample, WingBodyWritesAndReloads) {
  const std::string path = test::tmp_path("wing_body.step");
  write_example("wing-body", path);
  const CadModel m = load_cad(path);
  EXPECT_GE(m.num_faces(), 1);
  EXPECT_LE(m.num_faces(), 40);
  test::expect_closed_loops(m);
  EXPECT_GT(m.diagonal(), 9000);
  EXPECT_LT(m.diagonal(), 20000);
  double area = 0;
  for (LO f = 0; f < m.num_faces(); ++f) {
    area += m.faces()[f].area;
    EXPECT_GT(m.faces()[f].area, 1e-4 * m.diagonal() * m.diagonal()) << "sliver face " << f;
    const auto g = m.face_geometry(f);
    EXPECT_GT(test::signed_area(test::loop_polygon(m, *g, f, 0)), 0) << "face " << f;
  }
  EXPECT_GT(area, 0);
  for (LO f = 0; f < m.num_faces(); ++f)
    std::printf("face %d: %s, %zu loops, area %.4g%s\n", f, to_string(m.faces()[f].type),
                m.faces()[f].loops.size(), m.faces()[f].area,
                m.faces()[f].reversed ? " (reversed)" : "");
  for (LO c = 0; c < m.num_curves(); ++c) {
    // Every curve bounds two faces, or is the seam of one face.
    const auto fs = m.curve2faces()[c];
    if (fs.size() == 1) {
      const auto& seams = m.faces()[fs[0]].seams;
      EXPECT_TRUE(m.curves()[c].degenerate ||
                  std::find(seams.begin(), seams.end(), c) != seams.end())
          << "curve " << c;
    } else {
      EXPECT_EQ(fs.size(), 2u) << "curve " << c;
    }
  }

  STEPControl_Reader reader;
  ASSERT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  ASSERT_GT(reader.TransferRoots(), 0);
  const TopoDS_Shape shape = reader.OneShape();
  int solids = 0;
  for (TopExp_Explorer ex(shape, TopAbs_SOLID); ex.More(); ex.Next()) ++solids;
  EXPECT_EQ(solids, 1);
  EXPECT_TRUE(BRepCheck_Analyzer(shape).IsValid());
}

// The far-field domain: the aircraft's skin as an inner shell of the box, whose six walls are
// planar faces far larger than any skin face (what the background's bound must keep cheap).
TEST(CadExample, FarFieldIsTheWingBodyInsideABox) {
  const std::string wing = test::tmp_path("ff_wing_body.brep"), far = test::tmp_path("ff.brep");
  write_example("wing-body", wing, ExampleFormat::Brep);
  write_example("far-field", far, ExampleFormat::Brep);
  const CadModel body = load_cad(wing), m = load_cad(far);
  test::expect_closed_loops(m);
  EXPECT_EQ(m.num_faces(), body.num_faces() + 6);
  EXPECT_GT(m.diagonal(), 5 * body.diagonal());
  double largest_skin = 0;
  for (LO f = 0; f < body.num_faces(); ++f)
    largest_skin = std::max(largest_skin, body.faces()[f].area);
  int planar_walls = 0;
  for (LO f = 0; f < m.num_faces(); ++f)
    if (m.faces()[f].type == SurfaceType::Plane && m.faces()[f].area > 50 * largest_skin)
      ++planar_walls;
  EXPECT_EQ(planar_walls, 6);
}

// The perforated plate: two faces with one outer loop and 72 holes each, one cylinder per hole.
TEST(CadExample, PerforatedPlateHasTwoFacesWithManyHoles) {
  const std::string path = test::tmp_path("plate.brep");
  write_example("perforated-plate", path, ExampleFormat::Brep);
  const CadModel m = load_cad(path);
  test::expect_closed_loops(m);
  int many_loops = 0, cylinders = 0;
  for (LO f = 0; f < m.num_faces(); ++f) {
    if (m.faces()[f].loops.size() == 73) ++many_loops;
    if (m.faces()[f].type == SurfaceType::Cylinder) ++cylinders;
  }
  EXPECT_EQ(many_loops, 2);
  EXPECT_EQ(cylinders, 72);
  EXPECT_EQ(m.num_faces(), 2 + 4 + 72);
}

TEST(CadExample, UnknownNameAndUnwritablePathAreInputErrors) {
  EXPECT_THROW(write_example("wing-body", "/nonexistent_dir_qsmesh/x/wing.step"), InputError);
  EXPECT_THROW(write_example("rocket", test::tmp_path("rocket.step")), InputError);
  const auto names = example_names();
  EXPECT_EQ(names.front(), "wing-body");
  EXPECT_EQ(names.size(), 3u);
}

}  // namespace
}  // namespace qsmesh::cad
