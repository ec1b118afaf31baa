// Helpers shared by the writers (private to the io module).
#pragma once

#include <string>
#include <vector>

#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::io::detail {

/// Elements of each CAD face / curve, in mesh order: face2tris[f], face2quads[f], curve2bars[c]
/// hold indices into mesh.triangles / quads / bars.
struct ElementGroups {
  std::vector<std::vector<GO>> face2tris;
  std::vector<std::vector<GO>> face2quads;
  std::vector<std::vector<GO>> curve2bars;
};

/// Throws InputError (one line, "WHAT 'path' ...") unless `path` names a file (not a folder) in an
/// existing, writable folder.
void check_output_folder(const std::string& path, const std::string& what = "output");

/// The function a checked library call names, for error messages: the text of `call` (the
/// stringified call, "cg_open(path, ...)") before its argument list.
[[nodiscard]] std::string function_name(const char* call);

/// Groups the elements of a mesh that passed check_mesh_for_output.
ElementGroups group_elements(const mesh::SurfaceMesh& mesh);

}  // namespace qsmesh::io::detail
