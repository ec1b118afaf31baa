#include <gtest/gtest.h>

#include <numbers>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/mesh/assemble.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/mesh/validate.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::background {
namespace {

std::string tmp(const std::string& name) { return qsmesh::test::tmp_dir() + "/" + name; }

struct Meshed {
  mesh::SurfaceMesh mesh;
  std::vector<FaceReport> reports;
};

Meshed mesh_model(const cad::CadModel& model, double size, int threads) {
  BackgroundOptions options;
  options.sizes.size = size;
  const TaskArena tasks(threads);
  const auto curves = mesh_curves(model, options.sizes, tasks);
  std::vector<mesh::FaceMesh> faces(static_cast<std::size_t>(model.num_faces()));
  Meshed out;
  out.reports.resize(faces.size());
  tasks.parallel_for(model.num_faces(), [&](std::int64_t f) {
    faces[f] = mesh_face_background(model, static_cast<LO>(f), curves, options, &out.reports[f]);
  });
  out.mesh = mesh::assemble(model, curves, faces);
  return out;
}

void expect_valid(const Meshed& m, const cad::CadModel& model, double tolerance) {
  for (const auto& r : m.reports) {
    EXPECT_TRUE(r.ok) << r.error;
    EXPECT_FALSE(r.fell_back) << r.error;
  }
  const auto conformity = mesh::check_conformity(m.mesh, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
  EXPECT_LT(mesh::max_distance_to_cad(m.mesh, model), tolerance);
  const auto stats = mesh::compute_stats(m.mesh);
  EXPECT_GT(stats.triangles, 0);
  // Slivers: every triangle has all angles above 10 degrees away from sharp corners.
  EXPECT_EQ(stats.min_angle_histogram[0] + stats.min_angle_histogram[1] -
                stats.small_angle_at_sharp_corner,
            0)
      << "min angle " << stats.min_angle_deg;
}

TEST(FaceMesh, BoxWithHoleIsConformingAndWellShaped) {
  const cad::CadModel model = cad::load_cad(test::write_box_with_hole(tmp("fm_box.brep")));
  const Meshed m = mesh_model(model, 0.6, 2);
  expect_valid(m, model, 1e-9 * model.diagonal());
  // Total area of the triangulation close to the CAD area (flat faces and a cylinder of 16+
  // edges/turn).
  double cad_area = 0, mesh_area = 0;
  for (const auto& f : model.faces()) cad_area += f.area;
  for (const auto& t : m.mesh.triangles)
    mesh_area += 0.5 * norm(cross(m.mesh.points[t[1]] - m.mesh.points[t[0]],
                                  m.mesh.points[t[2]] - m.mesh.points[t[0]]));
  EXPECT_NEAR(mesh_area, cad_area, 0.01 * cad_area);
}

TEST(FaceMesh, CylinderSeamIsConforming) {
  const cad::CadModel model = cad::load_cad(test::write_cylinder(tmp("fm_cyl.brep")));
  const Meshed m = mesh_model(model, 0.5, 1);
  expect_valid(m, model, 1e-9 * model.diagonal());
}

TEST(FaceMesh, SpherePolesAreSingleVertices) {
  const cad::CadModel model = cad::load_cad(test::write_sphere(tmp("fm_sphere.brep")));
  const Meshed m = mesh_model(model, 0.5, 1);
  expect_valid(m, model, 1e-9 * model.diagonal());
  // Each vertex of the sphere mesh lies on the sphere; no two vertices coincide at the poles.
  int at_poles = 0;
  for (const auto& p : m.mesh.points) {
    EXPECT_NEAR(norm(p), 3.0, 1e-9);
    if (std::abs(std::abs(p.z) - 3.0) < 1e-9) ++at_poles;
  }
  EXPECT_EQ(at_poles, 2);
}

TEST(FaceMesh, FilletedBoxFromStep) {
  const cad::CadModel model = cad::load_cad(test::write_filleted_box(tmp("fm_fillet.step")));
  const Meshed m = mesh_model(model, 0.5, 2);
  expect_valid(m, model, 1e-6 * model.diagonal());
}

TEST(FaceMesh, SameMeshWhateverTheThreads) {
  const cad::CadModel model = cad::load_cad(test::write_filleted_box(tmp("fm_fillet2.step")));
  const Meshed a = mesh_model(model, 0.7, 1);
  const Meshed b = mesh_model(model, 0.7, 2);
  ASSERT_EQ(a.mesh.points.size(), b.mesh.points.size());
  for (std::size_t i = 0; i < a.mesh.points.size(); ++i)
    ASSERT_EQ(a.mesh.points[i], b.mesh.points[i]);
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
}

TEST(FaceMesh, FinerSizeGivesMoreTriangles) {
  const cad::CadModel model = cad::load_cad(test::write_box_with_hole(tmp("fm_box2.brep")));
  const auto coarse = mesh::compute_stats(mesh_model(model, 1.0, 2).mesh);
  const auto fine = mesh::compute_stats(mesh_model(model, 0.5, 2).mesh);
  // Halving the size roughly quadruples the triangle count on flat faces (the hole is already
  // resolved by its curvature at both sizes, hence the lower bound).
  EXPECT_GT(fine.triangles, 2.5 * coarse.triangles);
  EXPECT_LT(fine.triangles, 5 * coarse.triangles);
}

}  // namespace
}  // namespace qsmesh::background
