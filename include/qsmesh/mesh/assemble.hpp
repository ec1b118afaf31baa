// Assembly of per-face meshes into one surface mesh with global numbering.
#pragma once

#include <span>

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

/// Assembles the mesh of `model`: corners, curve meshes (`curves`, indexed by curve id) and face
/// meshes (`faces`, indexed by face id; an empty FaceMesh means the face has no mesh). Boundary
/// vertices of faces are identified through their classification, so faces sharing a curve share
/// its vertices; several uv images of one vertex (seams, poles) become one vertex.
/// The result does not depend on how the faces were distributed.
[[nodiscard]] SurfaceMesh assemble(const cad::CadModel& model, std::span<const CurveMesh> curves,
                                   std::span<const FaceMesh> faces);

}  // namespace qsmesh::mesh
