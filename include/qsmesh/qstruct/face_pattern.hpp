// Pattern-based quad meshing of whole CAD faces (paper 000 Sec. 6.1.2): a face with one boundary
// loop is split into sides at its convex corners, the side edge counts of the final (quantized)
// curve meshes are matched with the coarse patterns (Sec. 6.1.1), the refined pattern is laid out
// in the parameter plane and smoothed (Sec. 5.3), and kept only when its quality is good; else
// the caller uses the unstructured path (Sec. 5), and may still compare a refused fill with that
// path's mesh (PatternFaceReport::refused_mesh).
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/mesh/delaunay.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/qstruct/patterns.hpp"
#include "qsmesh/smooth/smooth.hpp"

namespace qsmesh::qstruct {

class MoveLayoutHelpers;

struct PatternFaceOptions {
  /// A CAD corner whose interior angle in the face (3D, degrees) is below this splits the
  /// boundary into sides (a convex corner, paper 000 Sec. 6: n_in = 1).
  double corner_angle_deg = 150;
  /// When no pattern mesh is kept with those sides, the convex corners whose angle is at least
  /// this (degrees) are taken as flat and matching is tried once more (blunt corners, e.g. 140
  /// degrees, fit one quad or two about as badly).
  double soft_corner_angle_deg = 120;
  /// The pattern mesh is kept when, after smoothing, every quad has SICN (Eq. 12) above
  /// min_sicn and the mean SICN is above min_sicn_avg (or every quad above keep_sicn_min,
  /// below). SICN also measures stretching (a w x h
  /// rectangle has 2wh / (w^2 + h^2)), so these bounds trade faces meshed by patterns against
  /// quality. Measured on Block.stp at --size-factor 0.02 (--until quasi-structured): 0.2 / 0.45
  /// gives 354 faces by patterns, SICN avg 0.855; 0.3 / 0.7 gives 304 faces, SICN avg 0.887
  /// (the unstructured path alone: 0.895).
  double min_sicn = 0.3;
  double min_sicn_avg = 0.7;
  /// A valid fill whose every quad has SICN above this (and above the face's min threshold) is
  /// kept whatever its mean (the acceptance rule of Gmsh's implementation of Sec. 6.1.2, which
  /// has no mean threshold). A319.brep at its reference count: two 4 x 10 grids at SICN 0.57 /
  /// 0.699 kept, 24 -> 26 faces by pattern, interior irregular 1233 -> 1226, SICN avg 0.890 ->
  /// 0.889; the other shared models unchanged. 1 or more: off. The untangler (lift_poor_quads)
  /// is still offered only fills whose mean passes min_sicn_avg: it lifts to min_sicn + 0.05,
  /// short of this bound.
  double keep_sicn_min = 0.5;
  /// A valid fill of at most this many quads is kept on its minimum alone (above the face's min
  /// threshold): its mean is that of a few corner quads and says little more than the minimum.
  /// Block.stp at size factor 0.0036: its [4, 10, 8] triangles get the triangle pattern (31
  /// quads, 1 irregular vertex, SICN avg 0.60-0.67) instead of 19-23 unstructured quads with 3
  /// irregular vertices (avg 0.77-0.80), 416 -> 423 faces by pattern. The price shows on A319's
  /// faces 44 and 79: 22-quad half-disks at SICN avg 0.52 where 14 unstructured quads had 0.74,
  /// with the same 2 irregular vertices. 0: off.
  std::int64_t small_fill_quads = 40;
  /// A kept fill of more than small_fill_quads quads whose mean SICN is at or below
  /// compare_below_avg (fill_to_compare: every fill kept on keep_sicn_min alone, and those kept on
  /// a mean just above min_sicn_avg) gives way to the unstructured mesh of the same face when the
  /// latter's mean SICN is higher by more than compare_avg_margin (unstructured_clearly_better;
  /// the caller meshes such faces both ways). A negative margin: off. wing_fuselage.step with the
  /// clamped sizing: face 15, a plane at a wing tip, got one-corner fills at SICN avg 0.678 (size
  /// factor 0.0058, kept on its minimum 0.50) and 0.727 (0.0064, kept on its mean) where its
  /// unstructured mesh has 0.95-0.96 (docs/benchmarks.md).
  double compare_below_avg = 0.8;
  double compare_avg_margin = 0.1;
  /// A kept fill of more than small_fill_quads quads with interior irregular vertices (a
  /// transition, whatever its mean) is compared too (fill_to_compare), and gives way to the
  /// unstructured mesh of the same face when that has fewer interior irregular vertices and is
  /// no worse in SICN min and mean within the pipeline's comparison tolerance
  /// (unstructured_fewer_irregular): a transition pattern places its irregular vertices in pairs,
  /// which is not always the fewest the face allows. It costs meshing those faces both ways
  /// (docs/benchmarks.md, "Transition fills weighed"). False: only poor means are compared
  /// (--fill-comparison mean).
  bool compare_irregular = true;
  /// ... on fills of at most this many quads, so that meshing a face both ways, and holding both
  /// meshes until the comparison, stays bounded per face (at 16x its reference count A319 took
  /// twice the time and 1.5 KB a quad without it). The second improvement pass's face bound
  /// (PipelineOptions::second_pass_max_quads).
  std::int64_t compare_irregular_max_quads = 4000;
  /// ... except a fill with no more interior irregular vertices than the face's cross field has
  /// interior singularities (fill_to_compare's `field_singularities`) and a mean above 1 -
  /// compare_avg_margin. The unstructured mesh follows the field, and its cavity step keeps an
  /// irregular vertex at each singularity, so it can hardly beat such a fill on that count, and
  /// no mesh beats its mean by the margin. At A319's 16x count its pentagon face 9 (3,453 quads,
  /// one irregular vertex, one singularity, SICN avg 0.930) was meshed both ways for nothing,
  /// the run's dearest improvement task (docs/benchmarks.md, "Fills at their field's count").
  /// False: every fill with an interior irregular vertex is compared (--fill-comparison all).
  bool compare_above_field = true;
  /// The quad at a corner of angle a < 90 degrees reaches SICN sin(a) at best (equal edges): at a
  /// face with a side-splitting corner where sin(a) <= min_sicn, which min_sicn would refuse
  /// whatever the mesh (a < 17.5 degrees for 0.3), the min threshold is corner_sicn_factor x
  /// sin(a) instead. Block.stp at size factor 0.0037: 383 -> 396 faces by pattern (transitions in
  /// wedges with 14.7-degree corners), interior irregular 1.11% -> 1.03%, SICN avg 0.938 ->
  /// 0.928, SICN min unchanged (0.183).
  double corner_sicn_factor = 0.9;
  /// When the smoothed mesh has its mean above min_sicn_avg but quads at or below min_sicn (or
  /// invalid), smooth::untangle_face lifts them (target min_sicn + 0.05) before the test.
  bool lift_poor_quads = true;
  /// ... but only when those quads are at most max(lift_min_poor_quads, lift_max_poor_fraction x
  /// the quads): the untangler is a local repair. On the shared models at their reference sizes
  /// the bound changes one face of 533 on Block.stp and no other, and cuts the pattern stage from
  /// 21.8 to 4.0 s on Block at size factor 0.0037 (qstruct_survey, one thread: a half-disk fill of
  /// face 380 with many folded quads took 10.7 s in the untangler and stayed folded).
  double lift_max_poor_fraction = 0.01;
  std::int64_t lift_min_poor_quads = 8;
  /// ... and within this many quad rings of them (smooth::UntangleOptions::max_rings; its rings,
  /// 2, at least). On the shared models at their reference counts every lift that let its fill
  /// pass did so within 2 rings (Block's faces 25, 85, 272, 410-420, 476; A319's 20 and 39);
  /// those that grew to the untangler's 8 either failed (Block's faces 400-436, three folded
  /// quads each: SICN min 0.112, mean 0.552, 0.2 s each, a tenth of the run) or, on Block's face
  /// 335, gained 0.00002 in the minimum for 0.028 of the mean. With 2, that face keeps the mean
  /// (0.907 -> 0.935) and every other mesh is byte-identical (docs/benchmarks.md, issue 27).
  int lift_max_rings = 2;
  /// Largest quad count a pattern mesh of the face may have (0: no bound). A pattern fill is
  /// structured, so a size transition along one side runs across the whole face: [96, 342, 26,
  /// 342] on wing_fuselage.step gives 22k quads where the size map asks for 4k. The pipeline
  /// sets it per face from the size map (PipelineOptions::pattern_max_quad_ratio).
  std::int64_t max_quads = 0;
  /// A kept fill with mean SICN below move_below_avg, and the best valid fill refused on quality,
  /// get up to move_evaluations more layouts with the pattern's irregular vertices moved
  /// (chord_moves: the same pattern and side counts, other chord subdivisions): a local search
  /// from the matched solution, four points spread along each move then halving steps. A kept
  /// fill keeps the best mean SICN above the thresholds; a refused one climbs toward them (mean
  /// less twice the minimum's shortfall) and is kept if it passes. When every match needs more
  /// than max_quads, the best one is searched the same way from its balanced solution, laying out
  /// only moves within the bound (Block at 0.0037: six half-disks [60, 78], 396 -> 402 faces by
  /// pattern). 0: off. Measured with 40:
  /// mambo's four [102, 20, 102, 32] transitions SICN avg 0.93 -> 0.97-0.99 (the model's 0.973
  /// -> 0.979 at its reference count), Block at size factor 0.0037 +6 faces by pattern (half-
  /// disks, avg 0.53 -> 0.80-0.84); the pattern stage 1.2-2.3 s longer on Block.
  int move_evaluations = 40;
  double move_below_avg = 0.97;
  /// Explicit smoothing passes of each layout the move search compares (the start among them):
  /// the layouts are ranked after this many passes, and only the winner is smoothed with `smooth`.
  /// A search lays out up to move_evaluations fills of the whole face, so its cost is that many
  /// smoothings; ranked after 3 passes of 10 it is about a third (docs/benchmarks.md, "Fields at
  /// the geometry's resolution"). 0, or at least smooth.iterations: every layout fully smoothed.
  int move_search_iterations = 3;
  /// Quads the size map asks of the face (sizemap::expected_quads; the pipeline sets it per face;
  /// 0: unknown, no bound below) and the bound it puts on the move search: the search lays out
  /// at most move_work_ratio x size_map_quads x move_evaluations quads, so a fill far finer
  /// than the size map gets proportionally fewer layouts (fewer than move_evaluations when its
  /// start has more than move_work_ratio x size_map_quads quads). wing_fuselage at its reference
  /// count: faces 7 and 15, one-corner fills of 8893 quads where the size map asks for 713 (the
  /// unstructured mesh has 792), laid out 18 times each and refused (docs/benchmarks.md).
  double size_map_quads = 0;
  double move_work_ratio = 2;
  /// The search is not started when that bound leaves it fewer layouts than this per move
  /// vector: it lays out 4 points of each vector's range before refining around the best, so it
  /// would stop inside the first vectors' coarse sweeps. Measured on the six shared models at
  /// their reference counts (docs/benchmarks.md, issue 27, branch `speed`): every search so
  /// short (A319's faces 6, 10, 21, 24, 25 with 5-7 layouts for 2 vectors, t20's face 13,
  /// wing_fuselage's faces 7 and 15 with 6) ended at a mean SICN of 0.36 at most, against the
  /// 0.7 asked, and its face took the unstructured mesh; the meshes are byte-identical without
  /// those searches, and wing_fuselage's patterns stage loses 0.5 s of its 1.5 s. 0: always.
  int move_min_layouts_per_vector = 4;
  /// Matches tried geometrically (laid out, smoothed, measured) before giving up, best first.
  int max_candidates = 4;
  /// A loop point where a candidate puts a single quad holds that quad's two boundary edges there,
  /// so no smoothing or untangling lifts it above boundary_held_sicn of those edges (a short CAD
  /// curve beside a long edge: wing_fuselage's faces 1 and 8, a 0.018-long edge beside a 3.8-long
  /// one, held at 0.028). A candidate held below held_sicn_ratio x the face's min threshold cannot
  /// pass the thresholds: it is laid out only when it is the first (still offered to the caller's
  /// comparison with the unstructured mesh), and never lifted or moved. At 1, on the six shared
  /// models at their reference counts, every mesh is unchanged, byte for byte; the pattern stage
  /// loses wing_fuselage's faces 1 and 8 (2.5 s each: four candidates, each lifted, then 28 moved
  /// layouts) and Block's faces 445-455 (held at 0.204 against 0.229, four lifts and 22 moved
  /// layouts each), docs/benchmarks.md. 0: off.
  double held_sicn_ratio = 1;
  MatchOptions match;
  smooth::SmoothOptions smooth;
  /// Threads for the move search (null or one thread: serial). Its steps stay serial, but the
  /// layouts one step may read (a vector's four coarse points; a halving step's +step and -step)
  /// are laid out at once, one task each, so that one large face's pattern work is split below
  /// the face (issue 28). The fill is the same as the serial search's at any thread count; a
  /// layout the serial search would not have read is wasted work.
  const TaskArena* tasks = nullptr;
  /// Other workers (ranks, in the pipeline: parallel::RankLayoutHelpers) that lay out layouts of
  /// the move search for this face while they have nothing else to do (null: none; issue 28).
  /// Where some are free, the layouts the search may read in its next halving levels (or a
  /// vector's four coarse points) are planned at once, at most move_lend_layouts of them, and
  /// dealt over the caller and the helpers; the serial rules then read them in their order, so
  /// the fill is the serial search's. Takes precedence over `tasks` for the search.
  MoveLayoutHelpers* helpers = nullptr;
  /// Most layouts one lent batch plans (the levels of halving steps it covers: 2, then 2 + 6,
  /// then 2 + 6 + 18 offsets); also what the batches are counted against when no helper is free,
  /// so that a run on one rank tells the scaling simulation what lending would be.
  int move_lend_layouts = 32;
};

/// Why a face was not meshed by a pattern.
enum class Refusal : std::uint8_t {
  None,          ///< meshed
  Loops,         ///< not exactly one boundary loop (holes), or a loop that is not closed
  Degenerate,    ///< a degenerate curve (pole, cone apex) or a corner where the surface is singular
  NoPattern,     ///< no pattern has as many sides, or none fits the side counts (Eq. 14)
  Quality,       ///< every candidate tried left a quad at or below the quality thresholds
  TooManyQuads,  ///< every fitting pattern needs more quads than PatternFaceOptions::max_quads
  Error,         ///< an error from the geometry or the smoother
  /// a kept fill with a poor mean gave way to the face's unstructured mesh, clearly better on
  /// average (PatternFaceOptions::compare_avg_margin; set by the caller that compares)
  UnstructuredBetter,
};
[[nodiscard]] const char* to_string(Refusal r);

/// What happened on one face.
struct PatternFaceReport {
  bool ok = false;
  Refusal refusal = Refusal::None;
  std::string reason;  ///< refusal details, with the face id
  /// Edges of each side, from the side after the first corner; without corner one side, the
  /// whole loop.
  std::vector<LO> side_edges;
  LO pattern = kNoIndex;  ///< index in the pattern list of the mesh kept (or last tried)
  std::string pattern_name;
  int start = 0;  ///< face side holding pattern side 0 (PatternMatch::start)
  bool reversed = false;
  std::vector<LO> chords;  ///< chord subdivisions of that match
  int candidates = 0;      ///< matches tried geometrically
  int lifts = 0;           ///< candidates handed to the untangler (lift_poor_quads)
  int moves = 0;           ///< improving moves made by the search (over every start without corner)
  /// The move search's layouts read by its rules (over every search of the face), the batches
  /// they came in (a step of the search's critical path when its layouts are made at once:
  /// PatternFaceOptions::tasks), and the searches' wall time, seconds: what the scaling
  /// simulation splits the face's pattern time by (scripts/simulate_scaling.py).
  int layouts = 0;
  int batches = 0;
  double search_seconds = 0;
  /// Lending the search's layouts (PatternFaceOptions::helpers, move_lend_layouts): the seconds
  /// this worker spent laying out the layouts the rules read (layout_seconds / layouts is one
  /// layout), the lent batches along the search's path (counted as if move_lend_layouts workers
  /// were free when there are no helpers), the layouts those batches plan (speculative ones
  /// included: the work lending deals out), the most helpers one batch had, and whether the search
  /// could be lent at all (1: it ran its rules over planned batches).
  double layout_seconds = 0;
  int layout_batches = 0;
  int layout_vectors = 0;
  int lend_ranks = 0;
  int vector_lendable = 0;
  double sicn_min = 0, sicn_avg = 0;  ///< of the mesh kept (or of the best refused one)
  /// The min threshold applied (options.min_sicn, lowered at sharp corners: corner_sicn_factor).
  double min_sicn = 0;
  std::int64_t quads = 0;
  /// On a Quality refusal: the best candidate (highest minimum SICN) when it is valid (every quad
  /// SICN > 0), else empty. Paper 000 Sec. 6.1.1 keeps a pattern mesh when its quality is better
  /// than the mesh it replaces; a caller that has the face's other mesh can make that comparison.
  mesh::FaceMesh refused_mesh;
  /// Every field, once (visit(name, member)): what the ranks exchange (parallel/record.hpp).
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("ok", self.ok);
    visit("refusal", self.refusal);
    visit("reason", self.reason);
    visit("side_edges", self.side_edges);
    visit("pattern", self.pattern);
    visit("pattern_name", self.pattern_name);
    visit("start", self.start);
    visit("reversed", self.reversed);
    visit("chords", self.chords);
    visit("candidates", self.candidates);
    visit("lifts", self.lifts);
    visit("moves", self.moves);
    visit("layouts", self.layouts);
    visit("batches", self.batches);
    visit("search_seconds", self.search_seconds);
    visit("layout_seconds", self.layout_seconds);
    visit("layout_batches", self.layout_batches);
    visit("layout_vectors", self.layout_vectors);
    visit("lend_ranks", self.lend_ranks);
    visit("vector_lendable", self.vector_lendable);
    visit("sicn_min", self.sicn_min);
    visit("sicn_avg", self.sicn_avg);
    visit("min_sicn", self.min_sicn);
    visit("quads", self.quads);
    visit("refused_mesh", self.refused_mesh);
  }
};

