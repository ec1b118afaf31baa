#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/qstruct/balance.hpp"
#include "qsmesh/qstruct/face_pattern.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::qstruct {
namespace {

using XY = std::vector<std::pair<double, double>>;

std::string tmp(const std::string& name) { return qsmesh::test::tmp_dir() + "/" + name; }

using test::polygon_curves;

struct Valences {
  std::map<int, int> interior;  // valence -> interior vertices
  std::vector<int> of;          // per vertex
};
Valences valences(const mesh::FaceMesh& m) {
  Valences v;
  v.of.assign(m.num_vertices(), 0);
  for (const auto& q : m.quads)
    for (const LO x : q) ++v.of[x];
  for (LO i = 0; i < m.num_vertices(); ++i)
    if (m.vclass[i].dim == 2) ++v.interior[v.of[i]];
  return v;
}

// Checks every property the caller relies on; returns the interior valence histogram.
Valences check_face(const cad::CadModel& model, LO f, const std::vector<mesh::CurveMesh>& curves,
                    const mesh::FaceMesh& m, const PatternFaceReport& rep) {
  EXPECT_TRUE(rep.ok) << rep.reason;
  EXPECT_EQ(rep.refusal, Refusal::None);
  EXPECT_EQ(m.face, f);
  EXPECT_TRUE(m.triangles.empty());
  EXPECT_EQ(rep.quads, static_cast<std::int64_t>(m.quads.size()));
  const auto surface = model.face_geometry(f);
  // The boundary is exactly background::face_boundary's loop.
  const auto loop = background::face_boundary(model, f, *surface, curves)[0].points;
  EXPECT_GE(m.num_vertices(), static_cast<LO>(loop.size()));
  for (std::size_t i = 0; i < loop.size() && i < m.points.size(); ++i) {
    EXPECT_EQ(m.points[i], loop[i].xyz);
    EXPECT_EQ(m.uv[i], loop[i].uv);
    EXPECT_EQ(m.vclass[i].dim, loop[i].vclass.dim);
    EXPECT_EQ(m.vclass[i].entity, loop[i].vclass.entity);
    EXPECT_EQ(m.vclass[i].index, loop[i].vclass.index);
  }
  for (LO i = static_cast<LO>(loop.size()); i < m.num_vertices(); ++i) {
    EXPECT_EQ(m.vclass[i].dim, 2);
    EXPECT_EQ(m.vclass[i].entity, f);
    EXPECT_LT(distance(surface->eval(m.uv[i]).p, m.points[i]), 1e-9 * model.diagonal());
  }
  // Valid quads, oriented along the face normal.
  for (const auto& q : m.quads) {
    const std::array<Vec3, 4> p{m.points[q[0]], m.points[q[1]], m.points[q[2]], m.points[q[3]]};
    EXPECT_GT(mesh::quad_sicn(p), 0);
    const Vec3 n = cross(p[1] - p[0], p[3] - p[0]) + cross(p[3] - p[2], p[1] - p[2]);
    const Vec2 c = (m.uv[q[0]] + m.uv[q[1]] + m.uv[q[2]] + m.uv[q[3]]) / 4.0;
    EXPECT_GT(dot(n, surface->normal(c)), 0);
  }
  EXPECT_GT(rep.sicn_min, 0);
  return valences(m);
}

struct PolygonCase {
  cad::CadModel model;
  std::vector<mesh::CurveMesh> curves;
};
PolygonCase polygon(const XY& xy, const std::vector<LO>& counts, const std::string& name) {
  PolygonCase c{cad::load_cad(test::write_polygon_face(xy, tmp(name))), {}};
  c.curves = polygon_curves(c.model, xy, counts);
  return c;
}

// A size transition's valences: interior vertices of valence 3, 4 and 5 only, n3 and n5 of the
// irregular ones, and every curve vertex of m (off the corners) in two quads.
void expect_transition_valences(const Valences& v, const mesh::FaceMesh& m, int n3, int n5) {
  EXPECT_EQ(v.interior.count(3) ? v.interior.at(3) : 0, n3);
  EXPECT_EQ(v.interior.count(5) ? v.interior.at(5) : 0, n5);
  EXPECT_EQ(v.interior.size(), 3u);
  for (LO i = 0; i < m.num_vertices(); ++i)
    if (m.vclass[i].dim == 1) {
      EXPECT_EQ(v.of[i], 2) << "curve vertex " << i;
    }
}

// The matched (balanced) chord subdivisions, not moved.
PatternFaceOptions without_moves() {
  PatternFaceOptions o;
  o.move_evaluations = 0;
  return o;
}

TEST(FacePattern, RectangleWithEqualOppositeSidesIsAGrid) {
  const XY xy = {{0, 0}, {10, 0}, {10, 4}, {0, 4}};
  const auto pc = polygon(xy, {10, 4, 10, 4}, "qs_rect.brep");
  const auto patterns = builtin_patterns();
  PatternFaceReport rep;
  const auto m = mesh_face_pattern(pc.model, 0, pc.curves, patterns, {}, &rep);
  const auto v = check_face(pc.model, 0, pc.curves, m, rep);
  EXPECT_EQ(rep.pattern_name, "grid");
  EXPECT_EQ(m.quads.size(), 40u);
  EXPECT_EQ(v.interior, (std::map<int, int>{{4, 27}}));
  std::vector<LO> sides = rep.side_edges;
  std::sort(sides.begin(), sides.end());
  EXPECT_EQ(sides, (std::vector<LO>{4, 4, 10, 10}));
  EXPECT_GT(rep.sicn_min, 0.99);
}

TEST(FacePattern, QuadCountBoundRefusesTooFineFills) {
  const XY xy = {{0, 0}, {10, 0}, {10, 4}, {0, 4}};
  const auto pc = polygon(xy, {10, 4, 10, 4}, "qs_rect_bound.brep");
  const auto patterns = builtin_patterns();
  PatternFaceOptions o;
  o.max_quads = 39;  // the grid needs 40
  PatternFaceReport rep;
  const auto refused = mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &rep);
  EXPECT_FALSE(rep.ok);
  EXPECT_EQ(rep.refusal, Refusal::TooManyQuads);
  EXPECT_NE(rep.reason.find("40"), std::string::npos) << rep.reason;
  EXPECT_TRUE(refused.quads.empty());
  o.max_quads = 40;
  const auto kept = mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &rep);
  EXPECT_TRUE(rep.ok) << rep.reason;
  EXPECT_EQ(kept.quads.size(), 40u);
}

// A w x 4 rectangle with 4 edges on every side: a 16-quad grid of (w / 4) x 1 cells, each of SICN
// `sicn`. Checks that the default options keep it and that `refusing` refuses it on quality;
// returns the report of the kept fill.
PatternFaceReport grid_kept_then_refused(double w, const std::string& name, double sicn,
                                         const PatternFaceOptions& refusing) {
  const auto pc = polygon({{0, 0}, {w, 0}, {w, 4}, {0, 4}}, {4, 4, 4, 4}, name);
  const auto patterns = builtin_patterns();
  PatternFaceReport kept;
  const auto m = mesh_face_pattern(pc.model, 0, pc.curves, patterns, {}, &kept);
  (void)check_face(pc.model, 0, pc.curves, m, kept);
  EXPECT_EQ(kept.pattern_name, "grid");
  EXPECT_EQ(m.quads.size(), 16u);
  EXPECT_NEAR(kept.sicn_min, sicn, 1e-6);
  PatternFaceReport rep;
  const auto refused = mesh_face_pattern(pc.model, 0, pc.curves, patterns, refusing, &rep);
  EXPECT_FALSE(rep.ok);
  EXPECT_EQ(rep.refusal, Refusal::Quality);
  EXPECT_TRUE(refused.quads.empty());
  return kept;
}

// Cells 2.5 x 1 have SICN 2 * 2.5 / (2.5^2 + 1) = 0.69 everywhere: below the mean threshold 0.7,
// above keep_sicn_min 0.5, so the grid is kept; without that rule it is refused on quality.
TEST(FacePattern, FillWithEveryQuadFairIsKeptWhateverItsMean) {
  PatternFaceOptions off;
  off.keep_sicn_min = 2;
  off.small_fill_quads = 0;  // 16 quads: small, kept on its minimum too
  const auto kept = grid_kept_then_refused(10, "qs_rect_fair.brep", 5.0 / 7.25, off);
  EXPECT_LT(kept.sicn_avg, PatternFaceOptions{}.min_sicn_avg);
}

