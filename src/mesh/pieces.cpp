#include "qsmesh/mesh/pieces.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <map>
#include <numeric>
#include <tuple>

#include "qsmesh/core/error.hpp"

namespace qsmesh::mesh {

namespace {

// Equal bit for bit (-0 and 0 differ; no tolerance).
bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

double coord(const Vec3& p, int axis) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; }

// Leaves [leaf, leaf + share.size()) for the quads `ids` (any order; reordered in place).
// The pieces of a strip (every cut across one axis) may be this many times longer across than
// along it. Cuts across one axis never cross, so the second cut's pieces hold each first cut
// whole; where cuts of two axes cross, a few first-cut vertices lie on a second cut too and keep
// what the first pass left. A 100 x 20 plate of 217k quads, 161 interior irregular vertices
// whole: in 12 strips 165; in 12 pieces cut across both axes 183; in 23 strips (aspect 4.6) 206,
// in 23 pieces across both axes 261.
constexpr double kMaxStripAspect = 8.0;

// Bounding box extents of the centroids of `ids` along x, y, z.
std::array<double, 3> extents(const std::vector<Vec3>& centroid, std::span<const LO> ids) {
  Vec3 lo = centroid[static_cast<std::size_t>(ids[0])], hi = lo;
  for (const LO q : ids) {
    const Vec3& c = centroid[static_cast<std::size_t>(q)];
    lo = {std::min(lo.x, c.x), std::min(lo.y, c.y), std::min(lo.z, c.z)};
    hi = {std::max(hi.x, c.x), std::max(hi.y, c.y), std::max(hi.z, c.z)};
  }
  return {hi.x - lo.x, hi.y - lo.y, hi.z - lo.z};
}

int longest(const std::array<double, 3>& e) {
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (e[static_cast<std::size_t>(a)] > e[static_cast<std::size_t>(axis)]) axis = a;
  return axis;
}

// Leaves [leaf, leaf + share.size()) for the quads `ids` (any order; reordered in place), cut
// across `strip_axis`, or across each set's longest extent when it is -1.
void bisect(const std::vector<Vec3>& centroid, std::span<LO> ids, std::span<const double> share,
            LO leaf, int strip_axis, std::vector<LO>& out) {
  if (share.size() == 1 || ids.empty()) {
    for (const LO q : ids) out[static_cast<std::size_t>(q)] = leaf;
    return;
  }
  const int axis = strip_axis >= 0 ? strip_axis : longest(extents(centroid, ids));
  const std::size_t m1 = share.size() / 2;
  const double left = std::accumulate(share.begin(), share.begin() + static_cast<long>(m1), 0.0);
  const double all = std::accumulate(share.begin(), share.end(), 0.0);
  const auto n1 =
      static_cast<std::size_t>(std::llround(static_cast<double>(ids.size()) * left / all));
  // A strict total order (coordinate, then id), so the first n1 quads are one set whatever the
  // algorithm leaves in the order of the others.
  const auto before = [&](LO a, LO b) {
    const double ca = coord(centroid[static_cast<std::size_t>(a)], axis);
    const double cb = coord(centroid[static_cast<std::size_t>(b)], axis);
    return ca != cb ? ca < cb : a < b;
  };
  if (n1 > 0 && n1 < ids.size())
    std::nth_element(ids.begin(), ids.begin() + static_cast<long>(n1), ids.end(), before);
  bisect(centroid, ids.first(n1), share.first(m1), leaf, strip_axis, out);
  bisect(centroid, ids.subspan(n1), share.subspan(m1), leaf + static_cast<LO>(m1), strip_axis, out);
}

}  // namespace

std::vector<Vec3> quad_centroids(const FaceMesh& m) {
  std::vector<Vec3> centroid(m.quads.size());
  for (std::size_t q = 0; q < m.quads.size(); ++q) {
    const auto& qd = m.quads[q];
    centroid[q] =
        (m.points[static_cast<std::size_t>(qd[0])] + m.points[static_cast<std::size_t>(qd[1])] +
         m.points[static_cast<std::size_t>(qd[2])] + m.points[static_cast<std::size_t>(qd[3])]) *
        0.25;
  }
  return centroid;
}

