// Clean-up of small 3D angles in a face triangulation, after the Delaunay kernel (paper 000
// Sec. 3.1: the background mesh must have no slivers). The kernel works in the (u, v) plane and
// cannot see two configurations that this pass handles in 3D:
//  - around a pole (a degenerate curve collapsed to one vertex) the fan triangles of the kernel are
//    separated by collapsed triangles, so flips that would join two thin fan triangles are never
//    candidates there;
//  - on strongly anisotropic parametrisations the uv centroid of a star is a poor 3D position.
#pragma once

#include <cstdint>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::mesh {

struct ImproveOptions {
  /// Triangles whose smallest 3D angle is below this (degrees) are worked on.
  double target_angle_deg = 20.0;
  /// Rounds of (flips, vertex moves).
  int rounds = 4;
  /// Move interior vertices too (the flips alone are much cheaper: no surface projection).
  bool move_vertices = true;
  /// When the centroids do not help, search the tangent plane around the vertex (costly: surface
  /// projections).
  bool compass_search = true;
};

struct ImproveStats {
  std::int64_t flips = 0;       ///< edges flipped
  std::int64_t moves = 0;       ///< interior vertices moved
  double min_angle_before = 0;  ///< smallest 3D angle of the input, degrees (180 when no triangle)
  double min_angle_after = 0;   ///< of the output
};

/// Raises the smallest 3D angles of a face triangulation by edge flips and interior-vertex moves,
/// each kept only when the smallest angle of the triangles it touches grows and every touched
/// triangle stays valid.
///
/// Takes a FaceMesh as mesh::triangulate_face returns it (triangles only; counterclockwise in uv
/// when `face_reversed` is false, clockwise when true; boundary vertices first; a pole is one
/// vertex), and the face's geometry. Valid means: a triangle without a pole vertex keeps its uv
/// orientation (exact orient2d); a triangle with a pole vertex (where surface.normal vanishes) has
/// its 3D normal along the face normal. Edges used by one triangle (curves, seams) are never
/// flipped and an edge is never flipped into one that already exists; only dim-2 vertices move (to
/// the uv centroid of their neighbours, part of the way there, or the projection of their 3D
/// centroid), with their point re-evaluated on the surface and vclass.param updated.
/// Returns the improved mesh (same vertices in the same order). Deterministic (fixed order, no
/// threads).
[[nodiscard]] FaceMesh improve_small_angles(const FaceMesh& mesh, const cad::FaceGeometry& surface,
                                            bool face_reversed, const ImproveOptions& options = {},
                                            ImproveStats* stats = nullptr);

}  // namespace qsmesh::mesh
