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

}  // namespace qsmesh::test
