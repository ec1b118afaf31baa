// Internal to the layout module: the vertex grid of a block or of a T-mesh patch, shared by the
// dense layout (quad_layout.cpp) and the coarse one (coarse_layout.cpp).
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "qsmesh/core/types.hpp"

namespace qsmesh::layout::detail {

// A block with its own vertex grid and its quads (the dense layout keeps them; the coarse one
// leaves them empty), as the patches give them and merging joins them.
struct Grid {
  LO face = kNoIndex;
  LO ni = 0, nj = 0;
  std::vector<GO> v;      // (ni + 1) x (nj + 1), i fastest
  std::vector<GO> quads;  // the mesh quads it covers
  [[nodiscard]] GO at(LO i, LO j) const {
    return v[static_cast<std::size_t>(j) * static_cast<std::size_t>(ni + 1) +
             static_cast<std::size_t>(i)];
  }
  // Boundary vertices of side s, counter-clockwise around the block: 0 = j min (i up), 1 = i max
  // (j up), 2 = j max (i down), 3 = i min (j down).
  [[nodiscard]] std::vector<GO> side(int s) const {
    std::vector<GO> out;
    if (s == 0)
      for (LO i = 0; i <= ni; ++i) out.push_back(at(i, 0));
    if (s == 1)
      for (LO j = 0; j <= nj; ++j) out.push_back(at(ni, j));
    if (s == 2)
      for (LO i = ni; i >= 0; --i) out.push_back(at(i, nj));
    if (s == 3)
      for (LO j = nj; j >= 0; --j) out.push_back(at(0, j));
    return out;
  }
  // Turns the index axes a quarter turn, keeping i x j (side s becomes side (s + 3) % 4).
  void rotate() {
    Grid r;
    r.face = face;
    r.ni = nj;
    r.nj = ni;
    r.quads = std::move(quads);
    r.v.resize(v.size());
    for (LO jr = 0; jr <= r.nj; ++jr)
      for (LO ir = 0; ir <= r.ni; ++ir)
        r.v[static_cast<std::size_t>(jr) * static_cast<std::size_t>(r.ni + 1) +
            static_cast<std::size_t>(ir)] = at(ni - jr, ir);
    *this = std::move(r);
  }
};

}  // namespace qsmesh::layout::detail
