// Run by ctest at 1, 2 and 4 ranks: OpenCASCADE models with curves that three faces border (a T of
// three plates; a box whose top face is given twice) mesh alike on any number of ranks, the
// assembled mesh conforms, and its block-structured CGNS file passes the block reader. The coarse
// block layout (paper 002) of a box with a hole is the same on any number of ranks too.
#include <gtest/gtest.h>
#include <mpi.h>

#include <filesystem>
#include <functional>
#include <sstream>
#include <string>

#include "cgns_blocks_check.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/layout/coarse_layout.hpp"
#include "qsmesh/layout/quad_layout.hpp"
#include "qsmesh/mesh/validate.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "shapes.hpp"

namespace qsmesh::parallel {
namespace {

std::string tmp(const std::string& name) { return std::string(QSMESH_TEST_TMP_DIR) + "/" + name; }

// Curves of `model` that three or more faces border.
int non_manifold_curves(const cad::CadModel& model) {
  int n = 0;
  for (LO c = 0; c < model.num_curves(); ++c) n += model.curve2faces()[c].size() >= 3 ? 1 : 0;
  return n;
}

// Rank 0 writes the model with `write`, every rank reads it and runs the pipeline to the
// quasi-structured mesh at `size`; rank 0 runs it alone too and checks that both meshes are the
// same, conform, and give the same blocks, in a file that passes the reader.
void check_model(const std::function<void(const std::string&)>& write, const std::string& name,
                 double size, int expect_non_manifold) {
  const Comm comm = Comm::world();
  const std::string path = tmp(name + "_np" + std::to_string(comm.size()) + ".brep");
  if (comm.rank() == 0) write(path);
  comm.barrier();
  const cad::CadModel model = cad::load_cad(path);
  EXPECT_EQ(non_manifold_curves(model), expect_non_manifold);
  PipelineOptions options;
  options.background.sizes.size = size;
  options.sizemap.size_max = size;
  options.until = Stage::QuasiStructured;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  const PipelineResult serial = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  ASSERT_EQ(dist.mesh.points.size(), serial.mesh.points.size());
  for (std::size_t i = 0; i < serial.mesh.points.size(); ++i)
    ASSERT_EQ(dist.mesh.points[i], serial.mesh.points[i]) << i;
  EXPECT_EQ(dist.mesh.quads, serial.mesh.quads);
  EXPECT_EQ(dist.mesh.bars, serial.mesh.bars);
  for (const auto& q : dist.quad_reports) EXPECT_TRUE(q.ok) << q.error;
  EXPECT_TRUE(dist.mesh.triangles.empty());
  const auto conformity = mesh::check_conformity(dist.mesh, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();

  // Every output writes; the block file joins every side at the non-manifold curves.
  const std::string stem = tmp(name + "_np" + std::to_string(comm.size()));
  for (const char* ext : {".cgns", ".vtu", ".msh", ".h5"})
    EXPECT_NO_THROW(io::write_mesh(dist.mesh, stem + ext)) << ext;
  const layout::QuadLayout lay = layout::extract_quad_layout(dist.mesh);
  EXPECT_TRUE(lay.unblocked_faces.empty());
  io::write_cgns_blocks(dist.mesh, lay, stem + "_blocks.cgns");
  const test::BlockFileSummary s = test::check_block_file(stem + "_blocks.cgns");
  EXPECT_EQ(s.error, "");
  EXPECT_EQ(s.structured_zones, static_cast<int>(lay.blocks.size()));
  EXPECT_EQ(s.block_quads, static_cast<std::int64_t>(dist.mesh.quads.size()));
  // The same blocks from the serial mesh (the files are compared byte for byte across processes
  // by scripts/check_models.sh; within one process cgnslib leaves stale bytes in a name's padding).
  const layout::QuadLayout alone = layout::extract_quad_layout(serial.mesh);
  ASSERT_EQ(alone.blocks.size(), lay.blocks.size());
  for (std::size_t k = 0; k < lay.blocks.size(); ++k) {
    EXPECT_EQ(alone.blocks[k].face, lay.blocks[k].face) << k;
    EXPECT_EQ(alone.blocks[k].ni, lay.blocks[k].ni) << k;
    EXPECT_EQ(alone.blocks[k].nj, lay.blocks[k].nj) << k;
  }
  EXPECT_EQ(alone.vertices, lay.vertices);
}

TEST(NonManifold, TOfThreePlates) {
  check_model([](const std::string& p) { test::write_t_of_three_plates(p); }, "nm_t", 0.7, 1);
}

TEST(NonManifold, BoxWithItsTopGivenTwice) {
  check_model([](const std::string& p) { test::write_box_with_duplicated_face(6.0, p); }, "nm_box",
              1.0, 4);
}

// The coarse layout runs on rank 0 on the gathered mesh: the same new mesh and blocks whatever the
// number of ranks that meshed it.
TEST(CoarseLayout, SameBlocksOnAnyRanks) {
  const Comm comm = Comm::world();
  const std::string path = tmp("coarse_np" + std::to_string(comm.size()) + ".brep");
  if (comm.rank() == 0) test::write_box_with_hole(path);
  comm.barrier();
  const cad::CadModel model = cad::load_cad(path);
  PipelineOptions options;
  options.background.sizes.size = 0.35;
  options.sizemap.size_max = 0.35;
  options.until = Stage::QuasiStructured;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  const PipelineResult serial = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  const layout::CoarseResult a = layout::build_coarse_layout(dist.mesh, model);
  const layout::CoarseResult b = layout::build_coarse_layout(serial.mesh, model);
  ASSERT_TRUE(a.ok) << a.failure;
  ASSERT_TRUE(b.ok) << b.failure;
  EXPECT_EQ(a.mesh.points, b.mesh.points);
  EXPECT_EQ(a.mesh.quads, b.mesh.quads);
  ASSERT_EQ(a.layout.blocks.size(), b.layout.blocks.size());
  for (std::size_t k = 0; k < a.layout.blocks.size(); ++k) {
    EXPECT_EQ(a.layout.blocks[k].ni, b.layout.blocks[k].ni) << k;
    EXPECT_EQ(a.layout.blocks[k].nj, b.layout.blocks[k].nj) << k;
  }
  EXPECT_EQ(a.layout.vertices, b.layout.vertices);
  EXPECT_GT(a.layout.blocks.size(), 0U);
}

}  // namespace
}  // namespace qsmesh::parallel
