#include "field_stage.hpp"

#include "qsmesh/fieldmesh/field_file.hpp"

namespace qsmesh::parallel {

FieldFace mesh_task_by_field(const FaceTask& task, const cad::CadModel& model,
                             std::span<const mesh::CurveMesh> curves,
                             const PipelineOptions& options, linalg::SolverLane* lane) {
  FieldFace out;
  out.method = fieldmesh::face_method(task.face, options.given_fields, options.separatrix_method);
  if (out.method == fieldmesh::FaceMethod::Default) return out;
  // The mesher's field as samples: each background triangle's first branch at its centroid.
  fieldmesh::FieldSamples own;
  const auto* cf = task.cross_field.get();
  if (out.method == fieldmesh::FaceMethod::Separatrix && cf != nullptr &&
      cf->directions.size() == task.background.triangles.size())
    for (std::size_t k = 0; k < cf->directions.size(); ++k) {
      Vec3 c;
      for (LO v : task.background.triangles[k]) c += task.background.points[v] / 3.0;
      own.positions.push_back(c);
      own.directions.push_back(cf->directions[k][0]);
    }
  if (cf != nullptr)
    for (const auto& sg : cf->singularities)
      if (crossfield::is_interior(sg)) own.singular.push_back({sg.position, sg.index});
  const fieldmesh::GivenFaceField* given =
      options.given_fields != nullptr ? options.given_fields->find(task.face) : nullptr;
  out.mesh = fieldmesh::mesh_face_by_method(model, task.face, curves, out.method, given, &own,
                                            options.fieldmesh, lane, &out.report);
  return out;
}

void take_field_mesh(FaceTask& task, FieldFace&& face) {
  if (face.method == fieldmesh::FaceMethod::Default) return;
  task.quasi.field_method = fieldmesh::to_string(face.method);
  if (!face.report.ok) {
    task.quasi.field_refusal = face.report.stage + ": " + face.report.reason;
    return;
  }
  task.quasi.by_field = true;
  task.quasi.field_regions = face.report.regions;
  task.quasi.by_pattern = false;
  task.quad_mesh = std::move(face.mesh);
  task.field_grids = std::move(face.report.grids);
  task.unstructured.ok = true;
  task.unstructured.quads = static_cast<std::int64_t>(task.quad_mesh.quads.size());
  task.unstructured.sicn_min = face.report.stats.sicn_min;
}

}  // namespace qsmesh::parallel
