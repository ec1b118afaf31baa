// Shared pieces of the crossfield stages (not installed).
#pragma once

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "qsmesh/crossfield/cross_field.hpp"

namespace qsmesh::crossfield::detail {

inline constexpr double kPi = std::numbers::pi;

/// Angle wrapped into (-pi, pi].
inline double wrap_angle(double a) {
  a = std::remainder(a, 2 * kPi);
  return a <= -kPi ? a + 2 * kPi : a;
}

/// Per-triangle frames and FE coefficients of the glued triangulation.
struct Geometry {
  std::vector<Vec3> normal;  ///< unit normal of each triangle
  std::vector<Vec3> xaxis;   ///< direction of edge tri2edges[t][0]
  std::vector<double> area;
  std::vector<std::array<double, 3>>
      phi;  ///< angle of edge tri2edges[t][k] from xaxis, around normal
  std::vector<std::array<double, 3>> corner;  ///< interior angle at triangles[t][k]
  std::vector<std::array<double, 3>> cot;     ///< cotangent of corner[t][k]
  std::vector<std::array<LO, 2>>
      edge2tris;                     ///< triangles of each edge (second kNoIndex on the boundary)
  std::vector<double> vertex_angle;  ///< sum of incident corner angles per vertex
  std::vector<std::uint8_t> boundary_vertex;  ///< endpoint of a boundary edge
  double diagonal = 0;                        ///< bounding-box diagonal
  double min_edge = 0;
};

Geometry compute_geometry(const FaceCrossField& cf);

/// Absolute 4θ of edge e's cross in the frame of triangle t (k: position of e in tri2edges[t]).
inline double angle_in_triangle(const FaceCrossField& cf, const Geometry& g, LO t, int k) {
  const Vec2& u = cf.u[cf.tri2edges[t][k]];
  return std::atan2(u.v, u.u) + 4 * g.phi[t][k];
}

/// Sec. 3.1: boundary-condition extension and Algorithm 1. Fills fixed_edge, u, u_norm, stats.
void diffuse(FaceCrossField& cf, const Geometry& g, const CrossFieldOptions& options,
             linalg::SolverLane* lane);

/// CrossFieldOptions::exact_uniform: when the glued triangulation is planar and every boundary
/// edge lies along one common cross, fills u (that cross in every edge frame), u_norm, fixed_edge
/// and stats as diffuse() would, and returns true; otherwise leaves cf untouched and returns
/// false. A face without boundary never qualifies.
bool set_exact_uniform_field(FaceCrossField& cf, const Geometry& g);
/// CrossFieldOptions::exact_revolution: when every boundary edge lies along the parallel through
/// its midpoint or across it (within 1e-4 rad on 4x the angle) and no edge midpoint lies on the
/// axis, fills u (the cross of the parallels, seen in every edge frame), u_norm, fixed_edge and
/// stats as diffuse() would, and returns true; otherwise leaves cf untouched and returns false.
bool set_revolution_field(FaceCrossField& cf, const Geometry& g, const cad::RevolutionAxis& axis);

/// Branches of the cross at each triangle barycentre. Fills directions.
void compute_directions(FaceCrossField& cf, const Geometry& g);

/// Whether some cell of the medial subdivision (a vertex cell inside the face, or a triangle cell)
/// has a non-zero index under the crosses cf.u: the field has a singularity inside the face.
[[nodiscard]] bool has_singular_cell(const FaceCrossField& cf, const Geometry& g);

/// Sec. 3.2 and Eq. 2: fills singularities and euler.
void find_singularities(FaceCrossField& cf, const Geometry& g, const CrossFieldOptions& options);

/// Sec. 3.3: fills H and h.
void compute_scaling(FaceCrossField& cf, const Geometry& g, const CrossFieldOptions& options,
                     linalg::SolverLane* lane);

}  // namespace qsmesh::crossfield::detail
