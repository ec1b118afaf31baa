#include "qsmesh/quad/recombine.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <tuple>
#include <unordered_set>
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

std::uint64_t edge_key(LO a, LO b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(std::max(a, b))) << 32) |
         static_cast<std::uint32_t>(std::min(a, b));
}

// Largest 3D angle (radians) of quad q at a corner on a CAD curve or corner whose two quad edges
// both lie on `fixed` edges (curves); 0 when there is no such corner. Midpoint subdivision leaves
// that corner a single sub-quad whose two edges run along the curve to the full-mesh midpoints,
// where a smooth curve is about twice as flat as here, and no smoothing can open it: its corners
// on the curve do not move.
double flat_fixed_corner(const mesh::FaceMesh& m, const std::array<LO, 4>& q,
                         const std::unordered_set<std::uint64_t>& fixed,
                         const std::map<std::pair<LO, LO>, Vec3>* corner_mids) {
  // Where subdivision puts a corner at the middle of a boundary edge (odd counts), the sub-quad
  // runs to that corner instead.
  const auto toward = [&](LO v, LO w) -> Vec3 {
    if (corner_mids != nullptr) {
      const auto it = corner_mids->find(std::minmax(v, w));
      if (it != corner_mids->end()) return it->second;
    }
    return m.points[w];
  };
  double worst = 0;
  for (int k = 0; k < 4; ++k) {
    const LO v = q[k], prev = q[(k + 3) % 4], next = q[(k + 1) % 4];
    if (m.vclass[v].dim > 1 || !fixed.contains(edge_key(prev, v)) ||
        !fixed.contains(edge_key(v, next)))
      continue;
    // A curve vertex beside a corner at a midpoint is flat (its sub-quad runs along its smooth
    // curve both ways), however the halved mesh turns there.
    if (corner_mids != nullptr && m.vclass[v].dim == 1 &&
        (corner_mids->contains(std::minmax(prev, v)) ||
         corner_mids->contains(std::minmax(v, next))))
      return std::numbers::pi;
    const Vec3 a = toward(v, prev) - m.points[v], b = toward(v, next) - m.points[v];
    worst = std::max(worst, std::atan2(norm(cross(a, b)), dot(a, b)));
  }
  return worst;
}

// A triangle the greedy pass left alone becomes a valence-3 vertex after subdivision. Augmenting
// paths of the matching (alternating free/held candidates from one lone triangle to another) pair
// two of them at the price of re-pairing the triangles in between; breadth first, bounded depth,
// only through candidates of acceptable quality, lone triangles in increasing order.
void augment(const std::vector<Candidate>& candidates, const RecombineOptions& options,
             std::vector<LO>& mate) {
  const auto nt = static_cast<LO>(mate.size());
  std::vector<std::vector<LO>> tri2cand(static_cast<std::size_t>(nt));
  for (LO ci = 0; ci < static_cast<LO>(candidates.size()); ++ci) {
    const Candidate& c = candidates[ci];
    if (c.sicn < options.augment_min_sicn) continue;
    tri2cand[c.t1].push_back(ci);
    tri2cand[c.t2].push_back(ci);
  }
  auto other = [&](LO ci, LO t) {
    return candidates[ci].t1 == t ? candidates[ci].t2 : candidates[ci].t1;
  };
  std::vector<std::uint32_t> seen(static_cast<std::size_t>(nt), 0);
  // Odd triangle -> candidate reaching it.
  std::vector<LO> parent(static_cast<std::size_t>(nt), kNoIndex);
  std::vector<int> depth(static_cast<std::size_t>(nt), 0);
  std::uint32_t stamp = 0;
  std::vector<LO> queue;
  for (LO u = 0; u < nt; ++u) {
    if (mate[u] != kNoIndex || tri2cand[u].empty()) continue;
    ++stamp;
    queue.assign(1, u);
    seen[u] = stamp;
    depth[u] = 0;
    LO found = kNoIndex;
    for (std::size_t k = 0; k < queue.size() && found == kNoIndex; ++k) {
      const LO e = queue[k];
      for (LO ci : tri2cand[e]) {
        if (ci == mate[e]) continue;
        const LO o = other(ci, e);
        if (seen[o] == stamp) continue;
        seen[o] = stamp;
        parent[o] = ci;
        if (mate[o] == kNoIndex) {
          found = o;
          break;
        }
        const LO w = other(mate[o], o);
        if (seen[w] == stamp || depth[e] + 1 > options.augment_depth) continue;
        seen[w] = stamp;
        depth[w] = depth[e] + 1;
        queue.push_back(w);
      }
    }
    if (found == kNoIndex) continue;
    for (LO o = found;;) {
      const LO ci = parent[o];
      const LO e = other(ci, o);
      const LO held = mate[e];  // e's current pair (none for u), released for the new one
      mate[o] = mate[e] = ci;
      if (e == u) break;
      o = other(held, e);
    }
  }
}

}  // namespace

mesh::FaceMesh recombine(const mesh::FaceMesh& mesh,
                         std::span<const std::array<Vec3, 2>> directions,
                         const RecombineOptions& options, RecombineStats* stats,
                         const std::map<std::pair<LO, LO>, Vec3>* corner_mids) {
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

  const auto on_curve = [&](LO a, LO b) {
    const auto& ca = mesh.vclass[a];
    const auto& cb = mesh.vclass[b];
    // Halved meshes carry full-mesh indices: consecutive halved vertices of a curve are 2 apart.
    return ca.dim == 1 && cb.dim == 1 && ca.entity == cb.entity &&
           (std::abs(ca.index - cb.index) == 1 || std::abs(ca.index - cb.index) == 2);
  };
  // Edges that stay where they are: the face boundary (one triangle) and curves inside the face.
  std::unordered_set<std::uint64_t> fixed;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].a == edges[i].a && edges[j].b == edges[i].b) ++j;
    if (j - i == 1 || on_curve(edges[i].a, edges[i].b))
      fixed.insert(edge_key(edges[i].a, edges[i].b));
    i = j;
  }
  const double max_flat = options.max_fixed_corner_angle_deg * std::numbers::pi / 180.0;

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
      const std::array<LO, 4> q{a, d, b, c};
      if (opposite && !on_curve(a, b) && c != d &&
          !(flat_fixed_corner(mesh, q, fixed, corner_mids) > max_flat)) {
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
  // Greedy selection, best score first.
  std::vector<LO> mate(static_cast<std::size_t>(nt), kNoIndex);  // candidate holding the triangle
  for (LO ci = 0; ci < static_cast<LO>(candidates.size()); ++ci) {
    const Candidate& c = candidates[ci];
    if (mate[c.t1] != kNoIndex || mate[c.t2] != kNoIndex) continue;
    mate[c.t1] = mate[c.t2] = ci;
  }
  if (options.augment_depth > 0) augment(candidates, options, mate);
  for (LO ci = 0; ci < static_cast<LO>(candidates.size()); ++ci)
    if (mate[candidates[ci].t1] == ci) out.quads.push_back(candidates[ci].quad);
  for (LO t = 0; t < nt; ++t)
    if (mate[t] == kNoIndex) out.triangles.push_back(mesh.triangles[t]);

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
