// Coarse, conforming block layout of an all-quad mesh (paper 002 Sec. III and IV.A-E): a T-mesh
// of traces with the cone stopping rule, the ILP of its quantization (constraints (1)-(4),
// objective (6)), then the coarse quad mesh extracted from the solution (patch splitting, merging
// of zero-length groups, placement with CAD priorities), subdivided by quad loops and smoothed on
// the CAD. Sharp CAD curves are walls: traces stop at them and blocks end on them; curves where
// the surface is smooth may be crossed by traces and by blocks (CoarseOptions::
// cross_smooth_curves), as the paper's blocks cross the construction curves of aircraft skins.
#pragma once

#include <cstdint>
#include <string>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/layout/ilp.hpp"
#include "qsmesh/layout/quad_layout.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::layout {

/// CoarseOptions::repairs.
enum class Repairs {
  /// A repair first forbids the arcs of the bad coarse quads' patches to collapse (q_a >= 1), then
  /// those of up to 3 rings of patches around them, the first set the last solution does not
  /// meet; when all are met, the same patches' arcs grow by one coarse unit toward their input
  /// lengths (q_a >= min(l_a, q_a + 1)), ring by ring, repair after repair; only when their arcs
  /// are all at their input lengths are those restored (q_a >= l_a), ring by ring. A restored
  /// input length spreads along the chains of patches (an arc at its input length forces the
  /// opposite side of its patch, and so on) and splits them into cells of one input quad: on the
  /// crossing pipes at size 0.037 one such repair took the layout from 874 to 11,216 coarse quads,
  /// one growth step to 1,317 (docs/benchmarks.md, issue 30).
  Grow,
  /// As Grow without the growth: input lengths straight after the rings.
  Local,
  /// The former repairs: a patch's second repair restores its input lengths. On Block they kept
  /// most of the model at its input lengths (70,841 blocks against 43,132, docs/benchmarks.md,
  /// branch coarse10).
  Restore,
};

struct CoarseOptions {
  /// Half-angle of the cone of the stopping rule and of the geometric consistency (4), radians
  /// (the paper's default pi/4). Larger: traces stop sooner and irregular vertices further off
  /// each other's lines may align, so fewer coarse quads, more distorted (docs/benchmarks.md).
  double alpha = 0.785398163397448;  // pi/4
  IlpOptions ilp;
  /// Quad-loop widths (Sec. IV.D) balanced against the coarse quads' shapes, in [0, 1]: 0 takes
  /// each loop's width from the input lengths alone (the mean of its edges' input lengths); b > 0
  /// blends each edge's input length with (1 - b, b) the width that would make the fine quads of
  /// its coarse quad square at their size (sqrt of the product of the two fine edge lengths
  /// there). 0 by default: measured in docs/benchmarks.md ("Coarse block layout").
  double loop_balance = 0;
  /// Blocks cross the CAD curves where the surface is smooth (cad::smooth_across within
  /// smooth_angle_deg): the coarse quads on both sides of such a curve are joined into one block
  /// where a whole closed chord of coarse edges, running along smooth curves and off the curves,
  /// can go (through CAD corners whose curves are all smooth). Sharp curves (a crease) stay block
  /// sides. false: every CAD curve is a block side. Chords are removed one at a time, each only
  /// when the blocks it joins stay grids.
  bool cross_smooth_curves = true;
  double smooth_angle_deg = 10;
  /// With cross_smooth_curves, T-mesh traces also run on across smooth curves into the next face
  /// (where the curve vertex has two quads on each side), as in the paper's T-mesh on the whole
  /// surface. Off by default: on A319 it made more patches and blocks (docs/benchmarks.md), as a
  /// trace crossing a curve runs on until the cone rule stops it in the next face.
  bool traces_across_smooth_curves = false;
  /// Passes of the smoother (smooth::smooth_face, Winslow kernels) on each face of the new mesh.
  int smoothing_iterations = 10;
  /// Before the kernels, the smoother's Laplacian in the parameter plane (a direct solve, kept
  /// only when the face's minimum SICN does not drop); not on faces with a seam or periodic.
  bool laplacian_uv = true;
  /// Fine nodes on coarse edges along CAD curves spread like the input mesh's nodes between the
  /// edge's two ends (their curve parameters interpolated), instead of uniformly in the curve
  /// parameter. Each such edge keeps the spacing choose_side_spacing prefers for the coarse
  /// quads on its sides, and falls back to the uniform one where fine quads fold.
  bool input_spacing_on_curves = true;
  /// Fine nodes inside faces placed from the input patch each coarse quad was cut from (its cell
  /// of the patch's lattice covers a part of the patch's ni x nj grid of input quads): node
  /// (i, j) of the coarse quad's n0 x n1 grid goes where the input grid is at the same fractional
  /// grid coordinates (bilinear in the input quad there, projected on the face), and the gap
  /// between that map and the coarse quad's actual side nodes is spread inside by transfinite
  /// interpolation. The fine rows then follow the input's rows and grading; with n0 x n1 equal
  /// to the input counts the input is reproduced. Coarse edges off the curves follow the input
  /// grid line between their ends the same way. false: the sides' transfinite interpolation
  /// alone, with coarse edges off the curves straight chords projected on the face. Off by
  /// default: it places better (before smoothing) but the smoothed meshes of the shared models
  /// are no better, as the uv Laplacian's direct solve forgets the placement and the gap comes
  /// from the quad-loop widths (docs/benchmarks.md, branch coarse7).
  bool patch_placement = false;
  /// Quad-loop widths fitted to the cells each loop crosses (fit_loop_width: the integer width
  /// nearest, in ratio and weighted by the input quads each cell covers, to the extent of every
  /// cell of the loop in its input patch grid) instead of the rounded mean of the loop's targets.
  bool fit_loop_widths = false;
  /// How the layout is repaired where its fine mesh has folded or invalid quads (each repair
  /// adds rows to the quantization and solves again; at most 60).
  Repairs repairs = Repairs::Grow;
};

