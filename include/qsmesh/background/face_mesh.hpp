// Background triangulation of one CAD face (paper 000 Sec. 3.1: the triangulation on which the
// cross field is computed), conforming to the locked curve meshes.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "qsmesh/background/size.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/delaunay.hpp"
#include "qsmesh/mesh/improve.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::background {

struct BackgroundOptions {
  SizeOptions sizes;
  mesh::TriangulateOptions triangulate;
  mesh::ImproveOptions improve;  ///< 3D clean-up of small angles after the kernel
};

/// What happened on one face.
struct FaceReport {
  LO face = kNoIndex;
  bool ok = false;            ///< false: the face could not be meshed and is absent from the output
  bool fell_back = false;     ///< true: refinement failed and the boundary-only triangulation was kept
  std::string error;          ///< the error met, if any (with stage and face id)
  double seconds = 0;
  /// Every field, once (visit(name, member)): what the ranks exchange (parallel/record.hpp).
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("face", self.face);
    visit("ok", self.ok);
    visit("fell_back", self.fell_back);
    visit("error", self.error);
    visit("seconds", self.seconds);
  }
};

/// The boundary loops of face f in its parameter plane, built from the curve meshes: each curve
/// use contributes its vertices in traversal order (the last one is the first of the next use),
/// with uv from the face's pcurve of that use, xyz and classification from the curve mesh.
[[nodiscard]] std::vector<mesh::BoundaryLoop> face_boundary(const cad::CadModel& model, LO f,
                                                            const cad::FaceGeometry& surface,
                                                            std::span<const mesh::CurveMesh> curves);

/// Triangulates face f with sizes adapted to its curvature (SizeOptions), the boundary locked to
/// `curves`. Never throws for a face-level failure: when refinement fails the boundary-only
/// triangulation is returned (report->fell_back), when that fails too an empty mesh
/// (report->ok false); `report` receives the details. Interior vertices are classified on face f.
[[nodiscard]] mesh::FaceMesh mesh_face_background(const cad::CadModel& model, LO f,
                                                  std::span<const mesh::CurveMesh> curves,
                                                  const BackgroundOptions& options,
                                                  FaceReport* report);

}  // namespace qsmesh::background
