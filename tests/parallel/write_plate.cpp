// Writes the long plate of the sub-face task measurements (issue 28, docs/benchmarks.md): a
// planar seven-sided face, LENGTH x WIDTH, with a slanted end, a notch and three holes, so that
// no pattern fits it and the unstructured path and the improvement mesh it whole.
//   qsmesh_write_plate OUT.brep [LENGTH [WIDTH]]   (default 100 x 20)
#include <cstdlib>
#include <iostream>
#include <string>

#include "shapes.hpp"

int main(int argc, char** argv) {
  if (argc < 2 || argc > 4) {
    std::cerr << "usage: qsmesh_write_plate OUT.brep [LENGTH [WIDTH]]\n";
    return 2;
  }
  const double length = argc > 2 ? std::atof(argv[2]) : 100.0;
  const double width = argc > 3 ? std::atof(argv[3]) : 20.0;
  if (!(length > 0 && width > 0)) {
    std::cerr << "qsmesh_write_plate: LENGTH and WIDTH must be positive\n";
    return 2;
  }
  std::cout << qsmesh::test::write_long_plate(length, width, argv[1]) << "\n";
  return 0;
}
