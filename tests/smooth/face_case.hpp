// Set-up shared by the smooth tests: one OpenCASCADE face written as BREP, loaded back through
// cad::CadModel, and the checks every optimiser must pass (locked boundary, points on the surface).
#pragma once

#include <TopoDS_Shape.hxx>
#include <memory>
#include <string>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::test {

/// Path of `name` in the test's scratch folder (QSMESH_TEST_TMP_DIR).
[[nodiscard]] std::string tmp_path(const std::string& name);

/// Writes the shape as BREP to tmp_path(name); returns the path. Throws std::runtime_error when
/// the file cannot be written.
std::string write_face(const TopoDS_Shape& shape, const std::string& name);

/// A loaded model and the geometry of one of its faces.
struct FaceCase {
  cad::CadModel model;
  std::unique_ptr<cad::FaceGeometry> geometry;
  LO face = 0;
};

/// Loads the model at `path` and the geometry of its last face of surface type `type`. Throws
/// std::runtime_error when it has none.
[[nodiscard]] FaceCase load_face(const std::string& path, cad::SurfaceType type);
/// Writes the single-face shape (write_face) and loads it back, face 0.
[[nodiscard]] FaceCase load_face(const TopoDS_Shape& shape, const std::string& name);

/// GoogleTest expectations on an optimiser's output: same quads and vertex count, vertices of
/// dim < 2 bit-identical in point and uv, every point at S(uv) within 1e-9 * size; with
/// check_params, the param of every dim-2 vertex equals its uv.
void expect_locked_and_on_surface(const mesh::FaceMesh& in, const mesh::FaceMesh& out,
                                  const cad::FaceGeometry& g, double size, bool check_params);

}  // namespace qsmesh::test
