// Midpoint subdivision of a quad-dominant face mesh into an all-quad mesh (paper 000 Sec. 5.2).
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <utility>

#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::quad {

struct SubdivideStats {
  std::int64_t quads = 0;                 ///< quads of the result
  std::int64_t snaps_reverted = 0;        ///< new face vertices moved back off their uv placement
  std::int64_t flat_boundary_splits = 0;  ///< strips re-triangulated at flat boundary vertices
};

/// The corners that subdivide puts at the middle of boundary edges of `mesh` (where a loop has
/// an odd count up to the corner: see background::halved_face_boundary), by sorted vertex pair
/// of the edge. Empty when every loop of the face has corners on halved vertices only (all
/// counts even). Throws what subdivide throws on an edge it cannot match.
[[nodiscard]] std::map<std::pair<LO, LO>, Vec3> corner_midpoints(
    const mesh::FaceMesh& mesh, const background::HalvedBoundary& boundary);

/// Midpoint subdivision (paper 000 Sec. 5.2): each quad into 4 quads, each triangle into 3.
/// New vertices are the edge midpoints and the element centres.
///  - First, a triangle (A, X, B) whose two edges at the boundary vertex X are boundary edges
///    meeting at more than about 160 degrees (in 3D) would leave X a single sub-quad with that
///    angle, which nothing can make valid. Such triangles form strips along slightly concave
///    boundaries; the strip (grown across its one interior edge, at most 8 triangles) up to the
///    first triangle with a vertex Z inside the face is triangulated again as a fan from Z, when
///    every fan triangle is oriented like the old ones in (u, v). Where a corner goes to the
///    middle of XA or XB (corner_midpoints), the angle is measured to that corner. Counted in
///    stats->flat_boundary_splits; the element counts do not change.
///  - `mesh` is a face mesh whose boundary is `boundary` (background::halved_face_boundary of its
///    face on `full_curves`, the final meshes of all curves, indexed by curve id): its curve
///    vertices carry their index in the full curve mesh.
///  - A boundary edge (used by one element) gets the full vertex its halved segment holds: on
///    curve c, vertex k of full_curves[c] (its t and point exactly, so every face sharing c gets
///    the same point), with uv interpolated along the edge in t and refined by projection; a
///    corner where its loop has an odd count up to it, at its pcurve image (it gets two
///    sub-quads); on a degenerate curve (two copies of one corner), another copy of it.
///    The edge's segment is found by the classification of its ends, the nearest in (u, v)
///    where several match (the banks of a seam). Curve vertices and corners keep their
///    classification.
///  - Interior edge midpoints and centres are placed at the uv midpoint / centroid of the element's
///    corners (uv of the element's own vertex copies: the chart of the element at seams) and
///    evaluated with surface.eval; when such a point leaves an adjacent quad with SICN <= 0, it is
///    moved to the 3D midpoint / centroid projected with surface.project if that is better, and
///    counted in stats->snaps_reverted.
/// Returns an all-quad FaceMesh oriented like the input: the old vertices first (same order), then
/// the edge midpoints, then the centres. Throws qsmesh::Error when a boundary edge matches no
/// segment of `boundary` or a curve vertex lies outside full_curves (inconsistent inputs).
[[nodiscard]] mesh::FaceMesh subdivide(const mesh::FaceMesh& mesh, const cad::FaceGeometry& surface,
                                       std::span<const mesh::CurveMesh> full_curves,
                                       const background::HalvedBoundary& boundary,
                                       SubdivideStats* stats = nullptr);

}  // namespace qsmesh::quad
