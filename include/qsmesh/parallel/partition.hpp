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

/// The same with a second balance constraint (METIS multi-constraint, ncon = 2): each part gets
/// a fair share of `weights` (the whole cost) and of `field_weights` (>= 0 per face: the cost of
/// the crossfield stage alone, which the faces' partition also runs and whose time is the slowest
/// rank's). Falls back to the one-constraint partition above, the same answer, when the second
/// column says nothing the first does not: it is empty, sums to zero, or (after METIS's integer
/// scaling) equals the first; when METIS refuses the two-constraint call; and when the
/// one-constraint partition has the smaller sum of the two imbalances (largest part / mean, on
/// the scaled weights; ties keep it). Deterministic.
/// Precondition: field_weights is empty or has one entry per face.
[[nodiscard]] std::vector<int> partition_faces(const Adjacency& face2faces,
                                               std::span<const double> weights,
                                               std::span<const double> field_weights, int parts);

/// Deals items over `parts` ranks, largest weight first (ties: the lower index), each to the rank
/// whose weights so far sum least (ties: the lower rank): the greedy longest-first rule,
/// the same on every rank (scripts/simulate_scaling.py's greedy_partition replays it). Returns the
/// rank of each item. Precondition: parts >= 1.
[[nodiscard]] std::vector<int> deal_by_weight(std::span<const double> weights, int parts);

}  // namespace qsmesh::parallel
