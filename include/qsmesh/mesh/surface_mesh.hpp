// Mesh data: per-curve and per-face meshes in local numbering, and the assembled surface mesh in
// global numbering. Flat arrays, explicit index types; every vertex carries its CAD classification.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "qsmesh/core/adjacency.hpp"
#include "qsmesh/core/types.hpp"

namespace qsmesh::mesh {

/// CAD classification of a vertex.
///  dim 0: on corner `entity`;
///  dim 1: on curve `entity`, at parameter param[0], vertex `index` of that curve's mesh;
///  dim 2: inside face `entity`, at (u, v) = (param[0], param[1]).
struct VertexClass {
  std::int8_t dim = 2;
  LO entity = kNoIndex;
  LO index = kNoIndex;
  std::array<double, 2> param{0, 0};
};

/// Mesh of one CAD curve: vertices ordered from t0 to t1, both ends included (they are the curve's
/// corners; a closed curve repeats its corner). A degenerate curve has exactly its two end
/// vertices.
struct CurveMesh {
  LO curve = kNoIndex;
  std::vector<double> t;     ///< curve parameters, increasing
  std::vector<Vec3> points;  ///< C(t) (corner points at both ends)
  [[nodiscard]] LO num_edges() const { return static_cast<LO>(t.size()) - 1; }
};

/// Mesh of one CAD face in face-local numbering. Elements are oriented along the face normal.
struct FaceMesh {
  LO face = kNoIndex;
  std::vector<Vec3> points;
  std::vector<Vec2> uv;  ///< parameter-plane position (boundary: the pcurve image)
  std::vector<VertexClass> vclass;
  std::vector<std::array<LO, 3>> triangles;
  std::vector<std::array<LO, 4>> quads;
  [[nodiscard]] LO num_vertices() const { return static_cast<LO>(points.size()); }
};

/// The assembled surface mesh of a model, global numbering: corners first (vertex id = corner id),
/// then interior vertices of the curves by curve id, then interior vertices of the faces by face
/// id. Elements are grouped by face, faces in increasing id; bars are grouped by curve.
struct SurfaceMesh {
  std::vector<Vec3> points;
  std::vector<VertexClass> vclass;
  std::vector<std::array<GO, 3>> triangles;
  std::vector<std::array<GO, 4>> quads;
  std::vector<LO> triangle_face;        ///< CAD face of each triangle
  std::vector<LO> quad_face;            ///< CAD face of each quad
  std::vector<std::array<GO, 2>> bars;  ///< curve edges
  std::vector<LO> bar_curve;            ///< CAD curve of each bar
  /// Order of the elements: 1 linear; 2..5 with the nodes below (highorder::make_high_order).
  int order = 1;
  /// High-order nodes, flat (empty when order is 1). Per quad, quad_nodes_per_quad() =
  /// (order + 1)^2 - 4 nodes after its four corners: the order - 1 nodes of each edge 0-1, 1-2,
  /// 2-3, 3-0 in turn, each edge's in its direction (from its first corner), then the
  /// (order - 1)^2 interior nodes row by row: node (i, j), 0 < i, j < order, at position
  /// (i - 1) + (order - 1) (j - 1), i along corner 0 -> 1 and j along 0 -> 3. For order 2 this is
  /// the order of CGNS QUAD_9, VTK 28 and MSH type 10 after the corners; for higher orders each
  /// writer permutes it. Per bar, its order - 1 interior nodes from bars[b][0] to bars[b][1].
  std::vector<GO> quad_nodes;
  std::vector<GO> bar_nodes;
  [[nodiscard]] int quad_nodes_per_quad() const { return (order + 1) * (order + 1) - 4; }
  [[nodiscard]] int bar_nodes_per_bar() const { return order - 1; }
  LO num_cad_faces = 0;
  LO num_cad_curves = 0;
  LO num_cad_corners = 0;
  /// CAD topology, for writers that record entities (MSH $Entities, CGNS families):
  std::vector<std::array<LO, 2>> curve_corners;  ///< end corners of each curve
  Adjacency face2curves;                         ///< curves bounding each face (each once)
  std::string length_unit = "mm";                ///< unit of the coordinates
  [[nodiscard]] GO num_vertices() const { return static_cast<GO>(points.size()); }
};

/// Sets `to`'s CAD entity counts, curve_corners, face2curves and length_unit to `from`'s: what a
/// mesh made from another on the same model (a coarse layout's, the blocks' patches) shares with
/// it.
inline void copy_cad_topology(const SurfaceMesh& from, SurfaceMesh& to) {
  to.num_cad_faces = from.num_cad_faces;
  to.num_cad_curves = from.num_cad_curves;
  to.num_cad_corners = from.num_cad_corners;
  to.curve_corners = from.curve_corners;
  to.face2curves = from.face2curves;
  to.length_unit = from.length_unit;
}

}  // namespace qsmesh::mesh
