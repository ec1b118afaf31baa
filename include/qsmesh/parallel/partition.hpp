// Partition of CAD faces across MPI ranks (the unit of distributed work is the CAD face).
#pragma once

#include <span>
#include <vector>

#include "qsmesh/core/adjacency.hpp"

namespace qsmesh::parallel {

/// Assigns each face to one of `parts` ranks with METIS (k-way, fixed seed) on the face-adjacency
/// graph `face2faces`, balancing `weights` (estimated cost per face, >= 0). Deterministic: every
/// rank computes the same answer from the same input. With parts == 1 every face goes to 0; with
/// more parts than faces, face i goes to part i.
[[nodiscard]] std::vector<int> partition_faces(const Adjacency& face2faces,
                                               std::span<const double> weights, int parts);

/// Deals items over `parts` ranks, largest weight first (ties: the lower index), each to the rank
/// whose weights so far sum least (ties: the lower rank): the greedy longest-first rule,
/// the same on every rank (scripts/simulate_scaling.py's greedy_partition replays it). Returns the
/// rank of each item. Precondition: parts >= 1.
[[nodiscard]] std::vector<int> deal_by_weight(std::span<const double> weights, int parts);

}  // namespace qsmesh::parallel
