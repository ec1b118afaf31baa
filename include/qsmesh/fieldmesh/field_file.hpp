// The user's cross field (`qsmesh mesh --cross-field FIELD`, paper 003) and the per-face method:
// which faces are meshed from a field by the separatrix partition and which keep the default
// pipeline. Formats: docs/usage.md, "Meshing from a given cross field".
#pragma once

#include <string>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/fieldmesh/field_mesh.hpp"

namespace qsmesh::fieldmesh {

/// Crosses sampled at points of a face: one branch per sample (3D, any length > 0), and the
/// field's interior singular points as the file or the mesher gives them. mesh_face_by_method does
/// not use `singular`: it detects the singular points on the field interpolated from the samples,
/// where that field has them (a point given near the boundary would otherwise be taken for a
/// boundary singular point, see SingularPoint).
struct FieldSamples {
  std::vector<Vec3> positions, directions;
  std::vector<SingularPoint> singular;
};

/// The given field of one face: either singular points (Eq. 2; `points`, possibly empty for a
/// field without singular point) or sampled crosses (`samples`, from a `qsmesh crossfield` file).
struct GivenFaceField {
  LO face = kNoIndex;
  bool sampled = false;
  std::vector<SingularPoint> points;
  FieldSamples samples;
};

struct GivenFields {
  std::string format;                 ///< "singular-points" or "crossfield-vtu"
  std::vector<GivenFaceField> faces;  ///< by increasing face id, each face at most once
  [[nodiscard]] const GivenFaceField* find(LO f) const;
};

/// Reads FIELD: a text file starting with the line `qsmesh-cross-field singular-points 1`, or the
/// VTU file `qsmesh crossfield -o` writes (ASCII or binary data arrays; the cell arrays cad_face
/// and cross_u of its triangles are read, each triangle one sample at its centroid, and its
/// singularity markers, vertex cells with singularity_index +1 / -1, into samples.singular).
/// Throws qsmesh::InputError, one line naming the file and, for text files, the line, when the file
/// cannot be read, is of neither form, or names a face outside [0, num_faces).
[[nodiscard]] GivenFields read_cross_field_file(const std::string& path, LO num_faces);

/// How one face is meshed.
enum class FaceMethod {
  Default,     ///< the pipeline's own stages (patterns, unstructured, improvement)
  GivenField,  ///< paper 003 from the field the user gave for this face
  Separatrix,  ///< paper 003's partition on the mesher's own cross field (--method separatrix)
};

[[nodiscard]] const char* to_string(FaceMethod m);

/// The per-face policy: a face the user gave a field for takes it; otherwise the separatrix
/// partition when `separatrix` (--method separatrix), else the default pipeline. `given` may be
/// null (no --cross-field).
[[nodiscard]] FaceMethod face_method(LO f, const GivenFields* given, bool separatrix);

/// Angles (modulo pi/2, from frame.ref) at the vertices of `tri` of the nearest sample's cross
/// (3D distance; the sample's branch projected on the vertex's tangent plane), then three Jacobi
/// passes of averaging the representation vectors (cos 4 theta, sin 4 theta) over the interior
/// vertices' neighbours, which removes the steps of the nearest-sample field.
[[nodiscard]] std::vector<double> field_from_samples(const mesh::FaceMesh& tri, const Frame& frame,
                                                     const FieldSamples& samples);

/// Face f by paper 003 with `method` (not Default): triangulates the face on its final curve
/// meshes at half their mean edge length, builds the frame and the field (`given` for
/// GivenField, `own` samples of the mesher's field for Separatrix) and calls
/// mesh_face_from_field. Never throws for a face-level failure: report->ok false, stage and
/// reason set, empty mesh.
[[nodiscard]] mesh::FaceMesh mesh_face_by_method(const cad::CadModel& model, LO f,
                                                 std::span<const mesh::CurveMesh> curves,
                                                 FaceMethod method, const GivenFaceField* given,
                                                 const FieldSamples* own,
                                                 const FieldMeshOptions& options,
                                                 linalg::SolverLane* lane, FieldMeshReport* report);

}  // namespace qsmesh::fieldmesh
