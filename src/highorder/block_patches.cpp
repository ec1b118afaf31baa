#include "qsmesh/highorder/block_patches.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <unordered_map>
#include <vector>

#include "lagrange.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/edges.hpp"

namespace qsmesh::highorder {

namespace {

struct Sample {
  Vec3 p;
  mesh::VertexClass c;
  bool on_cad = true;
};

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

BlockPatchReport make_block_patches(const mesh::SurfaceMesh& fine, const layout::QuadLayout& layout,
                                    const cad::CadModel& model, int order,
                                    mesh::SurfaceMesh& patches) {
  QSMESH_CHECK(order >= kMinOrder && order <= kMaxOrder, "block patches: order "
                                                             << order << " out of [" << kMinOrder
                                                             << ", " << kMaxOrder << "]");
  QSMESH_CHECK(fine.order == 1, "block patches: the fine mesh is of order " << fine.order);
  const GO nvf = fine.num_vertices();
  for (GO v : layout.vertices)
    QSMESH_CHECK(v >= 0 && v < nvf,
                 "block patches: a block grid holds vertex " << v << " of " << nvf);
  const int n = order;
  const int np = n + 1;
  const int per_edge = n - 1;
  const int per_quad = np * np - 4;

  // The fine cells' faces, found by either diagonal; the fine edges on CAD curves.
  std::unordered_map<std::uint64_t, LO> cell_face, edge_curve;
  for (std::size_t q = 0; q < fine.quads.size(); ++q) {
    const auto& x = fine.quads[q];
    cell_face.emplace(mesh::edge_key(x[0], x[2]), fine.quad_face[q]);
    cell_face.emplace(mesh::edge_key(x[1], x[3]), fine.quad_face[q]);
  }
  for (std::size_t b = 0; b < fine.bars.size(); ++b)
    edge_curve.emplace(mesh::edge_key(fine.bars[b][0], fine.bars[b][1]), fine.bar_curve[b]);
  std::vector<std::unique_ptr<cad::FaceGeometry>> face_geoms(
      static_cast<std::size_t>(model.num_faces()));
  std::vector<std::unique_ptr<cad::CurveGeometry>> curve_geoms(
      static_cast<std::size_t>(model.num_curves()));
  auto face_geom = [&](LO f) -> const cad::FaceGeometry& {
    auto& g = face_geoms[static_cast<std::size_t>(f)];
    if (!g) g = model.face_geometry(f);
    return *g;
  };
  auto curve_geom = [&](LO c) -> const cad::CurveGeometry& {
    auto& g = curve_geoms[static_cast<std::size_t>(c)];
    if (!g) g = model.curve_geometry(c);
    return *g;
  };
  auto point = [&](GO v) { return fine.points[static_cast<std::size_t>(v)]; };
  auto vclass = [&](GO v) -> const mesh::VertexClass& {
    return fine.vclass[static_cast<std::size_t>(v)];
  };

  // `p`, the bilinear point (fx, fy) of the fine cell with corners `c` (block orientation), on face
  // f: projected from the bilinear interpolation of the corners' (u, v) images in f, or left where
  // it is (NaN parameters) when the foot lands further than the cell's diagonal.
  auto on_face = [&](LO f, const Vec3& p, const std::array<GO, 4>& c, double fx, double fy) {
    const cad::FaceGeometry& geom = face_geom(f);
    const double reach =
        std::max(distance(point(c[0]), point(c[2])), distance(point(c[1]), point(c[3])));
    Vec2 ref{};
    bool have_ref = false;
    for (GO v : c)
      if (!have_ref && vclass(v).dim == 2 && vclass(v).entity == f) {
        ref = {vclass(v).param[0], vclass(v).param[1]};
        have_ref = true;
      }
    std::array<Vec2, 4> uv{};
    for (std::size_t k = 0; k < 4; ++k) {
      const auto images = detail::uv_images(model, geom, f, vclass(c[k]));
      if (images.empty()) return Sample{p, {2, f, kNoIndex, {kNaN, kNaN}}, false};
      if (!have_ref) {
        ref = images.front();
        have_ref = true;
      }
      uv[k] = detail::nearest(images, ref);
    }
    const Vec2 guess = detail::bilinear(uv, fx, fy);
    Vec3 foot{};
    const Vec2 at = geom.project(p, guess, &foot);
    if (!(distance(foot, p) <= reach)) return Sample{p, {2, f, kNoIndex, {kNaN, kNaN}}, false};
    return Sample{foot, {2, f, kNoIndex, {at.u, at.v}}, true};
  };
  // `p`, at fraction fr of the fine edge a-b on curve c, projected on the curve.
  auto on_curve = [&](LO c, const Vec3& p, GO a, GO b, double fr) {
    const cad::CurveGeometry& geom = curve_geom(c);
    const cad::Curve& cc = model.curves()[static_cast<std::size_t>(c)];
    const bool ta = vclass(a).dim == 1 && vclass(a).entity == c;
    const bool tb = vclass(b).dim == 1 && vclass(b).entity == c;
    const double guess = ta && tb ? (1 - fr) * vclass(a).param[0] + fr * vclass(b).param[0]
                         : ta     ? vclass(a).param[0]
                         : tb     ? vclass(b).param[0]
                                  : 0.5 * (cc.t0 + cc.t1);
    Vec3 foot{};
    const double t = geom.project(p, guess, &foot);
    if (!(distance(foot, p) <= distance(point(a), point(b))))
      return Sample{p, {1, c, kNoIndex, {kNaN, 0}}, false};
    return Sample{foot, {1, c, kNoIndex, {t, 0}}, true};
  };

  auto grid = [&](const layout::Block& k, LO i, LO j) { return k.vertex(i, j, layout.vertices); };
  auto face_of_cell = [&](const layout::Block& k, LO i, LO j) {
    const auto it = cell_face.find(mesh::edge_key(grid(k, i, j), grid(k, i + 1, j + 1)));
    return it != cell_face.end() ? it->second : k.face;
  };
  auto cell = [&](const layout::Block& k, LO i, LO j) {
    return std::array<GO, 4>{grid(k, i, j), grid(k, i + 1, j), grid(k, i + 1, j + 1),
                             grid(k, i, j + 1)};
  };
  auto corners_of = [&](const std::array<GO, 4>& c) {
    return std::array<Vec3, 4>{point(c[0]), point(c[1]), point(c[2]), point(c[3])};
  };
  // The fine cell's normal (the sum of its corners' cross products, as the SICN's).
  auto cell_normal = [&](const std::array<GO, 4>& c) {
    Vec3 nrm{};
    for (std::size_t q = 0; q < 4; ++q)
      nrm += cross(point(c[(q + 1) % 4]) - point(c[q]), point(c[(q + 3) % 4]) - point(c[q]));
    return nrm;
  };
  // Node (a, b) of block k's patch: grid position (a ni / n, b nj / n), exact in integers.
  auto sample = [&](const layout::Block& k, int a, int b) {
    const std::int64_t xi = static_cast<std::int64_t>(a) * k.ni,
                       yi = static_cast<std::int64_t>(b) * k.nj;
    const auto ix = static_cast<LO>(xi / n), iy = static_cast<LO>(yi / n);
    const auto rx = static_cast<int>(xi % n), ry = static_cast<int>(yi % n);
    if (rx == 0 && ry == 0) {
      const GO v = grid(k, ix, iy);
      return Sample{point(v), vclass(v), true};
    }
    if (rx == 0 || ry == 0) {  // on a fine edge
      const GO a0 = grid(k, ix, iy), a1 = rx == 0 ? grid(k, ix, iy + 1) : grid(k, ix + 1, iy);
      const double fr = static_cast<double>(rx == 0 ? ry : rx) / n;
      const Vec3 p = (1 - fr) * point(a0) + fr * point(a1);
      if (const auto it = edge_curve.find(mesh::edge_key(a0, a1)); it != edge_curve.end())
        return on_curve(it->second, p, a0, a1, fr);
      // Inside the face: the cell on this edge's side within the block.
      const LO ci = std::min<LO>(ix, k.ni - 1), cj = std::min<LO>(iy, k.nj - 1);
      const double fx = static_cast<double>(ix - ci) + static_cast<double>(rx) / n,
                   fy = static_cast<double>(iy - cj) + static_cast<double>(ry) / n;
      return on_face(face_of_cell(k, ci, cj), p, cell(k, ci, cj), fx, fy);
    }
    const auto c = cell(k, ix, iy);
    const double fx = static_cast<double>(rx) / n, fy = static_cast<double>(ry) / n;
    return on_face(face_of_cell(k, ix, iy), detail::bilinear(corners_of(c), fx, fy), c, fx, fy);
  };

  patches = mesh::SurfaceMesh{};
  patches.order = n;
  mesh::copy_cad_topology(fine, patches);
  BlockPatchReport report;
  report.order = n;

  // Vertex ids: the CAD corners first (as in the fine mesh), then the other block corners.
  std::vector<GO> vertex_of(static_cast<std::size_t>(nvf), -1);
  auto add_vertex = [&](GO v) {
    GO& id = vertex_of[static_cast<std::size_t>(v)];
    if (id < 0) {
      id = patches.num_vertices();
      patches.points.push_back(point(v));
      patches.vclass.push_back(vclass(v));
    }
    return id;
  };
  const auto corners = static_cast<GO>(fine.num_cad_corners);
  bool corners_first = corners <= nvf;
  for (GO v = 0; v < corners && corners_first; ++v)
    corners_first = vclass(v).dim == 0 && vclass(v).entity == v;
  if (corners_first)
    for (GO v = 0; v < corners; ++v) add_vertex(v);
  for (const layout::Block& k : layout.blocks) {
    patches.quads.push_back({add_vertex(grid(k, 0, 0)), add_vertex(grid(k, k.ni, 0)),
                             add_vertex(grid(k, k.ni, k.nj)), add_vertex(grid(k, 0, k.nj))});
    patches.quad_face.push_back(face_of_cell(k, 0, 0));
  }

  auto add_node = [&](const Sample& s) {
    const GO id = patches.num_vertices();
    patches.points.push_back(s.p);
    patches.vclass.push_back(s.c);
    ++report.nodes;
    if (!s.on_cad) ++report.unprojected;
    return id;
  };
  // A side's nodes, made once: keyed by its end vertices and the middle of its fine path (two
  // sides may join the same two corners), stored from the smaller end.
  std::map<std::array<GO, 3>, GO> side_nodes;
  const auto walk = detail::side_walk(n);
  patches.quad_nodes.resize(patches.quads.size() * static_cast<std::size_t>(per_quad));
  for (std::size_t kb = 0; kb < layout.blocks.size(); ++kb) {
    const layout::Block& k = layout.blocks[kb];
    GO* out = patches.quad_nodes.data() + kb * static_cast<std::size_t>(per_quad);
    for (std::size_t side = 0; side < 4; ++side) {
      // The side's fine path from its first corner.
      std::vector<GO> path;
      const LO len = side % 2 == 0 ? k.ni : k.nj;
      for (LO s = 0; s <= len; ++s) {
        const LO i = side == 0 ? s : side == 1 ? k.ni : side == 2 ? k.ni - s : 0;
        const LO j = side == 0 ? 0 : side == 1 ? s : side == 2 ? k.nj : k.nj - s;
        path.push_back(grid(k, i, j));
      }
      const GO a = path.front(), b = path.back();
      const GO m0 = path[path.size() / 2], m1 = path[(path.size() - 1) / 2];
      const std::array<GO, 3> key{std::min(a, b), std::max(a, b), std::min(m0, m1)};
      // A side from a corner back to itself (a ring) is told apart by its direction.
      const bool forward = a < b || (a == b && path[1] <= path[path.size() - 2]);
      auto [it, fresh] = side_nodes.try_emplace(key, patches.num_vertices());
      if (fresh) {
        std::vector<Sample> made;
        for (int s = 1; s < n; ++s)
          made.push_back(
              sample(k, walk[side][0] + s * walk[side][2], walk[side][1] + s * walk[side][3]));
        if (!forward) std::reverse(made.begin(), made.end());
        for (const Sample& x : made) add_node(x);
        // Along one CAD curve: a bar of that curve.
        LO curve = kNoIndex;
        bool on_one_curve = true;
        for (std::size_t e = 0; e + 1 < path.size() && on_one_curve; ++e) {
          const auto c = edge_curve.find(mesh::edge_key(path[e], path[e + 1]));
          on_one_curve = c != edge_curve.end() && (curve == kNoIndex || c->second == curve);
          if (on_one_curve) curve = c->second;
        }
        if (on_one_curve && curve != kNoIndex) {
          patches.bars.push_back({vertex_of[static_cast<std::size_t>(std::min(a, b))],
                                  vertex_of[static_cast<std::size_t>(std::max(a, b))]});
          patches.bar_curve.push_back(curve);
          for (int s = 0; s < per_edge; ++s) patches.bar_nodes.push_back(it->second + s);
          ++report.curve_bars;
        }
      }
      for (int s = 0; s < per_edge; ++s) *out++ = it->second + (forward ? s : per_edge - 1 - s);
    }
    for (int bj = 1; bj < n; ++bj)
      for (int ai = 1; ai < n; ++ai) *out++ = add_node(sample(k, ai, bj));
  }
  report.patches = static_cast<std::int64_t>(patches.quads.size());

  // Validity along the fine cells' normals, and the distance to the fine mesh.
  const detail::QuadChecker checker(n);
  std::vector<Vec3> nodes(static_cast<std::size_t>(np * np));
  for (std::size_t kb = 0; kb < layout.blocks.size(); ++kb) {
    const layout::Block& k = layout.blocks[kb];
    std::array<Vec3, detail::kMaxNodes> g{};
    const GO* ho = patches.quad_nodes.data() + kb * static_cast<std::size_t>(per_quad);
    for (std::size_t c = 0; c < nodes.size(); ++c) {
      const GO id = c < 4 ? patches.quads[kb][c] : ho[c - 4];
      nodes[c] = patches.points[static_cast<std::size_t>(id)];
      g[checker.grid(c)] = nodes[c];
    }
    // The fine cell at reference position (s, t) of the block, and the position inside it.
    auto locate = [&](double s, double t, double& fx, double& fy) {
      const double x = s * k.ni, y = t * k.nj;
      const auto i = std::clamp<LO>(static_cast<LO>(std::floor(x)), 0, k.ni - 1);
      const auto j = std::clamp<LO>(static_cast<LO>(std::floor(y)), 0, k.nj - 1);
      fx = x - i;
      fy = y - j;
      return cell(k, i, j);
    };
    const bool ok = checker.valid_along(g, [&](int m1, int m2) {
      double fx = 0, fy = 0;
      return cell_normal(
          locate(static_cast<double>(m1) / (2 * n), static_cast<double>(m2) / (2 * n), fx, fy));
    });
    if (!ok) ++report.invalid;
    for (int b = 0; b < n; ++b)
      for (int a = 0; a < n; ++a) {
        const double s = (a + 0.5) / n, t = (b + 0.5) / n;
        const Vec3 x = lagrange_quad_point(n, nodes, s, t);
        double fx = 0, fy = 0;
        const auto c = locate(s, t, fx, fy);
        const Vec3 y = detail::bilinear(corners_of(c), fx, fy);
        // Across the fine surface only: the patch's parametrization is not the fine grid's, so the
        // two points at one reference position also differ along the surface.
        const Vec3 nrm = cell_normal(c);
        const double len = norm(nrm);
        const double d = len > 0 ? std::abs(dot(x - y, nrm)) / len : distance(x, y);
        report.max_deviation = std::max(report.max_deviation, d);
      }
  }
  return report;
}

}  // namespace qsmesh::highorder
