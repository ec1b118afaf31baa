// One face's way through the pipeline: what the pipeline reports of a face (QuasiReport,
// ImprovementReport, CrossFieldOutput: their fields declared once, here, and set by the policy
// below or by record()), the record that carries a face's state from stage to stage (FaceTask),
// the stages that act on one record, and the per-face meshing policy of the quasi-structured
// stage (which of a pattern fill and the unstructured mesh a face keeps). All serial and free of
// MPI: run_pipeline deals the records out over threads and ranks and moves what crosses ranks
// (parallel/record.hpp); the policy is tested without mpirun.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/fieldmesh/field_mesh.hpp"
#include "qsmesh/holomorphic/group.hpp"
#include "qsmesh/holomorphic/holomorphic.hpp"
#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/qstruct/cavity.hpp"
#include "qsmesh/qstruct/face_pattern.hpp"
#include "qsmesh/qstruct/patterns.hpp"
#include "qsmesh/quad/unstructured.hpp"
#include "qsmesh/remesh/disk_remesh.hpp"
#include "qsmesh/sizemap/size_map.hpp"

namespace qsmesh::parallel {

// --- What the pipeline reports of a face --------------------------------------------------

/// What the topological improvement (paper 000 Sec. 6.2-6.3) did to one unstructured face. Its
/// fields are declared once, in fields(), each named by its total over the faces in the drivers'
/// --stats: the exchange between ranks, the drivers' totals and their writers go through it, and
/// the improvement fills it with record().
struct ImprovementReport {
  /// Cavity remeshing: interior irregular vertices before it (the unstructured mesh) and after
  /// it, cavities remeshed by step (Steps 1-4 of Sec. 6.2.2).
  std::int64_t irregular_before = 0, irregular_after = 0;
  std::array<std::int64_t, 4> cavities{};
  /// Disk remeshing: defects before/after, cavities replaced.
  std::int64_t defects_before = 0, defects_after = 0, disk_replaced = 0;
  /// Cavity remeshing stopped by CavityOptions::time_budget_s on this face (the mesh reached
  /// then is kept: every accepted step is valid).
  bool time_budget_hit = false;
  /// The face kept the result of the second pass (PipelineOptions::second_pass_cavities).
  bool second_pass_kept = false;

  /// Takes the cavity remeshing's counts (qstruct::remesh_cavities).
  void record(const qstruct::CavityReport& r) {
    irregular_before = r.irregular_before;
    irregular_after = r.irregular_after;
    cavities = r.remeshed;
    time_budget_hit = r.time_budget_hit;
  }
  /// Takes the disk remeshing's counts (remesh::remesh_disk_defects).
  void record(const remesh::DiskRemeshStats& s) {
    defects_before = s.defects_before;
    defects_after = s.defects_after;
    disk_replaced = s.replaced;
  }
  /// Adds the counts of one piece of a face improved in pieces (issue 28): its remeshings, and
  /// with `first_cut` its defects before the disk step (a cut vertex is none; the second cut's
  /// pieces start from the first's result). The face's own counts come from whole_face().
  void add_piece(const ImprovementReport& piece, bool first_cut) {
    for (std::size_t k = 0; k < cavities.size(); ++k) cavities[k] += piece.cavities[k];
    disk_replaced += piece.disk_replaced;
    time_budget_hit = time_budget_hit || piece.time_budget_hit;
    if (first_cut) defects_before += piece.defects_before;
  }
  /// The counts of a face improved in pieces that only the merged face gives (a piece's counts
  /// leave its cut vertices out).
  void whole_face(std::int64_t irregular_start, std::int64_t irregular_end,
                  std::int64_t defects_end) {
    irregular_before = irregular_start;
    irregular_after = irregular_end;
    defects_after = defects_end;
  }
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("irregular_unstructured_before", self.irregular_before);
    visit("irregular_unstructured_after_cavities", self.irregular_after);
    visit("cavities_remeshed_per_step", self.cavities);
    visit("disk_defects_before", self.defects_before);
    visit("disk_defects_after", self.defects_after);
    visit("disk_cavities_replaced", self.disk_replaced);
    visit("faces_time_budget_hit", self.time_budget_hit);
    visit("faces_second_pass_kept", self.second_pass_kept);
  }
};

