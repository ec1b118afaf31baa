// Meshes of the CAD curves (paper 000 Sec. 2: curves are meshed first and their meshes are locked;
// every face bounded by a curve uses the same vertices).
#pragma once

#include <memory>
#include <span>
#include <vector>

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
/// the model and the options: every rank computes the same meshes, whatever the thread count of
/// `tasks`. Returns one CurveMesh per curve, indexed by curve id.
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
