#include "qsmesh/core/error.hpp"

namespace qsmesh {

Error::Error(const std::string& message, ErrorContext context)
    : std::runtime_error(compose(message, context)),
      message_(message),
      context_(std::move(context)) {}

std::string Error::compose(const std::string& message, const ErrorContext& context) {
  std::ostringstream os;
  static constexpr const char* kDimName[] = {"corner", "curve", "face"};
  if (!context.stage.empty()) os << "[" << context.stage << "] ";
  if (context.entity_dim >= 0 && context.entity_dim <= 2)
    os << kDimName[context.entity_dim] << " " << context.entity_id << ": ";
  os << message;
  return os.str();
}

Error Error::with_context(const ErrorContext& outer) const {
  ErrorContext c = context_;
  if (c.stage.empty()) c.stage = outer.stage;
  if (c.entity_dim < 0) {
    c.entity_dim = outer.entity_dim;
    c.entity_id = outer.entity_id;
  }
  return Error(message_, c);
}

namespace detail {
void check_failed(const char* condition, const char* file, int line, const std::string& message) {
  std::ostringstream os;
  os << message << " (check '" << condition << "' failed at " << file << ":" << line << ")";
  throw Error(os.str());
}
}  // namespace detail

}  // namespace qsmesh
