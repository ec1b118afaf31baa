// Fuzz target of the command-line parser (drivers/cli.hpp). parse() may only return or throw
// qsmesh::InputError; any other exception, a crash or a sanitizer report is a bug. What it
// returns must keep the promises of cli.hpp, checked below.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "cli.hpp"
#include "fuzz_input.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/writer.hpp"

namespace {

// abort() so that libFuzzer records the input as a crash and the run fails.
void require(bool cond) {
  if (!cond) std::abort();
}

void check(const qsmesh::cli::Arguments& a) {
  using qsmesh::cli::Command;
  require(!(a.size && a.size_factor));
  require(!(a.size_min && a.size_min_ratio));
  if (a.size) require(std::isfinite(*a.size) && *a.size > 0);
  if (a.size_factor) require(std::isfinite(*a.size_factor) && *a.size_factor > 0);
  require(a.threads >= 0);
  require(a.order >= 1 && a.order <= 5);
  // CGNS has no order-5 elements; PLOT3D holds linear blocks only (and is always the layout).
  if (a.command == Command::Mesh && a.order > 4)
    require(qsmesh::io::output_format(a.output) != qsmesh::io::Format::kCgns);
  if (a.command == Command::Mesh &&
      qsmesh::io::output_format(a.output) == qsmesh::io::Format::kPlot3d)
    require(a.block_structured && a.order == 1);
  require(a.method == "default" || a.method == "holomorphic" || a.method == "auto" ||
          a.method == "separatrix");
  require(a.separatrix_method == (a.method == "separatrix"));
  require(a.sizemap == "features" || a.sizemap == "crossfield");
  require(a.sizing == "paper" || a.sizing == "clamped");
  // Odd counts are honoured (each face loop is halved, not each curve); their parity is checked
  // against the model's loops later, not by the parser.
  for (const auto& [id, n] : a.curve_edges) require(id >= 0 && n > 0);
  if (a.field_divisions)
    require(*a.field_divisions == 0 || (*a.field_divisions >= 1 && *a.field_divisions <= 1e6));
  for (const auto* list : {&a.face_quads, &a.corner_sizes, &a.curve_sizes, &a.face_sizes})
    for (const auto& [id, v] : *list) require(id >= 0 && std::isfinite(v) && v > 0);
  if (a.command == Command::Mesh || a.command == Command::SizeMap) require(!a.output.empty());
  if (a.command == Command::Example) {
    const auto names = qsmesh::cad::example_names();
    require(std::find(names.begin(), names.end(), a.example_name) != names.end() &&
            !a.output.empty());
  }
  // The help of whatever topic was asked must print.
  if (a.command == Command::Help) require(!qsmesh::cli::help(a.help_topic).empty());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto args = qsmesh::fuzz::split_arguments(data, size);
  qsmesh::cli::Arguments parsed;
  try {
    parsed = qsmesh::cli::parse(args);
  } catch (const qsmesh::InputError& e) {
    // The promised one line naming the problem (the arguments themselves hold no '\n' here).
    const std::string what = e.what();
    require(!what.empty() && what.find('\n') == std::string::npos);
    return 0;
  }
  check(parsed);
  return 0;
}
