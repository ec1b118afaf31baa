// Curve meshes of a test model as the pipeline builds them for the quad stage, with a uniform size
// in place of the size map: background curve meshes, quantized counts (halved minimums), then the
// final meshes and the halved ones (twice the edge length).
#pragma once

#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/quantize/quantize.hpp"

namespace qsmesh::test {

struct QuantizedCurves {
  std::vector<mesh::CurveMesh> background;    ///< before quantization (background stage)
  std::vector<mesh::CurveMesh> full, halved;  ///< quantized, final and halved
};

/// Every curve of `model` at edge length `size` (model units, > 0).
[[nodiscard]] QuantizedCurves quantized_curves(const cad::CadModel& model, double size);

/// The final curve meshes only, quantized with `options` (prescriptions, odd ones included, whose
/// halved curve meshes would not exist); `edges`, when given, receives the counts.
[[nodiscard]] std::vector<mesh::CurveMesh> quantized_full_curves(
    const cad::CadModel& model, double size, const quantize::QuantizeOptions& options,
    std::vector<int>* edges = nullptr);

}  // namespace qsmesh::test