/// The boundary of a face split at its convex corners.
struct FaceSides {
  std::vector<mesh::BoundaryPoint> points;  ///< the loop of background::face_boundary
  /// Interior angle (degrees, 3D, in (0, 360)) at each point that is a CAD corner (vclass.dim 0);
  /// 180 elsewhere.
  std::vector<double> angle_deg;
  std::vector<LO> corners;  ///< positions in `points` of the convex corners, increasing
  /// Side k runs from corners[k] to corners[k + 1] (cyclic); without corner one side of all
  /// points.size() edges, from point 0.
  std::vector<LO> side_edges;
  /// Position in `points` where each use of the face's loop starts (loop order). Corners sit at
  /// use starts, so a use lies in one side: side_of(fs, use_start[u]).
  std::vector<LO> use_start;
  double uv_area = 0;     ///< signed area of the loop in the parameter plane (> 0: CCW)
  std::vector<LO> poles;  ///< positions in `points` of the poles (merged degenerate curves)
};

/// Splits the boundary of face f (one loop) into sides. `curves`: the final curve meshes of all
/// curves, by curve id. A degenerate curve (pole) gives no edge: its copies of the pole become
/// one point, at their mean (u, v), the corner where the curves on either side meet (its angle
/// measured in the plane normal to the mean of the surface normals just off the pole towards its
/// two loop neighbours: the surface's normal at a smooth pole, an approximation at a cone's apex).
/// Throws qsmesh::Error when the face does not have exactly one closed loop, has only degenerate
/// curves, a pole between the two uses of a seam (inside the face: a whole sphere or cone), or a
/// corner where a tangent or the surface normal vanishes.
[[nodiscard]] FaceSides face_sides(const cad::CadModel& model, LO f,
                                   const cad::FaceGeometry& surface,
                                   std::span<const mesh::CurveMesh> curves,
                                   const PatternFaceOptions& options);

