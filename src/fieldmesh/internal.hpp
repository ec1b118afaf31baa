// Shared by the fieldmesh sources: the face's boundary loops on its triangulation, point location
// and field interpolation in the parameter plane.
#pragma once

#include <cmath>
#include <numbers>
#include <span>
#include <sstream>
#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/fieldmesh/field_mesh.hpp"
#include "qsmesh/mesh/delaunay.hpp"

namespace qsmesh::fieldmesh::detail {

inline constexpr double kPi = std::numbers::pi;

/// A face this module does not handle or a given field it refuses (poles, seams, two boundary
/// points on one vertex): qsmesh::Error with the parts as one line, the reason `--stats` reports
/// in face_stats[].field_refusal, without the source location a failed QSMESH_CHECK adds.
template <class... Parts>
[[noreturn]] void refuse(const Parts&... parts) {
  std::ostringstream os;
  (os << ... << parts);
  throw Error(os.str());
}

/// x wrapped into (-period / 2, period / 2].
inline double wrap(double x, double period) { return x - period * std::round(x / period); }

/// Angle of the tangent vector w at a vertex of frame (ref, normal), counter-clockwise around
/// the normal.
inline double frame_angle(const Vec3& w, const Vec3& ref, const Vec3& normal) {
  return std::atan2(dot(w, cross(normal, ref)), dot(w, ref));
}

/// The loops of the face on its triangulation, counter-clockwise in the parameter plane for the
/// outer one (reversed when the CAD gives them the other way), clockwise for holes.
struct Loops {
  std::vector<mesh::BoundaryLoop> loops;
  std::vector<std::vector<LO>> tri;            ///< tri[l][i]: vertex of the triangulation
  std::vector<std::vector<double>> angle;      ///< interior angle (3D, radians) at each point
  std::vector<std::vector<int>> quads;         ///< corners: round(angle / 90 deg) >= 1; else 0
  std::vector<std::vector<double>> turn;       ///< turn of the boundary at each point (radians)
  std::vector<std::vector<double>> transport;  ///< frame change along edge i -> i + 1
  std::vector<std::vector<double>> tangent;    ///< theta_N at each point (Sec. 2.4, see .cpp)
  /// given[l][i]: a boundary singular point of the user (Sec. 2.5); quads then come from its index
  std::vector<std::vector<char>> given;
  bool uv_reversed = false;  ///< the CAD loops ran clockwise in the parameter plane
};

/// A boundary singular point of the user: vertex of the face's triangulation, index d / 4.
struct BoundaryPoint {
  LO vertex = kNoIndex;
  int d = 0;
};

/// Throws qsmesh::Error when a loop point has no vertex of `tri` (seams, poles), or when a
/// boundary point is not a loop point. Loop points are corners with round(angle / 90 deg) quads
/// (at least 1) at CAD vertices, and with 2 - d quads (I = d / 4 by Eq. 15, replacing Table 1) at
/// the `boundary` points.
[[nodiscard]] Loops face_loops(const cad::CadModel& model, LO f,
                               std::span<const mesh::CurveMesh> curves, const mesh::FaceMesh& tri,
                               const Frame& frame, std::span<const BoundaryPoint> boundary = {});

/// The given singular points split into interior ones and boundary ones (paper 003 Sec. 2.5): a
/// point (projected on the surface) nearer to a boundary edge of `tri` than a quarter of the
/// edge's length is on the boundary, at the nearer end of that edge (a curve vertex: the curve
/// meshes are fixed). Throws qsmesh::Error when two points land on one vertex.
struct SplitPoints {
  std::vector<SingularPoint> interior;
  std::vector<BoundaryPoint> boundary;
};
[[nodiscard]] SplitPoints split_points(const mesh::FaceMesh& tri, const cad::FaceGeometry& surface,
                                       std::span<const SingularPoint> points);

/// Table 1 of paper 003: index of a boundary point from the number of quads its angle asks for.
inline double corner_index(int quads) { return quads == 0 ? 0.0 : (2 - quads) / 4.0; }

/// Point location in the parameter plane over the triangles of `tri` (uniform grid).
class Locator {
 public:
  explicit Locator(const mesh::FaceMesh& tri);
  /// Triangle containing uv (kNoIndex outside), barycentric coordinates in `bary`.
  [[nodiscard]] LO locate(const Vec2& uv, std::array<double, 3>& bary) const;

 private:
  const mesh::FaceMesh& tri_;
  Vec2 lo_, cell_;
  int nu_ = 1, nv_ = 1;
  std::vector<std::vector<LO>> bins_;
};

/// The field at a point of the parameter plane: angle from the interpolated frame.
struct FieldSample {
  bool inside = false;
  double theta = 0;
  Vec3 ref, normal;
  double magnitude = 0;  ///< |interpolated representation vector| (small near singularities)
};

[[nodiscard]] FieldSample sample_field(const Locator& locator, const mesh::FaceMesh& tri,
                                       const Frame& frame, std::span<const double> theta,
                                       const Vec2& uv);

/// The parameter-plane step whose image is the tangent vector w at uv (least squares on dS).
[[nodiscard]] Vec2 uv_direction(const cad::FaceGeometry& surface, const Vec2& uv, const Vec3& w);

}  // namespace qsmesh::fieldmesh::detail

namespace qsmesh::fieldmesh::detail {

/// Compatibility of theta on the loops (Eqs. 11, 16, 17).
[[nodiscard]] Compatibility compatibility(const Loops& loops, std::span<const double> theta);

/// Paper 003 Eqs. 14 and 18-20: theta + psi + phi at every vertex, psi the hole correction built
/// by Eq. 2 around a point of each hole, phi harmonic (cotangent Laplacian) with the boundary
/// values of Eq. 19, corner jumps by Eq. 15. Precondition: compat.ok.
[[nodiscard]] std::vector<double> align_field(const mesh::FaceMesh& tri, const Loops& loops,
                                              std::span<const double> theta,
                                              const Compatibility& compat,
                                              const linalg::SolverOptions& solver,
                                              linalg::SolverLane* lane);

}  // namespace qsmesh::fieldmesh::detail
