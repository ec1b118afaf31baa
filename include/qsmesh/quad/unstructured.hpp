// The unstructured all-quad mesh of one CAD face (paper 000 Sec. 5): triangulation of the face on
// the halved quantized curve meshes, triangle recombination, midpoint subdivision onto the full
// curve meshes, smoothing (Sec. 5.3). Not yet the cross-field-guided frontal insertion of Sec. 5.1: the triangulation is
// the Delaunay kernel's frontal refinement with sizes graded from the curve meshes.
#pragma once

#include <span>
#include <string>

#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/quad/recombine.hpp"

namespace qsmesh::quad {

struct UnstructuredOptions {
  double size = 0;  ///< largest final edge length (model units, > 0); the triangulation uses twice it
  RecombineOptions recombine;
};

/// What happened on one face.
struct UnstructuredReport {
  bool ok = false;          ///< an all-quad mesh with every quad valid (SICN > 0)
  bool fell_back = false;   ///< recombination failed or folded a quad: every triangle was subdivided instead
  std::string error;        ///< the error met, with stage and face id
  double sicn_min = 0;      ///< of the face's quads
  std::int64_t quads = 0;
};

/// All-quad mesh of face f. `halved`: curve meshes with half the final edge counts (quantize::
/// place_vertices(..., halved=true)); `full`: the final curve meshes, whose odd vertices the
/// subdivision uses on the boundary. Never throws for a face-level failure: the report says what
/// happened and an empty mesh is returned when nothing valid could be made.
[[nodiscard]] mesh::FaceMesh mesh_face_unstructured(const cad::CadModel& model, LO f,
                                                    std::span<const mesh::CurveMesh> halved,
                                                    std::span<const mesh::CurveMesh> full,
                                                    const UnstructuredOptions& options,
                                                    UnstructuredReport* report);

}  // namespace qsmesh::quad
