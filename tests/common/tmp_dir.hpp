// Scratch folder of a test process. ctest runs the tests of one executable as separate processes,
// several at once: each process gets its own subfolder, so two tests never write the same file.
// QSMESH_TEST_TMP_DIR is defined per test target (tests/CMakeLists.txt).
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace qsmesh::test {

inline std::string tmp_dir() {
  const std::string dir = std::string(QSMESH_TEST_TMP_DIR) + "/p" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace qsmesh::test
