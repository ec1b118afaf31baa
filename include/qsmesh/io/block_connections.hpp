// How the blocks of a quad layout meet: the 1-to-1 interfaces, the free block edges (boundary
// conditions on CAD curves) and the runs of block sides along faces the layout left out. Computed
// once here for every block-structured writer (CGNS, PLOT3D's sidecar), so that they agree.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "qsmesh/layout/quad_layout.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::io {

/// The four sides of a block, in the order they are visited: jmin, imax, jmax, imin (so that
/// walking them with increasing positions goes once around the block's boundary, i fastest).
inline constexpr std::array<const char*, 4> kBlockSideNames{"jmin", "imax", "jmax", "imin"};

/// A vertex range of a block, 1-based as in CGNS: (i0, j0) to (i1, j1), one of the indices
/// constant (a range along one side).
using BlockRange = std::array<std::int32_t, 4>;

/// A maximal run of one block side shared, edge for edge, with a run of one side of a block (the
/// same block across a seam, too): CGNS GridConnectivity1to1.
struct BlockInterface {
  int side = 0;            ///< this block's side (kBlockSideNames)
  BlockRange range{};      ///< on this block, from the run's first vertex to its last
  std::int64_t donor = 0;  ///< the other block (index into QuadLayout::blocks)
  int donor_side = 0;
  BlockRange donor_range{};  ///< the same points on the donor, in the same order
  /// CGNS Transform: index d of this block runs along index |t[d]| - 1 of the donor, in the
  /// direction of sign(t[d]).
  std::array<int, 2> transform{};
};

/// A maximal run of free block side edges (no block across, no left-out face across) on one CAD
/// curve: an open shell's border. CGNS writes a BC (family "Curve_<curve>", BCWall) there.
struct BlockBoundary {
  int side = 0;
  BlockRange range{};
  LO curve = kNoIndex;
};

/// A maximal run of block side edges on CAD curves along faces the layout left out (their elements
/// have the edges): where the block meets the unstructured part.
struct BlockAbutment {
  int side = 0;
  BlockRange range{};
  std::vector<std::array<std::int32_t, 2>> ij;  ///< the run's points (1-based (i, j)), in order
  std::vector<GO> vertices;                     ///< their mesh vertex ids, in the same order
};

/// The connections of one block, each list by side (jmin, imax, jmax, imin), then along it;
/// interfaces starting at the same edge by donor block, then donor side.
struct BlockLinks {
  std::vector<BlockInterface> interfaces;
  std::vector<BlockAbutment> abutments;
  std::vector<BlockBoundary> boundaries;
};

/// Per block of the layout (same order).
struct BlockConnections {
  std::vector<BlockLinks> blocks;
};

/// The name of block k of `layout` in block-structured output (CGNS zone, PLOT3D sidecar):
/// "Block_<k>_Face_<f>", k and f zero-padded to 6 digits, or to the digits of the larger of the
/// block count and `num_cad_faces` (so that the names sort as the blocks do).
[[nodiscard]] std::string block_name(const layout::QuadLayout& layout, GO k, LO num_cad_faces);

/// Throws qsmesh::Error (naming `what`, the writer) unless every block of `layout` fits the
/// layout's arrays and `mesh`: ni, nj > 0, face and vertex ids in range.
void check_layout_for_output(const mesh::SurfaceMesh& mesh, const layout::QuadLayout& layout,
                             const std::string& what);

/// The connections of the blocks of `layout` (from layout::extract_quad_layout(mesh); checked as by
/// check_layout_for_output). A block side edge is joined to every other block side edge between
/// the same two vertices when the edge lies on a CAD curve (where three or more faces border the
/// curve, each side to every other: a side edge where m sides meet is in m - 1 interfaces), and
/// off the curves only to sides of blocks of the same face (a face given twice meets its copy on
/// its curves only). Runs are maximal: consecutive side edges joined to consecutive edges of one
/// donor side, in one direction. A side edge on a curve joined to no block side is an abutment
/// when an element of a face in layout.unblocked_faces has it, else a boundary. Throws
/// qsmesh::Error when two joined runs do not carry the same vertices. Deterministic.
[[nodiscard]] BlockConnections block_connections(const mesh::SurfaceMesh& mesh,
                                                 const layout::QuadLayout& layout);

}  // namespace qsmesh::io
