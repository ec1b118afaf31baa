// Node layouts of the Lagrange quads and bars of order N (SurfaceMesh::order): where each node of
// an element sits on the (N + 1) x (N + 1) grid of its reference square, in the order qsmesh stores
// them and in the orders of the output formats.
#pragma once

#include <array>
#include <vector>

#include "qsmesh/core/error.hpp"

namespace qsmesh::mesh {

/// Grid position (i, j), 0 <= i, j <= order, of each node of a quad of `order` in qsmesh's order
/// (SurfaceMesh::quad_nodes): corners (0, 0), (N, 0), (N, N), (0, N); the nodes of edges 0-1,
/// 1-2, 2-3, 3-0, each in its direction; the interior nodes row by row (i fastest). i runs along
/// corner 0 -> 1, j along 0 -> 3. Precondition: order >= 1.
[[nodiscard]] inline std::vector<std::array<int, 2>> quad_grid_positions(int order) {
  QSMESH_CHECK(order >= 1, "quad nodes: order " << order << " is not positive");
  const int n = order;
  std::vector<std::array<int, 2>> ij{{0, 0}, {n, 0}, {n, n}, {0, n}};
  for (int k = 1; k < n; ++k) ij.push_back({k, 0});
  for (int k = 1; k < n; ++k) ij.push_back({n, k});
  for (int k = 1; k < n; ++k) ij.push_back({n - k, n});
  for (int k = 1; k < n; ++k) ij.push_back({0, n - k});
  for (int j = 1; j < n; ++j)
    for (int i = 1; i < n; ++i) ij.push_back({i, j});
  return ij;
}

/// The same positions in the order of Gmsh's quads of order N (MSH types 10, 36, 37, 38): corners
/// and edge nodes as qsmesh's, then the interior nodes numbered the same way again, ring by ring
/// (the interior of a 25-node quad is a 9-node quad: its corners, its edge nodes, its centre).
[[nodiscard]] inline std::vector<std::array<int, 2>> quad_grid_positions_recursive(int order) {
  QSMESH_CHECK(order >= 1, "quad nodes: order " << order << " is not positive");
  std::vector<std::array<int, 2>> ij;
  for (int lo = 0, hi = order; lo <= hi; ++lo, --hi) {
    if (lo == hi) {
      ij.push_back({lo, lo});
      break;
    }
    ij.insert(ij.end(), {{lo, lo}, {hi, lo}, {hi, hi}, {lo, hi}});
    for (int k = lo + 1; k < hi; ++k) ij.push_back({k, lo});
    for (int k = lo + 1; k < hi; ++k) ij.push_back({hi, k});
    for (int k = lo + 1; k < hi; ++k) ij.push_back({lo + hi - k, hi});
    for (int k = lo + 1; k < hi; ++k) ij.push_back({lo, lo + hi - k});
  }
  return ij;
}

/// The same positions in the order of CGNS QUAD_9 / QUAD_16 / QUAD_25: corners and edge nodes as
/// qsmesh's, then the interior nodes ring by ring, each ring walked counter-clockwise from its
/// corner next to corner 0 (QUAD_25: (1,1), (2,1), (3,1), (3,2), (3,3), (2,3), (1,3), (1,2), then
/// the centre; for QUAD_16 and QUAD_9 the same as Gmsh's).
[[nodiscard]] inline std::vector<std::array<int, 2>> quad_grid_positions_cgns(int order) {
  std::vector<std::array<int, 2>> ij = quad_grid_positions(order);
  ij.resize(static_cast<std::size_t>(4 * order));
  for (int lo = 1, hi = order - 1; lo <= hi; ++lo, --hi) {
    if (lo == hi) {
      ij.push_back({lo, lo});
      break;
    }
    for (int k = lo; k < hi; ++k) ij.push_back({k, lo});
    for (int k = lo; k < hi; ++k) ij.push_back({hi, k});
    for (int k = hi; k > lo; --k) ij.push_back({k, hi});
    for (int k = hi; k > lo; --k) ij.push_back({lo, k});
  }
  return ij;
}

/// The same positions in the order of VTK's Lagrange quadrilateral (cell type 70): corners; the
/// nodes of the edges (0,0)-(N,0), (N,0)-(N,N), (0,N)-(N,N), (0,0)-(0,N), each with i or j
/// increasing (so the last two run against qsmesh's edge direction); the interior row by row.
[[nodiscard]] inline std::vector<std::array<int, 2>> quad_grid_positions_vtk(int order) {
  QSMESH_CHECK(order >= 1, "quad nodes: order " << order << " is not positive");
  const int n = order;
  std::vector<std::array<int, 2>> ij{{0, 0}, {n, 0}, {n, n}, {0, n}};
  for (int k = 1; k < n; ++k) ij.push_back({k, 0});
  for (int k = 1; k < n; ++k) ij.push_back({n, k});
  for (int k = 1; k < n; ++k) ij.push_back({k, n});
  for (int k = 1; k < n; ++k) ij.push_back({0, k});
  for (int j = 1; j < n; ++j)
    for (int i = 1; i < n; ++i) ij.push_back({i, j});
  return ij;
}

/// For each node of a quad in the order `format_positions` lists them, its index in qsmesh's order
/// (corners 0..3, then 4 + its index in SurfaceMesh::quad_nodes of the quad).
[[nodiscard]] inline std::vector<int> quad_permutation(
    int order, const std::vector<std::array<int, 2>>& format_positions) {
  const auto ours = quad_grid_positions(order);
  std::vector<int> at(static_cast<std::size_t>((order + 1) * (order + 1)), -1);
  for (std::size_t k = 0; k < ours.size(); ++k)
    at[static_cast<std::size_t>(ours[k][0] + (order + 1) * ours[k][1])] = static_cast<int>(k);
  std::vector<int> perm;
  perm.reserve(format_positions.size());
  for (const auto& p : format_positions)
    perm.push_back(at[static_cast<std::size_t>(p[0] + (order + 1) * p[1])]);
  return perm;
}

}  // namespace qsmesh::mesh
