// Per-face quad statistics (mesh::face_quad_stats): valences against the ideal ones inside, on
// curves and at corners, and SICN.
#include <gtest/gtest.h>

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