// Cells 4.5 x 1: SICN 9 / 21.25 = 0.42 everywhere, above min_sicn 0.3 but below the mean
// threshold and keep_sicn_min. The 16-quad grid is small: kept on its minimum alone, and refused
// once small fills are fewer than 16 quads.
TEST(FacePattern, SmallFillIsKeptOnItsMinimumAlone) {
  PatternFaceOptions fewer;
  fewer.small_fill_quads = 15;
  const auto kept = grid_kept_then_refused(18, "qs_rect_small.brep", 9.0 / 21.25, fewer);
  EXPECT_LT(kept.sicn_min, PatternFaceOptions{}.keep_sicn_min);
}

// A kept fill of more than small_fill_quads quads with its mean at or below compare_below_avg
// (every fill kept on keep_sicn_min alone, and those kept on a mean just above min_sicn_avg) is
// compared with the face's unstructured mesh; it gives way only to a valid all-quad mesh without
// a quad at or below min_sicn whose mean is higher by more than compare_avg_margin. The numbers
// are wing_fuselage's face 15 with the clamped sizing: a one-corner fill at 0.50 / 0.678 (size
// factor 0.0058) against an unstructured mesh at 0.61 / 0.958.
TEST(FacePattern, PoorMeanFillGivesWayOnlyToAClearlyBetterUnstructuredMesh) {
  const PatternFaceOptions o;
  ASSERT_GE(o.compare_below_avg, o.min_sicn_avg);  // every fill kept on its minimum alone
  EXPECT_TRUE(fill_to_compare(0.678, 1725, 0, 0, o));
  EXPECT_TRUE(fill_to_compare(0.727, 1248, 0, 0, o));  // kept on its mean, just above
  EXPECT_FALSE(fill_to_compare(o.compare_below_avg + 0.01, 1725, 0, 0, o));  // a good mean
  EXPECT_FALSE(fill_to_compare(0.678, o.small_fill_quads, 0, 0, o));         // a small fill
  const auto stats = [](std::int64_t quads, std::int64_t triangles, double mn, double avg) {
    mesh::FaceQuadStats s;
    s.quads = quads;
    s.triangles = triangles;
    s.sicn_min = mn;
    s.sicn_avg = avg;
    return s;
  };
  const mesh::FaceQuadStats fill = stats(1725, 0, 0.50, 0.678);
  EXPECT_TRUE(unstructured_clearly_better(fill, stats(660, 0, 0.61, 0.958), o));
  // Within the margin, the fill's fewer irregular vertices win.
  EXPECT_FALSE(unstructured_clearly_better(
      fill, stats(660, 0, 0.61, 0.678 + 0.9 * o.compare_avg_margin), o));
  EXPECT_TRUE(unstructured_clearly_better(
      fill, stats(660, 0, 0.61, 0.678 + 1.1 * o.compare_avg_margin), o));
  // A better mean bought with a poor quad, or a mesh that is not all quads, does not replace it.
  EXPECT_FALSE(unstructured_clearly_better(fill, stats(660, 0, o.min_sicn, 0.958), o));
  EXPECT_FALSE(unstructured_clearly_better(fill, stats(660, 3, 0.61, 0.958), o));
  EXPECT_FALSE(unstructured_clearly_better(fill, stats(0, 0, 0, 0), o));
  PatternFaceOptions off;
  off.compare_avg_margin = -1;
  EXPECT_FALSE(fill_to_compare(0.678, 1725, 4, 0, off));
  EXPECT_FALSE(unstructured_clearly_better(fill, stats(660, 0, 0.61, 0.958), off));
}

// A kept fill with interior irregular vertices (a transition) is compared whatever its mean, and
// gives way to an unstructured mesh of the same face with fewer of them at no worse SICN min and
// mean (within the tolerance). The numbers are A319.brep's faces at its reference count: face 34,
// a 4-irregular fill at 0.853 / 0.994 against an unstructured mesh with 2 at 0.863 / 0.993; face
// 40, 4 at 0.755 / 0.921 against 4 at 0.760 / 0.973 (as many: the fill stays, its mean is not
// clearly worse); face 23, 4 at 0.315 / 0.878 against 8 at 0.730 / 0.971.
TEST(FacePattern, TransitionFillGivesWayToFewerIrregularVerticesAtNoQualityCost) {
  const PatternFaceOptions o;
  ASSERT_TRUE(o.compare_irregular);
  EXPECT_TRUE(fill_to_compare(0.994, 1535, 4, 0, o));   // a good mean, but irregular vertices
  EXPECT_FALSE(fill_to_compare(0.994, 1535, 0, 0, o));  // a grid: nothing to gain
  EXPECT_FALSE(fill_to_compare(0.994, o.small_fill_quads, 4, 0, o));  // a small fill
  // A large one: meshing it both ways would cost too much (a poor mean is still compared).
  EXPECT_TRUE(fill_to_compare(0.994, o.compare_irregular_max_quads, 4, 0, o));
  EXPECT_FALSE(fill_to_compare(0.994, o.compare_irregular_max_quads + 1, 4, 0, o));
  EXPECT_TRUE(fill_to_compare(0.7, o.compare_irregular_max_quads + 1, 4, 0, o));
  // No more irregular vertices than the field's singularities, and a mean no mesh beats by the
  // margin: nothing to gain.
  ASSERT_TRUE(o.compare_above_field);
  EXPECT_TRUE(fill_to_compare(0.994, 1535, 4, 3, o));
  EXPECT_FALSE(fill_to_compare(0.994, 1535, 4, 4, o));
  EXPECT_FALSE(fill_to_compare(0.930, 3453, 1, 1, o));  // A319 16x's pentagon face 9
  EXPECT_FALSE(fill_to_compare(1.0 - o.compare_avg_margin + 0.01, 1535, 4, 4, o));
  // Block's half disks at 0.854 gave way to unstructured means of 0.98: still compared.
  EXPECT_TRUE(fill_to_compare(1.0 - o.compare_avg_margin, 1535, 4, 4, o));
  EXPECT_TRUE(fill_to_compare(0.854, 568, 2, 2, o));
  EXPECT_TRUE(fill_to_compare(0.7, 1535, 4, 4, o));  // a poor mean always is
  PatternFaceOptions all = o;
  all.compare_above_field = false;
  EXPECT_TRUE(fill_to_compare(0.994, 1535, 4, 4, all));
  const auto stats = [](std::int64_t irregular, double mn, double avg) {
    mesh::FaceQuadStats s;
    s.quads = 500;
    s.irregular_interior = irregular;
    s.sicn_min = mn;
    s.sicn_avg = avg;
    return s;
  };
  const double tol = 0.01;
  EXPECT_FALSE(fill_wins(stats(4, 0.853, 0.994), stats(2, 0.863, 0.993), true, tol, o));  // 34
  EXPECT_TRUE(fill_wins(stats(4, 0.755, 0.921), stats(4, 0.760, 0.973), true, tol, o));   // 40
  EXPECT_TRUE(fill_wins(stats(4, 0.315, 0.878), stats(8, 0.730, 0.971), true, tol, o));   // 23
  // Fewer irregular vertices bought with a worse minimum or mean beyond the tolerance, or with
  // triangles, do not replace the fill.
  EXPECT_TRUE(fill_wins(stats(4, 0.853, 0.994), stats(2, 0.84, 0.993), true, tol, o));
  EXPECT_TRUE(fill_wins(stats(4, 0.853, 0.994), stats(2, 0.863, 0.98), true, tol, o));
  mesh::FaceQuadStats with_triangles = stats(2, 0.863, 0.993);
  with_triangles.triangles = 1;
  EXPECT_FALSE(unstructured_fewer_irregular(stats(4, 0.853, 0.994), with_triangles, tol, o));
  // --fill-comparison mean: the former rule, on the mean alone.
  PatternFaceOptions mean = o;
  mean.compare_irregular = false;
  EXPECT_FALSE(fill_to_compare(0.994, 1535, 4, 0, mean));
  EXPECT_TRUE(fill_wins(stats(4, 0.853, 0.994), stats(2, 0.863, 0.993), true, tol, mean));
}

