// Assembly of per-face meshes into one surface mesh with global numbering.
#pragma once

#include <span>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::mesh {

/// Global id of a classified boundary or interior vertex, given the numbering of SurfaceMesh:
/// corners [0, nc), then the interior vertices of each curve (curve_offset[c] + index - 1), then
/// interior vertices of faces (face_offset[f] + local interior rank).
struct GlobalNumbering {
  LO num_corners = 0;
  std::vector<GO> curve_offset;  ///< size num_curves + 1
  std::vector<GO> face_offset;   ///< size num_faces + 1
};

/// What a face mesh adds to the assembled mesh, known before the mesh itself reaches the
/// assembling rank (the counts are summed over ranks, the meshes follow one rank at a time).
struct FaceContribution {
  GO interior_vertices = 0;  ///< vertices classified on the face (dim 2)
  GO triangles = 0;          ///< triangles that keep three distinct vertices (see assemble)
  GO quads = 0;
};

/// The counts of `face` (any face mesh in face-local numbering).
[[nodiscard]] FaceContribution face_contribution(const FaceMesh& face);

/// Builds the assembled mesh of `model` face by face, the faces in any order, each written in
/// place (corners, then curve interiors, then face interiors and elements by increasing face id):
/// the result is the same whatever the order, and a face's mesh may be dropped once added. Memory:
/// the assembled mesh, sized exactly from the contributions, plus nothing per face.
class MeshAssembler {
 public:
  /// `curves` indexed by curve id (kept by reference until finish); `contributions[f]` the counts
  /// of the mesh that add_face will be given for face f (face_contribution). Throws Error when
  /// the sizes do not match the model.
  /// `inner_curves` (empty, or one flag per curve): curves that get no bars, those inside a group
  /// of faces meshed as one surface (add_group), whose quads cross them.
  MeshAssembler(const cad::CadModel& model, std::span<const CurveMesh> curves,
                std::span<const FaceContribution> contributions,
                std::span<const char> inner_curves = {});
  /// Adds the mesh of face f (once per face; faces never added stay empty). Throws Error when
  /// its counts differ from the contribution given for f or its classification is out of range.
  /// Returns the assembled mesh's id of each vertex of `face` (its numbering in the result).
  std::vector<GO> add_face(LO f, const FaceMesh& face);
  /// Adds the mesh of a group of faces meshed as one surface (holomorphic::mesh_group): quad q
  /// goes to face quad_face[q], a dim-2 vertex to the face it is classified on (vclass.entity),
  /// so a vertex may be shared by quads of two faces. Every face it names counts as added; the
  /// contributions of those faces must be its quads and interior vertices split that way.
  /// Returns the assembled mesh's id of each vertex of `group`.
  std::vector<GO> add_group(const FaceMesh& group, std::span<const LO> quad_face);
  /// The mesh; throws Error unless every face with a non-zero contribution was added.
  [[nodiscard]] SurfaceMesh finish();

 private:
  const cad::CadModel& model_;
  std::span<const CurveMesh> curves_;
  GlobalNumbering numbering_;
  std::vector<GO> triangle_offset_, quad_offset_;  ///< by face, size num_faces + 1
  std::vector<char> added_;
  SurfaceMesh out_;
};

/// Assembles the mesh of `model`: corners, curve meshes (`curves`, indexed by curve id) and face
/// meshes (`faces`, indexed by face id; an empty FaceMesh means the face has no mesh). Boundary
/// vertices of faces are identified through their classification, so faces sharing a curve share
/// its vertices; several uv images of one vertex (seams, poles) become one vertex, and a triangle
/// left with two equal vertices (at a pole) is dropped. The result does not depend on how the
/// faces were distributed. (MeshAssembler with every face at once.)
[[nodiscard]] SurfaceMesh assemble(const cad::CadModel& model, std::span<const CurveMesh> curves,
                                   std::span<const FaceMesh> faces);

}  // namespace qsmesh::mesh
