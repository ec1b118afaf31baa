// The byte records that ranks exchange (parallel/record.hpp): every field a report declares in
// its fields() travels, in both directions, with no MPI involved.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/parallel/face_task.hpp"
#include "qsmesh/parallel/record.hpp"
#include "qsmesh/qstruct/face_pattern.hpp"

namespace qsmesh::parallel {
namespace {

mesh::FaceMesh small_mesh(LO face) {
  mesh::FaceMesh a;
  a.face = face;
  a.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0.5}, {1, 1, 0}};
  a.uv = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
  a.vclass = {mesh::VertexClass{0, 7, kNoIndex, {0, 0}}, mesh::VertexClass{1, 2, 4, {0.25, 0}},
              mesh::VertexClass{2, 3, kNoIndex, {0, 1}}, mesh::VertexClass{2, 3, kNoIndex, {1, 1}}};
  a.triangles = {{0, 1, 2}};
  a.quads = {{0, 1, 3, 2}};
  return a;
}

// Counts the fields a record type declares (nested records counted field by field), so that a
// field added to a report without being set below fails the round trip test.
template <class R>
int count_fields(const R& r) {
  int n = 0;
  R::fields(r, [&](const char*, const auto& field) {
    using T = std::remove_cvref_t<decltype(field)>;
    if constexpr (HasFields<T>)
      n += count_fields(field);
    else
      ++n;
  });
  return n;
}

// A FaceOutput with every field away from its default.
FaceOutput full_output() {
  FaceOutput o;
  o.mesh = small_mesh(3);
  o.report.face = 3;
  o.report.ok = true;
  o.report.fell_back = true;
  o.report.error = "[background] face 3: refinement failed";
  o.report.seconds = 0.5;
  o.cross_field.ok = true;
  o.cross_field.error = "none";
  o.cross_field.directions = {{Vec3{1, 0, 0}, Vec3{0, 1, 0}}};
  o.cross_field.u_norm = {0.25};
  o.cross_field.H = {-1.5};
  o.cross_field.singularities = {crossfield::Singularity{{1, 2, 3}, -1}};
  o.cross_field.euler.chi = 1;
  o.cross_field.euler.expected = 4;
  o.cross_field.levels = 3;
  o.cross_field.factorizations = 2;
  o.cross_field.solves = 9;
  o.cross_field.stalled_levels = 2;
  o.cross_field.iterations_per_level = {5, 2, 2};
  o.cross_field.seconds = 0.125;
  o.cross_field.solver = "petsc/mumps-cholesky-mpi2";
  o.cross_field.solver_ranks = 2;
  o.cross_field.rows_per_rank = {407, 408};
  o.sizes.s = {1, 2, 3};
  o.sizes.s_min = {0.5, 2, 3};
  o.sizes.s_cf = {4};
  o.unstructured.ok = true;
  o.unstructured.fell_back = true;
  o.unstructured.frontal = true;
  o.unstructured.frontal_points = 77;
  o.unstructured.error = "[unstructured] face 3: a quad is folded";
  o.unstructured.sicn_min = -0.25;
  o.unstructured.quads = 1234;
  o.quasi.by_pattern = true;
  o.quasi.pattern = "grid";
  o.quasi.refusal = "quality";
  o.quasi.by_comparison = true;
  o.quasi.gave_way = true;
  o.quasi.by_holomorphic = true;
  o.quasi.holomorphic = "kept";
  o.quasi.by_field = true;
  o.quasi.field_method = "separatrix";
  o.quasi.field_regions = 17;
  o.quasi.field_refusal = "partition: a region has 5 corners";
  o.quasi.improvement.irregular_before = 11;
  o.quasi.improvement.irregular_after = 5;
  o.quasi.improvement.cavities = {1, 2, 3, 4};
  o.quasi.improvement.defects_before = 7;
  o.quasi.improvement.defects_after = 2;
  o.quasi.improvement.disk_replaced = 6;
  o.quasi.improvement.time_budget_hit = true;
  o.quasi.improvement.second_pass_kept = true;
  o.stats.vertices = 4;
  o.stats.quads = 1;
  o.stats.triangles = 1;
  o.stats.irregular_interior = 2;
  o.stats.irregular_boundary = 3;
  o.stats.sicn_min = 0.75;
  o.stats.sicn_avg = 0.875;
  o.seconds = 2.5;
  o.times = {0.5,  1.5,          2.5,          3.5, 4.5, 5.5,   6.5,   7.5, 8.25, 77.5, 42,
             1001, {0.25, 0.75}, {1.25, 1.75}, 9,   3,   0.125, 0.375, 4,   21,   7,    1};
  o.field_grids = {fieldmesh::RegionGrid{1, 1, {0, 1, 2, 3}}, fieldmesh::RegionGrid{2, 1, {}}};
  o.group_quad_face = {4, 5, 4};
  o.group_first = 4;
  return o;
}

