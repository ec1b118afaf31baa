// Turning a fuzzer's bytes into what the qsmesh entry points take, shared by every fuzz target.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace qsmesh::fuzz {

/// The input as an argument vector (argv[1..]): one argument per line ('\n'-separated, so the
/// seed corpus stays readable text; an empty line is an empty argument). At most `max_args`
/// arguments, the rest dropped: the parsers are linear in the count, nothing is gained beyond it.
inline std::vector<std::string> split_arguments(const std::uint8_t* data, std::size_t size,
                                                std::size_t max_args = 64) {
  std::vector<std::string> args;
  if (size == 0) return args;
  std::string current;
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == '\n') {
      args.push_back(current);
      current.clear();
      if (args.size() == max_args) return args;
    } else {
      current.push_back(static_cast<char>(data[i]));
    }
  }
  args.push_back(current);
  return args;
}

}  // namespace qsmesh::fuzz
