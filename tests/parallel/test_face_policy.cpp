// The per-face policy of the quasi-structured stage (parallel/face_task.hpp): which of a pattern
// fill and the unstructured mesh a face keeps. Serial; no MPI, no CAD model.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/parallel/face_task.hpp"

namespace qsmesh::parallel {
namespace {

// An n x n grid of unit quads in the plane z = 0, sheared by `shear` (x += shear * y: every quad a
// parallelogram, SICN below 1 as the shear grows), classified as a face: four corners, four
// sides, the rest interior.
mesh::FaceMesh grid(int n, double shear = 0) {
  mesh::FaceMesh m;
  m.face = 0;
  const auto id = [n](int i, int j) { return static_cast<LO>(j * (n + 1) + i); };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      m.points.push_back({i + shear * j, static_cast<double>(j), 0.0});
      m.uv.push_back({static_cast<double>(i), static_cast<double>(j)});
      mesh::VertexClass c;
      const bool side_i = i == 0 || i == n, side_j = j == 0 || j == n;
      if (side_i && side_j) {
        c.dim = 0;
        c.entity = id(i, j);
      } else if (side_i || side_j) {
        c.dim = 1;
        c.entity = side_j ? (j == 0 ? 0 : 2) : (i == 0 ? 3 : 1);
        c.index = side_j ? i : j;
      } else {
        c.dim = 2;
        c.entity = 0;
      }
      m.vclass.push_back(c);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      m.quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  return m;
}

PatternFill kept_fill(double sicn_avg, std::int64_t quads) {
  PatternFill fill;
  fill.report.ok = true;
  fill.report.pattern_name = "grid";
  fill.report.sicn_min = 0.6;
  fill.report.sicn_avg = sicn_avg;
  fill.report.quads = quads;
  fill.mesh = grid(2);
  fill.seconds = 0.5;
  return fill;
}

// A face whose unstructured path gave a valid all-quad mesh.
FaceTask unstructured_face(mesh::FaceMesh m) {
  FaceTask t;
  t.unstructured.ok = true;
  t.unstructured.frontal = true;
  t.quad_mesh = std::move(m);
  return t;
}

const qstruct::PatternFaceOptions kOptions;

TEST(FacePolicy, AFillWithAGoodMeanIsTheFacesMesh) {
  FaceTask t;
  t.seconds = 1;
  take_fill(t, kept_fill(0.95, 400), kOptions);
  EXPECT_TRUE(t.quasi.by_pattern);
  EXPECT_EQ(t.quasi.pattern, "grid");
  EXPECT_EQ(t.quasi.pattern_method(), "pattern:grid");
  EXPECT_TRUE(t.quasi.refusal.empty());
  EXPECT_TRUE(t.unstructured.ok);
  EXPECT_EQ(t.unstructured.quads, 400);
  EXPECT_EQ(t.unstructured.sicn_min, 0.6);
  EXPECT_EQ(t.quad_mesh.quads.size(), 4U);
  EXPECT_TRUE(t.refused.mesh.quads.empty());
  EXPECT_DOUBLE_EQ(t.seconds, 1.5);
  EXPECT_FALSE(wants_improvement(t));  // a pattern mesh is not improved
}

TEST(FacePolicy, AKeptFillWithAPoorMeanWaitsForTheUnstructuredMesh) {
  FaceTask t;
  take_fill(t, kept_fill(0.7, 400), kOptions);  // fill_to_compare: many quads, mean <= 0.8
  EXPECT_FALSE(t.quasi.by_pattern);
  EXPECT_TRUE(t.quad_mesh.quads.empty());
  EXPECT_EQ(t.refused.mesh.quads.size(), 4U);
  EXPECT_TRUE(t.refused.kept);
  EXPECT_EQ(t.refused.pattern, "grid");
  // A small fill is not held back, whatever its mean.
  FaceTask small;
  take_fill(small, kept_fill(0.7, kOptions.small_fill_quads), kOptions);
  EXPECT_TRUE(small.quasi.by_pattern);
}

// A triangle of three quads around one interior vertex of valence 3 (the triangle pattern's
// topology): one interior irregular vertex.
mesh::FaceMesh three_quads() {
  mesh::FaceMesh m;
  m.face = 0;
  const double h = std::sqrt(3.0);
  // Corners 0-2, side midpoints 3 (0-1), 4 (1-2), 5 (2-0), centre 6.
  m.points = {{0, 0, 0},       {2, 0, 0},       {1, h, 0},    {1, 0, 0},
              {1.5, h / 2, 0}, {0.5, h / 2, 0}, {1, h / 3, 0}};
  for (const Vec3& p : m.points) m.uv.push_back({p.x, p.y});
  for (LO v = 0; v < 7; ++v) {
    mesh::VertexClass c;
    c.dim = v < 3 ? 0 : v < 6 ? 1 : 2;
    c.entity = v < 3 ? v : v < 6 ? v - 3 : 0;
    m.vclass.push_back(c);
  }
  m.quads = {{0, 3, 6, 5}, {1, 4, 6, 3}, {2, 5, 6, 4}};
  return m;
}

// A fill with a good mean but an interior irregular vertex waits for the unstructured mesh only
// when it has more of them than the face's cross field has interior singularities: the
// unstructured mesh keeps one irregular vertex per singularity, so it cannot beat such a fill on
// that count. Acute-corner singularities are no interior vertex and do not count.
TEST(FacePolicy, AFillAtItsFieldsSingularityCountIsNotMeshedBothWays) {
  PatternFill fill = kept_fill(0.95, 400);
  fill.mesh = three_quads();
  ASSERT_EQ(mesh::face_quad_stats(fill.mesh).irregular_interior, 1);
  const auto with_field = [](const std::vector<crossfield::Singularity::Where>& where) {
    FaceTask t;
    t.cross_field = std::make_unique<crossfield::FaceCrossField>();
    for (const auto w : where) {
      crossfield::Singularity s;
      s.index = 1;
      s.where = w;
      t.cross_field->singularities.push_back(s);
    }
    return t;
  };
  using Where = crossfield::Singularity::Where;
  FaceTask at_count = with_field({Where::Vertex});
  EXPECT_EQ(interior_singularities(at_count), 1);
  take_fill(at_count, PatternFill(fill), kOptions);
  EXPECT_TRUE(at_count.quasi.by_pattern);
  EXPECT_TRUE(at_count.refused.mesh.quads.empty());

  // No field, or only an acute-corner singularity: the fill has one irregular vertex too many.
  for (const bool acute : {false, true}) {
    FaceTask t = acute ? with_field({Where::AcuteCorner}) : FaceTask{};
    EXPECT_EQ(interior_singularities(t), 0);
    take_fill(t, PatternFill(fill), kOptions);
    EXPECT_FALSE(t.quasi.by_pattern);
    EXPECT_TRUE(t.refused.kept);
  }
  // --fill-comparison all: every fill with an interior irregular vertex is compared.
  qstruct::PatternFaceOptions all = kOptions;
  all.compare_above_field = false;
  FaceTask compared = with_field({Where::Vertex});
  take_fill(compared, PatternFill(fill), all);
  EXPECT_FALSE(compared.quasi.by_pattern);
  EXPECT_TRUE(compared.refused.kept);
  // A poor mean is compared whatever the field asks for.
  FaceTask poor = with_field({Where::Vertex, Where::Triangle});
  PatternFill poor_fill = fill;
  poor_fill.report.sicn_avg = 0.7;
  take_fill(poor, std::move(poor_fill), kOptions);
  EXPECT_FALSE(poor.quasi.by_pattern);
  EXPECT_TRUE(poor.refused.kept);
}

TEST(FacePolicy, ARefusedFillLeavesItsReasonAndWaitsWhenValid) {
  PatternFill fill;
  fill.report.refusal = qstruct::Refusal::Quality;
  fill.report.pattern_name = "transition";
  fill.report.refused_mesh = grid(3);
  FaceTask t;
  take_fill(t, std::move(fill), kOptions);
  EXPECT_FALSE(t.quasi.by_pattern);
  EXPECT_EQ(t.quasi.refusal, qstruct::to_string(qstruct::Refusal::Quality));
  EXPECT_EQ(t.quasi.pattern_refusal(), t.quasi.refusal);
  EXPECT_EQ(t.refused.mesh.quads.size(), 9U);
  EXPECT_FALSE(t.refused.kept);
  EXPECT_EQ(t.refused.pattern, "transition");

  PatternFill none;
  none.report.refusal = qstruct::Refusal::NoPattern;
  FaceTask u;
  take_fill(u, std::move(none), kOptions);
  EXPECT_EQ(u.quasi.refusal, qstruct::to_string(qstruct::Refusal::NoPattern));
  EXPECT_TRUE(u.refused.mesh.quads.empty());
}

TEST(FacePolicy, OnlyFillsRefusedOnTheQuadBoundGetASecondChance) {
  const std::string over_bound = qstruct::to_string(qstruct::Refusal::TooManyQuads);
  // Unstructured mesh of 9 quads, bound 4: the curve counts forced more quads than the bound, so
  // the fills of at most 9 quads are laid out.
  FaceTask t = unstructured_face(grid(3));
  t.quasi.refusal = over_bound;
  EXPECT_EQ(second_fill_bound(t, 4), std::optional<std::int64_t>(9));
  // Within the bound, or without one: the refusal stands.
  EXPECT_EQ(second_fill_bound(t, 9), std::nullopt);
  EXPECT_EQ(second_fill_bound(t, 0), std::nullopt);
  // No valid all-quad mesh: any valid fill, without a bound.
  FaceTask failed = unstructured_face(grid(3));
  failed.quasi.refusal = over_bound;
  failed.unstructured.ok = false;
  EXPECT_TRUE(no_valid_quads(failed));
  EXPECT_EQ(second_fill_bound(failed, 0), std::optional<std::int64_t>(0));
  failed.unstructured.ok = true;
  failed.quad_mesh.triangles = {{0, 1, 5}};  // triangles left
  EXPECT_EQ(second_fill_bound(failed, 100), std::optional<std::int64_t>(0));
  // Other refusals would give the same answer again; a waiting fill needs no other.
  FaceTask quality = unstructured_face(grid(3));
  quality.quasi.refusal = qstruct::to_string(qstruct::Refusal::Quality);
  EXPECT_EQ(second_fill_bound(quality, 4), std::nullopt);
  FaceTask waiting = unstructured_face(grid(3));
  waiting.quasi.refusal = over_bound;
  waiting.refused.mesh = grid(1);
  EXPECT_EQ(second_fill_bound(waiting, 4), std::nullopt);

  // The second fill waits for the comparison, refused or not.
  PatternFill second = kept_fill(0.9, 9);
  take_second_fill(t, std::move(second));
  EXPECT_EQ(t.refused.mesh.quads.size(), 4U);
  EXPECT_FALSE(t.refused.kept);
}

TEST(FacePolicy, ARefusedFillNoWorseThanTheUnstructuredMeshReplacesIt) {
  FaceTask t = unstructured_face(grid(3, 0.5));  // sheared: SICN below 1
  t.quasi.refusal = qstruct::to_string(qstruct::Refusal::Quality);
  t.refused = {grid(3), "grid", false};
  const FillComparison c = compare_refused_fill(t, 0.01, kOptions);
  EXPECT_TRUE(c.compared);
  EXPECT_TRUE(c.against_unstructured);
  EXPECT_TRUE(c.fill_taken);
  EXPECT_TRUE(t.quasi.by_pattern);
  EXPECT_TRUE(t.quasi.by_comparison);
  EXPECT_EQ(t.quasi.refusal, qstruct::to_string(qstruct::Refusal::Quality));  // why it waited
  EXPECT_EQ(t.quasi.pattern, "grid");
  EXPECT_FALSE(t.unstructured.frontal);  // the report is the fill's now
  EXPECT_TRUE(t.unstructured.ok);
  EXPECT_EQ(t.unstructured.quads, 9);
  EXPECT_NEAR(t.unstructured.sicn_min, 1.0, 1e-12);
  EXPECT_NEAR(mesh::face_quad_stats(t.quad_mesh).sicn_min, 1.0, 1e-12);
  EXPECT_TRUE(t.refused.mesh.quads.empty());
}

TEST(FacePolicy, ARefusedFillWorseThanTheUnstructuredMeshIsDropped) {
  FaceTask t = unstructured_face(grid(3));
  t.refused = {grid(3, 0.5), "grid", false};
  const FillComparison c = compare_refused_fill(t, 0.01, kOptions);
  EXPECT_TRUE(c.compared);
  EXPECT_FALSE(c.fill_taken);
  EXPECT_FALSE(t.quasi.by_pattern);
  EXPECT_NEAR(mesh::face_quad_stats(t.quad_mesh).sicn_min, 1.0, 1e-12);
  EXPECT_TRUE(t.refused.mesh.quads.empty());
  // Without a valid unstructured mesh, the same fill is taken.
  FaceTask failed = unstructured_face(grid(3));
  failed.unstructured.ok = false;
  failed.refused = {grid(3, 0.5), "grid", false};
  const FillComparison f = compare_refused_fill(failed, 0.01, kOptions);
  EXPECT_TRUE(f.fill_taken);
  EXPECT_FALSE(f.against_unstructured);
  EXPECT_TRUE(failed.quasi.by_pattern);
  EXPECT_TRUE(failed.unstructured.ok);
}

TEST(FacePolicy, AKeptFillGivesWayOnlyToAClearlyBetterUnstructuredMesh) {
  // Shear 1: parallelograms at 45 degrees, SICN about 0.71 against 1 for the unstructured grid.
  FaceTask t = unstructured_face(grid(3));
  t.refused = {grid(3, 1.0), "grid", true};
  const FillComparison c = compare_refused_fill(t, 0.01, kOptions);
  EXPECT_TRUE(c.compared && c.kept && c.against_unstructured);
  EXPECT_FALSE(c.fill_taken);
  EXPECT_FALSE(t.quasi.by_pattern);
  EXPECT_TRUE(t.quasi.gave_way);
  EXPECT_EQ(t.quasi.refusal, qstruct::to_string(qstruct::Refusal::UnstructuredBetter));
  EXPECT_NEAR(mesh::face_quad_stats(t.quad_mesh).sicn_min, 1.0, 1e-12);  // the unstructured one

  // Not clearly better (means within the margin): the kept fill stays the face's mesh, and it
  // counts as kept by the thresholds, not by the comparison.
  FaceTask close = unstructured_face(grid(3, 0.2));
  close.refused = {grid(3, 0.1), "grid", true};
  const FillComparison k = compare_refused_fill(close, 0.01, kOptions);
  EXPECT_TRUE(k.fill_taken);
  EXPECT_TRUE(close.quasi.by_pattern);
  EXPECT_FALSE(close.quasi.by_comparison);
  EXPECT_FALSE(close.quasi.gave_way);
  EXPECT_TRUE(close.quasi.refusal.empty());

  // Nothing waiting: nothing changes.
  FaceTask plain = unstructured_face(grid(2));
  const FillComparison n = compare_refused_fill(plain, 0.01, kOptions);
  EXPECT_FALSE(n.compared);
  EXPECT_FALSE(plain.quasi.by_pattern);
  EXPECT_EQ(plain.quad_mesh.quads.size(), 4U);
}

TEST(FacePolicy, OnlyValidAllQuadUnstructuredFacesAreImproved) {
  FaceTask t = unstructured_face(grid(2));
  EXPECT_TRUE(wants_improvement(t));
  t.quad_mesh.triangles = {{0, 1, 3}};
  EXPECT_FALSE(wants_improvement(t));
  FaceTask failed = unstructured_face(grid(2));
  failed.unstructured.ok = false;
  EXPECT_FALSE(wants_improvement(failed));
}

// The second pass of the improvement is kept only when it removes irregular vertices at a bounded
// price in mean SICN, per vertex and summed over the face's quads, without a poor quad.
TEST(FacePolicy, SecondPassKeptOnlyWhenItsIrregularVerticesAreCheap) {
  const auto stats = [](std::int64_t quads, std::int64_t irregular, double min, double avg) {
    mesh::FaceQuadStats s;
    s.quads = quads;
    s.irregular_interior = irregular;
    s.sicn_min = min;
    s.sicn_avg = avg;
    return s;
  };
  const double per = 0.02, sum = 12, good = 0.6, keep = 0.8;
  const mesh::FaceQuadStats first = stats(800, 8, 0.62, 0.954);
  // wing_fuselage's wing tip at size factor 0.006: 8 -> 2 for 0.954 -> 0.922 (25 over 800 quads).
  EXPECT_TRUE(second_pass_wins(first, stats(600, 2, 0.62, 0.922), per, sum, good, keep));
  // No fewer irregular vertices, or more: never, however good the mean.
  EXPECT_FALSE(second_pass_wins(first, stats(800, 8, 0.7, 0.99), per, sum, good, keep));
  EXPECT_FALSE(second_pass_wins(first, stats(800, 9, 0.7, 0.99), per, sum, good, keep));
  // Too dear per vertex in the mean: 2 fewer for 0.05.
  EXPECT_FALSE(second_pass_wins(first, stats(800, 6, 0.62, 0.904), per, sum, good, keep));
  // Cheap in the mean but dear summed over a large face: 4 fewer for 0.01 over 6000 quads (60).
  EXPECT_FALSE(second_pass_wins(stats(6000, 20, 0.7, 0.97), stats(6000, 16, 0.7, 0.96), per, sum,
                                good, keep));
  EXPECT_TRUE(second_pass_wins(stats(6000, 20, 0.7, 0.97), stats(6000, 16, 0.7, 0.963), per, sum,
                               good, keep));
  // The minimum may drop to keep_ratio x the first's (0.496 here), not below; above good_sicn
  // it may drop freely.
  EXPECT_TRUE(second_pass_wins(first, stats(600, 2, 0.5, 0.95), per, sum, good, keep));
  EXPECT_FALSE(second_pass_wins(first, stats(600, 2, 0.49, 0.95), per, sum, good, keep));
  EXPECT_TRUE(
      second_pass_wins(stats(800, 8, 0.9, 0.95), stats(800, 6, 0.61, 0.95), per, sum, good, keep));
  // Triangles where the first had none: never. Off: never.
  mesh::FaceQuadStats tri = stats(600, 2, 0.62, 0.95);
  tri.triangles = 1;
  EXPECT_FALSE(second_pass_wins(first, tri, per, sum, good, keep));
  EXPECT_FALSE(second_pass_wins(first, stats(600, 2, 0.62, 0.95), 0, sum, good, keep));
}

TEST(FacePolicy, SecondPassRunsOnlyWhereTheFirstLeftUnnecessaryIrregularVertices) {
  mesh::FaceQuadStats first;
  first.quads = 3000;
  first.irregular_interior = 5;
  // 5 irregular, 3 of them asked for by singularities: 2 unnecessary, enough at min 2, not at 3.
  EXPECT_TRUE(second_pass_applies(first, 3, false, 2, 4000));
  EXPECT_FALSE(second_pass_applies(first, 4, false, 2, 4000));
  EXPECT_FALSE(second_pass_applies(first, 3, false, 3, 4000));
  // The quad bound: the first pass's count, inclusive; 0 is no bound.
  EXPECT_TRUE(second_pass_applies(first, 0, false, 2, 3000));
  EXPECT_FALSE(second_pass_applies(first, 0, false, 2, 2999));
  EXPECT_TRUE(second_pass_applies(first, 0, false, 2, 0));
  // A first pass stopped by its time budget: never.
  EXPECT_FALSE(second_pass_applies(first, 0, true, 2, 0));
}

}  // namespace
}  // namespace qsmesh::parallel