TEST(Pack, EveryFieldOfAFaceOutputRoundTrips) {
  const FaceOutput a = full_output();
  // 12 parts; the counts of their fields: mesh 1 (packed whole), background report 5, cross field
  // 16, sizes 3, unstructured 7, quasi 11 + improvement 8, stats 7, seconds 1, times 22, field
  // grids 1 (a vector of records), a smooth group's quad faces 1 and first face 1.
  ASSERT_EQ(count_fields(a), 1 + 5 + 16 + 3 + 7 + 19 + 7 + 1 + 22 + 1 + 2)
      << "a field was added to a report: set it in full_output() and check it here";
  std::vector<char> buf;
  write_record(buf, a);
  write_record(buf, FaceOutput{});
  std::size_t pos = 0;
  FaceOutput b, empty;
  read_record(buf, pos, b);
  read_record(buf, pos, empty);
  EXPECT_EQ(pos, buf.size());

  EXPECT_EQ(b.mesh.face, 3);
  EXPECT_EQ(b.mesh.points, a.mesh.points);
  EXPECT_EQ(b.mesh.uv, a.mesh.uv);
  EXPECT_EQ(b.mesh.triangles, a.mesh.triangles);
  EXPECT_EQ(b.mesh.quads, a.mesh.quads);
  EXPECT_EQ(b.mesh.vclass[1].entity, 2);
  EXPECT_EQ(b.mesh.vclass[1].index, 4);
  EXPECT_EQ(b.report.face, 3);
  EXPECT_TRUE(b.report.ok);
  EXPECT_TRUE(b.report.fell_back);
  EXPECT_EQ(b.report.error, a.report.error);
  EXPECT_EQ(b.report.seconds, 0.5);
  EXPECT_TRUE(b.cross_field.ok);
  EXPECT_EQ(b.cross_field.error, "none");
  ASSERT_EQ(b.cross_field.directions.size(), 1U);
  EXPECT_EQ(b.cross_field.directions[0][1].y, 1.0);
  EXPECT_EQ(b.cross_field.u_norm, a.cross_field.u_norm);
  EXPECT_EQ(b.cross_field.solver, a.cross_field.solver);
  EXPECT_EQ(b.cross_field.solver_ranks, 2);
  EXPECT_EQ(b.cross_field.rows_per_rank, a.cross_field.rows_per_rank);
  EXPECT_EQ(b.cross_field.H, a.cross_field.H);
  ASSERT_EQ(b.cross_field.singularities.size(), 1U);
  EXPECT_EQ(b.cross_field.singularities[0].index, -1);
  EXPECT_EQ(b.cross_field.singularities[0].position.z, 3.0);
  EXPECT_EQ(b.cross_field.euler.chi, 1);
  EXPECT_EQ(b.cross_field.euler.expected, 4);
  EXPECT_EQ(b.cross_field.levels, 3);
  EXPECT_EQ(b.cross_field.factorizations, 2);
  EXPECT_EQ(b.cross_field.solves, 9);
  EXPECT_EQ(b.cross_field.stalled_levels, 2);
  EXPECT_EQ(b.cross_field.iterations_per_level, a.cross_field.iterations_per_level);
  EXPECT_EQ(b.cross_field.seconds, 0.125);
  EXPECT_EQ(b.sizes.s, a.sizes.s);
  EXPECT_EQ(b.sizes.s_min, a.sizes.s_min);
  EXPECT_EQ(b.sizes.s_cf, a.sizes.s_cf);
  EXPECT_TRUE(b.unstructured.ok);
  EXPECT_TRUE(b.unstructured.fell_back);
  EXPECT_TRUE(b.unstructured.frontal);
  EXPECT_EQ(b.unstructured.frontal_points, 77);
  EXPECT_EQ(b.unstructured.error, a.unstructured.error);
  EXPECT_EQ(b.unstructured.sicn_min, -0.25);
  EXPECT_EQ(b.unstructured.quads, 1234);
  EXPECT_TRUE(b.quasi.by_pattern);
  EXPECT_EQ(b.quasi.pattern, "grid");
  EXPECT_EQ(b.quasi.refusal, "quality");
  EXPECT_TRUE(b.quasi.by_comparison);
  EXPECT_TRUE(b.quasi.gave_way);
  EXPECT_TRUE(b.quasi.by_holomorphic);
  EXPECT_EQ(b.quasi.holomorphic, "kept");
  EXPECT_TRUE(b.quasi.by_field);
  EXPECT_EQ(b.quasi.field_method, "separatrix");
  EXPECT_EQ(b.quasi.field_regions, 17);
  EXPECT_EQ(b.quasi.field_refusal, "partition: a region has 5 corners");
  const ImprovementReport& q = b.quasi.improvement;
  EXPECT_EQ(q.irregular_before, 11);
  EXPECT_EQ(q.irregular_after, 5);
  EXPECT_EQ(q.cavities, (std::array<std::int64_t, 4>{1, 2, 3, 4}));
  EXPECT_EQ(q.defects_before, 7);
  EXPECT_EQ(q.defects_after, 2);
  EXPECT_EQ(q.disk_replaced, 6);
  EXPECT_TRUE(q.time_budget_hit);
  EXPECT_TRUE(q.second_pass_kept);
  EXPECT_EQ(b.stats.vertices, 4);
  EXPECT_EQ(b.stats.quads, 1);
  EXPECT_EQ(b.stats.triangles, 1);
  EXPECT_EQ(b.stats.irregular_interior, 2);
  EXPECT_EQ(b.stats.irregular_boundary, 3);
  EXPECT_EQ(b.stats.sicn_min, 0.75);
  EXPECT_EQ(b.stats.sicn_avg, 0.875);
  EXPECT_EQ(b.seconds, 2.5);
  EXPECT_EQ(b.times.background, 0.5);
  EXPECT_EQ(b.times.crossfield, 1.5);
  EXPECT_EQ(b.times.sizemap, 2.5);
  EXPECT_EQ(b.times.patterns, 3.5);
  EXPECT_EQ(b.times.unstructured, 4.5);
  EXPECT_EQ(b.times.improvement, 5.5);
  EXPECT_EQ(b.times.compare, 6.5);
  EXPECT_EQ(b.times.distance, 7.5);
  EXPECT_EQ(b.times.pack, 8.25);
  EXPECT_EQ(b.times.pattern_layouts, 9);
  EXPECT_EQ(b.times.pattern_batches, 3);
  EXPECT_EQ(b.times.pattern_search, 0.125);
  EXPECT_EQ(b.times.pattern_layout_seconds, 0.375);
  EXPECT_EQ(b.times.pattern_layout_batches, 4);
  EXPECT_EQ(b.times.pattern_layout_vectors, 21);
  EXPECT_EQ(b.times.pattern_layout_lend_ranks, 7);
  EXPECT_EQ(b.times.pattern_vector_lendable, 1);
  EXPECT_EQ(b.times.expected_quads, 77.5);
  EXPECT_EQ(b.times.improvement_tasks, (std::vector<double>{0.25, 0.75}));
  EXPECT_EQ(b.times.improvement_quads, 42);
  EXPECT_EQ(b.times.bytes, 1001);
  ASSERT_EQ(b.field_grids.size(), 2U);
  EXPECT_EQ(b.field_grids[0].ni, 1);
  EXPECT_EQ(b.field_grids[0].vertices, (std::vector<GO>{0, 1, 2, 3}));
  EXPECT_EQ(b.field_grids[1].ni, 2);
  EXPECT_TRUE(b.field_grids[1].vertices.empty());
  EXPECT_EQ(b.group_quad_face, (std::vector<LO>{4, 5, 4}));
  EXPECT_EQ(b.group_first, 4);

  // The record after it came back at its defaults.
  EXPECT_TRUE(empty.mesh.points.empty());
  EXPECT_FALSE(empty.report.ok);
  EXPECT_TRUE(empty.report.error.empty());
  EXPECT_FALSE(empty.quasi.by_pattern);
  EXPECT_EQ(empty.quasi.improvement.disk_replaced, 0);
  EXPECT_TRUE(empty.field_grids.empty());
  EXPECT_TRUE(empty.group_quad_face.empty());
  EXPECT_EQ(empty.group_first, kNoIndex);
}

