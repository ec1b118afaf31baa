// Element quality measures and mesh statistics (paper 000 Eq. 12 for SICN).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::mesh {

/// Signed inverse condition number of a quad (paper 000 Eq. 12): the minimum over the four corners
/// of 2 (L_{i-1} x L_i).N / (|L_{i-1}|^2 + |L_i|^2), with N the normalised sum of the four corner
/// cross products. 1 for a square, <= 0 for a folded or non-convex quad.
[[nodiscard]] double quad_sicn(const std::array<Vec3, 4>& q);

/// The terms of quad_sicn at each corner i of q, computed once for callers that need them as well
/// as the SICN (the smoother's orientation test, the untangler's corner values):
/// n[i] = (q[i+1] - q[i]) x (q[i-1] - q[i]), denom[i] = |q[i+1] - q[i]|^2 + |q[i-1] - q[i]|^2, and
/// sum = n[0] + n[1] + n[2] + n[3] (the quad's area vector, twice its area for a planar quad).
struct QuadCorners {
  std::array<Vec3, 4> n;
  std::array<double, 4> denom;
  Vec3 sum;
};
// Defined here so that the smoother's and the untangler's inner loops inline them (they were a
// tenth of the run on Block.stp as calls returning the 136-byte QuadCorners through memory).
[[nodiscard]] inline QuadCorners quad_corners(const std::array<Vec3, 4>& q) {
  QuadCorners c;
  c.sum = Vec3{};
  for (int i = 0; i < 4; ++i) {
    const Vec3 prev = q[(i + 3) % 4] - q[i];
    const Vec3 next = q[(i + 1) % 4] - q[i];
    c.n[i] = cross(next, prev);
    c.denom[i] = norm2(prev) + norm2(next);
    c.sum += c.n[i];
  }
  return c;
}

/// quad_sicn from the terms of quad_corners(q): the same value, bit for bit.
[[nodiscard]] inline double quad_sicn_from(const QuadCorners& c) {
  const double ns = norm(c.sum);
  if (!(ns > 0)) return -1.0;
  const Vec3 normal = c.sum / ns;
  double worst = std::numeric_limits<double>::max();
  for (int i = 0; i < 4; ++i) {
    const double v = c.denom[i] > 0 ? 2.0 * dot(c.n[i], normal) / c.denom[i] : -1.0;
    worst = std::min(worst, v);
  }
  return worst;
}

/// Shape quality of a triangle, 4 sqrt(3) area / (sum of squared edge lengths): 1 equilateral,
/// 0 degenerate.
[[nodiscard]] double triangle_quality(const Vec3& a, const Vec3& b, const Vec3& c);

/// The three angles of a triangle, in degrees, at a, b, c.
[[nodiscard]] std::array<double, 3> triangle_angles(const Vec3& a, const Vec3& b, const Vec3& c);

struct MeshStats {
  std::int64_t vertices = 0, triangles = 0, quads = 0, bars = 0;
  /// Vertices not on a CAD curve or corner whose valence differs from the regular one
  /// (4 for a quad mesh, 6 for a triangle mesh).
  std::int64_t irregular_interior = 0;
  std::int64_t interior_vertices = 0;
  double sicn_min = 0, sicn_avg = 0;                ///< over quads (0 when none)
  double tri_quality_min = 0, tri_quality_avg = 0;  ///< over triangles (0 when none)
  /// Triangles by their smallest 3D angle: [0,5), [5,10), [10,20), [20,30), [30,60] degrees.
  std::array<std::int64_t, 5> min_angle_histogram{};
  double min_angle_deg = 0;  ///< smallest triangle angle (degrees)
  /// Among the triangles with an angle below 10 degrees, those inside the wedge of a CAD corner
  /// whose angle in that face is itself below 10 degrees: every vertex is that corner or lies on
  /// one of the two curves forming it (no triangle there can do better than the wedge allows).
  std::int64_t small_angle_at_sharp_corner = 0;
  /// Quads with SICN (Eq. 12) below kPoorSicn (0.1): flat or nearly folded.
  std::int64_t quads_sicn_below_0_1 = 0;
  /// Of those, the quads with a vertex at a CAD corner whose angle in the quad's face (the sum of
  /// the face's element angles there, 3D) is below kForcingCornerDeg: a quad there reaches SICN
  /// sin(angle) at best (below 0.14 under 8 degrees), so the corner, not the mesher, makes it poor.
  std::int64_t quads_sicn_below_0_1_forced_by_corner = 0;
  /// The others (quads_sicn_below_0_1 less the forced ones) by CAD face: one entry per face
  /// (SurfaceMesh::num_cad_faces), by quad_face; empty without quads or quad_face.
  std::vector<std::int64_t> face_quads_sicn_below_0_1;
};

/// The SICN below which compute_stats counts a quad as poor (MeshStats::quads_sicn_below_0_1).
inline constexpr double kPoorSicn = 0.1;
/// CAD corners sharper than this (degrees, in the face) force poor quads
/// (MeshStats::quads_sicn_below_0_1_forced_by_corner).
inline constexpr double kForcingCornerDeg = 8.0;

/// Statistics of one face's mesh (paper 000 Sec. 5, the per-face report of the quad stages).
struct FaceQuadStats {
  std::int64_t vertices = 0;  ///< FaceMesh vertices (the two copies of a seam vertex count twice)
  std::int64_t quads = 0, triangles = 0;
  /// dim-2 vertices whose element valence is not 4.
  std::int64_t irregular_interior = 0;
  /// Boundary vertices away from their ideal valence in this face: curve vertices (dim 1) with
  /// other than 2 elements per side (a seam vertex: 4 over its two copies), corners (dim 0) with
  /// other than max(1, round(angle / 90 deg)) elements, angle = the sum of their element angles
  /// in this face (3D).
  std::int64_t irregular_boundary = 0;
  double sicn_min = 0, sicn_avg = 0;  ///< over quads (0 when none)
  /// Every field, once (visit(name, member)), named as in the drivers' --stats face_stats; what
  /// the ranks exchange (parallel/record.hpp).
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("vertices", self.vertices);
    visit("quads", self.quads);
    visit("triangles", self.triangles);
    visit("irregular_interior", self.irregular_interior);
    visit("irregular_boundary", self.irregular_boundary);
    visit("sicn_min", self.sicn_min);
    visit("sicn_avg", self.sicn_avg);
  }
};

/// Statistics of a face mesh (FaceMesh: boundary vertices classified dim 0 / 1 with their
/// (entity, index); seam copies share them).
[[nodiscard]] FaceQuadStats face_quad_stats(const FaceMesh& mesh);

/// Statistics of an assembled mesh.
[[nodiscard]] MeshStats compute_stats(const SurfaceMesh& mesh);

}  // namespace qsmesh::mesh