// The choice between a fill waiting for its face's unstructured mesh and that mesh, in one place
// for both kinds of waiting fill.
TEST(FacePattern, FillWinsByItsKind) {
  const PatternFaceOptions o;
  mesh::FaceQuadStats fill, uns;
  fill.quads = 100, fill.sicn_min = 0.5, fill.sicn_avg = 0.70, fill.irregular_interior = 2;
  uns.quads = 80, uns.sicn_min = 0.6, uns.sicn_avg = 0.95, uns.irregular_interior = 6;
  // Kept by the thresholds: only a clearly better unstructured mesh replaces it.
  EXPECT_FALSE(fill_wins(fill, uns, true, 0.0, o));
  uns.sicn_avg = fill.sicn_avg + 0.5 * o.compare_avg_margin;
  EXPECT_TRUE(fill_wins(fill, uns, true, 0.0, o));
  // Refused by the thresholds: it must be no worse in min and mean (within the tolerance) and have
  // no more irregular vertices.
  uns.sicn_min = 0.5, uns.sicn_avg = 0.70;
  EXPECT_TRUE(fill_wins(fill, uns, false, 0.0, o));
  uns.sicn_avg = 0.72;
  EXPECT_FALSE(fill_wins(fill, uns, false, 0.0, o));
  EXPECT_TRUE(fill_wins(fill, uns, false, 0.03, o));
  uns.irregular_interior = 1;
  EXPECT_FALSE(fill_wins(fill, uns, false, 0.03, o));
}

TEST(FacePattern, RectangleWithATransitionGetsOneValence3And5) {
  const XY xy = {{0, 0}, {10, 0}, {10, 5}, {0, 5}};
  const auto pc = polygon(xy, {11, 4, 9, 6}, "qs_trans.brep");
  const auto patterns = builtin_patterns();
  const PatternFaceOptions balanced = without_moves();
  PatternFaceReport rep;
  const auto m = mesh_face_pattern(pc.model, 0, pc.curves, patterns, balanced, &rep);
  const auto v = check_face(pc.model, 0, pc.curves, m, rep);
  EXPECT_EQ(rep.pattern_name, "transition_1");
  expect_transition_valences(v, m, 1, 1);

  // Thresholds are honoured: nothing is that good, so the face is refused with the reason.
  PatternFaceOptions strict = balanced;
  strict.min_sicn = 0.999;
  const auto r = mesh_face_pattern(pc.model, 0, pc.curves, patterns, strict, &rep);
  EXPECT_FALSE(rep.ok);
  EXPECT_EQ(rep.refusal, Refusal::Quality);
  EXPECT_GE(rep.candidates, 1);
  EXPECT_TRUE(r.quads.empty());
  EXPECT_NE(rep.reason.find("face 0"), std::string::npos) << rep.reason;
  // ... and the refused mesh is handed back for a comparison: the same fill as the one kept above.
  EXPECT_EQ(rep.refused_mesh.quads.size(), m.quads.size());
  EXPECT_EQ(rep.quads, static_cast<std::int64_t>(m.quads.size()));
  PatternFaceReport as_kept = rep;  // check_face checks a kept mesh's report
  as_kept.ok = true;
  as_kept.refusal = Refusal::None;
  const auto refused_check = check_face(pc.model, 0, pc.curves, rep.refused_mesh, as_kept);
  EXPECT_EQ(refused_check.interior.count(3) ? refused_check.interior.at(3) : 0, 1);
  const smooth::QualityReport q = smooth::measure(rep.refused_mesh);
  EXPECT_EQ(q.invalid, 0);
  EXPECT_NEAR(q.sicn_min, rep.sicn_min, 1e-12);
}

// An 8 x 2 rectangle with sides [10, 2, 6, 2]: its short sides leave no room for two turning
// chords, and the U-turn pattern (a chord leaving the long side and coming back to it) is the one
// that fits: two valence-3 and two valence-5 vertices, nothing else irregular.
TEST(FacePattern, StripWithShortSidesGetsAUTurn) {
  const XY xy = {{0, 0}, {8, 0}, {8, 2}, {0, 2}};
  const auto pc = polygon(xy, {10, 2, 6, 2}, "qs_uturn.brep");
  const auto patterns = builtin_patterns();
  PatternFaceReport rep;
  const auto m = mesh_face_pattern(pc.model, 0, pc.curves, patterns, {}, &rep);
  const auto v = check_face(pc.model, 0, pc.curves, m, rep);
  EXPECT_EQ(rep.pattern_name, "chord_uturn");
  expect_transition_valences(v, m, 2, 2);
  EXPECT_GT(rep.sicn_min, 0.3);
}

// PatternFaceOptions::corner_sicn_factor: a quadrilateral with a 15-degree corner (the others
// 110, 115, 120), sides [20, 2, 4, 18] fitted by a transition. No quad at that corner can reach
// SICN 0.3 (sin 15 = 0.259), so the plain threshold would refuse every fill; the lowered one
// (0.9 x 0.259) keeps it.
TEST(FacePattern, SharpCornerLowersTheMinThresholdToWhatItAllows) {
  const XY xy = {{0, 0}, {10, 0}, {10.342, 0.940}, {8.898, 2.384}};
  const auto pc = polygon(xy, {20, 2, 4, 18}, "qs_sharp.brep");
  const auto patterns = builtin_patterns();
  PatternFaceReport rep;
  const auto m = mesh_face_pattern(pc.model, 0, pc.curves, patterns, {}, &rep);
  ASSERT_TRUE(rep.ok) << rep.reason;
  (void)check_face(pc.model, 0, pc.curves, m, rep);
  EXPECT_NEAR(rep.min_sicn, 0.9 * std::sin(15 * std::numbers::pi / 180), 0.01);
  EXPECT_LT(rep.sicn_min, 0.3);
  EXPECT_GT(rep.sicn_min, rep.min_sicn);
  PatternFaceOptions plain;
  plain.corner_sicn_factor = 1e9;  // never below min_sicn: the plain threshold
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, plain, &rep);
  EXPECT_FALSE(rep.ok);
  EXPECT_EQ(rep.refusal, Refusal::Quality);
  EXPECT_DOUBLE_EQ(rep.min_sicn, 0.3);
}

// PatternFaceOptions::move_evaluations: a strip 4 wide and 20 high that widens to 5.46 over its
// top fifth (the right side bends by 20 degrees at y = 16, too little to be a corner). The
// balanced chord subdivisions put the size transition halfway up, under rows of tall quads; the
// moves keep the pattern, its irregular vertices and the side counts, and raise the mean SICN.
PolygonCase flared_strip(const std::string& name) {
  return polygon({{0, 0}, {4, 0}, {4, 16}, {5.456, 20}, {0, 20}}, {8, 32, 8, 12, 40}, name);
}

TEST(FacePattern, MovesOfTheIrregularVerticesRaiseTheMeanSicn) {
  const auto pc = flared_strip("qs_flare.brep");
  const auto patterns = builtin_patterns();
  const PatternFaceOptions fixed = without_moves();
  PatternFaceReport before;
  const auto m0 = mesh_face_pattern(pc.model, 0, pc.curves, patterns, fixed, &before);
  ASSERT_TRUE(before.ok) << before.reason;
  EXPECT_EQ(before.moves, 0);
  PatternFaceReport after;
  const auto m1 = mesh_face_pattern(pc.model, 0, pc.curves, patterns, {}, &after);
  ASSERT_TRUE(after.ok) << after.reason;
  const auto v0 = check_face(pc.model, 0, pc.curves, m0, before);
  const auto v1 = check_face(pc.model, 0, pc.curves, m1, after);
  EXPECT_EQ(after.pattern_name, before.pattern_name);
  EXPECT_EQ(after.side_edges, before.side_edges);
  // The same irregular vertices; only the number of regular ones may change.
  auto irregular0 = v0.interior, irregular1 = v1.interior;
  irregular0.erase(4);
  irregular1.erase(4);
  EXPECT_EQ(irregular1, irregular0);
  EXPECT_FALSE(irregular1.empty());
  EXPECT_NE(after.chords, before.chords);
  EXPECT_GT(after.moves, 0);
  EXPECT_GT(after.sicn_avg, before.sicn_avg + 0.01);
  EXPECT_GT(after.sicn_min, after.min_sicn);
}

