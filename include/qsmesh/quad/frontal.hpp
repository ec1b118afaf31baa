// Cross-field-guided frontal point insertion (paper 000 Sec. 5.1): the interior points of the
// quad-dominant triangulation of one CAD face, placed along the cross field at the distance the
// size map asks for, so that the triangles come out right-angled and aligned and recombine into
// quads (Sec. 5.2).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/core/types.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/mesh/delaunay.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::quad {

/// The cross field and the size map of one face read at any (u, v) of the face, from its
/// background triangulation (the mesh the cross field and the size map were computed on).
/// Point location is in (u, v) through a uniform grid of the background triangles; the cross of
/// the located triangle is returned (constant per triangle) and the size is interpolated linearly
/// from the vertex values. Where (u, v) lies in no background triangle (outside the face, or near a
/// pole, where the background triangles of the pole fan are distorted or inverted in (u, v)) the
/// triangle of the nearby cells that is least outside is used instead (`found` false).
class FaceGuide {
 public:
  /// background: the face's background FaceMesh; cross_field: its cross field (input2glued must
  /// match `background`); sizes: one size per background vertex (model units, > 0; e.g.
  /// sizemap::FaceSizes::s). Throws qsmesh::Error when they do not fit together. The referenced
  /// objects must outlive the guide.
  FaceGuide(const mesh::FaceMesh& background, const crossfield::FaceCrossField& cross_field,
            std::span<const double> sizes);

  struct Sample {
    std::array<Vec3, 2> cross{};  ///< the two unit branches of the cross (3D, tangent)
    double size = 0;              ///< the size map (model units)
    bool found = false;           ///< uv lies in a background triangle
  };
  [[nodiscard]] Sample at(const Vec2& uv) const;
  /// Smallest and largest size at the background vertices (bounds of every Sample::size).
  [[nodiscard]] std::pair<double, double> size_range() const;

 private:
  const mesh::FaceMesh& bg_;
  const crossfield::FaceCrossField& cf_;
  std::span<const double> sizes_;
  std::vector<LO> tri2glued_;  // background triangle -> cross-field triangle (kNoIndex: collapsed)
  Box2 box_;
  int nu_ = 1, nv_ = 1;
  double cu_ = 1, cv_ = 1;                  // cell sizes
  std::vector<LO> cell_start_, cell_tris_;  // CSR: cell -> background triangles (increasing)
  [[nodiscard]] bool barycentric(LO t, const Vec2& uv, std::array<double, 3>& w) const;
};

struct FrontalOptions {
  /// Target spacing = spacing_factor x the size map. 2 at the halved level of the pipeline (the
  /// triangles become quads of half their size by midpoint subdivision).
  double spacing_factor = 2.0;
  /// A candidate is rejected when an existing point lies in its exclusion zone: the square of
  /// half-width min_distance x its target spacing with sides along the cross at the point it was
  /// proposed from (cross_aligned_exclusion, as Gmsh's frontal quad mesher), else the disk of
  /// that radius. With the disk, two fronts offset by half a spacing interleave (the diagonal
  /// neighbour at 0.71 x spacing passes) into a lattice turned by 45 degrees: mambo_s34's H-shaped
  /// face 41 had such a region of about 3000 quads across its middle, where the cross field is
  /// aligned with the sides (719 irregular vertices in its all-quad mesh, 112 with the square).
  /// Square, end to end at the reference vertex counts (docs/benchmarks.md), min_distance 0.5 /
  /// 0.55 / 0.6: interior irregular Block 1.83 / 2.01 / 2.03%, A319 4.57 / 5.26 / 5.58%, mambo
  /// 0.25 / 0.26 / 0.24%; SICN avg mambo 0.971 / 0.974 / 0.976. The disk had its best at 0.6
  /// (Block 2.03%, A319 5.06%, mambo 0.39% and SICN avg 0.959).
  double min_distance = 0.5;
  bool cross_aligned_exclusion = true;
  /// At most this many interior points (guards against runaway insertion).
  std::int64_t max_points = 5'000'000;
};

struct FrontalStats {
  std::int64_t proposed = 0;
  std::int64_t accepted = 0;
  std::int64_t outside = 0;    ///< rejected: outside the face (parameter-plane test) or unmappable
  std::int64_t too_close = 0;  ///< rejected: closer than min_distance x spacing to a point
  std::int64_t off_guide = 0;  ///< samples of the guide outside the background triangles
};

/// Paper 000 Sec. 5.1 on one face. The boundary points of `loops` (as background::face_boundary
/// builds them, in (u, v) and 3D) seed a FIFO queue; the vertex at its front proposes the four
/// points at distance spacing_factor x s(x) along the branches of the cross at x (in the tangent
/// plane, mapped to (u, v) by Gauss-Newton on the surface Jacobian, then evaluated on the
/// surface). A proposal is kept when it is inside the face (even-odd test on the loops in
/// (u, v)) and no existing point (boundary points and samples along the boundary segments
/// included) lies in its exclusion zone (FrontalOptions::cross_aligned_exclusion, min_distance x
/// its spacing, in 3D; multilevel uniform hash grids); kept
/// points join the end of the queue. Returns the (u, v) of the accepted points in insertion order.
/// Deterministic. Seams: their two parameter-plane images are boundary segments, the 3D distance
/// test sees across them. Poles: the 3D test sees the pole; the Gauss-Newton step is damped there.
[[nodiscard]] std::vector<Vec2> frontal_points(const cad::FaceGeometry& surface,
                                               std::span<const mesh::BoundaryLoop> loops,
                                               const FaceGuide& guide,
                                               const FrontalOptions& options,
                                               FrontalStats* stats = nullptr);

}  // namespace qsmesh::quad
