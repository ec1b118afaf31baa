// Raw pattern data compiled from data/patterns.txt (generated source patterns_data.cpp).
#pragma once

#include <span>

#include "qsmesh/core/types.hpp"

namespace qsmesh::qstruct::detail {

struct RawPattern {
  const char* name;
  const double* xy;  ///< 2 * num_vertices drawing coordinates
  LO num_vertices;
  const LO* quads;  ///< 4 * num_quads vertex ids
  LO num_quads;
};

/// The patterns of data/patterns.txt, in file order.
std::span<const RawPattern> raw_patterns();

}  // namespace qsmesh::qstruct::detail