// PatternFaceOptions::tasks: the move search's layouts made in batches, one task each, read by the
// serial rules: the same fill, point for point, the same moves, layouts and batches; on one thread
// or on four, and with the layouts cut short inside the search. Without corner (an ellipse, whose
// starts are each moved, the loop shift among the vectors) as well.
TEST(FacePattern, MoveSearchInBatchesGivesTheSameFill) {
  const auto patterns = builtin_patterns();
  const TaskArena one(1), four(4);
  std::vector<std::pair<std::vector<std::pair<double, double>>, std::vector<LO>>> shapes = {
      {{{0, 0}, {4, 0}, {4, 16}, {5.456, 20}, {0, 20}}, {8, 32, 8, 12, 40}}};
  std::vector<std::pair<double, double>> ellipse;
  for (int k = 0; k < 32; ++k) {
    const double a = 2 * std::numbers::pi * k / 32;
    ellipse.emplace_back(2 * std::cos(a), std::sin(a));
  }
  shapes.emplace_back(ellipse, std::vector<LO>(32, 2));
  int searched = 0;
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    const auto pc =
        polygon(shapes[k].first, shapes[k].second, "qs_batches" + std::to_string(k) + ".brep");
    for (const int evaluations : {40, 7}) {
      PatternFaceOptions o;
      o.move_evaluations = evaluations;  // 7: the search cut short inside its steps
      o.move_min_layouts_per_vector = 0;
      PatternFaceReport serial;
      const auto m0 = mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &serial);
      for (const TaskArena* arena : {&one, &four}) {
        o.tasks = arena;
        PatternFaceReport batched;
        const auto m1 = mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &batched);
        EXPECT_EQ(batched.ok, serial.ok) << k;
        EXPECT_EQ(batched.chords, serial.chords) << k;
        EXPECT_EQ(batched.moves, serial.moves) << k;
        EXPECT_EQ(batched.layouts, serial.layouts) << k;
        EXPECT_EQ(batched.batches, serial.batches) << k;
        EXPECT_EQ(batched.sicn_avg, serial.sicn_avg) << k;
        EXPECT_EQ(m1.quads, m0.quads) << k;
        ASSERT_EQ(m1.points.size(), m0.points.size()) << k;
        for (std::size_t i = 0; i < m0.points.size(); ++i)
          ASSERT_EQ(distance(m1.points[i], m0.points[i]), 0.0) << k << " point " << i;
      }
      o.tasks = nullptr;
      std::cout << "case " << k << ", " << evaluations
                << " layouts at most: " << serial.pattern_name << ", " << serial.layouts
                << " layouts in " << serial.batches << " batches, " << serial.moves << " moves\n";
      if (serial.layouts > 0) ++searched;
      // A batch holds one or more layouts the rules read.
      EXPECT_LE(serial.batches, serial.layouts);
      EXPECT_GE(serial.search_seconds, 0.0);
    }
  }
  EXPECT_EQ(searched, 4);  // the test must exercise searches
}

// PatternFaceOptions::helpers: a fake set of helpers in this process, laying out each lent
// layout with lay_out_move on sides of its own (as a helper rank does) and offering `free_now`
// workers per claim. The search planned over them must read the same layouts in the same order:
// the same fill point for point, the same moves, layouts and (single-step) batches; with helpers,
// fewer lent batches than batches along the search's path.
namespace {
class FakeHelpers final : public MoveLayoutHelpers {
 public:
  FakeHelpers(const cad::CadModel& model, std::span<const mesh::CurveMesh> curves,
              std::span<const Pattern> patterns, const PatternFaceOptions& options, int free_now)
      : model_(model), curves_(curves), patterns_(patterns), options_(options), free_(free_now) {}
  int claim(int wanted) override {
    claimed_ = std::min(wanted, free_);
    return claimed_;
  }
  std::vector<MoveLayoutResult> lay_out(
      const std::vector<MoveLayoutRequest>& requests,
      const std::function<MoveLayoutResult(const MoveLayoutRequest&)>& here) override {
    const std::size_t workers = static_cast<std::size_t>(claimed_) + 1;
    claimed_ = 0;
    std::vector<MoveLayoutResult> out(requests.size());
    for (std::size_t u = 0; u < requests.size(); ++u) {
      if (u % workers == 0) {
        out[u] = here(requests[u]);
        continue;
      }
      const auto surface = model_.face_geometry(requests[u].face);
      const FaceSides fs = face_sides(model_, requests[u].face, *surface, curves_, options_);
      out[u] = lay_out_move(model_, fs, patterns_, options_.smooth, requests[u]);
      ++lent;
    }
    ++calls;
    return out;
  }
  int lent = 0, calls = 0;

 private:
  const cad::CadModel& model_;
  std::span<const mesh::CurveMesh> curves_;
  std::span<const Pattern> patterns_;
  const PatternFaceOptions& options_;
  int free_ = 0, claimed_ = 0;
};
}  // namespace

TEST(FacePattern, MoveSearchWithHelpersGivesTheSameFill) {
  const auto patterns = builtin_patterns();
  std::vector<std::pair<std::vector<std::pair<double, double>>, std::vector<LO>>> shapes = {
      {{{0, 0}, {4, 0}, {4, 16}, {5.456, 20}, {0, 20}}, {8, 32, 8, 12, 40}}};
  std::vector<std::pair<double, double>> ellipse;
  for (int k = 0; k < 32; ++k) {
    const double a = 2 * std::numbers::pi * k / 32;
    ellipse.emplace_back(2 * std::cos(a), std::sin(a));
  }
  shapes.emplace_back(ellipse, std::vector<LO>(32, 2));
  int lent = 0;
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    const auto pc =
        polygon(shapes[k].first, shapes[k].second, "qs_helpers" + std::to_string(k) + ".brep");
    for (const int evaluations : {40, 7}) {
      PatternFaceOptions o;
      o.move_evaluations = evaluations;  // 7: the search cut short inside its steps
      o.move_min_layouts_per_vector = 0;
      PatternFaceReport serial;
      const auto m0 = mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &serial);
      EXPECT_EQ(serial.lend_ranks, 0);
      for (const int free_now : {0, 1, 3, 31}) {
        FakeHelpers helpers(pc.model, pc.curves, patterns, o, free_now);
        PatternFaceOptions oh = o;
        oh.helpers = &helpers;
        PatternFaceReport helped;
        const auto m1 = mesh_face_pattern(pc.model, 0, pc.curves, patterns, oh, &helped);
        EXPECT_EQ(helped.ok, serial.ok) << k;
        EXPECT_EQ(helped.chords, serial.chords) << k;
        EXPECT_EQ(helped.moves, serial.moves) << k;
        EXPECT_EQ(helped.layouts, serial.layouts) << k;
        EXPECT_EQ(helped.batches, serial.batches) << k;
        EXPECT_EQ(helped.sicn_avg, serial.sicn_avg) << k;
        EXPECT_EQ(m1.quads, m0.quads) << k;
        ASSERT_EQ(m1.points.size(), m0.points.size()) << k;
        for (std::size_t i = 0; i < m0.points.size(); ++i)
          ASSERT_EQ(distance(m1.points[i], m0.points[i]), 0.0) << k << " point " << i;
        EXPECT_LE(helped.lend_ranks, free_now);
        if (free_now == 0) {
          EXPECT_EQ(helpers.lent, 0);
        }
        if (free_now == 31 && serial.layouts > 0) {
          // Planned as deep as the counting of a run without helpers: the same lent batches.
          EXPECT_EQ(helped.layout_batches, serial.layout_batches) << k;
          EXPECT_GT(helpers.lent, 0) << k;
          lent += helpers.lent;
        }
      }
      std::cout << "case " << k << ", " << evaluations << " layouts at most: " << serial.layouts
                << " layouts read in " << serial.batches << " batches, " << serial.layout_batches
                << " lent batches planning " << serial.layout_vectors << " layouts\n";
      EXPECT_EQ(serial.vector_lendable, serial.layouts > 0 ? 1 : serial.vector_lendable);
      // Several levels per lent batch: never more lent batches than single steps.
      EXPECT_LE(serial.layout_batches, serial.batches) << k;
      if (evaluations == 40 && serial.batches > 2) {
        EXPECT_LT(serial.layout_batches, serial.batches);
      }
      EXPECT_GE(serial.layout_vectors, serial.layouts > 0 ? serial.layout_batches : 0);
    }
  }
  EXPECT_GT(lent, 0);  // the test must lend layouts
}

