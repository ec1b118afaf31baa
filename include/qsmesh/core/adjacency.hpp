// Compressed one-to-many map (CSR), named a2b after Omega_h: for item a, the b's are
// b[offsets[a] .. offsets[a+1]).
#pragma once

#include <span>
#include <utility>
#include <vector>

#include "qsmesh/core/types.hpp"

namespace qsmesh {

struct Adjacency {
  std::vector<LO> offsets{0};  ///< size n_a + 1
  std::vector<LO> targets;     ///< size offsets.back()

  [[nodiscard]] LO size() const { return static_cast<LO>(offsets.size()) - 1; }
  [[nodiscard]] std::span<const LO> operator[](LO a) const {
    return {targets.data() + offsets[a], static_cast<std::size_t>(offsets[a + 1] - offsets[a])};
  }
  /// Builds from (a, b) pairs; b's of each a keep the order of the pairs after a stable sort on a.
  static Adjacency from_pairs(LO n_a, std::vector<std::pair<LO, LO>> pairs);
  /// The transpose b2a of this a2b map, given the number of b's; each list sorted increasingly.
  [[nodiscard]] Adjacency transpose(LO n_b) const;
};

}  // namespace qsmesh
