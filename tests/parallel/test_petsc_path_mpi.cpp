// The mesh path solves a face's field system by PETSc when it is above the threshold
// (SolverOptions::petsc_threshold; petsc_threshold_complex for the cross field's heat systems):
// the same fields as Eigen's, and the same mesh at 1, 2 and 4 ranks.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/mesh/validate.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "shapes.hpp"

namespace qsmesh::parallel {
namespace {

TEST(PetscPath, FaceAboveTheThresholdIsSolvedByPetscAlikeOnEveryRankCount) {
  const Comm comm = Comm::world();
  const std::string path =
      std::string(QSMESH_TEST_TMP_DIR) + "/petsc_path_np" + std::to_string(comm.size()) + ".brep";
  if (comm.rank() == 0) test::write_teardrop(3.0, path);
  comm.barrier();
  const cad::CadModel model = cad::load_cad(path);

  PipelineOptions options;
  options.background.sizes.size = 0.2;  // the field system: about a thousand unknowns per level
  options.sizemap.size_max = 0.6;
  options.crossfield.solver.petsc_threshold = 300;
  options.crossfield.solver.petsc_threshold_complex = 300;
  options.cross_fields = true;
  options.until = Stage::Unstructured;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  linalg::SolverLane lane;  // one per process, as the drivers make it
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(2), log, &lane);
  if (comm.rank() != 0) return;

  // PETSc is what solves the face at this threshold.
  const auto curves = background::mesh_curves(model, options.background.sizes, TaskArena(1));
  const mesh::FaceMesh bg =
      background::mesh_face_background(model, 0, curves, options.background, nullptr);
  const crossfield::FaceCrossField cf =
      crossfield::compute_face_cross_field(bg, options.crossfield, &lane);
  EXPECT_EQ(std::string(cf.stats.solver).rfind("petsc", 0), 0u) << cf.stats.solver;
  EXPECT_GT(bg.num_vertices(), options.crossfield.solver.petsc_threshold);

  // The same mesh as one rank and one thread, both through PETSc.
  const PipelineResult one = run_pipeline(Comm::self(), model, options, TaskArena(1), log, &lane);
  ASSERT_EQ(dist.mesh.points.size(), one.mesh.points.size());
  for (std::size_t i = 0; i < one.mesh.points.size(); ++i)
    ASSERT_EQ(dist.mesh.points[i], one.mesh.points[i]) << i;
  EXPECT_EQ(dist.mesh.quads, one.mesh.quads);
  EXPECT_GT(dist.mesh.quads.size(), 50u);
  EXPECT_TRUE(dist.mesh.triangles.empty());
  const auto conformity = mesh::check_conformity(dist.mesh, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();

  // The fields equal Eigen's to 1e-8.
  const PipelineResult eigen =
      run_pipeline(Comm::self(), model, options, TaskArena(1), log, nullptr);
  ASSERT_EQ(dist.cross_fields.size(), eigen.cross_fields.size());
  for (std::size_t f = 0; f < eigen.cross_fields.size(); ++f) {
    const CrossFieldOutput& p = dist.cross_fields[f];
    const CrossFieldOutput& e = eigen.cross_fields[f];
    ASSERT_TRUE(p.ok && e.ok) << p.error << e.error;
    ASSERT_EQ(p.directions.size(), e.directions.size());
    double worst = 0;
    for (std::size_t t = 0; t < e.directions.size(); ++t)
      for (int k = 0; k < 2; ++k)
        worst = std::max(worst, norm(p.directions[t][k] - e.directions[t][k]));
    EXPECT_LT(worst, 1e-8) << "face " << f;
    ASSERT_EQ(p.H.size(), e.H.size());
    for (std::size_t t = 0; t < e.H.size(); ++t) ASSERT_NEAR(p.H[t], e.H[t], 1e-8) << t;
    EXPECT_EQ(p.singularities.size(), e.singularities.size());
  }
}

}  // namespace
}  // namespace qsmesh::parallel
