// Wall-clock timing of pipeline stages, and the process's peak memory.
#pragma once

#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace qsmesh {

/// Seconds since construction (steady clock).
class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  [[nodiscard]] double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  void reset() { start_ = std::chrono::steady_clock::now(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

/// Peak resident set size of this process so far, in megabytes (2^20 bytes; getrusage's
/// ru_maxrss). 0 when the system does not report it.
[[nodiscard]] double peak_resident_mb();

/// Ordered list of (stage name, seconds); adding to an existing stage accumulates.
class StageTimes {
 public:
  void add(const std::string& stage, double seconds);
  [[nodiscard]] double get(const std::string& stage) const;
  [[nodiscard]] const std::vector<std::pair<std::string, double>>& entries() const {
    return entries_;
  }
  [[nodiscard]] double total() const;

 private:
  std::vector<std::pair<std::string, double>> entries_;
};

}  // namespace qsmesh