/// Whether a face keeps the result of the second pass of the topological improvement
/// (PipelineOptions::second_pass_cavities) over the first pass's: it has fewer interior
/// irregular vertices, no more triangles, its SICN minimum is at least min(good_sicn, keep_ratio
/// x the first's) (the acceptance of a cavity replacement, qstruct::CavityOptions), and for
/// each irregular vertex it removes, its mean SICN is lower by at most avg_per_irregular and
/// the SICN summed over the first pass's quads by at most sum_per_irregular (a large face may
/// not spread a small mean loss over thousands of quads). False when avg_per_irregular <= 0
/// (off). Serial, pure.
[[nodiscard]] bool second_pass_wins(const mesh::FaceQuadStats& first,
                                    const mesh::FaceQuadStats& second, double avg_per_irregular,
                                    double sum_per_irregular, double good_sicn, double keep_ratio);

/// Whether a face's second pass of the topological improvement runs after its first
/// (PipelineOptions::second_pass_cavities): the first pass's result (`first`) still has at least
/// `min_unnecessary` interior irregular vertices beyond the `flagged_kept` that singularities ask
/// for, at most `max_quads` quads (0: no bound), and the first pass did not stop at its time
/// budget. Decided on the first pass's result alone, so the second pass may run beside it as its
/// own task and be dropped when this says no (issue 28). Serial, pure.
[[nodiscard]] bool second_pass_applies(const mesh::FaceQuadStats& first, std::int64_t flagged_kept,
                                       bool time_budget_hit, std::int64_t min_unnecessary,
                                       std::int64_t max_quads);

/// How the quasi-structured stage treated one face. Its fields are declared once, in fields(), the
/// countable ones named by their total over the faces in the drivers' --stats (as
/// ImprovementReport).
struct QuasiReport {
  bool by_pattern = false;  ///< meshed by a pattern (Sec. 6.1.2); else by the unstructured path
  std::string pattern;      ///< the pattern's name when by_pattern
  std::string refusal;      ///< why no pattern was kept (qstruct::to_string of the refusal)
  /// by_pattern, but only after the comparison of PipelineOptions::pattern_compare_tolerance
  /// (`refusal` then says why the thresholds refused it first).
  bool by_comparison = false;
  /// A fill kept with a poor mean gave way to the face's clearly better unstructured mesh
  /// (qstruct::unstructured_clearly_better; `refusal` is then UnstructuredBetter).
  bool gave_way = false;
  /// Unstructured faces only (others keep zeros).
  ImprovementReport improvement;
  /// Meshed from its holomorphic 1-form (PipelineOptions::face_method, choose_face_method).
  bool by_holomorphic = false;
  /// With --method holomorphic or auto: "kept", or why the face kept its default mesh.
  std::string holomorphic;
  /// Paper 003 (fieldmesh): meshed from a cross field by the separatrix partition; the method
  /// tried ("given-field", "separatrix", empty: none), the regions of the partition, and why the
  /// face kept the default mesh when it failed ("stage: reason").
  bool by_field = false;
  std::string field_method;
  std::int64_t field_regions = 0;
  std::string field_refusal;

  /// "pattern:<name>" when meshed by a pattern, else empty.
  [[nodiscard]] std::string pattern_method() const {
    return by_pattern ? "pattern:" + pattern : std::string();
  }
  /// Why no pattern was kept (qstruct::Refusal as text); empty when one was.
  [[nodiscard]] std::string pattern_refusal() const { return by_pattern ? std::string() : refusal; }
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("faces_meshed_by_pattern", self.by_pattern);
    visit("pattern", self.pattern);
    visit("pattern_refusal", self.refusal);
    visit("faces_meshed_by_pattern_after_comparison", self.by_comparison);
    visit("faces_fill_gave_way_to_unstructured", self.gave_way);
    visit("improvement", self.improvement);
    visit("faces_meshed_by_holomorphic", self.by_holomorphic);
    visit("holomorphic", self.holomorphic);
    visit("faces_meshed_by_field", self.by_field);
    visit("field_method", self.field_method);
    visit("field_regions", self.field_regions);
    visit("field_refusal", self.field_refusal);
  }
};

