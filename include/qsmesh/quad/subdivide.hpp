// Midpoint subdivision of a quad-dominant face mesh into an all-quad mesh (paper 000 Sec. 5.2).
#pragma once

#include <cstdint>
#include <span>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::quad {

struct SubdivideStats {
  std::int64_t quads = 0;           ///< quads of the result
  std::int64_t snaps_reverted = 0;  ///< new face vertices moved back off their uv placement
  std::int64_t flat_boundary_splits = 0;  ///< strips re-triangulated at flat boundary vertices
};

/// Midpoint subdivision (paper 000 Sec. 5.2): each quad into 4 quads, each triangle into 3.
/// New vertices are the edge midpoints and the element centres.
///  - First, a triangle (A, X, B) whose two edges at the boundary vertex X are boundary edges
///    meeting at more than about 160 degrees (in 3D) would leave X a single sub-quad with that
///    angle, which nothing can make valid. Such triangles form strips along slightly concave
///    boundaries; the strip (grown across its one interior edge, at most 8 triangles) up to the
///    first triangle with a vertex Z inside the face is triangulated again as a fan from Z, when
///    every fan triangle is oriented like the old ones in (u, v). Counted in stats->flat_boundary_splits; the element counts do not change.
///  - `mesh` is a face mesh whose boundary lies on the halved curve meshes
///  (quantize::place_vertices
///    with halved = true); `full_curves` are the full meshes of all curves (halved = false),
///    indexed by curve id, with twice the edges.
///  - A boundary edge (used by one element) on curve c between halved vertices i and i+1 gets
///    vertex 2i+1 of full_curves[c] (its t and point exactly, so every face sharing c gets the same
///    point); its uv is interpolated along the edge in t and refined by projection.
///    Curve vertices keep their classification with index doubled; corners are unchanged.
///    A boundary edge of a degenerate curve (two copies of one corner) gets another copy of it.
///  - Interior edge midpoints and centres are placed at the uv midpoint / centroid of the element's
///    corners (uv of the element's own vertex copies: the chart of the element at seams) and
///    evaluated with surface.eval; when such a point leaves an adjacent quad with SICN <= 0, it is
///    moved to the 3D midpoint / centroid projected with surface.project if that is better, and
///    counted in stats->snaps_reverted.
/// Returns an all-quad FaceMesh oriented like the input: the old vertices first (same order), then
/// the edge midpoints, then the centres. Throws qsmesh::Error when a boundary edge cannot be
/// matched with full_curves (wrong or inconsistent curve meshes).
[[nodiscard]] mesh::FaceMesh subdivide(const mesh::FaceMesh& mesh, const cad::FaceGeometry& surface,
                                       std::span<const mesh::CurveMesh> full_curves,
                                       SubdivideStats* stats = nullptr);

}  // namespace qsmesh::quad
