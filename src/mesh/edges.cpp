#include "qsmesh/mesh/edges.hpp"

namespace qsmesh::mesh {

std::unordered_map<std::uint64_t, LO> bar_curves(const SurfaceMesh& mesh) {
  std::unordered_map<std::uint64_t, LO> out;
  out.reserve(mesh.bars.size());
  for (std::size_t i = 0; i < mesh.bars.size(); ++i)
    out[edge_key(mesh.bars[i][0], mesh.bars[i][1])] = mesh.bar_curve[i];
  return out;
}

}  // namespace qsmesh::mesh
