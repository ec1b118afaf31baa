#include "qsmesh/highorder/quadratic.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/edges.hpp"

namespace qsmesh::highorder {

namespace {

struct Edge {
  GO a, b;
  LO face = kNoIndex;   // face of the first quad using it
  LO curve = kNoIndex;  // curve of its bar, if any
  GO quad = -1;         // first quad using it
};

// The (u, v) images of vertex v in face f: its own (u, v) inside the face; on a curve or at a
// corner, the pcurve images of every use of the curve(s) in the face's loops (a seam has two).
std::vector<Vec2> uv_images(const cad::CadModel& model, const cad::FaceGeometry& face, LO f,
                            const mesh::VertexClass& c) {
  if (c.dim == 2) return {Vec2{c.param[0], c.param[1]}};
  std::vector<Vec2> out;
  const auto& loops = model.faces()[static_cast<std::size_t>(f)].loops;
  for (std::size_t l = 0; l < loops.size(); ++l)
    for (std::size_t u = 0; u < loops[l].uses.size(); ++u) {
      const LO curve = loops[l].uses[u].curve;
      const cad::Curve& cc = model.curves()[static_cast<std::size_t>(curve)];
      if (c.dim == 1 && curve == c.entity) {
        out.push_back(face.boundary_uv(static_cast<LO>(l), static_cast<LO>(u), c.param[0]));
      } else if (c.dim == 0) {
        if (cc.corners[0] == c.entity)
          out.push_back(face.boundary_uv(static_cast<LO>(l), static_cast<LO>(u), cc.t0));
        if (cc.corners[1] == c.entity)
          out.push_back(face.boundary_uv(static_cast<LO>(l), static_cast<LO>(u), cc.t1));
      }
    }
  return out;
}

Vec2 nearest(const std::vector<Vec2>& images, const Vec2& ref) {
  Vec2 best = images.front();
  double d = std::numeric_limits<double>::max();
  for (const Vec2& x : images) {
    const double e = (x.u - ref.u) * (x.u - ref.u) + (x.v - ref.v) * (x.v - ref.v);
    if (e < d) {
      d = e;
      best = x;
    }
  }
  return best;
}

}  // namespace

bool quad9_valid(const std::array<Vec3, 9>& q, const Vec3& normal) {
  // Node (a, b) in {-1, 0, 1}^2 of each of the 9 nodes, and the 1D quadratic Lagrange basis.
  static constexpr std::array<std::array<int, 2>, 9> kAt{
      {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}, {0, -1}, {1, 0}, {0, 1}, {-1, 0}, {0, 0}}};
  auto l = [](int node, double s) {
    return node == -1 ? 0.5 * s * (s - 1) : (node == 0 ? 1 - s * s : 0.5 * s * (s + 1));
  };
  auto dl = [](int node, double s) {
    return node == -1 ? s - 0.5 : (node == 0 ? -2 * s : s + 0.5);
  };
  for (const auto& at : kAt) {
    const auto xi = static_cast<double>(at[0]), eta = static_cast<double>(at[1]);
    Vec3 dxi{}, deta{};
    for (std::size_t i = 0; i < 9; ++i) {
      dxi += q[i] * (dl(kAt[i][0], xi) * l(kAt[i][1], eta));
      deta += q[i] * (l(kAt[i][0], xi) * dl(kAt[i][1], eta));
    }
    if (!(dot(cross(dxi, deta), normal) > 0)) return false;
  }
  return true;
}

