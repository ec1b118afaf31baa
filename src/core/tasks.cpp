#include "qsmesh/core/tasks.hpp"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>

namespace qsmesh {

struct TaskArena::Impl {
  explicit Impl(int n) : arena(n) {}
  tbb::task_arena arena;
};

// Asking TBB for more threads than it grants gave an arena that reported the number asked while
// running on the cores available, and 100000 of them crashed at exit: the request is clamped.
TaskArena::TaskArena(int threads)
    : impl_(
          std::make_unique<Impl>(threads > 0 ? std::min(threads, max_threads()) : max_threads())) {}

int TaskArena::max_threads() {
  return std::max(
      1, static_cast<int>(std::min<std::size_t>(
             static_cast<std::size_t>(tbb::this_task_arena::max_concurrency()),
             tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism))));
}

TaskArena::~TaskArena() = default;

int TaskArena::threads() const { return impl_->arena.max_concurrency(); }

void TaskArena::parallel_for(std::int64_t n, const std::function<void(std::int64_t)>& body) const {
  if (n <= 0) return;
  if (threads() == 1) {
    for (std::int64_t i = 0; i < n; ++i) body(i);
    return;
  }
  // Grain 1 with the simple partitioner: items are coarse and of very uneven cost. Isolated: a
  // thread that waits for the items of a nested call (one face's layouts inside the dealt faces)
  // takes only those items, not another face, so that a face's measured time is its own.
  impl_->arena.execute([&] {
    tbb::this_task_arena::isolate([&] {
      tbb::parallel_for(
          tbb::blocked_range<std::int64_t>(0, n, 1),
          [&](const tbb::blocked_range<std::int64_t>& r) {
            for (std::int64_t i = r.begin(); i < r.end(); ++i) body(i);
          },
          tbb::simple_partitioner());
    });
  });
}

}  // namespace qsmesh