// ... and a fill whose balanced subdivisions need more quads than max_quads may still fit the
// bound once moved: the same strip with the bound one quad below the balanced fill's count.
TEST(FacePattern, MovedFillsMayFitTheQuadBound) {
  const auto pc = flared_strip("qs_flare_bound.brep");
  const auto patterns = builtin_patterns();
  PatternFaceOptions fixed = without_moves();
  PatternFaceReport rep;
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, fixed, &rep);
  ASSERT_TRUE(rep.ok) << rep.reason;
  const std::int64_t balanced = rep.quads;
  fixed.max_quads = balanced - 1;
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, fixed, &rep);
  EXPECT_FALSE(rep.ok);
  EXPECT_EQ(rep.refusal, Refusal::TooManyQuads);
  PatternFaceOptions bounded;
  bounded.max_quads = balanced - 1;
  const auto m = mesh_face_pattern(pc.model, 0, pc.curves, patterns, bounded, &rep);
  ASSERT_TRUE(rep.ok) << rep.reason;
  (void)check_face(pc.model, 0, pc.curves, m, rep);
  EXPECT_GT(rep.moves, 0);
  EXPECT_LE(static_cast<std::int64_t>(m.quads.size()), balanced - 1);
  EXPECT_EQ(rep.quads, static_cast<std::int64_t>(m.quads.size()));
}

// PatternFaceOptions::size_map_quads and move_work_ratio: the move search lays out at most
// move_work_ratio x size_map_quads x move_evaluations quads. On the flared strip, a size map
// asking for a quarter of the balanced fill's quads leaves the search fewer layouts than it makes
// improving moves unbounded; one asking for nothing near that leaves it none (the balanced fill).
TEST(FacePattern, SearchWorkIsBoundedByTheFacesQuads) {
  const auto pc = flared_strip("qs_flare_work.brep");
  const auto patterns = builtin_patterns();
  PatternFaceReport fixed, free, some, none;
  const auto m0 = mesh_face_pattern(pc.model, 0, pc.curves, patterns, without_moves(), &fixed);
  ASSERT_TRUE(fixed.ok) << fixed.reason;
  PatternFaceOptions o;
  o.move_work_ratio = 1;
  o.move_min_layouts_per_vector = 0;  // searches of a layout or two too (tested below)
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &free);  // size map unknown
  ASSERT_TRUE(free.ok) << free.reason;
  const auto quads = static_cast<double>(fixed.quads);
  ASSERT_GT(free.moves, 2);
  // Two layouts of the balanced fill's size, at most two improving moves.
  o.size_map_quads = 2.0 * quads / o.move_evaluations;
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &some);
  ASSERT_TRUE(some.ok) << some.reason;
  EXPECT_GT(some.moves, 0);
  EXPECT_LE(some.moves, 2);
  EXPECT_LT(some.moves, free.moves);
  // Less than one layout.
  o.size_map_quads = 0.5 * quads / o.move_evaluations;
  const auto m1 = mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &none);
  ASSERT_TRUE(none.ok) << none.reason;
  EXPECT_EQ(none.moves, 0);
  EXPECT_EQ(none.chords, fixed.chords);
  EXPECT_EQ(m1.quads, m0.quads);
  // A size map asking for as many quads as the fill has: the bound is move_work_ratio x
  // move_evaluations layouts, more than the search uses.
  o.size_map_quads = quads;
  PatternFaceReport loose;
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &loose);
  EXPECT_EQ(loose.moves, free.moves);
  EXPECT_EQ(loose.chords, free.chords);
}

// PatternFaceOptions::move_min_layouts_per_vector: a search the work bound would cut inside the
// coarse sweeps of its vectors is not started, and the fill is the balanced one; with layouts
// enough for them it runs.
TEST(FacePattern, SearchTooShortForItsCoarseSweepsIsNotStarted) {
  const auto pc = flared_strip("qs_flare_sweep.brep");
  const auto patterns = builtin_patterns();
  PatternFaceReport fixed, unbounded;
  const auto m0 = mesh_face_pattern(pc.model, 0, pc.curves, patterns, without_moves(), &fixed);
  ASSERT_TRUE(fixed.ok) << fixed.reason;
  PatternFaceOptions o;
  o.move_work_ratio = 1;
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &unbounded);
  ASSERT_GT(unbounded.moves, 0);
  const auto quads = static_cast<double>(fixed.quads);
  // Three layouts of the balanced fill's size: fewer than 4 per vector.
  o.size_map_quads = 3.0 * quads / o.move_evaluations;
  PatternFaceReport cut, allowed;
  const auto m1 = mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &cut);
  ASSERT_TRUE(cut.ok) << cut.reason;
  EXPECT_EQ(cut.moves, 0);
  EXPECT_EQ(cut.chords, fixed.chords);
  EXPECT_EQ(m1.quads, m0.quads);
  EXPECT_EQ(m1.points, m0.points);
  // The same bound, with the rule off: the search runs and moves.
  o.move_min_layouts_per_vector = 0;
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &allowed);
  EXPECT_GT(allowed.moves, 0);
  // Layouts enough for every coarse sweep: the search runs with the rule on.
  PatternFaceOptions enough;
  enough.move_work_ratio = 1;
  enough.size_map_quads = quads;
  PatternFaceReport full;
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, enough, &full);
  EXPECT_EQ(full.moves, unbounded.moves);
}

// qstruct::boundary_held_sicn is the SICN of the rectangle on the two edges, and no quad on them
// does better, whatever its fourth vertex.
TEST(FacePattern, BoundaryHeldSicnBoundsEveryQuadOnTheTwoEdges) {
  const Vec3 corner{1, 2, 0}, a{0.03, 0, 0}, b{0, 1, 0};
  const double held = boundary_held_sicn(a, b);
  EXPECT_NEAR(held, 2 * 0.03 / (1 + 0.03 * 0.03), 1e-15);
  EXPECT_NEAR(held, mesh::quad_sicn({corner, corner + a, corner + a + b, corner + b}), 1e-12);
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const Vec3 fourth = corner + Vec3{-1 + 0.15 * i, -1 + 0.15 * j, 0.05 * (i - j)};
      EXPECT_LE(mesh::quad_sicn({corner, corner + a, fourth, corner + b}), held + 1e-12);
    }
  EXPECT_EQ(boundary_held_sicn(Vec3{0, 0, 0}, Vec3{0, 0, 0}), 0.0);
}

// PatternFaceOptions::held_sicn_ratio: a 10 x 5 rectangle whose left side ends in a curve 0.03
// long at the top-left corner. Every fill puts one quad at that corner, on that short edge and
// the top side's first edge (length 1): held at about 0.06, below half the threshold 0.3. Only
// the first candidate is laid out, neither lifted nor moved; without the rule the others are,
// and none gets above the bound either.
TEST(FacePattern, QuadHeldByAShortBoundaryEdgeEndsTheTrials) {
  const XY xy = {{0, 0}, {10, 0}, {10, 5}, {0, 5}, {0, 4.97}};
  const auto pc = polygon(xy, {10, 6, 10, 1, 5}, "qs_held.brep");
  const auto patterns = builtin_patterns();
  const double held = boundary_held_sicn(Vec3{1, 0, 0}, Vec3{0, -0.03, 0});
  PatternFaceReport rep;
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, {}, &rep);
  EXPECT_FALSE(rep.ok);
  EXPECT_EQ(rep.refusal, Refusal::Quality);
  EXPECT_EQ(rep.candidates, 1);
  EXPECT_EQ(rep.lifts, 0);
  EXPECT_EQ(rep.moves, 0);
  EXPECT_FALSE(rep.refused_mesh.quads.empty());  // still offered to the comparison
  EXPECT_LE(rep.sicn_min, held + 1e-9);
  PatternFaceOptions off;
  off.held_sicn_ratio = 0;
  PatternFaceReport all;
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, off, &all);
  EXPECT_FALSE(all.ok);
  EXPECT_EQ(all.refusal, Refusal::Quality);
  EXPECT_GT(all.candidates + all.lifts + all.moves, 1);
  EXPECT_LE(all.sicn_min, held + 1e-9);
}

// PatternFaceOptions::lift_max_poor_fraction: the untangler only gets fills with few poor quads.
// With min_sicn 0.95 most quads of the transition fill are "poor" (and the average bound is off),
// so the default bound skips the untangler; without the bound it runs.
TEST(FacePattern, UntanglerOnlyForFewPoorQuads) {
  const XY xy = {{0, 0}, {10, 0}, {10, 5}, {0, 5}};
  const auto pc = polygon(xy, {11, 4, 9, 6}, "qs_lift.brep");
  const auto patterns = builtin_patterns();
  PatternFaceOptions o;
  o.min_sicn = 0.95;
  o.min_sicn_avg = 0;
  o.max_candidates = 1;
  PatternFaceReport rep;
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &rep);
  EXPECT_EQ(rep.candidates, 1);
  EXPECT_EQ(rep.lifts, 0);
  o.lift_max_poor_fraction = 1;
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &rep);
  EXPECT_EQ(rep.lifts, 1);
  o.lift_poor_quads = false;
  (void)mesh_face_pattern(pc.model, 0, pc.curves, patterns, o, &rep);
  EXPECT_EQ(rep.lifts, 0);
}