/// The side (index into fs.side_edges) that the boundary point at position `pos` starts: the last
/// corner at or before it, the last side before the first corner. Precondition: fs.corners not
/// empty, 0 <= pos < fs.points.size().
[[nodiscard]] int side_of(const FaceSides& fs, LO pos);

/// The highest SICN (Eq. 12, mesh::quad_sicn) a quad can have when two of its edges meeting at a
/// corner are `a` and `b` (vectors from that corner): the corner's term 2 |a x b| / (|a|^2 +
/// |b|^2), whatever the quad's other two vertices. A single quad at a boundary loop point has its
/// two boundary edges there fixed, so this bounds every fill that puts one quad there. 0 for a
/// zero edge.
[[nodiscard]] double boundary_held_sicn(const Vec3& a, const Vec3& b);

/// Paper 000 Sec. 6.1.2 on face f.
///  - Input: the model, the final curve meshes of all curves (`full_curves`, by curve id, as
///    quad::subdivide uses them), the pattern list (builtin_patterns()) and options.
///  - The face must have one boundary loop (seams included: a cylinder's lateral face is a 4-sided
///    disk in its parameter plane, the seam used twice). A pole (degenerate curve) is a corner of
///    that loop (face_sides): a cone sector or a fuselage's nose cap is a triangle.
///  - The boundary is split at the corners below options.corner_angle_deg; when that gives no
///    mesh, once more at the corners below options.soft_corner_angle_deg only. A face with one
///    corner takes the one-sided patterns with a corner (the teardrop), a face without corner
///    the patterns without corner (the disk, Pattern::cornerless).
///  - Matches (match_patterns) are ranked by how well the refined pattern's boundary valences fit
///    the CAD corners that do not split sides (ideal valence max(2, round(angle / 90))), then by
///    pattern order and energy; up to options.max_candidates of them are laid out (interior
///    vertices by a uniform-weight Laplace solve in (u, v), the boundary fixed), smoothed with
///    smooth::smooth_face and measured; the first above the thresholds is returned. Without
///    corner, eight starts spread over half the loop are laid out and each valid one moved
///    (chord_moves, then turns of the pattern along the loop, up to a quarter of it each way);
///    the best mean wins, the search stopping at the first at or above move_below_avg.
///  - Output: an all-quad FaceMesh whose boundary vertices are exactly those of
///    background::face_boundary (same uv, xyz, VertexClass: assembly merges them with the
///    neighbouring faces; a pole's copies are one vertex, at their mean uv), interior vertices
///    classified on f, quads oriented along the face normal. When the face is refused: an empty
///    mesh (face id set) and the reason in the report (with the best valid candidate in
///    report->refused_mesh on a quality refusal).
/// Never throws for a face-level failure. Deterministic.
[[nodiscard]] mesh::FaceMesh mesh_face_pattern(const cad::CadModel& model, LO f,
                                               std::span<const mesh::CurveMesh> full_curves,
                                               std::span<const Pattern> patterns,
                                               const PatternFaceOptions& options,
                                               PatternFaceReport* report = nullptr);

