#include "qsmesh/smooth/approx_surface.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "qsmesh/core/error.hpp"

namespace qsmesh::smooth {
namespace {

constexpr LO kLeafSize = 4;

double distance2(const Vec3& a, const Vec3& b) { return norm2(a - b); }

// Closest point of triangle (a, b, c) to p, as barycentric weights (wa, wb, wc): the Voronoi
// regions of the vertices, then of the edges, then the interior.
std::array<double, 3> closest_weights(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double t = d1 / (d1 - d3);
    return {1 - t, t, 0};
  }
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double t = d2 / (d2 - d6);
    return {1 - t, 0, t};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - t, t};
  }
  const double den = va + vb + vc;
  if (!(den > 0)) return {1, 0, 0};  // degenerate triangle: its first vertex
  const double v = vb / den, w = vc / den;
  return {1 - v - w, v, w};
}

double box_distance2(const Box3& b, const Vec3& p) {
  const double dx = std::max({b.lo.x - p.x, 0.0, p.x - b.hi.x});
  const double dy = std::max({b.lo.y - p.y, 0.0, p.y - b.hi.y});
  const double dz = std::max({b.lo.z - p.z, 0.0, p.z - b.hi.z});
  return dx * dx + dy * dy + dz * dz;
}

}  // namespace

ApproxSurface::ApproxSurface(std::vector<Vec3> points, std::vector<Vec2> uv,
                             std::vector<std::array<LO, 3>> triangles)
    : points_(std::move(points)), uv_(std::move(uv)), tris_(std::move(triangles)) {
  QSMESH_CHECK(points_.size() == uv_.size(), "approximate surface: points and uv sizes differ");
  for (const auto& t : tris_)
    for (const LO v : t)
      QSMESH_CHECK(v >= 0 && static_cast<std::size_t>(v) < points_.size(),
                   "approximate surface: triangle vertex " << v << " out of range");
  const LO n = static_cast<LO>(tris_.size());
  order_.resize(static_cast<std::size_t>(n));
  std::vector<Vec3> centres(static_cast<std::size_t>(n));
  for (LO t = 0; t < n; ++t) {
    order_[t] = t;
    centres[t] = (points_[tris_[t][0]] + points_[tris_[t][1]] + points_[tris_[t][2]]) / 3.0;
  }
  if (n > 0) {
    nodes_.reserve(static_cast<std::size_t>(2 * (n / kLeafSize + 1)));
    build(0, n, centres);
  }
}

// Median split along the longest axis of the centres' box; the sort is stable on the index, so
// the tree does not depend on the sort implementation.
LO ApproxSurface::build(LO first, LO count, std::vector<Vec3>& centres) {
  const LO id = static_cast<LO>(nodes_.size());
  nodes_.emplace_back();
  Box3 box, cbox;
  for (LO i = first; i < first + count; ++i) {
    const auto& t = tris_[order_[i]];
    for (const LO v : t) box.add(points_[v]);
    cbox.add(centres[order_[i]]);
  }
  nodes_[id].box = box;
  if (count <= kLeafSize) {
    nodes_[id].first = first;
    nodes_[id].count = count;
    return id;
  }
  const Vec3 ext = cbox.hi - cbox.lo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  auto key = [&](LO t) {
    return axis == 0 ? centres[t].x : (axis == 1 ? centres[t].y : centres[t].z);
  };
  const LO half = count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + first + half,
                   order_.begin() + first + count, [&](LO a, LO b) {
                     const double ka = key(a), kb = key(b);
                     return ka < kb || (ka == kb && a < b);
                   });
  const LO left = build(first, half, centres);
  const LO right = build(first + half, count - half, centres);
  nodes_[id].left = left;
  nodes_[id].right = right;
  return id;
}

ApproxSurface ApproxSurface::from_mesh(const mesh::FaceMesh& m) {
  std::vector<std::array<LO, 3>> tris = m.triangles;
  for (const auto& q : m.quads) {
    if (distance2(m.points[q[0]], m.points[q[2]]) <= distance2(m.points[q[1]], m.points[q[3]])) {
      tris.push_back({q[0], q[1], q[2]});
      tris.push_back({q[0], q[2], q[3]});
    } else {
      tris.push_back({q[0], q[1], q[3]});
      tris.push_back({q[1], q[2], q[3]});
    }
  }
  return ApproxSurface(m.points, m.uv, std::move(tris));
}

ApproxSurface::Hit ApproxSurface::closest(const Vec3& p, LO hint) const {
  Hit hit;
  if (nodes_.empty()) return hit;
  double best = std::numeric_limits<double>::infinity();
  std::array<double, 3> best_w{};
  const auto consider = [&](LO t) {
    const auto& tr = tris_[t];
    const auto w = closest_weights(p, points_[tr[0]], points_[tr[1]], points_[tr[2]]);
    const Vec3 x = points_[tr[0]] * w[0] + points_[tr[1]] * w[1] + points_[tr[2]] * w[2];
    const double d = distance2(x, p);
    if (d < best || (d == best && t < hit.triangle)) {
      best = d;
      best_w = w;
      hit.triangle = t;
      hit.point = x;
    }
  };
  // The hint only tightens the first bound: the answer is the same with or without it.
  if (hint >= 0 && hint < num_triangles()) consider(hint);
  // Depth-first, nearer child first; a node is skipped when its box is farther than the best.
  // The tree is balanced (median splits), so its depth is below 64 for any LO count.
  std::array<LO, 128> stack;
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& nd = nodes_[stack[--top]];
    if (box_distance2(nd.box, p) > best) continue;
    if (nd.left == kNoIndex) {
      for (LO i = nd.first; i < nd.first + nd.count; ++i) consider(order_[i]);
      continue;
    }
    const double dl = box_distance2(nodes_[nd.left].box, p);
    const double dr = box_distance2(nodes_[nd.right].box, p);
    if (dl <= dr) {
      stack[top++] = nd.right;
      stack[top++] = nd.left;
    } else {
      stack[top++] = nd.left;
      stack[top++] = nd.right;
    }
  }
  const auto& tr = tris_[hit.triangle];
  hit.uv = uv_[tr[0]] * best_w[0] + uv_[tr[1]] * best_w[1] + uv_[tr[2]] * best_w[2];
  hit.distance = std::sqrt(best);
  return hit;
}

}  // namespace qsmesh::smooth
