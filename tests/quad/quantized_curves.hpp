// Curve meshes of a test model as the pipeline builds them for the quad stage, with a uniform size
// in place of the size map: background curve meshes, quantized counts (halved minimums), then the
// final meshes and the halved ones (twice the edge length).
#pragma once

#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::test {

struct QuantizedCurves {
  std::vector<mesh::CurveMesh> background;    ///< before quantization (background stage)
  std::vector<mesh::CurveMesh> full, halved;  ///< quantized, final and halved
};

/// Every curve of `model` at edge length `size` (model units, > 0).
[[nodiscard]] QuantizedCurves quantized_curves(const cad::CadModel& model, double size);

}  // namespace qsmesh::test