TEST(Pack, PatternFillRoundTrips) {
  PatternFill a;
  a.report.ok = false;
  a.report.refusal = qstruct::Refusal::TooManyQuads;
  a.report.reason = "face 5: 400 quads";
  a.report.side_edges = {2, 4, 2, 4};
  a.report.pattern = 3;
  a.report.pattern_name = "transition";
  a.report.start = 1;
  a.report.reversed = true;
  a.report.chords = {1, 2};
  a.report.candidates = 6;
  a.report.lifts = 1;
  a.report.moves = 12;
  a.report.layouts = 20;
  a.report.batches = 8;
  a.report.search_seconds = 0.5;
  a.report.layout_seconds = 0.25;
  a.report.layout_batches = 3;
  a.report.layout_vectors = 17;
  a.report.lend_ranks = 5;
  a.report.vector_lendable = 1;
  a.report.sicn_min = 0.2;
  a.report.sicn_avg = 0.7;
  a.report.min_sicn = 0.3;
  a.report.quads = 400;
  a.report.refused_mesh = small_mesh(5);
  a.mesh = small_mesh(5);
  a.seconds = 0.75;
  ASSERT_EQ(count_fields(a), 25 + 1 + 1)
      << "a field was added to PatternFaceReport: set it here and check it below";
  std::vector<char> buf;
  write_record(buf, a);
  std::size_t pos = 0;
  PatternFill b;
  read_record(buf, pos, b);
  EXPECT_EQ(pos, buf.size());
  EXPECT_FALSE(b.report.ok);
  EXPECT_EQ(b.report.refusal, qstruct::Refusal::TooManyQuads);
  EXPECT_EQ(b.report.reason, a.report.reason);
  EXPECT_EQ(b.report.side_edges, a.report.side_edges);
  EXPECT_EQ(b.report.pattern, 3);
  EXPECT_EQ(b.report.pattern_name, "transition");
  EXPECT_EQ(b.report.start, 1);
  EXPECT_TRUE(b.report.reversed);
  EXPECT_EQ(b.report.chords, a.report.chords);
  EXPECT_EQ(b.report.candidates, 6);
  EXPECT_EQ(b.report.lifts, 1);
  EXPECT_EQ(b.report.moves, 12);
  EXPECT_EQ(b.report.layouts, 20);
  EXPECT_EQ(b.report.batches, 8);
  EXPECT_EQ(b.report.search_seconds, 0.5);
  EXPECT_EQ(b.report.layout_seconds, 0.25);
  EXPECT_EQ(b.report.layout_batches, 3);
  EXPECT_EQ(b.report.layout_vectors, 17);
  EXPECT_EQ(b.report.lend_ranks, 5);
  EXPECT_EQ(b.report.vector_lendable, 1);
  EXPECT_EQ(b.report.sicn_min, 0.2);
  EXPECT_EQ(b.report.sicn_avg, 0.7);
  EXPECT_EQ(b.report.min_sicn, 0.3);
  EXPECT_EQ(b.report.quads, 400);
  EXPECT_EQ(b.report.refused_mesh.quads, a.report.refused_mesh.quads);
  EXPECT_EQ(b.mesh.points, a.mesh.points);
  EXPECT_EQ(b.seconds, 0.75);
}

