// The coarse block layout (paper 002 Sec. III-IV) on OpenCASCADE-built models meshed through the
// library, and the integer program solver behind it on small programs with known answers.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cgns_blocks_check.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/log.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/layout/coarse_layout.hpp"
#include "qsmesh/layout/ilp.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/mesh/validate.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::layout {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Issue 30: the block-structured mesh's SICN average within this of the quasi-structured one's.
constexpr double kQualityGap = 0.03;

TEST(Ilp, SolvesASmallProgramExactly) {
  // min x + y + 3z  s.t.  x + 2y >= 3,  x - y = 0,  y + z >= 2,  0 <= x, y, z <= 5.
  // x = y >= 1; x = y = 1 needs z = 1 (cost 5), x = y = 2 needs no z (cost 4, the optimum).
  IntegerProgram p;
  p.objective = {1, 1, 3};
  p.lower = {0, 0, 0};
  p.upper = {5, 5, 5};
  p.rows.push_back({{{0, 1.0}, {1, 2.0}}, 3, kInf});
  p.rows.push_back({{{0, 1.0}, {1, -1.0}}, 0, 0});
  p.rows.push_back({{{1, 1.0}, {2, 1.0}}, 2, kInf});
  const IlpResult r = solve_integer_program(p);
  ASSERT_TRUE(r.feasible) << r.status;
  EXPECT_TRUE(r.optimal);
  EXPECT_EQ(r.x, (std::vector<long>{2, 2, 0}));
  EXPECT_DOUBLE_EQ(r.objective, 4.0);
  // The same program gives the same solution.
  EXPECT_EQ(solve_integer_program(p).x, r.x);
}

TEST(Ilp, IntegralityMatters) {
  // 2x = 1 has the LP solution 1/2 and no integer one.
  IntegerProgram p;
  p.objective = {1};
  p.lower = {0};
  p.upper = {3};
  p.rows.push_back({{{0, 2.0}}, 1, 1});
  const IlpResult r = solve_integer_program(p);
  EXPECT_FALSE(r.feasible);
  EXPECT_TRUE(r.x.empty());
  // 2x >= 1: the integer optimum is 1.
  p.rows.front().hi = kInf;
  EXPECT_EQ(solve_integer_program(p).x, (std::vector<long>{1}));
}

struct Meshed {
  cad::CadModel model;
  mesh::SurfaceMesh mesh;
};

Meshed mesh_model(const std::string& path, double size) {
  Meshed m{cad::load_cad(path), {}};
  parallel::PipelineOptions options;
  options.background.sizes.size = size;
  options.sizemap.size_max = size;
  options.until = parallel::Stage::QuasiStructured;
  // The input mesh `qsmesh mesh --layout coarse` makes: fills compared on their mean only.
  options.patterns.compare_irregular = false;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  m.mesh = parallel::run_pipeline(parallel::Comm::self(), m.model, options, TaskArena(1), log).mesh;
  return m;
}

// Side s of block b (vertex ids, counter-clockwise around the block as in quad_layout.cpp).
std::vector<GO> block_side(const QuadLayout& lay, const Block& b, int s) {
  std::vector<GO> out;
  if (s == 0)
    for (LO i = 0; i <= b.ni; ++i) out.push_back(b.vertex(i, 0, lay.vertices));
  if (s == 1)
    for (LO j = 0; j <= b.nj; ++j) out.push_back(b.vertex(b.ni, j, lay.vertices));
  if (s == 2)
    for (LO i = b.ni; i >= 0; --i) out.push_back(b.vertex(i, b.nj, lay.vertices));
  if (s == 3)
    for (LO j = b.nj; j >= 0; --j) out.push_back(b.vertex(0, j, lay.vertices));
  return out;
}

