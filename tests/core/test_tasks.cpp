#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <vector>

#include "qsmesh/core/tasks.hpp"

namespace qsmesh {
namespace {

TEST(TaskArena, EveryIndexRunsOnce) {
  for (int threads : {1, 2, 4}) {
    const TaskArena arena(threads);
    EXPECT_EQ(arena.threads(), std::min(threads, TaskArena::max_threads()));
    std::vector<int> hits(1000, 0);
    arena.parallel_for(static_cast<std::int64_t>(hits.size()),
                       [&](std::int64_t i) { hits[i] += 1; });
    for (int h : hits) ASSERT_EQ(h, 1);
  }
}

// A request beyond what the scheduler grants is clamped, not reported as granted (it used to be,
// and 100000 threads crashed at exit).
TEST(TaskArena, MoreThreadsThanGrantedAreClamped) {
  ASSERT_GE(TaskArena::max_threads(), 1);
  const TaskArena arena(100000);
  EXPECT_EQ(arena.threads(), TaskArena::max_threads());
  std::vector<int> hits(100, 0);
  arena.parallel_for(static_cast<std::int64_t>(hits.size()), [&](std::int64_t i) { hits[i] += 1; });
  for (int h : hits) ASSERT_EQ(h, 1);
  EXPECT_EQ(TaskArena(0).threads(), TaskArena::max_threads());
}

TEST(TaskArena, ExceptionPropagates) {
  const TaskArena arena(2);
  EXPECT_THROW(arena.parallel_for(100,
                                  [](std::int64_t i) {
                                    if (i == 57) throw std::runtime_error("face 57 failed");
                                  }),
               std::runtime_error);
}

TEST(TaskArena, EmptyRangeDoesNothing) {
  const TaskArena arena(2);
  std::atomic<int> calls{0};
  arena.parallel_for(0, [&](std::int64_t) { ++calls; });
  EXPECT_EQ(calls.load(), 0);
}

}  // namespace
}  // namespace qsmesh
