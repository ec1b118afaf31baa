// One face's way through the pipeline: the record that carries its state from stage to stage
// (FaceTask), the stages that act on one record, and the per-face meshing policy of the
// quasi-structured stage (which of a pattern fill and the unstructured mesh a face keeps). All
// serial and free of MPI: run_pipeline deals the records out over threads and ranks and moves
// what crosses ranks (parallel/record.hpp); the policy is tested without mpirun.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "qsmesh/qstruct/face_pattern.hpp"
#include "qsmesh/qstruct/patterns.hpp"
#include "qsmesh/quad/unstructured.hpp"
#include "qsmesh/sizemap/size_map.hpp"

namespace qsmesh::parallel {

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
};

/// Background triangulation of task.face (background::mesh_face_background) into task.background
/// and task.background_report.
void mesh_background(FaceTask& task, const cad::CadModel& model,
                     std::span<const mesh::CurveMesh> curves,
                     const background::BackgroundOptions& options);

/// Cross field of the task's background mesh (paper 000 Sec. 3). `summarize`: the driver wants
/// task.field_summary; `keep`: later stages need the field (size map, frontal insertion), kept in
/// task.cross_field (shrunk to what they read when not summarized). A face whose field throws
/// gets field_summary.error (with stage and face id) and no field: later stages fall back.
void compute_cross_field(FaceTask& task, const crossfield::CrossFieldOptions& options,
                         bool summarize, bool keep, linalg::PetscLane* lane);

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

/// What a face does with its pattern fill: a fill the thresholds kept becomes the face's mesh
/// (quasi.by_pattern), unless its mean is poor (qstruct::fill_to_compare), when it waits in
/// task.refused (kept) for the unstructured mesh; a refused fill leaves quasi.refusal and, when
/// valid, waits in task.refused as well. Adds the fill's time to task.seconds.
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

/// The faces the topological improvement works on: meshed by the unstructured path, all quads,
/// valid.
[[nodiscard]] bool wants_improvement(const FaceTask& task);

}  // namespace qsmesh::parallel
