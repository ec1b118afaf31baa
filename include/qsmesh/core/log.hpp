// Progress and diagnostics output. A Logger is created by a driver and passed by reference to the
// stages that report; there is no global logger. Thread-safe: lines from tasks never interleave.
#pragma once

#include <iosfwd>
#include <mutex>
#include <sstream>
#include <string>

namespace qsmesh {

enum class LogLevel { Quiet = 0, Warning = 1, Info = 2, Debug = 3 };

class Logger {
 public:
  /// Writes to `out` the messages at or below `level`; `prefix` (e.g. "[rank 1] ") starts each
  /// line.
  explicit Logger(std::ostream& out, LogLevel level = LogLevel::Info, std::string prefix = {});

  void log(LogLevel level, const std::string& line);
  void info(const std::string& line) { log(LogLevel::Info, line); }
  void warn(const std::string& line) { log(LogLevel::Warning, "warning: " + line); }
  void debug(const std::string& line) { log(LogLevel::Debug, line); }
  [[nodiscard]] bool enabled(LogLevel level) const { return level <= level_; }
  [[nodiscard]] LogLevel level() const { return level_; }

 private:
  std::ostream* out_;
  LogLevel level_;
  std::string prefix_;
  std::mutex mutex_;
};

/// Formats anything streamable into a string: log.info(cat("faces: ", n)).
template <class... Args>
std::string cat(const Args&... args) {
  std::ostringstream os;
  (os << ... << args);
  return os.str();
}

}  // namespace qsmesh
