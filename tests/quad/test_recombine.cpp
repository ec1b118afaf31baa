#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepTools.hxx>
#include <TopoDS_Shape.hxx>
#include <algorithm>
#include <cmath>
#include <gp_Pnt.hxx>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/quad/recombine.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::quad {
namespace {

std::string tmp(const std::string& name) { return qsmesh::test::tmp_dir() + "/" + name; }

cad::CadModel square_plate(double side, const std::string& name) {
  BRepBuilderAPI_MakePolygon poly;
  poly.Add(gp_Pnt(0, 0, 0));
  poly.Add(gp_Pnt(side, 0, 0));
  poly.Add(gp_Pnt(side, side, 0));
  poly.Add(gp_Pnt(0, side, 0));
  poly.Close();
  BRepBuilderAPI_MakeFace face(poly.Wire(), /*OnlyPlane=*/true);
  if (!face.IsDone()) throw std::runtime_error("face construction failed");
  const std::string path = tmp(name);
  if (!BRepTools::Write(face.Shape(), path.c_str()))
    throw std::runtime_error("cannot write " + path);
  return cad::load_cad(path);
}

mesh::FaceMesh background_face(const cad::CadModel& model, LO f, double size) {
  background::BackgroundOptions options;
  options.sizes.size = size;
  const TaskArena tasks(1);
  const auto curves = background::mesh_curves(model, options.sizes, tasks);
  background::FaceReport report;
  auto m = background::mesh_face_background(model, f, curves, options, &report);
  EXPECT_TRUE(report.ok) << report.error;
  return m;
}

LO face_of_type(const cad::CadModel& model, cad::SurfaceType type) {
  for (LO f = 0; f < model.num_faces(); ++f)
    if (model.faces()[f].type == type) return f;
  return kNoIndex;
}

double sicn(const mesh::FaceMesh& m, const std::array<LO, 4>& q) {
  return mesh::quad_sicn({m.points[q[0]], m.points[q[1]], m.points[q[2]], m.points[q[3]]});
}

// Every edge used once lies on the boundary (both ends classified on curves/corners), every other
// edge is used by exactly two elements traversing it in opposite directions.
void expect_conforming(const mesh::FaceMesh& m) {
  std::map<std::pair<LO, LO>, std::pair<int, int>> edges;  // (min,max) -> (uses, sum of +1/-1)
  auto add = [&](LO a, LO b) {
    auto& e = edges[{std::min(a, b), std::max(a, b)}];
    ++e.first;
    e.second += a < b ? 1 : -1;
  };
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) add(t[k], t[(k + 1) % 3]);
  for (const auto& q : m.quads)
    for (int k = 0; k < 4; ++k) add(q[k], q[(k + 1) % 4]);
  int bad = 0;
  for (const auto& [e, u] : edges) {
    if (u.first == 1) {
      if (m.vclass[e.first].dim == 2 || m.vclass[e.second].dim == 2) ++bad;
    } else if (u.first != 2 || u.second != 0) {
      ++bad;
    }
  }
  EXPECT_EQ(bad, 0);
}

void check_recombined(const mesh::FaceMesh& in, const mesh::FaceMesh& out,
                      const RecombineOptions& o, const RecombineStats& stats) {
  EXPECT_EQ(out.points, in.points);  // no vertex added or moved
  EXPECT_EQ(out.uv, in.uv);
  EXPECT_EQ(2 * out.quads.size() + out.triangles.size(), in.triangles.size());
  EXPECT_EQ(stats.quads, static_cast<std::int64_t>(out.quads.size()));
  EXPECT_EQ(stats.triangles_left, static_cast<std::int64_t>(out.triangles.size()));
  for (const auto& q : out.quads) EXPECT_GT(sicn(out, q), o.min_sicn);
  EXPECT_GT(stats.sicn_min, o.min_sicn);
  EXPECT_GE(stats.sicn_avg, stats.sicn_min);
  expect_conforming(out);
}

// Mean angle (degrees, 0..45) between the quad edges and the nearest of the two axes a, b.
double mean_axis_angle(const mesh::FaceMesh& m, const Vec3& a, const Vec3& b) {
  double sum = 0;
  int n = 0;
  for (const auto& q : m.quads)
    for (int k = 0; k < 4; ++k) {
      const Vec3 e = normalized(m.points[q[(k + 1) % 4]] - m.points[q[k]]);
      const double c = std::min(1.0, std::max(std::abs(dot(e, a)), std::abs(dot(e, b))));
      sum += std::acos(c) * 180 / std::numbers::pi;
      ++n;
    }
  return n ? sum / n : 90;
}