/// What the drivers need of a face's cross field, per triangle of its background mesh in the
/// order of the assembled mesh (triangles collapsed at poles excluded, as in assembly).
struct CrossFieldOutput {
  bool ok = false;
  std::string error;
  std::vector<std::array<Vec3, 2>> directions;  ///< two unit branches per triangle
  std::vector<double> u_norm;                   ///< per triangle: mean |U| of its edges
  std::vector<double> H;                        ///< per triangle: mean conformal scaling H
  std::vector<crossfield::Singularity> singularities;
  crossfield::EulerCheck euler;
  int levels = 0, factorizations = 0, solves = 0;
  /// Levels ended by the stall rule (crossfield::CrossFieldStats::stalled_levels).
  int stalled_levels = 0;
  /// Solves of each level run, in order (crossfield::CrossFieldStats::iterations_per_level).
  std::vector<LO> iterations_per_level;
  double seconds = 0;
  std::string solver;  ///< the heat systems' solver (crossfield::CrossFieldStats::solver)
  /// A face whose systems were split over ranks (PipelineOptions: SolverOptions::
  /// distributed_threshold): the ranks, and the rows each assembled of the largest system.
  int solver_ranks = 0;
  std::vector<LO> rows_per_rank;
  /// Every field, once (visit(name, member)): what the ranks exchange (parallel/record.hpp).
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("ok", self.ok);
    visit("error", self.error);
    visit("directions", self.directions);
    visit("u_norm", self.u_norm);
    visit("H", self.H);
    visit("singularities", self.singularities);
    visit("euler", self.euler);
    visit("levels", self.levels);
    visit("factorizations", self.factorizations);
    visit("solves", self.solves);
    visit("stalled_levels", self.stalled_levels);
    visit("iterations_per_level", self.iterations_per_level);
    visit("seconds", self.seconds);
    visit("solver", self.solver);
    visit("solver_ranks", self.solver_ranks);
    visit("rows_per_rank", self.rows_per_rank);
  }
};

/// The driver's view of a face cross field (see CrossFieldOutput).
[[nodiscard]] CrossFieldOutput summarize(const crossfield::FaceCrossField& cf);

/// Where a face's time went, stage by stage (wall seconds of the thread that ran it, on whichever
/// rank), and the keys by which the dealt stages order the faces: what scripts/simulate_scaling.py
/// replays to predict other rank and thread counts. Written per face in --stats (face_stats'
/// "stage_seconds"); fields declared once, in fields().
struct FaceTimes {
  double background = 0;    ///< background triangulation (METIS partition)
  double crossfield = 0;    ///< cross field (METIS partition)
  double sizemap = 0;       ///< the size map's two passes over the face (METIS partition)
  double patterns = 0;      ///< the face's pattern fill (dealt out)
  double unstructured = 0;  ///< the unstructured mesh (METIS partition)
  double improvement = 0;   ///< cavity, disk remeshing, final smoothing (dealt out)
  double compare = 0;       ///< second fill and comparison (METIS partition)
  double distance = 0;      ///< its final mesh's distance to the CAD (METIS partition)
  /// Its output taken for the gather on its own rank: the quad statistics (take_output), before
  /// its record is written (METIS partition: every rank packs its own faces).
  double pack = 0;
  /// The pattern stage deals the faces out by this, largest first (the size map's quads).
  double expected_quads = 0;
  /// The improvement deals its faces out by this, largest first (the unstructured mesh's quads;
  /// 0: the face is not improved).
  std::int64_t improvement_quads = 0;
  /// Bytes of the face's gathered record (its mesh and reports): the size of what crosses ranks
  /// for the face at the gather, and about that of its improvement's input and result.
  std::int64_t bytes = 0;
  /// A face improved in pieces (PipelineOptions::task_quads): the seconds of each piece, the
  /// first cut's k pieces (dealt with the whole faces) then the second cut's k + 1 (dealt after
  /// them), then, where the face was improved whole after them (PipelineOptions::
  /// whole_pass_after_cuts: 2k + 2 entries), that third round's task. Their sum and the cutting
  /// and merging make `improvement`. Empty: one task.
  std::vector<double> improvement_tasks;
  /// A whole face whose two improvement passes were dealt as two tasks at once (ImproveSettings::
  /// second_pass_task_irregular): the seconds of its first pass, then of its second (0 where it
  /// was skipped: its first, ended before on the same rank, did not ask for it). Their sum and
  /// the choice between them make `improvement`. Empty: one task.
  std::vector<double> improvement_passes;
  /// The pattern fill's move search (qstruct::PatternFaceReport: layouts, batches,
  /// search_seconds): the part of `patterns` that its batches split over the threads.
  std::int64_t pattern_layouts = 0;
  std::int64_t pattern_batches = 0;
  double pattern_search = 0;
  /// Lending the search to free ranks (qstruct::PatternFaceReport: layout_seconds,
  /// layout_batches, layout_vectors, lend_ranks, vector_lendable): what the scaling simulation's
  /// helped schedule replays.
  double pattern_layout_seconds = 0;
  std::int64_t pattern_layout_batches = 0;
  std::int64_t pattern_layout_vectors = 0;
  std::int64_t pattern_layout_lend_ranks = 0;
  std::int64_t pattern_vector_lendable = 0;
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("background", self.background);
    visit("crossfield", self.crossfield);
    visit("sizemap", self.sizemap);
    visit("patterns", self.patterns);
    visit("unstructured", self.unstructured);
    visit("improvement", self.improvement);
    visit("pattern_compare", self.compare);
    visit("distance", self.distance);
    visit("pack", self.pack);
    visit("expected_quads", self.expected_quads);
    visit("improvement_quads", self.improvement_quads);
    visit("bytes", self.bytes);
    visit("improvement_tasks", self.improvement_tasks);
    visit("improvement_passes", self.improvement_passes);
    visit("pattern_layouts", self.pattern_layouts);
    visit("pattern_batches", self.pattern_batches);
    visit("pattern_search", self.pattern_search);
    visit("pattern_layout_seconds", self.pattern_layout_seconds);
    visit("pattern_layout_batches", self.pattern_layout_batches);
    visit("pattern_layout_vectors", self.pattern_layout_vectors);
    visit("pattern_layout_lend_ranks", self.pattern_layout_lend_ranks);
    visit("pattern_vector_lendable", self.pattern_vector_lendable);
  }
};

