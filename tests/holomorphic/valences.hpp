// The valence counts the holomorphic tests check: valence-8 interior vertices (the theory's
// singularities), other irregular interior vertices, and boundary vertices with other than two
// quads.
#pragma once

#include <cstddef>
#include <vector>

#include "qsmesh/core/types.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::test {

struct Valences {
  LO eight = 0, other_irregular = 0, boundary_irregular = 0;
};

inline Valences valences(const mesh::FaceMesh& q) {
  std::vector<int> count(q.points.size(), 0);
  for (const auto& quad : q.quads)
    for (const LO v : quad) ++count[static_cast<std::size_t>(v)];
  Valences out;
  for (std::size_t v = 0; v < q.points.size(); ++v) {
    if (q.vclass[v].dim < 2) {
      out.boundary_irregular += count[v] != 2 ? 1 : 0;
      continue;
    }
    if (count[v] == 8)
      ++out.eight;
    else if (count[v] != 4)
      ++out.other_irregular;
  }
  return out;
}

}  // namespace qsmesh::test
