// Validation of an assembled mesh against its CAD model: conformity and classification.
// Used by the end-to-end tests and the benchmark scripts (paper 000 Sec. 2: "strict respect of
// the CAD features").
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::mesh {

struct ConformityReport {
  std::int64_t edges = 0;  ///< distinct element edges
  /// Edges off the curves that some face using them does not have in exactly 2 of its elements
  /// (two faces may each have one inside: a face given twice, faces sharing two curves).
  std::int64_t interior_edges_bad = 0;
  std::int64_t curve_edges_bad = 0;  ///< curve edges not used once per use of the curve by a face
  std::int64_t orientation_bad = 0;  ///< interior edges traversed the same way by both elements
  std::int64_t degenerate_elements = 0;  ///< elements repeating a vertex
  std::int64_t faces_without_elements = 0;
  [[nodiscard]] bool ok() const {
    return interior_edges_bad == 0 && curve_edges_bad == 0 && orientation_bad == 0 &&
           degenerate_elements == 0 && faces_without_elements == 0;
  }
  [[nodiscard]] std::string summary() const;
};

/// Checks that elements of a face meet edge to edge, that faces meet along the curve meshes and
/// nowhere else, and that each face is consistently oriented. `face_group` (empty: each face
/// alone) gives each face's group of faces meshed as one surface (the first face of its group,
/// holomorphic::mesh_group): within a group, elements of two faces meet edge to edge like those
/// of one face (the group's quads cross its inner curves, which then carry no element edge), and
/// a group rather than each of its faces must have elements.
[[nodiscard]] ConformityReport check_conformity(const SurfaceMesh& mesh, const cad::CadModel& model,
                                                std::span<const LO> face_group = {});

/// Largest distance (model units) between a vertex and its CAD entity evaluated at the vertex's
/// parameters (corner point, C(t), S(u, v)): the maximum of the by-dimension distances below over
/// dimensions 0, 1 and 2.
[[nodiscard]] double max_distance_to_cad(const SurfaceMesh& mesh, const cad::CadModel& model);

/// The same distance over the vertices of `vclass` (positions `points`, same length) whose
/// classification has dimension `dim` alone; 0 where there are none. A maximum does not depend on
/// how the vertices are split, so the assembled mesh's distance is that of its corners, of each
/// curve mesh's interior vertices (below) and of each face mesh's interior vertices, taken on the
/// ranks and tasks that hold them and max-reduced (parallel's `distance` stage; the end-of-run
/// statistics then do not take one rank through every vertex).
[[nodiscard]] double max_distance_to_cad(std::span<const Vec3> points,
                                         std::span<const VertexClass> vclass,
                                         const cad::CadModel& model, int dim);

/// The distance of a curve mesh's interior vertices (the assembled mesh's dimension-1 vertices of
/// that curve: points[i] against C(t[i]), 0 < i < num_edges()).
[[nodiscard]] double max_distance_to_cad(const CurveMesh& curve, const cad::CadModel& model);

}  // namespace qsmesh::mesh
