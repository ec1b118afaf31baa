#include "qsmesh/highorder/high_order.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <unordered_map>
#include <vector>

#include "lagrange.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/edges.hpp"
#include "qsmesh/mesh/high_order_nodes.hpp"

namespace qsmesh::highorder {

namespace {

struct Edge {
  GO a, b;
  LO face = kNoIndex;   // face of the first quad using it
  LO curve = kNoIndex;  // curve of its bar, if any
  GO quad = -1;         // first quad using it
};

using detail::bilinear;
using detail::coons;
using detail::kMaxNodes;
using detail::lagrange_1d;
using detail::nearest;
using detail::QuadChecker;
using detail::side_walk;
using detail::uv_images;

}  // namespace

bool lagrange_quad_valid(int order, const std::vector<Vec3>& nodes, const Vec3& normal) {
  const QuadChecker checker(order);
  QSMESH_CHECK(nodes.size() == checker.positions().size(),
               "Lagrange quad of order " << order << ": " << nodes.size() << " nodes");
  std::array<Vec3, kMaxNodes> g{};
  for (std::size_t k = 0; k < nodes.size(); ++k) g[checker.grid(k)] = nodes[k];
  return checker.valid(g, normal);
}

Vec3 lagrange_quad_point(int order, const std::vector<Vec3>& nodes, double s, double t) {
  QSMESH_CHECK(order >= 1 && order <= kMaxOrder,
               "Lagrange quad: order " << order << " out of [1, " << kMaxOrder << "]");
  const auto positions = mesh::quad_grid_positions(order);
  QSMESH_CHECK(nodes.size() == positions.size(),
               "Lagrange quad of order " << order << ": " << nodes.size() << " nodes");
  std::array<double, kMaxOrder + 1> ls{}, lt{};
  lagrange_1d(order, s, ls.data(), nullptr);
  lagrange_1d(order, t, lt.data(), nullptr);
  Vec3 x{};
  for (std::size_t k = 0; k < nodes.size(); ++k)
    x += nodes[k] * (ls[static_cast<std::size_t>(positions[k][0])] *
                     lt[static_cast<std::size_t>(positions[k][1])]);
  return x;
}

HighOrderReport make_high_order(mesh::SurfaceMesh& m, const cad::CadModel& model, int order,
                                const TaskArena& tasks) {
  QSMESH_CHECK(order >= kMinOrder && order <= kMaxOrder, "high-order elements: order "
                                                             << order << " out of [" << kMinOrder
                                                             << ", " << kMaxOrder << "]");
  QSMESH_CHECK(m.triangles.empty(), "high-order elements: the mesh has triangles");
  QSMESH_CHECK(m.order == 1 && m.quad_nodes.empty() && m.bar_nodes.empty(),
               "high-order elements: the mesh has them already");
  const int n = order;
  const GO per_edge = n - 1;                        // nodes inside an edge
  const GO per_interior = per_edge * per_edge;      // nodes inside a quad
  const GO per_quad = 4 * per_edge + per_interior;  // SurfaceMesh::quad_nodes_per_quad
  const GO nv = m.num_vertices();
  const auto nq = static_cast<GO>(m.quads.size());
  // Unique edges: the bars first (their curve), then the quads' (their face). Edge e's nodes are
  // nv + e per_edge + s, s = 0 .. per_edge - 1 from its end a to its end b.
  std::unordered_map<std::uint64_t, GO> edge_of;
  std::vector<Edge> edges;
  m.bar_nodes.resize(m.bars.size() * static_cast<std::size_t>(per_edge));
  for (std::size_t b = 0; b < m.bars.size(); ++b) {
    const auto [it, fresh] = edge_of.try_emplace(mesh::edge_key(m.bars[b][0], m.bars[b][1]),
                                                 static_cast<GO>(edges.size()));
    if (fresh) edges.push_back({m.bars[b][0], m.bars[b][1], kNoIndex, m.bar_curve[b], -1});
    const bool reversed = edges[static_cast<std::size_t>(it->second)].a != m.bars[b][0];
    for (GO s = 0; s < per_edge; ++s)
      m.bar_nodes[b * static_cast<std::size_t>(per_edge) + static_cast<std::size_t>(s)] =
          nv + it->second * per_edge + (reversed ? per_edge - 1 - s : s);
  }
  // Side k of quad q: 2 e + 1 when it runs against edge e's direction, 2 e else.
  std::vector<std::array<GO, 4>> quad_sides(static_cast<std::size_t>(nq));
  for (GO q = 0; q < nq; ++q) {
    const auto& quad = m.quads[static_cast<std::size_t>(q)];
    for (int k = 0; k < 4; ++k) {
      const auto [it, fresh] = edge_of.try_emplace(mesh::edge_key(quad[k], quad[(k + 1) % 4]),
                                                   static_cast<GO>(edges.size()));
      if (fresh) edges.push_back({quad[k], quad[(k + 1) % 4], kNoIndex, kNoIndex, -1});
      Edge& e = edges[static_cast<std::size_t>(it->second)];
      if (e.quad < 0) {
        e.quad = q;
        e.face = m.quad_face[static_cast<std::size_t>(q)];
      }
      quad_sides[static_cast<std::size_t>(q)][static_cast<std::size_t>(k)] =
          2 * it->second + (e.a != quad[k] ? 1 : 0);
    }
  }
  const auto ne = static_cast<GO>(edges.size());
  // The interior nodes follow the edge nodes, quad by quad, row by row.
  const GO first_interior = ne * per_edge;
  m.quad_nodes.resize(static_cast<std::size_t>(nq * per_quad));
  for (GO q = 0; q < nq; ++q) {
    GO* out = m.quad_nodes.data() + q * per_quad;
    for (int k = 0; k < 4; ++k) {
      const GO side = quad_sides[static_cast<std::size_t>(q)][static_cast<std::size_t>(k)];
      const GO e = side / 2;
      for (GO s = 0; s < per_edge; ++s)
        *out++ = nv + e * per_edge + ((side & 1) != 0 ? per_edge - 1 - s : s);
    }
    for (GO k = 0; k < per_interior; ++k) *out++ = nv + first_interior + q * per_interior + k;
  }

  std::vector<Vec3> points(static_cast<std::size_t>(first_interior + nq * per_interior));
  std::vector<mesh::VertexClass> vclass(points.size());
  std::vector<char> projected(points.size(), 1);
  auto fraction = [n](GO s) { return static_cast<double>(s + 1) / n; };  // of edge node s

  std::vector<std::vector<GO>> curve_edges(static_cast<std::size_t>(model.num_curves()));
  std::vector<std::vector<GO>> face_edges(static_cast<std::size_t>(model.num_faces()));
  std::vector<std::vector<GO>> face_quads(static_cast<std::size_t>(model.num_faces()));
  for (GO e = 0; e < ne; ++e) {
    const Edge& x = edges[static_cast<std::size_t>(e)];
    if (x.curve != kNoIndex)
      curve_edges[static_cast<std::size_t>(x.curve)].push_back(e);
    else if (x.face != kNoIndex)
      face_edges[static_cast<std::size_t>(x.face)].push_back(e);
  }
  for (GO q = 0; q < nq; ++q)
    face_quads[static_cast<std::size_t>(m.quad_face[static_cast<std::size_t>(q)])].push_back(q);

  // Whether the nodes of an edge from pa to pb (all placed on the CAD) are unevenly apart: the
  // longest of the per_edge + 1 steps over 1.25 times the shortest.
  auto uneven = [&](const Vec3& pa, const Vec3& pb, const Vec3* nodes, const char* on_cad) {
    double shortest = std::numeric_limits<double>::max(), longest = 0;
    Vec3 prev = pa;
    for (GO s = 0; s <= per_edge; ++s) {
      if (s < per_edge && on_cad[s] == 0) return false;
      const Vec3& p = s < per_edge ? nodes[s] : pb;
      shortest = std::min(shortest, distance(prev, p));
      longest = std::max(longest, distance(prev, p));
      prev = p;
    }
    return longest > 1.25 * shortest;
  };
  constexpr std::size_t kSamples = 8;  // samples per node step to measure arc lengths

  // Curve nodes: at equispaced parameters between the bar's ends. A parameter point further from
  // the chord than the chord is long (a closed curve's wrong end, a wild parametrization) gives
  // way to the projection of the chord's point, and that to the chord's point itself.
  tasks.parallel_for(model.num_curves(), [&](std::int64_t ci) {
    const auto c = static_cast<LO>(ci);
    if (curve_edges[static_cast<std::size_t>(c)].empty()) return;
    const cad::Curve& cc = model.curves()[static_cast<std::size_t>(c)];
    const auto geom = model.curve_geometry(c);
    auto t_of = [&](const mesh::VertexClass& v, double other) {
      if (v.dim == 1) return v.param[0];
      if (cc.corners[0] == v.entity && cc.corners[1] == v.entity)  // closed curve: the nearer end
        return std::abs(cc.t0 - other) <= std::abs(cc.t1 - other) ? cc.t0 : cc.t1;
      return cc.corners[0] == v.entity ? cc.t0 : cc.t1;
    };
    for (GO e : curve_edges[static_cast<std::size_t>(c)]) {
      const Edge& x = edges[static_cast<std::size_t>(e)];
      const auto& ca = m.vclass[static_cast<std::size_t>(x.a)];
      const auto& cb = m.vclass[static_cast<std::size_t>(x.b)];
      const double mid_range = 0.5 * (cc.t0 + cc.t1);
      const double ta = t_of(ca, cb.dim == 1 ? cb.param[0] : mid_range);
      const double tb = t_of(cb, ta);
      const Vec3 pa = m.points[static_cast<std::size_t>(x.a)],
                 pb = m.points[static_cast<std::size_t>(x.b)];
      const double chord = distance(pa, pb);
      for (GO s = 0; s < per_edge; ++s) {
        const double r = fraction(s);
        const Vec3 straight = pa + r * (pb - pa);
        const auto node = static_cast<std::size_t>(e * per_edge + s);
        double t = ta + r * (tb - ta);
        Vec3 p = geom->point(t);
        if (distance(p, straight) > chord) t = geom->project(straight, t, &p);
        if (distance(p, straight) <= chord) {
          points[node] = p;
          vclass[node] = {1, c, kNoIndex, {t, 0}};
        } else {
          points[node] = straight;
          vclass[node] = {1, c, kNoIndex, {ta + r * (tb - ta), 0}};
          projected[node] = 0;
        }
      }
      // Where the parametrization runs at an uneven speed along the bar, equal parameter steps
      // are uneven 3D steps, and a Lagrange edge through unevenly spread nodes swings (its end
      // tangent can turn back and fold the quad): the nodes go to equal arc lengths instead.
      const std::size_t first = static_cast<std::size_t>(e * per_edge);
      if (!uneven(pa, pb, &points[first], &projected[first])) continue;
      std::vector<double> ts(kSamples * static_cast<std::size_t>(n) + 1), len(ts.size(), 0.0);
      Vec3 prev = pa;
      for (std::size_t k = 0; k < ts.size(); ++k) {
        ts[k] = ta + (tb - ta) * static_cast<double>(k) / static_cast<double>(ts.size() - 1);
        const Vec3 p = k + 1 < ts.size() ? geom->point(ts[k]) : pb;
        if (k > 0) len[k] = len[k - 1] + distance(prev, p);
        prev = p;
      }
      for (GO s = 0; s < per_edge; ++s) {
        const double want = fraction(s) * len.back();
        const auto k = static_cast<std::size_t>(std::upper_bound(len.begin(), len.end(), want) -
                                                len.begin() - 1);
        const std::size_t k1 = std::min(k + 1, len.size() - 1);
        const double w = len[k1] > len[k] ? (want - len[k]) / (len[k1] - len[k]) : 0.0;
        const double t = ts[k] + w * (ts[k1] - ts[k]);
        const Vec3 p = geom->point(t);
        if (distance(p, pa + fraction(s) * (pb - pa)) > chord) continue;
        points[first + static_cast<std::size_t>(s)] = p;
        vclass[first + static_cast<std::size_t>(s)] = {1, c, kNoIndex, {t, 0}};
      }
    }
  });

  // Faces: their edge nodes in one pass, their interior nodes in the next (which read the edge
  // nodes of their quads, on this face or on its curves, all placed by then).
  for (const bool interior : {false, true}) {
    tasks.parallel_for(model.num_faces(), [&](std::int64_t fi) {
      const auto f = static_cast<LO>(fi);
      if (face_quads[static_cast<std::size_t>(f)].empty()) return;
      const auto geom = model.face_geometry(f);
      // A reference (u, v) near a quad: a face vertex's own, else an image of its first corner.
      auto reference = [&](GO q) {
        const auto& quad = m.quads[static_cast<std::size_t>(q)];
        for (GO v : quad)
          if (m.vclass[static_cast<std::size_t>(v)].dim == 2)
            return Vec2{m.vclass[static_cast<std::size_t>(v)].param[0],
                        m.vclass[static_cast<std::size_t>(v)].param[1]};
        const auto images = uv_images(model, *geom, f, m.vclass[static_cast<std::size_t>(quad[0])]);
        return images.empty() ? Vec2{0, 0} : images.front();
      };
      auto uv_near = [&](GO v, const Vec2& ref) {
        const auto images = uv_images(model, *geom, f, m.vclass[static_cast<std::size_t>(v)]);
        return images.empty() ? ref : nearest(images, ref);
      };
      // Node `node` at the projection of `target` on the face, or at `target` itself when the
      // projection lands further than `reach` from it. The projection is Newton's in (u, v),
      // which stalls next to a singular point of the parametrization (a sphere's pole: there u
      // hardly moves the point) on a point of the surface that is not the nearest: a node off
      // its place along the surface, which costs the element its order. When the residual is
      // not along the normal, the projection starts again from `more` guesses (the element's
      // corners) and the nearest foot wins.
      auto nearest_foot = [&](const Vec3& target, const Vec2& guess, double reach,
                              std::span<const Vec2> more, Vec3& foot) {
        Vec2 uv = geom->project(target, guess, &foot);
        auto converged = [&](const Vec2& at, const Vec3& p) {
          const Vec3 r = target - p;
          const Vec3 nrm = geom->normal(at);
          return norm(r - dot(r, nrm) * nrm) <= 1e-9 * reach;
        };
        for (std::size_t k = 0; k < more.size() && !converged(uv, foot); ++k) {
          Vec3 other{};
          const Vec2 w = geom->project(target, more[k], &other);
          if (distance(other, target) < distance(foot, target)) {
            foot = other;
            uv = w;
          }
        }
        return uv;
      };
      auto place = [&](std::size_t node, const Vec3& target, const Vec2& guess, double reach,
                       std::span<const Vec2> more) {
        Vec3 foot{};
        const Vec2 uv = nearest_foot(target, guess, reach, more, foot);
        if (distance(foot, target) <= reach) {
          points[node] = foot;
          vclass[node] = {2, f, kNoIndex, {uv.u, uv.v}};
        } else {
          points[node] = target;
          vclass[node] = {2, f, kNoIndex, {guess.u, guess.v}};
          projected[node] = 0;
        }
      };
      if (!interior) {
        for (GO e : face_edges[static_cast<std::size_t>(f)]) {
          const Edge& x = edges[static_cast<std::size_t>(e)];
          const Vec2 ref = reference(x.quad);
          const Vec2 ua = uv_near(x.a, ref), ub = uv_near(x.b, ref);
          const std::array<Vec2, 2> ends{ua, ub};
          const Vec3 pa = m.points[static_cast<std::size_t>(x.a)],
                     pb = m.points[static_cast<std::size_t>(x.b)];
          const double chord = distance(pa, pb);
          for (GO s = 0; s < per_edge; ++s) {
            const double r = fraction(s);
            place(static_cast<std::size_t>(e * per_edge + s), pa + r * (pb - pa),
                  ua + r * (ub - ua), chord, ends);
          }
          // On a surface curved strongly across the edge (a small radius spanned by a few
          // elements) the chord's projected points bunch up, and a Lagrange edge through them
          // swings and folds its quads: the nodes go to equal arc lengths along the projected
          // chord instead.
          const std::size_t first = static_cast<std::size_t>(e * per_edge);
          if (!uneven(pa, pb, &points[first], &projected[first])) continue;
          const std::size_t ns = kSamples * static_cast<std::size_t>(n) + 1;
          std::vector<Vec3> sp(ns);
          std::vector<Vec2> suv(ns);
          std::vector<double> len(ns, 0.0);
          bool on_surface = true;
          for (std::size_t k = 0; k < ns && on_surface; ++k) {
            const double r = static_cast<double>(k) / static_cast<double>(ns - 1);
            if (k == 0 || k + 1 == ns) {
              sp[k] = k == 0 ? pa : pb;
              suv[k] = k == 0 ? ua : ub;
            } else {
              const Vec3 target = pa + r * (pb - pa);
              suv[k] = nearest_foot(target, ua + r * (ub - ua), chord, ends, sp[k]);
              on_surface = distance(sp[k], target) <= chord;
            }
            if (k > 0) len[k] = len[k - 1] + distance(sp[k - 1], sp[k]);
          }
          if (!on_surface) continue;
          for (GO s = 0; s < per_edge; ++s) {
            const double want = fraction(s) * len.back();
            const auto k = static_cast<std::size_t>(std::upper_bound(len.begin(), len.end(), want) -
                                                    len.begin() - 1);
            const std::size_t k1 = std::min(k + 1, ns - 1);
            const double w = len[k1] > len[k] ? (want - len[k]) / (len[k1] - len[k]) : 0.0;
            place(first + static_cast<std::size_t>(s), sp[k] + w * (sp[k1] - sp[k]),
                  suv[k] + w * (suv[k1] - suv[k]), chord, ends);
          }
        }
        return;
      }
      // Interior nodes: the Coons patch of the four curved sides, guessed at the bilinear
      // interpolation of the corners' (u, v).
      const int np = n + 1;
      std::vector<Vec3> g(static_cast<std::size_t>(np * np));
      auto at = [&](int i, int j) -> Vec3& { return g[static_cast<std::size_t>(i + np * j)]; };
      for (GO q : face_quads[static_cast<std::size_t>(f)]) {
        const auto& quad = m.quads[static_cast<std::size_t>(q)];
        const GO* ho = m.quad_nodes.data() + q * per_quad;
        at(0, 0) = m.points[static_cast<std::size_t>(quad[0])];
        at(n, 0) = m.points[static_cast<std::size_t>(quad[1])];
        at(n, n) = m.points[static_cast<std::size_t>(quad[2])];
        at(0, n) = m.points[static_cast<std::size_t>(quad[3])];
        for (int s = 1; s < n; ++s) {
          const auto node = [&](int side) {
            return points[static_cast<std::size_t>(ho[side * per_edge + s - 1] - nv)];
          };
          at(s, 0) = node(0);
          at(n, s) = node(1);
          at(n - s, n) = node(2);
          at(0, n - s) = node(3);
        }
        const Vec2 ref = reference(q);
        std::array<Vec2, 4> uv{};
        for (std::size_t k = 0; k < 4; ++k) uv[k] = uv_near(quad[k], ref);
        const double reach = std::max(distance(at(0, 0), at(n, n)), distance(at(n, 0), at(0, n)));
        for (int j = 1; j < n; ++j)
          for (int i = 1; i < n; ++i) {
            const double r = static_cast<double>(i) / n, t = static_cast<double>(j) / n;
            place(static_cast<std::size_t>(first_interior + q * per_interior + (i - 1) +
                                           per_edge * (j - 1)),
                  coons(at, n, i, j), bilinear(uv, r, t), reach, uv);
          }
      }
    });
  }

  HighOrderReport report;
  report.order = order;

  // Validity: a curved quad that folds gets its face nodes back on the straight positions.
  const QuadChecker checker(order);
  auto node_point = [&](GO id) {
    return id < nv ? m.points[static_cast<std::size_t>(id)]
                   : points[static_cast<std::size_t>(id - nv)];
  };
  // The normal SICN (Eq. 12) measures the linear quad against: the sum of its corner cross
  // products. A linear quad of positive SICN is then valid as a straight Lagrange quad.
  auto linear_normal = [&](GO q) {
    const auto& quad = m.quads[static_cast<std::size_t>(q)];
    Vec3 nrm{};
    for (int k = 0; k < 4; ++k) {
      const Vec3& c = m.points[static_cast<std::size_t>(quad[k])];
      nrm += cross(m.points[static_cast<std::size_t>(quad[(k + 1) % 4])] - c,
                   m.points[static_cast<std::size_t>(quad[(k + 3) % 4])] - c);
    }
    return nrm;
  };
  auto element = [&](GO q) {
    std::array<Vec3, kMaxNodes> g{};
    const auto& quad = m.quads[static_cast<std::size_t>(q)];
    for (std::size_t k = 0; k < 4; ++k)
      g[checker.grid(k)] = m.points[static_cast<std::size_t>(quad[k])];
    const GO* ho = m.quad_nodes.data() + q * per_quad;
    for (std::size_t k = 0; k < static_cast<std::size_t>(per_quad); ++k)
      g[checker.grid(4 + k)] = node_point(ho[k]);
    return g;
  };
  auto valid = [&](GO q) { return checker.valid(element(q), linear_normal(q)); };
  // Puts the edge nodes of quad q (those inside its face only, or all of them) and its interior
  // nodes back on the straight positions: the bilinear quad's, which every order reproduces.
  auto straighten = [&](GO q, bool curve_nodes_too) {
    const auto& quad = m.quads[static_cast<std::size_t>(q)];
    for (std::size_t k = 0; k < 4; ++k) {
      const GO e = quad_sides[static_cast<std::size_t>(q)][k] / 2;
      const Edge& x = edges[static_cast<std::size_t>(e)];
      if (x.curve != kNoIndex && !curve_nodes_too) continue;
      const Vec3 pa = m.points[static_cast<std::size_t>(x.a)],
                 pb = m.points[static_cast<std::size_t>(x.b)];
      for (GO s = 0; s < per_edge; ++s) {
        const auto node = static_cast<std::size_t>(e * per_edge + s);
        points[node] = pa + fraction(s) * (pb - pa);
        projected[node] = 0;
      }
    }
    std::array<Vec3, 4> c{};
    for (std::size_t k = 0; k < 4; ++k) c[k] = m.points[static_cast<std::size_t>(quad[k])];
    for (int j = 1; j < n; ++j)
      for (int i = 1; i < n; ++i) {
        const double r = static_cast<double>(i) / n, t = static_cast<double>(j) / n;
        const auto node = static_cast<std::size_t>(first_interior + q * per_interior + (i - 1) +
                                                   per_edge * (j - 1));
        points[node] = bilinear(c, r, t);
        projected[node] = 0;
      }
  };
  // Puts the face nodes of quad q back on its face along the parameter lines instead of straight:
  // the nodes of its edges inside the face at the images of evenly spaced (u, v) between the
  // edge's ends, its interior nodes at the image of the Coons patch of its four sides' (u, v)
  // (curve nodes stay where they are, their pcurve images are the patch's sides). The element is
  // then S o phi with phi the quad's parameter patch: on a regular surface it folds only where
  // phi does, whereas the projected 3D positions fold where the surface turns strongly across a
  // long edge. Returns false, changing nothing, where the images are not known (a node already
  // off the CAD, a vertex with no image in the face).
  std::vector<Vec2> patch(static_cast<std::size_t>((n + 1) * (n + 1)));
  auto reshape = [&](GO q) {
    const auto& quad = m.quads[static_cast<std::size_t>(q)];
    const LO f = m.quad_face[static_cast<std::size_t>(q)];
    const auto geom = model.face_geometry(f);
    const int np = n + 1;
    auto uv = [&](int i, int j) -> Vec2& { return patch[static_cast<std::size_t>(i + np * j)]; };
    Vec2 ref{};
    bool have_ref = false;
    for (GO v : quad)
      if (!have_ref && m.vclass[static_cast<std::size_t>(v)].dim == 2) {
        ref = {m.vclass[static_cast<std::size_t>(v)].param[0],
               m.vclass[static_cast<std::size_t>(v)].param[1]};
        have_ref = true;
      }
    std::array<Vec2, 4> corner{};
    for (std::size_t k = 0; k < 4; ++k) {
      const auto images = uv_images(model, *geom, f, m.vclass[static_cast<std::size_t>(quad[k])]);
      if (images.empty()) return false;
      if (!have_ref) {
        ref = images.front();
        have_ref = true;
      }
      corner[k] = nearest(images, ref);
    }
    uv(0, 0) = corner[0];
    uv(n, 0) = corner[1];
    uv(n, n) = corner[2];
    uv(0, n) = corner[3];
    const GO* ho = m.quad_nodes.data() + q * per_quad;
    const auto walk = side_walk(n);
    for (std::size_t k = 0; k < 4; ++k) {
      const Edge& x =
          edges[static_cast<std::size_t>(quad_sides[static_cast<std::size_t>(q)][k] / 2)];
      const Vec2 a = corner[k], b = corner[(k + 1) % 4];
      for (int s = 1; s < n; ++s) {
        const Vec2 straight = a + (static_cast<double>(s) / n) * (b - a);
        Vec2 at = straight;
        if (x.curve != kNoIndex) {
          const auto node = static_cast<std::size_t>(ho[k * per_edge + s - 1] - nv);
          if (projected[node] == 0) return false;
          const auto images = uv_images(model, *geom, f, vclass[node]);
          if (images.empty()) return false;
          at = nearest(images, straight);
        }
        uv(walk[k][0] + s * walk[k][2], walk[k][1] + s * walk[k][3]) = at;
      }
    }
    for (int j = 1; j < n; ++j)
      for (int i = 1; i < n; ++i) {
        uv(i, j) = coons(uv, n, i, j);
      }
    auto set = [&](std::size_t node, const Vec2& at) {
      points[node] = geom->eval(at).p;
      vclass[node] = {2, f, kNoIndex, {at.u, at.v}};
      projected[node] = 1;
    };
    for (std::size_t k = 0; k < 4; ++k) {
      if (edges[static_cast<std::size_t>(quad_sides[static_cast<std::size_t>(q)][k] / 2)].curve !=
          kNoIndex)
        continue;
      for (int s = 1; s < n; ++s)
        set(static_cast<std::size_t>(ho[k * per_edge + s - 1] - nv),
            uv(walk[k][0] + s * walk[k][2], walk[k][1] + s * walk[k][3]));
    }
    for (int j = 1; j < n; ++j)
      for (int i = 1; i < n; ++i)
        set(static_cast<std::size_t>(first_interior + q * per_interior + (i - 1) +
                                     per_edge * (j - 1)),
            uv(i, j));
    return true;
  };
  // Quads sharing an edge (and so edge nodes) with q; interior nodes are q's own.
  std::vector<GO> edge_quad_offsets(static_cast<std::size_t>(ne) + 1, 0), edge_quads;
  for (const auto& sides : quad_sides)
    for (GO side : sides) ++edge_quad_offsets[static_cast<std::size_t>(side / 2) + 1];
  for (std::size_t e = 0; e < static_cast<std::size_t>(ne); ++e)
    edge_quad_offsets[e + 1] += edge_quad_offsets[e];
  edge_quads.resize(static_cast<std::size_t>(edge_quad_offsets.back()));
  {
    std::vector<GO> fill(edge_quad_offsets.begin(), edge_quad_offsets.end() - 1);
    for (GO q = 0; q < nq; ++q)
      for (GO side : quad_sides[static_cast<std::size_t>(q)])
        edge_quads[static_cast<std::size_t>(fill[static_cast<std::size_t>(side / 2)]++)] = q;
  }
  // Untangles quad q in parameter space, every node staying on its CAD entity: its curve nodes
  // move along their curve's parameter (between their edge's ends, in order), its face nodes (of
  // its edges inside the face, and inside it) in (u, v) inside the face. A folded quad that the
  // reshaping left folded is folded by its curve nodes (a curve bending across the element at a
  // sharp CAD corner, two sides on one curve): no placement of the face nodes alone unfolds it,
  // but the freedom along the curves often does. The quads sharing an edge with q move with it
  // (an edge node is theirs too). Pattern search, coordinate by coordinate (steps of 1/16 of the
  // node spacing in t, or of the quad's (u, v) extent over N, halved when no step helps): first
  // the folds summed over the samples of those quads (min_scaled_jacobian's `folded`) up, then
  // their smallest scaled Jacobian, until it reaches kUntangleEnough. Past that the nodes would
  // only spread further unevenly along the curves, and the geometric error of the quads on them
  // grows with that (on a cylinder's side next to a cap quad with two sides on the circle, order
  // 3: 2.6e-3 with small steps and this stop, 5e-3 with steps of a quarter, 9e-3 maximising;
  // the linear mesh's 3.3e-2). Kept only when q comes out valid and no quad that was valid
  // folds; else the search starts once more from the curve nodes at equal parameter steps, and
  // failing that every node goes back. Returns whether it was kept. Serial, so deterministic.
  constexpr int kUntangleBudget = 3000;  // objective evaluations per search at most
  constexpr int kUntangleHalvings = 8;
  constexpr double kUntangleEnough = 0.1;
  constexpr double kUntangleStep = 1.0 / 16;  // first step, of the node spacing
  std::vector<char> untangled(static_cast<std::size_t>(nq), 0);
  auto untangle = [&](GO q) {
    const auto& quad = m.quads[static_cast<std::size_t>(q)];
    const LO f = m.quad_face[static_cast<std::size_t>(q)];
    const GO* ho = m.quad_nodes.data() + q * per_quad;
    for (GO k = 0; k < per_quad; ++k)
      if (projected[static_cast<std::size_t>(ho[k] - nv)] == 0) return false;
    // The quads moving with q (q included), sorted, and each one's part of the objective.
    std::vector<GO> near;
    for (GO side : quad_sides[static_cast<std::size_t>(q)]) {
      const auto e = static_cast<std::size_t>(side / 2);
      for (GO k = edge_quad_offsets[e]; k < edge_quad_offsets[e + 1]; ++k)
        near.push_back(edge_quads[static_cast<std::size_t>(k)]);
    }
    std::sort(near.begin(), near.end());
    near.erase(std::unique(near.begin(), near.end()), near.end());
    std::vector<Vec3> normals(near.size());
    std::vector<char> was_valid(near.size());
    std::vector<double> folded(near.size(), 0.0), worst(near.size());
    auto measure = [&](std::size_t k) {
      folded[k] = 0;
      worst[k] = checker.min_scaled_jacobian(element(near[k]), normals[k], &folded[k]);
    };
    for (std::size_t k = 0; k < near.size(); ++k) {
      normals[k] = linear_normal(near[k]);
      was_valid[k] = valid(near[k]) ? 1 : 0;
      measure(k);
    }
    auto total = [&] {
      double fold = 0, low = 1;
      for (std::size_t k = 0; k < near.size(); ++k) {
        fold += folded[k];
        low = std::min(low, worst[k]);
      }
      return std::array<double, 2>{fold, low};
    };
    const auto face = model.face_geometry(f, true);
    // The coordinates: node, which parameter (0: t, 1: u, 2: v), step; for a curve node, its
    // edge's nodes' parameters bound it (the edge's end parameters at the ends).
    struct Coordinate {
      std::size_t node;
      int which;
      double step;
      double lo_end, hi_end;           // end parameters of a curve node's edge (a side, b side)
      std::size_t first;               // a curve edge's first node
      std::size_t curve;               // a curve node's evaluator in `curves`
      std::vector<std::size_t> quads;  // indices in `near` of the quads holding the node
    };
    std::vector<Coordinate> coords;
    std::vector<std::unique_ptr<cad::CurveGeometry>> curves;
    auto holders = [&](GO e) {
      std::vector<std::size_t> out;
      for (GO k = edge_quad_offsets[static_cast<std::size_t>(e)];
           k < edge_quad_offsets[static_cast<std::size_t>(e) + 1]; ++k)
        out.push_back(static_cast<std::size_t>(
            std::lower_bound(near.begin(), near.end(), edge_quads[static_cast<std::size_t>(k)]) -
            near.begin()));
      return out;
    };
    // The (u, v) extent of the quad, for the steps: its face nodes' and corners' (u, v).
    Vec2 lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max()};
    Vec2 hi{-lo.u, -lo.v};
    auto extend = [&](const Vec2& x) {
      lo = {std::min(lo.u, x.u), std::min(lo.v, x.v)};
      hi = {std::max(hi.u, x.u), std::max(hi.v, x.v)};
    };
    const auto& centre_class = vclass[static_cast<std::size_t>(first_interior + q * per_interior)];
    const Vec2 ref{centre_class.param[0], centre_class.param[1]};
    for (GO v : quad) {
      const auto images = uv_images(model, *face, f, m.vclass[static_cast<std::size_t>(v)]);
      if (!images.empty()) extend(nearest(images, ref));
    }
    std::vector<std::size_t> face_nodes;
    for (std::size_t k = 0; k < 4; ++k) {
      const GO e = quad_sides[static_cast<std::size_t>(q)][k] / 2;
      const Edge& x = edges[static_cast<std::size_t>(e)];
      const auto first = static_cast<std::size_t>(e * per_edge);
      if (x.curve == kNoIndex) {
        for (GO s = 0; s < per_edge; ++s) face_nodes.push_back(first + static_cast<std::size_t>(s));
        continue;
      }
      // The parameters of the edge's ends: a vertex's own on the curve; at a CAD corner the end
      // of the curve's range nearer to the edge's node next to it (closed curves have two).
      const cad::Curve& cc = model.curves()[static_cast<std::size_t>(x.curve)];
      auto end_t = [&](GO v, double next_to) {
        const auto& c = m.vclass[static_cast<std::size_t>(v)];
        if (c.dim == 1) return c.param[0];
        const bool at0 = cc.corners[0] == c.entity, at1 = cc.corners[1] == c.entity;
        if (at0 && at1)
          return std::abs(cc.t0 - next_to) <= std::abs(cc.t1 - next_to) ? cc.t0 : cc.t1;
        return at0 ? cc.t0 : cc.t1;
      };
      const double ta = end_t(x.a, vclass[first].param[0]);
      const double tb = end_t(x.b, vclass[first + static_cast<std::size_t>(per_edge - 1)].param[0]);
      // Only an edge whose nodes run in order between its ends moves.
      bool ordered = (tb - ta) != 0;
      double prev = ta;
      for (GO s = 0; s <= per_edge && ordered; ++s) {
        const double t = s < per_edge ? vclass[first + static_cast<std::size_t>(s)].param[0] : tb;
        ordered = (t - prev) * (tb - ta) > 0;
        prev = t;
      }
      if (!ordered) continue;
      curves.push_back(model.curve_geometry(x.curve));
      const auto who = holders(e);
      for (GO s = 0; s < per_edge; ++s)
        coords.push_back({first + static_cast<std::size_t>(s), 0, kUntangleStep * (tb - ta) / n, ta,
                          tb, first, curves.size() - 1, who});
    }
    for (GO k = 0; k < per_interior; ++k)
      face_nodes.push_back(static_cast<std::size_t>(first_interior + q * per_interior + k));
    for (std::size_t node : face_nodes) {
      if (vclass[node].dim != 2 || vclass[node].entity != f) return false;
      extend({vclass[node].param[0], vclass[node].param[1]});
    }
    const double du = hi.u - lo.u, dv = hi.v - lo.v;
    const double step_u = kUntangleStep * std::max(du, 1e-3 * dv) / n,
                 step_v = kUntangleStep * std::max(dv, 1e-3 * du) / n;
    for (std::size_t node : face_nodes) {
      std::vector<std::size_t> who;
      if (node < static_cast<std::size_t>(first_interior))
        who = holders(static_cast<GO>(node) / per_edge);
      else
        who = {
            static_cast<std::size_t>(std::lower_bound(near.begin(), near.end(), q) - near.begin())};
      coords.push_back({node, 1, step_u, 0, 0, 0, 0, who});
      coords.push_back({node, 2, step_v, 0, 0, 0, 0, who});
    }
    if (!(step_u > 0) || !(step_v > 0)) return false;
    // Saved state, to go back to.
    std::vector<std::pair<Vec3, mesh::VertexClass>> saved;
    saved.reserve(coords.size());
    for (const Coordinate& c : coords) saved.emplace_back(points[c.node], vclass[c.node]);
    // Moves coordinate k by `delta`; false, changing nothing, when that leaves its range.
    auto move = [&](std::size_t k, double delta) {
      const Coordinate& c = coords[k];
      if (c.which == 0) {
        const double t = vclass[c.node].param[0] + delta;
        const double t_prev = c.node == c.first ? c.lo_end : vclass[c.node - 1].param[0];
        const double t_next = c.node + 1 == c.first + static_cast<std::size_t>(per_edge)
                                  ? c.hi_end
                                  : vclass[c.node + 1].param[0];
        const double gap = 1e-3 * std::abs(c.hi_end - c.lo_end) / n;
        const double dir = c.hi_end > c.lo_end ? 1.0 : -1.0;
        if (!((t - t_prev) * dir > gap && (t_next - t) * dir > gap)) return false;
        vclass[c.node].param[0] = t;
        points[c.node] = curves[c.curve]->point(t);
        return true;
      }
      Vec2 uv{vclass[c.node].param[0], vclass[c.node].param[1]};
      (c.which == 1 ? uv.u : uv.v) += delta;
      if (!face->contains(uv)) return false;
      vclass[c.node].param = {uv.u, uv.v};
      points[c.node] = face->eval(uv).p;
      return true;
    };
    auto better = [](const std::array<double, 2>& a, const std::array<double, 2>& b) {
      return a[0] > b[0] || (a[0] == b[0] && a[1] > b[1]);
    };
    std::array<double, 2> best{};
    std::vector<double> step(coords.size());
    auto search = [&] {
      best = total();
      for (std::size_t k = 0; k < coords.size(); ++k) step[k] = coords[k].step;
      int evaluations = 0;
      for (int halvings = 0; halvings <= kUntangleHalvings && evaluations < kUntangleBudget &&
                             !(best[0] == 0 && best[1] >= kUntangleEnough);) {
        bool improved = false;
        for (std::size_t k = 0; k < coords.size() && evaluations < kUntangleBudget &&
                                !(best[0] == 0 && best[1] >= kUntangleEnough);
             ++k)
          for (const double sign : {1.0, -1.0}) {
            const auto before = std::make_pair(points[coords[k].node], vclass[coords[k].node]);
            if (!move(k, sign * step[k])) continue;
            ++evaluations;
            std::vector<std::array<double, 2>> old;
            for (std::size_t h : coords[k].quads) {
              old.push_back({folded[h], worst[h]});
              measure(h);
            }
            const auto now = total();
            if (better(now, best)) {
              best = now;
              improved = true;
              break;
            }
            points[coords[k].node] = before.first;
            vclass[coords[k].node] = before.second;
            for (std::size_t i = 0; i < coords[k].quads.size(); ++i) {
              folded[coords[k].quads[i]] = old[i][0];
              worst[coords[k].quads[i]] = old[i][1];
            }
          }
        if (!improved) {
          for (double& x : step) x *= 0.5;
          ++halvings;
        }
      }
    };
    auto acceptable = [&] {
      bool ok = valid(q);
      for (std::size_t k = 0; k < near.size() && ok; ++k) ok = was_valid[k] == 0 || valid(near[k]);
      return ok;
    };
    search();
    bool kept = acceptable();
    // A search that ended folded (a local optimum) starts again once from the curve nodes at
    // equal parameter steps between their edge's ends, the face nodes where they were.
    if (!kept) {
      bool relaxed = false;
      for (std::size_t k = 0; k < coords.size(); ++k) {
        points[coords[k].node] = saved[k].first;
        vclass[coords[k].node] = saved[k].second;
        if (coords[k].which != 0) continue;
        const double t =
            coords[k].lo_end + static_cast<double>(coords[k].node - coords[k].first + 1) / n *
                                   (coords[k].hi_end - coords[k].lo_end);
        vclass[coords[k].node].param[0] = t;
        points[coords[k].node] = curves[coords[k].curve]->point(t);
        relaxed = true;
      }
      if (relaxed) {
        for (std::size_t k = 0; k < near.size(); ++k) measure(k);
        search();
        kept = acceptable();
      }
    }
    untangled[static_cast<std::size_t>(q)] = kept ? 1 : 0;
    if (!kept)
      for (std::size_t k = 0; k < coords.size(); ++k) {
        points[coords[k].node] = saved[k].first;
        vclass[coords[k].node] = saved[k].second;
      }
    return kept;
  };
  // Each quad's smallest scaled Jacobian, positive where the quad is valid (the same test as
  // valid's: the Jacobian over positive lengths), as of the last check_all.
  std::vector<double> lowest(static_cast<std::size_t>(nq), 1.0);
  auto check_all = [&] {
    tasks.parallel_for(nq, [&](std::int64_t q) {
      lowest[static_cast<std::size_t>(q)] =
          checker.min_scaled_jacobian(element(q), linear_normal(q), nullptr);
    });
    std::vector<GO> bad;
    for (GO q = 0; q < nq; ++q)
      if (!(lowest[static_cast<std::size_t>(q)] > 0)) bad.push_back(q);
    return bad;
  };
  // Applies `fix` to the quads of `work` that are not valid, then to those the fixed nodes fold,
  // round after round in quad order (deterministic); each quad once at most. `fix` returns
  // whether it changed the quad.
  auto fix_all = [&](std::vector<GO> work, auto&& fix) {
    std::vector<char> done(static_cast<std::size_t>(nq), 0);
    std::int64_t count = 0;
    while (!work.empty()) {
      std::vector<GO> next;
      for (GO q : work) {
        if (done[static_cast<std::size_t>(q)] != 0 || valid(q)) continue;
        done[static_cast<std::size_t>(q)] = 1;
        if (!fix(q)) continue;
        ++count;
        for (GO side : quad_sides[static_cast<std::size_t>(q)]) {
          const auto e = static_cast<std::size_t>(side / 2);
          for (GO k = edge_quad_offsets[e]; k < edge_quad_offsets[e + 1]; ++k) {
            const GO other = edge_quads[static_cast<std::size_t>(k)];
            if (done[static_cast<std::size_t>(other)] == 0) next.push_back(other);
          }
        }
      }
      std::sort(next.begin(), next.end());
      next.erase(std::unique(next.begin(), next.end()), next.end());
      work = std::move(next);
    }
    return count;
  };
  // Folded quads first get their face nodes along the parameter lines (still on the CAD); those
  // still folded get them straight, off the CAD.
  // (A check that found nothing folded is not repeated: nothing changed since.)
  std::vector<GO> bad = check_all();
  report.reshaped = fix_all(bad, reshape);
  // Those still folded are untangled in parameter space (still on the CAD).
  if (!bad.empty()) bad = check_all();
  report.untangled = fix_all(bad, untangle);
  if (!bad.empty()) bad = check_all();
  report.straightened = fix_all(bad, [&](GO q) {
    straighten(q, false);
    return true;
  });
  // A quad still folded by its curve nodes (at a sharp CAD corner the curve bends across the
  // element) gets those straight too: its edge then leaves the curve between its ends.
  if (report.straightened > 0) {
    report.curve_straightened = fix_all(check_all(), [&](GO q) {
      straighten(q, true);
      return true;
    });
    report.invalid = static_cast<std::int64_t>(check_all().size());
  }
  // `lowest` is the final elements': the last check_all found nothing to straighten (so nothing
  // changed since), or came after the straightening.
  report.min_scaled_jacobian =
      lowest.empty() ? 1.0 : *std::min_element(lowest.begin(), lowest.end());
  for (GO q = 0; q < nq; ++q)
    if (untangled[static_cast<std::size_t>(q)] != 0)
      report.untangled_min_scaled_jacobian =
          std::min(report.untangled_min_scaled_jacobian, lowest[static_cast<std::size_t>(q)]);

