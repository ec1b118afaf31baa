// 3D clean-up of small angles (mesh::improve_small_angles) on hand-made triangulations: a thin
// pole fan that only a flip through the pole fixes, and a badly placed interior vertex that only
// a move fixes.
#include <gtest/gtest.h>

#include <cmath>

#include "analytic_surfaces.hpp"
#include "qsmesh/mesh/improve.hpp"
#include "qsmesh/mesh/predicates.hpp"

namespace {

using namespace qsmesh;
using namespace qsmesh::mesh;

using test::Plane;  // Newton projection: the moves project their targets
using test::Polar;

double degrees(double rad) { return rad * 180.0 / 3.14159265358979323846; }

double smallest_angle(const FaceMesh& m) {
  double worst = 180;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const Vec3 a = m.points[t[k]], b = m.points[t[(k + 1) % 3]], c = m.points[t[(k + 2) % 3]];
      worst = std::min(worst, degrees(std::acos(dot(b - a, c - a) / (norm(b - a) * norm(c - a)))));
    }
  return worst;
}

void add_vertex(FaceMesh& m, const cad::FaceGeometry& s, Vec2 uv, int dim, LO entity) {
  m.uv.push_back(uv);
  m.points.push_back(s.eval(uv).p);
  VertexClass vc;
  vc.dim = static_cast<std::int8_t>(dim);
  vc.entity = entity;
  vc.param = {uv.u, uv.v};
  m.vclass.push_back(vc);
}

TEST(ImproveSmallAngles, FlipsThinPoleFanIntoOneCornerTriangle) {
  // A 17-degree wedge at a pole P: the kernel's fan splits it in two 8.6-degree triangles through
  // the interior vertex c; the corner triangle (P, a, b) is what a good mesh has there.
  const Polar s;
  FaceMesh m;
  add_vertex(m, s, {0.15, 0.0}, 0, 0);  // 0: P, the pole
  add_vertex(m, s, {0.0, 0.5}, 1, 0);   // 1: a
  add_vertex(m, s, {0.3, 0.5}, 1, 2);   // 2: b
  add_vertex(m, s, {0.0, 1.0}, 0, 1);   // 3: a2
  add_vertex(m, s, {0.3, 1.0}, 0, 2);   // 4: b2
  add_vertex(m, s, {0.15, 0.7}, 2, 0);  // 5: c
  m.triangles = {{0, 2, 5}, {0, 5, 1}, {1, 5, 3}, {5, 4, 3}, {2, 4, 5}};
  for (const auto& t : m.triangles) ASSERT_GT(orient2d(m.uv[t[0]], m.uv[t[1]], m.uv[t[2]]), 0);
  ASSERT_LT(smallest_angle(m), 9.0);

  ImproveStats stats;
  const FaceMesh out = improve_small_angles(m, s, /*face_reversed=*/false, {}, &stats);
  EXPECT_GE(stats.flips, 1);
  EXPECT_NEAR(stats.min_angle_before, smallest_angle(m), 1e-9);
  EXPECT_GT(smallest_angle(out), 17.0);  // the wedge angle itself, 0.3 rad
  EXPECT_NEAR(stats.min_angle_after, smallest_angle(out), 1e-9);
  ASSERT_EQ(out.triangles.size(), m.triangles.size());
  // Every triangle without the pole keeps its uv orientation; the one at the pole is along the
  // face normal in 3D.
  for (const auto& t : out.triangles) {
    if (t[0] == 0 || t[1] == 0 || t[2] == 0) {
      const Vec3 n =
          cross(out.points[t[1]] - out.points[t[0]], out.points[t[2]] - out.points[t[0]]);
      EXPECT_GT(dot(n, s.normal({0.15, 0.5})), 0);
    } else {
      EXPECT_GT(orient2d(out.uv[t[0]], out.uv[t[1]], out.uv[t[2]]), 0);
    }
  }
}

TEST(ImproveSmallAngles, MovesBadlyPlacedInteriorVertex) {
  // A regular hexagon whose centre vertex sits next to one corner: no flip is valid (the centre is
  // inside the corner triangle), only moving it helps.
  const Plane s;
  FaceMesh m;
  for (int k = 0; k < 6; ++k) {
    const double a = k * 3.14159265358979323846 / 3;
    add_vertex(m, s, {std::cos(a), std::sin(a)}, 1, 0);
  }
  add_vertex(m, s, {0.9, 0.0}, 2, 0);
  for (LO k = 0; k < 6; ++k) m.triangles.push_back({6, k, static_cast<LO>((k + 1) % 6)});
  ASSERT_LT(smallest_angle(m), 6.0);

  ImproveStats stats;
  const FaceMesh out = improve_small_angles(m, s, false, {}, &stats);
  EXPECT_GE(stats.moves, 1);
  EXPECT_GT(smallest_angle(out), 50.0);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(out.points[k], m.points[k]);  // boundary untouched
  EXPECT_NEAR(out.vclass[6].param[0], out.uv[6].u, 0);
  for (const auto& t : out.triangles)
    EXPECT_GT(orient2d(out.uv[t[0]], out.uv[t[1]], out.uv[t[2]]), 0);

  // Reversed face: the same mesh with clockwise triangles is improved the same way.
  FaceMesh rev = m;
  for (auto& t : rev.triangles) std::swap(t[1], t[2]);
  const FaceMesh out_rev = improve_small_angles(rev, s, true, {}, nullptr);
  EXPECT_GT(smallest_angle(out_rev), 50.0);
}

TEST(ImproveSmallAngles, LeavesGoodMeshAlone) {
  const Plane s;
  FaceMesh m;
  add_vertex(m, s, {0, 0}, 0, 0);
  add_vertex(m, s, {1, 0}, 0, 1);
  add_vertex(m, s, {0.5, 0.8660254037844386}, 0, 2);
  m.triangles = {{0, 1, 2}};
  ImproveStats stats;
  const FaceMesh out = improve_small_angles(m, s, false, {}, &stats);
  EXPECT_EQ(stats.flips + stats.moves, 0);
  EXPECT_EQ(out.triangles, m.triangles);
  EXPECT_EQ(out.points, m.points);
}

}  // namespace