// --- One face's state through the stages ----------------------------------------------------

/// A valid pattern fill that is not (yet) the face's mesh: refused on quality, or kept by the
/// thresholds but with a poor mean (qstruct::fill_to_compare). It waits for the face's final
/// unstructured mesh (compare_refused_fill).
struct RefusedFill {
  mesh::FaceMesh mesh;  ///< empty: none
  std::string pattern;  ///< the pattern's name
  /// Kept by mesh_face_pattern's thresholds and held back for the comparison (fill_to_compare);
  /// false: refused by them.
  bool kept = false;
};

/// One face of this rank, from its background mesh to its final quad mesh. Each stage reads what
/// the earlier ones left and writes its own part; the large per-face data (background mesh,
/// cross field, size map) are released once the unstructured mesh is made (release_fields).
struct FaceTask {
  LO face = kNoIndex;
  mesh::FaceMesh background;  ///< background triangulation (Sec. 3.1)
  /// The face's axis when it lies on a surface of revolution (cad::revolution_axis), for the
  /// cross field's revolution shortcut; set with the background.
  std::optional<cad::RevolutionAxis> axis;
  background::FaceReport background_report;
  CrossFieldOutput field_summary;  ///< when the driver asked for cross fields, or the error met
  std::unique_ptr<crossfield::FaceCrossField> cross_field;  ///< null: none (or released)
  sizemap::FaceSizes sizes;                                 ///< at the background vertices
  /// The cross field's singularities, kept for the cavity remeshing once the field is released.
  std::vector<crossfield::Singularity> singularities;
  mesh::FaceMesh quad_mesh;               ///< the face's quad mesh (pattern fill or unstructured)
  quad::UnstructuredReport unstructured;  ///< of quad_mesh (set from the fill when a pattern)
  QuasiReport quasi;
  RefusedFill refused;
  double seconds = 0;  ///< wall time of the quad stages on this face (s)
  FaceTimes times;     ///< per stage
  /// The face's holomorphic mesh until choose_face_method weighs it (empty: none).
  mesh::FaceMesh holomorphic_mesh;
  holomorphic::HolomorphicReport holomorphic;
  /// Meshed from a cross field (quasi.by_field): the partition's regions as grids of quad_mesh's
  /// vertices (fieldmesh::FieldMeshReport::grids), the face's blocks in block-structured output.
  std::vector<fieldmesh::RegionGrid> field_grids;
  /// A smooth group's mesh (PipelineOptions::smooth_groups), held by the task of the group's first
  /// face: quad_mesh is then the whole group's mesh, group_quad_face the face of each quad, and
  /// its dim-2 vertices are classified on the face they lie on. The other faces of a kept group
  /// have an empty quad_mesh and group_first set to the group's first face.
  std::vector<LO> group_quad_face;
  LO group_first = kNoIndex;
};

