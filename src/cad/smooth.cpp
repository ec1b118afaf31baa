#include "qsmesh/cad/smooth.hpp"

#include <array>
#include <cmath>
#include <memory>
#include <numbers>
#include <utility>

#include "qsmesh/cad/geometry.hpp"

namespace qsmesh::cad {

namespace {

// The (loop, use) of curve c in face f's loops; {-1, -1} when f does not use it.
std::pair<LO, LO> use_of(const Face& f, LO c) {
  for (std::size_t l = 0; l < f.loops.size(); ++l)
    for (std::size_t k = 0; k < f.loops[l].uses.size(); ++k)
      if (f.loops[l].uses[k].curve == c) return {static_cast<LO>(l), static_cast<LO>(k)};
  return {-1, -1};
}

}  // namespace

bool smooth_across(const CadModel& model, LO c, double max_normal_angle_deg, int samples) {
  const Curve& curve = model.curves()[static_cast<std::size_t>(c)];
  if (curve.degenerate) return false;
  const auto faces = model.curve2faces()[c];
  if (faces.size() != 2 || faces[0] == faces[1]) return false;
  std::array<std::unique_ptr<FaceGeometry>, 2> surface;
  std::array<std::pair<LO, LO>, 2> use;
  std::array<bool, 2> forward{};
  for (std::size_t i = 0; i < 2; ++i) {
    const Face& f = model.faces()[static_cast<std::size_t>(faces[i])];
    use[i] = use_of(f, c);
    if (use[i].first < 0) return false;
    surface[i] = model.face_geometry(faces[i]);
    // The loops are the surface's natural orientation (du x dv); a reversed face's normal points
    // the other way, and so does its boundary's direction relative to that normal.
    forward[i] = f.loops[static_cast<std::size_t>(use[i].first)]
                     .uses[static_cast<std::size_t>(use[i].second)]
                     .reversed == f.reversed;
  }
  // In a consistently oriented shell the two faces traverse their common curve in opposite
  // directions; traversed the same way, one of them is flipped and so is its normal.
  const double sign = forward[0] != forward[1] ? 1.0 : -1.0;
  const double cos_max = std::cos(max_normal_angle_deg * std::numbers::pi / 180);
  int compared = 0;
  for (int i = 1; i <= samples; ++i) {
    const double t = curve.t0 + (curve.t1 - curve.t0) * double(i) / double(samples + 1);
    const Vec3 n0 = surface[0]->normal(surface[0]->boundary_uv(use[0].first, use[0].second, t));
    const Vec3 n1 = surface[1]->normal(surface[1]->boundary_uv(use[1].first, use[1].second, t));
    if (norm(n0) == 0 || norm(n1) == 0) continue;  // a pole: no normal there
    if (sign * dot(n0, n1) < cos_max) return false;
    ++compared;
  }
  return compared > 0;
}

}  // namespace qsmesh::cad
