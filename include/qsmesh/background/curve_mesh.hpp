// Meshes of the CAD curves (paper 000 Sec. 2: curves are meshed first and their meshes are locked;
// every face bounded by a curve uses the same vertices).
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "qsmesh/background/feature_size.hpp"
#include "qsmesh/background/size.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::background {

/// Meshes every curve of `model`: the number of edges is the integral of 1/h along the curve,
/// rounded (at least 1; at least 3 on a closed curve; at least 2 when another curve joins the same
/// two corners, so the two never coincide), with h the smallest of the curve's cap (`sizes.size`,
/// or with `sizes.field_divisions` the smallest SizeOptions::field_cap of its faces), the curvature
/// size of the curve and the curvature sizes of its adjacent faces along it; vertices are placed
/// where the integral of 1/h reaches equal steps. Degenerate curves get one edge. Depends only on
/// the model and the options, whatever the thread count of `tasks` (and however CurveMeshing's
/// steps are split by curve). Returns one CurveMesh per curve, indexed by curve id.
[[nodiscard]] std::vector<mesh::CurveMesh> mesh_curves(const cad::CadModel& model,
                                                       const SizeOptions& sizes,
                                                       const TaskArena& tasks);

/// For each curve, the (face, loop, use) triples where a face loop uses it.
struct CurveUseRef {
  LO face = kNoIndex;
  LO loop = kNoIndex;
  LO use = kNoIndex;
};
[[nodiscard]] std::vector<std::vector<CurveUseRef>> curve_uses(const cad::CadModel& model);

/// A curve sampled finely enough to resolve its size field (the first step of mesh_curves): at
/// each sample its parameter t, arc length s from the curve's start and point p (model units),
/// and the mesh size h there (model units). Empty for a degenerate curve.
struct CurveSamples {
  LO curve = kNoIndex;
  std::vector<double> t, s, h;
  std::vector<Vec3> p;
  [[nodiscard]] double length() const { return s.empty() ? 0.0 : s.back(); }
  /// The fields in order, for the byte records of the parallel layer (parallel/record.hpp).
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("curve", self.curve);
    visit("t", self.t);
    visit("s", self.s);
    visit("h", self.h);
    visit("p", self.p);
  }
};

/// mesh_curves in three steps, for a caller that splits the first two by curve (the parallel
/// layer deals the curves over the ranks and gathers their results between the steps):
///   1. sample(c) for every curve c;
///   2. when limits_sizes(): search = feature_search(samples) on every curve's step-1 samples,
///      then limit_sizes(search, samples[c]) for every curve c;
///   3. place(samples) on every curve's step-2 samples.
/// A curve's result of steps 1 and 2 depends only on the model, the options and the step-1
/// points of all curves, never on which curves are done together, where, or on the threads: any
/// dealing of the curves gives exactly mesh_curves' meshes. Holds a reference to `model`.
class CurveMeshing {
 public:
  /// Throws qsmesh::Error when sizes.size is not positive.
  CurveMeshing(const cad::CadModel& model, const SizeOptions& sizes);
  [[nodiscard]] LO num_curves() const { return model_.num_curves(); }
  /// Step 1: curve c sampled with its curvature sizes (see mesh_curves), c.curve set; empty
  /// vectors for a degenerate curve. Thread-safe. Errors carry the stage "curves" and the curve.
  [[nodiscard]] CurveSamples sample(LO c) const;
  /// What sample(c) is expected to cost, in arbitrary units (about the size evaluations it makes,
  /// from the curve's length, cap and faces), to deal the curves before they are sampled.
  [[nodiscard]] double sampling_cost(LO c) const;
  /// Whether step 2 changes anything (SizeOptions::feature_size).
  [[nodiscard]] bool limits_sizes() const { return sizes_.feature_size; }
  /// Step 2's search over the points of every curve's step-1 samples (indexed by curve id).
  [[nodiscard]] CurveFeatureSearch feature_search(std::span<const CurveSamples> samples) const;
  /// Step 2 on one curve's step-1 samples: s.h lowered to the small-feature distances
  /// (limit_by_feature_distance) and then the sharp-wedge widths (limit_in_sharp_wedges) of
  /// mesh_curves. Nothing when !limits_sizes(). Thread-safe.
  void limit_sizes(const CurveFeatureSearch& search, CurveSamples& s) const;
  /// Step 3: corner sizes, gradation along each curve and vertices at equal steps of the integral
  /// of 1/h, from every curve's samples (indexed by curve id). Returns mesh_curves' result.
  [[nodiscard]] std::vector<mesh::CurveMesh> place(std::vector<CurveSamples> samples,
                                                   const TaskArena& tasks) const;

 private:
  const cad::CadModel& model_;
  SizeOptions sizes_;
  std::vector<std::vector<CurveUseRef>> uses_;
  std::vector<double> cap_;  // by curve: the largest size, the smallest cap of its faces
  double largest_ = 0;       // the largest cap
};

/// The curvature size along one curve: the smallest of `sizes.from_curvature` of the curve's own
/// curvature and of the largest principal curvature of every face using it, at the curve parameter
/// t. Owns its evaluators: one object per task.
class CurveCurvatureSize {
 public:
  CurveCurvatureSize(const cad::CadModel& model, LO curve, std::span<const CurveUseRef> uses,
                     const SizeOptions& sizes);
  [[nodiscard]] const cad::CurveGeometry& geometry() const { return *geometry_; }
  /// Size (model units) at curve parameter t, within the bounds of the SizeOptions.
  [[nodiscard]] double operator()(double t) const;

 private:
  std::unique_ptr<cad::CurveGeometry> geometry_;
  std::vector<std::unique_ptr<cad::FaceGeometry>> faces_;
  std::vector<CurveUseRef> refs_;
  SizeOptions sizes_;
};

}  // namespace qsmesh::background