std::vector<LO> bisect_quads(const FaceMesh& m, LO k, bool shifted) {
  QSMESH_CHECK(k >= 1, "bisect_quads: " << k << " pieces");
  const std::size_t nq = m.quads.size();
  const std::vector<Vec3> centroid = quad_centroids(m);
  std::vector<double> share(static_cast<std::size_t>(k) + (shifted ? 1 : 0), 1.0);
  if (shifted) share.front() = share.back() = 0.5;
  std::vector<LO> ids(nq);
  std::iota(ids.begin(), ids.end(), LO{0});
  std::vector<LO> leaf(nq, 0);
  // Strips across the face's longest extent when k of them are no more than kMaxStripAspect
  // times longer across than along (k, not k + 1: both cuts of a face take the same rule).
  int strip_axis = -1;
  if (nq > 0) {
    const std::array<double, 3> e = extents(centroid, ids);
    const int a = longest(e);
    double across = 0;
    for (int b = 0; b < 3; ++b)
      if (b != a) across = std::max(across, e[static_cast<std::size_t>(b)]);
    if (across * static_cast<double>(k) <= kMaxStripAspect * e[static_cast<std::size_t>(a)])
      strip_axis = a;
  }
  bisect(centroid, ids, share, 0, strip_axis, leaf);
  // Drop empty leaves.
  std::vector<LO> renumber(share.size(), kNoIndex);
  for (const LO l : leaf) renumber[static_cast<std::size_t>(l)] = 0;
  LO next = 0;
  for (LO& r : renumber)
    if (r == 0) r = next++;
  for (LO& l : leaf) l = renumber[static_cast<std::size_t>(l)];
  return leaf;
}

