// Paper 004 on a group of CAD faces (holomorphic/group.hpp): a T-shaped duct built with
// OpenCASCADE (two pipes fused, the junction filleted, the end caps removed) is one smooth group
// of faces whose glued triangulation is a pair of pants (b = 3), meshed as one surface with the
// one valence-8 vertex the theory allows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <numbers>
#include <numeric>
#include <set>

#include "holo_shapes.hpp"
#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/holomorphic/group.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"
#include "valences.hpp"

namespace qsmesh::holomorphic {
namespace {

std::string tmp(const std::string& name) { return qsmesh::test::tmp_dir() + "/" + name; }

constexpr double kMainRadius = 1.0, kHalfLength = 2.5, kBranchRadius = 0.7, kBranchHeight = 4.0;

cad::CadModel t_duct(double fillet, const std::string& name) {
  return cad::load_cad(test::write_t_duct(kMainRadius, kHalfLength, kBranchRadius, kBranchHeight,
                                          fillet, tmp(name)));
}

TEST(HolomorphicGroup, FilletedTDuctIsOneSmoothGroup) {
  const cad::CadModel model = t_duct(0.25, "tduct.brep");
  // Two cylinders and the fillet; the fillet's two curves are the smooth ones, the ends and the
  // seams are not (one face each).
  ASSERT_EQ(model.num_faces(), 3);
  int smooth = 0;
  for (LO c = 0; c < model.num_curves(); ++c) {
    const bool two = model.curve2faces()[c].size() == 2;
    EXPECT_EQ(smooth_across(model, c, {}), two) << "curve " << c;
    smooth += two ? 1 : 0;
  }
  EXPECT_EQ(smooth, 2);
  const auto groups = smooth_face_groups(model, {});
  ASSERT_EQ(groups.size(), 1u);
  EXPECT_EQ(static_cast<LO>(groups[0].size()), model.num_faces());
}

// Without the fillet the pipes meet at a crease (90 degrees where the branch's top meets the
// main pipe's): no curve is smooth, each face is its own group.
TEST(HolomorphicGroup, CreasedTDuctIsNotGrouped) {
  const cad::CadModel model = t_duct(0, "tduct_sharp.brep");
  const auto groups = smooth_face_groups(model, {});
  EXPECT_EQ(static_cast<LO>(groups.size()), model.num_faces());
  for (LO c = 0; c < model.num_curves(); ++c) EXPECT_FALSE(smooth_across(model, c, {}));
}

TEST(HolomorphicGroup, BalancedLoopCountsAddUp) {
  // Periods of a pair of pants: the first loop carries what the two others do.
  const std::vector<double> periods{-6.1, 3.9, 2.3};
  const auto counts = balanced_loop_counts(periods, 0.25);
  ASSERT_EQ(counts.size(), 3u);
  EXPECT_EQ(counts[1], 16);  // 15.6 rounded to even
  EXPECT_EQ(counts[2], 10);  // 9.2
  EXPECT_EQ(counts[0], counts[1] + counts[2]);
  for (const LO n : counts) EXPECT_EQ(n % 2, 0);
}

using test::Valences;
using test::valences;

// The filleted T-duct meshed as one group: the basis and the energy on the glued triangulation
// (three faces, their seams and the two fillet curves inside it), loop counts from the optimised
// form's periods, then the patches.
TEST(HolomorphicGroup, FilletedTDuctMeshedAsOnePairOfPants) {
  const cad::CadModel model = t_duct(0.25, "tduct_mesh.brep");
  const auto groups = smooth_face_groups(model, {});
  ASSERT_EQ(groups.size(), 1u);
  const std::vector<LO>& faces = groups[0];
  background::BackgroundOptions options;
  options.sizes.size = 0.12;
  const std::vector<mesh::CurveMesh> curves =
      background::mesh_curves(model, options.sizes, TaskArena(1));
  std::vector<mesh::FaceMesh> backgrounds;
  std::vector<std::unique_ptr<cad::FaceGeometry>> owned;
  std::vector<const cad::FaceGeometry*> surfaces;
  auto loops_on = [&](std::span<const mesh::CurveMesh> c) {
    std::vector<std::vector<mesh::BoundaryLoop>> out;
    for (std::size_t i = 0; i < faces.size(); ++i)
      out.push_back(background::face_boundary(model, faces[i], *surfaces[i], c));
    return out;
  };
  for (const LO f : faces) {
    background::FaceReport report;
    backgrounds.push_back(background::mesh_face_background(model, f, curves, options, &report));
    ASSERT_TRUE(report.ok) << report.error;
    owned.push_back(model.face_geometry(f));
    surfaces.push_back(owned.back().get());
  }
  const GluedGroup first = glue_group(faces, backgrounds, loops_on(curves));
  ASSERT_TRUE(first.ok) << first.reason;
  const PolyAnnulus s = poly_annulus(first.background);
  ASSERT_TRUE(s.ok) << s.reason;
  EXPECT_EQ(s.loops.size(), 3u);  // the three open ends
  EXPECT_EQ(s.euler, -1);
  // The form's periods set the ends' counts (the free curves of the duct).
  const HolomorphicBasis B = holomorphic_basis(s, {}, nullptr);
  const EnergyResult E = minimize_area_distortion(s, B, {});
  const auto phi = combine(B, E.lambda);
  const ZeroReport Z = find_zeros(s, phi);
  EXPECT_NEAR(Z.index_sum, 1.0, 1e-6);  // b - 2
  const std::vector<double> periods = loop_periods(s, phi);
  EXPECT_NEAR(periods[0] + periods[1] + periods[2], 0.0, 1e-6 * std::abs(periods[0]));
  const std::vector<LO> counts = balanced_loop_counts(periods, 0.2);
  std::vector<mesh::CurveMesh> final_curves = curves;
  std::map<LO, LO> merged_curve;  // merged vertex -> its curve (curve vertices of the glue)
  for (std::size_t v = 0; v < first.background.vclass.size(); ++v)
    if (first.background.vclass[v].dim == 1)
      merged_curve[s.face2merged[v]] = first.background.vclass[v].entity;
  for (std::size_t l = 0; l < s.loops.size(); ++l) {
    std::set<LO> on;
    for (const LO x : s.loops[l])
      if (merged_curve.count(x) != 0) on.insert(merged_curve[x]);
    ASSERT_EQ(on.size(), 1u) << "each end is one closed curve";
    final_curves[static_cast<std::size_t>(*on.begin())] =
        test::uniform_curve_mesh(model, *on.begin(), counts[l]);
  }
  const GluedGroup group = glue_group(faces, backgrounds, loops_on(final_curves));
  ASSERT_TRUE(group.ok) << group.reason;
  HolomorphicReport report;
  const Stopwatch clock;
  const GroupMesh q = mesh_group(group, surfaces, {}, &report);
  const double seconds = clock.seconds();
  ASSERT_TRUE(report.ok) << report.reason;
  EXPECT_EQ(report.boundaries, 3);
  EXPECT_EQ(report.zeros, 1);
  ASSERT_GE(report.energy.size(), 2u);
  for (std::size_t i = 1; i < report.energy.size(); ++i)
    EXPECT_LT(report.energy[i], report.energy[i - 1]) << "iteration " << i;
  const Valences v = valences(q.mesh);
  EXPECT_EQ(v.eight, 1);  // one simple zero: index -1 = chi of the pair of pants
  EXPECT_EQ(v.other_irregular, 0);
  EXPECT_EQ(v.boundary_irregular, 0);
  const auto stats = mesh::face_quad_stats(q.mesh);
  EXPECT_EQ(stats.triangles, 0);
  EXPECT_GT(stats.sicn_min, 0.3);
  std::cout << "T-duct group of " << faces.size() << " faces: counts " << counts[0] << ", "
            << counts[1] << ", " << counts[2] << "; " << stats.quads << " quads, " << report.patches
            << " patches, SICN min " << stats.sicn_min << " avg " << stats.sicn_avg << ", energy "
            << report.energy.front() << " -> " << report.energy.back() << " in "
            << report.energy.size() - 1 << " iterations, " << seconds << " s\n";
  // Conforming: every edge in at most two quads, the edges in one exactly the ends' segments.
  std::map<std::pair<LO, LO>, int> uses;
  for (const auto& quad : q.mesh.quads)
    for (int k = 0; k < 4; ++k) {
      const LO a = quad[static_cast<std::size_t>(k)],
               b = quad[static_cast<std::size_t>((k + 1) % 4)];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  std::size_t boundary = 0;
  for (const auto& [e, n] : uses) {
    EXPECT_LE(n, 2);
    if (n == 1) {
      ++boundary;
      EXPECT_LT(q.mesh.vclass[static_cast<std::size_t>(e.first)].dim, 2);
      EXPECT_LT(q.mesh.vclass[static_cast<std::size_t>(e.second)].dim, 2);
    }
  }
  EXPECT_EQ(static_cast<LO>(boundary), counts[0] + counts[1] + counts[2]);
  // Each quad goes to the face that holds its centre: a main-pipe quad's centre is at the main
  // radius from the x axis, a branch quad's at the branch radius from the z axis; the fillet
  // gets the quads between.
  ASSERT_EQ(q.quad_face.size(), q.mesh.quads.size());
  std::map<LO, LO> per_face;
  for (std::size_t k = 0; k < q.mesh.quads.size(); ++k) {
    const LO f = q.quad_face[k];
    ++per_face[f];
    Vec3 c{0, 0, 0};
    for (const LO x : q.mesh.quads[k]) c = c + q.mesh.points[static_cast<std::size_t>(x)] * 0.25;
    const cad::SurfaceType type = model.faces()[static_cast<std::size_t>(f)].type;
    if (type != cad::SurfaceType::Cylinder) continue;
    const double to_x = std::hypot(c.y, c.z), to_z = std::hypot(c.x, c.y);
    const bool main_pipe = std::abs(to_x - kMainRadius) < 0.1;
    const bool branch = std::abs(to_z - kBranchRadius) < 0.1 && c.z > 0.5;
    EXPECT_TRUE(main_pipe || branch) << "quad " << k << " on face " << f << " centre " << c.x << " "
                                     << c.y << " " << c.z << " to_x " << to_x << " to_z " << to_z;
  }
  EXPECT_EQ(per_face.size(), faces.size()) << "every face of the group holds quads";
  // The vertices lie on the CAD: each on the face it is classified on.
  for (std::size_t x = 0; x < q.mesh.points.size(); ++x) {
    const auto& vc = q.mesh.vclass[x];
    if (vc.dim != 2) continue;
    const auto it = std::find(faces.begin(), faces.end(), vc.entity);
    ASSERT_NE(it, faces.end());
    const auto at = surfaces[static_cast<std::size_t>(it - faces.begin())]->eval(q.mesh.uv[x]);
    EXPECT_LT(norm(at.p - q.mesh.points[x]), 1e-6);
  }
}

// A straight pipe in two faces (b = 2 once glued): the annulus grid of the group, the two seams
// and the circle between the faces inside it, no singularity.
TEST(HolomorphicGroup, TwoPiecePipeIsOneAnnulusGrid) {
  const cad::CadModel model =
      cad::load_cad(test::write_two_piece_pipe(1.0, 1.5, tmp("pipe2.brep")));
  ASSERT_EQ(model.num_faces(), 2);
  const auto groups = smooth_face_groups(model, {});
  ASSERT_EQ(groups.size(), 1u);
  background::BackgroundOptions options;
  options.sizes.size = 0.2;
  std::vector<mesh::CurveMesh> curves = background::mesh_curves(model, options.sizes, TaskArena(1));
  // The two end circles (one face each) get 30 edges.
  for (LO c = 0; c < model.num_curves(); ++c) {
    const auto& curve = model.curves()[static_cast<std::size_t>(c)];
    if (model.curve2faces()[c].size() == 1 && curve.corners[0] == curve.corners[1] &&
        std::abs(curve.length - 2 * std::numbers::pi) < 1e-6)
      curves[static_cast<std::size_t>(c)] = test::uniform_curve_mesh(model, c, 30);
  }
  std::vector<mesh::FaceMesh> backgrounds;
  std::vector<std::vector<mesh::BoundaryLoop>> loops;
  std::vector<std::unique_ptr<cad::FaceGeometry>> owned;
  std::vector<const cad::FaceGeometry*> surfaces;
  for (const LO f : groups[0]) {
    background::FaceReport report;
    backgrounds.push_back(background::mesh_face_background(model, f, curves, options, &report));
    ASSERT_TRUE(report.ok) << report.error;
    owned.push_back(model.face_geometry(f));
    surfaces.push_back(owned.back().get());
    loops.push_back(background::face_boundary(model, f, *surfaces.back(), curves));
  }
  const GluedGroup group = glue_group(groups[0], backgrounds, loops);
  ASSERT_TRUE(group.ok) << group.reason;
  HolomorphicReport report;
  const GroupMesh q = mesh_group(group, surfaces, {}, &report);
  ASSERT_TRUE(report.ok) << report.reason;
  EXPECT_EQ(report.boundaries, 2);
  EXPECT_EQ(report.zeros, 0);
  EXPECT_EQ(report.columns, 30);
  // Rows from the modulus: height 3 over the period 2 pi, 30 columns: 14.3 -> 14.
  EXPECT_EQ(report.rows, 14);
  const auto stats = mesh::face_quad_stats(q.mesh);
  EXPECT_EQ(stats.quads, 30 * 14);
  EXPECT_EQ(stats.irregular_interior, 0);
  EXPECT_GT(stats.sicn_min, 0.95);
  for (const auto& p : q.mesh.points) EXPECT_NEAR(std::hypot(p.x, p.y), 1.0, 1e-6);
  // Half the quads on each face, split at the middle circle.
  std::map<LO, int> per_face;
  for (std::size_t k = 0; k < q.quad_face.size(); ++k) {
    ++per_face[q.quad_face[k]];
    Vec3 c{0, 0, 0};
    for (const LO x : q.mesh.quads[k]) c = c + q.mesh.points[static_cast<std::size_t>(x)] * 0.25;
    const LO lower = c.z < 1.5 ? 0 : 1;
    const auto& f = model.faces()[static_cast<std::size_t>(q.quad_face[k])];
    EXPECT_EQ(f.box.lo.z < 0.75 ? 0 : 1, lower) << "quad " << k;
  }
  EXPECT_EQ(per_face.size(), 2u);
}

}  // namespace
}  // namespace qsmesh::holomorphic
