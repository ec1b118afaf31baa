// Work split by item over the ranks and threads, where every rank needs every result: the curves
// stage's rounds (run_pipeline) and the load's face measurements (measure_split).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "qsmesh/core/tasks.hpp"
#include "qsmesh/core/types.hpp"
#include "qsmesh/parallel/comm.hpp"

namespace qsmesh::parallel {

/// One round of work split by item over the ranks: the items dealt by `weights` (deal_by_weight),
/// each rank's on its threads, every result all-gathered. For --stats and
/// scripts/simulate_scaling.py, which deals the items by `weights` as the round did and replays
/// `item_seconds` on other rank and thread counts.
struct SplitRound {
  /// Wall time of the round on this rank, seconds: its share of the items, the round's setup done
  /// by every rank (the curves' round 2: the search over all curves' samples), and the all-gather.
  double seconds = 0;
  /// The records of all items that the all-gather moves, all ranks together (record_bytes;
  /// counted on one rank too, where nothing is sent).
  std::int64_t bytes = 0;
  std::vector<double> weights;       ///< by item: its weight in the dealing
  std::vector<double> item_seconds;  ///< by item: its time on the rank that did it, seconds
};

/// measure(i) for every item i of [0, count), in item order, on every rank: the items dealt
/// evenly by id over the ranks (equal weights), each rank's measured on its threads, the values
/// all-gathered. Each value is computed once, by one rank, and copied bit for bit, so the result is
/// that of one thread measuring every item in turn (cad::LoadOptions::measure_faces).
/// `round` (optional) gets the round's times for --stats. measure must be thread-safe. Collective.
[[nodiscard]] std::vector<double> measure_split(const Comm& comm, const TaskArena& tasks, LO count,
                                                const std::function<double(LO)>& measure,
                                                SplitRound* round = nullptr);

}  // namespace qsmesh::parallel
