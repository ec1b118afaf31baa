#include "qsmesh/io/block_connections.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "detail.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/edges.hpp"

namespace qsmesh::io {

namespace {

// Where a side lies in the block's index space.
struct Side {
  int tangent;  // index (0: i, 1: j) that runs along the side
  bool at_max;  // the side is at the largest value of the other index
};
constexpr std::array<Side, 4> kSides{
    {{0, false}, {1, true}, {0, true}, {1, false}}};  // jmin imax jmax imin

// The 1-based (i, j) of position p on side s of block b.
std::array<std::int32_t, 2> side_index(const layout::Block& b, int s, LO p) {
  const Side& side = kSides[static_cast<std::size_t>(s)];
  std::array<std::int32_t, 2> ij{};
  ij[static_cast<std::size_t>(side.tangent)] = p + 1;
  const LO n = side.tangent == 0 ? b.nj : b.ni;  // the other index's cell count
  ij[static_cast<std::size_t>(1 - side.tangent)] = side.at_max ? n + 1 : 1;
  return ij;
}

GO side_vertex(const layout::Block& b, int s, LO p, const std::vector<GO>& vertices) {
  const auto ij = side_index(b, s, p);
  return b.vertex(ij[0] - 1, ij[1] - 1, vertices);
}

LO side_edges(const layout::Block& b, int s) {
  return kSides[static_cast<std::size_t>(s)].tangent == 0 ? b.ni : b.nj;
}

// The vertex range of edges p..q of side s of block b.
BlockRange side_range(const layout::Block& b, int s, LO p, LO q) {
  const auto a = side_index(b, s, p), c = side_index(b, s, q + 1);
  return {a[0], a[1], c[0], c[1]};
}

// Calls f(p, q, key) for every maximal run p..q of positions in [0, n) with the same key(x),
// other than kNoIndex.
template <typename Key, typename F>
void for_each_run(LO n, const Key& key, const F& f) {
  for (LO p = 0; p < n;) {
    const LO k = key(p);
    LO q = p;
    while (q + 1 < n && key(q + 1) == k) ++q;
    if (k != kNoIndex) f(p, q, k);
    p = q + 1;
  }
}

}  // namespace

std::string block_name(const layout::QuadLayout& layout, GO k, LO num_cad_faces) {
  const auto nb = static_cast<GO>(layout.blocks.size());
  const int width =
      std::max<int>(6, static_cast<int>(std::to_string(std::max<GO>(nb, num_cad_faces)).size()));
  auto padded = [width](GO x) {
    std::string t = std::to_string(x);
    return std::string(
               static_cast<std::size_t>(std::max<int>(0, width - static_cast<int>(t.size()))),
               '0') +
           t;
  };
  return "Block_" + padded(k) + "_Face_" + padded(layout.blocks[static_cast<std::size_t>(k)].face);
}

void check_layout_for_output(const mesh::SurfaceMesh& mesh, const layout::QuadLayout& layout,
                             const std::string& what) {
  for (const layout::Block& b : layout.blocks) {
    QSMESH_CHECK(b.ni > 0 && b.nj > 0 && b.face >= 0 && b.face < mesh.num_cad_faces &&
                     b.first >= 0 &&
                     b.first + static_cast<std::int64_t>(b.ni + 1) * (b.nj + 1) <=
                         static_cast<std::int64_t>(layout.vertices.size()),
                 what << ": a block does not fit the layout's arrays");
  }
  for (GO v : layout.vertices)
    QSMESH_CHECK(v >= 0 && v < mesh.num_vertices(), what << ": vertex " << v << " out of range");
  for (LO f : layout.unblocked_faces)
    QSMESH_CHECK(f >= 0 && f < mesh.num_cad_faces,
                 what << ": left-out face " << f << " out of range");
}

BlockConnections block_connections(const mesh::SurfaceMesh& mesh,
                                   const layout::QuadLayout& layout) {
  check_layout_for_output(mesh, layout, "block connections");
  const auto nb = static_cast<GO>(layout.blocks.size());

  // Block sides sharing a mesh edge: edge -> (block, side, position along the side).
  struct Use {
    GO block;
    int side;
    LO p;
  };
  std::unordered_map<std::uint64_t, std::vector<Use>> edge_uses;
  using mesh::edge_key;
  for (GO k = 0; k < nb; ++k) {
    const layout::Block& b = layout.blocks[static_cast<std::size_t>(k)];
    for (int s = 0; s < 4; ++s)
      for (LO p = 0; p < side_edges(b, s); ++p)
        edge_uses[edge_key(side_vertex(b, s, p, layout.vertices),
                           side_vertex(b, s, p + 1, layout.vertices))]
            .push_back({k, s, p});
  }

  // The element edges of the faces left out: where blocks abut them.
  const detail::ElementGroups groups = detail::group_elements(mesh);
  std::unordered_set<std::uint64_t> unstructured_edges;
  {
    auto element = [&](const auto& vertices) {
      const std::size_t n = vertices.size();
      for (std::size_t i = 0; i < n; ++i)
        unstructured_edges.insert(edge_key(vertices[i], vertices[(i + 1) % n]));
    };
    for (LO f : layout.unblocked_faces) {
      for (GO t : groups.face2tris[static_cast<std::size_t>(f)])
        element(mesh.triangles[static_cast<std::size_t>(t)]);
      for (GO q : groups.face2quads[static_cast<std::size_t>(f)])
        element(mesh.quads[static_cast<std::size_t>(q)]);
    }
  }
  // Which block sides a side edge is joined to. On a CAD curve: every other block side along it;
  // where three or more faces border the curve (non-manifold), every pair of sides at the edge is
  // thus joined, once each way. Off the curves only sides of the same face: two faces on one
  // surface with one boundary (a face given twice) may have edges between the same boundary
  // vertices, but they meet on their curves only.
  // A block of the coarse layout may span faces joined across smooth curves: the face of a side
  // edge off the curves is that of the block's quad along it (found through quad2block), not the
  // block's first face.
  std::unordered_map<std::uint64_t, std::vector<GO>> side_quads;  // side edge -> quads with it
  if (layout.quad2block.size() == mesh.quads.size())
    for (std::size_t q = 0; q < mesh.quads.size(); ++q) {
      const auto& quad = mesh.quads[q];
      for (std::size_t c = 0; c < 4; ++c) {
        const auto it = edge_uses.find(edge_key(quad[c], quad[(c + 1) % 4]));
        if (it != edge_uses.end()) side_quads[it->first].push_back(static_cast<GO>(q));
      }
    }
  auto face_at = [&](GO k, std::uint64_t e) {
    const auto it = side_quads.find(e);
    if (it != side_quads.end())
      for (GO q : it->second)
        if (layout.quad2block[static_cast<std::size_t>(q)] == k)
          return mesh.quad_face[static_cast<std::size_t>(q)];
    return layout.blocks[static_cast<std::size_t>(k)].face;
  };
  const std::unordered_map<std::uint64_t, LO> edge_curve = mesh::bar_curves(mesh);
  auto joins = [&](GO k, std::uint64_t e, const Use& u) {
    return edge_curve.count(e) > 0 || face_at(u.block, e) == face_at(k, e);
  };
  auto abuts_unstructured = [&](std::uint64_t e) {
    return edge_curve.count(e) > 0 && unstructured_edges.count(e) > 0;
  };
  // A block edge (of block k, at side s, position p) is free (a BC) when no other block side it
  // joins and no element of the unstructured part has it.
  auto is_free = [&](GO k, int s, LO p, std::uint64_t e) {
    for (const Use& u : edge_uses.at(e))
      if (!(u.block == k && u.side == s && u.p == p) && joins(k, e, u)) return false;
    return !abuts_unstructured(e);
  };

  BlockConnections out;
  out.blocks.resize(static_cast<std::size_t>(nb));
  for (GO k = 0; k < nb; ++k) {
    const layout::Block& b = layout.blocks[static_cast<std::size_t>(k)];
    BlockLinks& links = out.blocks[static_cast<std::size_t>(k)];
    for (int s = 0; s < 4; ++s) {
      auto edge_at = [&](LO q) {
        return edge_key(side_vertex(b, s, q, layout.vertices),
                        side_vertex(b, s, q + 1, layout.vertices));
      };
      // 1-to-1 interfaces: maximal runs of side edges shared with the same side of the same
      // block, the donor positions moving by one edge per edge.
      struct Run {
        GO block;
        int side;
        LO p0, p1;  // this side's edges p0..p1
        LO d0, d1;  // the donor side's edges matching p0 and p1
      };
      std::vector<Run> open, done;
      for (LO p = 0; p < side_edges(b, s); ++p) {
        std::vector<Run> next;
        const std::uint64_t e = edge_at(p);
        for (const Use& u : edge_uses.at(e)) {
          // The edge itself; another position of this same side (a side running along both
          // banks of a seam) is an interface of the block with itself.
          if ((u.block == k && u.side == s && u.p == p) || !joins(k, e, u)) continue;
          auto it = std::find_if(open.begin(), open.end(), [&](const Run& r) {
            if (r.block != u.block || r.side != u.side || r.p1 != p - 1) return false;
            const LO step = r.p1 > r.p0 ? (r.d1 - r.d0) / (r.p1 - r.p0) : u.p - r.d1;
            return (step == 1 || step == -1) && u.p == r.d1 + step;
          });
          if (it != open.end()) {
            Run r = *it;
            r.p1 = p;
            r.d1 = u.p;
            open.erase(it);
            next.push_back(r);
          } else {
            next.push_back({u.block, u.side, p, p, u.p, u.p});
          }
        }
        for (const Run& r : open) done.push_back(r);
        open.swap(next);
      }
      for (const Run& r : open) done.push_back(r);
      std::sort(done.begin(), done.end(), [](const Run& x, const Run& y) {
        return std::tie(x.p0, x.block, x.side) < std::tie(y.p0, y.block, y.side);
      });
      for (const Run& r : done) {
        const layout::Block& d = layout.blocks[static_cast<std::size_t>(r.block)];
        // Vertex ends: this side's p0 and p1 + 1; the donor's are whichever end of its matching
        // edges carries the same vertex.
        const GO first_vertex = side_vertex(b, s, r.p0, layout.vertices);
        const LO dir =
            r.p1 > r.p0 ? (r.d1 - r.d0) / (r.p1 - r.p0)
                        : (side_vertex(d, r.side, r.d0, layout.vertices) == first_vertex ? 1 : -1);
        const LO dv0 = dir > 0 ? r.d0 : r.d0 + 1;
        const LO dv1 = dir > 0 ? r.d1 + 1 : r.d1;
        QSMESH_CHECK(side_vertex(d, r.side, dv0, layout.vertices) == first_vertex &&
                         side_vertex(d, r.side, dv1, layout.vertices) ==
                             side_vertex(b, s, r.p1 + 1, layout.vertices),
                     "block connections: blocks " << k << " and " << r.block
                                                  << " do not match along their interface");
        BlockInterface i;
        i.side = s;
        i.range = side_range(b, s, r.p0, r.p1);
        i.donor = r.block;
        i.donor_side = r.side;
        const auto j0 = side_index(d, r.side, dv0), j1 = side_index(d, r.side, dv1);
        i.donor_range = {j0[0], j0[1], j1[0], j1[1]};
        const Side& me = kSides[static_cast<std::size_t>(s)];
        const Side& them = kSides[static_cast<std::size_t>(r.side)];
        i.transform[static_cast<std::size_t>(me.tangent)] = dir * (them.tangent + 1);
        // Leaving this block across the side is entering the donor across its side.
        const int normal = 1 - me.tangent, donor_normal = 1 - them.tangent;
        i.transform[static_cast<std::size_t>(normal)] =
            (me.at_max == them.at_max ? -1 : 1) * (donor_normal + 1);
        links.interfaces.push_back(i);
      }
      for_each_run(
          side_edges(b, s), [&](LO q) { return abuts_unstructured(edge_at(q)) ? LO{0} : kNoIndex; },
          [&](LO p, LO q, LO) {
            BlockAbutment a;
            a.side = s;
            a.range = side_range(b, s, p, q);
            for (LO x = p; x <= q + 1; ++x) {
              a.ij.push_back(side_index(b, s, x));
              a.vertices.push_back(side_vertex(b, s, x, layout.vertices));
            }
            links.abutments.push_back(std::move(a));
          });
      // Free edges: one run per stretch of them on one curve.
      auto curve_of_free = [&](LO q) -> LO {
        const std::uint64_t e = edge_at(q);
        if (!is_free(k, s, q, e)) return kNoIndex;
        const auto it = edge_curve.find(e);
        return it == edge_curve.end() ? kNoIndex : it->second;
      };
      for_each_run(side_edges(b, s), curve_of_free, [&](LO p, LO q, LO c) {
        links.boundaries.push_back({s, side_range(b, s, p, q), c});
      });
    }
  }
  return out;
}

}  // namespace qsmesh::io
