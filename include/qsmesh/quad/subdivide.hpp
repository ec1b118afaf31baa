// Midpoint subdivision of a quad-dominant face mesh into an all-quad mesh (paper 000 Sec. 5.2).
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <utility>
#include <vector>

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

/// A parameter line of a surface whose 3D image is a single point: a pole of the
/// parametrization (the apex of a cone, a pole of a sphere, the tip of a surface of revolution
/// whose profile ends on its axis). A pole vertex has an arbitrary uv on its line.
struct PoleLine {
  int fixed = 0;     ///< 0: the line u = value (v runs along it); 1: the line v = value
  double value = 0;  ///< the fixed parameter
  Vec3 point;        ///< the line's 3D image
};

/// The degenerate parameter lines through the parameter points `poles` (the uv of pole vertices,
/// where surface.normal is zero), one per distinct line. At a pole the derivative along the
/// degenerate direction vanishes; the line is kept only when steps of up to +-reach along it
/// move the point by at most 1e-3 of what a step of reach across it moves (reach: a length in
/// (u, v), > 0, such as the extent of the elements at the pole). A pole where neither
/// derivative vanishes (du parallel to dv) has no such line and is left out; none for reach <= 0.
[[nodiscard]] std::vector<PoleLine> degenerate_lines(const cad::FaceGeometry& surface,
                                                     std::span<const Vec2> poles, double reach);

/// The point of `line` that faces an element whose other (regular) corners have the uv centroid
/// `toward`: `toward` moved along the fixed parameter onto the line.
[[nodiscard]] Vec2 pole_image(const PoleLine& line, const Vec2& toward);

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
///  - The centre of an element touching a pole is the 3D centroid projected from the uv centroid
///    of its regular corners (a pole's uv says nothing about where the element is). Where that
///    leaves one of its sub-quads below SICN 0.1 (the projection can land on the boundary: the
///    3D centroid of an element spanning a half of revolution lies on the axis), the uv centroid
///    with each pole corner replaced by its pole_image (toward the regular corners) is tried too,
///    and the better of the two minimum sub-quad SICNs kept.
/// Returns an all-quad FaceMesh oriented like the input: the old vertices first (same order), then
/// the edge midpoints, then the centres. Throws qsmesh::Error when a boundary edge matches no
/// segment of `boundary` or a curve vertex lies outside full_curves (inconsistent inputs).
[[nodiscard]] mesh::FaceMesh subdivide(const mesh::FaceMesh& mesh, const cad::FaceGeometry& surface,
                                       std::span<const mesh::CurveMesh> full_curves,
                                       const background::HalvedBoundary& boundary,
                                       SubdivideStats* stats = nullptr);

}  // namespace qsmesh::quad
