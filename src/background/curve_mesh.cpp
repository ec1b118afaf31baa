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
mesh::CurveMesh place_vertices(const CurveSamples& cs, const cad::CurveGeometry& geometry, LO c,
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
    out.points[k] = geometry.point(out.t[k]);
  }
  // End points are the corners themselves, so that every curve ending there shares them exactly.
  out.points.front() = p0;
  out.points.back() = p1;
  return out;
}

template <class Body>
void with_context(LO c, const Body& body) {
  try {
    body();
  } catch (const Error& e) {
    throw e.with_context({"curves", 1, c});
  }
}

}  // namespace

CurveMeshing::CurveMeshing(const cad::CadModel& model, const SizeOptions& sizes)
    : model_(model), sizes_(sizes), uses_(curve_uses(model)) {
  QSMESH_CHECK(sizes.size > 0, "mesh size must be positive, got " << sizes.size);
  const LO n = model.num_curves();
  // The largest size of each curve: the smallest background cap of the faces using it (the
  // target size, or the geometry's resolution with SizeOptions::field_divisions).
  cap_.assign(static_cast<std::size_t>(n), sizes.size);
  for (LO c = 0; c < n; ++c) {
    if (uses_[c].empty()) continue;
    double v = std::numeric_limits<double>::infinity();
    for (const CurveUseRef& u : uses_[c])
      v = std::min(v, sizes.field_cap(model.faces()[u.face].box.diagonal()));
    cap_[c] = v;
  }
  largest_ = n > 0 ? *std::max_element(cap_.begin(), cap_.end()) : sizes.size;
}

CurveSamples CurveMeshing::sample(LO c) const {
  CurveSamples out;
  if (!model_.curves()[c].degenerate)
    with_context(c, [&] {
      const CurveCurvatureSize sizer(model_, c, uses_[c], sizes_.capped(cap_[c]));
      out = sample_curve(sizer, model_.curves()[c], cap_[c]);
    });
  out.curve = c;
  return out;
}

double CurveMeshing::sampling_cost(LO c) const {
  const cad::Curve& curve = model_.curves()[c];
  if (curve.degenerate) return 0;
  // sample_curve: 16 coarse evaluations, then at least 8 per edge of the cap (32 to 16384), each
  // of the curve's curvature and of every face using it.
  const double samples = std::clamp(8 * curve.length / cap_[c], 32.0, 16384.0);
  return (17 + samples) * (1 + static_cast<double>(uses_[c].size()));
}

CurveFeatureSearch CurveMeshing::feature_search(std::span<const CurveSamples> samples) const {
  QSMESH_CHECK(static_cast<LO>(samples.size()) == model_.num_curves(),
               "samples of " << samples.size() << " curves for " << model_.num_curves());
  std::vector<std::vector<Vec3>> polylines(samples.size());
  for (std::size_t c = 0; c < samples.size(); ++c) polylines[c] = samples[c].p;
  return {model_, std::move(polylines)};
}

void CurveMeshing::limit_sizes(const CurveFeatureSearch& search, CurveSamples& s) const {
  if (!sizes_.feature_size || s.p.empty()) return;
  with_context(s.curve, [&] {
    // Gaps narrower than a tenth of the smallest size are curves touching or lying on top of each
    // other (unsewn volumes, sloppy models), not features the mesh could resolve.
    const double touching = 0.1 * sizes_.effective_min_size();
    search.limit_by_feature_distance(s.curve, s.h, touching, sizes_.effective_min_size());
    // Inside sharp wedges the sides share a corner, so the search above does not see them; the
    // thin-face cap of the size map grades the sizes along such a tail with its width, and needs
    // vertices there.
    search.limit_in_sharp_wedges(s.curve, s.h, touching, 10);
  });
}

std::vector<mesh::CurveMesh> CurveMeshing::place(std::vector<CurveSamples> samples,
                                                 const TaskArena& tasks) const {
  const LO n = model_.num_curves();
  QSMESH_CHECK(static_cast<LO>(samples.size()) == n,
               "samples of " << samples.size() << " curves for " << n);
  // Corners take the smallest size of the curves ending there (a curve never asks for more than
  // its length); then sizes grade along each curve from its two corners.
  std::vector<double> corner_size(static_cast<std::size_t>(model_.num_corners()), largest_);
  for (LO c = 0; c < n; ++c) {
    const auto& cc = model_.curves()[c];
    if (cc.degenerate || samples[c].p.empty()) continue;
    const double len = samples[c].length();
    corner_size[cc.corners[0]] = std::min({corner_size[cc.corners[0]], samples[c].h.front(), len});
    corner_size[cc.corners[1]] = std::min({corner_size[cc.corners[1]], samples[c].h.back(), len});
  }

  // Curves joining the same corner pair would coincide if both were single straight edges.
  std::map<std::pair<LO, LO>, int> pair_count;
  for (const cad::Curve& c : model_.curves()) {
    if (c.degenerate) continue;
    ++pair_count[std::minmax(c.corners[0], c.corners[1])];
  }

  // Vertices at equal steps of the integral of 1/h.
  std::vector<mesh::CurveMesh> meshes(static_cast<std::size_t>(n));
  tasks.parallel_for(n, [&](std::int64_t i) {
    const auto c = static_cast<LO>(i);
    const cad::Curve& curve = model_.curves()[c];
    const Vec3 p0 = model_.corners()[curve.corners[0]].point;
    const Vec3 p1 = model_.corners()[curve.corners[1]].point;
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
                  sizes_.gradation);
      meshes[c] = place_vertices(samples[c], *model_.curve_geometry(c), c, p0, p1, min_edges);
    });
  });
  return meshes;
}

std::vector<mesh::CurveMesh> mesh_curves(const cad::CadModel& model, const SizeOptions& sizes,
                                         const TaskArena& tasks) {
  const CurveMeshing meshing(model, sizes);
  const LO n = model.num_curves();
  std::vector<CurveSamples> samples(static_cast<std::size_t>(n));
  tasks.parallel_for(n, [&](std::int64_t i) { samples[i] = meshing.sample(static_cast<LO>(i)); });
  if (meshing.limits_sizes()) {
    const CurveFeatureSearch search = meshing.feature_search(samples);
    tasks.parallel_for(n, [&](std::int64_t i) { meshing.limit_sizes(search, samples[i]); });
  }
  return meshing.place(std::move(samples), tasks);
}

}  // namespace qsmesh::background
