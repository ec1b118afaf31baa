#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "holo_shapes.hpp"
#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/holomorphic/holomorphic.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::holomorphic {
namespace {

std::string tmp(const std::string& name) { return qsmesh::test::tmp_dir() + "/" + name; }

// A face of a test model with its curve meshes (uniform size, or `edges` on every closed curve),
// background triangulation and final boundary (on the same curve meshes).
struct MeshedFace {
  cad::CadModel model;
  LO face = kNoIndex;
  std::vector<mesh::CurveMesh> curves;
  mesh::FaceMesh background;
  std::vector<mesh::BoundaryLoop> loops;
  std::unique_ptr<cad::FaceGeometry> surface;
};

MeshedFace mesh_face(const std::string& path, cad::SurfaceType type, double size,
                     LO closed_edges = 0) {
  MeshedFace m{cad::load_cad(path), kNoIndex, {}, {}, {}, nullptr};
  for (LO f = 0; f < m.model.num_faces(); ++f)
    if (m.model.faces()[static_cast<std::size_t>(f)].type == type) m.face = f;
  EXPECT_NE(m.face, kNoIndex);
  background::BackgroundOptions options;
  options.sizes.size = size;
  const TaskArena tasks(1);
  m.curves = background::mesh_curves(m.model, options.sizes, tasks);
  if (closed_edges > 0)
    for (LO c = 0; c < static_cast<LO>(m.curves.size()); ++c) {
      const auto& curve = m.model.curves()[static_cast<std::size_t>(c)];
      if (curve.corners[0] == curve.corners[1] && !curve.degenerate)
        m.curves[static_cast<std::size_t>(c)] = test::uniform_curve_mesh(m.model, c, closed_edges);
    }
  background::FaceReport report;
  m.background = background::mesh_face_background(m.model, m.face, m.curves, options, &report);
  EXPECT_TRUE(report.ok) << report.error;
  m.surface = m.model.face_geometry(m.face);
  m.loops = background::face_boundary(m.model, m.face, *m.surface, m.curves);
  return m;
}

void expect_monotone(const std::vector<double>& energy) {
  ASSERT_FALSE(energy.empty());
  for (std::size_t i = 1; i < energy.size(); ++i)
    EXPECT_LT(energy[i], energy[i - 1]) << "iteration " << i;
}

// Every quad turns like the background triangles (the face normal) and none is folded.
void expect_oriented_like(const mesh::FaceMesh& quads, const mesh::FaceMesh& background) {
  Vec3 n{0, 0, 0};
  for (const auto& t : background.triangles)
    n += cross(background.points[t[1]] - background.points[t[0]],
               background.points[t[2]] - background.points[t[0]]);
  for (const auto& q : quads.quads) {
    const Vec3 qn =
        cross(quads.points[q[2]] - quads.points[q[0]], quads.points[q[3]] - quads.points[q[1]]);
    // Planar faces only: one normal.
    EXPECT_GT(dot(qn, n), 0);
  }
}

TEST(Holomorphic, AnnulusGivesARegularGridWithTheConformalModulus) {
  const double r = 1.0, R = 2.5;
  const LO N = 48;
  const MeshedFace m =
      mesh_face(test::write_annulus(r, R, tmp("annulus.brep")), cad::SurfaceType::Plane, 0.15, N);
  const PolyAnnulus s = poly_annulus(m.background);
  ASSERT_TRUE(s.ok) << s.reason;
  EXPECT_EQ(s.loops.size(), 2u);
  HolomorphicReport report;
  const mesh::FaceMesh q = mesh_annulus(m.background, m.loops, *m.surface, {}, &report);
  ASSERT_TRUE(report.ok) << report.reason;
  EXPECT_EQ(report.zeros, 0);
  EXPECT_EQ(report.columns, N);
  // The annulus is conformal to a cylinder of height log(R / r) per turn of 2 pi.
  EXPECT_EQ(report.rows, std::lround(N * std::log(R / r) / (2 * std::numbers::pi)));
  expect_monotone(report.energy);
  const auto stats = mesh::face_quad_stats(q);
  EXPECT_EQ(stats.quads, static_cast<std::int64_t>(report.rows) * N);
  EXPECT_EQ(stats.triangles, 0);
  EXPECT_EQ(stats.irregular_interior, 0);
  EXPECT_EQ(stats.irregular_boundary, 0);
  EXPECT_GT(stats.sicn_min, 0.3);
  expect_oriented_like(q, m.background);
  // Interior points are on the rings |x| = const of the grid rows (a conformal grid is radial).
  for (std::size_t v = 0; v < q.points.size(); ++v) {
    const double rho = std::hypot(q.points[v].x, q.points[v].y);
    EXPECT_GE(rho, r - 1e-9);
    EXPECT_LE(rho, R + 1e-9);
  }
}

TEST(Holomorphic, AnnulusWithDifferentLoopCountsFallsBack) {
  const MeshedFace m =
      mesh_face(test::write_annulus(1.0, 2.5, tmp("annulus2.brep")), cad::SurfaceType::Plane, 0.2);
  HolomorphicReport report;
  const mesh::FaceMesh q = mesh_annulus(m.background, m.loops, *m.surface, {}, &report);
  EXPECT_FALSE(report.ok);
  EXPECT_NE(report.reason.find("counts differ"), std::string::npos) << report.reason;
  EXPECT_TRUE(q.quads.empty());
}

// A square plate with a round hole is an annulus, but its square loop turns by 90 degrees at each
// corner, where a grid of two quads per boundary vertex would fold: it falls back.
TEST(Holomorphic, AnnulusWithSharpCornersFallsBack) {
  MeshedFace m =
      mesh_face(test::write_plate_with_holes(4, 4, {{{2.0, 2.0, 1.0}}}, tmp("square_hole.brep")),
                cad::SurfaceType::Plane, 0.2);
  for (LO c = 0; c < static_cast<LO>(m.curves.size()); ++c) {
    const auto& curve = m.model.curves()[static_cast<std::size_t>(c)];
    m.curves[static_cast<std::size_t>(c)] =
        test::uniform_curve_mesh(m.model, c, curve.corners[0] == curve.corners[1] ? 40 : 10);
  }
  m.loops = background::face_boundary(m.model, m.face, *m.surface, m.curves);
  HolomorphicReport report;
  const mesh::FaceMesh q = mesh_annulus(m.background, m.loops, *m.surface, {}, &report);
  EXPECT_FALSE(report.ok);
  EXPECT_NE(report.reason.find("turns by 90 degrees"), std::string::npos) << report.reason;
  EXPECT_TRUE(q.quads.empty());
}

TEST(Holomorphic, CylinderBetweenTwoCirclesIsAGridAlongTheSeam) {
  const MeshedFace m =
      mesh_face(test::write_cylinder(tmp("cyl.brep")), cad::SurfaceType::Cylinder, 0.4);
  const PolyAnnulus s = poly_annulus(m.background);
  ASSERT_TRUE(s.ok) << s.reason;
  EXPECT_EQ(s.loops.size(), 2u);
  HolomorphicReport report;
  const mesh::FaceMesh q = mesh_annulus(m.background, m.loops, *m.surface, {}, &report);
  ASSERT_TRUE(report.ok) << report.reason;
  expect_monotone(report.energy);
  const auto stats = mesh::face_quad_stats(q);
  EXPECT_EQ(stats.irregular_interior, 0);
  EXPECT_EQ(stats.irregular_boundary, 0);
  EXPECT_GT(stats.sicn_min, 0.3);
  // The seam (height 5) keeps its count; every grid point is on the cylinder of radius 2.
  LO seam_edges = 0;
  for (const LO c : std::vector<LO>(m.model.faces()[static_cast<std::size_t>(m.face)].seams))
    seam_edges = m.curves[static_cast<std::size_t>(c)].num_edges();
  EXPECT_EQ(report.rows, seam_edges);
  for (const auto& p : q.points) EXPECT_NEAR(std::hypot(p.x, p.y), 2.0, 1e-7);
  // Rows are horizontal circles: the four corners of a quad lie on two heights.
  for (const auto& quad : q.quads) {
    EXPECT_NEAR(q.points[quad[0]].z, q.points[quad[1]].z, 1e-3);
    EXPECT_NEAR(q.points[quad[2]].z, q.points[quad[3]].z, 1e-3);
  }
}

// Zeros of the optimised form and of the basis forms on a plate with holes: b - 2 simple zeros
// (Poincare-Hopf, paper 004 Sec. 3.3: the holomorphic double of the plate has genus b - 1).
void check_plate(const std::vector<std::array<double, 3>>& holes, const std::string& name) {
  const MeshedFace m = mesh_face(test::write_plate_with_holes(10, 6, holes, tmp(name)),
                                 cad::SurfaceType::Plane, 0.25);
  const PolyAnnulus s = poly_annulus(m.background);
  ASSERT_TRUE(s.ok) << s.reason;
  const LO b = static_cast<LO>(holes.size()) + 1;
  ASSERT_EQ(static_cast<LO>(s.loops.size()), b);
  EXPECT_EQ(s.euler, 2 - b);
  const HolomorphicBasis B = holomorphic_basis(s, {}, nullptr);
  ASSERT_EQ(B.n, b - 1);
  EXPECT_EQ(B.factorizations, 2);
  // Stokes: integral omega_m ^ df_j = +-delta_mj.
  for (LO i = 0; i < B.n; ++i)
    for (LO j = 0; j < B.n; ++j)
      EXPECT_NEAR(std::abs(B.wedge[i][j]), i == j ? 1.0 : 0.0, 0.02) << i << " " << j;
  for (LO k = 0; k < B.n; ++k) {
    const ZeroReport z = find_zeros(s, B.phi[static_cast<std::size_t>(k)]);
    EXPECT_NEAR(z.index_sum, b - 2, 1e-6) << "basis form " << k;
  }
  const EnergyResult E = minimize_area_distortion(s, B, {});
  EXPECT_TRUE(E.converged);
  expect_monotone(E.energy);
  EXPECT_LT(E.energy.back(), E.energy.front());
  const ZeroReport z = find_zeros(s, combine(B, E.lambda));
  EXPECT_EQ(static_cast<LO>(z.interior.size()), b - 2);
  for (const Zero& zero : z.interior) EXPECT_EQ(zero.order, 1);  // valence 8 in the quad mesh
  EXPECT_TRUE(z.boundary.empty());
  EXPECT_NEAR(z.index_sum, b - 2, 1e-6);
  // Critical trajectories: 2 (order + 1) = 4 horizontal and 4 vertical prongs per simple zero;
  // the boundary is horizontal, so vertical prongs end on it and horizontal ones at zeros.
  const auto traj = critical_trajectories(s, combine(B, E.lambda), z, {});
  EXPECT_EQ(static_cast<LO>(traj.size()), 8 * (b - 2));
  int vertical_on_boundary = 0, horizontal_at_zero = 0;
  for (const auto& t : traj) {
    if (!t.horizontal && t.end == Trajectory::End::Boundary) ++vertical_on_boundary;
    if (t.horizontal && t.end == Trajectory::End::Zero) ++horizontal_at_zero;
  }
  EXPECT_EQ(vertical_on_boundary, 4 * (b - 2));
  EXPECT_EQ(horizontal_at_zero, 4 * (b - 2));
  // The critical graph cuts the plate into rectangles (paper 004 Fig. 5): every hole is reached
  // by a vertical prong.
  for (LO l = 1; l < b; ++l)
    EXPECT_TRUE(std::any_of(traj.begin(), traj.end(),
                            [&](const Trajectory& t) {
                              return !t.horizontal && t.end == Trajectory::End::Boundary &&
                                     t.end_loop == l;
                            }))
        << "loop " << l;
  // b >= 3 is not an annulus: mesh_annulus refuses it (mesh_poly_annulus meshes it,
  // test_patches.cpp).
  HolomorphicReport report;
  const mesh::FaceMesh q = mesh_annulus(m.background, m.loops, *m.surface, {}, &report);
  EXPECT_FALSE(report.ok);
  EXPECT_TRUE(q.quads.empty());
  EXPECT_FALSE(report.reason.empty());
}

TEST(Holomorphic, PlateWithTwoHolesHasOneSimpleZero) {
  check_plate({{{3.0, 3.0, 1.0}}, {{7.0, 3.0, 1.2}}}, "plate2.brep");
}

TEST(Holomorphic, PlateWithThreeHolesHasTwoSimpleZeros) {
  check_plate({{{2.0, 2.0, 0.8}}, {{5.0, 4.0, 0.9}}, {{8.0, 2.5, 0.7}}}, "plate3.brep");
}

TEST(Holomorphic, BasisOnALargerPolyAnnulusHasTheRightPeriodsAndIsHarmonic) {
  std::vector<std::array<double, 3>> holes;
  for (int i = 0; i < 5; ++i)
    holes.push_back({1.5 + 1.75 * i, 3.0 + (i % 2 == 0 ? 1.0 : -1.0), 0.5});
  const MeshedFace m = mesh_face(test::write_plate_with_holes(10, 6, holes, tmp("plate5.brep")),
                                 cad::SurfaceType::Plane, 0.08);
  const PolyAnnulus s = poly_annulus(m.background);
  ASSERT_TRUE(s.ok) << s.reason;
  EXPECT_GT(s.num_vertices(), 5000);
  const HolomorphicBasis B = holomorphic_basis(s, {}, nullptr);
  EXPECT_EQ(B.factorizations, 2);
  EXPECT_EQ(B.solves, 2 * B.n);
  for (LO k = 0; k < B.n; ++k) {
    const auto& w = B.omega[static_cast<std::size_t>(k)];
    // Periods on the interior loops: delta_jk (loop j + 1).
    for (LO j = 0; j < B.n; ++j) {
      const auto& loop = s.loops[static_cast<std::size_t>(j + 1)];
      double p = 0;
      for (std::size_t i = 0; i < loop.size(); ++i) {
        const LO a = loop[i], c = loop[(i + 1) % loop.size()];
        for (LO e = 0; e < s.num_edges(); ++e)
          if (s.edges[e] == std::array<LO, 2>{std::min(a, c), std::max(a, c)})
            p += s.edges[e][0] == a ? w[e] : -w[e];
      }
      EXPECT_NEAR(p, j == k ? 1.0 : 0.0, 1e-9);
    }
    // Co-closed at every vertex (boundary included: Neumann), relative to the flux scale.
    std::vector<double> div(s.points.size(), 0.0), scale(s.points.size(), 0.0);
    for (LO e = 0; e < s.num_edges(); ++e) {
      const double flux = B.weights[e] * w[e];
      div[s.edges[e][0]] += flux;
      div[s.edges[e][1]] -= flux;
      scale[s.edges[e][0]] += std::abs(flux);
      scale[s.edges[e][1]] += std::abs(flux);
    }
    for (std::size_t v = 0; v < div.size(); ++v)
      EXPECT_LT(std::abs(div[v]), 1e-8 * (scale[v] + 1e-30));
  }
}

// Equal loop counts for the annulus grid (balance_annulus_counts): a planar annulus's two circles
// (two loops), the cylindrical hole of a box (one loop with a seam), a plate with a hole (square
// corners: left alone).
std::vector<mesh::CurveMesh> background_curves(const cad::CadModel& model, double size) {
  background::BackgroundOptions options;
  options.sizes.size = size;
  return background::mesh_curves(model, options.sizes, TaskArena(1));
}

TEST(Holomorphic, AnnulusCountsAreMadeEqualWithinTheirRoom) {
  const cad::CadModel model = cad::load_cad(test::write_annulus(1.0, 2.0, tmp("bal_ann.brep")));
  ASSERT_EQ(model.num_faces(), 1);
  ASSERT_EQ(model.num_curves(), 2);
  const auto chains = annulus_chains(model, 0);
  ASSERT_EQ(chains.size(), 2u);
  const auto curves = background_curves(model, 0.2);
  const LO outer = model.curves()[0].length > model.curves()[1].length ? 0 : 1;
  std::vector<int> edges(2);
  edges[static_cast<std::size_t>(outer)] = 40;
  edges[static_cast<std::size_t>(1 - outer)] = 32;
  const std::vector<double> ideal(edges.begin(), edges.end());
  const std::vector<LO> no_chord(2, kNoIndex);
  AnnulusCountReport report;
  const auto out = balance_annulus_counts(model, curves, edges, ideal, no_chord, {}, {}, &report);
  // The short loop raised (room: 35% of 32 = 11.2 edges).
  EXPECT_EQ(out[static_cast<std::size_t>(1 - outer)], 40);
  EXPECT_EQ(out[static_cast<std::size_t>(outer)], 40);
  EXPECT_EQ(report.annuli, 1);
  EXPECT_EQ(report.equal_before, 0);
  EXPECT_EQ(report.equal_after, 1);
  EXPECT_EQ(report.curves_changed, 1);
  // The inner circle prescribed: the outer comes down instead.
  const std::vector<LO> fixed{1 - outer};
  const auto down =
      balance_annulus_counts(model, curves, edges, ideal, no_chord, fixed, {}, &report);
  EXPECT_EQ(down[static_cast<std::size_t>(outer)], 32);
  EXPECT_EQ(down[static_cast<std::size_t>(1 - outer)], 32);
  // Loops further apart than 20% (40 against 24) are left alone, as is a face whose room does
  // not reach (the inner prescribed, the outer's room 14 < 16, with the limit lifted).
  edges[static_cast<std::size_t>(1 - outer)] = 24;
  EXPECT_EQ(balance_annulus_counts(model, curves, edges, ideal, no_chord, {}, {}, &report), edges);
  EXPECT_EQ(report.equal_after, 0);
  AnnulusCountOptions wide;
  wide.max_loop_difference = 1;
  const std::vector<double> ideal2(edges.begin(), edges.end());
  EXPECT_EQ(balance_annulus_counts(model, curves, edges, ideal2, no_chord, fixed, wide, &report),
            edges);
  const auto both = balance_annulus_counts(model, curves, edges, ideal2, no_chord, {}, wide);
  EXPECT_EQ(both[0], 32);  // inner up by 8, outer down by 8
  EXPECT_EQ(both[1], 32);
}

TEST(Holomorphic, AnnulusCountsOnACylinderSideAndNotOnASquarePlate) {
  const cad::CadModel box = cad::load_cad(test::write_box_with_hole(tmp("bal_box.brep")));
  LO side = kNoIndex;
  for (LO f = 0; f < box.num_faces(); ++f)
    if (box.faces()[static_cast<std::size_t>(f)].type == cad::SurfaceType::Cylinder) side = f;
  ASSERT_NE(side, kNoIndex);
  const auto chains = annulus_chains(box, side);
  ASSERT_EQ(chains.size(), 2u);  // the two circles, the seam's uses removed
  const auto curves = background_curves(box, 0.5);
  std::vector<int> edges(static_cast<std::size_t>(box.num_curves()), 8);
  const LO a = chains[0][0].curve, b = chains[1][0].curve;
  edges[static_cast<std::size_t>(a)] = 20;
  edges[static_cast<std::size_t>(b)] = 24;
  const std::vector<double> ideal(edges.begin(), edges.end());
  const std::vector<LO> no_chord(edges.size(), kNoIndex);
  AnnulusCountReport report;
  const auto out = balance_annulus_counts(box, curves, edges, ideal, no_chord, {}, {}, &report);
  EXPECT_EQ(out[static_cast<std::size_t>(a)], 24);  // the short loop raised
  EXPECT_EQ(out[static_cast<std::size_t>(b)], 24);
  EXPECT_EQ(report.equal_after, 1);
  // The box's faces with the hole are annuli with four 90-degree corners: not counted.
  EXPECT_EQ(report.annuli, 1);

  const cad::CadModel plate =
      cad::load_cad(test::write_plate_with_holes(8, 4, {{{4, 2, 1}}}, tmp("bal_plate.brep")));
  ASSERT_EQ(annulus_chains(plate, 0).size(), 2u);
  std::vector<int> pe(static_cast<std::size_t>(plate.num_curves()), 10);
  const std::vector<double> pi(pe.begin(), pe.end());
  const auto pout = balance_annulus_counts(plate, background_curves(plate, 0.5), pe, pi,
                                           std::vector<LO>(pe.size(), kNoIndex), {}, {}, &report);
  EXPECT_EQ(pout, pe);
  EXPECT_EQ(report.annuli, 0);
}

TEST(Holomorphic, PolicyKeepsTheHolomorphicMeshOnlyWhenItWins) {
  HolomorphicReport ok;
  ok.ok = true;
  mesh::FaceQuadStats h, d;
  h.quads = d.quads = 100;
  h.irregular_interior = 0;
  d.irregular_interior = 6;
  h.sicn_min = 0.6;
  h.sicn_avg = 0.9;
  d.sicn_min = 0.62;
  d.sicn_avg = 0.92;
  EXPECT_FALSE(keep_holomorphic(Method::Default, ok, h, d, 0.05));
  EXPECT_TRUE(keep_holomorphic(Method::Holomorphic, ok, h, d, 0.05));
  EXPECT_TRUE(keep_holomorphic(Method::Auto, ok, h, d, 0.05));
  EXPECT_FALSE(keep_holomorphic(Method::Auto, ok, h, d, 0.01));  // SICN min 0.02 lower
  d.irregular_interior = 0;
  EXPECT_FALSE(keep_holomorphic(Method::Auto, ok, h, d, 0.05));  // no fewer irregular vertices
  HolomorphicReport failed;
  EXPECT_FALSE(keep_holomorphic(Method::Holomorphic, failed, h, d, 0.05));
  EXPECT_EQ(parse_method("auto"), Method::Auto);
  EXPECT_EQ(parse_method("default"), Method::Default);
  EXPECT_THROW((void)parse_method("fast"), InputError);
}

}  // namespace
}  // namespace qsmesh::holomorphic
