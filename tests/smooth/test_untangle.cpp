#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepTools.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <gp_Ax3.hxx>
#include <gp_Cylinder.hxx>
#include <gp_Pln.hxx>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>

#include "face_case.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/smooth/untangle.hpp"

namespace qsmesh::smooth {
namespace {

using Case = test::FaceCase;
using test::load_face;

// n x n grid of quads over the uv box, boundary classified on one curve (dim 1) or a corner.
mesh::FaceMesh grid(const cad::FaceGeometry& g, Box2 box, int n) {
  mesh::FaceMesh m;
  m.face = 0;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const Vec2 uv{box.lo.u + (box.hi.u - box.lo.u) * i / n,
                    box.lo.v + (box.hi.v - box.lo.v) * j / n};
      mesh::VertexClass c;
      const bool bi = i == 0 || i == n, bj = j == 0 || j == n;
      if (bi && bj) {
        c.dim = 0;
        c.entity = (i == 0 ? 0 : 1) + (j == 0 ? 0 : 2);
      } else if (bi || bj) {
        c.dim = 1;
        c.entity = 0;
        c.index = j * (n + 1) + i;
      } else {
        c.param = {uv.u, uv.v};
      }
      m.uv.push_back(uv);
      m.points.push_back(g.eval(uv).p);
      m.vclass.push_back(c);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const auto id = [&](int a, int b) { return static_cast<LO>(b * (n + 1) + a); };
      m.quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

// Moves interior vertex (i, j) of the grid by `duv` cells: its quads fold.
void fold(mesh::FaceMesh& m, const cad::FaceGeometry& g, Box2 box, int n, int i, int j, Vec2 duv) {
  const LO v = static_cast<LO>(j * (n + 1) + i);
  m.uv[v] += Vec2{duv.u * (box.hi.u - box.lo.u) / n, duv.v * (box.hi.v - box.lo.v) / n};
  m.points[v] = g.eval(m.uv[v]).p;
  m.vclass[v].param = {m.uv[v].u, m.uv[v].v};
}

void expect_locked_and_on_surface(const mesh::FaceMesh& in, const mesh::FaceMesh& out,
                                  const cad::FaceGeometry& g, double size) {
  test::expect_locked_and_on_surface(in, out, g, size, /*check_params=*/true);
}

TEST(Untangle, FoldedPatchOnAPlaneBecomesValid) {
  const Case c = load_face(
      BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 0.0, 8.0, 0.0, 8.0).Face(),
      "untangle_plate.brep");
  const Box2 box = c.model.faces()[0].uv_box;
  auto in = grid(*c.geometry, box, 8);
  // Two neighbouring vertices pushed across each other and one past its neighbour's cell.
  fold(in, *c.geometry, box, 8, 3, 3, {1.6, 0.4});
  fold(in, *c.geometry, box, 8, 4, 3, {-1.3, 0.2});
  fold(in, *c.geometry, box, 8, 5, 5, {0.3, -1.7});
  UntangleStats st;
  const auto out = untangle_face(in, *c.geometry, UntangleOptions{}, &st);
  std::printf(
      "plane: before min %.4f invalid %lld, after min %.4f invalid %lld, %lld seeds, %d "
      "rings, %d sweeps\n",
      st.before.sicn_min, static_cast<long long>(st.before.invalid), st.after.sicn_min,
      static_cast<long long>(st.after.invalid), static_cast<long long>(st.seeds), st.rings,
      st.sweeps);
  EXPECT_GE(st.before.invalid, 4);
  EXPECT_EQ(st.after.invalid, 0);
  EXPECT_GT(st.after.sicn_min, 0.2);
  EXPECT_FALSE(st.rolled_back);
  EXPECT_EQ(measure(out).sicn_min, st.after.sicn_min);
  expect_locked_and_on_surface(in, out, *c.geometry, c.model.diagonal());
  // Vertices far from the folds are not touched.
  EXPECT_TRUE(out.points[1 * 9 + 7] == in.points[1 * 9 + 7]);
}

TEST(Untangle, FoldedPatchOnACylinderBecomesValid) {
  const Case c =
      load_face(BRepBuilderAPI_MakeFace(gp_Cylinder(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2.0),
                                        0.0, std::numbers::pi, 0.0, 3.0)
                    .Face(),
                "untangle_cyl.brep");
  const Box2 box = c.model.faces()[0].uv_box;
  auto in = grid(*c.geometry, box, 10);
  fold(in, *c.geometry, box, 10, 4, 5, {1.5, 0.5});
  fold(in, *c.geometry, box, 10, 6, 4, {-0.4, 1.4});
  UntangleStats st;
  const auto out = untangle_face(in, *c.geometry, UntangleOptions{}, &st);
  std::printf("cylinder: before min %.4f invalid %lld, after min %.4f invalid %lld, %d sweeps\n",
              st.before.sicn_min, static_cast<long long>(st.before.invalid), st.after.sicn_min,
              static_cast<long long>(st.after.invalid), st.sweeps);
  EXPECT_GE(st.before.invalid, 2);
  EXPECT_EQ(st.after.invalid, 0);
  EXPECT_GT(st.after.sicn_min, 0.2);
  expect_locked_and_on_surface(in, out, *c.geometry, c.model.diagonal());
  for (const auto& p : out.points) EXPECT_NEAR(std::hypot(p.x, p.y), 2.0, 1e-9);
}

TEST(Untangle, ValidMeshIsReturnedUnchanged) {
  const Case c = load_face(
      BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 0.0, 4.0, 0.0, 4.0).Face(),
      "untangle_valid.brep");
  const auto in = grid(*c.geometry, c.model.faces()[0].uv_box, 4);
  UntangleStats st;
  const auto out = untangle_face(in, *c.geometry, UntangleOptions{}, &st);
  EXPECT_EQ(st.seeds, 0);
  EXPECT_EQ(st.sweeps, 0);
  for (std::size_t v = 0; v < in.points.size(); ++v) EXPECT_TRUE(in.points[v] == out.points[v]);
}

TEST(Untangle, ImpossibleFoldIsRolledBack) {
  // A quad of four boundary vertices given in the wrong order: no free vertex can help, the
  // input comes back unchanged.
  const Case c = load_face(
      BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 0.0, 4.0, 0.0, 4.0).Face(),
      "untangle_impossible.brep");
  auto in = grid(*c.geometry, c.model.faces()[0].uv_box, 1);
  in.quads[0] = {in.quads[0][0], in.quads[0][2], in.quads[0][1], in.quads[0][3]};
  UntangleStats st;
  const auto out = untangle_face(in, *c.geometry, UntangleOptions{}, &st);
  EXPECT_EQ(st.before.invalid, 1);
  EXPECT_TRUE(st.rolled_back);
  for (std::size_t v = 0; v < in.points.size(); ++v) EXPECT_TRUE(in.points[v] == out.points[v]);
}

