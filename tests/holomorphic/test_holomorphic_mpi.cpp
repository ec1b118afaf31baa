// Run by ctest at 1, 2 and 4 ranks: with --method holomorphic the distributed pipeline gives, on
// rank 0, exactly the mesh of a serial run, and the cylinder's side (a topological annulus whose
// two circles share their counts with the disks) is the grid of its holomorphic 1-form.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <iostream>
#include <map>
#include <sstream>

#include "holo_shapes.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/mesh/validate.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "shapes.hpp"

namespace qsmesh::parallel {
namespace {

TEST(HolomorphicPipeline, CylinderSideIsAGridOnEveryRankCount) {
  const Comm comm = Comm::world();
  const std::string path =
      std::string(QSMESH_TEST_TMP_DIR) + "/holo_cyl_np" + std::to_string(comm.size()) + ".brep";
  if (comm.rank() == 0) test::write_cylinder(path);
  comm.barrier();
  const cad::CadModel model = cad::load_cad(path);
  PipelineOptions options;
  options.background.sizes.size = 0.5;
  options.sizemap.size_max = 0.5;
  options.until = Stage::QuasiStructured;
  options.face_method = holomorphic::Method::Holomorphic;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  const PipelineResult serial = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  EXPECT_EQ(dist.mesh.points, serial.mesh.points);
  EXPECT_EQ(dist.mesh.quads, serial.mesh.quads);
  EXPECT_TRUE(dist.mesh.triangles.empty());
  const auto conformity = mesh::check_conformity(dist.mesh, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
  int kept = 0;
  for (LO f = 0; f < model.num_faces(); ++f) {
    const auto& q = dist.quasi_reports[static_cast<std::size_t>(f)];
    EXPECT_EQ(q.by_holomorphic, serial.quasi_reports[static_cast<std::size_t>(f)].by_holomorphic);
    if (model.faces()[static_cast<std::size_t>(f)].type == cad::SurfaceType::Cylinder) {
      EXPECT_TRUE(q.by_holomorphic) << q.holomorphic;
      EXPECT_EQ(dist.face_stats[static_cast<std::size_t>(f)].irregular_interior, 0);
      EXPECT_EQ(dist.face_stats[static_cast<std::size_t>(f)].irregular_boundary, 0);
      EXPECT_GT(dist.face_stats[static_cast<std::size_t>(f)].sicn_min, 0.3);
    } else {
      EXPECT_FALSE(q.by_holomorphic);  // the disks have one loop
      EXPECT_NE(q.holomorphic.find("not a poly-annulus"), std::string::npos) << q.holomorphic;
    }
    kept += q.by_holomorphic ? 1 : 0;
  }
  EXPECT_EQ(kept, 1);
}

// A disk with two holes (b = 3) whose circles are prescribed 48, 24 and 24 edges (the outer
// count the sum of the holes', as the form's periods add up): its mesh is the patches' (one
// valence-8 vertex), the same at every rank count.
TEST(HolomorphicPipeline, DiskWithTwoHolesIsPatchMeshedOnEveryRankCount) {
  const Comm comm = Comm::world();
  const std::string path =
      std::string(QSMESH_TEST_TMP_DIR) + "/holo_disk2_np" + std::to_string(comm.size()) + ".brep";
  if (comm.rank() == 0)
    test::write_disk_with_holes(3.0, {{{-1.3, 0.0, 0.8}}, {{1.3, 0.0, 0.8}}}, path);
  comm.barrier();
  const cad::CadModel model = cad::load_cad(path);
  ASSERT_EQ(model.num_faces(), 1);
  PipelineOptions options;
  options.background.sizes.size = 0.2;
  options.sizemap.size_max = 0.2;
  options.until = Stage::QuasiStructured;
  options.face_method = holomorphic::Method::Holomorphic;
  for (LO c = 0; c < model.num_curves(); ++c)
    options.quantize.prescribed.emplace_back(
        c, model.curves()[static_cast<std::size_t>(c)].length > 10 ? 48 : 24);
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  const PipelineResult serial = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  EXPECT_EQ(dist.mesh.points, serial.mesh.points);
  EXPECT_EQ(dist.mesh.quads, serial.mesh.quads);
  EXPECT_TRUE(dist.mesh.triangles.empty());
  const auto conformity = mesh::check_conformity(dist.mesh, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
  const auto& q = dist.quasi_reports[0];
  EXPECT_TRUE(q.by_holomorphic) << q.holomorphic;
  EXPECT_EQ(dist.face_stats[0].irregular_interior, 1);
  EXPECT_EQ(dist.face_stats[0].irregular_boundary, 0);
  EXPECT_GT(dist.face_stats[0].sicn_min, 0.3);
}

// --smooth-groups: a filleted T-duct (two pipes and the fillet between them, three faces joined
// across G1 curves) is one group meshed as one pair of pants: one valence-8 vertex and no other
// interior irregular vertex, its quads crossing the fillet's curves, conforming with the inner
// curves crossed, the same mesh at every rank count. The ends' counts come from the form.
TEST(HolomorphicPipeline, FilletedTDuctIsOneGroupOnEveryRankCount) {
  const Comm comm = Comm::world();
  const std::string path =
      std::string(QSMESH_TEST_TMP_DIR) + "/holo_tduct_np" + std::to_string(comm.size()) + ".brep";
  if (comm.rank() == 0) test::write_t_duct(1.0, 2.5, 0.7, 4.0, 0.25, path);
  comm.barrier();
  const cad::CadModel model = cad::load_cad(path);
  ASSERT_EQ(model.num_faces(), 3);
  PipelineOptions options;
  options.background.sizes.size = 0.2;
  options.sizemap.size_max = 0.2;
  options.until = Stage::QuasiStructured;
  options.face_method = holomorphic::Method::Holomorphic;
  options.smooth_groups = true;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  const PipelineResult serial = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  EXPECT_EQ(dist.mesh.points, serial.mesh.points);
  EXPECT_EQ(dist.mesh.quads, serial.mesh.quads);
  EXPECT_EQ(dist.mesh.quad_face, serial.mesh.quad_face);
  EXPECT_TRUE(dist.mesh.triangles.empty());
  ASSERT_EQ(dist.face_group, (std::vector<LO>{0, 0, 0}));
  const auto conformity = mesh::check_conformity(dist.mesh, model, dist.face_group);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
  // Face by face, the quads crossing the fillet's curves meet quads of another face.
  EXPECT_FALSE(mesh::check_conformity(dist.mesh, model).ok());
  for (LO f = 0; f < model.num_faces(); ++f) {
    const auto& q = dist.quasi_reports[static_cast<std::size_t>(f)];
    EXPECT_TRUE(q.by_holomorphic) << q.holomorphic;
    EXPECT_EQ(q.holomorphic, "kept: group of faces 0 1 2");
  }
  std::vector<int> valence(dist.mesh.points.size(), 0);
  std::vector<int> per_face(3, 0);
  double sicn_min = 1;
  for (std::size_t k = 0; k < dist.mesh.quads.size(); ++k) {
    std::array<Vec3, 4> x{};
    for (std::size_t i = 0; i < 4; ++i) {
      const auto v = static_cast<std::size_t>(dist.mesh.quads[k][i]);
      ++valence[v];
      x[i] = dist.mesh.points[v];
    }
    sicn_min = std::min(sicn_min, mesh::quad_sicn(x));
    ++per_face[static_cast<std::size_t>(dist.mesh.quad_face[k])];
  }
  int eight = 0, other = 0, unused = 0;
  for (std::size_t v = 0; v < valence.size(); ++v) {
    if (dist.mesh.vclass[v].dim < 2) {
      unused += valence[v] == 0 ? 1 : 0;  // the inner curves' vertices
      continue;
    }
    if (valence[v] == 8)
      ++eight;
    else if (valence[v] != 4)
      ++other;
  }
  EXPECT_EQ(eight, 1);
  EXPECT_EQ(other, 0);
  // Bars only on the group's outer curves (used once by its faces' loops): the fillet's curves
  // and the seams are crossed by quads.
  std::map<LO, int> uses;
  for (const auto& f : model.faces())
    for (const auto& loop : f.loops)
      for (const auto& use : loop.uses) ++uses[use.curve];
  ASSERT_FALSE(dist.mesh.bars.empty());
  for (const LO c : dist.mesh.bar_curve) EXPECT_EQ(uses[c], 1) << "bar on curve " << c;
  EXPECT_GT(unused, 0);
  EXPECT_GT(sicn_min, 0.3);
  for (const int n : per_face) EXPECT_GT(n, 0);
  std::cout << "T-duct group: " << dist.mesh.quads.size() << " quads (" << per_face[0] << ", "
            << per_face[1] << ", " << per_face[2] << " by face), SICN min " << sicn_min << "\n";
}

}  // namespace
}  // namespace qsmesh::parallel
