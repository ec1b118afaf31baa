// Per-face quad statistics (mesh::face_quad_stats): valences against the ideal ones inside, on
// curves and at corners, and SICN.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "qsmesh/mesh/quality.hpp"

namespace {

using namespace qsmesh;
using namespace qsmesh::mesh;

// A 2 x 2 grid of unit squares: corners (dim 0) at the four outer corners, curve vertices (dim 1)
// at the side midpoints, the centre on the face (dim 2).
FaceMesh grid2x2() {
  FaceMesh m;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      m.points.push_back({static_cast<double>(i), static_cast<double>(j), 0});
      m.uv.push_back({static_cast<double>(i), static_cast<double>(j)});
      VertexClass c;
      const bool side_i = i == 0 || i == 2, side_j = j == 0 || j == 2;
      c.dim = static_cast<std::int8_t>(side_i && side_j ? 0 : (side_i || side_j ? 1 : 2));
      c.entity = c.dim == 2 ? 0
                            : (c.dim == 0 ? i + 3 * j
                                          : (j == 0   ? 0
                                             : j == 2 ? 2
                                             : i == 0 ? 3
                                                      : 1));
      c.index = c.dim == 1 ? 1 : kNoIndex;
      m.vclass.push_back(c);
    }
  auto v = [](int i, int j) { return static_cast<LO>(i + 3 * j); };
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i)
      m.quads.push_back({v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)});
  return m;
}

TEST(FaceQuadStats, RegularGridHasNoIrregularVertex) {
  const FaceQuadStats s = face_quad_stats(grid2x2());
  EXPECT_EQ(s.vertices, 9);
  EXPECT_EQ(s.quads, 4);
  EXPECT_EQ(s.triangles, 0);
  EXPECT_EQ(s.irregular_interior, 0);
  EXPECT_EQ(s.irregular_boundary, 0);
  EXPECT_NEAR(s.sicn_min, 1.0, 1e-12);
  EXPECT_NEAR(s.sicn_avg, 1.0, 1e-12);
}

TEST(FaceQuadStats, MissingQuadMakesIrregularVertices) {
  FaceMesh m = grid2x2();
  m.quads.pop_back();  // the quad at (1..2, 1..2): an L-shape
  const FaceQuadStats s = face_quad_stats(m);
  EXPECT_EQ(s.irregular_interior, 1);  // the centre has 3 quads
  // The midpoints of the top and right sides keep one quad (ideal 2); the corner (2, 2) is unused
  // and not counted.
  EXPECT_EQ(s.irregular_boundary, 2);
}

TEST(FaceQuadStats, FoldedQuadHasNegativeSicn) {
  FaceMesh m = grid2x2();
  m.points[4] = {2.5, 2.5, 0};  // the centre pulled outside: its quads fold
  const FaceQuadStats s = face_quad_stats(m);
  EXPECT_LE(s.sicn_min, 0.0);
  EXPECT_LT(s.sicn_avg, 1.0);
}

}  // namespace

namespace {

// Assembled-mesh statistics (mesh::compute_stats) of quads with SICN < 0.1: those at a CAD corner
// sharper than 8 degrees in their face are forced by it, the others are counted by face.
class PoorQuads : public ::testing::Test {
 protected:
  GO add(const Vec3& p, std::int8_t dim, LO entity) {
    m_.points.push_back(p);
    VertexClass c;
    c.dim = dim;
    c.entity = entity;
    m_.vclass.push_back(c);
    return static_cast<GO>(m_.points.size()) - 1;
  }
  // A fan of `n` quads of `step_deg` degrees each at a corner (dim 0) placed at `origin`, in face
  // `face`: the corner's angle in that face is n x step_deg.
  void fan(const Vec3& origin, LO corner, int n, double step_deg, LO face) {
    const GO c = add(origin, 0, corner);
    const double rad = std::numbers::pi / 180.0;
    auto ray = [&](double deg, double r) {
      return origin + Vec3{r * std::cos(deg * rad), r * std::sin(deg * rad), 0};
    };
    GO prev = add(ray(0, 1), 1, 0);
    for (int k = 0; k < n; ++k) {
      const GO mid = add(ray((k + 0.5) * step_deg, 1.05), 2, face);
      const GO next = add(ray((k + 1) * step_deg, 1), k + 1 == n ? 1 : 2, face);
      m_.quads.push_back({c, prev, mid, next});
      m_.quad_face.push_back(face);
      prev = next;
    }
  }
  SurfaceMesh m_;
};

TEST_F(PoorQuads, SharpCornersForceThemOthersCountByFace) {
  m_.num_cad_faces = 3;
  fan({0, 0, 0}, 0, 2, 3.0, 0);   // a 6-degree corner: two quads of SICN < sin(3 deg)
  fan({10, 0, 0}, 1, 2, 5.0, 2);  // a 10-degree corner: SICN < sin(5 deg) = 0.087 each, not forced
  // Face 1: a 1 x 0.04 rectangle (SICN 2 x 0.04 / (1 + 0.04^2) = 0.08) at a 90-degree corner, and
  // a unit square (SICN 1).
  const GO k = add({20, 0, 0}, 0, 2);
  const GO a = add({21, 0, 0}, 1, 1), b = add({21, 0.04, 0}, 2, 1), c = add({20, 0.04, 0}, 1, 2);
  m_.quads.push_back({k, a, b, c});
  m_.quad_face.push_back(1);
  const GO d = add({21, 1.04, 0}, 2, 1), e = add({20, 1.04, 0}, 1, 2);
  m_.quads.push_back({c, b, d, e});
  m_.quad_face.push_back(1);
  const MeshStats s = compute_stats(m_);
  ASSERT_EQ(s.quads, 6);
  EXPECT_LT(s.sicn_min, 0.06);
  EXPECT_EQ(s.quads_sicn_below_0_1, 5);
  EXPECT_EQ(s.quads_sicn_below_0_1_forced_by_corner, 2);
  EXPECT_EQ(s.face_quads_sicn_below_0_1, (std::vector<std::int64_t>{0, 1, 2}));
}

TEST_F(PoorQuads, CornerAngleIsThatOfTheQuadsFace) {
  // A 3-degree quad at a corner that a 60-degree quad of another face also touches: the corner
  // is sharp in the first face only (angles are summed per face, not over the vertex).
  m_.num_cad_faces = 2;
  fan({0, 0, 0}, 0, 1, 3.0, 0);
  const GO c = 0;
  const double rad = std::numbers::pi / 180.0;
  const GO p = add({std::cos(-60 * rad), std::sin(-60 * rad), 0}, 1, 3);
  const GO q = add({1.0, -0.4, 0}, 2, 1);
  m_.quads.push_back({c, p, q, 1});  // from 0 to -60 degrees, through the fan's first ray
  m_.quad_face.push_back(1);
  const MeshStats s = compute_stats(m_);
  EXPECT_EQ(s.quads_sicn_below_0_1_forced_by_corner, 1);
  EXPECT_EQ(s.face_quads_sicn_below_0_1, (std::vector<std::int64_t>{0, 0}));
}

}  // namespace