// PatternFaceOptions::lift_max_rings: the untangler moves only vertices within that many quad
// rings of the quads it lifts. A transition fill with a few quads under a high min_sicn (0.85),
// lifted, against the same fill not lifted.
TEST(FacePattern, LiftStaysWithinItsRings) {
  const XY xy = {{0, 0}, {30, 0}, {30, 15}, {0, 15}};
  const auto pc = polygon(xy, {33, 12, 27, 18}, "qs_lift_rings.brep");
  const auto patterns = builtin_patterns();
  PatternFaceOptions o;
  o.min_sicn = 0.85;
  o.min_sicn_avg = 0;
  o.max_candidates = 1;
  o.lift_max_poor_fraction = 1;
  o.move_evaluations = 0;
  const auto fill = [&](bool lift, int rings) {
    PatternFaceOptions p = o;
    p.lift_poor_quads = lift;
    p.lift_max_rings = rings;
    PatternFaceReport rep;
    mesh::FaceMesh m = mesh_face_pattern(pc.model, 0, pc.curves, patterns, p, &rep);
    EXPECT_EQ(rep.lifts, lift ? 1 : 0);
    return rep.ok ? m : rep.refused_mesh;
  };
  const mesh::FaceMesh plain = fill(false, 2);
  ASSERT_FALSE(plain.quads.empty());
  // Vertices within r quad rings of the quads the untangler starts from (SICN <= its target).
  const double target = o.min_sicn + 0.05;
  const auto within = [&](int r) {
    std::vector<char> near(plain.points.size(), 0), seen(plain.quads.size(), 0);
    for (std::size_t q = 0; q < plain.quads.size(); ++q) {
      const auto& qd = plain.quads[q];
      if (mesh::quad_sicn({plain.points[qd[0]], plain.points[qd[1]], plain.points[qd[2]],
                           plain.points[qd[3]]}) <= target)
        for (const LO v : qd) near[v] = 1;
    }
    for (int k = 0; k < r; ++k) {
      std::vector<char> next = near;
      for (const auto& qd : plain.quads)
        if (near[qd[0]] || near[qd[1]] || near[qd[2]] || near[qd[3]])
          for (const LO v : qd) next[v] = 1;
      near = std::move(next);
    }
    return near;
  };
  const auto moved_outside = [&](const mesh::FaceMesh& m, int r) {
    EXPECT_EQ(m.quads, plain.quads);
    const std::vector<char> near = within(r);
    int n = 0;
    for (std::size_t v = 0; v < plain.points.size(); ++v)
      n += !near[v] && !(m.points[v] == plain.points[v]) ? 1 : 0;
    return n;
  };
  EXPECT_EQ(moved_outside(fill(true, 2), 2), 0);
  // The untangler's own bound (8 rings) reaches farther on this fill.
  EXPECT_GT(moved_outside(fill(true, 8), 2), 0);
}

TEST(FacePattern, TriangleAndPentagonGetTheirIrregularVertex) {
  const auto patterns = builtin_patterns();
  {
    const XY xy = {{0, 0}, {6, 0}, {3, 3 * std::sqrt(3.0)}};
    const auto pc = polygon(xy, {6, 6, 6}, "qs_tri.brep");
    PatternFaceReport rep;
    const auto m = mesh_face_pattern(pc.model, 0, pc.curves, patterns, {}, &rep);
    const auto v = check_face(pc.model, 0, pc.curves, m, rep);
    EXPECT_EQ(rep.pattern_name, "triangle");
    EXPECT_EQ(v.interior.at(3), 1);
    EXPECT_EQ(v.interior.size(), 2u);
    EXPECT_EQ(m.quads.size(), 27u);
  }
  {
    XY xy;
    for (int k = 0; k < 5; ++k) {
      const double a = std::numbers::pi / 2 + 2 * std::numbers::pi * k / 5;
      xy.emplace_back(5 * std::cos(a), 5 * std::sin(a));
    }
    const auto pc = polygon(xy, {4, 4, 4, 4, 4}, "qs_penta.brep");
    PatternFaceReport rep;
    const auto m = mesh_face_pattern(pc.model, 0, pc.curves, patterns, {}, &rep);
    const auto v = check_face(pc.model, 0, pc.curves, m, rep);
    EXPECT_EQ(rep.pattern_name, "pentagon");
    EXPECT_EQ(v.interior.at(5), 1);
    EXPECT_EQ(v.interior.size(), 2u);
  }
}

TEST(FacePattern, LShapeKeepsItsConcaveCornerOnTheBoundary) {
  const XY xy = {{0, 0}, {6, 0}, {6, 3}, {3, 3}, {3, 6}, {0, 6}};
  const auto pc = polygon(xy, {6, 3, 3, 3, 3, 6}, "qs_l.brep");
  const auto patterns = builtin_patterns();
  PatternFaceReport rep;
  const auto m = mesh_face_pattern(pc.model, 0, pc.curves, patterns, {}, &rep);
  const auto v = check_face(pc.model, 0, pc.curves, m, rep);
  EXPECT_EQ(rep.pattern_name, "l_shape");
  EXPECT_EQ(rep.side_edges.size(), 5u);  // the concave corner does not split a side
  EXPECT_EQ(v.interior, (std::map<int, int>{{4, static_cast<int>(v.interior.at(4))}}));
  for (LO i = 0; i < m.num_vertices(); ++i)
    if (m.vclass[i].dim == 0 && std::abs(m.points[i].x - 3) < 1e-12 &&
        std::abs(m.points[i].y - 3) < 1e-12) {
      EXPECT_EQ(v.of[i], 3);
    }
}

TEST(FacePattern, CylinderSideIsAFourSidedDiskAcrossItsSeam) {
  const auto model = cad::load_cad(test::write_cylinder(tmp("qs_cyl.brep")));
  LO side = kNoIndex;
  for (LO f = 0; f < model.num_faces(); ++f)
    if (model.faces()[f].type == cad::SurfaceType::Cylinder) side = f;
  ASSERT_NE(side, kNoIndex);
  std::vector<mesh::CurveMesh> curves;
  for (LO c = 0; c < model.num_curves(); ++c)
    curves.push_back(test::uniform_curve_mesh(
        model, c, model.curves()[c].type == cad::CurveType::Circle ? 12 : 5));
  const auto patterns = builtin_patterns();
  PatternFaceReport rep;
  const auto m = mesh_face_pattern(model, side, curves, patterns, {}, &rep);
  const auto v = check_face(model, side, curves, m, rep);
  EXPECT_EQ(rep.pattern_name, "grid");
  EXPECT_EQ(m.quads.size(), 60u);
  EXPECT_EQ(v.interior, (std::map<int, int>{{4, 44}}));
  // The seam's vertices appear twice (two uv images, one 3D point).
  std::map<std::pair<LO, LO>, int> copies;
  for (const auto& vc : m.vclass)
    if (vc.dim == 1) ++copies[{vc.entity, vc.index}];
  int twice = 0;
  for (const auto& [k, n] : copies) twice += n == 2;
  EXPECT_EQ(twice, 4);
}

// A face bounded by one smooth loop has no corner: Euler (paper 000 Eq. 2) asks for four
// valence-3 vertices inside, which the disk pattern has (a centre quad in a ring of four).
TEST(FacePattern, DiskWithoutCornerGetsFourValence3Vertices) {
  const auto model = cad::load_cad(test::write_cylinder(tmp("qs_cyl_caps.brep")));
  std::vector<mesh::CurveMesh> curves;
  for (LO c = 0; c < model.num_curves(); ++c)
    curves.push_back(test::uniform_curve_mesh(
        model, c, model.curves()[c].type == cad::CurveType::Circle ? 32 : 5));
  const auto patterns = builtin_patterns();
  int caps = 0;
  for (LO f = 0; f < model.num_faces(); ++f) {
    if (model.faces()[f].type != cad::SurfaceType::Plane) continue;
    ++caps;
    PatternFaceReport rep;
    const auto m = mesh_face_pattern(model, f, curves, patterns, {}, &rep);
    const auto v = check_face(model, f, curves, m, rep);
    EXPECT_EQ(rep.pattern_name, "disk");
    EXPECT_EQ(rep.side_edges, std::vector<LO>{32});
    EXPECT_EQ(v.interior.at(3), 4);
    EXPECT_EQ(v.interior.size(), 2u) << "only valences 3 and 4 inside";
    // The ring has as many layers as the chords say: a x b centre quads, 2 (a + b) per layer.
    ASSERT_EQ(rep.chords.size(), 3u);
    EXPECT_EQ(rep.chords[0] + rep.chords[1], 16);
    EXPECT_EQ(rep.quads,
              static_cast<std::int64_t>(rep.chords[0]) * rep.chords[1] + 32 * rep.chords[2]);
    EXPECT_GT(rep.sicn_avg, 0.8);
  }
  EXPECT_EQ(caps, 2);
}

