// Triangle combination into a quad-dominant mesh (paper 000 Sec. 5.2).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <span>
#include <utility>

#include "qsmesh/core/types.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::quad {

struct RecombineOptions {
  /// Quads whose SICN (paper 000 Eq. 12) is not above this are not formed.
  double min_sicn = 0.1;
  /// Weight of the cross-field alignment in the score, in [0, 1]: the score of a candidate quad is
  /// sicn * (1 - w + w * alignment), alignment in [0, 1] (1: every edge along a cross branch,
  /// 0: every edge at 45 degrees). Ignored when no directions are given.
  double alignment_weight = 0.5;
  /// After the greedy pass, triangles left alone are paired by augmenting paths of at most this
  /// many re-paired quads (0: greedy only). Each lone triangle becomes an irregular vertex after
  /// midpoint subdivision.
  int augment_depth = 0;
  /// Quads that augmenting paths may form must have at least this SICN.
  double augment_min_sicn = 0.3;
  /// A quad with a corner on a CAD curve or corner whose two edges both lie on curves (the face
  /// boundary or a curve inside the face) and meet at more than this 3D angle (degrees) is not
  /// formed: midpoint subdivision gives that corner a single sub-quad with about the same angle
  /// (flatter still on a smooth curve, whose full mesh turns half as much per edge), which
  /// smoothing cannot open since its corners stay on the curve. Measured on Block.stp: halved
  /// corners of 174 degrees (quad SICN 0.105) became 177 degrees (SICN 0.052) after subdivision.
  /// 150 rather than 160: on the fuselage nose of wing_fuselage.step a halved corner of about 155
  /// degrees became 167 (SICN 0.033); at the reference vertex counts SICN min goes A319 0.123 ->
  /// 0.214 and wing_fuselage 0.033 -> 0.147, irregular vertices unchanged within 0.02 points
  /// (140 also lifts mambo_s34 0.259 -> 0.379 but adds irregular vertices there at size 0.02).
  double max_fixed_corner_angle_deg = 150.0;
};

struct RecombineStats {
  std::int64_t quads = 0;             ///< quads in the result (input quads included)
  std::int64_t triangles_left = 0;    ///< triangles not combined
  double sicn_min = 0, sicn_avg = 0;  ///< over the quads of the result (0 when none)
};

/// Paper 000 Sec. 5.2: every pair of triangles of `mesh` sharing an edge (an edge used by exactly
/// two triangles of the face; seam copies are distinct vertices, so seams and curves are never
/// crossed) is a candidate quad, scored by its SICN (Eq. 12, mesh::quad_sicn on the 3D points),
/// weighted by its alignment with the cross field when `directions` is not empty. Candidates are
/// selected greedily, best score first (ties: smaller triangle ids first), when both triangles are
/// still free, the SICN is above options.min_sicn and no corner on the curves is flatter than
/// options.max_fixed_corner_angle_deg; then, with options.augment_depth > 0, lone
/// triangles are paired along augmenting paths (breadth first from each lone triangle in id order,
/// through candidates with SICN >= options.augment_min_sicn).
/// `directions`: empty, or one entry per triangle of `mesh`: two unit tangent vectors (the two
/// branches of the cross; the other two are their opposites).
/// Returns the mesh with the same vertices (points, uv, classification unchanged), the input quads
/// followed by the new ones (each oriented like its triangles), and the remaining triangles in
/// their input order. Deterministic. Throws qsmesh::Error when `directions` has the wrong size.
/// `corner_mids` (optional): the corners that subdivision will put at the middle of boundary
/// edges (quad::corner_midpoints, for loops with odd counts), by sorted vertex pair; the angle
/// of a corner on the curves is then measured to that corner, as the sub-quad will have it.
[[nodiscard]] mesh::FaceMesh recombine(
    const mesh::FaceMesh& mesh, std::span<const std::array<Vec3, 2>> directions,
    const RecombineOptions& options, RecombineStats* stats = nullptr,
    const std::map<std::pair<LO, LO>, Vec3>* corner_mids = nullptr);

}  // namespace qsmesh::quad
