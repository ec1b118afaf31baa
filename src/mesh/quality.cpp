#include "qsmesh/mesh/quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>

namespace qsmesh::mesh {

double quad_sicn(const std::array<Vec3, 4>& q) { return quad_sicn_from(quad_corners(q)); }

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

FaceQuadStats face_quad_stats(const FaceMesh& mesh) {
  FaceQuadStats s;
  s.vertices = mesh.num_vertices();
  s.quads = static_cast<std::int64_t>(mesh.quads.size());
  s.triangles = static_cast<std::int64_t>(mesh.triangles.size());
  const auto nv = static_cast<std::size_t>(s.vertices);
  std::vector<std::int32_t> valence(nv, 0);
  std::vector<double> angle(nv, 0.0);  // degrees, sum of the element angles at the vertex
  auto corner_angle = [&](LO v, LO prev, LO next) {
    const Vec3 a = mesh.points[prev] - mesh.points[v], b = mesh.points[next] - mesh.points[v];
    return std::atan2(norm(cross(a, b)), dot(a, b)) * 180.0 / std::numbers::pi;
  };
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      ++valence[t[k]];
      angle[t[k]] += corner_angle(t[k], t[(k + 2) % 3], t[(k + 1) % 3]);
    }
  double sum = 0;
  s.sicn_min = s.quads > 0 ? std::numeric_limits<double>::max() : 0.0;
  for (const auto& q : mesh.quads) {
    for (int k = 0; k < 4; ++k) {
      ++valence[q[k]];
      angle[q[k]] += corner_angle(q[k], q[(k + 3) % 4], q[(k + 1) % 4]);
    }
    const double v =
        quad_sicn({mesh.points[q[0]], mesh.points[q[1]], mesh.points[q[2]], mesh.points[q[3]]});
    s.sicn_min = std::min(s.sicn_min, v);
    sum += v;
  }
  if (s.quads > 0) s.sicn_avg = sum / static_cast<double>(s.quads);
  const std::int32_t regular = s.quads >= s.triangles ? 4 : 6;
  // Boundary vertices: copies of one CAD vertex (seams) are summed before comparing with the ideal.
  struct Total {
    std::int32_t valence = 0, copies = 0;
    double angle = 0;
    int dim = 0;
  };
  std::unordered_map<std::uint64_t, Total> boundary;
  for (std::size_t v = 0; v < nv; ++v) {
    const VertexClass& c = mesh.vclass[v];
    if (valence[v] == 0) continue;
    if (c.dim == 2) {
      s.irregular_interior += valence[v] != regular ? 1 : 0;
      continue;
    }
    const std::uint64_t key =
        (static_cast<std::uint64_t>(c.dim) << 62) ^
        (static_cast<std::uint64_t>(static_cast<std::uint32_t>(c.entity)) << 31) ^
        static_cast<std::uint32_t>(c.index);
    Total& t = boundary[key];
    t.valence += valence[v];
    t.copies += 1;
    t.angle += angle[v];
    t.dim = c.dim;
  }
  for (const auto& [key, t] : boundary) {
    const std::int32_t ideal =
        t.dim == 1 ? (regular / 2) * t.copies
                   : std::max<std::int32_t>(1, static_cast<std::int32_t>(std::lround(
                                                   t.angle / (regular == 4 ? 90.0 : 60.0))));
    s.irregular_boundary += t.valence != ideal ? 1 : 0;
  }
  return s;
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

  // Angle of each face at each CAD corner: the sum of its elements' 3D angles there.
  std::unordered_map<std::int64_t, double> corner_angle;
  auto key = [](LO face, GO corner) { return (static_cast<std::int64_t>(face) << 32) | corner; };
  std::vector<std::array<double, 3>> angles(mesh.triangles.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    angles[i] = triangle_angles(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]]);
    for (int k = 0; k < 3; ++k)
      if (mesh.vclass[t[k]].dim == 0)
        corner_angle[key(mesh.triangle_face[i], t[k])] += angles[i][k];
  }
  const bool quad_faces = mesh.quad_face.size() == mesh.quads.size();
  if (quad_faces)
    for (std::size_t i = 0; i < mesh.quads.size(); ++i) {
      const auto& q = mesh.quads[i];
      for (int k = 0; k < 4; ++k)
        if (mesh.vclass[q[k]].dim == 0)
          corner_angle[key(mesh.quad_face[i], q[k])] += triangle_angles(
              mesh.points[q[k]], mesh.points[q[(k + 1) % 4]], mesh.points[q[(k + 3) % 4]])[0];
    }

  if (s.quads > 0) {
    double sum = 0;
    s.sicn_min = std::numeric_limits<double>::max();
    if (quad_faces)
      s.face_quads_sicn_below_0_1.assign(static_cast<std::size_t>(mesh.num_cad_faces), 0);
    for (std::size_t i = 0; i < mesh.quads.size(); ++i) {
      const auto& q = mesh.quads[i];
      const double v =
          quad_sicn({mesh.points[q[0]], mesh.points[q[1]], mesh.points[q[2]], mesh.points[q[3]]});
      s.sicn_min = std::min(s.sicn_min, v);
      sum += v;
      if (!(v < kPoorSicn)) continue;
      ++s.quads_sicn_below_0_1;
      bool forced = false;
      for (int k = 0; k < 4 && quad_faces && !forced; ++k)
        if (mesh.vclass[q[k]].dim == 0) {
          const auto it = corner_angle.find(key(mesh.quad_face[i], q[k]));
          forced = it != corner_angle.end() && it->second < kForcingCornerDeg;
        }
      if (forced) {
        ++s.quads_sicn_below_0_1_forced_by_corner;
      } else if (quad_faces) {
        const LO f = mesh.quad_face[i];
        if (f >= 0 && static_cast<std::size_t>(f) < s.face_quads_sicn_below_0_1.size())
          ++s.face_quads_sicn_below_0_1[static_cast<std::size_t>(f)];
      }
    }
    s.sicn_avg = sum / static_cast<double>(s.quads);
  }

  if (s.triangles > 0) {
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
      const int k = static_cast<int>(std::min_element(angles[i].begin(), angles[i].end()) -
                                     angles[i].begin());
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