TEST(Untangle, Deterministic) {
  const Case c =
      load_face(BRepBuilderAPI_MakeFace(gp_Cylinder(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2.0),
                                        0.0, std::numbers::pi, 0.0, 3.0)
                    .Face(),
                "untangle_det.brep");
  const Box2 box = c.model.faces()[0].uv_box;
  auto in = grid(*c.geometry, box, 8);
  fold(in, *c.geometry, box, 8, 3, 4, {1.5, 0.5});
  const auto a = untangle_face(in, *c.geometry, UntangleOptions{});
  const auto b = untangle_face(in, *c.geometry, UntangleOptions{});
  for (std::size_t v = 0; v < a.points.size(); ++v) {
    EXPECT_TRUE(a.points[v] == b.points[v]);
    EXPECT_TRUE(a.uv[v] == b.uv[v]);
  }
}

// Issue 29: the poor quads the smoother leaves are lifted patch by patch. The face has two: a
// short edge made by a free vertex pushed next to its neighbour (SICN just under 0.1, valid), and
// a quad held by a corner whose neighbour is a fixed (curve) vertex pushed beside it (SICN about
// 0.01, which no free vertex can change). The untangler, judging the whole face by its minimum,
// keeps neither; the lift keeps the first and leaves the second as it is.
TEST(LiftPoorQuads, LiftsAFreeQuadBesideAForcedOne) {
  const Case c = load_face(
      BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 0.0, 12.0, 0.0, 12.0)
          .Face(),
      "lift_plate.brep");
  const Box2 box = c.model.faces()[0].uv_box;
  const int n = 12;
  auto in = grid(*c.geometry, box, n);
  const auto id = [&](int i, int j) { return static_cast<LO>(j * (n + 1) + i); };
  // Free vertex (8, 8) pushed 0.95 cells toward (9, 8): its quads on that side get a 0.05 edge.
  fold(in, *c.geometry, box, n, 8, 8, {0.95, 0.0});
  // Vertex (1, 1) made a fixed curve vertex and put beside corner (1, 0).
  fold(in, *c.geometry, box, n, 1, 1, {-0.02, -0.97});
  in.vclass[id(1, 1)].dim = 1;
  in.vclass[id(1, 1)].entity = 0;
  in.vclass[id(1, 1)].index = id(1, 1);
  const auto sicn = [](const mesh::FaceMesh& m, LO q) {
    const auto& qd = m.quads[q];
    return mesh::quad_sicn({m.points[qd[0]], m.points[qd[1]], m.points[qd[2]], m.points[qd[3]]});
  };
  const LO free_quad = 7 * n + 8, forced_quad = 0;  // cells (8, 7) and (0, 0)
  ASSERT_GT(sicn(in, free_quad), 0.0);
  ASSERT_LT(sicn(in, free_quad), 0.1);
  ASSERT_GT(sicn(in, forced_quad), 0.0);
  ASSERT_LT(sicn(in, forced_quad), sicn(in, free_quad));

  UntangleOptions uo;
  uo.target = 0.1;
  UntangleStats us;
  const auto whole = untangle_face(in, *c.geometry, uo, &us);
  EXPECT_TRUE(us.rolled_back);
  EXPECT_LT(sicn(whole, free_quad), 0.1);

  LiftStats st;
  const auto out = lift_poor_quads(in, *c.geometry, LiftOptions{}, &st);
  std::printf("lift: free quad %.4f -> %.4f, forced %.4f -> %.4f, %lld seeds, %lld lifted\n",
              sicn(in, free_quad), sicn(out, free_quad), sicn(in, forced_quad),
              sicn(out, forced_quad), static_cast<long long>(st.seeds),
              static_cast<long long>(st.lifted));
  EXPECT_GT(sicn(out, free_quad), 0.3);
  EXPECT_EQ(sicn(out, forced_quad), sicn(in, forced_quad));
  EXPECT_GE(st.lifted, 1);
  EXPECT_GE(st.after.sicn_min, st.before.sicn_min);
  EXPECT_EQ(st.after.invalid, 0);
  expect_locked_and_on_surface(in, out, *c.geometry, c.model.diagonal());
  // Far from both, nothing moves.
  EXPECT_TRUE(out.points[id(4, 10)] == in.points[id(4, 10)]);
  // A mesh above the target comes back as it is.
  const auto good = grid(*c.geometry, box, n);
  const auto same = lift_poor_quads(good, *c.geometry, LiftOptions{}, &st);
  EXPECT_EQ(st.seeds, 0);
  for (std::size_t v = 0; v < good.points.size(); ++v)
    EXPECT_TRUE(good.points[v] == same.points[v]);
}

}  // namespace
}  // namespace qsmesh::smooth