/// Whether a fill kept by mesh_face_pattern (valid, its minimum above the face's threshold) with
/// this mean SICN, quad count and number of interior irregular vertices is compared with the
/// face's unstructured mesh: more than options.small_fill_quads quads, and its mean at or below
/// options.compare_below_avg or (options.compare_irregular, at most
/// options.compare_irregular_max_quads quads) an interior irregular vertex; with
/// options.compare_above_field, not a fill with at most `field_singularities` of them (the
/// interior singularities of the face's cross field, 0 where the face has no field) and a mean
/// above 1 - options.compare_avg_margin. The
/// mean takes in every fill kept on options.keep_sicn_min alone (the acceptance rule of Gmsh's
/// implementation: every quad above it, whatever the mean) when compare_below_avg is at least
/// min_sicn_avg. False when options.compare_avg_margin is negative (no comparison). Serial, pure.
[[nodiscard]] bool fill_to_compare(double sicn_avg, std::int64_t quads,
                                   std::int64_t irregular_interior,
                                   std::int64_t field_singularities,
                                   const PatternFaceOptions& options);

/// Whether the unstructured mesh of a face (paper 000 Sec. 5-6.3, after the topological steps)
/// is clearly better than a kept fill of the same face (fill_to_compare), so that it replaces
/// the fill: it is all quads, valid, with its minimum SICN above options.min_sicn (it trades no
/// poor quad for the fill's mean), and its mean SICN is above the fill's by more than
/// options.compare_avg_margin (never when that is negative). Irregular vertices are not
/// weighed here (unstructured_fewer_irregular weighs them): a better mean bought with more of
/// them replaces the fill only when it is clearly better. Serial, pure.
[[nodiscard]] bool unstructured_clearly_better(const mesh::FaceQuadStats& fill,
                                               const mesh::FaceQuadStats& unstructured,
                                               const PatternFaceOptions& options);