// A lent move layout (qstruct::MoveLayoutRequest) and its answer (MoveLayoutResult) travel as
// vectors of records, every field declared once.
TEST(Pack, MoveLayoutRequestAndResultRoundTrip) {
  qstruct::MoveLayoutRequest r;
  r.face = 7;
  r.pattern = 2;
  r.reversed = true;
  r.chords = {3, 1, 4};
  r.seq = {5, 6, 7, 0, 1, 2, 3, 4};
  r.smooth_iterations = 3;
  ASSERT_EQ(count_fields(r), 6) << "a field was added to MoveLayoutRequest: check it here";
  qstruct::MoveLayoutResult ok, failed;
  ok.mesh = small_mesh(7);
  ok.quality = {0.25, 0.75, 1, 9};
  failed.error = "the Laplace layout is not finite";
  ASSERT_EQ(count_fields(ok), 3) << "a field was added to MoveLayoutResult: check it here";
  std::vector<char> buf;
  write_record(buf, std::vector<qstruct::MoveLayoutRequest>{r, qstruct::MoveLayoutRequest{}});
  write_record(buf, std::vector<qstruct::MoveLayoutResult>{ok, failed});
  std::size_t pos = 0;
  std::vector<qstruct::MoveLayoutRequest> rs;
  std::vector<qstruct::MoveLayoutResult> results;
  read_record(buf, pos, rs);
  read_record(buf, pos, results);
  EXPECT_EQ(pos, buf.size());
  ASSERT_EQ(rs.size(), 2U);
  EXPECT_EQ(rs[0].face, 7);
  EXPECT_EQ(rs[0].pattern, 2);
  EXPECT_TRUE(rs[0].reversed);
  EXPECT_EQ(rs[0].chords, r.chords);
  EXPECT_EQ(rs[0].seq, r.seq);
  EXPECT_EQ(rs[0].smooth_iterations, 3);
  EXPECT_EQ(rs[1].face, kNoIndex);
  EXPECT_FALSE(rs[1].reversed);
  EXPECT_TRUE(rs[1].seq.empty());
  ASSERT_EQ(results.size(), 2U);
  EXPECT_EQ(results[0].mesh.points, ok.mesh.points);
  EXPECT_EQ(results[0].mesh.quads, ok.mesh.quads);
  EXPECT_EQ(results[0].mesh.vclass[1].index, 4);
  EXPECT_EQ(results[0].quality.sicn_min, 0.25);
  EXPECT_EQ(results[0].quality.sicn_avg, 0.75);
  EXPECT_EQ(results[0].quality.invalid, 1);
  EXPECT_EQ(results[0].quality.quads, 9);
  EXPECT_TRUE(results[0].error.empty());
  EXPECT_TRUE(results[1].mesh.quads.empty());
  EXPECT_EQ(results[1].error, failed.error);
  // A share cut short is an error, not a short answer.
  buf.resize(buf.size() - 3);
  pos = 0;
  read_record(buf, pos, rs);
  EXPECT_THROW(read_record(buf, pos, results), Error);
}

