#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::background {
namespace {

std::string tmp(const std::string& name) { return qsmesh::test::tmp_dir() + "/" + name; }

TEST(CurveMesh, StraightEdgesFollowTheSize) {
  const cad::CadModel model = cad::load_cad(test::write_box_with_hole(tmp("cm_box.brep")));
  SizeOptions sizes;
  sizes.size = 0.5;
  const TaskArena tasks(1);
  const auto meshes = mesh_curves(model, sizes, tasks);
  ASSERT_EQ(static_cast<LO>(meshes.size()), model.num_curves());
  for (LO c = 0; c < model.num_curves(); ++c) {
    const auto& curve = model.curves()[c];
    const auto& m = meshes[c];
    ASSERT_GE(m.num_edges(), 1);
    EXPECT_EQ(m.points.front(), model.corners()[curve.corners[0]].point);
    EXPECT_EQ(m.points.back(), model.corners()[curve.corners[1]].point);
    for (std::size_t i = 1; i < m.t.size(); ++i) ASSERT_GT(m.t[i], m.t[i - 1]);
    if (curve.type == cad::CurveType::Line) {
      // A straight edge of length L gets round(L / h) edges of equal length.
      EXPECT_EQ(m.num_edges(), std::lround(curve.length / sizes.size)) << "curve " << c;
      for (LO i = 0; i < m.num_edges(); ++i)
        EXPECT_NEAR(distance(m.points[i], m.points[i + 1]), curve.length / m.num_edges(), 1e-9);
    }
  }
}

TEST(CurveMesh, CirclesGetEdgesPerTurnFromCurvature) {
  const cad::CadModel model = cad::load_cad(test::write_cylinder(tmp("cm_cyl.brep")));
  SizeOptions sizes;
  sizes.size = 100.0;  // the cap does not bind: curvature decides
  sizes.min_size = 1e-3;
  sizes.edges_per_turn = 16;
  const TaskArena tasks(2);
  const auto meshes = mesh_curves(model, sizes, tasks);
  int circles = 0;
  for (LO c = 0; c < model.num_curves(); ++c) {
    if (model.curves()[c].type != cad::CurveType::Circle) continue;
    ++circles;
    EXPECT_EQ(meshes[c].num_edges(), 16) << "curve " << c;
  }
  EXPECT_EQ(circles, 2);
}

TEST(CurveMesh, ClosedCurveHasAtLeastThreeEdgesAndDegenerateOne) {
  const cad::CadModel model = cad::load_cad(test::write_sphere(tmp("cm_sphere.brep")));
  SizeOptions sizes;
  sizes.size = 1e3;
  sizes.edges_per_turn = 2;  // asks for fewer than allowed
  const TaskArena tasks(1);
  const auto meshes = mesh_curves(model, sizes, tasks);
  for (LO c = 0; c < model.num_curves(); ++c) {
    if (model.curves()[c].degenerate) {
      EXPECT_EQ(meshes[c].num_edges(), 1);
    } else if (model.curves()[c].corners[0] == model.curves()[c].corners[1]) {
      EXPECT_GE(meshes[c].num_edges(), 3);
    }
  }
}

TEST(CurveMesh, SameResultWhateverTheThreads) {
  const cad::CadModel model = cad::load_cad(test::write_filleted_box(tmp("cm_fillet.step")));
  SizeOptions sizes;
  sizes.size = 0.4;
  const auto a = mesh_curves(model, sizes, TaskArena(1));
  const auto b = mesh_curves(model, sizes, TaskArena(2));
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t c = 0; c < a.size(); ++c) {
    EXPECT_EQ(a[c].t, b[c].t);
    ASSERT_EQ(a[c].points.size(), b[c].points.size());
    for (std::size_t i = 0; i < a[c].points.size(); ++i) EXPECT_EQ(a[c].points[i], b[c].points[i]);
  }
}

// CurveMeshing's steps done curve by curve, in other orders and split in two as two ranks would
// do them (the pipeline's rounds), give mesh_curves' meshes exactly. The face has a slot (two
// sides 0.2 apart that share no corner: a small feature) and a 3.8-degree wedge, so that the
// second step changes sizes.
TEST(CurveMesh, CurveByCurveInAnyOrderGivesTheSameMeshes) {
  const cad::CadModel model = cad::load_cad(test::write_polygon_face(
      {{-15, 0.5}, {0, 0}, {10, 0}, {10, 1}, {5.1, 1}, {5.1, 0.2}, {4.9, 0.2}, {4.9, 1}, {0, 1}},
      tmp("cm_slot_wedge.brep")));
  SizeOptions sizes;
  sizes.size = 0.5;
  const auto reference = mesh_curves(model, sizes, TaskArena(1));

  const CurveMeshing meshing(model, sizes);
  const LO n = meshing.num_curves();
  ASSERT_EQ(n, 9);
  ASSERT_TRUE(meshing.limits_sizes());
  // Step 1: the even curves on "rank 0", the odd ones on "rank 1", each backwards; then every
  // curve's samples copied from its rank, as the all-gather does.
  std::vector<CurveSamples> rank0(static_cast<std::size_t>(n)), rank1(rank0.size());
  for (LO c = n - 1; c >= 0; --c) (c % 2 == 0 ? rank0 : rank1)[c] = meshing.sample(c);
  std::vector<CurveSamples> samples(rank0.size());
  for (LO c = 0; c < n; ++c) samples[c] = (c % 2 == 0 ? rank0 : rank1)[c];
  for (LO c = 0; c < n; ++c) {
    EXPECT_EQ(samples[c].curve, c);
    EXPECT_GE(meshing.sampling_cost(c), 1.0);
  }
  // Step 2: each "rank" with its own search, its curves in another split and order.
  const auto before = samples;
  auto done0 = samples, done1 = samples;
  {
    const CurveFeatureSearch search0 = meshing.feature_search(samples);
    const CurveFeatureSearch search1 = meshing.feature_search(samples);
    for (LO c = 0; c < n; ++c)
      if (c < 4) meshing.limit_sizes(search0, done0[c]);
    for (LO c = n - 1; c >= 4; --c) meshing.limit_sizes(search1, done1[c]);
  }
  int lowered = 0;
  for (LO c = 0; c < n; ++c) {
    samples[c].h = (c < 4 ? done0 : done1)[c].h;
    for (std::size_t k = 0; k < samples[c].h.size(); ++k)
      if (samples[c].h[k] < before[c].h[k]) {
        ++lowered;
        break;
      }
  }
  EXPECT_GE(lowered, 4) << "the slot's and the wedge's sides should be lowered by step 2";
  const auto meshes = meshing.place(std::move(samples), TaskArena(2));
  ASSERT_EQ(meshes.size(), reference.size());
  for (std::size_t c = 0; c < meshes.size(); ++c) {
    EXPECT_EQ(meshes[c].curve, reference[c].curve);
    EXPECT_EQ(meshes[c].t, reference[c].t) << "curve " << c;
    ASSERT_EQ(meshes[c].points.size(), reference[c].points.size()) << "curve " << c;
    for (std::size_t i = 0; i < meshes[c].points.size(); ++i)
      EXPECT_EQ(meshes[c].points[i], reference[c].points[i]) << "curve " << c << " vertex " << i;
  }
}

TEST(CurveMesh, RejectsNonPositiveSize) {
  const cad::CadModel model = cad::load_cad(test::write_cylinder(tmp("cm_cyl2.brep")));
  SizeOptions sizes;
  sizes.size = 0;
  EXPECT_THROW((void)mesh_curves(model, sizes, TaskArena(1)), Error);
}

}  // namespace
}  // namespace qsmesh::background
