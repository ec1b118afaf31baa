// Local untangling of the quads of one CAD face (paper 000 Sec. 5.3, "Non-linear optimization"):
// small patches around invalid quads, free vertices moved on the surface to maximise the minimum
// SICN, boundary locked, measured and rolled back when it does not help.
#pragma once

#include <cstdint>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/smooth/smooth.hpp"

namespace qsmesh::smooth {

struct UntangleOptions {
  /// Quads whose SICN is at most `target` seed the patches (0: only invalid quads). A positive
  /// value also lifts poor but valid quads.
  double target = 0.0;
  /// Each patch is the seed quads grown by `rings` rings of quads (vertex adjacency); when the
  /// result still has quads at or below `target`, the patch grows by `rings` more, up to
  /// `max_rings`.
  int rings = 2;
  int max_rings = 8;
  /// Sweeps over the free vertices of a patch (each sweep gives every vertex one pattern search).
  int sweeps = 60;
  /// Sweeps done after every quad of the patch is above `target` (lifting its minimum further).
  int polish_sweeps = 5;
  /// Wall-clock bound on the whole call (0: none). When it stops a run early the result depends
  /// on timing; leave 0 where reproducibility matters (the iteration bounds always apply).
  double time_budget_s = 0;
};

struct UntangleStats {
  QualityReport before, after;
  std::int64_t seeds = 0;           ///< quads at or below the target on input
  std::int64_t patch_vertices = 0;  ///< free vertices of the last patch optimised
  int rings = 0;                    ///< rings of the last patch optimised (0: nothing to do)
  int sweeps = 0;                   ///< sweeps done, all patches together
  bool rolled_back = false;         ///< the output is the input: the minimum SICN did not improve
  bool timed_out = false;           ///< stopped by time_budget_s
};

/// Untangles the quads of one face mesh.
///
/// Takes a FaceMesh with consistent uv (every point is S(uv); boundary vertices at their pcurve
/// images) and the face's geometry. Free vertices: dim-2 vertices not used by any triangle; the
/// others (dim 0 corners, dim 1 curve vertices, triangle vertices) keep bit-identical point and uv.
/// Quality: SICN (paper 000 Eq. 12) of each quad, -1 for a quad turning against the face normal
/// (orientation of the majority of the quads).
///
/// Method: the patch is the set of free vertices within `rings` quad rings of the seed quads.
///  1) Start: 30 Gauss-Seidel sweeps moving each patch vertex to the mean of its edge neighbours
///     (in the tangent plane, mapped to (u, v) through the first derivatives), kept only when the
///     worst quad of the patch gets better.
///  2) Sweeps in vertex order over the patch; each vertex does a compass (pattern) search in the
///     tangent plane at its position (8 directions, step from a quarter of its shortest incident
///     edge, grown after a success, halved after a failure), each trial mapped to (u, v) and
///     evaluated exactly as S(u, v). The score is a soft minimum (log-sum-exp, sharpness 0.02) of
///     the Eq. 12 corner values of the vertex's quads; a trial is taken when it raises the score
///     and makes no valid quad invalid. Trials stay inside the uv box of the input.
///  3) A patch stops after a sweep that moves nothing, after `sweeps`, `polish_sweeps` sweeps after
///     all its quads passed `target`, when its worst quad gained less than 1e-3 over 10 sweeps, or
///     on the time budget; then the patch grows by `rings` while seeds remain, up to `max_rings`.
/// Every moved vertex ends on the surface at its uv (dim-2 vclass.param updated).
/// The result is returned only when its minimum SICN is larger than the input's and it has no
/// more invalid quads; otherwise the input is returned (stats->rolled_back).
/// Deterministic when time_budget_s is 0: no randomness, fixed order, no threads.
[[nodiscard]] mesh::FaceMesh untangle_face(const mesh::FaceMesh& mesh,
                                           const cad::FaceGeometry& surface,
                                           const UntangleOptions& options,
                                           UntangleStats* stats = nullptr);

}  // namespace qsmesh::smooth