// record_bytes counts what write_record writes, for every kind of field: records nested in
// records, vectors of records, strings, bools, meshes, arrays, and a curve's samples (the curves
// stage's records).
TEST(Pack, RecordBytesCountsWhatIsWritten) {
  const auto written = [](const auto& v) {
    std::vector<char> buf;
    write_record(buf, v);
    return static_cast<std::int64_t>(buf.size());
  };
  const FaceOutput full = full_output();
  EXPECT_EQ(record_bytes(full), written(full));
  EXPECT_EQ(record_bytes(FaceOutput{}), written(FaceOutput{}));
  PatternFill fill;
  fill.report.reason = "a reason";
  fill.report.refused_mesh = small_mesh(2);
  EXPECT_EQ(record_bytes(fill), written(fill));
  background::CurveSamples samples;
  samples.curve = 7;
  samples.t = {0, 0.5, 1};
  samples.s = {0, 1, 2};
  samples.h = {0.25, 0.25, 0.5};
  samples.p = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  EXPECT_EQ(record_bytes(samples), written(samples));
  EXPECT_EQ(record_bytes(samples), static_cast<std::int64_t>(sizeof(LO) + 4 * 8 + 9 * 8 + 3 * 24));
  std::vector<char> buf;
  write_record(buf, samples);
  std::size_t pos = 0;
  background::CurveSamples back;
  read_record(buf, pos, back);
  EXPECT_EQ(back.curve, 7);
  EXPECT_EQ(back.t, samples.t);
  EXPECT_EQ(back.s, samples.s);
  EXPECT_EQ(back.h, samples.h);
  EXPECT_EQ(back.p, samples.p);
}

TEST(Pack, TruncatedRecordsAreErrors) {
  std::vector<char> buf;
  write_record(buf, full_output());
  write_record(buf, full_output());
  // Cut anywhere in the second record: reading it throws, the first still reads.
  for (const std::size_t cut : {std::size_t{1}, std::size_t{9}, std::size_t{100}}) {
    std::vector<char> bytes(buf.begin(), buf.end() - static_cast<std::ptrdiff_t>(cut));
    std::size_t pos = 0;
    FaceOutput o;
    read_record(bytes, pos, o);
    EXPECT_EQ(o.quasi.improvement.disk_replaced, 6);
    EXPECT_THROW(read_record(bytes, pos, o), Error) << "cut " << cut;
  }
  // A size field far beyond the buffer does not allocate it.
  std::vector<char> lying;
  put<std::int64_t>(lying, std::int64_t{1} << 60);
  std::size_t pos = 0;
  std::vector<std::string> texts;
  EXPECT_THROW(read_record(lying, pos, texts), Error);
}

}  // namespace
}  // namespace qsmesh::parallel
