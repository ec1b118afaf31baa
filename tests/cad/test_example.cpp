// The built-in wing-body example.
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
  write_wing_body_example(path);
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

TEST(CadExample, UnwritablePathIsInputError) {
  EXPECT_THROW(write_wing_body_example("/nonexistent_dir_qsmesh/x/wing.step"), InputError);
}

}  // namespace
}  // namespace qsmesh::cad