QuadraticReport make_quadratic(mesh::SurfaceMesh& m, const cad::CadModel& model,
                               const TaskArena& tasks) {
  QSMESH_CHECK(m.triangles.empty(), "second-order elements: the mesh has triangles");
  QSMESH_CHECK(m.quad_nodes.empty() && m.bar_nodes.empty(),
               "second-order elements: the mesh has them already");
  const GO nv = m.num_vertices();
  const auto nq = static_cast<GO>(m.quads.size());
  // Unique edges: the bars first (their curve), then the quads' (their face).
  std::unordered_map<std::uint64_t, GO> edge_of;
  std::vector<Edge> edges;
  m.bar_nodes.resize(m.bars.size());
  for (std::size_t b = 0; b < m.bars.size(); ++b) {
    const auto [it, fresh] = edge_of.try_emplace(mesh::edge_key(m.bars[b][0], m.bars[b][1]),
                                                 static_cast<GO>(edges.size()));
    if (fresh) edges.push_back({m.bars[b][0], m.bars[b][1], kNoIndex, m.bar_curve[b], -1});
    m.bar_nodes[b] = nv + it->second;
  }
  m.quad_nodes.resize(static_cast<std::size_t>(nq));
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
      m.quad_nodes[static_cast<std::size_t>(q)][static_cast<std::size_t>(k)] = nv + it->second;
    }
  }
  // The centres follow the edge nodes.
  const auto ne = static_cast<GO>(edges.size());
  for (GO q = 0; q < nq; ++q) m.quad_nodes[static_cast<std::size_t>(q)][4] = nv + ne + q;

  std::vector<Vec3> points(static_cast<std::size_t>(ne + nq));
  std::vector<mesh::VertexClass> vclass(points.size());
  std::vector<char> projected(points.size(), 1);

  // Edges on curves, by curve.
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
      const Vec3 straight = 0.5 * (pa + pb);
      Vec3 foot{};
      const double t = geom->project(straight, 0.5 * (ta + tb), &foot);
      auto& out = points[static_cast<std::size_t>(e)];
      auto& cl = vclass[static_cast<std::size_t>(e)];
      if (distance(foot, straight) <= distance(pa, pb)) {
        out = foot;
        cl = {1, c, kNoIndex, {t, 0}};
      } else {
        out = straight;
        cl = {1, c, kNoIndex, {0.5 * (ta + tb), 0}};
        projected[static_cast<std::size_t>(e)] = 0;
      }
    }
  });

  // Faces: their edge nodes, then their centres (which read the edge nodes of their quads, on
  // this face or on its curves, placed above).
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
    // projection lands further than `reach` from it.
    auto place = [&](std::size_t node, const Vec3& target, const Vec2& guess, double reach) {
      Vec3 foot{};
      const Vec2 uv = geom->project(target, guess, &foot);
      if (distance(foot, target) <= reach) {
        points[node] = foot;
        vclass[node] = {2, f, kNoIndex, {uv.u, uv.v}};
      } else {
        points[node] = target;
        vclass[node] = {2, f, kNoIndex, {guess.u, guess.v}};
        projected[node] = 0;
      }
    };
    for (GO e : face_edges[static_cast<std::size_t>(f)]) {
      const Edge& x = edges[static_cast<std::size_t>(e)];
      const Vec2 ref = reference(x.quad);
      const Vec2 ua = uv_near(x.a, ref), ub = uv_near(x.b, ref);
      const Vec3 pa = m.points[static_cast<std::size_t>(x.a)],
                 pb = m.points[static_cast<std::size_t>(x.b)];
      place(static_cast<std::size_t>(e), 0.5 * (pa + pb), 0.5 * (ua + ub), distance(pa, pb));
    }
    // Centres: the point the 8 boundary nodes predict, guessed at the mean (u, v) of the quad's
    // face edge nodes.
    for (GO q : face_quads[static_cast<std::size_t>(f)]) {
      const auto& quad = m.quads[static_cast<std::size_t>(q)];
      const auto& ho = m.quad_nodes[static_cast<std::size_t>(q)];
      Vec3 corners{}, mids{};
      Vec2 guess{0, 0};
      int guesses = 0;
      for (int k = 0; k < 4; ++k) {
        corners += m.points[static_cast<std::size_t>(quad[k])];
        const auto node = static_cast<std::size_t>(ho[static_cast<std::size_t>(k)] - nv);
        mids += points[node];
        if (vclass[node].dim == 2) {
          guess += Vec2{vclass[node].param[0], vclass[node].param[1]};
          ++guesses;
        }
      }
      guess = guesses > 0 ? guess / guesses : reference(q);
      place(static_cast<std::size_t>(ne + q), 0.5 * mids - 0.25 * corners, guess,
            distance(m.points[static_cast<std::size_t>(quad[0])],
                     m.points[static_cast<std::size_t>(quad[2])]));
    }
  });

  QuadraticReport report;

  // Validity: a curved quad that folds gets its face nodes back on the straight positions.
  auto node_point = [&](GO id) {
    return id < nv ? m.points[static_cast<std::size_t>(id)]
                   : points[static_cast<std::size_t>(id - nv)];
  };
  auto element = [&](GO q) {
    std::array<Vec3, 9> x{};
    const auto& quad = m.quads[static_cast<std::size_t>(q)];
    for (int k = 0; k < 4; ++k)
      x[static_cast<std::size_t>(k)] = m.points[static_cast<std::size_t>(quad[k])];
    for (std::size_t k = 0; k < 5; ++k)
      x[4 + k] = node_point(m.quad_nodes[static_cast<std::size_t>(q)][k]);
    return x;
  };
  // The normal SICN (Eq. 12) measures the linear quad against: the sum of its corner cross
  // products. A linear quad of positive SICN is then valid as a straight 9-node quad.
  auto linear_normal = [&](GO q) {
    const auto& quad = m.quads[static_cast<std::size_t>(q)];
    Vec3 n{};
    for (int k = 0; k < 4; ++k) {
      const Vec3& c = m.points[static_cast<std::size_t>(quad[k])];
      n += cross(m.points[static_cast<std::size_t>(quad[(k + 1) % 4])] - c,
                 m.points[static_cast<std::size_t>(quad[(k + 3) % 4])] - c);
    }
    return n;
  };
  // Puts the edge nodes of quad q (its face nodes only, or all of them) and its centre back on the
  // straight positions.
  auto straighten = [&](GO q, bool curve_nodes_too) {
    const auto& quad = m.quads[static_cast<std::size_t>(q)];
    for (int k = 0; k < 4; ++k) {
      const auto node = static_cast<std::size_t>(
          m.quad_nodes[static_cast<std::size_t>(q)][static_cast<std::size_t>(k)] - nv);
      if (vclass[node].dim != 2 && !curve_nodes_too) continue;
      points[node] = 0.5 * (m.points[static_cast<std::size_t>(quad[k])] +
                            m.points[static_cast<std::size_t>(quad[(k + 1) % 4])]);
      projected[node] = 0;
    }
    Vec3 centre{};
    for (GO v : quad) centre += m.points[static_cast<std::size_t>(v)];
    points[static_cast<std::size_t>(ne + q)] = 0.25 * centre;
    projected[static_cast<std::size_t>(ne + q)] = 0;
  };
  for (GO q = 0; q < nq; ++q) {
    if (quad9_valid(element(q), linear_normal(q))) continue;
    ++report.straightened;
    straighten(q, false);
  }
  // A quad still folded by its curve nodes (at a sharp CAD corner the curve bends across the
  // element) gets those straight too: its edge then leaves the curve between its ends.
  // Straightening a node changes the quads around it too, so this runs until no quad changes;
  // each quad goes straight once at most.
  if (report.straightened > 0) {
    std::vector<char> straight(static_cast<std::size_t>(nq), 0);
    for (bool changed = true; changed;) {
      changed = false;
      for (GO q = 0; q < nq; ++q) {
        if (straight[static_cast<std::size_t>(q)] || quad9_valid(element(q), linear_normal(q)))
          continue;
        straight[static_cast<std::size_t>(q)] = 1;
        changed = true;
        ++report.curve_straightened;
        straighten(q, true);
      }
    }
    for (GO q = 0; q < nq; ++q)
      if (!quad9_valid(element(q), linear_normal(q))) ++report.invalid;
  }

  // A node off its entity keeps the entity it belongs to (dim, id) but no parameters: a reader
  // that evaluated them would put it back on the CAD, curving the quad that had to go straight.
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (vclass[i].dim == 1)
      ++report.curve_nodes;
    else
      ++report.face_nodes;
    if (projected[i]) continue;
    ++report.unprojected;
    vclass[i].param = {std::numeric_limits<double>::quiet_NaN(),
                       std::numeric_limits<double>::quiet_NaN()};
  }

  m.points.insert(m.points.end(), points.begin(), points.end());
  m.vclass.insert(m.vclass.end(), vclass.begin(), vclass.end());
  return report;
}

}  // namespace qsmesh::highorder
