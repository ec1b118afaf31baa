// Quad layout of an all-quad surface mesh: its partition into structured blocks (paper 002 Sec.
// II-III.A), for block-structured output (structured zones with 1-to-1 connectivity).
//
// Traces (separatrices) leave every irregular interior vertex along each of its edges, and every
// CAD corner or curve vertex with a side of other than two quads (a side: the quads between two
// consecutive curve edges at the vertex) along that side's interior edges; a corner with two quads
// on its side lies on a block side, a convex one with one quad is a block corner. A trace runs
// straight through regular vertices (valence 4) and stops at a CAD curve, at an irregular vertex
// or, as in the motorcycle graph of paper 002 Sec. III.A, at a vertex another trace has already
// reached (a T-junction). All traces advance one edge per round in a fixed order, so the layout
// depends on the mesh only. The quads are then grouped into patches bounded by traces and CAD
// curves; each patch is a grid of ni x nj quads, a block, and blocks of one face sharing a whole
// side off the CAD curves are merged while any do. Paper 002 goes on to simplify this layout (ILP
// quantization, Sec. III.B-C); that is not done here, so the blocks are those of the
// quasi-structured mesh as it is. A curve that three or more faces border is a curve like any
// other: no trace crosses it, and each face's blocks end on it. Edges are taken face by face, so
// a face the CAD gives twice (the same surface and boundary) is cut along its own traces even
// where both copies hold an edge between the same two curve vertices.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "qsmesh/core/types.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::layout {

/// One structured block: ni x nj quads of CAD face `face` (a block of the coarse layout may span
/// faces joined across smooth curves, layout::CoarseOptions::cross_smooth_curves: `face` is then
/// the face of its first coarse quad, and each quad keeps its own face in the mesh). Its (ni + 1) x
/// (nj + 1) vertices are QuadLayout::vertices[first + j * (ni + 1) + i] (global mesh vertex ids, i
/// fastest); the quads are counter-clockwise about the face normal in (i, j), i.e. the normal is
/// along i x j.
struct Block {
  LO face = kNoIndex;
  LO ni = 0, nj = 0;
  std::int64_t first = 0;
  [[nodiscard]] GO vertex(LO i, LO j, const std::vector<GO>& vertices) const {
    return vertices[static_cast<std::size_t>(first + static_cast<std::int64_t>(j) * (ni + 1) + i)];
  }
};

struct LayoutOptions {
  /// Traces stop at vertices other traces reached first (motorcycle graph: fewer, larger blocks).
  /// A face whose patches are not all grids this way (a patch around a hole, say) is traced again
  /// with every trace extended to a CAD curve or an irregular vertex.
  bool motorcycle = true;
  /// Then merge, face by face, blocks sharing a whole side that is not on a CAD curve (their union
  /// is a grid), as long as any do.
  bool merge = true;
};

/// A block given for a face instead of traced from its mesh: paper 003's partition into
/// four-sided regions (fieldmesh::RegionGrid, in the assembled mesh's vertex ids). ni x nj quads
/// of CAD face `face` with (ni + 1) x (nj + 1) vertices, i fastest, oriented as Block.
struct GivenBlock {
  LO face = kNoIndex;
  LO ni = 0, nj = 0;
  std::vector<GO> vertices;
};

struct QuadLayout {
  std::vector<Block> blocks;   ///< by face, then by the smallest quad id of the block
  std::vector<GO> vertices;    ///< the blocks' vertex grids (Block::first)
  std::vector<GO> quad2block;  ///< block of each mesh quad (-1: in no block)
  /// Faces meshed with triangles, or whose patches are not grids even with extended traces: their
  /// elements are in no block (block-structured output writes them as an unstructured zone).
  std::vector<LO> unblocked_faces;
  LO faces_with_extended_traces = 0;  ///< faces traced again with extended traces
  LO faces_with_given_blocks = 0;     ///< faces whose blocks are the given ones
};

/// Partitions the quads of `mesh` (an assembled SurfaceMesh: bars on every CAD curve, each CAD
/// face's elements oriented along its normal) into blocks. Deterministic: depends on the mesh only.
/// The faces of `given` take those blocks as they are (neither traced nor merged) when they cover
/// the face's quads exactly once, each cell a quad of the face with its orientation; a face whose
/// given blocks do not is traced as the others. Their blocks end on the CAD curves like the traced
/// ones, so those of a neighbouring face may meet them in T-junctions there, as traced faces do.
[[nodiscard]] QuadLayout extract_quad_layout(const mesh::SurfaceMesh& mesh,
                                             const LayoutOptions& options = {},
                                             std::span<const GivenBlock> given = {});

}  // namespace qsmesh::layout