/// One coarse quad a quad loop crosses: how many input quads its cell spans across the loop (in
/// its input patch's grid, fractional where the cell's sides run between grid lines) and its
/// weight in the fit (the input quads the cell covers).
struct LoopCrossing {
  double extent = 1;
  double weight = 1;
};

/// The width of a quad loop fitted to the coarse quads it crosses: the integer w >= 1 that
/// minimises sum weight * |ln w - ln extent| (extents below 1/2 count as 1/2: a cell spanning
/// no input quad still gets one fine quad), the smallest such w on a tie; 1 for no crossing.
/// A fine quad in a cell meshed w times across an extent e is stretched by w / e against the
/// input quads it replaces; the loop's rounded mean of targets lets large cells pay for small
/// ones, this weighted median in ratio lets the cells that hold most input quads decide.
/// The integer program "widths minimising the weighted mismatch over every cell" separates by
/// loop (each cell's two terms each hold one loop's width, no row couples loops), so this is
/// its exact solution, loop by loop.
[[nodiscard]] int fit_loop_width(const std::vector<LoopCrossing>& crossings);

/// Quality of the fine quads of one coarse quad (SICN, before smoothing), for one placement of
/// the fine nodes on its sides.
struct SideScore {
  double sicn_min = 0;
  double sicn_avg = 0;
};

/// The policy between the two placements of a coarse quad's side nodes on CAD curves: true keeps
/// the input mesh's spacing (`input_like`), false the uniform parameter spacing (`uniform`).
/// The input spacing is kept when it leaves no inverted quad and neither lowers the average by
/// more than `avg_slack` nor the minimum below 0.9 of the uniform's (a lower minimum with a
/// higher average is how a stretched corner quad shows up, and corner quads are what folds).
[[nodiscard]] bool choose_side_spacing(const SideScore& uniform, const SideScore& input_like,
                                       double avg_slack = 0.0);