TEST(Recombine, PlatePairsMostTriangles) {
  const auto model = square_plate(10, "rc_plate.brep");
  const auto tri = background_face(model, 0, 0.7);
  ASSERT_GT(tri.triangles.size(), 100u);
  RecombineOptions options;
  RecombineStats stats;
  const auto out = recombine(tri, {}, options, &stats);
  check_recombined(tri, out, options, stats);
  const double paired =
      2.0 * static_cast<double>(out.quads.size()) / static_cast<double>(tri.triangles.size());
  std::printf("plate: %zu triangles, %.1f%% paired, SICN min %.3f avg %.3f\n", tri.triangles.size(),
              100 * paired, stats.sicn_min, stats.sicn_avg);
  EXPECT_GE(paired, 0.8);
  // Deterministic.
  const auto again = recombine(tri, {}, options);
  EXPECT_EQ(again.quads, out.quads);
  EXPECT_EQ(again.triangles, out.triangles);
}

TEST(Recombine, CylinderSidePairsMostTriangles) {
  const auto model = cad::load_cad(test::write_cylinder(tmp("rc_cyl.brep")));
  const LO f = face_of_type(model, cad::SurfaceType::Cylinder);
  ASSERT_NE(f, kNoIndex);
  const auto tri = background_face(model, f, 0.5);
  RecombineOptions options;
  RecombineStats stats;
  const auto out = recombine(tri, {}, options, &stats);
  check_recombined(tri, out, options, stats);
  const double paired =
      2.0 * static_cast<double>(out.quads.size()) / static_cast<double>(tri.triangles.size());
  std::printf("cylinder side: %zu triangles, %.1f%% paired, SICN min %.3f avg %.3f\n",
              tri.triangles.size(), 100 * paired, stats.sicn_min, stats.sicn_avg);
  EXPECT_GE(paired, 0.7);
}

TEST(Recombine, HigherThresholdFormsOnlyBetterQuads) {
  const auto model = square_plate(10, "rc_plate2.brep");
  const auto tri = background_face(model, 0, 0.7);
  RecombineOptions strict;
  strict.min_sicn = 0.7;
  RecombineStats stats;
  const auto out = recombine(tri, {}, strict, &stats);
  check_recombined(tri, out, strict, stats);
  RecombineStats loose_stats;
  (void)recombine(tri, {}, {}, &loose_stats);
  EXPECT_LE(stats.quads, loose_stats.quads);
}

TEST(Recombine, CrossFieldAlignmentImprovesEdgeDirections) {
  const auto model = square_plate(10, "rc_plate3.brep");
  const auto tri = background_face(model, 0, 0.5);
  // Axes of the plate, and the same cross turned by 30 degrees: the alignment term must pull the
  // quad edges toward whichever cross it is given.
  for (const double deg : {0.0, 30.0}) {
    const double r = deg * std::numbers::pi / 180;
    const Vec3 a{std::cos(r), std::sin(r), 0}, b{-std::sin(r), std::cos(r), 0};
    const std::vector<std::array<Vec3, 2>> dirs(tri.triangles.size(), {a, b});
    RecombineOptions plain;
    plain.alignment_weight = 0;
    RecombineOptions aligned;
    aligned.alignment_weight = 0.5;
    RecombineStats s0, s1;
    const auto q0 = recombine(tri, dirs, plain, &s0);
    const auto q1 = recombine(tri, dirs, aligned, &s1);
    check_recombined(tri, q1, aligned, s1);
    const double angle0 = mean_axis_angle(q0, a, b);
    const double angle1 = mean_axis_angle(q1, a, b);
    std::printf(
        "cross at %g deg: mean edge angle %.2f deg (weight 0), %.2f deg (weight 0.5); quads %lld / "
        "%lld\n",
        deg, angle0, angle1, static_cast<long long>(s0.quads), static_cast<long long>(s1.quads));
    EXPECT_LT(angle1, angle0 - 0.5) << "cross at " << deg << " degrees";
    EXPECT_GE(2.0 * static_cast<double>(s1.quads),
              0.75 * static_cast<double>(tri.triangles.size()));
  }
  // Wrong number of directions.
  const std::vector<std::array<Vec3, 2>> few(3);
  EXPECT_THROW((void)recombine(tri, few, {}), Error);
}

}  // namespace
}  // namespace qsmesh::quad
