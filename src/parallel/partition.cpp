#include "qsmesh/parallel/partition.hpp"

#include <metis.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "qsmesh/core/error.hpp"

namespace qsmesh::parallel {

std::vector<int> partition_faces(const Adjacency& face2faces, std::span<const double> weights,
                                 int parts) {
  const LO n = face2faces.size();
  QSMESH_CHECK(static_cast<LO>(weights.size()) == n, "one weight per face expected");
  QSMESH_CHECK(parts >= 1, "number of parts must be positive");
  std::vector<int> part(static_cast<std::size_t>(n), 0);
  if (parts == 1 || n == 0) return part;
  if (parts >= n) {
    for (LO i = 0; i < n; ++i) part[i] = i;
    return part;
  }

  // METIS balances integer weights: scale the costs to [1, 1e6] (a face always costs something).
  const double wmax = std::max(1e-300, *std::max_element(weights.begin(), weights.end()));
  std::vector<idx_t> vwgt(static_cast<std::size_t>(n));
  for (LO i = 0; i < n; ++i)
    vwgt[i] = static_cast<idx_t>(std::max(1.0, std::round(1e6 * std::max(0.0, weights[i]) / wmax)));
  std::vector<idx_t> xadj(face2faces.offsets.begin(), face2faces.offsets.end());
  std::vector<idx_t> adjncy(face2faces.targets.begin(), face2faces.targets.end());
  idx_t nvtxs = n, ncon = 1, nparts = parts, objval = 0;
  std::vector<idx_t> result(static_cast<std::size_t>(n), 0);
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 12345;  // fixed: every rank must get the same partition
  options[METIS_OPTION_NUMBERING] = 0;
  options[METIS_OPTION_CONTIG] = 0;
  const int status =
      METIS_PartGraphKway(&nvtxs, &ncon, xadj.data(), adjncy.data(), vwgt.data(), nullptr, nullptr,
                          &nparts, nullptr, nullptr, options, &objval, result.data());
  QSMESH_CHECK(status == METIS_OK, "METIS_PartGraphKway failed with status " << status);
  for (LO i = 0; i < n; ++i) part[i] = static_cast<int>(result[i]);
  return part;
}

std::vector<int> deal_by_weight(std::span<const double> weights, int parts) {
  QSMESH_CHECK(parts >= 1, "number of parts must be positive");
  std::vector<std::size_t> order(weights.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return weights[a] > weights[b]; });
  std::vector<int> part(weights.size(), 0);
  std::vector<double> load(static_cast<std::size_t>(parts), 0.0);
  for (const std::size_t i : order) {
    const auto r =
        static_cast<std::size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    load[r] += weights[i];
    part[i] = static_cast<int>(r);
  }
  return part;
}

}  // namespace qsmesh::parallel
