// The distributed pipeline: curves meshed on every rank, faces partitioned with METIS and meshed
// as TBB tasks on their rank, per-face results gathered on rank 0 and assembled with global
// numbering. The assembled mesh does not depend on the number of ranks or threads.
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
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/qstruct/balance.hpp"
#include "qsmesh/qstruct/cavity.hpp"
#include "qsmesh/qstruct/face_pattern.hpp"
#include "qsmesh/quad/unstructured.hpp"
#include "qsmesh/quantize/quantize.hpp"
#include "qsmesh/remesh/disk_remesh.hpp"
#include "qsmesh/sizemap/size_map.hpp"

namespace qsmesh::parallel {

/// Pipeline stages, in order. QuasiStructured (paper 000 Sec. 6): the simple CAD faces meshed by
/// patterns (Sec. 6.1.2) before the unstructured path meshes the others, whose irregular vertices
/// are then reduced by cavity remeshing (Sec. 6.2) and their defects by disk quadrangulations
/// (Sec. 6.3).
enum class Stage { Background, Unstructured, QuasiStructured };
[[nodiscard]] const char* to_string(Stage s);
/// Parses a stage name; throws InputError listing the valid names.
[[nodiscard]] Stage parse_stage(const std::string& name);

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
  /// [2, 48, 2, 48] instead of 101 quads with 3 irregular vertices). All count in by_comparison.
  /// Negative: never. On Block.stp the faces this takes are small triangles (three or seven quads) that
  /// both paths mesh alike.
  double pattern_compare_tolerance = 0.01;
  /// Stage::QuasiStructured: cavity remeshing of the unstructured faces (Sec. 6.2).
  qstruct::CavityOptions cavities;
  /// Stage::QuasiStructured: disk remeshing of the defects of the unstructured faces (Sec. 6.3).
  remesh::DiskRemeshOptions disk;
  /// Stage::QuasiStructured: a last smoothing (Sec. 5.3) of each face the topological steps
  /// changed, boundary locked; the smoother keeps its result only when the minimum SICN does not
  /// drop. The cavity and disk steps smooth only around each replacement. Measured at size factor
  /// 0.02: SICN avg mambo 0.920 -> 0.922, t20 0.881 -> 0.884, wing_fuselage 0.873 -> 0.878, Block
  /// 0.884 -> 0.885 (min 0.093 -> 0.099) for 0.06-0.5 s; 30 iterations instead of 10 add nothing.
  bool final_smoothing = true;
  smooth::SmoothOptions final_smooth;
};

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
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("irregular_unstructured_before", self.irregular_before);
    visit("irregular_unstructured_after_cavities", self.irregular_after);
    visit("cavities_remeshed_per_step", self.cavities);
    visit("disk_defects_before", self.defects_before);
    visit("disk_defects_after", self.defects_after);
    visit("disk_cavities_replaced", self.disk_replaced);
    visit("faces_time_budget_hit", self.time_budget_hit);
  }
};

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
  double seconds = 0;
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
    visit("seconds", self.seconds);
  }
};

struct PipelineResult {
  mesh::SurfaceMesh mesh;                       ///< assembled mesh (rank 0 only)
  std::vector<background::FaceReport> reports;  ///< one per face, by face id (rank 0 only)
  std::vector<CrossFieldOutput> cross_fields;   ///< one per face when requested (rank 0 only)
  std::vector<mesh::FaceMesh> background;       ///< background meshes by face (rank 0, size map only)
  std::vector<sizemap::FaceSizes> face_sizes;   ///< size fields by face (rank 0, size map only)
  sizemap::CurveSizes curve_sizes;              ///< size map on the background curve meshes (every rank)
  quantize::Quantization quantization;          ///< curve edge counts (every rank)
  qstruct::BalanceReport balance;               ///< pattern-aware balancing of those counts (every rank)
  /// Curves refined because a face boundary crossed itself (boundary_repair_rounds), by round.
  std::vector<LO> curves_refined_for_crossings;
  std::vector<mesh::CurveMesh> quantized_curves;  ///< final curve meshes (every rank)
  std::vector<quad::UnstructuredReport> quad_reports;  ///< by face, Stage::Unstructured (rank 0)
  std::vector<QuasiReport> quasi_reports;  ///< by face, Stage::QuasiStructured (rank 0)
  /// By face, quad stages (rank 0): statistics of the face's final mesh, and the wall time spent
  /// on the face in the quad stages (patterns, unstructured, disk remeshing), seconds.
  std::vector<mesh::FaceQuadStats> face_stats;
  std::vector<double> face_seconds;
  std::vector<int> face_rank;                   ///< rank that meshed each face (every rank)
  /// Wall time (s) each rank spent in the stages split by faces (background to the comparison of
  /// refused pattern fills), its own work without its waits for the others (every rank). Their
  /// spread is the load imbalance of the METIS partition (max / mean, 1 on one rank).
  std::vector<double> rank_busy_seconds;
  /// Time of the improvement's steps (cavity remeshing, disk remeshing, final smoothing) summed
  /// over the faces of all ranks, seconds (every rank). The stage itself is timed as one
  /// ("improvement"): its faces are dealt out dynamically, each face running the three in turn.
  std::array<double, 3> improvement_seconds{};
  StageTimes times;                             ///< wall time per stage (max over ranks)
};

/// Runs the pipeline up to options.until on all ranks of `comm` (collective). Stage::Unstructured
/// needs the size map and quantization (options.size_map is then implied): the assembled mesh is
/// the all-quad mesh on the quantized curve meshes. `lane` serialises
/// this rank's PETSc solves (null: Eigen only).
[[nodiscard]] PipelineResult run_pipeline(const Comm& comm, const cad::CadModel& model,
                                          const PipelineOptions& options, const TaskArena& tasks,
                                          Logger& log, linalg::PetscLane* lane = nullptr);

/// The driver's view of a face cross field (see CrossFieldOutput).
[[nodiscard]] CrossFieldOutput summarize(const crossfield::FaceCrossField& cf);

/// Estimated cost of meshing each face (area / size^2), the METIS vertex weights.
[[nodiscard]] std::vector<double> estimate_face_costs(const cad::CadModel& model, double size);

}  // namespace qsmesh::parallel