/// Background triangulation of task.face (background::mesh_face_background) into task.background
/// and task.background_report, and task.axis.
void mesh_background(FaceTask& task, const cad::CadModel& model,
                     std::span<const mesh::CurveMesh> curves,
                     const background::BackgroundOptions& options);

/// Cross field of the task's background mesh (paper 000 Sec. 3). `summarize`: the driver wants
/// task.field_summary; `keep`: later stages need the field (size map, frontal insertion), kept in
/// task.cross_field (shrunk to what they read when not summarized). A face whose field throws
/// gets field_summary.error (with stage and face id) and no field: later stages fall back.
void compute_cross_field(FaceTask& task, const crossfield::CrossFieldOptions& options,
                         bool summarize, bool keep, linalg::SolverLane* lane);

/// The gathered view of a face: what rank 0 assembles and reports. Every field is exchanged
/// (fields()); parts of stages that did not run stay empty.
struct FaceOutput {
  mesh::FaceMesh mesh;  ///< the final mesh (quad mesh, or background mesh before the quad stages)
  background::FaceReport report;
  CrossFieldOutput cross_field;
  sizemap::FaceSizes sizes;
  quad::UnstructuredReport unstructured;
  QuasiReport quasi;
  mesh::FaceQuadStats stats;  ///< of the quad mesh (quad stages)
  double seconds = 0;
  FaceTimes times;
  std::vector<fieldmesh::RegionGrid> field_grids;  ///< FaceTask::field_grids, of `mesh`
  std::vector<LO> group_quad_face;                 ///< FaceTask::group_quad_face
  LO group_first = kNoIndex;                       ///< FaceTask::group_first
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("mesh", self.mesh);
    visit("report", self.report);
    visit("cross_field", self.cross_field);
    visit("sizes", self.sizes);
    visit("unstructured", self.unstructured);
    visit("quasi", self.quasi);
    visit("stats", self.stats);
    visit("seconds", self.seconds);
    visit("times", self.times);
    visit("field_grids", self.field_grids);
    visit("group_quad_face", self.group_quad_face);
    visit("group_first", self.group_first);
  }
};

/// Moves a finished task's results into its FaceOutput (the quad mesh and its statistics when
/// `quads`, else the background mesh). The task is left empty.
[[nodiscard]] FaceOutput take_output(FaceTask&& task, bool quads);

// --- The quasi-structured policy (paper 000 Sec. 6.1), serial, per face ------------------------

/// A pattern fill of one face as mesh_face_fill makes it, wherever it ran; exchanged whole.
struct PatternFill {
  qstruct::PatternFaceReport report;  ///< refused_mesh kept only for the comparison
  mesh::FaceMesh mesh;                ///< the fill when report.ok
  double seconds = 0;
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("report", self.report);
    visit("mesh", self.mesh);
    visit("seconds", self.seconds);
  }
};

/// Pattern meshing of face f (qstruct::mesh_face_pattern, Sec. 6.1.2) with at most `max_quads`
/// quads (0: no bound). The refused candidate is kept only when `keep_refused` (a comparison will
/// follow) and the fill was refused.
[[nodiscard]] PatternFill mesh_face_fill(const cad::CadModel& model, LO f,
                                         std::span<const mesh::CurveMesh> curves,
                                         std::span<const qstruct::Pattern> patterns,
                                         const qstruct::PatternFaceOptions& options,
                                         std::int64_t max_quads, bool keep_refused);

/// The interior singularities of the face's cross field (acute-corner ones left out: they are
/// no interior irregular vertex); 0 when the task holds no field.
[[nodiscard]] std::int64_t interior_singularities(const FaceTask& task);

