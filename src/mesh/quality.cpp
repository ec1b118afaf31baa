#include "qsmesh/mesh/quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>

namespace qsmesh::mesh {

double quad_sicn(const std::array<Vec3, 4>& q) {
  std::array<Vec3, 4> n{};
  Vec3 sum{};
  for (int i = 0; i < 4; ++i) {
    const Vec3 prev = q[(i + 3) % 4] - q[i];
    const Vec3 next = q[(i + 1) % 4] - q[i];
    n[i] = cross(next, prev);
    sum += n[i];
  }
  const double ns = norm(sum);
  if (!(ns > 0)) return -1.0;
  const Vec3 normal = sum / ns;
  double worst = std::numeric_limits<double>::max();
  for (int i = 0; i < 4; ++i) {
    const Vec3 prev = q[(i + 3) % 4] - q[i];
    const Vec3 next = q[(i + 1) % 4] - q[i];
    const double denom = norm2(prev) + norm2(next);
    const double v = denom > 0 ? 2.0 * dot(n[i], normal) / denom : -1.0;
    worst = std::min(worst, v);
  }
  return worst;
}

double triangle_quality(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double area2 = norm(cross(b - a, c - a));
  const double l2 = norm2(b - a) + norm2(c - b) + norm2(a - c);
  return l2 > 0 ? 2.0 * std::sqrt(3.0) * area2 / l2 : 0.0;
}

std::array<double, 3> triangle_angles(const Vec3& a, const Vec3& b, const Vec3& c) {
  auto angle = [](const Vec3& p, const Vec3& x, const Vec3& y) {
    const Vec3 u = x - p, v = y - p;
    const double s = norm(cross(u, v)), d = dot(u, v);
    return std::atan2(s, d) * 180.0 / std::numbers::pi;
  };
  return {angle(a, b, c), angle(b, c, a), angle(c, a, b)};
}

MeshStats compute_stats(const SurfaceMesh& mesh) {
  MeshStats s;
  s.vertices = mesh.num_vertices();
  s.triangles = static_cast<std::int64_t>(mesh.triangles.size());
  s.quads = static_cast<std::int64_t>(mesh.quads.size());
  s.bars = static_cast<std::int64_t>(mesh.bars.size());

  std::vector<std::int32_t> valence(static_cast<std::size_t>(s.vertices), 0);
  for (const auto& t : mesh.triangles)
    for (GO v : t) ++valence[v];
  for (const auto& q : mesh.quads)
    for (GO v : q) ++valence[v];
  const int regular = s.quads >= s.triangles ? 4 : 6;
  for (GO v = 0; v < s.vertices; ++v) {
    if (mesh.vclass[v].dim != 2) continue;
    ++s.interior_vertices;
    if (valence[v] != regular) ++s.irregular_interior;
  }

  if (s.quads > 0) {
    double sum = 0;
    s.sicn_min = std::numeric_limits<double>::max();
    for (const auto& q : mesh.quads) {
      const double v = quad_sicn({mesh.points[q[0]], mesh.points[q[1]], mesh.points[q[2]], mesh.points[q[3]]});
      s.sicn_min = std::min(s.sicn_min, v);
      sum += v;
    }
    s.sicn_avg = sum / static_cast<double>(s.quads);
  }

  if (s.triangles > 0) {
    // Angle of each face at each CAD corner: the sum of its triangles' angles there.
    std::unordered_map<std::int64_t, double> corner_angle;
    auto key = [](LO face, GO corner) { return (static_cast<std::int64_t>(face) << 32) | corner; };
    std::vector<std::array<double, 3>> angles(mesh.triangles.size());
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
      const auto& t = mesh.triangles[i];
      angles[i] = triangle_angles(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]]);
      for (int k = 0; k < 3; ++k)
        if (mesh.vclass[t[k]].dim == 0) corner_angle[key(mesh.triangle_face[i], t[k])] += angles[i][k];
    }
    // Curves forming a sharp corner of a face: (face, curve) pairs.
    std::unordered_map<std::int64_t, std::vector<GO>> sharp_curves;  // face -> corners
    for (const auto& [k, angle] : corner_angle)
      if (angle < 10) sharp_curves[k >> 32].push_back(k & 0xffffffff);
    auto in_sharp_wedge = [&](std::size_t i) {
      const LO f = mesh.triangle_face[i];
      const auto it = sharp_curves.find(f);
      if (it == sharp_curves.end() || mesh.curve_corners.empty()) return false;
      for (const GO corner : it->second) {
        bool all = true;
        for (const GO v : mesh.triangles[i]) {
          const VertexClass& vc = mesh.vclass[v];
          const bool on = (vc.dim == 0 && v == corner) ||
                          (vc.dim == 1 && (mesh.curve_corners[vc.entity][0] == corner ||
                                           mesh.curve_corners[vc.entity][1] == corner));
          all = all && on;
        }
        if (all) return true;
      }
      return false;
    };
    double qsum = 0;
    s.tri_quality_min = std::numeric_limits<double>::max();
    s.min_angle_deg = 180;
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
      const auto& t = mesh.triangles[i];
      const double q = triangle_quality(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]]);
      s.tri_quality_min = std::min(s.tri_quality_min, q);
      qsum += q;
      const int k = static_cast<int>(std::min_element(angles[i].begin(), angles[i].end()) - angles[i].begin());
      const double a = angles[i][k];
      s.min_angle_deg = std::min(s.min_angle_deg, a);
      const int bin = a < 5 ? 0 : a < 10 ? 1 : a < 20 ? 2 : a < 30 ? 3 : 4;
      ++s.min_angle_histogram[bin];
      if (a < 10 && in_sharp_wedge(i)) ++s.small_angle_at_sharp_corner;
    }
    s.tri_quality_avg = qsum / static_cast<double>(s.triangles);
  }
  return s;
}

}  // namespace qsmesh::mesh
