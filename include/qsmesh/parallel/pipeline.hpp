// The distributed pipeline: curves sampled split over the ranks and meshed on every rank, faces
// partitioned with METIS and meshed as TBB tasks on their rank, per-face results gathered on
// rank 0 and assembled with global numbering. The assembled mesh does not depend on the number of
// ranks or threads.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/log.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/fieldmesh/field_file.hpp"
#include "qsmesh/holomorphic/group.hpp"
#include "qsmesh/holomorphic/holomorphic.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/face_task.hpp"
#include "qsmesh/parallel/split.hpp"
#include "qsmesh/qstruct/balance.hpp"
#include "qsmesh/qstruct/cavity.hpp"
#include "qsmesh/qstruct/face_pattern.hpp"
#include "qsmesh/quad/unstructured.hpp"
#include "qsmesh/quantize/quantize.hpp"
#include "qsmesh/remesh/disk_remesh.hpp"
#include "qsmesh/sizemap/size_map.hpp"
#include "qsmesh/smooth/untangle.hpp"

namespace qsmesh::parallel {

/// Pipeline stages, in order. QuasiStructured (paper 000 Sec. 6): the simple CAD faces meshed by
/// patterns (Sec. 6.1.2) before the unstructured path meshes the others, whose irregular vertices
/// are then reduced by cavity remeshing (Sec. 6.2) and their defects by disk quadrangulations
/// (Sec. 6.3).
enum class Stage { Background, Unstructured, QuasiStructured };
[[nodiscard]] const char* to_string(Stage s);
/// Parses a stage name; throws InputError listing the valid names.
[[nodiscard]] Stage parse_stage(const std::string& name);

/// Default PipelineOptions::task_quads: above the largest improved face of the six shared models
/// at their reference sizes (their meshes do not change), and small enough that the one face
/// that dominates A319 at 16 times its reference vertex count is dealt as several tasks
/// (docs/benchmarks.md, issue 28).
inline constexpr std::int64_t kDefaultTaskQuads = 20000;

/// Default PipelineOptions::second_pass_task_irregular. On A319 at 16 times its reference vertex
/// count it splits the three faces whose improvement takes over 0.9 s (25-41 irregular vertices
/// before it) and none of the nine others of at most second_pass_max_quads quads (at most 10
/// each); it costs one rank no measurable time, the second pass taking the first's memo there
/// (docs/benchmarks.md, issue 28, branch `scale7`). The mesh does not depend on it.
inline constexpr std::int64_t kDefaultSecondPassTaskIrregular = 16;

/// The cavity options of the second pass (PipelineOptions::second_pass_cavities): the defaults
/// with keep_avg_ratio 0.94 (0.97), max_candidates 4 (2) and max_backtracks 16 (8). Each alone,
/// for every face, on wing_fuselage's window (eight factors 0.0058-0.0063) left 3, 7 and 3 of the
/// 8 factors at both criteria of the Gmsh reference; together, as a second pass, all 8
/// (max_quads_maximal 3000 from the start as well: the same meshes there and on Block, at more
/// cost; docs/benchmarks.md, issue 29).
[[nodiscard]] inline qstruct::CavityOptions loose_cavity_options() {
  qstruct::CavityOptions o;
  o.keep_avg_ratio = 0.94;
  o.max_candidates = 4;
  o.max_backtracks = 16;
  return o;
}

struct PipelineOptions {
  background::BackgroundOptions background;
  Stage until = Stage::Background;
  /// Compute the cross field of every face on its background mesh (paper 000 Sec. 3).
  bool cross_fields = false;
  crossfield::CrossFieldOptions crossfield;
  /// Compute the size map (paper 000 Sec. 4.1-4.2) and quantize the curves (Sec. 4.3). With
  /// the crossfield method the cross fields are computed too.
  bool size_map = false;
  sizemap::SizeMapOptions sizemap;
  quantize::QuantizeOptions quantize;
  /// Where the quantized curves' vertices go (quantize::place_vertices).
  quantize::PlaceOptions place;
  /// Pattern-aware quantization (qstruct::balance_curve_counts) after Sec. 4.3: curve counts
  /// nudged so that more faces fit a coarse pattern (Sec. 6.1.2). Applies with the size map.
  bool balance_counts = true;
  qstruct::BalanceOptions balance;
  /// Rounds of boundary repair after the quantization: the curves of a face boundary that crosses
  /// itself in the face's parameter plane (halved or final curve meshes, quantize::crossing_curves)
  /// get twice their edges (their chords too), until no boundary crosses. Without it such a face
  /// cannot be meshed and is missing from the output: a tight curve with too few edges, which the
  /// curvature sizes prevent by default, but not --curvature-edges 0 or a raised --size-min at
  /// coarse sizes (Block.stp at size factor 0.05: 2 faces). 0: off.
  int boundary_repair_rounds = 4;
  /// Stage::QuasiStructured: pattern meshing of simple CAD faces (Sec. 6.1.2).
  qstruct::PatternFaceOptions patterns;
  /// With one thread per rank, the ranks that have finished their share of the pattern stage
  /// lay out the move-search layouts of the faces still being filled (issue 28:
  /// parallel::RankLayoutHelpers, qstruct::PatternFaceOptions::helpers and move_lend_layouts).
  /// The fills are those of one rank. Off: patterns.move_lend_layouts is set to 0 (no lending, no
  /// counting).
  bool move_layouts_over_ranks = true;
  /// A pattern mesh of a face may have at most this many times the quads the size map asks for
  /// (the sum over the background triangles of area / s^2); patterns.max_quads is set from it per
  /// face. 0 (the default): no bound, as in paper 000 Sec. 6.1.2 and Gmsh, which keep a fill on
  /// its quality alone. Measured ratios of the pattern meshes kept at size factor 0.02: Block 11
  /// faces below 1, 146 in 1-1.5, 141 in 1.5-2, 15 in 2-3 (fine boundaries make structured fills
  /// finer than the size map inside). A bound of 3 (the default until the sixteenth session) kept
  /// A319's trailing-edge strips and one-corner leaves on the unstructured path at fine sizes (72
  /// of 83 faces by patterns at size factor 0.0007, 75 without); at the reference vertex counts,
  /// 0.01 and 0.02 the six shared models give the same numbers either way, within 2 faces and
  /// 0.3% of the vertices (docs/benchmarks.md).
  double pattern_max_quad_ratio = 0.0;
  /// ... but never below this many quads: on a face the size map gives a handful of quads the
  /// ratio means nothing (Block's triangles 215 and 307 ask for about 2 quads, and their 7-quad
  /// triangle fill, the same mesh as the unstructured path's, was refused on count).
  std::int64_t pattern_min_quad_bound = 64;
  /// A face whose pattern mesh was refused on quality alone (valid, but at or below
  /// patterns.min_sicn or patterns.min_sicn_avg) gets it after all when it is no worse than what
  /// the unstructured path and the topological steps made of the face: SICN min and avg each at
  /// least theirs minus this tolerance, and no more interior irregular vertices (paper 000 Sec.
  /// 6.1.1 keeps a pattern mesh when its quality is better than the mesh it replaces). The
  /// pattern mesh is also taken when the unstructured path gave no valid all-quad mesh; a face
  /// refused only on the quad bound then gets its fill laid out without the bound and taken when
  /// valid (t20_data's cusp slivers at size factor 0.01). A face refused on the quad bound whose
  /// unstructured mesh has more quads than the bound gets its fills of at most that many quads
  /// laid out, compared as above (wing_fuselage's blunt trailing edges at size factor 0.02: grids
  /// [2, 48, 2, 48] instead of 101 quads with 3 irregular vertices). All count as meshed by
  /// patterns after the comparison (QuasiReport).
  /// Negative: never. On Block.stp the faces this takes are small triangles (three or seven quads)
  /// that both paths mesh alike.
  double pattern_compare_tolerance = 0.01;
  /// Stage::QuasiStructured: cavity remeshing of the unstructured faces (Sec. 6.2).
  qstruct::CavityOptions cavities;
  /// Stage::QuasiStructured: a second pass of the topological steps on a face whose first pass
  /// (with `cavities`) left at least second_pass_min_unnecessary interior irregular vertices that
  /// no singularity asks for: the steps run again from the face's unstructured mesh with these
  /// looser options (loose_cavity_options), and the face keeps the second result when it has
  /// fewer interior irregular vertices and, per vertex removed, costs at most
  /// second_pass_sicn_per_irregular of the face's mean SICN and second_pass_sicn_sum_per_irregular
  /// of its SICN summed over its quads, its minimum not below min(good_sicn, keep_ratio x the
  /// first's) (second_pass_wins). The remeshing's path depends on which replacement it accepts
  /// first, and neighbouring size factors swing by a third (wing_fuselage's fuselage and wing-tip
  /// faces, 65-99 interior irregular vertices across its window; docs/benchmarks.md, issue 29).
  /// The looser options everywhere lower the mean SICN on every model (mambo_s34 0.984 -> 0.982
  /// for no fewer irregular vertices); per face, under the two costs, only faces that gain take
  /// them. The sum bound (12: a removed irregular vertex may cost twelve quads 0.1 of SICN each,
  /// say) keeps mambo_s34's 5.9k-quad face 38 (4 fewer for 0.97 -> 0.93) and t20_data's face 0
  /// (2 fewer for 0.951 -> 0.941) on their first pass. Faces of more than
  /// second_pass_max_quads quads (after the first pass; 0: no bound) are not tried: the sum bound
  /// lets a second pass through there only for a mean loss of a few thousandths, and there it
  /// costs most (mambo_s34, with maximal cavities of 3000 quads in the second pass: the
  /// improvement stage 12.7 s against 3.2 s with the bound 4000, for 250 against 254 interior
  /// irregular vertices).
  /// second_pass_sicn_per_irregular <= 0: off.
  qstruct::CavityOptions second_pass_cavities = loose_cavity_options();
  double second_pass_sicn_per_irregular = 0.02;
  double second_pass_sicn_sum_per_irregular = 12;
  std::int64_t second_pass_min_unnecessary = 2;
  std::int64_t second_pass_max_quads = 4000;
  /// Stage::QuasiStructured: disk remeshing of the defects of the unstructured faces (Sec. 6.3).
  remesh::DiskRemeshOptions disk;
  /// Stage::QuasiStructured: a last smoothing (Sec. 5.3) of each face the topological steps
  /// changed, boundary locked; the smoother keeps its result only when the minimum SICN does not
  /// drop. The cavity and disk steps smooth only around each replacement. Measured at size factor
  /// 0.02: SICN avg mambo 0.920 -> 0.922, t20 0.881 -> 0.884, wing_fuselage 0.873 -> 0.878, Block
  /// 0.884 -> 0.885 (min 0.093 -> 0.099) for 0.06-0.5 s; 30 iterations instead of 10 add nothing.
  bool final_smoothing = true;
  smooth::SmoothOptions final_smooth;
  /// Stage::QuasiStructured, after the final smoothing: the quads still below lift.target are
  /// lifted one patch at a time (smooth::lift_poor_quads; target 0: off). The poor quads the
  /// smoother leaves have one angle near 180 degrees at a curve vertex (issue 29).
  smooth::LiftOptions lift;
  /// Stage::QuasiStructured: a face whose unstructured mesh has more quads than this is improved
  /// in pieces, each a task of its own (ImproveSettings::task_quads; 0: never). A fixed count,
  /// not a share of the ranks' work, so that the mesh does not depend on the rank count.
  std::int64_t task_quads = kDefaultTaskQuads;
  /// Stage::QuasiStructured: a face improved in pieces is then improved once more whole, as a
  /// task of a third round (ImproveSettings::whole_pass_after_cuts).
  bool whole_pass_after_cuts = true;
  /// Stage::QuasiStructured: a whole face of at most second_pass_max_quads quads whose
  /// unstructured mesh has at least this many interior irregular vertices has its second pass
  /// dealt as a task of its own, beside its first (ImproveSettings::second_pass_task_irregular;
  /// 0: never). The mesh is the same either way.
  std::int64_t second_pass_task_irregular = kDefaultSecondPassTaskIrregular;
  /// Quad stages: the per-face method (`--method`). Holomorphic and Auto also mesh each face whose
  /// background triangulation is a topological annulus from its holomorphic 1-form (paper 004,
  /// holomorphic::mesh_annulus) and choose between that and the default mesh with
  /// holomorphic::keep_holomorphic (choose_face_method); a face where the construction fails
  /// keeps the default mesh, the reason in QuasiReport::holomorphic.
  holomorphic::Method face_method = holomorphic::Method::Default;
  holomorphic::HolomorphicOptions holomorphic;
  /// Method::Auto: how much lower the holomorphic mesh's SICN min and avg may each be than the
  /// default mesh's (it must have fewer interior irregular vertices).
  double holomorphic_sicn_tolerance = 0.02;
  /// With face_method Holomorphic or Auto (`--smooth-groups`): faces joined across smooth curves
  /// (holomorphic::smooth_face_groups) are meshed as one surface (holomorphic::mesh_group), each
  /// group on one rank (the partition moves a group's faces to the rank of its first face). The
  /// counts of a group's outer loops come from its optimised form's periods
  /// (holomorphic::balanced_loop_counts), prescribed to the quantization like `--curve-edges`
  /// where it can meet them and the group meshes on them (a trial in the quantize stage);
  /// the group's quads cross its inner curves and go to the face that holds their centre. The
  /// face policy (holomorphic::keep_holomorphic, the group against its faces' own meshes taken
  /// together) decides; a group not kept keeps its faces' meshes, the reason in
  /// QuasiReport::holomorphic.
  bool smooth_groups = false;
  holomorphic::GroupOptions groups;
  /// Paper 003 (fieldmesh::face_method per face): faces of `given_fields` (--cross-field; null:
  /// none) are meshed from their field, the others from the mesher's own cross field when
  /// `separatrix_method` (--method separatrix); a valid result replaces the face's default mesh.
  const fieldmesh::GivenFields* given_fields = nullptr;
  bool separatrix_method = false;
  fieldmesh::FieldMeshOptions fieldmesh;
  /// The `distance` stage before the gather: PipelineResult::max_distance_to_cad of the final
  /// mesh, each face's part on its rank and the curves' split over the ranks (the `mesh`
  /// command's statistics; otherwise rank 0 would go through every vertex after the gather).
  bool distance_to_cad = false;
};

struct PipelineResult {
  mesh::SurfaceMesh mesh;                       ///< assembled mesh (rank 0 only)
  std::vector<background::FaceReport> reports;  ///< one per face, by face id (rank 0 only)
  std::vector<CrossFieldOutput> cross_fields;   ///< one per face when requested (rank 0 only)
  std::vector<mesh::FaceMesh> background;  ///< background meshes by face (rank 0, size map only)
  std::vector<sizemap::FaceSizes> face_sizes;  ///< size fields by face (rank 0, size map only)
  sizemap::CurveSizes curve_sizes;      ///< size map on the background curve meshes (every rank)
  quantize::Quantization quantization;  ///< curve edge counts (every rank)
  qstruct::BalanceReport balance;       ///< pattern-aware balancing of those counts (every rank)
  /// Curves refined because a face boundary crossed itself (boundary_repair_rounds), by round.
  std::vector<LO> curves_refined_for_crossings;
  std::vector<mesh::CurveMesh> quantized_curves;       ///< final curve meshes (every rank)
  std::vector<quad::UnstructuredReport> quad_reports;  ///< by face, Stage::Unstructured (rank 0)
  std::vector<QuasiReport> quasi_reports;              ///< by face, Stage::QuasiStructured (rank 0)
  /// By face, quad stages (rank 0): statistics of the face's final mesh, and the wall time spent
  /// on the face in the quad stages (patterns, unstructured, disk remeshing), seconds.
  std::vector<mesh::FaceQuadStats> face_stats;
  std::vector<double> face_seconds;
  /// By face, quad stages (rank 0): the face's time per stage and the dealt stages' keys.
  std::vector<FaceTimes> face_times;
  /// By face, quad stages (rank 0): the regions of the faces meshed from a cross field
  /// (QuasiReport::by_field) as grids of the assembled mesh's vertex ids (fieldmesh::RegionGrid);
  /// empty for the other faces. Their blocks in block-structured output.
  std::vector<std::vector<fieldmesh::RegionGrid>> field_grids;
  std::vector<int> face_rank;  ///< rank that meshed each face (every rank)
  /// The curves stage's rounds split by curve over the ranks, in order (every rank): round 1
  /// samples the curves, round 2 (with SizeOptions::feature_size) lowers their sizes to the small
  /// features and sharp wedges: the first two steps of background::CurveMeshing.
  std::vector<SplitRound> curve_rounds;
  /// With smooth_groups: the first face of each face's group (itself when alone; every rank),
  /// for mesh::check_conformity. Empty otherwise.
  std::vector<LO> face_group;
  /// Wall time (s) each rank spent in the stages split by faces (background to the comparison of
  /// refused pattern fills), its own work without its waits for the others (every rank). Their
  /// spread is the load imbalance of the METIS partition (max / mean, 1 on one rank).
  std::vector<double> rank_busy_seconds;
  /// Time of the improvement's steps (cavity remeshing, disk remeshing, final smoothing) summed
  /// over the faces of all ranks, seconds (every rank). The stage itself is timed as one
  /// ("improvement"): its faces are dealt out dynamically, each face running the three in turn.
  std::array<double, 3> improvement_seconds{};
  /// With PipelineOptions::distance_to_cad: mesh::max_distance_to_cad of the assembled mesh,
  /// model units (every rank); -1 otherwise.
  double max_distance_to_cad = -1;
  StageTimes times;  ///< wall time per stage (max over ranks)
};

/// Runs the pipeline up to options.until on all ranks of `comm` (collective). Stage::Unstructured
/// needs the size map and quantization (options.size_map is then implied): the assembled mesh is
/// the all-quad mesh on the quantized curve meshes. `lane` serialises
/// this rank's PETSc solves (null: Eigen only).
[[nodiscard]] PipelineResult run_pipeline(const Comm& comm, const cad::CadModel& model,
                                          const PipelineOptions& options, const TaskArena& tasks,
                                          Logger& log, linalg::SolverLane* lane = nullptr);

/// Estimated cost of meshing each face (area / size^2), the METIS vertex weights.
[[nodiscard]] std::vector<double> estimate_face_costs(const cad::CadModel& model, double size);

/// Estimated cost of each face's crossfield stage (cross field, singularities, scaling), the
/// partition's second balance constraint: area / e^2, with e the largest edge of the face's
/// background (`size`, or with `field_divisions` > 0 the larger of `size` and the diagonal of the
/// face's bounding box over field_divisions, as background::SizeOptions::field_cap), but nothing
/// (0) for a face that takes the exact-uniform shortcut (cad::planar_with_right_angle_lines) when
/// `exact_uniform` (CrossFieldOptions::exact_uniform) is on, or the revolution shortcut on a
/// cylinder (cad::iso_line_revolution_axis) when `exact_revolution` is; a tenth of it on the
/// other surfaces of revolution that take it (the scaling's one vertex-based solve is left). From
/// the CAD model alone, so it is known before the background stage and the same on every rank.
[[nodiscard]] std::vector<double> estimate_field_costs(const cad::CadModel& model, double size,
                                                       bool exact_uniform = true,
                                                       bool exact_revolution = true,
                                                       double field_divisions = 0);

/// The faces over `nranks` ranks as run_pipeline partitions them: partition_faces with both
/// estimates (also `qsmesh info --partition`, which scripts/simulate_scaling.py replays).
[[nodiscard]] std::vector<int> partition_model_faces(const cad::CadModel& model, double size,
                                                     int nranks, bool exact_uniform = true,
                                                     bool exact_revolution = true,
                                                     double field_divisions = 0);

}  // namespace qsmesh::parallel