/// Whether the unstructured mesh of a face has fewer interior irregular vertices than a kept
/// fill of the same face at no cost in quality: all quads, valid, its SICN min and mean each at
/// least the fill's less `tolerance`. False unless options.compare_irregular. Serial, pure.
[[nodiscard]] bool unstructured_fewer_irregular(const mesh::FaceQuadStats& fill,
                                                const mesh::FaceQuadStats& unstructured,
                                                double tolerance,
                                                const PatternFaceOptions& options);

/// Which mesh a face keeps when a pattern fill waits for its unstructured mesh (the pipeline's
/// comparison after paper 000 Sec. 6.2-6.3): true for the fill. A fill kept by mesh_face_pattern
/// but held back by fill_to_compare (`kept`) wins unless unstructured_clearly_better or
/// unstructured_fewer_irregular; a fill the thresholds refused wins when it is no worse than the
/// unstructured mesh in SICN min and mean (within `tolerance`) and has no more interior irregular
/// vertices. Serial, pure.
[[nodiscard]] bool fill_wins(const mesh::FaceQuadStats& fill,
                             const mesh::FaceQuadStats& unstructured, bool kept, double tolerance,
                             const PatternFaceOptions& options);

/// One layout of the move search (move_irregular_vertices) that another worker can make: the
/// pattern `pattern` (index in the pattern list) with chord subdivisions `chords`, mirrored or
/// not, its refined boundary position p on face loop point seq[p] (FaceSides::points), laid out
/// and smoothed with `smooth_iterations` passes. Plain data: what the ranks exchange.
struct MoveLayoutRequest {
  LO face = kNoIndex;
  LO pattern = kNoIndex;
  bool reversed = false;
  std::vector<LO> chords;
  std::vector<LO> seq;
  int smooth_iterations = 0;
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("face", self.face);
    visit("pattern", self.pattern);
    visit("reversed", self.reversed);
    visit("chords", self.chords);
    visit("seq", self.seq);
    visit("smooth_iterations", self.smooth_iterations);
  }
};