struct CoarseStats {
  std::int64_t tmesh_nodes = 0, tmesh_arcs = 0, tmesh_patches = 0, traces = 0;
  std::int64_t ilp_variables = 0, ilp_constraints = 0;
  double ilp_seconds = 0;  ///< all rounds
  /// Solves, each after rows forbidding the CAD merges of the last one (at most 40 per repair).
  int ilp_rounds = 0;
  /// Solves again after an invalid fine mesh, the patches that made the bad coarse quads and rings
  /// of patches around them kept from collapsing, then at their input lengths
  /// (CoarseOptions::repairs; at most 60).
  int repairs = 0;
  int repairs_grown = 0;     ///< repairs that grew arcs one unit (Repairs::Grow)
  int repairs_restored = 0;  ///< repairs that restored input lengths
  std::string ilp_status;
  std::int64_t smooth_curves = 0;  ///< CAD curves crossed (CoarseOptions::cross_smooth_curves)
  std::int64_t traces_across_curves = 0;  ///< traces that ran on across a smooth curve
  std::int64_t blocks_across_curves = 0;  ///< blocks whose quads lie on two faces or more
  /// Coarse vertices inside smooth curves with other than four coarse quads: no chord runs along
  /// the curve through them (a trace of one face ending where the other face has none).
  std::int64_t smooth_curve_vertices_not_four = 0;
  /// Coarse quads of the quantization (the split patches, Sec. IV.A), before they are joined
  /// into blocks across chords.
  std::int64_t cells = 0;
  /// Coarse vertices inside faces with other than four coarse quads: every chord through one
  /// stops there (a block corner), so these bound how far cells join into blocks.
  std::int64_t irregular_coarse_vertices = 0;
  /// Chords of coarse edges: removed (closed, the blocks they join stay grids), closed but kept
  /// (a block would not be a grid), open with an end at an irregular coarse vertex, and open
  /// with both ends elsewhere (CAD corners of other than four quads, curve vertices of other
  /// than four, free boundaries).
  std::int64_t chords_removed = 0, chords_closed_kept = 0, chords_open_at_irregular = 0,
               chords_open_elsewhere = 0;
  std::int64_t coarse_quads = 0;  ///< blocks
  std::int64_t fine_quads = 0;
  /// Coarse edges on CAD curves whose fine nodes follow the input spacing, and those kept at the
  /// uniform spacing (by choose_side_spacing, or after a fold).
  std::int64_t sides_input_spacing = 0, sides_uniform_spacing = 0;
  /// Fine meshes built again with some sides back at the uniform spacing, after folds.
  int spacing_fallbacks = 0;
  double sicn_min = 0, sicn_avg = 0;  ///< of the new mesh (after smoothing)
  double seconds = 0;                 ///< the whole stage
};

struct CoarseResult {
  bool ok = false;         ///< mesh and layout hold a valid conforming block-structured mesh
  std::string failure;     ///< why not, when !ok (one line)
  mesh::SurfaceMesh mesh;  ///< the new all-quad mesh (SurfaceMesh numbering and classification)
  /// Its blocks: the coarse quads, joined across chords that can go (closed loops of coarse edges
  /// through vertices of four coarse quads, CAD corners included, along no sharp curve); every
  /// side shared whole with one other side.
  QuadLayout layout;
  CoarseStats stats;
};

/// Builds the coarse block-structured mesh of `input`.
/// Preconditions: `input` is an assembled SurfaceMesh of `model` (bars on every CAD curve, each
/// face's quads oriented along its normal). A mesh with triangles, a T-mesh patch that is not a
/// grid, an ILP without solution, or a result that does not validate after the rounds and repairs
/// (a coarse quad with a repeated corner, a non-manifold coarse edge, two CAD corners merged, a
/// folded fine quad) gives ok = false and the reason; nothing is thrown for those. Deterministic:
/// the same input gives the same mesh.
[[nodiscard]] CoarseResult build_coarse_layout(const mesh::SurfaceMesh& input,
                                               const cad::CadModel& model,
                                               const CoarseOptions& options = {});

}  // namespace qsmesh::layout
