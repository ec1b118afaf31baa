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

/// Node k of quad q in qsmesh's order (mesh::quad_grid_positions): corner k for k < 4, else
/// quad_nodes entry k - 4 of the quad.
[[nodiscard]] inline GO quad_node(const mesh::SurfaceMesh& mesh, std::size_t q, int k) {
  return k < 4 ? mesh.quads[q][static_cast<std::size_t>(k)]
               : mesh.quad_nodes[q * static_cast<std::size_t>(mesh.quad_nodes_per_quad()) +
                                 static_cast<std::size_t>(k - 4)];
}

/// Node k of bar b: its ends for k < 2, then its interior nodes in its direction (the order of
/// CGNS BAR_n, Gmsh's lines and VTK's Lagrange curves).
[[nodiscard]] inline GO bar_node(const mesh::SurfaceMesh& mesh, std::size_t b, int k) {
  return k < 2 ? mesh.bars[b][static_cast<std::size_t>(k)]
               : mesh.bar_nodes[b * static_cast<std::size_t>(mesh.bar_nodes_per_bar()) +
                                static_cast<std::size_t>(k - 2)];
}

}  // namespace qsmesh::io::detail