/// What a face does with its pattern fill: a fill the thresholds kept becomes the face's mesh
/// (quasi.by_pattern), unless qstruct::fill_to_compare holds it back (a poor mean, or more
/// interior irregular vertices than interior_singularities), when it waits in task.refused
/// (kept) for the unstructured mesh; a refused fill leaves quasi.refusal and, when valid, waits
/// in task.refused as well. Adds the fill's time to task.seconds.
void take_fill(FaceTask& task, PatternFill&& fill, const qstruct::PatternFaceOptions& options);

/// The unstructured path left the face without a valid all-quad mesh (failed, triangles left, or
/// no quads).
[[nodiscard]] bool no_valid_quads(const FaceTask& task);

/// Whether the face needs a pattern fill but has neither: pattern fills replace the unstructured
/// mesh only on faces whose fill was refused on the size map's quad bound (`bound`, 0: none):
///  - a face that the unstructured path could not mesh validly takes the fill whatever its size,
///    if valid (poor quads beat folded ones): returns 0 (no bound);
///  - a face whose unstructured mesh has more quads than the bound (the curve counts forced its
///    size) gets the fills of at most that many quads: returns that count.
/// Otherwise (a pattern mesh, a fill waiting already, another refusal, or an unstructured mesh
/// within the bound): nullopt.
[[nodiscard]] std::optional<std::int64_t> second_fill_bound(const FaceTask& task,
                                                            std::int64_t bound);

/// Keeps the fill of second_fill_bound for the comparison (its report's refused candidate when
/// refused and valid). Adds its time to task.seconds.
void take_second_fill(FaceTask& task, PatternFill&& fill);

/// What compare_refused_fill decided, for the log.
struct FillComparison {
  bool compared = false;  ///< a fill was waiting
  bool kept = false;      ///< it was a kept fill with a poor mean (RefusedFill::kept)
  /// The face had a valid all-quad unstructured mesh, weighed by qstruct::fill_wins (else any
  /// valid fill is taken).
  bool against_unstructured = false;
  bool fill_taken = false;
  std::string pattern;
  mesh::FaceQuadStats fill, unstructured;  ///< unstructured: when against_unstructured
};

/// The comparison after the topological improvement (PipelineOptions::pattern_compare_tolerance,
/// qstruct::fill_wins): a waiting fill replaces the face's mesh when the unstructured path left
/// no valid all-quad mesh, or when fill_wins says so; a kept fill that loses marks
/// quasi.refusal UnstructuredBetter and quasi.gave_way. The fill then counts as by_pattern
/// (by_comparison unless it was a kept one). task.refused is emptied either way.
FillComparison compare_refused_fill(FaceTask& task, double tolerance,
                                    const qstruct::PatternFaceOptions& options);

/// The holomorphic mesh of the task's face (holomorphic::mesh_annulus on its background mesh and
/// its boundary on the final curve meshes `full`) into task.holomorphic_mesh, the report into
/// task.holomorphic; a failure leaves the reason in task.quasi.holomorphic. Needs the background
/// mesh (before the unstructured stage releases it). Depends on the face's data only.
void make_holomorphic_candidate(FaceTask& task, const cad::CadModel& model,
                                std::span<const mesh::CurveMesh> full,
                                const holomorphic::HolomorphicOptions& options);

/// Per-face dispatch once the default mesh is final: the holomorphic mesh replaces task.quad_mesh
/// when holomorphic::keep_holomorphic says so against the default mesh's statistics (or the
/// default path left no valid all-quad mesh); task.quasi records it (by_holomorphic, holomorphic:
/// "kept" or why not; a kept one clears by_pattern, by_comparison and pattern). The candidate is
/// released either way. Returns whether it was kept.
bool choose_face_method(FaceTask& task, holomorphic::Method method, double sicn_tolerance);

/// The faces the unstructured path meshes: those without a pattern mesh (take_fill).
[[nodiscard]] bool wants_unstructured(const FaceTask& task);

/// The faces the topological improvement works on: meshed by the unstructured path, all quads,
/// valid.
[[nodiscard]] bool wants_improvement(const FaceTask& task);

}  // namespace qsmesh::parallel
