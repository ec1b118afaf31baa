// The output format from a path's extension, apart from the writers: the command-line parser
// needs it, and the parser's fuzz target (tests/fuzz) links it without HDF5, CGNS or the mesh.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

#include "qsmesh/io/writer.hpp"

namespace qsmesh::io {

namespace fs = std::filesystem;

std::string lowercase_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

Format output_format(const std::string& path) {
  const std::string ext = lowercase_extension(path);
  if (ext == ".cgns") return Format::kCgns;
  if (ext == ".vtu") return Format::kVtu;
  if (ext == ".msh") return Format::kMsh;
  if (ext == ".h5") return Format::kHdf5;
  if (ext == ".xyz" || ext == ".p3d") return Format::kPlot3d;
  return Format::kNone;
}

bool is_supported_output(const std::string& path) {
  return !fs::path(path).stem().empty() && output_format(path) != Format::kNone;
}

}  // namespace qsmesh::io