std::vector<FacePiece> split_face_mesh(const FaceMesh& m, std::span<const LO> quad_piece,
                                       LO pieces) {
  const LO nv = m.num_vertices();
  QSMESH_CHECK(m.triangles.empty(), "face " << m.face << ": only an all-quad mesh is split");
  QSMESH_CHECK(m.uv.size() == m.points.size() && m.vclass.size() == m.points.size(),
               "face " << m.face << ": points, uv and vclass sizes differ");
  QSMESH_CHECK(quad_piece.size() == m.quads.size(), "face " << m.face << ": " << quad_piece.size()
                                                            << " pieces for " << m.quads.size()
                                                            << " quads");
  QSMESH_CHECK(nv < (LO{1} << 30), "face " << m.face << ": too many vertices to cut");
  // The piece of each vertex's quads: kNoIndex none yet, -2 two or more (a cut vertex).
  constexpr LO kShared = -2;
  std::vector<LO> vpiece(static_cast<std::size_t>(nv), kNoIndex);
  for (std::size_t q = 0; q < m.quads.size(); ++q) {
    const LO p = quad_piece[q];
    QSMESH_CHECK(p >= 0 && p < pieces, "face " << m.face << ": quad " << q << " in piece " << p);
    for (const LO v : m.quads[q]) {
      LO& s = vpiece[static_cast<std::size_t>(v)];
      s = s == kNoIndex || s == p ? p : kShared;
    }
  }
  // The id in a cut vertex's entity: its own, or for the images of one seam vertex (same
  // (dim, entity, index) on the curve, two uv) the first image's, so that smoothing still sees
  // the seam (one key, two uv) inside a piece.
  std::vector<LO> cut_id(static_cast<std::size_t>(nv));
  std::map<std::tuple<int, LO, LO>, LO> first_image;
  for (LO v = 0; v < nv; ++v) {
    const VertexClass& c = m.vclass[static_cast<std::size_t>(v)];
    cut_id[static_cast<std::size_t>(v)] =
        c.dim == 2
            ? v
            : first_image
                  .emplace(std::make_tuple(int(c.dim), c.entity, c.dim == 1 ? c.index : kNoIndex),
                           v)
                  .first->second;
  }
  std::vector<FacePiece> out(static_cast<std::size_t>(pieces));
  // Each piece's own vertices (not cut ones): its dim < 2 ones first, then its interior, each in
  // face order.
  for (int pass = 0; pass < 2; ++pass)
    for (LO v = 0; v < nv; ++v) {
      const LO s = vpiece[static_cast<std::size_t>(v)];
      // Used by no quad (left to the merge, dim < 2, or dropped), or a cut vertex (below).
      if (s == kNoIndex || s == kShared) continue;
      if ((m.vclass[static_cast<std::size_t>(v)].dim < 2) != (pass == 0)) continue;
      out[static_cast<std::size_t>(s)].vertex.push_back(v);
    }
  std::vector<LO> local(static_cast<std::size_t>(nv), kNoIndex);  // in the vertex's piece
  // Cut vertices belong to several pieces: give each piece its copy as it meets them, in face
  // order (a quad sweep would order them by quads), among the boundary vertices. So the pieces'
  // boundary is collected per piece: a second sweep over the vertices per piece would cost
  // pieces x vertices, hence the per-piece lists built from the quads, then sorted.
  std::vector<std::vector<LO>> cuts(static_cast<std::size_t>(pieces));
  for (std::size_t q = 0; q < m.quads.size(); ++q)
    for (const LO v : m.quads[q])
      if (vpiece[static_cast<std::size_t>(v)] == kShared)
        cuts[static_cast<std::size_t>(quad_piece[q])].push_back(v);
  for (LO pi = 0; pi < pieces; ++pi) {
    FacePiece& p = out[static_cast<std::size_t>(pi)];
    std::vector<LO>& c = cuts[static_cast<std::size_t>(pi)];
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
    // Merge the piece's non-cut boundary vertices (already first, in face order) with its cut
    // vertices, in face order.
    std::size_t nb = 0;
    while (nb < p.vertex.size() && m.vclass[static_cast<std::size_t>(p.vertex[nb])].dim < 2) ++nb;
    std::vector<LO> order;  // face vertices: boundary and cut, then interior
    order.reserve(p.vertex.size() + c.size());
    std::merge(p.vertex.begin(), p.vertex.begin() + static_cast<long>(nb), c.begin(), c.end(),
               std::back_inserter(order));
    order.insert(order.end(), p.vertex.begin() + static_cast<long>(nb), p.vertex.end());
    FaceMesh pm;
    pm.face = m.face;
    pm.points.reserve(order.size());
    pm.uv.reserve(order.size());
    pm.vclass.reserve(order.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
      const auto v = static_cast<std::size_t>(order[i]);
      pm.points.push_back(m.points[v]);
      pm.uv.push_back(m.uv[v]);
      pm.vclass.push_back(
          vpiece[v] == kShared
              ? VertexClass{0, kCutEntity - cut_id[v], kNoIndex, {m.uv[v].u, m.uv[v].v}}
              : m.vclass[v]);
    }
    p.boundary = static_cast<LO>(nb + c.size());
    // Face vertex -> piece vertex, through `local` for the piece's own vertices and a lookup in
    // the sorted cut list for the shared ones.
    for (std::size_t i = 0; i < order.size(); ++i)
      if (vpiece[static_cast<std::size_t>(order[i])] != kShared)
        local[static_cast<std::size_t>(order[i])] = static_cast<LO>(i);
    const auto piece_vertex = [&](LO v) {
      if (vpiece[static_cast<std::size_t>(v)] != kShared) return local[static_cast<std::size_t>(v)];
      // Cut vertices sit among the first p.boundary entries of `order`, which is sorted there.
      const auto it = std::lower_bound(order.begin(), order.begin() + p.boundary, v);
      return static_cast<LO>(it - order.begin());
    };
    for (std::size_t q = 0; q < m.quads.size(); ++q)
      if (quad_piece[q] == pi) {
        const auto& qd = m.quads[q];
        pm.quads.push_back(
            {piece_vertex(qd[0]), piece_vertex(qd[1]), piece_vertex(qd[2]), piece_vertex(qd[3])});
      }
    p.mesh = std::move(pm);
    p.vertex = std::move(order);
  }
  return out;
}

