// The topological improvement of the unstructured faces (paper 000 Sec. 6.2-6.3 and the final
// smoothing), dealt out across ranks and threads as faces finish (src/parallel only).
#pragma once

#include <array>
#include <atomic>
#include <functional>
#include <span>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/log.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "qsmesh/qstruct/patterns.hpp"
#include "qsmesh/remesh/disk_table.hpp"
#include "qsmesh/smooth/untangle.hpp"

namespace qsmesh::parallel {

/// Calls body(k) once for each k in [0, n), over the threads of every rank together: each free
/// thread takes the next k from a SharedCounter (collective; body may call MPI only through
/// objects that take `comm`'s lock, such as SharedBytes::read). Which rank runs which k depends on
/// timing; the caller keeps results keyed by k and sends them where they belong. `then` (when
/// set) runs once on this rank after its threads found no k left and before the collective end:
/// while other ranks are still in their body (RankLayoutHelpers::serve_until_all_done).
void deal_out(const Comm& comm, std::int64_t n, const TaskArena& tasks,
              const std::function<void(std::int64_t)>& body,
              const std::function<void()>& then = nullptr);

/// Progress of a dealt-out stage as this rank sees it: done() after each item it finished logs
/// "STAGE: d/n faces" on one rank, "STAGE: d faces on rank r (n on all ranks)" on several, at
/// every tenth of n. Thread-safe.
class DealProgress {
 public:
  DealProgress(const char* stage, std::int64_t n, const Comm& comm, Logger& log)
      : stage_(stage), n_(n), rank_(comm.rank()), ranks_(comm.size()), log_(log) {}
  void done();

 private:
  const char* stage_;
  std::int64_t n_;
  int rank_, ranks_;
  Logger& log_;
  std::atomic<std::int64_t> done_{0};
};

/// One face of this rank to improve.
struct ImproveFace {
  LO face = kNoIndex;
  mesh::FaceMesh* mesh = nullptr;  ///< in: the valid all-quad unstructured mesh; out: improved
  std::span<const crossfield::Singularity> singularities;  ///< of the face's cross field
  ImprovementReport* report = nullptr;                     ///< out: what the steps did
  double* seconds = nullptr;                               ///< out: += wall time spent on the face
  /// out (optional): the seconds of each piece task of a face cut into pieces (the first cut's
  /// pieces, then the second's; ImproveSettings::task_quads), appended.
  std::vector<double>* task_seconds = nullptr;
  /// out (optional): the seconds of its first and second pass where they ran as two tasks
  /// (ImproveSettings::second_pass_task_irregular), appended.
  std::vector<double>* pass_seconds = nullptr;
};

/// What the steps take.
struct ImproveSettings {
  std::span<const qstruct::Pattern> patterns;
  const remesh::DiskQuadTable* table = nullptr;
  qstruct::CavityOptions cavities;
  remesh::DiskRemeshOptions disk;
  bool final_smoothing = true;
  smooth::SmoothOptions final_smooth;
  /// After the final smoothing (when on): PipelineOptions::lift.
  smooth::LiftOptions lift;
  /// A face of more quads than this is improved in pieces (0: never; issue 28): cut into k =
  /// ceil(quads / task_quads) pieces by mesh::bisect_quads, each piece a task with its cut
  /// vertices fixed, merged, then cut again halfway between the first cuts (k + 1 pieces, the
  /// end ones half size) and improved again, so that the first cuts end inside pieces. The
  /// result depends on the face and task_quads only, not on ranks or threads.
  std::int64_t task_quads = 0;
  /// After the two rounds of pieces, each cut face runs its cavity and disk steps once more
  /// whole, as a task of a third round (improve_faces; no final smoothing: its pieces had it):
  /// the pieces' cut vertices keep their valence and their cavities stay small, so the irregular
  /// vertices the cuts left are taken back there. false: the face is what the second round's
  /// pieces make it.
  bool whole_pass_after_cuts = true;
  /// The second pass of PipelineOptions (second_pass_cavities, ...): whole faces only (a piece's
  /// count depends on its cuts), never after a face reached its time budget. cost <= 0: off.
  qstruct::CavityOptions second_pass_cavities;
  double second_pass_sicn_per_irregular = 0;
  double second_pass_sicn_sum_per_irregular = 0;
  std::int64_t second_pass_min_unnecessary = 2;
  std::int64_t second_pass_max_quads = 0;  ///< 0: no bound
  /// A whole face whose unstructured mesh has at least this many interior irregular vertices
  /// gets its second pass as a task of its own, dealt beside its first pass (0: never; issue
  /// 28): a face's cavity remeshing costs with its irregular vertices, not its quads, and the
  /// two passes in a row were the longest task of the stage (A319 at 16x: face 18, 2949 quads,
  /// 3.2 s). The second pass starts from the same input either way and the memo the first
  /// pass leaves it only spares work (qstruct::CavityMemo), so the mesh is the same. The second
  /// passes are dealt after every other task: one whose first pass ended on the same rank
  /// without asking for it (second_pass_applies) is skipped; else it runs, and the owner drops
  /// it where the first's result does not ask for it. Not with a time budget (the first pass's
  /// may stop it).
  std::int64_t second_pass_task_irregular = 0;
};

/// Per face, in order: cavity remeshing (Sec. 6.2), disk remeshing of the defects (Sec. 6.3), the
/// final smoothing (when settings.final_smoothing). A step that throws leaves the face's valid
/// mesh as it was (the warning names the face and the step).
///
/// Collective over `comm`. A face's cost is not known before (a few faces of a model take most of
/// the time, whatever their size), so no partition fixed in advance balances it: every rank
/// learns every face's record (id, quads, owner), the faces are taken largest first (quad count,
/// then face id) from a SharedCounter by whichever thread of whichever rank is free, a face taken
/// away from its owner is read from the owner's SharedBytes (its mesh and singularities, that face
/// alone), and each result goes back to the owner alone (Comm::alltoall_bytes). A rank thus holds
/// its own faces plus those it works on, not the model. A face's result depends only on the face,
/// so the mesh is the same whatever the numbers of ranks and threads. One rank: no copies.
/// Faces above settings.task_quads are dealt as pieces instead, in two rounds (the pieces of
/// the first cut with the whole faces, then those of the second cut); their counts in the report
/// are of the whole face (irregular vertices and defects before the first cut and after the
/// second, cavities and disk replacements summed over the pieces).
/// Returns the wall time of the three steps summed over the faces of all ranks (every rank).
std::array<double, 3> improve_faces(const Comm& comm, const cad::CadModel& model,
                                    std::span<ImproveFace> mine, const ImproveSettings& settings,
                                    const TaskArena& tasks, Logger& log);

}  // namespace qsmesh::parallel
