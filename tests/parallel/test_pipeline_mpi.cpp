// Run by ctest at 1, 2 and 4 ranks: the distributed pipeline must give, on rank 0, exactly the
// mesh that a serial run gives.
#include <gtest/gtest.h>
#include <mpi.h>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/mesh/assemble.hpp"
#include "qsmesh/mesh/validate.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "shapes.hpp"

#include <sstream>

namespace qsmesh::parallel {
namespace {

std::string tmp(const std::string& name) { return std::string(QSMESH_TEST_TMP_DIR) + "/" + name; }

/// Rank 0 writes the model, everybody reads it (every rank reads the CAD file itself).
cad::CadModel shared_model(const Comm& comm, const std::string& name) {
  const std::string path = tmp(name + "_np" + std::to_string(comm.size()) + ".step");
  if (comm.rank() == 0) test::write_filleted_box(path);
  comm.barrier();
  return cad::load_cad(path);
}

TEST(Comm, ReductionsAndGather) {
  const Comm comm = Comm::world();
  std::vector<std::int64_t> v{1, static_cast<std::int64_t>(comm.rank())};
  comm.allreduce_sum(v);
  EXPECT_EQ(v[0], comm.size());
  EXPECT_EQ(v[1], static_cast<std::int64_t>(comm.size()) * (comm.size() - 1) / 2);
  EXPECT_EQ(comm.allreduce_max(comm.rank()), comm.size() - 1);
  std::vector<double> m{static_cast<double>(comm.rank()), 5.0 - comm.rank()};
  comm.allreduce_min(m);
  EXPECT_EQ(m, (std::vector<double>{0.0, 5.0 - (comm.size() - 1)}));
  EXPECT_FALSE(comm.allreduce_and(comm.rank() != 0));
  const std::vector<char> mine(static_cast<std::size_t>(comm.rank()) + 1, static_cast<char>('a' + comm.rank()));
  const auto all = comm.gather_bytes(mine, 0);
  if (comm.rank() == 0) {
    ASSERT_EQ(static_cast<int>(all.size()), comm.size());
    for (int r = 0; r < comm.size(); ++r) EXPECT_EQ(all[r], std::vector<char>(r + 1, static_cast<char>('a' + r)));
  } else {
    EXPECT_TRUE(all.empty());
  }
  std::vector<char> b;
  if (comm.rank() == 0) b = {'x', 'y', 'z'};
  comm.broadcast_bytes(b, 0);
  EXPECT_EQ(b, (std::vector<char>{'x', 'y', 'z'}));
}

TEST(Pipeline, DistributedEqualsSerial) {
  const Comm comm = Comm::world();
  const cad::CadModel model = shared_model(comm, "pipe_fillet");
  PipelineOptions options;
  options.background.sizes.size = 0.6;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const TaskArena tasks(2);
  const PipelineResult result = run_pipeline(comm, model, options, tasks, log);

  // Every face is assigned to exactly one existing rank.
  ASSERT_EQ(static_cast<LO>(result.face_rank.size()), model.num_faces());
  for (int r : result.face_rank) EXPECT_TRUE(r >= 0 && r < comm.size());
  EXPECT_GT(result.times.get("background"), 0.0);

  if (comm.rank() != 0) return;
  // The serial reference: the same stage functions, no MPI, one thread.
  const TaskArena one(1);
  const auto curves = background::mesh_curves(model, options.background.sizes, one);
  std::vector<mesh::FaceMesh> faces(static_cast<std::size_t>(model.num_faces()));
  for (LO f = 0; f < model.num_faces(); ++f)
    faces[f] = background::mesh_face_background(model, f, curves, options.background, nullptr);
  const mesh::SurfaceMesh serial = mesh::assemble(model, curves, faces);

  const mesh::SurfaceMesh& dist = result.mesh;
  ASSERT_EQ(dist.points.size(), serial.points.size());
  for (std::size_t i = 0; i < serial.points.size(); ++i) ASSERT_EQ(dist.points[i], serial.points[i]) << i;
  EXPECT_EQ(dist.triangles, serial.triangles);
  EXPECT_EQ(dist.triangle_face, serial.triangle_face);
  EXPECT_EQ(dist.bars, serial.bars);
  ASSERT_EQ(static_cast<LO>(result.reports.size()), model.num_faces());
  for (const auto& r : result.reports) EXPECT_TRUE(r.ok) << r.error;
  const auto conformity = mesh::check_conformity(dist, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
}

TEST(Pipeline, CrossFieldsDoNotDependOnRanks) {
  const Comm comm = Comm::world();
  const cad::CadModel model = shared_model(comm, "pipe_cf");
  PipelineOptions options;
  options.background.sizes.size = 0.8;
  options.cross_fields = true;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult result = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  ASSERT_EQ(static_cast<LO>(result.cross_fields.size()), model.num_faces());
  const auto curves = background::mesh_curves(model, options.background.sizes, TaskArena(1));
  int consistent = 0;
  for (LO f = 0; f < model.num_faces(); ++f) {
    const auto face = background::mesh_face_background(model, f, curves, options.background, nullptr);
    const CrossFieldOutput serial = summarize(crossfield::compute_face_cross_field(face, options.crossfield, nullptr));
    const CrossFieldOutput& dist = result.cross_fields[f];
    ASSERT_TRUE(dist.ok) << dist.error;
    ASSERT_EQ(dist.directions.size(), serial.directions.size());
    for (std::size_t t = 0; t < serial.directions.size(); ++t) {
      ASSERT_EQ(dist.directions[t][0], serial.directions[t][0]);
      ASSERT_EQ(dist.directions[t][1], serial.directions[t][1]);
    }
    EXPECT_EQ(dist.H, serial.H);
    ASSERT_EQ(dist.singularities.size(), serial.singularities.size());
    for (std::size_t k = 0; k < serial.singularities.size(); ++k) {
      EXPECT_EQ(dist.singularities[k].position, serial.singularities[k].position);
      EXPECT_EQ(dist.singularities[k].index, serial.singularities[k].index);
    }
    consistent += dist.euler.consistent ? 1 : 0;
  }
  // A box with filleted edges: flat faces, cylinders and sphere corners, all simple enough for the
  // Euler relation to hold everywhere.
  EXPECT_EQ(consistent, model.num_faces());
}

}  // namespace
}  // namespace qsmesh::parallel

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  qsmesh::parallel::MpiSession mpi(&argc, &argv);
  // Only rank 0 prints the gtest report; failures on other ranks still fail the exit code.
  if (qsmesh::parallel::Comm::world().rank() != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  int failed = RUN_ALL_TESTS();
  int any = 0;
  MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return any;
}
