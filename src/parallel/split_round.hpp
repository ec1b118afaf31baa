// One round of work split by item over the ranks (private to src/parallel): the curves stage's
// two rounds and the load's face measurements.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/partition.hpp"
#include "qsmesh/parallel/record.hpp"
#include "qsmesh/parallel/split.hpp"

namespace qsmesh::parallel {

// The first error a rank met in a round, sent with its items so that every rank throws the same
// one: that of the lowest item over all ranks.
struct ItemError {
  LO item = kNoIndex;  // kNoIndex: none
  std::string message, stage;
  int dim = -1;
  std::int64_t id = -1;
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("item", self.item);
    visit("message", self.message);
    visit("stage", self.stage);
    visit("dim", self.dim);
    visit("id", self.id);
  }
};

// The items dealt over the ranks by `weights` (deal_by_weight: by item id, the same on every
// rank), work(i) on this rank's items as tasks, then every item's result on every rank: each rank
// writes, per item of its own, the item id, its seconds and write(i, bytes), all of which are
// all-gathered and read back with read(i, bytes, pos). Each item's result is computed by one rank
// and copied byte for byte to the others, so the results are those of one rank doing every item.
// bytes(i): what write(i, ...) appends (record_bytes). Collective. Throws on every rank the error
// of the lowest item whose work failed on any rank.
template <class Work, class Bytes, class Write, class Read>
SplitRound split_round(const Comm& comm, const TaskArena& tasks, std::vector<double> weights,
                       const Work& work, const Bytes& bytes, const Write& write, const Read& read) {
  const Stopwatch clock;
  const int nranks = comm.size();
  const int rank = comm.rank();
  const auto n = static_cast<LO>(weights.size());
  const std::vector<int> owner = deal_by_weight(weights, nranks);
  std::vector<LO> mine;
  for (LO i = 0; i < n; ++i)
    if (owner[i] == rank) mine.push_back(i);
  SplitRound round;
  round.item_seconds.assign(weights.size(), 0.0);
  std::vector<std::optional<Error>> errors(mine.size());
  tasks.parallel_for(static_cast<std::int64_t>(mine.size()), [&](std::int64_t k) {
    const Stopwatch item_clock;
    try {
      work(mine[k]);
    } catch (const Error& e) {
      errors[k] = e;
    }
    round.item_seconds[mine[k]] = item_clock.seconds();
  });
  ItemError first;
  for (std::size_t k = 0; k < mine.size() && first.item == kNoIndex; ++k)
    if (errors[k])
      first = {mine[k], errors[k]->message(), errors[k]->context().stage,
               errors[k]->context().entity_dim, errors[k]->context().entity_id};
  if (nranks > 1) {
    std::vector<char> out;
    write_record(out, first);
    for (const LO i : mine) {
      put<LO>(out, i);
      put<double>(out, round.item_seconds[i]);
      write(i, out);
    }
    const std::vector<std::vector<char>> all = comm.allgather_bytes(out);
    for (int r = 0; r < nranks; ++r) {
      if (r == rank) continue;
      const std::vector<char>& in = all[r];
      std::size_t pos = 0;
      ItemError theirs;
      read_record(in, pos, theirs);
      if (theirs.item != kNoIndex && (first.item == kNoIndex || theirs.item < first.item))
        first = std::move(theirs);
      while (pos < in.size()) {
        const LO i = get<LO>(in, pos);
        QSMESH_CHECK(i >= 0 && i < n && owner[i] == r,
                     "split round: rank " << r << " sent item " << i << ", not one of its own");
        round.item_seconds[i] = get<double>(in, pos);
        read(i, in, pos);
      }
    }
  }
  if (first.item != kNoIndex)
    throw Error(first.message, ErrorContext{first.stage, first.dim, first.id});
  for (LO i = 0; i < n; ++i)
    round.bytes += static_cast<std::int64_t>(sizeof(LO) + sizeof(double)) + bytes(i);
  round.weights = std::move(weights);
  round.seconds = clock.seconds();
  return round;
}

}  // namespace qsmesh::parallel
