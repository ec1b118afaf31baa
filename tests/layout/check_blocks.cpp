// check_blocks [--conforming] FILE.cgns: reads a block-structured CGNS file (qsmesh mesh
// --block-structured) back and checks every interface point by point, their reciprocity and that
// every block side edge is covered once, or once by each other side where more than two meet (a
// non-manifold curve; tests/common/cgns_blocks_check.hpp); with --conforming (the coarse layout),
// also that every interface joins a whole block side to a whole block side (no T-junction). Prints
// a one-line summary; exit 1 when a check fails.
#include <iostream>
#include <string>

#include "cgns_blocks_check.hpp"

int main(int argc, char** argv) {
  const bool conforming = argc == 3 && std::string(argv[1]) == "--conforming";
  if (argc != 2 && !conforming) {
    std::cerr << "usage: check_blocks [--conforming] FILE.cgns\n";
    return 2;
  }
  const char* file = argv[argc - 1];
  const qsmesh::test::BlockFileSummary s = qsmesh::test::check_block_file(file, conforming);
  std::cout << file << ": " << s.structured_zones << " structured zones (" << s.block_quads
            << " quads), " << s.unstructured_zones << " unstructured, " << s.interfaces
            << " 1-to-1 interfaces over " << s.interface_points << " points, " << s.abutments
            << " connectivities to the unstructured zone, " << s.boundary_conditions
            << " BCs: " << (s.error.empty() ? "all match" : s.error.substr(0, 2000)) << "\n";
  return s.error.empty() ? 0 : 1;
}
