// Paper 004 (Sec. 4, Alg. 1: basis, Eqs. 4.3-4.8; energy, Eqs. 4.9-4.11; patches) on a group of
// CAD faces: faces joined across curves where the surface is smooth form one surface (a T-shaped
// duct made of two pipes and the fillet between them is one pair of pants), their background
// triangulations are glued along the shared curves, and the basis, energy and patches of
// holomorphic.hpp run on the glued triangulation as on one face's (the paper's input is one
// triangulated surface; its vessels are such unions).
//
// The quads of a group cross its inner curves: the form's critical trajectories are where the
// patches end, and a fillet's tangent curves are not among them, so forcing quad edges onto them
// would add the singularities the method exists to avoid. A demanding user of a smooth duct wants
// the fewest singularities and square quads, not the CAD's construction curves in the mesh;
// each quad is then given to the CAD face that holds its centre (GroupMesh::quad_face), for
// output by face. The group's boundary curves (those it shares with faces outside it, or free)
// keep their final curve meshes, so the group stays conforming with its neighbours.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/holomorphic/holomorphic.hpp"
#include "qsmesh/mesh/delaunay.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::holomorphic {

struct GroupOptions {
  /// Two faces join across a curve when their normals (each oriented as its face) differ by at
  /// most this angle (degrees) at every sample point of the curve: G1 within a tolerance. A
  /// fillet's tangent curves differ by 0, a cylinder cut by a plane by 90.
  double max_normal_angle_deg = 10;
  int samples = 9;  ///< points per curve, at equal steps of its parameter, ends excluded
};

/// Whether the surface is smooth across curve c (GroupOptions): cad::smooth_across with the
/// options' tolerance and samples.
[[nodiscard]] bool smooth_across(const cad::CadModel& model, LO c, const GroupOptions& options);

/// The groups of faces joined across smooth curves (connected components): every face is in
/// exactly one group, each group's faces increasing, groups ordered by their first face; a face
/// with no smooth curve is a group of its own.
[[nodiscard]] std::vector<std::vector<LO>> smooth_face_groups(const cad::CadModel& model,
                                                              const GroupOptions& options);

/// A group's background triangulations glued along their shared curves into one triangulation.
struct GluedGroup {
  bool ok = false;
  std::string reason;     ///< why not (a face without triangles, orientations that disagree)
  std::vector<LO> faces;  ///< the group's CAD faces, in the order given
  /// The faces' background meshes one after the other (points, uv, vclass, triangles), face =
  /// faces[0]: vertices of a shared curve appear once per face and carry the same classification,
  /// so poly_annulus merges them as it merges a seam's copies. The triangles of a face whose
  /// orientation disagrees with the first face's are reversed.
  mesh::FaceMesh background;
  std::vector<LO> triangle_part;  ///< index in `faces` of each triangle's face
  std::vector<LO> point_part;     ///< index in `faces` of each point's face
  std::vector<char> reversed;     ///< per face of `faces`: its triangles were reversed
  /// Every face's final loops, each directed as its face's glued triangles run along it, one after
  /// the other: a curve
  /// shared by two faces of the group is traversed both ways, so merge_final treats it as inside
  /// (like a seam), and the cycles left are the group's boundary.
  std::vector<mesh::BoundaryLoop> loops;
  std::vector<LO> loop_part;  ///< index in `faces` of each loop's face
};

/// Glues the background meshes of `faces` (backgrounds[i] of faces[i], all made on the same
/// background curve meshes) with the final loops of each face (loops[i]: face_boundary on the
/// final curve meshes). Orientation: faces are visited across shared curves from faces[0], and a
/// face whose triangles traverse a shared edge in the same direction as a face already visited
/// is reversed. Never throws for a group-level failure (ok false, reason).
[[nodiscard]] GluedGroup glue_group(std::span<const LO> faces,
                                    std::span<const mesh::FaceMesh> backgrounds,
                                    std::span<const std::vector<mesh::BoundaryLoop>> loops);

/// The signed periods of phi around the loops of `surface` (each loop traversed with the surface
/// on its left: they sum to 0 for a closed form). For the optimised form of a poly-annulus whose
/// loops are horizontal, |period| is a loop's length in the form's flat metric, and the loops'
/// counts of a conforming mesh made from it must add up as these do (mesh_poly_annulus).
[[nodiscard]] std::vector<double> loop_periods(const PolyAnnulus& surface,
                                               std::span<const std::complex<double>> phi);

/// Loop counts for a target edge length `size` from the signed periods (loop_periods): each
/// |period| / size rounded to an even count >= 2, then the largest count of the side (positive or
/// negative periods) whose sum is short raised by the difference, so that both sides sum the
/// same (the condition mesh_poly_annulus checks across the critical curves).
[[nodiscard]] std::vector<LO> balanced_loop_counts(std::span<const double> periods, double size);

/// A group's quad mesh.
struct GroupMesh {
  /// All quads, oriented like the glued background; interior vertices are classified on the face
  /// they were placed on (vclass dim 2, entity that face, uv in its parameter plane), boundary
  /// vertices are the final loops' points (uv on the face of the loop that gave them).
  mesh::FaceMesh mesh;
  std::vector<LO> vertex_face;  ///< CAD face whose parameter plane holds uv of each vertex
  std::vector<LO> quad_face;    ///< CAD face that holds each quad's centre (its output face)
};

/// mesh_poly_annulus (b >= 3) or mesh_annulus (b = 2) on a glued group: the points the grids put
/// inside a background triangle are projected on that triangle's face (surfaces[i] for faces[i]).
/// With options.smooth_patches, the interior vertices are then smoothed in 3D (group_sweeps
/// Laplacian sweeps, each move projected on the face of the background triangle nearest it and
/// kept only when the minimum SICN of the vertex's quads does not drop; smooth::smooth_face works
/// in one face's parameter plane).
/// Returns an empty mesh with report->reason on failure, as mesh_poly_annulus; never throws for
/// a group-level failure.
[[nodiscard]] GroupMesh mesh_group(const GluedGroup& group,
                                   std::span<const cad::FaceGeometry* const> surfaces,
                                   const HolomorphicOptions& options, HolomorphicReport* report);

}  // namespace qsmesh::holomorphic
