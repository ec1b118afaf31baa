#include "qsmesh/parallel/split.hpp"

#include "split_round.hpp"

namespace qsmesh::parallel {

std::vector<double> measure_split(const Comm& comm, const TaskArena& tasks, LO count,
                                  const std::function<double(LO)>& measure, SplitRound* round) {
  std::vector<double> values(static_cast<std::size_t>(count), 0.0);
  SplitRound r = split_round(
      comm, tasks, std::vector<double>(static_cast<std::size_t>(count), 1.0),
      [&](LO i) { values[i] = measure(i); }, [](LO) { return std::int64_t{sizeof(double)}; },
      [&](LO i, std::vector<char>& out) { put<double>(out, values[i]); },
      [&](LO i, const std::vector<char>& in, std::size_t& pos) {
        values[i] = get<double>(in, pos);
      });
  if (round != nullptr) *round = std::move(r);
  return values;
}

}  // namespace qsmesh::parallel
