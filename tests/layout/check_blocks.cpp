// check_blocks FILE.cgns: reads a block-structured CGNS file (qsmesh mesh --block-structured) back
// and checks every interface point by point, their reciprocity and that every block side edge is
// covered once, or once by each other side where more than two meet (a non-manifold curve;
// tests/common/cgns_blocks_check.hpp). Prints a
// one-line summary; exit 1 when a check fails.
#include <iostream>

#include "cgns_blocks_check.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: check_blocks FILE.cgns\n";
    return 2;
  }
  const qsmesh::test::BlockFileSummary s = qsmesh::test::check_block_file(argv[1]);
  std::cout << argv[1] << ": " << s.structured_zones << " structured zones (" << s.block_quads
            << " quads), " << s.unstructured_zones << " unstructured, " << s.interfaces
            << " 1-to-1 interfaces over " << s.interface_points << " points, " << s.abutments
            << " connectivities to the unstructured zone, " << s.boundary_conditions
            << " BCs: " << (s.error.empty() ? "all match" : s.error.substr(0, 2000)) << "\n";
  return s.error.empty() ? 0 : 1;
}
