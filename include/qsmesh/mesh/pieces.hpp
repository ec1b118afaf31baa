// A face's quad mesh cut into pieces that are improved as tasks of their own, and put back
// together (issue 28: the CAD face is no longer the unit of parallelism). The cuts run along quad
// edges; the vertices shared by pieces ("cut vertices") are fixed in every piece, so the pieces
// can be edited independently and still conform when merged.
#pragma once

#include <span>
#include <vector>

#include "qsmesh/core/types.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::mesh {

/// Entities at or below kCutEntity mark cut vertices in a piece: VertexClass{0, kCutEntity - v}
/// for face vertex v (a corner of its own, so every improvement step keeps it fixed and keeps its
/// valence, and no two vertices share a key, which smoothing would read as a seam; the two images
/// of a seam vertex share v, the first image's id, so that it still does). The steps' own locked
/// classes (entities -2 - k, k small) stay far above.
inline constexpr LO kCutEntity = -(LO{1} << 30);

/// Whether `c` marks a cut vertex (split_face_mesh).
[[nodiscard]] inline bool is_cut_vertex(const VertexClass& c) {
  return c.dim == 0 && c.entity <= kCutEntity;
}

/// The centroid of each quad of `m` (the mean of its four points), by quad.
[[nodiscard]] std::vector<Vec3> quad_centroids(const FaceMesh& m);

/// Partition of the quads of `m` into pieces by recursive coordinate bisection of the quad
/// centroids in 3D: each set is cut across the longest extent of its centroids' bounding box (x
/// before y before z on ties), at the quantile that its two halves' shares of the leaves ask
/// for, centroids ordered by coordinate then quad id. Where k strips across the face's longest
/// extent would be at most 8 times longer across than along, every cut is across that extent
/// (strips: cuts that never cross, which a second, shifted cut then holds whole). Without
/// `shifted`, k leaves of equal share; with it, k + 1 leaves of shares 1/2, 1, ..., 1, 1/2, so that
/// on a strip the cuts fall halfway between those of the unshifted partition. Returns the piece of
/// each quad (pieces numbered from 0, none empty: empty leaves are dropped and the others
/// renumbered in order). Depends only on the mesh. Precondition: k >= 1.
[[nodiscard]] std::vector<LO> bisect_quads(const FaceMesh& m, LO k, bool shifted);

/// One piece of a face mesh.
struct FacePiece {
  /// The piece's quads (in face order) and the vertices they use: first the `boundary` vertices
  /// that must come back unchanged (the face's dim < 2 vertices of the piece and the cut
  /// vertices, in face order; cut vertices classified as is_cut_vertex), then the piece's own
  /// face-interior vertices in face order. triangles are not carried (an all-quad mesh is split).
  FaceMesh mesh;
  std::vector<LO> vertex;  ///< face vertex of each piece vertex
  LO boundary = 0;
};

/// Cuts `m` (all quads; quad_piece[q] in [0, pieces)) into `pieces` meshes. A cut vertex is a
/// vertex used by quads of two pieces or more. Throws Error when m has triangles or the sizes
/// differ.
[[nodiscard]] std::vector<FacePiece> split_face_mesh(const FaceMesh& m,
                                                     std::span<const LO> quad_piece, LO pieces);

/// Puts the pieces back into one face mesh. improved[p] is pieces[p].mesh after steps that keep
/// the first pieces[p].boundary vertices in place (same ids, points and uv bit for bit: checked,
/// Error otherwise) and may renumber, add or drop the others. The result: the face's dim < 2
/// vertices and its cut vertices in face order, with their classes in `m`, then each piece's
/// other vertices piece by piece; quads piece by piece.
[[nodiscard]] FaceMesh merge_face_pieces(const FaceMesh& m, std::span<const FacePiece> pieces,
                                         std::span<const FaceMesh> improved);

}  // namespace qsmesh::mesh