  // A node off its entity keeps the entity it belongs to (dim, id) but no parameters: a reader
  // that evaluated them would put it back on the CAD, curving the quad that had to go straight.
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (vclass[i].dim == 1)
      ++report.curve_nodes;
    else
      ++report.face_nodes;
    if (projected[i] != 0) continue;
    ++report.unprojected;
    vclass[i].param = {std::numeric_limits<double>::quiet_NaN(),
                       std::numeric_limits<double>::quiet_NaN()};
  }

  m.points.insert(m.points.end(), points.begin(), points.end());
  m.vclass.insert(m.vclass.end(), vclass.begin(), vclass.end());
  m.order = order;
  return report;
}

double max_element_distance_to_cad(const mesh::SurfaceMesh& m, const cad::CadModel& model,
                                   const TaskArena& tasks) {
  QSMESH_CHECK(m.order > 1 && m.order <= kMaxOrder,
               "element distance to the CAD: the mesh is of order " << m.order);
  const int n = m.order;
  const auto per_quad = static_cast<std::size_t>(m.quad_nodes_per_quad());
  const auto positions = mesh::quad_grid_positions(n);
  // Interior node (i, j) is quad_nodes entry 4 (n - 1) + (i - 1) + (n - 1) (j - 1).
  auto interior = [n](int i, int j) {
    return static_cast<std::size_t>(4 * (n - 1) + (i - 1) + (n - 1) * (j - 1));
  };
  const std::array<std::array<int, 2>, 4> near{{{1, 1}, {n - 1, 1}, {n - 1, n - 1}, {1, n - 1}}};
  const double lo = 0.5 / n, hi = 1 - 0.5 / n;
  const std::array<std::array<double, 2>, 4> at{{{lo, lo}, {hi, lo}, {hi, hi}, {lo, hi}}};
  std::vector<std::vector<std::size_t>> face_quads(static_cast<std::size_t>(model.num_faces()));
  for (std::size_t q = 0; q < m.quads.size(); ++q)
    face_quads[static_cast<std::size_t>(m.quad_face[q])].push_back(q);
  std::vector<double> worst(face_quads.size(), 0.0);
  tasks.parallel_for(model.num_faces(), [&](std::int64_t fi) {
    const auto f = static_cast<std::size_t>(fi);
    if (face_quads[f].empty()) return;
    const auto geom = model.face_geometry(static_cast<LO>(f));
    std::vector<Vec3> x(positions.size());
    for (std::size_t q : face_quads[f]) {
      const GO* ho = m.quad_nodes.data() + q * per_quad;
      bool curved = true;
      for (std::size_t k = 0; k < per_quad; ++k)
        curved = curved && !std::isnan(m.vclass[static_cast<std::size_t>(ho[k])].param[0]);
      if (!curved) continue;
      for (std::size_t k = 0; k < 4; ++k) x[k] = m.points[static_cast<std::size_t>(m.quads[q][k])];
      for (std::size_t k = 0; k < per_quad; ++k)
        x[4 + k] = m.points[static_cast<std::size_t>(ho[k])];
      for (std::size_t c = 0; c < 4; ++c) {
        const mesh::VertexClass& g =
            m.vclass[static_cast<std::size_t>(ho[interior(near[c][0], near[c][1])])];
        const Vec3 p = lagrange_quad_point(n, x, at[c][0], at[c][1]);
        Vec3 foot{};
        (void)geom->project(p, {g.param[0], g.param[1]}, &foot);
        worst[f] = std::max(worst[f], distance(p, foot));
      }
    }
  });
  return worst.empty() ? 0.0 : *std::max_element(worst.begin(), worst.end());
}

}  // namespace qsmesh::highorder
