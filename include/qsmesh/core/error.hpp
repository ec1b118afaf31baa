// Project exception and check macros.
//
// QSMESH_CHECK is always on: it throws qsmesh::Error carrying the failed condition, a message,
// the source location and, when given through ErrorContext, the CAD entity and pipeline stage.
// QSMESH_ASSERT is for expensive invariants and compiles away unless QSMESH_DEBUG is defined.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace qsmesh {

/// Where an error happened in the pipeline: stage name and CAD entity (dimension, id).
struct ErrorContext {
  std::string stage;    ///< e.g. "background", "load"; empty when unknown
  int entity_dim = -1;  ///< 0 corner, 1 curve, 2 face, -1 none
  long entity_id = -1;
};

/// The one exception type of the project. what() is a complete, single-line message.
class Error : public std::runtime_error {
 public:
  Error(const std::string& message, ErrorContext context = {});
  [[nodiscard]] const ErrorContext& context() const { return context_; }
  [[nodiscard]] const std::string& message() const { return message_; }
  /// A copy of this error with the stage/entity filled in where they were unknown.
  [[nodiscard]] Error with_context(const ErrorContext& outer) const;

 private:
  static std::string compose(const std::string& message, const ErrorContext& context);
  std::string message_;
  ErrorContext context_;
};

/// The output could not be written (disk full, a file size limit, the folder gone mid-run): the
/// mesh is fine, its destination is not. The drivers print what() as one line (not as an internal
/// error) and exit 1; the writers have removed their temporary files by then.
class OutputError : public Error {
 public:
  using Error::Error;
};

/// Bad input from the user (file, option). The drivers turn it into one line on stderr and exit 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace detail {
[[noreturn]] void check_failed(const char* condition, const char* file, int line,
                               const std::string& message);
}  // namespace detail

}  // namespace qsmesh

/// Always-on check. Usage: QSMESH_CHECK(n > 0, "face " << f << " has no vertex");
#define QSMESH_CHECK(cond, msg)                                                          \
  do {                                                                                   \
    if (!(cond)) [[unlikely]] {                                                          \
      std::ostringstream qsmesh_check_os_;                                               \
      qsmesh_check_os_ << msg; /* NOLINT(bugprone-macro-parentheses) */                  \
      ::qsmesh::detail::check_failed(#cond, __FILE__, __LINE__, qsmesh_check_os_.str()); \
    }                                                                                    \
  } while (false)

#ifdef QSMESH_DEBUG
#define QSMESH_ASSERT(cond, msg) QSMESH_CHECK(cond, msg)
#else
#define QSMESH_ASSERT(cond, msg) \
  do {                           \
  } while (false)
#endif
