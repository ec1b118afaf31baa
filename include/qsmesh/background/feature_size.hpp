// Small CAD features (paper 000 Sec. 4.1): the distance from a curve to the nearest curve that is
// not topologically adjacent to it bounds the mesh size there. Used by the background curve
// meshing and by the small-feature size field s_min of the size map.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/core/types.hpp"

namespace qsmesh::background {

/// Lowers sizes[c][k] to the distance from polyline vertex k of curve c to the nearest curve that
/// shares no corner with c (model units), searching only within the current sizes[c][k] (a k-d tree
/// over all vertices: no all-pairs search, and no cost that depends on how the radii vary).
/// polylines[c] are points along curve c, dense enough that the polyline stands for the curve (its
/// segments are what distances are taken to); empty polylines (degenerate curves) are skipped.
/// Distances up to `touching` are ignored: curves that touch or lie on top of each other are not
/// features. A feature never asks for less than `floor` (sizes already below it stay as they are).
/// Deterministic, whatever the thread count of `tasks`.
void limit_by_feature_distance(const cad::CadModel& model,
                               std::span<const std::vector<Vec3>> polylines,
                               std::vector<std::vector<double>>& sizes, double touching,
                               double floor, const TaskArena& tasks);

/// The width of thin faces along their sides: lowers sizes[c][k] to the distance d from polyline
/// vertex k of curve c to the nearest curve that bounds a face with c but shares no corner with it
/// (the other side of a strip or a neck), searching only within the current sizes[c][k]; no floor.
/// Distances up to `touching` are ignored (curves touching), and up to `wedge_touching` between
/// sides sharing a corner (inside a sharp wedge, where the tip sharp_wedge_tips finds with the
/// same width is one edge) or joined by a sliver curve within 4 x its length of it (a blunted
/// wedge's tip). Curves near each other across a gap between two faces (a slot) do not count:
/// neither face is thin there. Two curves whose ends are joined by a curve shorter than `sliver`
/// (the end of a strip, or the blunted tip of a wedge) count only where d is at most twice that
/// curve's length (a strip as wide as its end) or less than sin(10 degrees) x the distance from the
/// vertex to the joint (a wedge sharper than that). The distance is taken in space, so it is at
/// most the width inside the face. Sides sharing a corner count (at 3/4 of d) only where both
/// bound that one face and no other; with `shared_wedges_only`, only the other sharp wedges'
/// sides count (at d), and nothing else (sizemap: the tails of extruded wedges). Same inputs and
/// determinism as limit_by_feature_distance.
void limit_by_face_width(const cad::CadModel& model, std::span<const std::vector<Vec3>> polylines,
                         std::vector<std::vector<double>>& sizes, double touching,
                         double wedge_touching, double sliver, const TaskArena& tasks,
                         bool shared_wedges_only = false);

/// limit_by_feature_distance, and the resolution inside sharp wedges, one curve at a time over
/// polylines given once (their k-d tree built once), for callers that split the curves over ranks
/// or tasks: a curve's result is exactly what limit_by_feature_distance over all curves gives it,
/// whichever curves are done with it and in whatever order. Thread-safe (const). Holds a reference
/// to `model`.
class CurveFeatureSearch {
 public:
  /// polylines: as limit_by_feature_distance's, indexed by curve id.
  CurveFeatureSearch(const cad::CadModel& model, std::vector<std::vector<Vec3>> polylines);
  ~CurveFeatureSearch();
  CurveFeatureSearch(CurveFeatureSearch&&) noexcept;
  CurveFeatureSearch& operator=(CurveFeatureSearch&&) noexcept;
  /// limit_by_feature_distance on curve c: h, one size per vertex of polyline c (checked), lowered
  /// in place.
  void limit_by_feature_distance(LO c, std::vector<double>& h, double touching, double floor) const;
  /// Resolution inside sharp wedges (a cusp's tail): lowers h[k] to twice the distance d from
  /// vertex k of curve c to another side of one of its faces that shares a corner with c, where d
  /// is below sin(sharp_deg) x the distance to that corner, searching within half the current
  /// size; distances up to `touching` are ignored. The background curve meshes need it so that the
  /// sizes graded along such a tail (sizemap::SizeMapOptions::thin_aspect) have vertices to live
  /// on. h: one size per vertex of polyline c (checked).
  void limit_in_sharp_wedges(LO c, std::vector<double>& h, double touching, double sharp_deg) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The tip of a sharp wedge: where curve `curve` leaves its corner at end `end` (0: its first
/// corner, 1: its last) inside a wedge sharper than the given angle with another side of one of its
/// faces sharing that corner (a cusp, a sliver's end), the stretch of it, `length` (model units,
/// straight from the corner), that one quad holds. `shared`: the two sides do not bound that face
/// alone (see sharp_wedge_tips).
struct SharpTip {
  LO curve = kNoIndex;
  int end = 0;
  double length = 0;
  bool shared = false;
};

/// Every sharp wedge tip of the model: for each curve end at a corner shared with another side of
/// one of its faces, the polyline vertices of the curve (polylines[c], dense enough to stand for
/// the curve; sizes[c], the mesh size at each) walked away from the corner while the distance d to
/// the other side's polyline stays below sin(sharp_deg) x the distance r to the corner (the wedge
/// sharper than sharp_deg there) and below the tip's width; the tip's length is the largest such
/// r, at most half the curve's chord. The tip's width: `touching` where both sides bound that face
/// and no other (their tail behind the tip is graded with its width, limit_in_sharp_wedges), else
/// shared_ratio x the size (the tail keeps the sizes of the faces beside it, so the tip takes all
/// of it that is too thin for them). Ends with no such vertex give no tip. Ordered by curve, then
/// end. Deterministic (no threads).
[[nodiscard]] std::vector<SharpTip> sharp_wedge_tips(const cad::CadModel& model,
                                                     std::span<const std::vector<Vec3>> polylines,
                                                     std::span<const std::vector<double>> sizes,
                                                     double touching, double shared_ratio,
                                                     double sharp_deg);

}  // namespace qsmesh::background
