// The one wrapper over the task scheduler (oneTBB). Algorithms call parallel_for on a TaskArena
// and never see TBB. Work items are coarse (a CAD face, a curve), so the std::function indirection
// costs nothing measurable; results must not depend on the thread count, so bodies write only to
// their own slot of a pre-sized output.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>

namespace qsmesh {

class TaskArena {
 public:
  /// threads <= 0: all hardware threads. More than max_threads() are not granted: the arena gets
  /// max_threads() (check threads() to tell the user).
  explicit TaskArena(int threads = 0);
  ~TaskArena();
  TaskArena(const TaskArena&) = delete;
  TaskArena& operator=(const TaskArena&) = delete;

  [[nodiscard]] int threads() const;

  /// The most threads the scheduler grants this process: the cores it may run on (its affinity
  /// mask, which mpirun's binding narrows), or less where the scheduler is limited.
  [[nodiscard]] static int max_threads();

  /// Calls body(i) for i in [0, n), in parallel, one task per index (grain 1).
  /// The first exception thrown by a body is rethrown here after all tasks stop.
  void parallel_for(std::int64_t n, const std::function<void(std::int64_t)>& body) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace qsmesh
