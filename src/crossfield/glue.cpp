// Glued triangulation of a face (seams become interior) and its per-triangle frames.
#include <algorithm>
#include <map>
#include <tuple>

#include "internal.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::crossfield {

void glue_triangulation(const mesh::FaceMesh& background, FaceCrossField& cf) {
  const LO nv = background.num_vertices();
  QSMESH_CHECK(!background.triangles.empty(), "crossfield: face has no triangles");
  QSMESH_CHECK(static_cast<LO>(background.vclass.size()) == nv, "crossfield: vclass size mismatch");
  // Seam copies share their classification: the same corner, or the same vertex of the same curve.
  std::map<std::tuple<int, LO, LO>, LO> key2glued;
  cf.input2glued.assign(static_cast<std::size_t>(nv), kNoIndex);
  cf.points.clear();
  cf.vertex_dim.clear();
  for (LO i = 0; i < nv; ++i) {
    const auto& c = background.vclass[i];
    LO g = kNoIndex;
    if (c.dim == 0 || c.dim == 1) {
      const auto key = std::make_tuple(int(c.dim), c.entity, c.dim == 0 ? LO{0} : c.index);
      const auto [it, inserted] = key2glued.emplace(key, static_cast<LO>(cf.points.size()));
      g = it->second;
      if (!inserted) {
        cf.input2glued[i] = g;
        continue;
      }
    }
    g = static_cast<LO>(cf.points.size());
    cf.points.push_back(background.points[i]);
    cf.vertex_dim.push_back(c.dim);
    cf.input2glued[i] = g;
  }
  cf.triangles.clear();
  for (const auto& t : background.triangles) {
    const std::array<LO, 3> g{cf.input2glued[t[0]], cf.input2glued[t[1]], cf.input2glued[t[2]]};
    // A triangle collapsed by gluing has no area in 3D either; it carries no cross.
    if (g[0] == g[1] || g[1] == g[2] || g[2] == g[0]) continue;
    cf.triangles.push_back(g);
  }
  QSMESH_CHECK(!cf.triangles.empty(), "crossfield: every triangle collapsed by gluing");

  // Edges numbered in the order of their first appearance in the triangle list. The edges (a, b),
  // a < b, of each vertex a sit in a slot of a flat array sized by the half-edges leaving a: a
  // short linear scan finds an edge again (the balanced tree this replaces cost as much as the
  // rest of the stage on the large planar walls of a far-field box).
  const std::size_t nv_glued = cf.points.size();
  std::vector<LO> first(nv_glued + 1, 0);
  for (const auto& tri : cf.triangles)
    for (int k = 0; k < 3; ++k) ++first[std::min(tri[k], tri[(k + 1) % 3]) + 1];
  for (std::size_t v = 0; v < nv_glued; ++v) first[v + 1] += first[v];
  std::vector<LO> filled(nv_glued, 0);
  std::vector<LO> slot_edge(static_cast<std::size_t>(first[nv_glued]));
  cf.edges.clear();
  cf.tri2edges.assign(cf.triangles.size(), {kNoIndex, kNoIndex, kNoIndex});
  std::vector<int> count;
  for (std::size_t t = 0; t < cf.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      LO a = cf.triangles[t][k], b = cf.triangles[t][(k + 1) % 3];
      if (a > b) std::swap(a, b);
      const LO* begin = slot_edge.data() + first[a];
      const LO* end = begin + filled[a];
      const LO* it = std::find_if(begin, end, [&](LO e) { return cf.edges[e][1] == b; });
      LO e = 0;
      if (it != end) {
        e = *it;
      } else {
        e = static_cast<LO>(cf.edges.size());
        slot_edge[first[a] + filled[a]++] = e;
        cf.edges.push_back({a, b});
        count.push_back(0);
      }
      cf.tri2edges[t][k] = e;
      ++count[e];
    }
  }
  cf.boundary_edge.assign(cf.edges.size(), 0);
  // A non-manifold edge (3+ triangles, broken input) is treated as a boundary: aligned crosses.
  for (std::size_t e = 0; e < cf.edges.size(); ++e) cf.boundary_edge[e] = count[e] != 2 ? 1 : 0;
}

namespace detail {

Geometry compute_geometry(const FaceCrossField& cf) {
  Geometry g;
  const std::size_t nt = cf.triangles.size(), ne = cf.edges.size(), nv = cf.points.size();
  g.normal.resize(nt);
  g.xaxis.resize(nt);
  g.area.resize(nt);
  g.phi.resize(nt);
  g.corner.resize(nt);
  g.cot.resize(nt);
  g.edge2tris.assign(ne, {kNoIndex, kNoIndex});
  g.vertex_angle.assign(nv, 0.0);
  g.boundary_vertex.assign(nv, 0);
  Box3 box;
  for (const auto& p : cf.points) box.add(p);
  g.diagonal = box.diagonal();
  g.min_edge = 1e300;
  for (const auto& e : cf.edges)
    g.min_edge = std::min(g.min_edge, distance(cf.points[e[0]], cf.points[e[1]]));
  for (std::size_t e = 0; e < ne; ++e)
    if (cf.boundary_edge[e])
      g.boundary_vertex[cf.edges[e][0]] = g.boundary_vertex[cf.edges[e][1]] = 1;

  for (std::size_t t = 0; t < nt; ++t) {
    const auto& tri = cf.triangles[t];
    const Vec3 p[3] = {cf.points[tri[0]], cf.points[tri[1]], cf.points[tri[2]]};
    const Vec3 n = cross(p[1] - p[0], p[2] - p[0]);
    g.area[t] = 0.5 * norm(n);
    g.normal[t] = normalized(n);
    for (int k = 0; k < 3; ++k) {
      const LO e = cf.tri2edges[t][k];
      auto& slot = g.edge2tris[e];
      if (slot[0] == kNoIndex)
        slot[0] = static_cast<LO>(t);
      else if (slot[1] == kNoIndex)
        slot[1] = static_cast<LO>(t);
    }
    const auto dir = [&](int k) {
      const auto& e = cf.edges[cf.tri2edges[t][k]];
      return normalized(cf.points[e[1]] - cf.points[e[0]]);
    };
    g.xaxis[t] = dir(0);
    const Vec3 y = cross(g.normal[t], g.xaxis[t]);
    for (int k = 0; k < 3; ++k) {
      const Vec3 d = dir(k);
      g.phi[t][k] = std::atan2(dot(d, y), dot(d, g.xaxis[t]));
      const Vec3 a = p[(k + 1) % 3] - p[k], b = p[(k + 2) % 3] - p[k];
      const double s = norm(cross(a, b)), c = dot(a, b);
      g.corner[t][k] = std::atan2(s, c);
      // Zero-area triangles get no stiffness rather than infinite cotangents.
      g.cot[t][k] = s > 1e-300 ? c / s : 0.0;
      g.vertex_angle[tri[k]] += g.corner[t][k];
    }
  }
  return g;
}

}  // namespace detail
}  // namespace qsmesh::crossfield
