// Run by ctest at 1, 2 and 4 ranks: one face's move search lent to the ranks that have finished
// their own work (parallel::RankHelpers, RankLayoutHelpers; issue 28) reads the layouts the serial
// search reads and gives its fill, point for point, with fewer searches than ranks and with more;
// every rank leaves the helper loop once all are done.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/pattern_helpers.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "qsmesh/qstruct/face_pattern.hpp"
#include "shapes.hpp"

namespace qsmesh::parallel {
namespace {

using XY = std::vector<std::pair<double, double>>;

std::string tmp(const std::string& name) { return std::string(QSMESH_TEST_TMP_DIR) + "/" + name; }

using test::polygon_curves;

struct Shape {
  XY xy;
  std::vector<LO> counts;
};

TEST(PatternHelpers, SearchDealtOverRanksGivesTheSerialFill) {
  const Comm comm = Comm::world();
  // A pentagon whose transition is moved (the batched search's case) and an ellipse whose eight
  // starts are each moved, the loop shift among the vectors.
  std::vector<Shape> shapes = {
      {{{0, 0}, {4, 0}, {4, 16}, {5.456, 20}, {0, 20}}, {8, 32, 8, 12, 40}}};
  Shape ellipse;
  for (int k = 0; k < 32; ++k) {
    const double a = 2 * std::numbers::pi * k / 32;
    ellipse.xy.emplace_back(2 * std::cos(a), std::sin(a));
  }
  ellipse.counts.assign(32, 2);
  shapes.push_back(ellipse);
  const auto patterns = qstruct::builtin_patterns();
  std::int64_t lent = 0;
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    const std::string path =
        tmp("helpers_shape" + std::to_string(k) + "_np" + std::to_string(comm.size()) + ".brep");
    if (comm.rank() == 0) test::write_polygon_face(shapes[k].xy, path);
    comm.barrier();
    const cad::CadModel model = cad::load_cad(path);
    const auto curves = polygon_curves(model, shapes[k].xy, shapes[k].counts);
    qstruct::PatternFaceOptions o;
    o.move_min_layouts_per_vector = 0;
    qstruct::PatternFaceReport serial;
    const mesh::FaceMesh m0 = qstruct::mesh_face_pattern(model, 0, curves, patterns, o, &serial);
    ASSERT_GT(serial.layouts, 0) << "shape " << k << ": the test must search";
    // Fewer searches than ranks (one), and more (one more than the ranks: rank 0 runs two, the
    // second while the others are free).
    for (const int searches : {1, comm.size() + 1}) {
      RankHelpers ranks(comm);
      RankLayoutHelpers helpers(ranks, model, curves, patterns, o);
      for (int j = comm.rank(); j < searches; j += comm.size()) {
        qstruct::PatternFaceOptions oh = o;
        oh.helpers = &helpers;
        qstruct::PatternFaceReport helped;
        const mesh::FaceMesh m1 =
            qstruct::mesh_face_pattern(model, 0, curves, patterns, oh, &helped);
        EXPECT_EQ(helped.ok, serial.ok) << k;
        EXPECT_EQ(helped.chords, serial.chords) << k;
        EXPECT_EQ(helped.moves, serial.moves) << k;
        EXPECT_EQ(helped.layouts, serial.layouts) << k;
        EXPECT_EQ(helped.sicn_avg, serial.sicn_avg) << k;
        EXPECT_EQ(m1.quads, m0.quads) << k;
        ASSERT_EQ(m1.points.size(), m0.points.size()) << k;
        for (std::size_t i = 0; i < m0.points.size(); ++i)
          ASSERT_EQ(distance(m1.points[i], m0.points[i]), 0.0) << k << " point " << i;
        EXPECT_LT(helped.lend_ranks, comm.size());
      }
      helpers.serve_until_all_done();
      std::vector<std::int64_t> served{helpers.served()};
      comm.allreduce_sum(served);
      lent += served[0];
    }
  }
  // The other ranks are free from the start of the one-search case: they must have been used.
  if (comm.size() > 1) {
    EXPECT_GT(lent, 0);
  } else {
    EXPECT_EQ(lent, 0);
  }
}

// The pipeline (PipelineOptions::move_layouts_over_ranks, on by default): one face, one thread per
// rank, so every other rank is free while its search runs. The mesh is the one-rank mesh, and the
// search had helpers (the ranks wait for the pattern stage's end in the helper loop, not in the
// shared counter's collective end).
TEST(PatternHelpers, PipelineLendsTheSearchOfItsOneFace) {
  const Comm comm = Comm::world();
  const XY xy = {{0, 0}, {4, 0}, {4, 16}, {5.456, 20}, {0, 20}};
  const std::string path = tmp("helpers_pipeline_np" + std::to_string(comm.size()) + ".brep");
  if (comm.rank() == 0) test::write_polygon_face(xy, path);
  comm.barrier();
  const cad::CadModel model = cad::load_cad(path);
  PipelineOptions options;
  options.background.sizes.size = 0.4;
  options.sizemap.size_max = 0.4;
  options.until = Stage::QuasiStructured;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(1), log);
  if (comm.rank() != 0) return;
  const PipelineResult serial = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  ASSERT_EQ(dist.face_times.size(), 1U);
  const FaceTimes& t = dist.face_times[0];
  EXPECT_GT(t.pattern_layouts, 0) << "the face must be searched";
  EXPECT_EQ(t.pattern_vector_lendable, 1);
  EXPECT_EQ(t.pattern_layouts, serial.face_times[0].pattern_layouts);
  if (comm.size() > 1) {
    EXPECT_GT(t.pattern_layout_lend_ranks, 0);
  } else {
    EXPECT_EQ(t.pattern_layout_lend_ranks, 0);
  }
  EXPECT_EQ(dist.mesh.points, serial.mesh.points);
  EXPECT_EQ(dist.mesh.quads, serial.mesh.quads);
}

}  // namespace
}  // namespace qsmesh::parallel
