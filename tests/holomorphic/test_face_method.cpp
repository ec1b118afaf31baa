#include <gtest/gtest.h>

#include "holo_shapes.hpp"
#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/parallel/face_task.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::parallel {
namespace {

// A planar annulus whose two circles have `edges` each (or the uniform size's counts when 0),
// as FaceTask after the background stage, with its final curve meshes.
struct AnnulusTask {
  cad::CadModel model;
  std::vector<mesh::CurveMesh> curves;
  FaceTask task;
};

AnnulusTask annulus_task(LO edges, const std::string& name) {
  AnnulusTask a{cad::load_cad(test::write_annulus(1.0, 2.0, test::tmp_dir() + "/" + name)), {}, {}};
  background::BackgroundOptions options;
  options.sizes.size = 0.2;
  a.curves = background::mesh_curves(a.model, options.sizes, TaskArena(1));
  if (edges > 0)
    for (LO c = 0; c < static_cast<LO>(a.curves.size()); ++c)
      a.curves[static_cast<std::size_t>(c)] = test::uniform_curve_mesh(a.model, c, edges);
  a.task.face = 0;
  mesh_background(a.task, a.model, a.curves, options);
  return a;
}

TEST(FaceMethod, HolomorphicReplacesTheDefaultMeshOfAnAnnulus) {
  AnnulusTask a = annulus_task(40, "fm_annulus.brep");
  make_holomorphic_candidate(a.task, a.model, a.curves, {});
  ASSERT_TRUE(a.task.holomorphic.ok) << a.task.holomorphic.reason;
  ASSERT_FALSE(a.task.holomorphic_mesh.quads.empty());
  // The default path left nothing valid here: any valid holomorphic mesh is taken, but not by
  // Method::Default.
  AnnulusTask b = annulus_task(40, "fm_annulus_default.brep");
  make_holomorphic_candidate(b.task, b.model, b.curves, {});
  EXPECT_FALSE(choose_face_method(b.task, holomorphic::Method::Default, 0.02));
  EXPECT_TRUE(b.task.quad_mesh.quads.empty());
  a.task.quasi.by_pattern = true;  // as if a pattern had meshed it: the form's mesh replaces it
  a.task.quasi.pattern = "grid";
  EXPECT_TRUE(choose_face_method(a.task, holomorphic::Method::Holomorphic, 0.02));
  EXPECT_FALSE(a.task.quasi.by_pattern);
  EXPECT_TRUE(a.task.quasi.pattern.empty());
  EXPECT_TRUE(a.task.quasi.by_holomorphic);
  EXPECT_EQ(a.task.quasi.holomorphic, "kept");
  EXPECT_TRUE(a.task.holomorphic_mesh.quads.empty());  // released
  EXPECT_EQ(mesh::face_quad_stats(a.task.quad_mesh).irregular_interior, 0);
}

TEST(FaceMethod, AutoKeepsAnEquallyRegularDefaultMesh) {
  AnnulusTask a = annulus_task(40, "fm_annulus_auto.brep");
  make_holomorphic_candidate(a.task, a.model, a.curves, {});
  ASSERT_TRUE(a.task.holomorphic.ok) << a.task.holomorphic.reason;
  // The default mesh: the same grid (no fewer irregular vertices to gain).
  a.task.quad_mesh = a.task.holomorphic_mesh;
  a.task.unstructured.ok = true;
  EXPECT_FALSE(choose_face_method(a.task, holomorphic::Method::Auto, 0.02));
  EXPECT_FALSE(a.task.quasi.by_holomorphic);
  EXPECT_NE(a.task.quasi.holomorphic.find("default mesh kept"), std::string::npos);
}

TEST(FaceMethod, DifferentLoopCountsFallBackWithAReason) {
  AnnulusTask a = annulus_task(0, "fm_annulus_counts.brep");  // circles of lengths 2 pi and 4 pi
  make_holomorphic_candidate(a.task, a.model, a.curves, {});
  EXPECT_FALSE(a.task.holomorphic.ok);
  EXPECT_TRUE(a.task.holomorphic_mesh.quads.empty());
  EXPECT_NE(a.task.quasi.holomorphic.find("counts differ"), std::string::npos)
      << a.task.quasi.holomorphic;
  EXPECT_FALSE(choose_face_method(a.task, holomorphic::Method::Auto, 0.02));
}

}  // namespace
}  // namespace qsmesh::parallel
