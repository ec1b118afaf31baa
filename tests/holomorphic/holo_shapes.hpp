// OpenCASCADE-built poly-annuli for the holomorphic tests and benchmark.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace qsmesh::test {

/// Writes the planar annulus between the circles of radii inner < outer about the origin (z = 0),
/// as BREP; returns path.
std::string write_annulus(double inner, double outer, const std::string& path);

/// Writes the rectangle [0, length] x [0, width] (z = 0) with circular holes {x, y, radius}
/// (inside it, disjoint), as BREP; returns path.
std::string write_plate_with_holes(double length, double width,
                                   const std::vector<std::array<double, 3>>& holes,
                                   const std::string& path);

/// Writes the disk of radius `radius` about the origin (z = 0) with circular holes {x, y, radius}
/// (inside it, disjoint), as BREP; returns path.
std::string write_disk_with_holes(double radius, const std::vector<std::array<double, 3>>& holes,
                                  const std::string& path);

/// Writes write_plate_with_holes' plate with its four corners rounded (radius `corner`, tangent
/// arcs: the outer loop has no sharp corner), as BREP; returns path.
std::string write_rounded_plate_with_holes(double length, double width, double corner,
                                           const std::vector<std::array<double, 3>>& holes,
                                           const std::string& path);

/// Writes a T-shaped duct as an open shell, as BREP; returns path: the lateral surface of the
/// main pipe (radius `main_radius` about the x axis, x in [-half_length, half_length]) fused
/// with a branch (radius `branch_radius` < main_radius about the z axis, z in [0, branch_height]),
/// the junction rounded by a fillet of radius `fillet` (tangent: the three faces meet G1 across
/// the two fillet curves), the end caps removed: three open ends. The main pipe's seam runs
/// along its bottom (z = -main_radius), away from the branch.
std::string write_t_duct(double main_radius, double half_length, double branch_radius,
                         double branch_height, double fillet, const std::string& path);

/// Writes a straight pipe (radius `radius` about the z axis, z in [0, 2 * half_length]) made of
/// two cylindrical faces joined along the circle at z = half_length (two cylinders fused), end caps
/// removed, as BREP; returns path.
std::string write_two_piece_pipe(double radius, double half_length, const std::string& path);

}  // namespace qsmesh::test
