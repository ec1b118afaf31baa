// Layouts of small quad meshes in the parameter plane (smooth::laplace_uv, chord_laplace_uv).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "qsmesh/smooth/quad_tools.hpp"

namespace qsmesh::smooth {
namespace {

// An nx x ny grid on [0, 1] x [0, 1]: boundary vertices first (the fixed ones), interior after.
// Column i sits at x(i) on the bottom and top sides, row j at y(j) on the left and right sides.
struct Grid {
  std::vector<std::array<LO, 4>> quads;
  std::vector<Vec2> uv;
  std::vector<LO> id;  // (i, j) -> vertex
  LO nx = 0, ny = 0, num_fixed = 0;
  LO at(LO i, LO j) const { return id[static_cast<std::size_t>(j * (nx + 1) + i)]; }
};

template <class X, class Y>
Grid make_grid(LO nx, LO ny, X x, Y y) {
  Grid g;
  g.nx = nx;
  g.ny = ny;
  g.id.assign(static_cast<std::size_t>((nx + 1) * (ny + 1)), kNoIndex);
  LO next = 0;
  const auto boundary = [&](LO i, LO j) { return i == 0 || j == 0 || i == nx || j == ny; };
  for (int pass = 0; pass < 2; ++pass)
    for (LO j = 0; j <= ny; ++j)
      for (LO i = 0; i <= nx; ++i)
        if (boundary(i, j) == (pass == 0))
          g.id[static_cast<std::size_t>(j * (nx + 1) + i)] = next++;
  g.uv.resize(static_cast<std::size_t>(next));
  for (LO j = 0; j <= ny; ++j)
    for (LO i = 0; i <= nx; ++i) {
      const LO v = g.at(i, j);
      // Interior vertices start far away: the layout must not depend on them.
      g.uv[v] = boundary(i, j) ? Vec2{x(i), y(j)} : Vec2{7.0, -3.0};
      if (boundary(i, j)) ++g.num_fixed;
    }
  for (LO j = 0; j < ny; ++j)
    for (LO i = 0; i < nx; ++i)
      g.quads.push_back({g.at(i, j), g.at(i + 1, j), g.at(i + 1, j + 1), g.at(i, j + 1)});
  return g;
}

// Largest distance of an interior vertex from the straight grid (x(i), y(j)).
template <class X, class Y>
double off_grid(const Grid& g, X x, Y y) {
  double worst = 0;
  for (LO j = 1; j < g.ny; ++j)
    for (LO i = 1; i < g.nx; ++i) {
      const Vec2 p = g.uv[g.at(i, j)];
      worst = std::max(worst, std::hypot(p.u - x(i), p.v - y(j)));
    }
  return worst;
}

TEST(Layout, ChordLaplaceKeepsTheBoundaryGrading) {
  // Opposite sides graded alike (fine at both ends, coarse in the middle, as the curve meshes of
  // a long face between two small features): the grid lines must stay straight.
  const LO nx = 24, ny = 6;
  const auto x = [&](LO i) {
    const double t = static_cast<double>(i) / nx;
    return 0.5 - 0.5 * std::cos(std::acos(-1.0) * t);
  };
  const auto y = [&](LO j) { return 0.125 * j / ny; };
  Grid chord = make_grid(nx, ny, x, y);
  ASSERT_TRUE(chord_laplace_uv(chord.quads, chord.num_fixed, chord.uv));
  EXPECT_LT(off_grid(chord, x, y), 1e-9);

  // The uniform Laplacian evens the spacing out inside and skews the quads near the fine ends.
  Grid uniform = make_grid(nx, ny, x, y);
  ASSERT_TRUE(laplace_uv(uniform.quads, uniform.num_fixed, uniform.uv));
  EXPECT_GT(off_grid(uniform, x, y), 1e-3);
}

TEST(Layout, ChordLaplaceOnAnEvenGridIsTheBilinearGrid) {
  const LO nx = 5, ny = 3;
  const auto x = [&](LO i) { return 2.0 * i / nx; };
  const auto y = [&](LO j) { return 1.0 * j / ny; };
  Grid g = make_grid(nx, ny, x, y);
  ASSERT_TRUE(chord_laplace_uv(g.quads, g.num_fixed, g.uv));
  EXPECT_LT(off_grid(g, x, y), 1e-12);
}

TEST(Layout, ChordLaplaceInterpolatesAlongAStrip) {
  // Bottom side even, top side graded: each column ends at the two spacings of its strip and the
  // interior spacing goes from one to the other, so every interior x stays between the two.
  const LO nx = 10, ny = 8;
  const auto xb = [&](LO i) { return static_cast<double>(i) / nx; };
  const auto xt = [&](LO i) { return std::pow(static_cast<double>(i) / nx, 2.0); };
  Grid g = make_grid(nx, ny, xb, [&](LO j) { return static_cast<double>(j) / ny; });
  for (LO i = 0; i <= nx; ++i) g.uv[g.at(i, ny)].u = xt(i);
  ASSERT_TRUE(chord_laplace_uv(g.quads, g.num_fixed, g.uv));
  for (LO j = 1; j < ny; ++j)
    for (LO i = 1; i < nx; ++i) {
      const double u = g.uv[g.at(i, j)].u;
      EXPECT_LE(u, xb(i) + 1e-9);
      EXPECT_GE(u, xt(i) - 1e-9);
      EXPECT_GT(u, g.uv[g.at(i - 1, j)].u);  // no fold
    }
}

}  // namespace
}  // namespace qsmesh::smooth
