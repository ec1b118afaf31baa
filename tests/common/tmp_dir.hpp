// Scratch folder of a test process. ctest runs the tests of one executable as separate processes,
// several at once: each process gets its own subfolder, so two tests never write the same file.
// QSMESH_TEST_TMP_DIR is defined per test target (tests/CMakeLists.txt).
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace qsmesh::test {

inline std::string tmp_dir() {
  const std::string dir = std::string(QSMESH_TEST_TMP_DIR) + "/p" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  return dir;
}

/// A file name in the test folder, prefixed by the process id ("p<pid>_NAME").
inline std::string tmp(const std::string& name) {
  return std::string(QSMESH_TEST_TMP_DIR) + "/p" + std::to_string(::getpid()) + "_" + name;
}

/// The whole content of a file ("" when it cannot be read).
inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace qsmesh::test
