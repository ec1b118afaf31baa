// Edges of an assembled SurfaceMesh by key: what the validation, the quad layout, the second-order
// nodes and the block writer look edges up with.
#pragma once

#include <algorithm>
#include <cstdint>
#include <unordered_map>

#include "qsmesh/core/types.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::mesh {

/// Key of the undirected edge {a, b}: the same for (a, b) and (b, a). Vertex ids below 2^32.
[[nodiscard]] constexpr std::uint64_t edge_key(GO a, GO b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
         static_cast<std::uint64_t>(std::max(a, b));
}

/// The CAD curve of every bar of `mesh`, by edge_key of its two vertices.
[[nodiscard]] std::unordered_map<std::uint64_t, LO> bar_curves(const SurfaceMesh& mesh);

}  // namespace qsmesh::mesh
