#include "qsmesh/core/timer.hpp"

#include <sys/resource.h>

namespace qsmesh {

double peak_resident_mb() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux: kilobytes
}

void StageTimes::add(const std::string& stage, double seconds) {
  for (auto& [name, s] : entries_) {
    if (name == stage) {
      s += seconds;
      return;
    }
  }
  entries_.emplace_back(stage, seconds);
}

double StageTimes::get(const std::string& stage) const {
  for (const auto& [name, s] : entries_)
    if (name == stage) return s;
  return 0.0;
}

double StageTimes::total() const {
  double t = 0;
  for (const auto& e : entries_) t += e.second;
  return t;
}

}  // namespace qsmesh
