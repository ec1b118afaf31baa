// Each block of a structured layout as one Lagrange quad of order 2 to 5 on the CAD: paper 002's
// "light, universal" representation of a model by its coarse blocks (Sec. IV.F: the blocks of the
// coarse layout as high-order patches).
#pragma once

#include <cstdint>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/layout/quad_layout.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::highorder {

struct BlockPatchReport {
  int order = 1;
  std::int64_t patches = 0;      ///< one per block
  std::int64_t curve_bars = 0;   ///< block sides along one CAD curve, written as bars
  std::int64_t nodes = 0;        ///< high-order nodes (edges and interiors)
  std::int64_t unprojected = 0;  ///< nodes left off the CAD (no CAD point near: NaN parameters)
  /// Patches whose Jacobian is not positive along the fine mesh's normal at every point of the
  /// (2N + 1)^2 sample grid: the block bends too much for one polynomial of this order.
  std::int64_t invalid = 0;
  /// Largest distance between a patch, at the centres of the cells of its node grid, and the fine
  /// mesh's bilinear cell at the same grid position, along that cell's normal (model units): how
  /// far the light representation is from the mesh.
  double max_deviation = 0;
};

/// Makes `patches` the mesh of order `order` (in [kMinOrder, kMaxOrder]) with one quad per block of
/// `layout` over `fine` (an order-1 all-quad SurfaceMesh, the mesh whose vertex ids the layout's
/// grids hold; Block::vertex(i, j) with i along corner 0 -> 1 of the patch). Node (a, b) of a
/// block's patch, 0 <= a, b <= order, sits at grid position (a ni / order, b nj / order) of the
/// block: a fine vertex where that is a whole grid position, else the bilinear point of the fine
/// cell (or the linear point of the fine edge) projected on its CAD curve (a fine edge on a curve)
/// or face (from the (u, v) of the cell's corners); classified as such (dim 1 or 2 with its
/// parameters, index kNoIndex). A side shared by two blocks has one set of nodes (the layout is
/// conforming: sides are shared whole); a side along a CAD curve is also a bar of that curve.
/// Block corners keep the fine mesh's vertex ids' classification; vertex ids are renumbered:
/// the CAD corners first (id = corner id), then the other block corners by first use, then the
/// nodes. Each patch is checked (Jacobian along the fine cell's normal at each sample) and
/// counted in `invalid` when it folds; nothing is straightened (a straight block is no better a
/// representation). Serial and deterministic. Throws qsmesh::Error on an out-of-range order, a
/// fine mesh that is not of order 1, or a block grid that does not reference `fine`'s vertices.
BlockPatchReport make_block_patches(const mesh::SurfaceMesh& fine, const layout::QuadLayout& layout,
                                    const cad::CadModel& model, int order,
                                    mesh::SurfaceMesh& patches);

}  // namespace qsmesh::highorder
