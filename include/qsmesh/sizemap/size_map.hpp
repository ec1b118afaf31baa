// Size map of the final quad mesh (paper 000 Sec. 4 intro, 4.1, 4.2): the small-feature size field
// s_min (Sec. 4.1, Eq. 10), the per-face conformal sizes s_cf = exp(H + C_i) of the cross field
// (Sec. 3.3, Sec. 4.2) with C_i chosen for the face's share N_i of the target quad count, their
// union with the minimum on shared curves and corners, the one-way gradation, s = min(s_cf, s_min).
//
// Distributed flow (every rank; nothing depends on the partition or the thread count):
//   initial = initial_curve_sizes(model, curves, options, tasks)      // identical on every rank
//   union = initial                                                   // (a copy; see
//   fold_boundary_min) for each local face f: fold_boundary_min(bg[f], face_sizes(bg[f], cf[f],
//   curves, initial, N[f], options).s, union) MPI min-reduction of union.pack() over all ranks,
//   union.unpack(...) grade_curves(model, curves, options.gradation, union)            // the curve
//   sizes of the model for each local face f: face_sizes(bg[f], cf[f], curves, union, N[f],
//   options)   // final per-face field
// The curve sizes after grade_curves feed the curve quantization (Sec. 4.3): ideal count = ∫ dl /
// s.
#pragma once

#include <span>
#include <utility>
#include <vector>

#include "qsmesh/background/feature_size.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/core/types.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::sizemap {

/// `Features`: s_min and the user sizes only (Sec. 4.1); `CrossField`: min(union of s_cf, s_min)
/// (Sec. 4.2).
enum class Method { Features, CrossField };

struct SizeMapOptions {
  Method method = Method::CrossField;
  /// Global cap (model units, > 0): --size, or --size-factor x the model diagonal.
  double size_max = 0;
  /// Floor of the automatic sizes (model units); 0: size_max / 100. User sizes below it are
  /// honoured (the floor is then lowered to the smallest user size, see effective_size_min).
  /// Given (> 0, --size-min), it also bounds rule (i) of Sec. 4.1: a curve shorter than the floor
  /// (a sliver edge of the CAD) keeps its 2 edges but no longer makes the sizes around it finer
  /// than the floor, except at its two corners, which are at most 5 x its length (rule (i'),
  /// unless a four-sided face without the curve touches the corner) so that the sizes grade
  /// toward its edges instead of dropping to them in one row of quads. With 0, rule (i) goes below
  /// the default floor as the paper has it (no size above its curve's length): wing_fuselage's two
  /// 0.036-long curves at the wing root then grade every face around them from 0.036 where the size
  /// cap is about 6.
  double size_min = 0;
  /// g_max of Eq. 10: largest growth of the size per unit distance (0.2: progression ratio 1.2).
  double gradation = 0.2;
  /// Edges per full turn on curved curves (a radius R gives 2 pi R / n on the curves); 0 switches
  /// the curvature sizes off.
  double edges_per_turn = 16;
  /// Also 2 pi R / n from the largest principal curvature of the faces along their curves. Off by
  /// default: paper 000's size map has no curvature term, and a face's curvature across it (a
  /// wing's leading edge) then sets isotropic sizes along it as well, so that its opposite sides
  /// get unequal counts and no pattern fits. Measured at the reference vertex counts
  /// (docs/benchmarks.md, tenth session): A319 interior irregular 3.13% -> 1.54%, SICN avg 0.886 ->
  /// 0.889, 45 -> 56 faces by pattern; Block 1.29% -> 1.28%, 0.912 -> 0.928, 393 -> 398.
  bool face_curvature = false;
  /// How far a small feature may refine: rule (ii) (the distance to the nearest curve sharing no
  /// corner) lowers a curve's size to no less than this fraction of the size it has without that
  /// rule, in [0, 1]; 0 resolves every feature down to the floor, as Sec. 4.1 reads. Gmsh's
  /// implementation clamps the same way, by the edges of its background triangulation, which is
  /// about as fine as the target mesh. Without the clamp a thin strip (a wing's blunt trailing
  /// edge, a slot) sizes its long curves by its width, and the faces along them carry the
  /// transition back to the target size with irregular vertices. Measured at the reference vertex
  /// counts (docs/benchmarks.md, eleventh session), 0 -> 0.75: interior irregular Block 1.28% ->
  /// 0.96%, wing_fuselage 2.60% -> 0.82%, A319 1.54% -> 1.50%.
  double feature_ratio = 0.75;
  /// Largest length-to-width ratio K of the edges along a thin face (>= 0; 0: off). Where a curve
  /// and another side of one of its faces (sharing no corner with it; joined through a curve
  /// shorter than the floor only as a strip's end, see background::limit_by_face_width) are closer
  /// than half the curve's size before rule (ii), the size along the curve is capped at K x that
  /// width. The feature ratio keeps the size along a strip at nearly the full size, and a quad w/2
  /// wide (2 across) and L long has SICN about w / L: K = 4 keeps it near 0.25. Only along the
  /// strip (local anisotropy; the count across stays that of the quantization), and below the
  /// floor, which would otherwise make flat quads in strips narrower than floor / K; gaps under a
  /// tenth of the floor (curves touching) do not count. Inside a wedge sharper than 10 degrees
  /// (sides sharing a corner: a cusp's tail) the tip is one edge (CurveSizes::tips) and, where
  /// both sides bound that face alone, the tail behind it is capped at 3/4 K x its width
  /// (background::limit_by_face_width, background::sharp_wedge_tips).
  double thin_aspect = 0;
  /// One edge on sliver curves: a curve shorter than a tenth of the floor (sliver_length) takes 1
  /// edge in the quantization (quantize::QuantizeOptions::sliver_length) and rule (i') grades its
  /// corners from kOneEdgeSliverCornerRatio x its length at every corner, grid faces' included. A
  /// quad with an edge l beside an edge L has SICN at most about 2 l / L: the two half-length
  /// edges of a 2-edge sliver need neighbours twice as short, and grading a corner that a grid
  /// face touches carries the finer counts through the grid (see size_min).
  bool one_edge_slivers = false;
  /// N, the target number of quads of the whole model; 0: total area / size_max^2.
  double target_quads = 0;
  /// (face id, quad count) fixed by the user: that face gets this N_i instead of its area share.
  std::vector<std::pair<LO, double>> face_quads;
  /// User size constraints (entity id, size in model units, > 0). A face size caps the size inside
  /// the face and on its boundary curves.
  std::vector<std::pair<LO, double>> corner_sizes, curve_sizes, face_sizes;
};

