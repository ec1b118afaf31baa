// Run by ctest at 1, 2 and 4 ranks: a face improved in pieces (PipelineOptions::task_quads,
// issue 28) gives the same mesh at every rank count, and the cuts cost little quality against
// the face improved whole.
#include <gtest/gtest.h>

#include <iostream>
#include <sstream>
#include <string>

#include "qsmesh/mesh/validate.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "shapes.hpp"

namespace qsmesh::parallel {
namespace {

std::string tmp(const std::string& name) { return std::string(QSMESH_TEST_TMP_DIR) + "/" + name; }

// The model `write(path)` makes, written once by rank 0 (one file per rank count: the ctest runs
// at 1, 2 and 4 ranks may overlap) and loaded by every rank.
template <class Write>
cad::CadModel load_written_by_rank0(const Comm& comm, const std::string& name, const Write& write) {
  const std::string path = tmp(name + "_np" + std::to_string(comm.size()) + ".brep");
  if (comm.rank() == 0) write(path);
  comm.barrier();
  return cad::load_cad(path);
}

PipelineOptions plate_options(std::int64_t task_quads) {
  PipelineOptions options;
  options.background.sizes.size = 0.5;
  options.sizemap.size_max = 0.5;
  options.until = Stage::QuasiStructured;
  options.task_quads = task_quads;
  return options;
}

TEST(SubFace, PiecesGiveTheSameMeshAtEveryRankCountAndKeepTheQuality) {
  const Comm comm = Comm::world();
  const cad::CadModel model =
      load_written_by_rank0(comm, "subface_plate",
                            [](const std::string& path) { test::write_long_plate(100, 20, path); });
  ASSERT_EQ(model.num_faces(), 1);
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  constexpr std::int64_t kTaskQuads = 800;
  const PipelineResult dist =
      run_pipeline(comm, model, plate_options(kTaskQuads), TaskArena(2), log);
  if (comm.rank() != 0) return;
  const PipelineResult serial =
      run_pipeline(Comm::self(), model, plate_options(kTaskQuads), TaskArena(1), log);
  const PipelineResult whole =
      run_pipeline(Comm::self(), model, plate_options(0), TaskArena(1), log);

  // Improved, in at least 8 pieces at the first cut, one more at the second, then whole.
  ASSERT_EQ(dist.face_times.size(), 1U);
  const std::int64_t quads = dist.face_times[0].improvement_quads;
  ASSERT_GT(quads, 8 * kTaskQuads);
  const std::size_t k = static_cast<std::size_t>((quads + kTaskQuads - 1) / kTaskQuads);
  EXPECT_EQ(dist.face_times[0].improvement_tasks.size(), 2 * k + 2);
  EXPECT_TRUE(whole.face_times[0].improvement_tasks.empty());
  PipelineOptions pieces_only = plate_options(kTaskQuads);
  pieces_only.whole_pass_after_cuts = false;
  const PipelineResult no_third = run_pipeline(Comm::self(), model, pieces_only, TaskArena(1), log);
  EXPECT_EQ(no_third.face_times[0].improvement_tasks.size(), 2 * k + 1);
  std::cout << "plate without the whole pass after the cuts: interior irregular "
            << no_third.face_stats[0].irregular_interior << ", SICN avg "
            << no_third.face_stats[0].sicn_avg << "\n";

  // The same mesh at every rank count.
  EXPECT_EQ(dist.mesh.points, serial.mesh.points);
  EXPECT_EQ(dist.mesh.quads, serial.mesh.quads);
  const auto conformity = mesh::check_conformity(dist.mesh, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
  EXPECT_TRUE(dist.mesh.triangles.empty());

  // The cuts cost little: interior irregular vertices at most 1.1 times those of the face
  // improved whole (plus one: a few dozen here), SICN avg within 0.01, no folded quad. Pieces
  // much smaller than these (a few hundred quads, against cavities of up to 600) do cost
  // irregular vertices: docs/benchmarks.md, issue 28.
  const mesh::FaceQuadStats& cut = dist.face_stats[0];
  const mesh::FaceQuadStats& one = whole.face_stats[0];
  EXPECT_LE(cut.irregular_interior, 1.1 * static_cast<double>(one.irregular_interior) + 1)
      << "whole " << one.irregular_interior;
  EXPECT_GE(cut.sicn_avg, one.sicn_avg - 0.01);
  EXPECT_GT(cut.sicn_min, 0);
  std::cout << "plate: " << quads << " quads, " << k << " pieces; interior irregular "
            << cut.irregular_interior << " (whole " << one.irregular_interior << "), SICN avg "
            << cut.sicn_avg << " (whole " << one.sicn_avg << "), min " << cut.sicn_min << " (whole "
            << one.sicn_min << ")\n";
}

// A sphere: one face with a seam and two poles, cut into pieces that hold both images of seam
// vertices (the cut follows the centroids in 3D, not the parameter plane). Valid, conforming, and
// the same at every rank count.
TEST(SubFace, SeamAndPolesInPieces) {
  const Comm comm = Comm::world();
  const cad::CadModel model = load_written_by_rank0(
      comm, "subface_sphere", [](const std::string& path) { test::write_sphere(path); });
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  PipelineOptions options = plate_options(150);
  options.background.sizes.size = 0.3;
  options.sizemap.size_max = 0.3;
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  const PipelineResult serial = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  ASSERT_EQ(dist.face_times.size(), 1U);
  EXPECT_GT(dist.face_times[0].improvement_tasks.size(), 8U)
      << dist.face_times[0].improvement_quads << " quads";
  EXPECT_EQ(dist.mesh.points, serial.mesh.points);
  EXPECT_EQ(dist.mesh.quads, serial.mesh.quads);
  const auto conformity = mesh::check_conformity(dist.mesh, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
  EXPECT_GT(dist.face_stats[0].sicn_min, 0);
}

// A face's second improvement pass dealt as a task of its own, beside its first
// (PipelineOptions::second_pass_task_irregular): the same mesh as the two passes in a row, at
// every rank count. The plate coarse enough (a few thousand quads) for its second pass.
TEST(SubFace, SecondPassAsATaskGivesTheSameMesh) {
  const Comm comm = Comm::world();
  const cad::CadModel model =
      load_written_by_rank0(comm, "second_pass_plate",
                            [](const std::string& path) { test::write_long_plate(100, 20, path); });
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  PipelineOptions options = plate_options(0);
  options.background.sizes.size = 1.0;
  options.sizemap.size_max = 1.0;
  options.second_pass_task_irregular = 1;
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  options.second_pass_task_irregular = 0;
  const PipelineResult in_a_row = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  ASSERT_EQ(dist.face_times.size(), 1U);
  const std::int64_t quads = dist.face_times[0].improvement_quads;
  ASSERT_GT(quads, 0);
  ASSERT_LE(quads, options.second_pass_max_quads);
  EXPECT_EQ(dist.face_times[0].improvement_passes.size(), 2U);
  EXPECT_TRUE(in_a_row.face_times[0].improvement_passes.empty());
  EXPECT_EQ(dist.mesh.points, in_a_row.mesh.points);
  EXPECT_EQ(dist.mesh.quads, in_a_row.mesh.quads);
  // The plate keeps its second pass (1981 quads, 29 interior irregular vertices after it): the
  // choice between the two tasks is exercised, not only the drop.
  EXPECT_TRUE(dist.quasi_reports[0].improvement.second_pass_kept);
  EXPECT_TRUE(in_a_row.quasi_reports[0].improvement.second_pass_kept);
  std::cout << "plate: " << quads << " quads, interior irregular "
            << dist.face_stats[0].irregular_interior << ", second pass kept "
            << dist.quasi_reports[0].improvement.second_pass_kept << "\n";
}

}  // namespace
}  // namespace qsmesh::parallel
