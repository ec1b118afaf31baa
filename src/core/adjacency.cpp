#include "qsmesh/core/adjacency.hpp"

#include <algorithm>

namespace qsmesh {

Adjacency Adjacency::from_pairs(LO n_a, std::vector<std::pair<LO, LO>> pairs) {
  // A counting sort by the first entry, stable: the targets of each a keep their input order.
  Adjacency a2b;
  a2b.offsets.assign(static_cast<std::size_t>(n_a) + 1, 0);
  for (const auto& [a, b] : pairs) ++a2b.offsets[static_cast<std::size_t>(a) + 1];
  for (LO a = 0; a < n_a; ++a) a2b.offsets[a + 1] += a2b.offsets[a];
  a2b.targets.resize(pairs.size());
  std::vector<LO> next(a2b.offsets.begin(), a2b.offsets.end() - 1);
  for (const auto& [a, b] : pairs)
    a2b.targets[static_cast<std::size_t>(next[static_cast<std::size_t>(a)]++)] = b;
  return a2b;
}

Adjacency Adjacency::transpose(LO n_b) const {
  std::vector<std::pair<LO, LO>> pairs;
  pairs.reserve(targets.size());
  for (LO a = 0; a < size(); ++a)
    for (LO b : (*this)[a]) pairs.emplace_back(b, a);
  return from_pairs(n_b, std::move(pairs));
}

}  // namespace qsmesh
