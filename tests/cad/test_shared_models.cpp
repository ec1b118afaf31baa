// Topology counts of the shared CAD models (skipped when ../shared/cad is absent).
#include <gtest/gtest.h>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <string>

#include "helpers.hpp"
#include "qsmesh/cad/model.hpp"

namespace qsmesh::cad {
namespace {

struct Expected {
  const char* file;
  LO corners, curves, faces;
};

void PrintTo(const Expected& e, std::ostream* os) { *os << e.file; }

class SharedModel : public ::testing::TestWithParam<Expected> {};

TEST_P(SharedModel, CountsAndConsistency) {
  const Expected ex = GetParam();
  const std::string path = std::string(QSMESH_SHARED_CAD_DIR) + "/" + ex.file;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not found";
  const CadModel m = load_cad(path);
  EXPECT_EQ(m.num_corners(), ex.corners);
  EXPECT_EQ(m.num_curves(), ex.curves);
  EXPECT_EQ(m.num_faces(), ex.faces);
  EXPECT_EQ(m.curve2faces().size(), m.num_curves());
  EXPECT_EQ(m.corner2curves().size(), m.num_corners());
  EXPECT_EQ(m.face2faces().size(), m.num_faces());
  EXPECT_GT(m.diagonal(), 0);
  LO open = 0;
  for (LO f = 0; f < m.num_faces(); ++f) {
    const Face& face = m.faces()[f];
    ASSERT_FALSE(face.loops.empty()) << "face " << f;
    EXPECT_TRUE(face.loops[0].outer);
    if (!face.loops_closed) ++open;
    for (const Loop& l : face.loops)
      for (const CurveUse& u : l.uses) {
        ASSERT_GE(u.curve, 0);
        ASSERT_LT(u.curve, m.num_curves());
        bool found = false;
        for (LO g : m.curve2faces()[u.curve]) found = found || g == f;
        EXPECT_TRUE(found) << "face " << f << " curve " << u.curve;
      }
    for (LO g : m.face2faces()[f]) EXPECT_NE(g, f);
  }
  for (LO c = 0; c < m.num_curves(); ++c) {
    const auto fs = m.curve2faces()[c];
    for (std::size_t k = 1; k < fs.size(); ++k) EXPECT_LT(fs[k - 1], fs[k]);
  }
  // Outer loops run counterclockwise in (u, v), holes clockwise (faces whose loops close in the
  // parameter plane; a loop around a periodic direction without a seam does not).
  LO checked = 0, wrong = 0;
  for (LO f = 0; f < m.num_faces(); ++f) {
    const auto g = m.face_geometry(f);
    const Face& face = m.faces()[f];
    for (LO l = 0; l < static_cast<LO>(face.loops.size()); ++l) {
      const auto poly = test::loop_polygon(m, *g, f, l, 16);
      if (norm(poly.front() - poly.back()) > 0.25 * norm(face.uv_box.hi - face.uv_box.lo)) continue;
      ++checked;
      const double a = test::signed_area(poly);
      if ((l == 0) != (a > 0)) {
        ++wrong;
        std::printf("  face %d loop %d (%s%s): signed area %g\n", f, l, to_string(face.type),
                    face.reversed ? ", reversed" : "", a);
      }
    }
  }
  std::printf("%s: %d loops checked for orientation, %d wrong\n", ex.file, checked, wrong);
  EXPECT_EQ(wrong, 0);
  // Projection from a nearby guess finds boundary points of every face and every curve again.
  for (LO f = 0; f < m.num_faces(); ++f) {
    const Face& face = m.faces()[f];
    if (face.loops.empty() || face.loops[0].uses.empty()) continue;
    const auto g = m.face_geometry(f, true);
    const Curve& c = m.curves()[face.loops[0].uses[0].curve];
    const Vec2 uv = g->boundary_uv(0, 0, 0.5 * (c.t0 + c.t1));
    const Vec3 p = g->eval(uv).p;
    const Vec2 guess = uv + (face.uv_box.hi - face.uv_box.lo) * 1e-3;
    Vec3 foot;
    (void)g->project(p, guess, &foot);
    // Pcurves may leave the surface's parameter domain by the edge tolerance; project stays in it.
    EXPECT_LT(distance(foot, p), 1e-6 * m.diagonal()) << "face " << f;
    EXPECT_TRUE(g->contains(uv)) << "face " << f;
  }
  for (LO c = 0; c < m.num_curves(); ++c) {
    const Curve& cu = m.curves()[c];
    const auto g = m.curve_geometry(c);
    const double t = cu.t0 + 0.37 * (cu.t1 - cu.t0);
    Vec3 foot;
    (void)g->project(g->point(t), t + 0.01 * (cu.t1 - cu.t0), &foot);
    EXPECT_LT(distance(foot, g->point(t)), 1e-7 * m.diagonal()) << "curve " << c;
  }
  RecordProperty("open_faces", open);
  std::printf("%s: %d corners, %d curves, %d faces, %d faces with open loops\n", ex.file,
              m.num_corners(), m.num_curves(), m.num_faces(), open);
  EXPECT_EQ(open, 0);
}

INSTANTIATE_TEST_SUITE_P(Shared, SharedModel,
                         ::testing::Values(Expected{"Block.stp", 1044, 1584, 533},
                                           Expected{"A319.brep", 287, 375, 83},
                                           Expected{"wing_fuselage.step", 20, 38, 16},
                                           Expected{"mambo_s34.step", 77, 123, 46},
                                           Expected{"cube_filet.stp", 40, 74, 25},
                                           Expected{"t20_data.step", 28, 48, 21}),
                         [](const auto& param_info) {
                           std::string n = param_info.param.file;
                           for (char& ch : n)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return n;
                         });

}  // namespace
}  // namespace qsmesh::cad
