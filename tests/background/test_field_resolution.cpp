// Backgrounds at the geometry's resolution (SizeOptions::field_divisions): bounded on large flat
// faces whatever the target size, fine where the geometry is small.
#include <gtest/gtest.h>

#include <cmath>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/cad/model.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::background {
namespace {

std::string tmp(const std::string& name) { return qsmesh::test::tmp_dir() + "/" + name; }

std::vector<mesh::FaceMesh> backgrounds(const cad::CadModel& model, double size, double divisions) {
  BackgroundOptions options;
  options.sizes.size = size;
  options.sizes.field_divisions = divisions;
  const TaskArena tasks(2);
  const auto curves = mesh_curves(model, options.sizes, tasks);
  std::vector<mesh::FaceMesh> faces;
  for (LO f = 0; f < model.num_faces(); ++f) {
    FaceReport report;
    faces.push_back(mesh_face_background(model, f, curves, options, &report));
    EXPECT_TRUE(report.ok && !report.fell_back) << report.error;
  }
  return faces;
}

double mean_edge(const mesh::FaceMesh& m) {
  double sum = 0;
  int n = 0;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      sum += distance(m.points[t[k]], m.points[t[(k + 1) % 3]]);
      ++n;
    }
  return n > 0 ? sum / n : 0.0;
}

TEST(FieldResolution, CapIsTheLargerOfTheTargetAndTheFaceOverTheDivisions) {
  SizeOptions s;
  s.size = 2;
  EXPECT_EQ(s.field_cap(1000), 2);  // no divisions: the target size
  s.field_divisions = 32;
  EXPECT_DOUBLE_EQ(s.field_cap(320), 10);
  EXPECT_DOUBLE_EQ(s.field_cap(32), 2);  // a small face keeps the target size
  const SizeOptions c = s.capped(10);
  EXPECT_DOUBLE_EQ(c.size, 10);
  EXPECT_DOUBLE_EQ(c.effective_min_size(), s.effective_min_size());  // the floor stays the target's
}

TEST(FieldResolution, LargeFlatFaceStaysBoundedAsTheTargetShrinks) {
  const cad::CadModel model = cad::load_cad(
      test::write_polygon_face({{0, 0}, {100, 0}, {100, 60}, {0, 60}}, tmp("fr_flat.brep")));
  const double h = 2.0;
  const auto coarse = backgrounds(model, h, 32);
  const auto fine = backgrounds(model, h / 16, 32);
  ASSERT_EQ(coarse.size(), 1u);
  const auto n_coarse = static_cast<double>(coarse[0].triangles.size());
  const auto n_fine = static_cast<double>(fine[0].triangles.size());
  EXPECT_GT(n_coarse, 100);
  EXPECT_LE(n_fine, 1.2 * n_coarse) << n_coarse << " -> " << n_fine << " triangles";
  EXPECT_LE(n_fine, 4000);
  // At the target's resolution the same shrink costs the square of 16.
  const auto target = backgrounds(model, h / 4, 0);
  EXPECT_GT(static_cast<double>(target[0].triangles.size()), 4 * n_fine);
}

TEST(FieldResolution, ThinStripGetsAFinerBackgroundThanItsNeighbours) {
  // A strip 0.05 wide between two 100 x 40 faces: the curves along it are 0.05 apart, a feature.
  const cad::CadModel model =
      cad::load_cad(test::write_plate_with_strip(100, 40, 0.05, tmp("fr_strip.brep")));
  ASSERT_EQ(model.num_faces(), 3);
  const auto faces = backgrounds(model, 0.5, 32);
  const auto finer_target = backgrounds(model, 0.125, 32);
  LO strip = kNoIndex;
  for (LO f = 0; f < 3; ++f)
    if (model.faces()[f].area < 10) strip = f;
  ASSERT_NE(strip, kNoIndex);
  // Across the strip the background is about as fine as the strip is wide, whatever the target.
  const double fine = mean_edge(faces[strip]);
  EXPECT_LT(fine, 0.1);
  for (LO f = 0; f < 3; ++f) {
    if (f == strip) continue;
    // The neighbours grade out from the strip's curves to their own size (diagonal / 32, about
    // 3.4): far coarser on average than the strip ...
    EXPECT_GT(mean_edge(faces[f]), 4 * fine) << "face " << f;
    // ... and set by the geometry: a target 4 times finer does not change them.
    const auto n = static_cast<double>(faces[f].triangles.size());
    EXPECT_LT(std::abs(static_cast<double>(finer_target[f].triangles.size()) - n), 0.1 * n)
        << "face " << f << ": " << n << " -> " << finer_target[f].triangles.size();
  }
}

}  // namespace
}  // namespace qsmesh::background
