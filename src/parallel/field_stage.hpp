// Paper 003 in the pipeline (fieldmesh): the faces that fieldmesh::face_method sends to a cross
// field (given by the user, or the mesher's own with --method separatrix) are meshed by the
// separatrix partition after the quantization; each valid result replaces the face's default mesh
// at the end, so a face whose separatrices fail keeps the default pipeline's mesh.
#pragma once

#include <span>
#include <vector>

#include "qsmesh/fieldmesh/field_mesh.hpp"
#include "qsmesh/parallel/face_task.hpp"
#include "qsmesh/parallel/pipeline.hpp"

namespace qsmesh::parallel {

/// One face's paper 003 result (method Default: not tried).
struct FieldFace {
  fieldmesh::FaceMethod method = fieldmesh::FaceMethod::Default;
  fieldmesh::FieldMeshReport report;
  mesh::FaceMesh mesh;
};

/// Serial, on one face: its method, and its mesh by that method on the final curve meshes
/// (`curves`), from the task's cross field for Separatrix (read while the task still holds it).
[[nodiscard]] FieldFace mesh_task_by_field(const FaceTask& task, const cad::CadModel& model,
                                           std::span<const mesh::CurveMesh> curves,
                                           const PipelineOptions& options,
                                           linalg::SolverLane* lane);

/// Serial, on one face: a valid result becomes the task's mesh (QuasiReport::by_field); a failed
/// one leaves the mesh and records the stage and reason (QuasiReport::field_refusal).
void take_field_mesh(FaceTask& task, FieldFace&& face);

}  // namespace qsmesh::parallel
