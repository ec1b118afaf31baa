// The names of the built-in examples, apart from their OpenCASCADE builders (examples.cpp) so
// that the command-line parser, which validates `qsmesh example NAME` before any work, links
// without OpenCASCADE (the fuzz targets build drivers/cli.cpp on its own).
#include "qsmesh/cad/model.hpp"

namespace qsmesh::cad {

std::vector<std::string> example_names() { return {"wing-body", "far-field", "perforated-plate"}; }

}  // namespace qsmesh::cad
