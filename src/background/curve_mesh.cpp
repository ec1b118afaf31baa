#include "qsmesh/background/curve_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "qsmesh/core/error.hpp"

namespace qsmesh::background {

std::vector<std::vector<CurveUseRef>> curve_uses(const cad::CadModel& model) {
  std::vector<std::vector<CurveUseRef>> uses(static_cast<std::size_t>(model.num_curves()));
  for (LO f = 0; f < model.num_faces(); ++f) {
    const auto& loops = model.faces()[f].loops;
    for (LO l = 0; l < static_cast<LO>(loops.size()); ++l)
      for (LO u = 0; u < static_cast<LO>(loops[l].uses.size()); ++u)
        uses[loops[l].uses[u].curve].push_back({f, l, u});
  }
  return uses;
}

namespace {

/// Size at curve parameter t: user cap, curve curvature, and curvature of every adjacent face.
class CurveSizer {
 public:
  CurveSizer(const cad::CadModel& model, LO curve, std::span<const CurveUseRef> uses,
             const SizeOptions& sizes)
      : geometry_(model.curve_geometry(curve)), sizes_(sizes) {
    for (const CurveUseRef& u : uses) {
      faces_.push_back(model.face_geometry(u.face));
      refs_.push_back(u);
    }
  }

  [[nodiscard]] const cad::CurveGeometry& geometry() const { return *geometry_; }

  [[nodiscard]] double size_at(double t) const {
    double h = sizes_.from_curvature(curve_curvature(*geometry_, t));
    for (std::size_t i = 0; i < faces_.size(); ++i) {
      const Vec2 uv = faces_[i]->boundary_uv(refs_[i].loop, refs_[i].use, t);
      h = std::min(h, sizes_.from_curvature(max_principal_curvature(*faces_[i], uv)));
    }
    return h;
  }

 private:
  std::unique_ptr<cad::CurveGeometry> geometry_;
  std::vector<std::unique_ptr<cad::FaceGeometry>> faces_;
  std::vector<CurveUseRef> refs_;
  const SizeOptions& sizes_;
};

/// Cumulative integral of |C'(t)| / h(t) on `samples + 1` equally spaced parameters.
struct DensityTable {
  std::vector<double> t, cumulative;
  [[nodiscard]] double total() const { return cumulative.back(); }
};

DensityTable integrate_density(const CurveSizer& sizer, double t0, double t1, int samples) {
  DensityTable table;
  table.t.resize(static_cast<std::size_t>(samples) + 1);
  table.cumulative.assign(table.t.size(), 0.0);
  double prev = 0;
  for (int i = 0; i <= samples; ++i) {
    const double t = t0 + (t1 - t0) * i / samples;
    const double rho = norm(sizer.geometry().derivative(t)) / sizer.size_at(t);
    table.t[i] = t;
    if (i > 0) table.cumulative[i] = table.cumulative[i - 1] + 0.5 * (rho + prev) * (t1 - t0) / samples;
    prev = rho;
  }
  return table;
}

/// Parameter where the cumulative density reaches `target` (linear inside a sample interval).
double invert(const DensityTable& table, double target) {
  const auto it = std::lower_bound(table.cumulative.begin(), table.cumulative.end(), target);
  if (it == table.cumulative.begin()) return table.t.front();
  if (it == table.cumulative.end()) return table.t.back();
  const auto i = static_cast<std::size_t>(it - table.cumulative.begin());
  const double c0 = table.cumulative[i - 1], c1 = table.cumulative[i];
  const double w = c1 > c0 ? (target - c0) / (c1 - c0) : 0.0;
  return table.t[i - 1] + w * (table.t[i] - table.t[i - 1]);
}

mesh::CurveMesh mesh_one_curve(const cad::CadModel& model, LO c, std::span<const CurveUseRef> uses,
                               const SizeOptions& sizes, int min_edges) {
  const cad::Curve& curve = model.curves()[c];
  mesh::CurveMesh out;
  out.curve = c;
  const Vec3 p0 = model.corners()[curve.corners[0]].point;
  const Vec3 p1 = model.corners()[curve.corners[1]].point;
  if (curve.degenerate) {
    out.t = {curve.t0, curve.t1};
    out.points = {p0, p1};
    return out;
  }
  const CurveSizer sizer(model, c, uses, sizes);
  // A coarse pass estimates the edge count; the fine pass resolves the density at ~8 samples/edge.
  const DensityTable coarse = integrate_density(sizer, curve.t0, curve.t1, 32);
  const int samples = std::clamp(static_cast<int>(std::ceil(8 * coarse.total())), 64, 8192);
  const DensityTable table = integrate_density(sizer, curve.t0, curve.t1, samples);
  QSMESH_CHECK(std::isfinite(table.total()), "curve " << c << ": size integral is not finite");
  const int n = std::max(min_edges, static_cast<int>(std::lround(table.total())));
  out.t.resize(static_cast<std::size_t>(n) + 1);
  out.points.resize(out.t.size());
  out.t.front() = curve.t0;
  out.t.back() = curve.t1;
  for (int i = 1; i < n; ++i) out.t[i] = invert(table, table.total() * i / n);
  for (int i = 1; i < n; ++i) out.points[i] = sizer.geometry().point(out.t[i]);
  // End points are the corners themselves, so that every curve ending there shares them exactly.
  out.points.front() = p0;
  out.points.back() = p1;
  return out;
}

}  // namespace

std::vector<mesh::CurveMesh> mesh_curves(const cad::CadModel& model, const SizeOptions& sizes,
                                         const TaskArena& tasks) {
  QSMESH_CHECK(sizes.size > 0, "mesh size must be positive, got " << sizes.size);
  const LO n = model.num_curves();
  const auto uses = curve_uses(model);

  // Curves joining the same corner pair would coincide if both were single straight edges.
  std::map<std::pair<LO, LO>, int> pair_count;
  for (const cad::Curve& c : model.curves()) {
    if (c.degenerate) continue;
    ++pair_count[std::minmax(c.corners[0], c.corners[1])];
  }

  std::vector<mesh::CurveMesh> meshes(static_cast<std::size_t>(n));
  tasks.parallel_for(n, [&](std::int64_t i) {
    const auto c = static_cast<LO>(i);
    const cad::Curve& curve = model.curves()[c];
    int min_edges = 1;
    if (curve.corners[0] == curve.corners[1]) min_edges = 3;
    else if (pair_count.at(std::minmax(curve.corners[0], curve.corners[1])) > 1) min_edges = 2;
    try {
      meshes[c] = mesh_one_curve(model, c, uses[c], sizes, min_edges);
    } catch (const Error& e) {
      throw e.with_context({"curves", 1, c});
    }
  });
  return meshes;
}

}  // namespace qsmesh::background
