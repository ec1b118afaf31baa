// The driver's commands. Each returns the process exit code.
#pragma once

#include "cli.hpp"

namespace qsmesh::cli {

int run_info(const Arguments& args);
int run_example(const Arguments& args);
/// Collective over MPI_COMM_WORLD; MPI must be initialised.
int run_mesh(const Arguments& args);

/// Writes `text` to `path` through a temporary file renamed at the end.
void write_text_file_atomically(const std::string& path, const std::string& text);
/// Throws InputError when `path` cannot be created (missing or unwritable directory).
void check_writable(const std::string& option, const std::string& path);

}  // namespace qsmesh::cli
