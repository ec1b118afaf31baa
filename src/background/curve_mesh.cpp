#include "qsmesh/background/curve_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <unordered_map>

#include "qsmesh/background/feature_size.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::background {

CurveCurvatureSize::CurveCurvatureSize(const cad::CadModel& model, LO curve,
                                       std::span<const CurveUseRef> uses, const SizeOptions& sizes)
    : geometry_(model.curve_geometry(curve)), refs_(uses.begin(), uses.end()), sizes_(sizes) {
  for (const CurveUseRef& u : uses) faces_.push_back(model.face_geometry(u.face));
}

double CurveCurvatureSize::operator()(double t) const {
  double h = sizes_.from_curvature(curve_curvature(*geometry_, t));
  for (std::size_t i = 0; i < faces_.size(); ++i) {
    const Vec2 uv = faces_[i]->boundary_uv(refs_[i].loop, refs_[i].use, t);
    h = std::min(h, sizes_.from_curvature(max_principal_curvature(*faces_[i], uv)));
  }
  return h;
}

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

/// A curve sampled finely enough to resolve its size field: parameters, points, arc length, and
/// the size at each sample (reduced by the feature and gradation passes).
struct CurveSamples {
  std::vector<double> t, s, h;
  std::vector<Vec3> p;
  [[nodiscard]] double length() const { return s.empty() ? 0.0 : s.back(); }
};

CurveSamples sample_curve(const CurveCurvatureSize& sizer, const cad::Curve& curve, double cap) {
  // A coarse pass estimates the edge count from the curvature sizes; the samples then resolve the
  // size field at ~8 per edge and are never further apart than cap / 4 (for the feature search).
  // Size evaluations (second derivatives of the curve and of every adjacent surface) dominate the
  // cost of curve meshing, hence no more samples than that.
  const int coarse_n = 16;
  double estimate = 0, length = 0;
  Vec3 prev = sizer.geometry().point(curve.t0);
  for (int i = 1; i <= coarse_n; ++i) {
    const double t = curve.t0 + (curve.t1 - curve.t0) * i / coarse_n;
    const Vec3 q = sizer.geometry().point(t);
    const double ds = distance(prev, q);
    estimate += ds / sizer(t);
    length += ds;
    prev = q;
  }
  const int n =
      std::clamp(static_cast<int>(std::ceil(std::max(8 * estimate, 4 * length / cap))), 32, 16384);
  CurveSamples cs;
  cs.t.resize(static_cast<std::size_t>(n) + 1);
  cs.s.assign(cs.t.size(), 0.0);
  cs.h.resize(cs.t.size());
  cs.p.resize(cs.t.size());
  for (int i = 0; i <= n; ++i) {
    cs.t[i] = curve.t0 + (curve.t1 - curve.t0) * i / n;
    cs.p[i] = sizer.geometry().point(cs.t[i]);
    cs.h[i] = sizer(cs.t[i]);
    if (i > 0) cs.s[i] = cs.s[i - 1] + distance(cs.p[i - 1], cs.p[i]);
  }
  return cs;
}

/// Lowers the sizes so that they grow by at most `g` per unit arc length from either end value
/// and along the curve (one forward and one backward sweep: the exact one-way gradation in 1D).
void grade_along(CurveSamples& cs, double h_start, double h_end, double g) {
  const std::size_t n = cs.h.size();
  cs.h.front() = std::min(cs.h.front(), h_start);
  cs.h.back() = std::min(cs.h.back(), h_end);
  for (std::size_t i = 1; i < n; ++i)
    cs.h[i] = std::min(cs.h[i], cs.h[i - 1] + g * (cs.s[i] - cs.s[i - 1]));
  for (std::size_t i = n - 1; i-- > 0;)
    cs.h[i] = std::min(cs.h[i], cs.h[i + 1] + g * (cs.s[i + 1] - cs.s[i]));
}