/// The smoothed layout of a MoveLayoutRequest and its quality, or the error laying it out threw
/// (non-empty `error`: the owner throws it when its rules read the layout).
struct MoveLayoutResult {
  mesh::FaceMesh mesh;
  smooth::QualityReport quality;
  std::string error;
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("mesh", self.mesh);
    visit("quality", self.quality);
    visit("error", self.error);
  }
};

/// Lays out one move of the search: what the owner of a face and a helper both run, so that a
/// lent layout is bit for bit the owner's own. `fs`: face_sides of request.face (its points, poles
/// and loop area; the corners do not matter); `smooth`: PatternFaceOptions::smooth (its iterations
/// replaced by the request's). Never throws: an error goes into the result.
[[nodiscard]] MoveLayoutResult lay_out_move(const cad::CadModel& model, const FaceSides& fs,
                                            std::span<const Pattern> patterns,
                                            const smooth::SmoothOptions& smooth,
                                            const MoveLayoutRequest& request);

/// Workers that lay out moves for a face's search (PatternFaceOptions::helpers). Implemented over
/// ranks by parallel::RankLayoutHelpers; qstruct sees only this interface. Used by one thread at a
/// time.
class MoveLayoutHelpers {
 public:
  virtual ~MoveLayoutHelpers() = default;
  /// Claims up to `wanted` workers free now; returns how many (0: none). Every claimed worker is
  /// handed a share, possibly empty, by the next lay_out, which releases it.
  virtual int claim(int wanted) = 0;
  /// Lays out `requests` over the claimed workers and the caller (`here` runs the caller's share);
  /// the results in request order.
  virtual std::vector<MoveLayoutResult> lay_out(
      const std::vector<MoveLayoutRequest>& requests,
      const std::function<MoveLayoutResult(const MoveLayoutRequest&)>& here) = 0;
};

}  // namespace qsmesh::qstruct
