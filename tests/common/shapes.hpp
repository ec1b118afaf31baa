// OpenCASCADE-built test models shared by the background, parallel and driver tests.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::test {

/// Curve mesh of curve c of `model` with n >= 1 edges at equal parameter steps, its end points
/// exactly the curve's corners.
mesh::CurveMesh uniform_curve_mesh(const cad::CadModel& model, LO c, LO n);

/// Curve meshes of a planar polygon face (write_polygon_face): counts[k] uniform edges on the
/// polygon edge from xy[k] to xy[k + 1]. Throws when a curve of `model` is on no polygon edge.
std::vector<mesh::CurveMesh> polygon_curves(const cad::CadModel& model,
                                            const std::vector<std::pair<double, double>>& xy,
                                            const std::vector<LO>& counts);

/// Writes a 10 x 6 x 4 box with a cylindrical hole (radius 1.5) through it, as BREP; returns path.
std::string write_box_with_hole(const std::string& path);
/// Writes a cylinder (radius 2, height 5): side face with a seam, two disks.
std::string write_cylinder(const std::string& path);
/// Writes a sphere of radius 3: one face, a seam and two degenerate pole curves.
std::string write_sphere(const std::string& path);
/// Writes the octant of a sphere of radius 3 (longitude and latitude 0 to 90 degrees): a spherical
/// triangle whose corner at the north pole ends in a degenerate curve, and three quarter disks.
std::string write_sphere_octant(const std::string& path);
/// Writes a lune of a sphere of radius 3 (a quarter of its longitudes, pole to pole): a face whose
/// loop holds both poles, between two half meridians, and two half disks.
std::string write_sphere_lune(const std::string& path);
/// Writes the planar face (z = 0) bounded by the polygon through `xy`, as BREP; returns path.
std::string write_polygon_face(const std::vector<std::pair<double, double>>& xy,
                               const std::string& path);
/// Writes a planar seven-sided plate, length x width (x along the length), with a slanted end,
/// a notch in one long side and three round holes: no pattern fits it (issue 28's long face).
/// BREP; returns path.
std::string write_long_plate(double length, double width, const std::string& path);
/// Writes the planar teardrop made of a circle of this radius about the origin and the two
/// tangents to it from the point (0, -radius sqrt 2): one corner (90 degrees), smooth elsewhere.
std::string write_teardrop(double radius, const std::string& path);
/// Writes the planar slot made of the segments y = -radius and y = radius for 0 <= x <= length and
/// two half circles closing them: no corner. `arc_first`: the wire starts with the right half
/// circle instead of the bottom segment (the same face, its loop starting elsewhere).
std::string write_stadium(double length, double radius, bool arc_first, const std::string& path);
/// Writes the planar half annulus between the circles of radii `inner` < `outer` about the origin,
/// y >= 0: outer arc, radial segment, inner arc, radial segment (four corners).
std::string write_half_annulus(double inner, double outer, const std::string& path);
/// Writes the planar half disk of this radius about the origin, y >= 0: two curves (the arc and
/// the diameter) joining the same two corners.
std::string write_half_disk(double radius, const std::string& path);
/// Writes the L-shaped prism: the hexagon (0,0) (8,0) (8,3) (3,3) (3,6) (0,6) extruded by 2 along
/// z: two six-sided faces (z = 0 and z = 2) and six rectangles, as STEP.
std::string write_l_prism(const std::string& path);
/// Writes a box with filleted edges (radius 1), as STEP.
std::string write_filleted_box(const std::string& path);
/// Writes three fused pipes of different radii crossing near the origin: radius 1 along x from
/// x = -3, 0.8 along y from y = -3 (axis at z = 0.2), 0.6 along z from z = -3 (axis at x = 0.5),
/// each 6 long. Their intersection curves meet the cylinders' seams and each other, leaving
/// reflex CAD corners on the cylinders (as BREP).
std::string write_pipe_cross(const std::string& path);
/// Writes a T of three plates meeting along one curve (non-manifold: three faces border it): the
/// 4 x 2 rectangles [0, 4] x [0, 2] and [4, 8] x [0, 2] at z = 0 and the upright 2 x 3 one
/// x = 4, 0 <= z <= 3, all bounded by the shared TopoDS edge x = 4, z = 0. The faces are one
/// (non-manifold) shell, as a STEP surface model holds them (a STEP file of a compound of faces
/// would not share their edges); written as BREP, or as STEP when `path` ends in .step or .stp.
std::string write_t_of_three_plates(const std::string& path);
/// Writes a 10 x `depth` x 4 box whose top face (10 x `depth`) appears twice: a second face with
/// the same surface and the same TopoDS edges (another face entity, as a STEP file that repeats a
/// face gives), so each of the top's four curves borders three faces. A shell of seven faces, as
/// BREP (or STEP, by the extension as above).
std::string write_box_with_duplicated_face(double depth, const std::string& path);
/// Writes the rectangle [0, length] x [0, width] at z = 0 twice: two faces on one plane with the
/// same four TopoDS edges, a shell (BREP, or STEP by the extension as above).
std::string write_rectangle_given_twice(double length, double width, const std::string& path);
/// Writes a plate of three coplanar rectangles (z = 0) sharing their TopoDS edges: [0, length] x
/// [0, side], the strip [0, length] x [side, side + strip], and [0, length] x [side + strip,
/// 2 side + strip]. A shell (BREP, or STEP by the extension as above).
std::string write_plate_with_strip(double length, double side, double strip,
                                   const std::string& path);

}  // namespace qsmesh::test