FaceMesh merge_face_pieces(const FaceMesh& m, std::span<const FacePiece> pieces,
                           std::span<const FaceMesh> improved) {
  QSMESH_CHECK(pieces.size() == improved.size(), "face " << m.face << ": " << improved.size()
                                                         << " results for " << pieces.size()
                                                         << " pieces");
  const LO nv = m.num_vertices();
  // The face's vertices that come back: dim < 2 ones and those of the pieces' boundaries.
  std::vector<LO> merged(static_cast<std::size_t>(nv), kNoIndex);
  for (LO v = 0; v < nv; ++v)
    if (m.vclass[static_cast<std::size_t>(v)].dim < 2) merged[static_cast<std::size_t>(v)] = 0;
  for (const FacePiece& p : pieces)
    for (LO i = 0; i < p.boundary; ++i) merged[static_cast<std::size_t>(p.vertex[i])] = 0;
  FaceMesh out;
  out.face = m.face;
  for (LO v = 0; v < nv; ++v) {
    LO& id = merged[static_cast<std::size_t>(v)];
    if (id == kNoIndex) continue;
    id = out.num_vertices();
    out.points.push_back(m.points[static_cast<std::size_t>(v)]);
    out.uv.push_back(m.uv[static_cast<std::size_t>(v)]);
    out.vclass.push_back(m.vclass[static_cast<std::size_t>(v)]);
  }
  for (std::size_t pi = 0; pi < pieces.size(); ++pi) {
    const FacePiece& p = pieces[pi];
    const FaceMesh& r = improved[pi];
    QSMESH_CHECK(r.num_vertices() >= p.boundary && r.uv.size() == r.points.size() &&
                     r.vclass.size() == r.points.size() && r.triangles.empty(),
                 "face " << m.face << ": piece " << pi << " came back with " << r.num_vertices()
                         << " vertices for " << p.boundary << " fixed ones");
    std::vector<LO> to_out(r.points.size());
    for (LO i = 0; i < p.boundary; ++i) {
      const auto v = static_cast<std::size_t>(p.vertex[i]);
      const auto ri = static_cast<std::size_t>(i);
      // Bit for bit: the neighbouring piece holds the same vertex and must meet it exactly.
      QSMESH_CHECK(
          same_bits(r.points[ri].x, m.points[v].x) && same_bits(r.points[ri].y, m.points[v].y) &&
              same_bits(r.points[ri].z, m.points[v].z) && same_bits(r.uv[ri].u, m.uv[v].u) &&
              same_bits(r.uv[ri].v, m.uv[v].v) && r.vclass[ri].dim == p.mesh.vclass[ri].dim &&
              r.vclass[ri].entity == p.mesh.vclass[ri].entity,
          "face " << m.face << ": piece " << pi << " moved its fixed vertex " << i
                  << " (face vertex " << v << ")");
      to_out[ri] = merged[v];
    }
    for (std::size_t i = static_cast<std::size_t>(p.boundary); i < r.points.size(); ++i) {
      QSMESH_CHECK(r.vclass[i].dim == 2, "face " << m.face << ": piece " << pi
                                                 << " has a boundary vertex beyond its fixed ones");
      to_out[i] = out.num_vertices();
      out.points.push_back(r.points[i]);
      out.uv.push_back(r.uv[i]);
      out.vclass.push_back(r.vclass[i]);
    }
    for (const auto& q : r.quads)
      out.quads.push_back(
          {to_out[static_cast<std::size_t>(q[0])], to_out[static_cast<std::size_t>(q[1])],
           to_out[static_cast<std::size_t>(q[2])], to_out[static_cast<std::size_t>(q[3])]});
  }
  return out;
}

}  // namespace qsmesh::mesh
