#include "qsmesh/quad/recombine.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/quality.hpp"

namespace qsmesh::quad {
namespace {

struct HalfEdge {
  LO a, b;  // sorted vertex pair
  LO tri;
  int local;  // edge local index in the triangle: (v[local], v[local+1])
  bool operator<(const HalfEdge& o) const {
    return std::tie(a, b, tri, local) < std::tie(o.a, o.b, o.tri, o.local);
  }
};

struct Candidate {
  double score;
  double sicn;
  LO t1, t2;
  std::array<LO, 4> quad;
};

// 1 when the edge runs along one of the branches of the cross, 0 at 45 degrees.
double edge_alignment(const Vec3& e, const std::array<Vec3, 2>& cross_dirs) {
  const double len = norm(e);
  if (len <= 0) return 0;
  const double c = std::max(std::abs(dot(e, cross_dirs[0])), std::abs(dot(e, cross_dirs[1]))) / len;
  const double c45 = std::sqrt(0.5);
  return std::clamp((c - c45) / (1 - c45), 0.0, 1.0);
}

}  // namespace

mesh::FaceMesh recombine(const mesh::FaceMesh& mesh,
                         std::span<const std::array<Vec3, 2>> directions,
                         const RecombineOptions& options, RecombineStats* stats) {
  const auto nt = static_cast<LO>(mesh.triangles.size());
  QSMESH_CHECK(directions.empty() || directions.size() == mesh.triangles.size(),
               "face " << mesh.face << ": " << directions.size() << " cross directions for " << nt
                       << " triangles");
  const double w = directions.empty() ? 0.0 : std::clamp(options.alignment_weight, 0.0, 1.0);

  // Edges by sorted vertex pair; an edge is a candidate only when exactly two triangles use it.
  std::vector<HalfEdge> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (LO t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const LO a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), t, k});
    }
  std::sort(edges.begin(), edges.end());

  std::vector<Candidate> candidates;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].a == edges[i].a && edges[j].b == edges[i].b) ++j;
    if (j - i == 2) {
      const HalfEdge& e1 = edges[i];
      const HalfEdge& e2 = edges[i + 1];
      const auto& T1 = mesh.triangles[e1.tri];
      const auto& T2 = mesh.triangles[e2.tri];
      const LO a = T1[e1.local], b = T1[(e1.local + 1) % 3], c = T1[(e1.local + 2) % 3];
      const LO d = T2[(e2.local + 2) % 3];
      // Consistently oriented neighbours traverse the shared edge in opposite directions.
      const bool opposite = T2[e2.local] == b && T2[(e2.local + 1) % 3] == a;
      // An edge along a CAD curve inside the face (both ends consecutive on one curve) stays.
      const auto& ca = mesh.vclass[a];
      const auto& cb = mesh.vclass[b];
      const bool on_curve = ca.dim == 1 && cb.dim == 1 && ca.entity == cb.entity &&
                            std::abs(ca.index - cb.index) == 1;
      if (opposite && !on_curve && c != d) {
        const std::array<LO, 4> q{a, d, b, c};
        const double sicn = mesh::quad_sicn(
            {mesh.points[q[0]], mesh.points[q[1]], mesh.points[q[2]], mesh.points[q[3]]});
        if (sicn > options.min_sicn) {
          double score = sicn;
          if (w > 0) {
            // Edges a-d, d-b belong to the second triangle, b-c, c-a to the first.
            const auto& P = mesh.points;
            const double align = 0.25 * (edge_alignment(P[d] - P[a], directions[e2.tri]) +
                                         edge_alignment(P[b] - P[d], directions[e2.tri]) +
                                         edge_alignment(P[c] - P[b], directions[e1.tri]) +
                                         edge_alignment(P[a] - P[c], directions[e1.tri]));
            score = sicn * (1 - w + w * align);
          }
          candidates.push_back(
              {score, sicn, std::min(e1.tri, e2.tri), std::max(e1.tri, e2.tri), q});
        }
      }
    }
    i = j;
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    if (x.score != y.score) return x.score > y.score;
    return std::tie(x.t1, x.t2) < std::tie(y.t1, y.t2);
  });

  mesh::FaceMesh out;
  out.face = mesh.face;
  out.points = mesh.points;
  out.uv = mesh.uv;
  out.vclass = mesh.vclass;
  out.quads = mesh.quads;
  std::vector<char> used(mesh.triangles.size(), 0);
  for (const Candidate& c : candidates) {
    if (used[c.t1] || used[c.t2]) continue;
    used[c.t1] = used[c.t2] = 1;
    out.quads.push_back(c.quad);
  }
  for (LO t = 0; t < nt; ++t)
    if (!used[t]) out.triangles.push_back(mesh.triangles[t]);

  if (stats) {
    *stats = {};
    stats->quads = static_cast<std::int64_t>(out.quads.size());
    stats->triangles_left = static_cast<std::int64_t>(out.triangles.size());
    double sum = 0, mn = 1e300;
    for (const auto& q : out.quads) {
      const double s =
          mesh::quad_sicn({out.points[q[0]], out.points[q[1]], out.points[q[2]], out.points[q[3]]});
      sum += s;
      mn = std::min(mn, s);
    }
    if (!out.quads.empty()) {
      stats->sicn_min = mn;
      stats->sicn_avg = sum / static_cast<double>(out.quads.size());
    }
  }
  return out;
}

}  // namespace qsmesh::quad
