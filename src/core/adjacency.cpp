#include "qsmesh/core/adjacency.hpp"

#include <algorithm>

namespace qsmesh {

Adjacency Adjacency::from_pairs(LO n_a, std::vector<std::pair<LO, LO>> pairs) {
  std::stable_sort(pairs.begin(), pairs.end(),
                   [](const auto& x, const auto& y) { return x.first < y.first; });
  Adjacency a2b;
  a2b.offsets.assign(static_cast<std::size_t>(n_a) + 1, 0);
  a2b.targets.reserve(pairs.size());
  for (const auto& [a, b] : pairs) {
    ++a2b.offsets[static_cast<std::size_t>(a) + 1];
    a2b.targets.push_back(b);
  }
  for (LO a = 0; a < n_a; ++a) a2b.offsets[a + 1] += a2b.offsets[a];
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
