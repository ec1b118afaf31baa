// High-order quads on the CAD (paper 002 Sec. IV.F's high-order quads, here for the final mesh
// itself): every quad becomes a Lagrange quad of order N (2..5, (N + 1)^2 nodes) and every curve
// bar a Lagrange bar of order N (N + 1 nodes), the new nodes placed on the CAD entity they belong
// to.
#pragma once

#include <cstdint>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::highorder {

/// The orders make_high_order accepts.
inline constexpr int kMinOrder = 2;
inline constexpr int kMaxOrder = 5;

struct HighOrderReport {
  int order = 1;
  std::int64_t curve_nodes = 0;  ///< edge nodes on CAD curves
  std::int64_t face_nodes = 0;   ///< edge and interior nodes inside CAD faces
  /// Nodes not on the CAD in the result: left at their straight (linear) position because the
  /// projection went further from it than the edge is long (a wrong branch of a periodic surface,
  /// say), or put back there to keep a quad valid (straightened, below). Their classification
  /// keeps the curve or face they belong to, with parameters NaN.
  std::int64_t unprojected = 0;
  /// Quads whose curved element was not valid and whose face nodes were put again on the face
  /// along its parameter lines (the images of the Coons patch of the quad's sides in (u, v)),
  /// still on the CAD; counted whether or not that made them valid.
  std::int64_t reshaped = 0;
  /// Quads still not valid after that, untangled in parameter space and kept on the CAD: their
  /// curve nodes moved along their curves (between their edge's ends, in order), their face
  /// nodes in (u, v), to raise the smallest scaled Jacobian of the quad and of the quads sharing
  /// an edge with it; counted when it came out valid without folding a neighbour.
  std::int64_t untangled = 0;
  /// Quads whose curved element was not valid (lagrange_quad_valid) and whose face nodes (the
  /// nodes of their edges inside the face and their interior nodes) were put back on their
  /// straight positions.
  std::int64_t straightened = 0;
  /// Quads then made fully straight, curve nodes included (their edges then leave the curve
  /// between their ends; a sharp CAD corner bends the curve across them), until none is left
  /// folded by its own or a neighbour's straightened nodes.
  std::int64_t curve_straightened = 0;
  /// Quads not valid even with every node straight (their linear quad is not valid).
  std::int64_t invalid = 0;
  /// The smallest scaled Jacobian of the final elements (the Jacobian along the linear quad's
  /// normal over the product of its columns' lengths, at the (2N + 1)^2 samples of the validity
  /// check), in [-1, 1].
  double min_scaled_jacobian = 1;
  /// The same over the untangled quads only (1 when there is none).
  double untangled_min_scaled_jacobian = 1;
};

/// Makes `mesh` (an assembled all-quad SurfaceMesh: no triangles, order 1) a mesh of order `order`
/// in [kMinOrder, kMaxOrder], appending the new nodes to mesh.points / mesh.vclass and filling
/// mesh.quad_nodes and mesh.bar_nodes (SurfaceMesh documents their order; every edge's nodes are
/// made once and shared by the elements on it). Nodes at equispaced reference positions:
///  - on a bar, N - 1 nodes at equispaced curve parameters between its ends (checked against the
///    chord; the projection of the chord's points where the parameters lead astray);
///  - on a quad edge inside a face, the chord's equispaced points projected on the face from
///    (u, v) guesses interpolated between its ends (pcurve images chosen next to the quad, so
///    seams do not mislead the guess);
///  - inside a quad, (N - 1)^2 nodes: the transfinite (Coons) interpolation of its four curved
///    sides, projected on the face.
/// An edge whose nodes come out unevenly apart (longest step over 1.25 times the shortest: a
/// surface curved strongly across the edge, a curve's uneven parameter speed) gets them at equal
/// arc lengths along the same curve instead (through which a Lagrange edge does not swing). Face
/// projections that stall next to a singular point of the parametrization (a pole) are started
/// again from the element's corners.
/// Each is classified on its entity (dim 1 with the curve parameter, dim 2 with (u, v); index
/// kNoIndex; parameters NaN for the nodes left off the CAD, see unprojected). Quads whose curved
/// form is not valid first get their face nodes along the face's parameter lines (the surface's
/// images of the Coons patch of the quad's sides in (u, v): still on the CAD, see reshaped); those
/// still not valid are untangled in parameter space (curve nodes along their curves, face nodes
/// in (u, v): still on the CAD, see untangled); those still not valid get their face nodes back on
/// the straight (bilinear) positions, and then their curve nodes. Deterministic whatever the thread
/// count of `tasks`. Throws qsmesh::Error when the mesh has triangles or is already of higher
/// order, and when `order` is out of range.
HighOrderReport make_high_order(mesh::SurfaceMesh& mesh, const cad::CadModel& model, int order,
                                const TaskArena& tasks);

/// The geometric error of a mesh of order > 1 made by make_high_order: the largest distance, in
/// model units, between the Lagrange map of a curved quad (no node put back straight) at the
/// centres of its four corner cells of the node grid ((1 / 2N, 1 / 2N) and its mirror images) and
/// their projections on the quad's CAD face (from the (u, v) of the interior node next to each).
/// Quads with a node off the CAD are skipped (their straight form misses the CAD by about the
/// sagitta, as the linear mesh does). Deterministic; threads by face.
[[nodiscard]] double max_element_distance_to_cad(const mesh::SurfaceMesh& mesh,
                                                 const cad::CadModel& model,
                                                 const TaskArena& tasks);

/// Whether the Lagrange quad of `order` with nodes `nodes` ((order + 1)^2 points in qsmesh's order,
/// mesh::quad_grid_positions) has a positive Jacobian along `normal` at each point of the
/// (2 order + 1) x (2 order + 1) grid of its reference square (its nodes and the points halfway
/// between them).
[[nodiscard]] bool lagrange_quad_valid(int order, const std::vector<Vec3>& nodes,
                                       const Vec3& normal);

/// The point of the Lagrange quad of `order` with nodes `nodes` (as above) at reference position
/// (s, t) in [0, 1]^2 (s along corner 0 -> 1, t along 0 -> 3).
[[nodiscard]] Vec3 lagrange_quad_point(int order, const std::vector<Vec3>& nodes, double s,
                                       double t);

}  // namespace qsmesh::highorder