/// Places round(integral of ds / h) edges (at least min_edges) at equal steps of that integral.
mesh::CurveMesh place_vertices(const CurveSamples& cs, const CurveCurvatureSize& sizer, LO c,
                               const Vec3& p0, const Vec3& p1, int min_edges) {
  const std::size_t n = cs.t.size();
  std::vector<double> cumulative(n, 0.0);
  for (std::size_t i = 1; i < n; ++i)
    cumulative[i] =
        cumulative[i - 1] + 0.5 * (1 / cs.h[i - 1] + 1 / cs.h[i]) * (cs.s[i] - cs.s[i - 1]);
  const double total = cumulative.back();
  QSMESH_CHECK(std::isfinite(total) && total > 0, "size integral is not finite (" << total << ")");
  const int edges = std::max(min_edges, static_cast<int>(std::lround(total)));
  mesh::CurveMesh out;
  out.curve = c;
  out.t.resize(static_cast<std::size_t>(edges) + 1);
  out.points.resize(out.t.size());
  out.t.front() = cs.t.front();
  out.t.back() = cs.t.back();
  for (int k = 1; k < edges; ++k) {
    const double target = total * k / edges;
    const auto it = std::lower_bound(cumulative.begin(), cumulative.end(), target);
    const auto i =
        std::clamp<std::size_t>(static_cast<std::size_t>(it - cumulative.begin()), 1, n - 1);
    const double c0 = cumulative[i - 1], c1 = cumulative[i];
    const double w = c1 > c0 ? std::clamp((target - c0) / (c1 - c0), 0.0, 1.0) : 0.0;
    out.t[k] = cs.t[i - 1] + w * (cs.t[i] - cs.t[i - 1]);
    out.points[k] = sizer.geometry().point(out.t[k]);
  }
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
  auto with_context = [](LO c, auto&& body) {
    try {
      body();
    } catch (const Error& e) {
      throw e.with_context({"curves", 1, c});
    }
  };

  // 0. The largest size of each curve: the smallest background cap of the faces using it (the
  //    target size, or the geometry's resolution with SizeOptions::field_divisions).
  std::vector<double> cap(static_cast<std::size_t>(n), sizes.size);
  for (LO c = 0; c < n; ++c) {
    if (uses[c].empty()) continue;
    double v = std::numeric_limits<double>::infinity();
    for (const CurveUseRef& u : uses[c])
      v = std::min(v, sizes.field_cap(model.faces()[u.face].box.diagonal()));
    cap[c] = v;
  }
  const double largest = n > 0 ? *std::max_element(cap.begin(), cap.end()) : sizes.size;

  // 1. Sample every curve with its curvature sizes.
  std::vector<std::unique_ptr<CurveCurvatureSize>> sizers(static_cast<std::size_t>(n));
  std::vector<CurveSamples> samples(static_cast<std::size_t>(n));
  tasks.parallel_for(n, [&](std::int64_t i) {
    const auto c = static_cast<LO>(i);
    if (model.curves()[c].degenerate) return;
    with_context(c, [&] {
      sizers[c] = std::make_unique<CurveCurvatureSize>(model, c, uses[c], sizes.capped(cap[c]));
      samples[c] = sample_curve(*sizers[c], model.curves()[c], cap[c]);
    });
  });

  // 2. Small features: no size larger than the distance to a curve sharing no corner with this one.
  if (sizes.feature_size) {
    std::vector<std::vector<Vec3>> polylines(samples.size());
    std::vector<std::vector<double>> h(samples.size());
    for (std::size_t c = 0; c < samples.size(); ++c) {
      polylines[c] = samples[c].p;
      h[c] = samples[c].h;
    }
    // Gaps narrower than a tenth of the smallest size are curves touching or lying on top of each
    // other (unsewn volumes, sloppy models), not features the mesh could resolve.
    limit_by_feature_distance(model, polylines, h, 0.1 * sizes.effective_min_size(),
                              sizes.effective_min_size(), tasks);
    // Inside sharp wedges the sides share a corner, so (ii) does not see them; the thin-face cap
    // of the size map grades the sizes along such a tail with its width, and needs vertices there.
    limit_in_sharp_wedges(model, polylines, h, 0.1 * sizes.effective_min_size(), 10, tasks);
    for (std::size_t c = 0; c < samples.size(); ++c) samples[c].h = std::move(h[c]);
  }

  // 3. Corners take the smallest size of the curves ending there (a curve never asks for more than
  //    its length); then sizes grade along each curve from its two corners.
  std::vector<double> corner_size(static_cast<std::size_t>(model.num_corners()), largest);
  for (LO c = 0; c < n; ++c) {
    const auto& cc = model.curves()[c];
    if (cc.degenerate || samples[c].p.empty()) continue;
    const double len = samples[c].length();
    corner_size[cc.corners[0]] = std::min({corner_size[cc.corners[0]], samples[c].h.front(), len});
    corner_size[cc.corners[1]] = std::min({corner_size[cc.corners[1]], samples[c].h.back(), len});
  }

  // Curves joining the same corner pair would coincide if both were single straight edges.
  std::map<std::pair<LO, LO>, int> pair_count;
  for (const cad::Curve& c : model.curves()) {
    if (c.degenerate) continue;
    ++pair_count[std::minmax(c.corners[0], c.corners[1])];
  }

  // 4. Vertices at equal steps of the integral of 1/h.
  std::vector<mesh::CurveMesh> meshes(static_cast<std::size_t>(n));
  tasks.parallel_for(n, [&](std::int64_t i) {
    const auto c = static_cast<LO>(i);
    const cad::Curve& curve = model.curves()[c];
    const Vec3 p0 = model.corners()[curve.corners[0]].point;
    const Vec3 p1 = model.corners()[curve.corners[1]].point;
    if (curve.degenerate) {
      meshes[c].curve = c;
      meshes[c].t = {curve.t0, curve.t1};
      meshes[c].points = {p0, p1};
      return;
    }
    int min_edges = 1;
    if (curve.corners[0] == curve.corners[1])
      min_edges = 3;
    else if (pair_count.at(std::minmax(curve.corners[0], curve.corners[1])) > 1)
      min_edges = 2;
    with_context(c, [&] {
      grade_along(samples[c], corner_size[curve.corners[0]], corner_size[curve.corners[1]],
                  sizes.gradation);
      meshes[c] = place_vertices(samples[c], *sizers[c], c, p0, p1, min_edges);
    });
  });
  return meshes;
}

}  // namespace qsmesh::background
