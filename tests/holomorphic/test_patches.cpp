// Patch meshing of poly-annuli with b >= 3 loops (mesh_poly_annulus, paper 004 Sec. 4): disks and
// rounded plates with 2 and 3 holes, built with OpenCASCADE, with curve counts that add up as the
// form's periods do.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <numeric>

#include "holo_shapes.hpp"
#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/holomorphic/holomorphic.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"
#include "valences.hpp"

namespace qsmesh::holomorphic {
namespace {

std::string tmp(const std::string& name) { return qsmesh::test::tmp_dir() + "/" + name; }

struct MeshedFace {
  cad::CadModel model;
  LO face = 0;
  std::vector<mesh::CurveMesh> curves;
  mesh::FaceMesh background;
  std::vector<mesh::BoundaryLoop> loops;
  std::unique_ptr<cad::FaceGeometry> surface;
  std::vector<LO> hole_counts;
  LO outer_count = 0;
};

double length(const mesh::CurveMesh& c) {
  double l = 0;
  for (std::size_t i = 1; i < c.points.size(); ++i) l += norm(c.points[i] - c.points[i - 1]);
  return l;
}

// The planar face of `path` with `hole` edges on each hole circle (a closed curve shorter than
// `hole_length`) and the outer loop's curves sharing `outer` edges in proportion to their lengths.
MeshedFace mesh_face(const std::string& path, double size, double hole_length, LO hole, LO outer) {
  MeshedFace m{cad::load_cad(path), 0, {}, {}, {}, nullptr, {}, 0};
  EXPECT_EQ(m.model.num_faces(), 1);
  background::BackgroundOptions options;
  options.sizes.size = size;
  m.curves = background::mesh_curves(m.model, options.sizes, TaskArena(1));
  std::vector<LO> outer_curves;
  double outer_length = 0;
  for (LO c = 0; c < static_cast<LO>(m.curves.size()); ++c) {
    const auto& curve = m.model.curves()[static_cast<std::size_t>(c)];
    const double l = length(m.curves[static_cast<std::size_t>(c)]);
    if (curve.corners[0] == curve.corners[1] && l < hole_length) {
      m.curves[static_cast<std::size_t>(c)] = test::uniform_curve_mesh(m.model, c, hole);
      m.hole_counts.push_back(hole);
    } else {
      outer_curves.push_back(c);
      outer_length += l;
    }
  }
  // Largest remainders: the outer counts sum to `outer` exactly.
  std::vector<LO> n(outer_curves.size());
  std::vector<std::pair<double, std::size_t>> rest;
  LO sum = 0;
  for (std::size_t i = 0; i < outer_curves.size(); ++i) {
    const double x =
        double(outer) * length(m.curves[static_cast<std::size_t>(outer_curves[i])]) / outer_length;
    n[i] = std::max<LO>(1, static_cast<LO>(std::floor(x)));
    sum += n[i];
    rest.emplace_back(x - std::floor(x), i);
  }
  std::sort(rest.rbegin(), rest.rend());
  for (std::size_t k = 0; sum < outer; ++k, ++sum) ++n[rest[k % rest.size()].second];
  for (std::size_t i = 0; i < outer_curves.size(); ++i)
    m.curves[static_cast<std::size_t>(outer_curves[i])] =
        test::uniform_curve_mesh(m.model, outer_curves[i], n[i]);
  m.outer_count = std::accumulate(n.begin(), n.end(), LO{0});
  background::FaceReport report;
  m.background = background::mesh_face_background(m.model, 0, m.curves, options, &report);
  EXPECT_TRUE(report.ok) << report.error;
  m.surface = m.model.face_geometry(0);
  m.loops = background::face_boundary(m.model, 0, *m.surface, m.curves);
  return m;
}

using test::Valences;
using test::valences;

// The quad mesh's boundary edges are exactly the final loops' segments (conforming with the
// neighbouring faces), and no edge has more than two quads.
void expect_conforming(const mesh::FaceMesh& q, std::span<const mesh::BoundaryLoop> loops) {
  std::map<std::pair<LO, LO>, int> uses;
  for (const auto& quad : q.quads)
    for (int k = 0; k < 4; ++k) {
      const LO a = quad[static_cast<std::size_t>(k)],
               b = quad[static_cast<std::size_t>((k + 1) % 4)];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  std::size_t boundary = 0, segments = 0;
  for (const auto& [e, n] : uses) {
    EXPECT_LE(n, 2);
    if (n == 1) {
      ++boundary;
      EXPECT_LT(q.vclass[static_cast<std::size_t>(e.first)].dim, 2);
      EXPECT_LT(q.vclass[static_cast<std::size_t>(e.second)].dim, 2);
    }
  }
  for (const auto& l : loops) segments += l.points.size();
  EXPECT_EQ(boundary, segments);
}

void expect_oriented(const mesh::FaceMesh& q) {
  for (const auto& quad : q.quads) {
    const Vec3 n = cross(
        q.points[static_cast<std::size_t>(quad[2])] - q.points[static_cast<std::size_t>(quad[0])],
        q.points[static_cast<std::size_t>(quad[3])] - q.points[static_cast<std::size_t>(quad[1])]);
    EXPECT_GT(n.z, 0);  // the planar faces here face +z
    if (n.z <= 0) {
      for (const LO v : quad)
        std::printf("  (%g %g d%d)", q.points[v].x, q.points[v].y, q.vclass[v].dim);
      std::printf("\n");
    }
  }
}

void check(const MeshedFace& m, LO b) {
  ASSERT_EQ(static_cast<LO>(m.loops.size()), b);
  HolomorphicReport report;
  const mesh::FaceMesh q = mesh_poly_annulus(m.background, m.loops, *m.surface, {}, &report);
  ASSERT_TRUE(report.ok) << report.reason;
  EXPECT_EQ(report.boundaries, b);
  EXPECT_EQ(report.zeros, b - 2);
  // The edges of the Reeb graph of v (a tree: 2b - 3), less the thin ones between two zeros.
  EXPECT_GE(report.patches, b);
  EXPECT_LE(report.patches, 2 * b - 3);
  // The energy decreases at every logged iteration.
  ASSERT_GE(report.energy.size(), 2u);
  for (std::size_t i = 1; i < report.energy.size(); ++i)
    EXPECT_LT(report.energy[i], report.energy[i - 1]) << "iteration " << i;
  const Valences v = valences(q);
  EXPECT_EQ(v.eight, b - 2);        // Poincare-Hopf: each simple zero has index -1
  EXPECT_EQ(v.other_irregular, 0);  // no 3-5 pair
  EXPECT_EQ(v.boundary_irregular, 0);
  const auto stats = mesh::face_quad_stats(q);
  EXPECT_EQ(stats.triangles, 0);
  EXPECT_EQ(stats.irregular_interior, b - 2);
  EXPECT_GT(stats.sicn_min, 0.3);
  std::cout << "b = " << b << ": " << stats.quads << " quads, " << report.patches
            << " patches, SICN min " << stats.sicn_min << " avg " << stats.sicn_avg << ", energy "
            << report.energy.front() << " -> " << report.energy.back() << " in "
            << report.energy.size() - 1 << " iterations\n";
  expect_conforming(q, m.loops);
  expect_oriented(q);
}

TEST(HolomorphicPatches, DiskWithTwoHolesHasOneValenceEightVertex) {
  const MeshedFace m = mesh_face(
      test::write_disk_with_holes(3.0, {{{-1.3, 0.0, 0.8}}, {{1.3, 0.0, 0.8}}}, tmp("disk2.brep")),
      0.2, 6.0, 24, 48);
  check(m, 3);
}

TEST(HolomorphicPatches, DiskWithThreeHolesHasTwoValenceEightVertices) {
  const MeshedFace m = mesh_face(
      test::write_disk_with_holes(3.0, {{{-1.4, -0.8, 0.6}}, {{0.0, 1.5, 0.6}}, {{1.4, -0.8, 0.6}}},
                                  tmp("disk3.brep")),
      0.2, 5.0, 20, 60);
  check(m, 4);
}

TEST(HolomorphicPatches, RoundedPlateWithTwoHoles) {
  const MeshedFace m =
      mesh_face(test::write_rounded_plate_with_holes(
                    8, 4, 1.0, {{{2.5, 2.0, 0.8}}, {{5.5, 2.0, 0.8}}}, tmp("rplate2.brep")),
                0.2, 6.0, 28, 56);
  check(m, 3);
}

TEST(HolomorphicPatches, RoundedPlateWithThreeHoles) {
  const MeshedFace m =
      mesh_face(test::write_rounded_plate_with_holes(
                    10, 4, 1.0, {{{2.0, 2.0, 0.8}}, {{5.0, 2.2, 0.7}}, {{8.0, 1.9, 0.8}}},
                    tmp("rplate3.brep")),
                0.2, 6.0, 24, 72);
  check(m, 4);
}

// Counts that do not add up as the periods do (every loop 24: 24 != 24 + 24) cannot be
// conforming with one valence-8 vertex: the face falls back with a reason.
TEST(HolomorphicPatches, CountsThatDoNotAddUpFallBack) {
  const MeshedFace m = mesh_face(
      test::write_disk_with_holes(3.0, {{{-1.3, 0.0, 0.7}}, {{1.3, 0.2, 0.8}}}, tmp("disk2b.brep")),
      0.2, 6.0, 24, 24);
  HolomorphicReport report;
  const mesh::FaceMesh q = mesh_poly_annulus(m.background, m.loops, *m.surface, {}, &report);
  EXPECT_FALSE(report.ok);
  EXPECT_TRUE(q.quads.empty());
  EXPECT_NE(report.reason.find("do not add up"), std::string::npos) << report.reason;
}

// A plate with square corners: each corner is a boundary vertex of two quads of the outer
// patch's grid (the right angle split by the column from it), the interior as on the rounded
// plate. Above max_patch_corner_turn_deg the face falls back.
TEST(HolomorphicPatches, SquarePlateWithTwoHolesSplitsItsCorners) {
  const MeshedFace m =
      mesh_face(test::write_plate_with_holes(8, 4, {{{2.5, 2.0, 0.8}}, {{5.5, 2.0, 0.8}}},
                                             tmp("splate2.brep")),
                0.2, 6.0, 28, 56);
  HolomorphicReport report;
  const mesh::FaceMesh q = mesh_poly_annulus(m.background, m.loops, *m.surface, {}, &report);
  ASSERT_TRUE(report.ok) << report.reason;
  const Valences v = valences(q);
  EXPECT_EQ(v.eight, 1);
  EXPECT_EQ(v.other_irregular, 0);
  EXPECT_EQ(v.boundary_irregular, 0);  // two quads at every boundary vertex, corners included
  const auto stats = mesh::face_quad_stats(q);
  EXPECT_EQ(stats.irregular_interior, 1);
  EXPECT_EQ(stats.irregular_boundary, 4);  // the corners, where the default mesh puts one quad
  EXPECT_GT(stats.sicn_min, 0.3);
  std::cout << "square plate: " << stats.quads << " quads, SICN min " << stats.sicn_min << " avg "
            << stats.sicn_avg << "\n";
  expect_conforming(q, m.loops);
  expect_oriented(q);
  HolomorphicOptions strict;
  strict.max_patch_corner_turn_deg = 60;
  const mesh::FaceMesh none = mesh_poly_annulus(m.background, m.loops, *m.surface, strict, &report);
  EXPECT_FALSE(report.ok);
  EXPECT_TRUE(none.quads.empty());
  EXPECT_NE(report.reason.find("turns by 90 degrees"), std::string::npos) << report.reason;
}

}  // namespace
}  // namespace qsmesh::holomorphic
