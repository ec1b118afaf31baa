// Internal to the layout module: the vertex grid of a block or of a T-mesh patch, shared by the
// dense layout (quad_layout.cpp) and the coarse one (coarse_layout.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "qsmesh/core/types.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

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

// The patch `members` (sorted quad ids of face `face` of m) as an ni x nj grid of its vertices, its
// quads left empty; none when the patch is not a grid. `across(q, a, b)` gives the patch quad
// across edge (a, b) of quad q, or -1 where that edge bounds the patch. Both layouts keep their
// own edge tables, hence the callable.
template <class Across>
[[nodiscard]] std::optional<Grid> patch_grid(const mesh::SurfaceMesh& m,
                                             std::span<const GO> members, LO face, Across across) {
  // An oriented quad: local corners (0,0), (1,0), (1,1), (0,1) are quad[k], [k+1], [k+2], [k+3].
  struct Oriented {
    GO q;
    int k;
  };
  auto corner = [&](Oriented o, int c) {
    return m.quads[static_cast<std::size_t>(o.q)][static_cast<std::size_t>((o.k + c) % 4)];
  };
  auto position = [&](GO q, GO v) {
    const auto& quad = m.quads[static_cast<std::size_t>(q)];
    for (int k = 0; k < 4; ++k)
      if (quad[static_cast<std::size_t>(k)] == v) return k;
    return -1;
  };
  // The first quad with a patch corner: both its edges at that vertex bound the patch.
  Oriented start{-1, 0};
  for (GO q : members) {
    const auto& quad = m.quads[static_cast<std::size_t>(q)];
    for (int k = 0; k < 4 && start.q < 0; ++k)
      if (across(q, quad[k], quad[(k + 1) % 4]) < 0 && across(q, quad[(k + 3) % 4], quad[k]) < 0)
        start = {q, k};
    if (start.q >= 0) break;
  }
  if (start.q < 0) return std::nullopt;
  auto step_i = [&](Oriented o) -> Oriented {
    const GO b = corner(o, 1), c = corner(o, 2);
    const GO n = across(o.q, b, c);
    return n < 0 ? Oriented{-1, 0} : Oriented{n, position(n, b)};
  };
  auto step_j = [&](Oriented o) -> Oriented {
    const GO d = corner(o, 3), c = corner(o, 2);
    const GO n = across(o.q, d, c);
    return n < 0 ? Oriented{-1, 0} : Oriented{n, position(n, d)};
  };
  const auto count = static_cast<GO>(members.size());
  LO ni = 0;
  for (Oriented o = start; o.q >= 0; o = step_i(o))
    if (++ni > count) return std::nullopt;
  std::vector<GO> gv;
  std::vector<GO> seen;
  LO nj = 0;
  for (Oriented row = start; row.q >= 0; row = step_j(row)) {
    if (static_cast<GO>(nj + 1) * ni > count) return std::nullopt;
    gv.resize(static_cast<std::size_t>(ni + 1) * static_cast<std::size_t>(nj + 2), -1);
    Oriented o = row;
    for (LO i = 0; i < ni; ++i) {
      if (o.q < 0) return std::nullopt;
      seen.push_back(o.q);
      const std::array<std::pair<LO, LO>, 4> at{
          {{i, nj}, {i + 1, nj}, {i + 1, nj + 1}, {i, nj + 1}}};
      for (int c = 0; c < 4; ++c) {
        GO& slot = gv[static_cast<std::size_t>(at[static_cast<std::size_t>(c)].second) *
                          static_cast<std::size_t>(ni + 1) +
                      static_cast<std::size_t>(at[static_cast<std::size_t>(c)].first)];
        if (slot >= 0 && slot != corner(o, c)) return std::nullopt;
        slot = corner(o, c);
      }
      o = step_i(o);
    }
    if (o.q >= 0) return std::nullopt;  // a longer row: not a grid
    ++nj;
  }
  std::sort(seen.begin(), seen.end());
  if (!std::equal(seen.begin(), seen.end(), members.begin(), members.end())) return std::nullopt;
  return Grid{face, ni, nj, std::move(gv), {}};
}

}  // namespace qsmesh::layout::detail
