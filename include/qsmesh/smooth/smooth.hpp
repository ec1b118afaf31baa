// Geometry optimisation of quad meshes of one CAD face (paper 000 Sec. 5.3): SICN quality,
// Laplacian smoothing in the parameter plane, Winslow / angle-based kernels, measure and roll back.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/linalg/solver_cache.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::smooth {

/// SICN statistics over the quads of a mesh.
struct QualityReport {
  double sicn_min = 0, sicn_avg = 0;  ///< 0 when the mesh has no quad
  std::int64_t invalid = 0;           ///< quads with SICN <= 0
  std::int64_t quads = 0;             ///< quads measured
};

/// SICN (paper 000 Eq. 12, mesh::quad_sicn, on the 3D points) of every quad of the mesh.
/// Triangles are ignored.
[[nodiscard]] QualityReport measure(const mesh::FaceMesh& mesh);

struct SmoothOptions {
  int iterations = 10;       ///< passes of the explicit kernels over all free vertices
  bool laplacian_uv = true;  ///< step 1: Laplacian in the parameter plane (direct solve)
  bool winslow = true;       ///< step 2: Winslow (regular) / angle-based (irregular) kernels
  /// Step 2 maps kernel targets to the surface through the closest point on the input mesh
  /// (triangulated, with a bounding-volume hierarchy: ApproxSurface) instead of Gauss-Newton on
  /// the CAD surface; the last pass is always exact. Off by default: measured slower on the shared
  /// models (A319 at size factor 0.02: 3.9 s against 2.9-3.2 s of smoothing), the Gauss-Newton
  /// steps being three surface evaluations next to the quality checks of each move.
  bool approximate_projection = false;
  /// Wall-clock bound on the explicit passes, checked between passes (0: none). When it stops a
  /// run early the result depends on timing; leave 0 where reproducibility matters.
  double time_budget_s = 0;
  /// Called after each explicit pass (`pass` = 1, 2, ...) with the mesh as it stands (points and
  /// uv current, the dim-2 vclass.param not yet synced): false stops the smoothing there, and
  /// smooth_face returns that mesh as is, without the roll-back (SmoothStats::stopped_early).
  /// For a caller that refuses results below a threshold and can tell after a few passes that a
  /// candidate will not reach it (qstruct::remesh_cavities); the passes that run are the same
  /// as without it, so a mesh it lets through is bit for bit the mesh without it. Empty: none.
  std::function<bool(int pass, const mesh::FaceMesh& mesh)> after_pass;
};

struct SmoothStats {
  QualityReport before, after;
  int iterations = 0;          ///< explicit passes done
  bool rolled_back = false;    ///< the output is the input because the minimum SICN dropped
  bool stopped_early = false;  ///< SmoothOptions::after_pass stopped the passes
  /// Steps applied, e.g. "uv_laplacian+kernels", "uv_laplacian(rejected)+kernels",
  /// "uv_laplacian(skipped:seam)+kernels".
  std::string method;
};

/// Paper 000 Sec. 5.3 on the quads of one face mesh, boundary locked.
///
/// Takes a FaceMesh with consistent uv (boundary vertices at their pcurve images) and the face's
/// geometry. Free vertices: dim-2 vertices that are not used by any triangle; all others (dim 0,
/// dim 1, triangle vertices) keep bit-identical point and uv.
///  1) Laplacian in (u, v): arithmetic average of edge neighbours, one sparse direct solve (Eigen)
///     with the locked uv as Dirichlet values; skipped when the uv images are not continuous (a
///     boundary vertex whose (dim, entity, index) appears twice with different uv: seam; or a
///     boundary vertex where the surface normal vanishes: pole). New points S(uv). Kept only when
///     the minimum SICN does not drop and no quad flips against the face normal.
///  2) `iterations` Gauss-Seidel passes in vertex order: Winslow kernel (Eq. 13) on vertices with
///     four incident quads, angle-based kernel (bisectors of the one-ring) on the others, computed
///     in the tangent plane at the vertex, mapped to uv by the closest point on the input mesh
///     triangulated (ApproxSurface, uv interpolated; with approximate_projection) or by
///     Gauss-Newton steps on (du, dv) from the current uv (otherwise, and always in the last pass:
///     after `iterations` - 1 passes or after the pass that converged), the new point S(uv), so
///     every vertex lies on the CAD surface at its uv. A move is kept only when the minimum SICN of
///     the incident quads does not drop and none of them flips against the face normal.
///  3) Cusp quads: a quad that alone holds a dim-0 vertex where its angle is under 10 degrees has
///     its minimum SICN fixed by that corner, so step 2 lets its opposite (free) vertex wander.
///     That vertex is put on the line in (u, v) from the corner through the middle of the other
///     two vertices (the rung), 0.05 to 0.5 rung lengths past it, where the minimum SICN of its
///     other quads is highest, if higher than where it is; the cusp quad stays valid (oriented as
///     before) and no worse. Without it the quads behind the rung got a sharp or a flat angle
///     there.
/// Measures before and after; when the minimum SICN dropped or more quads are invalid, returns the
/// input (stats->rolled_back). Deterministic: no randomness, fixed order, no threads.
/// Returns the smoothed mesh (same topology and classification; dim-2 vclass.param = new uv).
/// `cache` (optional, owned by the calling thread): step 1's solver analysis is reused when the
/// same pattern comes again (linalg::SolverCache); the result is the same with or without it.
[[nodiscard]] mesh::FaceMesh smooth_face(const mesh::FaceMesh& mesh,
                                         const cad::FaceGeometry& surface,
                                         const SmoothOptions& options, SmoothStats* stats = nullptr,
                                         linalg::SolverCache* cache = nullptr);

}  // namespace qsmesh::smooth