// A long face without corner: the disk pattern's corners and chords must follow the shape,
// wherever the CAD loop starts (eight starts over half the loop, each moved).
TEST(FacePattern, SlotWithoutCornerIsADiskWhereverItsLoopStarts) {
  const auto patterns = builtin_patterns();
  std::vector<double> means;
  for (const bool arc_first : {false, true}) {
    const auto model = cad::load_cad(test::write_stadium(
        8.0, 1.0, arc_first, tmp(arc_first ? "qs_slot_a.brep" : "qs_slot_b.brep")));
    std::vector<mesh::CurveMesh> curves;
    // Edges about 0.5 long: 16 on the segments, 6 on the half circles (pi long).
    for (LO c = 0; c < model.num_curves(); ++c)
      curves.push_back(test::uniform_curve_mesh(
          model, c, model.curves()[c].type == cad::CurveType::Circle ? 6 : 16));
    PatternFaceReport rep;
    const auto m = mesh_face_pattern(model, 0, curves, patterns, {}, &rep);
    const auto v = check_face(model, 0, curves, m, rep);
    EXPECT_EQ(rep.pattern_name, "disk");
    EXPECT_EQ(v.interior.at(3), 4);
    EXPECT_EQ(v.interior.size(), 2u) << "only valences 3 and 4 inside";
    // A ring of one or two layers around a long centre quad, not the balanced 11 x 11 square.
    ASSERT_EQ(rep.chords.size(), 3u);
    EXPECT_GE(std::max(rep.chords[0], rep.chords[1]), 4 * std::min(rep.chords[0], rep.chords[1]));
    EXPECT_LE(rep.chords[2], 2);
    EXPECT_GT(rep.sicn_avg, 0.9);
    means.push_back(rep.sicn_avg);
  }
  EXPECT_NEAR(means[0], means[1], 0.02);
}

// One corner: three valence-3 vertices inside (Eq. 2), the teardrop pattern.
TEST(FacePattern, TeardropWithOneCornerGetsThreeValence3Vertices) {
  const auto model = cad::load_cad(test::write_teardrop(2.0, tmp("qs_teardrop.brep")));
  ASSERT_EQ(model.num_faces(), 1);
  std::vector<mesh::CurveMesh> curves;
  // About 0.25 apart: the tangents are 2 long, the arc 3 pi (270 degrees of radius 2).
  for (LO c = 0; c < model.num_curves(); ++c)
    curves.push_back(test::uniform_curve_mesh(
        model, c, model.curves()[c].type == cad::CurveType::Circle ? 38 : 8));
  const auto patterns = builtin_patterns();
  PatternFaceReport rep;
  const auto m = mesh_face_pattern(model, 0, curves, patterns, {}, &rep);
  const auto v = check_face(model, 0, curves, m, rep);
  EXPECT_EQ(rep.pattern_name, "one_corner");
  EXPECT_EQ(rep.side_edges, std::vector<LO>{54});
  EXPECT_EQ(v.interior.at(3), 3);
  EXPECT_EQ(v.interior.size(), 2u) << "only valences 3 and 4 inside";
  EXPECT_GT(rep.sicn_avg, 0.7);
}

// The spherical face of a model made by test::write_sphere_*, kNoIndex when there is none.
LO sphere_face(const cad::CadModel& model) {
  for (LO f = 0; f < model.num_faces(); ++f)
    if (model.faces()[f].type == cad::SurfaceType::Sphere) return f;
  return kNoIndex;
}

// n edges on every curve, one on the degenerate ones (poles).
std::vector<mesh::CurveMesh> curves_with_poles(const cad::CadModel& model, LO n) {
  std::vector<mesh::CurveMesh> curves;
  for (LO c = 0; c < model.num_curves(); ++c)
    curves.push_back(test::uniform_curve_mesh(model, c, model.curves()[c].degenerate ? 1 : n));
  return curves;
}

// A pole is a corner where the curves on either side meet (paper 000 Sec. 6.1.2 on a face whose
// loop holds a degenerate curve): the sphere octant is a triangle with 90-degree corners, the
// triangle pattern's one valence-3 vertex inside, the pole one vertex.
TEST(FacePattern, PoleOfASphereOctantIsACornerOfATriangle) {
  const auto model = cad::load_cad(test::write_sphere_octant(tmp("qs_octant.brep")));
  const LO f = sphere_face(model);
  ASSERT_NE(f, kNoIndex);
  LO pole = kNoIndex;
  for (const auto& use : model.faces()[f].loops[0].uses)
    if (model.curves()[use.curve].degenerate) pole = model.curves()[use.curve].corners[0];
  ASSERT_NE(pole, kNoIndex) << "the octant's loop has its degenerate curve";
  const auto curves = curves_with_poles(model, 8);
  const auto patterns = builtin_patterns();
  const auto surface = model.face_geometry(f);
  const FaceSides fs = face_sides(model, f, *surface, curves, PatternFaceOptions{});
  EXPECT_EQ(fs.side_edges, (std::vector<LO>{8, 8, 8}));
  for (const LO c : fs.corners) EXPECT_NEAR(fs.angle_deg[c], 90.0, 1.0);
  PatternFaceReport rep;
  const auto m = mesh_face_pattern(model, f, curves, patterns, {}, &rep);
  ASSERT_TRUE(rep.ok) << rep.reason;
  EXPECT_EQ(rep.pattern_name, "triangle");
  EXPECT_EQ(m.quads.size(), 48u);  // three 4 x 4 blocks
  const auto v = valences(m);
  EXPECT_EQ(v.interior, (std::map<int, int>{{3, 1}, {4, 36}}));
  int at_pole = 0;
  for (LO i = 0; i < m.num_vertices(); ++i)
    if (m.vclass[i].dim == 0 && m.vclass[i].entity == pole) {
      ++at_pole;
      EXPECT_EQ(v.of[i], 1) << "a 90-degree corner is in one quad";
    }
  EXPECT_EQ(at_pole, 1);
  for (const auto& q : m.quads) {
    const std::array<Vec3, 4> p{m.points[q[0]], m.points[q[1]], m.points[q[2]], m.points[q[3]]};
    EXPECT_GT(mesh::quad_sicn(p), 0.5);
    // Outward like the sphere: the quad's normal along its centre's position.
    EXPECT_GT(dot(cross(p[1] - p[0], p[3] - p[0]) + cross(p[3] - p[2], p[1] - p[2]),
                  p[0] + p[1] + p[2] + p[3]),
              0);
  }
  for (LO i = 0; i < m.num_vertices(); ++i) EXPECT_NEAR(norm(m.points[i]), 3.0, 1e-9);
  EXPECT_GT(rep.sicn_avg, 0.8);
}

// Two poles in one loop (a lune between two half meridians): two corners of 90 degrees, a
// two-sided face; whatever fills it must be valid, with each pole one vertex.
TEST(FacePattern, LuneWithTwoPolesHasTwoCorners) {
  const auto model = cad::load_cad(test::write_sphere_lune(tmp("qs_lune.brep")));
  const LO f = sphere_face(model);
  ASSERT_NE(f, kNoIndex);
  const auto curves = curves_with_poles(model, 12);
  const FaceSides fs = face_sides(model, f, *model.face_geometry(f), curves, PatternFaceOptions{});
  EXPECT_EQ(fs.poles.size(), 2u);
  EXPECT_EQ(fs.side_edges, (std::vector<LO>{12, 12}));
  for (const LO c : fs.corners) EXPECT_NEAR(fs.angle_deg[c], 90.0, 1.0);
  PatternFaceReport rep;
  const auto m = mesh_face_pattern(model, f, curves, builtin_patterns(), {}, &rep);
  if (rep.ok || !rep.refused_mesh.quads.empty()) {
    const auto& mm = rep.ok ? m : rep.refused_mesh;
    std::map<LO, int> poles;
    for (LO i = 0; i < mm.num_vertices(); ++i)
      if (mm.vclass[i].dim == 0) ++poles[mm.vclass[i].entity];
    EXPECT_EQ(poles.size(), 2u);
    for (const auto& [corner, n] : poles) EXPECT_EQ(n, 1) << "corner " << corner;
    for (const auto& q : mm.quads)
      EXPECT_GT(
          mesh::quad_sicn({mm.points[q[0]], mm.points[q[1]], mm.points[q[2]], mm.points[q[3]]}), 0);
  }
  EXPECT_TRUE(rep.ok) << rep.reason;
  EXPECT_EQ(rep.pattern_name, "half_disk");
}