// Checks the coarse result of a closed model: a valid all-quad mesh conforming to the CAD, whose
// blocks cover it and each share every side whole with exactly one other block side.
void expect_conforming_blocks(const CoarseResult& r, const cad::CadModel& model) {
  ASSERT_TRUE(r.ok) << r.failure;
  const mesh::SurfaceMesh& m = r.mesh;
  EXPECT_TRUE(m.triangles.empty());
  ASSERT_FALSE(m.quads.empty());
  const auto conformity = mesh::check_conformity(m, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
  for (const auto& q : m.quads) {
    std::array<Vec3, 4> p{};
    for (int c = 0; c < 4; ++c)
      p[static_cast<std::size_t>(c)] =
          m.points[static_cast<std::size_t>(q[static_cast<std::size_t>(c)])];
    EXPECT_GT(mesh::quad_sicn(p), 0.0);
  }
  std::int64_t covered = 0;
  std::map<std::vector<GO>, int> sides;
  for (const Block& b : r.layout.blocks) {
    covered += static_cast<std::int64_t>(b.ni) * b.nj;
    for (int s = 0; s < 4; ++s) ++sides[block_side(r.layout, b, s)];
  }
  EXPECT_EQ(covered, static_cast<std::int64_t>(m.quads.size()));
  for (const auto& [side, n] : sides) {
    std::vector<GO> back(side.rbegin(), side.rend());
    const auto it = sides.find(back);
    EXPECT_TRUE(it != sides.end() && it->second == 1 && n == 1)
        << "a block side of " << side.size() - 1 << " edges from " << side.front() << " to "
        << side.back() << " is not shared whole with exactly one other block";
  }
  for (GO b : r.layout.quad2block) EXPECT_GE(b, 0);
}

TEST(CoarseLayout, BoxWithHoleIsConformingValidAndDeterministic) {
  const std::string path = test::write_box_with_hole(test::tmp("coarse_box_hole.brep"));
  const Meshed in = mesh_model(path, 0.35);
  ASSERT_TRUE(in.mesh.triangles.empty());
  const CoarseResult r = build_coarse_layout(in.mesh, in.model);
  expect_conforming_blocks(r, in.model);
  // The quantization keeps the mesh density: subdivision by quad loops uses the input lengths.
  EXPECT_GT(r.mesh.quads.size(), in.mesh.quads.size() / 2);
  EXPECT_LT(r.mesh.quads.size(), in.mesh.quads.size() * 2);
  EXPECT_GT(r.stats.ilp_variables, 0);
  // Blocks are the coarse quads joined across the removed chords: fewer exactly when some chord
  // went. The box's holes make irregular coarse vertices, which stop chords.
  const auto blocks = static_cast<std::int64_t>(r.layout.blocks.size());
  EXPECT_GE(r.stats.cells, blocks);
  EXPECT_EQ(r.stats.cells > blocks, r.stats.chords_removed > 0);
  EXPECT_GT(r.stats.irregular_coarse_vertices + r.stats.chords_open_elsewhere, 0);
  // The CGNS file of the blocks reads back with every interface matching.
  const std::string out = test::tmp("coarse_box_hole.cgns");
  io::write_cgns_blocks(r.mesh, r.layout, out);
  const test::BlockFileSummary s = test::check_block_file(out, true);
  EXPECT_TRUE(s.error.empty()) << s.error;
  EXPECT_EQ(s.structured_zones, static_cast<int>(r.layout.blocks.size()));
  // Deterministic.
  const CoarseResult again = build_coarse_layout(in.mesh, in.model);
  EXPECT_EQ(again.mesh.quads, r.mesh.quads);
  EXPECT_EQ(again.mesh.points, r.mesh.points);
}

TEST(CoarseLayout, CylinderWithClosedCurves) {
  const std::string path = test::write_cylinder(test::tmp("coarse_cylinder.brep"));
  const Meshed in = mesh_model(path, 0.4);
  const CoarseResult r = build_coarse_layout(in.mesh, in.model);
  expect_conforming_blocks(r, in.model);
  EXPECT_GT(r.stats.ilp_variables, 0);
}

// Mean over the blocks, weighted by their quads, of |log(aspect)| of the fine quads each block
// plans: its straight sides between its corners, over its counts. What loop_balance aims at
// (CoarseOptions), before the fine nodes are placed on the CAD and smoothed.
double block_log_aspect(const CoarseResult& r) {
  double sum = 0, weight = 0;
  for (const auto& b : r.layout.blocks) {
    auto p = [&](LO i, LO j) {
      return r.mesh.points[static_cast<std::size_t>(b.vertex(i, j, r.layout.vertices))];
    };
    const double li = 0.5 * (distance(p(0, 0), p(b.ni, 0)) + distance(p(0, b.nj), p(b.ni, b.nj)));
    const double lj = 0.5 * (distance(p(0, 0), p(0, b.nj)) + distance(p(b.ni, 0), p(b.ni, b.nj)));
    const double w = static_cast<double>(b.ni) * b.nj;
    sum += w * std::abs(std::log((li / b.ni) / (lj / b.nj)));
    weight += w;
  }
  return weight > 0 ? sum / weight : 0;
}

TEST(CoarseLayout, LoopWidthsBalancedAgainstTheCoarseQuadsShapes) {
  // The widths of the quad loops come from the input mesh's lengths; balanced fully against the
  // coarse quads' shapes (loop_balance 1), the blocks plan squarer fine quads, and the layout
  // stays conforming and valid. The fine quads as placed on the CAD and smoothed are not always
  // squarer: at sizes 0.3 to 0.4 their mean |log(aspect)| drops at 4 of 7, the planned one at 6
  // (docs/benchmarks.md, "Complex factorization").
  const std::string path = test::write_box_with_hole(test::tmp("coarse_balance.brep"));
  const Meshed in = mesh_model(path, 0.35);
  const CoarseResult plain = build_coarse_layout(in.mesh, in.model);
  CoarseOptions o;
  o.loop_balance = 1;
  const CoarseResult balanced = build_coarse_layout(in.mesh, in.model, o);
  expect_conforming_blocks(plain, in.model);
  expect_conforming_blocks(balanced, in.model);
  EXPECT_LT(block_log_aspect(balanced), block_log_aspect(plain));
  // The same blocks, other widths.
  EXPECT_EQ(balanced.layout.blocks.size(), plain.layout.blocks.size());
  EXPECT_NE(balanced.mesh.quads.size(), plain.mesh.quads.size());
}

TEST(CoarseLayout, LoopWidthFitFollowsTheCellsThatHoldMostInputQuads) {
  // Three cells one input quad across (one quad each) and one eight across (eight quads): the
  // loop's mean of targets would give 3, wrong for all four; the fit gives the large cell its
  // extent, as it holds most of the input quads.
  EXPECT_EQ(fit_loop_width({{1, 1}, {1, 1}, {1, 1}, {8, 8}}), 8);
  // Many small cells outweigh one large one.
  EXPECT_EQ(fit_loop_width({{1, 4}, {1, 4}, {1, 4}, {8, 8}}), 1);
  // One cell: its extent, rounded in ratio (2.6 is nearer 3 than 2 in ratio).
  EXPECT_EQ(fit_loop_width({{11, 1}}), 11);
  EXPECT_EQ(fit_loop_width({{2.6, 1}}), 3);
  // A tie between 2 and 4 (every width between costs the same): the smallest.
  EXPECT_EQ(fit_loop_width({{2, 1}, {4, 1}}), 2);
  // Cells spanning no input quad still get one fine quad; no cell: width 1.
  EXPECT_EQ(fit_loop_width({{0, 1}, {0.2, 3}}), 1);
  EXPECT_EQ(fit_loop_width({}), 1);
}

TEST(CoarseLayout, FittedLoopWidthsKeepTheLayoutConforming) {
  // The fitted widths change the fine counts (and, where fine quads fold, the repairs and so the
  // blocks); the layout stays conforming and valid on the box with a hole.
  const std::string path = test::write_box_with_hole(test::tmp("coarse_fit.brep"));
  const Meshed in = mesh_model(path, 0.35);
  const CoarseResult plain = build_coarse_layout(in.mesh, in.model);
  CoarseOptions o;
  o.fit_loop_widths = true;
  const CoarseResult fit = build_coarse_layout(in.mesh, in.model, o);
  expect_conforming_blocks(plain, in.model);
  expect_conforming_blocks(fit, in.model);
  EXPECT_NE(fit.mesh.quads.size(), plain.mesh.quads.size());
  EXPECT_GT(fit.stats.sicn_min, 0.0);
}

TEST(CoarseLayout, RepairsForbidCollapseBeforeRestoringInputLengths) {
  // Three crossing pipes: fine quads fold near the reflex corners of the pipes' junctions after
  // the first solve and again after the first repair. The former repairs then restore the input
  // lengths of those patches, which spreads along chains of patches (an arc at its input length
  // forces the opposite side of its patch): most of the model ends at its input lengths. Local
  // repairs keep the patches and rings around them from collapsing first, and stay coarse.
  const std::string path = test::write_pipe_cross(test::tmp("coarse_pipe_cross.brep"));
  // Whether a size provokes the spread depends on where the input mesh's folds fall: with the
  // stall rule on the pipes' solved faces (crossfield::CrossFieldOptions::
  // revolution_stall_window) 0.035 and 0.0365 do, 0.034, 0.0355 and 0.038 need one repair only.
  const Meshed in = mesh_model(path, 0.0365);
  const CoarseResult local = build_coarse_layout(in.mesh, in.model);
  CoarseOptions restore_options;
  restore_options.repairs = Repairs::Restore;
  const CoarseResult restore = build_coarse_layout(in.mesh, in.model, restore_options);
  expect_conforming_blocks(local, in.model);
  expect_conforming_blocks(restore, in.model);
  EXPECT_GE(local.stats.repairs, 2);
  EXPECT_GE(restore.stats.repairs, 2);
  // Measured: 2,526 cells against 15,415 (77,385 input quads).
  std::printf("[coarse] pipes: %lld cells with local repairs, %lld restoring, %zu input quads\n",
              static_cast<long long>(local.stats.cells),
              static_cast<long long>(restore.stats.cells), in.mesh.quads.size());
  EXPECT_LT(local.stats.cells * 4, restore.stats.cells)
      << local.stats.cells << " cells with local repairs, " << restore.stats.cells << " without";
}

TEST(CoarseLayout, GrowRepairsKeepTheLayoutCoarseWhereRingsAreNotEnough) {
  // The crossing pipes at another size: after four repairs every ring of patches around the last
  // folded fine quads is kept from collapsing already. Restoring the input lengths of those
  // patches then spreads along their chains and splits most of the model into cells of one input
  // quad; growing their arcs one unit does not (measured: 1,317 cells against 11,216).
  const std::string path = test::write_pipe_cross(test::tmp("coarse_pipe_grow.brep"));
  const Meshed in = mesh_model(path, 0.037);
  const CoarseResult grow = build_coarse_layout(in.mesh, in.model);
  CoarseOptions bound_options;
  bound_options.repairs = Repairs::Local;
  const CoarseResult bound = build_coarse_layout(in.mesh, in.model, bound_options);
  expect_conforming_blocks(grow, in.model);
  expect_conforming_blocks(bound, in.model);
  EXPECT_GE(grow.stats.repairs_grown, 1);
  EXPECT_EQ(grow.stats.repairs_restored, 0);
  EXPECT_EQ(bound.stats.repairs_grown, 0);
  EXPECT_GE(bound.stats.repairs_restored, 1);
  EXPECT_LT(grow.stats.cells * 4, bound.stats.cells)
      << grow.stats.cells << " cells with grown arcs, " << bound.stats.cells
      << " with input lengths restored";
  EXPECT_GT(grow.stats.sicn_min, 0.0);
}

TEST(CoarseLayout, BlocksCrossSmoothCurvesNotSharpOnes) {
  // A filleted box: the fillets meet the box's faces and each other along smooth curves, which
  // blocks may cross; fewer blocks than with every curve a wall, still conforming.
  const std::string path = test::write_filleted_box(test::tmp("coarse_fillet.step"));
  const Meshed in = mesh_model(path, 0.6);
  CoarseOptions walls;
  walls.cross_smooth_curves = false;
  const CoarseResult across = build_coarse_layout(in.mesh, in.model);
  const CoarseResult walled = build_coarse_layout(in.mesh, in.model, walls);
  expect_conforming_blocks(across, in.model);
  expect_conforming_blocks(walled, in.model);
  EXPECT_GT(across.stats.smooth_curves, 0);
  EXPECT_EQ(walled.stats.smooth_curves, 0);
  EXPECT_GT(across.stats.blocks_across_curves, 0);
  EXPECT_EQ(walled.stats.blocks_across_curves, 0);
  EXPECT_LT(across.layout.blocks.size(), walled.layout.blocks.size());
  // The same new mesh: only the blocks change.
  EXPECT_EQ(across.mesh.quads, walled.mesh.quads);
  // The box with a hole has sharp curves only: nothing is crossed.
  const std::string box = test::write_box_with_hole(test::tmp("coarse_sharp.brep"));
  const Meshed sharp = mesh_model(box, 0.35);
  const CoarseResult a = build_coarse_layout(sharp.mesh, sharp.model);
  const CoarseResult w = build_coarse_layout(sharp.mesh, sharp.model, walls);
  EXPECT_EQ(a.stats.smooth_curves, 0);
  EXPECT_EQ(a.layout.blocks.size(), w.layout.blocks.size());
}

// Quad-weighted SICN average and minimum of a mesh.
SideScore mesh_sicn(const mesh::SurfaceMesh& m) {
  SideScore s{2, 0};
  for (const auto& q : m.quads) {
    std::array<Vec3, 4> p{};
    for (int c = 0; c < 4; ++c)
      p[static_cast<std::size_t>(c)] =
          m.points[static_cast<std::size_t>(q[static_cast<std::size_t>(c)])];
    const double v = mesh::quad_sicn(p);
    s.sicn_min = std::min(s.sicn_min, v);
    s.sicn_avg += v;
  }
  s.sicn_avg /= static_cast<double>(std::max<std::size_t>(m.quads.size(), 1));
  return s;
}

TEST(CoarseLayout, FineMeshKeepsTheInputQuality) {
  // Issue 30's quality target: the block-structured fine mesh keeps SICN min > 0 and its average
  // within 0.03 of the quasi-structured mesh's. On a half annulus (radii 1 and 3), the fine nodes
  // along the arcs spread uniformly in the curve parameter and the kernels alone (the uv
  // Laplacian was skipped: every face looked like a seam) left the average 0.24 below the
  // input's (0.70 against 0.94).
  const std::string path = test::write_half_annulus(1.0, 3.0, test::tmp("coarse_quality.brep"));
  const Meshed in = mesh_model(path, 0.2);
  const CoarseResult r = build_coarse_layout(in.mesh, in.model);
  ASSERT_TRUE(r.ok) << r.failure;
  const auto conformity = mesh::check_conformity(r.mesh, in.model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
  const SideScore input = mesh_sicn(in.mesh), fine = mesh_sicn(r.mesh);
  EXPECT_GT(fine.sicn_min, 0.0);
  EXPECT_DOUBLE_EQ(fine.sicn_avg, r.stats.sicn_avg);
  EXPECT_GT(fine.sicn_avg, input.sicn_avg - kQualityGap)
      << "input SICN avg " << input.sicn_avg << ", block mesh " << fine.sicn_avg;
  EXPECT_GT(r.stats.sides_input_spacing, 0);
  // Both changes off: the former placement and smoothing, measurably worse.
  CoarseOptions former;
  former.laplacian_uv = false;
  former.input_spacing_on_curves = false;
  const CoarseResult old = build_coarse_layout(in.mesh, in.model, former);
  ASSERT_TRUE(old.ok) << old.failure;
  EXPECT_EQ(old.stats.sides_input_spacing, 0);
  EXPECT_LT(old.stats.sicn_avg, fine.sicn_avg);
}

TEST(CoarseLayout, PatchPlacementFollowsTheInputGrid) {
  // The planar teardrop (a circle and its two tangents from one corner): the input quads bend
  // around the circle and grade towards the corner, and the coarse quads' edges inside the face
  // are chords of those curved rows. Placement alone (no smoothing): the sides' transfinite
  // interpolation, with straight chords, leaves the average 0.05 below the input's (0.932
  // against 0.983); the nodes taken from the input patch grid stay within issue 30's 0.03.
  const std::string path = test::write_teardrop(3.0, test::tmp("coarse_patch.brep"));
  const Meshed in = mesh_model(path, 0.3);
  CoarseOptions patch;
  patch.patch_placement = true;
  patch.smoothing_iterations = 0;
  CoarseOptions coons = patch;
  coons.patch_placement = false;
  const CoarseResult p = build_coarse_layout(in.mesh, in.model, patch);
  const CoarseResult c = build_coarse_layout(in.mesh, in.model, coons);
  ASSERT_TRUE(p.ok) << p.failure;
  ASSERT_TRUE(c.ok) << c.failure;
  const auto conformity = mesh::check_conformity(p.mesh, in.model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
  // The same blocks and counts: only the nodes move.
  EXPECT_EQ(p.mesh.quads, c.mesh.quads);
  EXPECT_EQ(p.layout.blocks.size(), c.layout.blocks.size());
  const SideScore input = mesh_sicn(in.mesh);
  EXPECT_GT(p.stats.sicn_min, 0.0);
  EXPECT_GT(p.stats.sicn_avg, input.sicn_avg - kQualityGap)
      << "input SICN avg " << input.sicn_avg << ", patch placement " << p.stats.sicn_avg;
  EXPECT_LT(c.stats.sicn_avg, input.sicn_avg - kQualityGap)
      << "input SICN avg " << input.sicn_avg << ", transfinite placement " << c.stats.sicn_avg;
}

TEST(CoarseLayout, SideSpacingPolicyKeepsTheBetterPlacement) {
  // The input spacing when it is as good on average and keeps the minimum ...
  EXPECT_TRUE(choose_side_spacing({0.5, 0.8}, {0.5, 0.85}));
  EXPECT_TRUE(choose_side_spacing({0.5, 0.8}, {0.46, 0.8}));
  // ... not when it lowers the average, nor when it drops the minimum (a stretched corner quad).
  EXPECT_FALSE(choose_side_spacing({0.5, 0.8}, {0.6, 0.79}));
  EXPECT_FALSE(choose_side_spacing({0.5, 0.8}, {0.3, 0.9}));
  EXPECT_TRUE(choose_side_spacing({0.5, 0.8}, {0.6, 0.79}, 0.02));
  // An inverted quad decides: never the placement that has one when the other has none.
  EXPECT_FALSE(choose_side_spacing({0.1, 0.5}, {-0.1, 0.9}));
  EXPECT_TRUE(choose_side_spacing({-0.2, 0.5}, {0.01, 0.4}));
  EXPECT_FALSE(choose_side_spacing({-0.2, 0.5}, {-0.01, 0.9}));
}

TEST(CoarseLayout, AMeshWithTrianglesIsRefusedWithAReason) {
  mesh::SurfaceMesh m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.vclass.assign(3, {});
  m.triangles = {{0, 1, 2}};
  m.triangle_face = {0};
  m.num_cad_faces = 1;
  const std::string path = test::write_cylinder(test::tmp("coarse_refused.brep"));
  const cad::CadModel model = cad::load_cad(path);
  const CoarseResult r = build_coarse_layout(m, model);
  EXPECT_FALSE(r.ok);
  EXPECT_FALSE(r.failure.empty());
  EXPECT_TRUE(r.layout.blocks.empty());
}

}  // namespace
}  // namespace qsmesh::layout
