// Second-order (quadratic) quads on the CAD (paper 002 Sec. IV.F's high-order quads, here for the
// final mesh itself): every quad becomes a 9-node quad and every curve bar a 3-node bar, the new
// nodes placed on the CAD entity they belong to.
#pragma once

#include <cstdint>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::highorder {

struct QuadraticReport {
  std::int64_t curve_nodes = 0;  ///< edge nodes on CAD curves
  std::int64_t face_nodes = 0;   ///< edge and centre nodes inside CAD faces
  /// Nodes not on the CAD in the result: left at their straight (linear) position because the
  /// projection went further from it than the edge is long (a wrong branch of a periodic surface,
  /// say), or put back there to keep a quad valid (straightened, below). Their classification
  /// keeps the curve or face they belong to, with parameters NaN.
  std::int64_t unprojected = 0;
  /// Quads whose curved element was not valid (the Jacobian of the 9-node map not positive along
  /// the face normal at every node) and whose face nodes were put back on their straight positions.
  std::int64_t straightened = 0;
  /// Quads then made fully straight, curve nodes included (their edges then leave the curve
  /// between their ends; a sharp CAD corner bends the curve across them), until none is left
  /// folded by its own or a neighbour's straightened nodes.
  std::int64_t curve_straightened = 0;
  /// Quads not valid even with every node straight (their linear quad is not valid).
  std::int64_t invalid = 0;
};

/// Appends the second-order nodes to `mesh` (an assembled all-quad SurfaceMesh: no triangles):
/// the midpoint of every mesh edge and the centre of every quad, projected on the CAD curve
/// (bar edges) or face they lie on, and classified there (dim 1 with the curve parameter, dim 2
/// with (u, v); index kNoIndex; parameters NaN for the nodes left off the CAD, see unprojected).
/// Fills mesh.quad_nodes and mesh.bar_nodes (SurfaceMesh documents their order). Quads whose curved
/// form is not valid get their face nodes back on the straight positions, and then their curve
/// nodes if still not valid. Deterministic whatever the thread count of `tasks`. Throws
/// qsmesh::Error when the mesh has triangles or already has second-order nodes.
QuadraticReport make_quadratic(mesh::SurfaceMesh& mesh, const cad::CadModel& model,
                               const TaskArena& tasks);

/// Whether the 9-node quad `q` (corners, edge midpoints of 0-1, 1-2, 2-3, 3-0, centre) has a
/// positive Jacobian along `normal` at each of its nodes.
[[nodiscard]] bool quad9_valid(const std::array<Vec3, 9>& q, const Vec3& normal);

}  // namespace qsmesh::highorder