TEST(FacePattern, PolesInsideAndHolesAreRefused) {
  const auto patterns = builtin_patterns();
  {
    // The whole sphere: its poles lie between the two uses of the seam, inside the face.
    const auto model = cad::load_cad(test::write_sphere(tmp("qs_sphere.brep")));
    const auto curves = curves_with_poles(model, 8);
    PatternFaceReport rep;
    const auto m = mesh_face_pattern(model, 0, curves, patterns, {}, &rep);
    EXPECT_FALSE(rep.ok);
    EXPECT_EQ(rep.refusal, Refusal::Degenerate) << rep.reason;
    EXPECT_TRUE(m.quads.empty());
  }
  {
    const auto model = cad::load_cad(test::write_box_with_hole(tmp("qs_holed.brep")));
    std::vector<mesh::CurveMesh> curves;
    for (LO c = 0; c < model.num_curves(); ++c)
      curves.push_back(test::uniform_curve_mesh(model, c, 4));
    int holes = 0, meshed = 0;
    // Quality bounds that accept the stretched 4 x 4 grids of the box's long sides: this test is
    // about the refusal of holes, not about the quality policy.
    PatternFaceOptions loose;
    loose.min_sicn = 0.2;
    loose.min_sicn_avg = 0.45;
    for (LO f = 0; f < model.num_faces(); ++f) {
      PatternFaceReport rep;
      const auto m = mesh_face_pattern(model, f, curves, patterns, loose, &rep);
      if (model.faces()[f].loops.size() > 1) {
        ++holes;
        EXPECT_EQ(rep.refusal, Refusal::Loops);
        EXPECT_TRUE(m.quads.empty());
      } else if (rep.ok) {
        ++meshed;
      }
    }
    EXPECT_EQ(holes, 2);
    EXPECT_GE(meshed, 4);  // the four box sides without the hole, all 4 x 4 grids
  }
}

// A quantization whose counts are the polygon's curve meshes, each its own ideal value, no chord.
quantize::Quantization quantization_of(const PolygonCase& pc) {
  quantize::Quantization q;
  for (const auto& curve : pc.curves) {
    q.edges.push_back(curve.num_edges());
    q.ideal.push_back(static_cast<double>(q.edges.back()));
  }
  q.curve2chord.assign(pc.curves.size(), kNoIndex);
  return q;
}

// Pattern-aware quantization: a long rectangle whose bottom side is two curves gets [14, 2, 10, 4]
// from the per-curve rounding, which no pattern fits (the ends differ by 2 edges, the long sides
// by 4, across a strip 2 to 4 edges wide); balancing moves curves so that a pattern fits.
TEST(Balance, SidesOfSeveralCurvesAreMadeToFit) {
  const XY xy = {{0, 0}, {3, 0}, {10, 0}, {10, 1}, {0, 1}};
  const std::vector<LO> counts = {6, 8, 2, 10, 4};
  const auto pc = polygon(xy, counts, "qs_balance.brep");
  ASSERT_EQ(pc.model.num_curves(), 5);
  const quantize::Quantization q = quantization_of(pc);
  const auto patterns = builtin_patterns();
  const auto fs =
      face_sides(pc.model, 0, *pc.model.face_geometry(0), pc.curves, PatternFaceOptions{});
  ASSERT_EQ(fs.corners.size(), 4u);  // the 180-degree vertex at (3, 0) is no corner
  const auto& uses = pc.model.faces()[0].loops[0].uses;
  ASSERT_EQ(fs.use_start.size(), uses.size());
  const auto sides = [&](const std::vector<int>& e) {
    std::vector<LO> n(fs.corners.size(), 0);
    for (std::size_t u = 0; u < uses.size(); ++u)
      n[side_of(fs, fs.use_start[u])] += e[uses[u].curve];
    return n;
  };
  const std::vector<LO> before = sides(q.edges);
  ASSERT_TRUE(match_patterns(patterns, before).empty());

  BalanceReport rep;
  const std::vector<int> edges =
      balance_curve_counts(pc.model, pc.curves, q, patterns, {}, BalanceOptions{}, &rep);
  EXPECT_EQ(rep.faces_considered, 1);
  EXPECT_EQ(rep.fitting_before, 0);
  EXPECT_EQ(rep.fitting_after, 1);
  EXPECT_FALSE(match_patterns(patterns, sides(edges)).empty());
  for (LO c = 0; c < 5; ++c) {
    EXPECT_EQ(edges[c] % 2, 0);
    EXPECT_LE(std::abs(edges[c] - q.ideal[c]), std::max(2.0, 0.35 * q.ideal[c]) + 1e-9)
        << "curve " << c;
  }

  // With the bottom and top curves prescribed (user sizes) only the ends may move, and the fit
  // comes from them.
  const std::vector<LO> fixed = {0, 1, 3};
  const std::vector<int> ends =
      balance_curve_counts(pc.model, pc.curves, q, patterns, fixed, BalanceOptions{});
  for (const LO c : fixed) EXPECT_EQ(ends[c], q.edges[c]);
  EXPECT_FALSE(match_patterns(patterns, sides(ends)).empty());
  // With every curve prescribed nothing moves.
  const std::vector<LO> all = {0, 1, 2, 3, 4};
  EXPECT_EQ(balance_curve_counts(pc.model, pc.curves, q, patterns, all, BalanceOptions{}), q.edges);
}

// A rectangle that a transition fits only because the size map gave its bottom two more edges than
// its top: the sides are as long as each other, so balancing makes the counts equal (a grid). A
// trapezoid with the same counts keeps its transition, and so does the rectangle with the option
// off.
TEST(Balance, RectanglesFittedByATransitionBecomeGrids) {
  const auto run = [](const XY& xy, const std::string& name, double ratio) {
    const auto pc = polygon(xy, {12, 4, 10, 4}, name);
    const quantize::Quantization q = quantization_of(pc);
    const auto patterns = builtin_patterns();
    EXPECT_FALSE(match_patterns(patterns, std::vector<LO>{12, 4, 10, 4}).empty());  // transitions
    BalanceOptions o;
    o.grid_length_ratio = ratio;
    BalanceReport rep;
    const std::vector<int> edges =
        balance_curve_counts(pc.model, pc.curves, q, patterns, {}, o, &rep);
    EXPECT_EQ(rep.fitting_before, 1);
    EXPECT_EQ(rep.fitting_after, 1);
    for (LO c = 0; c < 4; ++c)
      EXPECT_LE(std::abs(edges[c] - q.ideal[c]), std::max(2.0, 0.35 * q.ideal[c]) + 1e-9);
    return std::make_pair(edges, rep);
  };
  const XY rectangle = {{0, 0}, {10, 0}, {10, 4}, {0, 4}};
  const auto [rect, rect_rep] = run(rectangle, "qs_balance_rect.brep", 1.1);
  EXPECT_EQ(rect[0], rect[2]);  // bottom and top now equal: 10 and 10, or 12 and 12
  EXPECT_EQ(rect[1], rect[3]);
  EXPECT_EQ(rect_rep.grids_before, 0);
  EXPECT_EQ(rect_rep.grids_after, 1);
  const auto [off, off_rep] = run(rectangle, "qs_balance_off.brep", 0);
  EXPECT_EQ(off, (std::vector<int>{12, 4, 10, 4}));
  EXPECT_EQ(off_rep.grids_after, 0);
  const auto [trap, trap_rep] = run({{0, 0}, {10, 0}, {8, 4}, {2, 4}}, "qs_balance_trap.brep", 1.1);
  EXPECT_EQ(trap, (std::vector<int>{12, 4, 10, 4}));
  EXPECT_EQ(trap_rep.grids_after, 0);
}

}  // namespace
}  // namespace qsmesh::qstruct
