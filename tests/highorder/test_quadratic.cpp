// Validity of 9-node quads (highorder::quad9_valid); make_quadratic on CAD models is tested end
// to end (tests/drivers, Qsmesh.SecondOrderNodesLieOnTheCad).
#include <gtest/gtest.h>

#include <array>

#include "qsmesh/highorder/quadratic.hpp"

namespace qsmesh::highorder {
namespace {

// The unit square as a 9-node quad (corners, edge midpoints 0-1, 1-2, 2-3, 3-0, centre).
std::array<Vec3, 9> square() {
  return {Vec3{0, 0, 0}, {1, 0, 0},   {1, 1, 0},   {0, 1, 0},    {0.5, 0, 0},
          {1, 0.5, 0},   {0.5, 1, 0}, {0, 0.5, 0}, {0.5, 0.5, 0}};
}

TEST(Quad9, StraightSquareIsValidAlongItsNormalOnly) {
  EXPECT_TRUE(quad9_valid(square(), {0, 0, 1}));
  EXPECT_FALSE(quad9_valid(square(), {0, 0, -1}));
}

TEST(Quad9, GentlyCurvedIsValid) {
  auto q = square();
  q[4].y = -0.1;  // the bottom edge bulges out
  q[8].z = 0.05;  // the centre lifts off the plane
  EXPECT_TRUE(quad9_valid(q, {0, 0, 1}));
}

TEST(Quad9, EdgeNodePastTheOppositeSideFolds) {
  auto q = square();
  q[4].y = 1.2;  // the bottom edge's midpoint beyond the top edge
  EXPECT_FALSE(quad9_valid(q, {0, 0, 1}));
  auto c = square();
  c[8] = {1.4, 0.5, 0};  // the centre outside the element
  EXPECT_FALSE(quad9_valid(c, {0, 0, 1}));
}

}  // namespace
}  // namespace qsmesh::highorder
