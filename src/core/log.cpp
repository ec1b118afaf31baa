#include "qsmesh/core/log.hpp"

#include <ostream>

namespace qsmesh {

Logger::Logger(std::ostream& out, LogLevel level, std::string prefix)
    : out_(&out), level_(level), prefix_(std::move(prefix)) {}

void Logger::log(LogLevel level, const std::string& line) {
  if (!enabled(level)) return;
  const std::lock_guard<std::mutex> lock(mutex_);
  *out_ << prefix_ << line << '\n' << std::flush;
}

}  // namespace qsmesh