/// The floor actually applied: size_min (or size_max / 100) lowered to the smallest user size.
/// Throws InputError when size_max <= 0, size_min < 0 or size_min > size_max.
[[nodiscard]] double effective_size_min(const SizeMapOptions& options);

/// The length below which a curve is a sliver that takes one edge (one_edge_slivers): a tenth of
/// effective_size_min, the gap below which rule (ii) ignores a feature; 0 when one_edge_slivers is
/// off.
[[nodiscard]] double sliver_length(const SizeMapOptions& options);

/// Size values (model units) at the vertices of the curve meshes.
struct CurveSizes {
  /// at[c][i]: vertex i of curve c's mesh, both ends included (they are corners; a corner's value
  /// is the same in every curve ending there once grade_curves / initial_curve_sizes ran).
  std::vector<std::vector<double>> at;
  /// corner[k]: the value at corner k (what faces read at their dim-0 vertices).
  std::vector<double> corner;
  /// The tips of sharp wedges (thin_aspect, initial_curve_sizes): one quad holds each, so
  /// grade_curves sets the curve's sizes within `length` of the corner to `length` (one edge),
  /// whatever the gradation gave them. The same on every rank; not part of pack().
  std::vector<background::SharpTip> tips;

  /// Every value in one flat array: at[0], at[1], ..., then corner (for an MPI min-reduction).
  [[nodiscard]] std::vector<double> pack() const;
  /// Inverse of pack: `flat` must have the size pack() returns.
  void unpack(std::span<const double> flat);
};

/// CurveSizes shaped like `curves` (one value per curve-mesh vertex) and `num_corners`, all
/// `value`.
[[nodiscard]] CurveSizes make_curve_sizes(std::span<const mesh::CurveMesh> curves, LO num_corners,
                                          double value);

