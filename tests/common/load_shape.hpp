// Test models built with OpenCASCADE inside a test, written to the test's scratch folder and
// loaded.
#pragma once

#include <BRepTools.hxx>
#include <TopoDS_Shape.hxx>
#include <stdexcept>
#include <string>

#include "qsmesh/cad/model.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::test {

/// Writes `shape` as BREP under `name` in this process's scratch folder (tmp_dir()) and loads it.
/// Throws std::runtime_error when the file cannot be written. Inline: tmp_dir() needs the test
/// target's QSMESH_TEST_TMP_DIR.
inline cad::CadModel load_shape(const TopoDS_Shape& shape, const std::string& name) {
  const std::string path = tmp_dir() + "/" + name;
  if (!BRepTools::Write(shape, path.c_str())) throw std::runtime_error("cannot write " + path);
  return cad::load_cad(path);
}

}  // namespace qsmesh::test
