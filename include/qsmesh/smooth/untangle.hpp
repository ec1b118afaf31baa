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
  /// Start each patch from its tangent-plane Laplacian (step 1 below), kept when the patch's worst
  /// quad gets better.
  bool laplacian_start = true;
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

struct LiftOptions {
  /// Quads whose SICN is below this seed a lift (0: none).
  double target = 0.1;
  /// The quads within this many rings (vertex adjacency) of a seed form its patch; the free
  /// vertices all of whose quads lie in the patch move, the others stay.
  int rings = 3;
  /// A patch that does not reach the target but gets a tenth of the way there is tried again
  /// with `rings` more rings, up to this (the perforated-plate example at size factor 0.04: two
  /// quads at 0.025 and 0.038 need 6). One that gets less is held by its fixed vertices, which
  /// more room does not change (wing_fuselage's quads against a 0.018 sliver edge).
  int max_rings = 6;
  /// UntangleOptions::polish_sweeps and laplacian_start of each patch. Polishing past the target
  /// costs the mean (Block at 0.02: SICN avg 0.8087 with 5 sweeps, 0.8089 without).
  int polish_sweeps = 0;
  bool laplacian_start = true;
  /// A patch whose minimum rose but stays below the target is kept only when its mean SICN did
  /// not drop (false: kept whenever its minimum rose).
  bool partial_only_free = true;
};

struct LiftStats {
  QualityReport before, after;
  std::int64_t seeds = 0;   ///< patches tried (seed quads still below the target when reached)
  std::int64_t lifted = 0;  ///< patches kept
};

/// Lifts the poor quads of one face mesh (SICN below options.target) one patch at a time, each
/// kept on its own: the shape the smoother leaves is a quad with one angle near 180 degrees at a
/// curve vertex whose face angle it splits very unevenly with its neighbour (a 225-degree hole arc
/// vertex held as 179 / 46), and its opposite corner near 0. The smoothing kernels move the
/// interior vertex towards the middle of its neighbours and never look at the angle at the curve;
/// the untangler's max-min search does, but it judges a whole face by its minimum, so one quad the
/// CAD forces (a cusp) would make it refuse every other lift of the face.
///
/// Takes and returns a FaceMesh as untangle_face does (same topology; dim < 2 vertices and
/// triangle vertices bit-identical). For each quad in order still below the target: its patch (the
/// quads within options.rings rings) is untangled alone (untangle_face with the target, the
/// patch's outer vertices fixed, measured on the quads with a vertex that may move) and kept when
/// it has no more invalid quads and its minimum SICN rose to the target, or rose at all without
/// lowering the patch's mean (partial_only_free); then a larger patch as max_rings says. The
/// quads outside the patch do not change. Every kept patch raises the minimum of the quads it
/// touches, so the face's minimum never drops.
/// Deterministic: fixed order, no threads.
[[nodiscard]] mesh::FaceMesh lift_poor_quads(const mesh::FaceMesh& mesh,
                                             const cad::FaceGeometry& surface,
                                             const LiftOptions& options,
                                             LiftStats* stats = nullptr);

}  // namespace qsmesh::smooth
