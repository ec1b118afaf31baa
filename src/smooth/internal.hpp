// Pieces shared by the smoothing kernels and the untangler of one face (not installed).
#pragma once

#include <array>
#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/smooth/smooth.hpp"

namespace qsmesh::smooth::detail {

/// Incident quads of every vertex, in increasing order.
[[nodiscard]] std::vector<std::vector<LO>> vertex_quads(const mesh::FaceMesh& m);

/// Sets the param of every dim-2 vertex to its uv.
void sync_interior_params(mesh::FaceMesh& m);

/// When an optimiser's output is accepted against its input's quality `before`.
enum class Accept {
  kGain,    ///< the minimum SICN must rise
  kNoDrop,  ///< the minimum SICN must not drop
};

/// Measures m into `after`; when it fails `accept` or has more invalid quads than `before`, m
/// becomes `input` and `after` becomes `before`. Returns true when it rolled back.
bool keep_or_roll_back(mesh::FaceMesh& m, const mesh::FaceMesh& input, const QualityReport& before,
                       Accept accept, QualityReport& after);

}  // namespace qsmesh::smooth::detail