/// Initial curve sizes, global and the same on every rank (Sec. 4.1): size_max, user curve sizes,
/// user face sizes on the face's boundary curves; for both methods the small-feature limits: no
/// larger than (i) the curve's length and (ii) the distance to the nearest curve sharing no corner
/// (background::limit_by_feature_distance on the curve-mesh polylines, densified so that a segment
/// is no longer than half the local size), (ii) lowering a size to no less than feature_ratio x
/// its value before (ii); floored by effective_size_min (so (i) and (ii) hold for
/// features larger than the floor; (i) also below the floor unless size_min was given); the
/// corners of curves shorter than the floor at most 5 x their length (i'); then user corner sizes,
/// the thin-face cap (thin_aspect), and grade_curves (corners = min over their curves, Eq. 10 along
/// the curve edges and through corners). `curves` indexed by curve id, as background::mesh_curves
/// returns them. Deterministic whatever the thread count of `tasks`. Throws InputError for bad
/// options (sizes <= 0, ids out of range).
[[nodiscard]] CurveSizes initial_curve_sizes(const cad::CadModel& model,
                                             std::span<const mesh::CurveMesh> curves,
                                             const SizeMapOptions& options, const TaskArena& tasks);

/// Face quad targets N_i (Sec. 4.2): area_i / total area x N, or the user's value (face_quads) for
/// the faces the user fixed (the paper's substitution: the other faces keep their area share).
/// Indexed by face id. Throws InputError for a bad face id or a negative count.
[[nodiscard]] std::vector<double> face_quad_targets(const cad::CadModel& model,
                                                    const SizeMapOptions& options);

/// Quads a mesh following the size field `s` (one value per vertex of `background`, model units)
/// would have on the face: the sum over the triangles of their 3D area over the squared mean of
/// `s` at their corners (an edge of length s per quad side). Triangles where that mean is not
/// positive count for nothing. Used to bound structured fills by what the size map asks for.
[[nodiscard]] double expected_quads(const mesh::FaceMesh& background, std::span<const double> s);

/// Per FaceMesh vertex (model units).
struct FaceSizes {
  std::vector<double> s;  ///< the size map: min(s_cf, s_min) graded, capped, floored
  /// Small-feature field (Sec. 4.1): the `curve` values graded over the face, capped and floored
  /// (the pure s_min when `curve` is initial_curve_sizes; after the union it includes s_cf there).
  std::vector<double> s_min;
  std::vector<double> s_cf;  ///< exp(H + C_i), ungraded (empty when no cross field is used)
  /// Every field, once (visit(name, member)): what the ranks exchange (parallel/record.hpp).
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("s", self.s);
    visit("s_min", self.s_min);
    visit("s_cf", self.s_cf);
  }
};

/// The size field of one face at its FaceMesh vertices. Boundary vertices start from `curve` (dim
/// 1: at[curve][index], dim 0: corner[corner]), interior vertices from +inf (s_min) or from s_cf =
/// exp(H + C_i) with C_i = crossfield::scaling_constant(*cf, face_quads) (CrossField method, cf not
/// null, face_quads > 0); then Eq. 10 by Dijkstra (a heap) over every edge of the glued
/// triangulation (seams and poles interior), the edges on curves included, so a boundary value may
/// come out lower than `curve` where a path through the face is shorter than along the curves (the
/// union, fold + reduction + grade_curves, carries that to the other faces). Then capped by
/// size_max and the user face size, floored by effective_size_min (both keep the gradation bound).
/// cf: the face's cross field (its input2glued must match `background`), or null (Features method,
/// or a face whose cross field failed: s_min only). Throws qsmesh::Error on inconsistent inputs.
[[nodiscard]] FaceSizes face_sizes(const mesh::FaceMesh& background,
                                   const crossfield::FaceCrossField* cf,
                                   std::span<const mesh::CurveMesh> curves, const CurveSizes& curve,
                                   double face_quads, const SizeMapOptions& options);

/// Folds values at the boundary vertices of `background` (one per FaceMesh vertex) into `into` by
/// minimum: dim 1 into at[curve][index], dim 0 into corner[corner]. This is one rank's contribution
/// to the union of Sec. 4.2; start `into` as a copy of initial_curve_sizes (identical on every
/// rank, so an MPI min over ranks is unchanged by it, and curves that no local face touches keep
/// their initial values), then min-reduce pack() over ranks.
void fold_boundary_min(const mesh::FaceMesh& background, std::span<const double> values,
                       CurveSizes& into);

/// The one-way 1D gradation along the curves (Eq. 10 along curve-mesh edges, through corners):
/// first corner[k] = min(corner[k], the end values of the curves ending at k), then Dijkstra over
/// the graph of all curve meshes (exact, no sweeps), and every curve end gets its corner's value.
/// Degenerate curves take their corner's value. Serial and deterministic.
void grade_curves(const cad::CadModel& model, std::span<const mesh::CurveMesh> curves,
                  double gradation, CurveSizes& sizes);

}  // namespace qsmesh::sizemap
