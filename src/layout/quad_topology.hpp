// Internal to the layout module: the quads around each vertex of an assembled mesh and the trace
// starts at a vertex, shared by the dense layout (quad_layout.cpp) and the coarse one
// (coarse_layout.cpp). The two keep different edge tables (the dense one per face, since a face
// given twice in the CAD meshes the same edge twice), so an edge's "other quad" is asked through a
// callable.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <numeric>
#include <span>
#include <vector>

#include "qsmesh/core/types.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::layout::detail {

// Vertex -> quads of a mesh (CSR, each list in increasing quad order).
class VertexQuads {
 public:
  explicit VertexQuads(const mesh::SurfaceMesh& m) {
    off_.assign(static_cast<std::size_t>(m.num_vertices()) + 1, 0);
    for (const auto& q : m.quads)
      for (GO v : q) ++off_[static_cast<std::size_t>(v) + 1];
    std::partial_sum(off_.begin(), off_.end(), off_.begin());
    quads_.resize(static_cast<std::size_t>(off_.back()));
    std::vector<GO> fill(off_.begin(), off_.end() - 1);
    const auto nq = static_cast<GO>(m.quads.size());
    for (GO q = 0; q < nq; ++q)
      for (GO v : m.quads[static_cast<std::size_t>(q)])
        quads_[static_cast<std::size_t>(fill[static_cast<std::size_t>(v)]++)] = q;
  }
  [[nodiscard]] std::span<const GO> operator[](GO v) const {
    const auto b = static_cast<std::size_t>(off_[static_cast<std::size_t>(v)]);
    const auto e = static_cast<std::size_t>(off_[static_cast<std::size_t>(v) + 1]);
    return {quads_.data() + b, e - b};
  }
  [[nodiscard]] LO valence(GO v) const { return static_cast<LO>((*this)[v].size()); }

 private:
  std::vector<GO> off_, quads_;
};

// The two vertices of quad `quad` joined to v by its edges; none when v is not in it.
[[nodiscard]] inline bool neighbours_in_quad(const std::array<GO, 4>& quad, GO v,
                                             std::array<GO, 2>& out) {
  for (int k = 0; k < 4; ++k)
    if (quad[k] == v) {
      out = {quad[(k + 1) % 4], quad[(k + 3) % 4]};
      return true;
    }
  return false;
}

// An interior edge (v, w) leaving v, taken from quads[quad] (the list given to side_edges), and
// whether the side of v it lies in has other than two quads.
struct SideEdge {
  GO w;
  std::size_t quad;
  bool irregular_side;
};

// The interior edges leaving v, for the trace starts of both layouts: a side of v is a set of its
// quads joined through interior edges at v (a boundary vertex has one per sector between its
// curves, an interior vertex one), and a side of other than two quads is where a block corner or
// a T-junction must start a trace. `across(w, q)` gives the quad across edge (v, w) from quad q
// when that edge is interior to a face (traces may follow it), or -1. `quads` are v's quads.
template <class Across>
[[nodiscard]] std::vector<SideEdge> side_edges(const mesh::SurfaceMesh& m, GO v,
                                               std::span<const GO> quads, Across across) {
  std::vector<std::size_t> parent(quads.size());
  std::iota(parent.begin(), parent.end(), std::size_t{0});
  auto find = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i];
    return i;
  };
  std::vector<SideEdge> out;
  for (std::size_t a = 0; a < quads.size(); ++a) {
    std::array<GO, 2> nb{};
    if (!neighbours_in_quad(m.quads[static_cast<std::size_t>(quads[a])], v, nb)) continue;
    for (GO w : nb) {
      const GO other = across(w, quads[a]);
      if (other < 0) continue;
      out.push_back({w, a, false});
      const auto b =
          static_cast<std::size_t>(std::find(quads.begin(), quads.end(), other) - quads.begin());
      parent[find(a)] = find(b);
    }
  }
  std::vector<int> side_size(quads.size(), 0);
  for (std::size_t a = 0; a < quads.size(); ++a) ++side_size[find(a)];
  for (auto& e : out) e.irregular_side = side_size[find(e.quad)] != 2;
  return out;
}

}  // namespace qsmesh::layout::detail
