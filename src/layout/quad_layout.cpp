#include "qsmesh/layout/quad_layout.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <numeric>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "grid.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/edges.hpp"
#include "quad_topology.hpp"

namespace qsmesh::layout {

namespace {

// The edges are those of each face: a face given twice in the CAD (the same surface and boundary)
// may mesh an edge between the same two boundary vertices as its copy does, and each copy's
// blocks are cut along its own traces.
struct FaceEdge {
  std::uint64_t edge;  // mesh::edge_key
  LO face;
  bool operator==(const FaceEdge&) const = default;
};
struct FaceEdgeHash {
  std::size_t operator()(const FaceEdge& e) const {
    return std::hash<std::uint64_t>()(e.edge ^
                                      (static_cast<std::uint64_t>(e.face) * 0x9E3779B97F4A7C15ULL));
  }
};

struct EdgeInfo {
  std::array<GO, 2> quads{-1, -1};
  int count = 0;     // quads of the face using the edge (2 inside it; 1 on a free boundary)
  bool bar = false;  // on a CAD curve
  bool traced = false;
};

// A trace start: the edge (v, w) of face `face`.
struct Start {
  GO v, w;
  LO face;
  auto operator<=>(const Start&) const = default;
};

using detail::Grid;

class Layouter {
 public:
  explicit Layouter(const mesh::SurfaceMesh& m) : m_(m), nv_(m.num_vertices()), v2q_(m) {
    const auto nq = static_cast<GO>(m.quads.size());
    face_unblocked_.assign(static_cast<std::size_t>(std::max<LO>(m.num_cad_faces, 0)), 0);
    for (LO f : m.triangle_face) face_unblocked_[static_cast<std::size_t>(f)] = 1;
    edges_.reserve(static_cast<std::size_t>(2 * nq + m.bars.size()));
    for (GO q = 0; q < nq; ++q) {
      const auto& quad = m.quads[static_cast<std::size_t>(q)];
      for (int k = 0; k < 4; ++k) {
        EdgeInfo& e = edges_[edge(quad[k], quad[(k + 1) % 4], q)];
        if (e.count < 2) e.quads[static_cast<std::size_t>(e.count)] = q;
        ++e.count;
      }
    }
    const std::unordered_map<std::uint64_t, LO> on_curve = mesh::bar_curves(m);
    for (auto& [k, e] : edges_) e.bar = on_curve.count(k.edge) > 0;
  }

  /// 1 for the faces with triangles: they get no block.
  [[nodiscard]] const std::vector<char>& face_unblocked() const { return face_unblocked_; }

  [[nodiscard]] bool blocked_quad(GO q) const {
    return face_unblocked_[static_cast<std::size_t>(m_.quad_face[static_cast<std::size_t>(q)])] ==
           0;
  }

  // An edge inside a face that a trace may follow and a patch may be crossed through.
  [[nodiscard]] bool interior(const EdgeInfo& e) const {
    return !e.bar && e.count == 2 && blocked_quad(e.quads[0]) && blocked_quad(e.quads[1]);
  }

  [[nodiscard]] bool regular_interior(GO v) const {
    return m_.vclass[static_cast<std::size_t>(v)].dim == 2 && v2q_.valence(v) == 4;
  }

  // Trace starts (v, w) in their face: the edges leaving irregular interior vertices, and the
  // interior edges of the sides of other than two quads of CAD corners and curve vertices (poles
  // included: their fan is one side). Restricted to the faces in `faces` when given.
  [[nodiscard]] std::vector<Start> starts(const std::vector<char>* faces) const {
    std::vector<Start> out;
    for (GO v = 0; v < nv_; ++v) {
      const auto& c = m_.vclass[static_cast<std::size_t>(v)];
      const auto quads = v2q_[v];
      if (quads.empty() || (c.dim == 2 && quads.size() == 4)) continue;
      auto across = [&](GO w, GO q) -> GO {
        const EdgeInfo& e = edges_.at(edge(v, w, q));
        if (!interior(e)) return -1;
        return e.quads[0] == q ? e.quads[1] : e.quads[0];
      };
      for (const auto& [w, a, irregular_side] : detail::side_edges(m_, v, quads, across)) {
        if (c.dim == 2 || irregular_side) {
          const LO f = m_.quad_face[static_cast<std::size_t>(quads[a])];
          if (faces != nullptr && (*faces)[static_cast<std::size_t>(f)] == 0) continue;
          out.push_back({v, w, f});
        }
      }
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  // Runs the traces from `from`, all advancing one edge per round in order (see the header).
  void trace(const std::vector<Start>& from, bool motorcycle) {
    std::vector<char> reached(static_cast<std::size_t>(nv_), 0);
    struct State {
      GO prev, cur;
      LO face;
    };
    std::vector<State> live;
    for (const auto& [v, w, f] : from) {
      EdgeInfo& e = edges_.at({mesh::edge_key(v, w), f});
      if (motorcycle && e.traced) continue;
      e.traced = true;
      reached[static_cast<std::size_t>(v)] = 1;
      live.push_back({v, w, f});
    }
    std::vector<State> next;
    while (!live.empty()) {
      next.clear();
      for (State s : live) {
        if (!regular_interior(s.cur)) continue;
        if (motorcycle && reached[static_cast<std::size_t>(s.cur)]) continue;
        reached[static_cast<std::size_t>(s.cur)] = 1;
        const GO after = straight_on(s.cur, s.prev, s.face);
        EdgeInfo& e = edges_.at({mesh::edge_key(s.cur, after), s.face});
        if (!motorcycle && e.traced) continue;  // the rest of this line is traced already
        e.traced = true;
        next.push_back({s.cur, after, s.face});
      }
      live.swap(next);
    }
  }

  void clear_traces(const std::vector<char>& faces) {
    for (auto& [k, e] : edges_)
      if (faces[static_cast<std::size_t>(k.face)]) e.traced = false;
  }

  // Patches of the quads of the faces in `faces`, as grids appended to `out` in the order of their
  // smallest quad; returns the faces with a patch that is not a grid.
  std::vector<LO> patches(const std::vector<char>& faces, std::vector<Grid>& out) const {
    const auto nq = static_cast<GO>(m_.quads.size());
    std::vector<GO> patch(static_cast<std::size_t>(nq), -1);
    std::vector<LO> failed;
    std::vector<GO> members, stack;
    for (GO seed = 0; seed < nq; ++seed) {
      const LO f = m_.quad_face[static_cast<std::size_t>(seed)];
      if (patch[static_cast<std::size_t>(seed)] >= 0 || !faces[static_cast<std::size_t>(f)])
        continue;
      members.clear();
      stack.assign(1, seed);
      patch[static_cast<std::size_t>(seed)] = seed;
      while (!stack.empty()) {
        const GO q = stack.back();
        stack.pop_back();
        members.push_back(q);
        const auto& quad = m_.quads[static_cast<std::size_t>(q)];
        for (int k = 0; k < 4; ++k) {
          const EdgeInfo& e = edges_.at({mesh::edge_key(quad[k], quad[(k + 1) % 4]), f});
          if (!crossable(e)) continue;
          const GO other = e.quads[0] == q ? e.quads[1] : e.quads[0];
          if (patch[static_cast<std::size_t>(other)] >= 0) continue;
          patch[static_cast<std::size_t>(other)] = seed;
          stack.push_back(other);
        }
      }
      std::sort(members.begin(), members.end());
      if (auto g = grid(members, f)) {
        out.push_back(std::move(*g));
      } else {
        failed.push_back(f);
      }
    }
    std::sort(failed.begin(), failed.end());
    failed.erase(std::unique(failed.begin(), failed.end()), failed.end());
    return failed;
  }

 private:
  // The edge (a, b) in the face of quad q.
  [[nodiscard]] FaceEdge edge(GO a, GO b, GO q) const {
    return {mesh::edge_key(a, b), m_.quad_face[static_cast<std::size_t>(q)]};
  }

  [[nodiscard]] bool crossable(const EdgeInfo& e) const { return interior(e) && !e.traced; }

  [[nodiscard]] std::array<GO, 2> neighbours_in_quad(GO q, GO v) const {
    std::array<GO, 2> nb{};
    QSMESH_CHECK(detail::neighbours_in_quad(m_.quads[static_cast<std::size_t>(q)], v, nb),
                 "layout: vertex " << v << " not in quad " << q);
    return nb;
  }

  // At a valence-4 vertex c of face `face` reached from prev: the vertex across c on the same grid
  // line.
  [[nodiscard]] GO straight_on(GO c, GO prev, LO face) const {
    const EdgeInfo& e = edges_.at({mesh::edge_key(c, prev), face});
    std::array<GO, 3> side{prev, -1, -1};
    for (int s = 0; s < 2; ++s) {
      const auto n = neighbours_in_quad(e.quads[static_cast<std::size_t>(s)], c);
      side[static_cast<std::size_t>(s) + 1] = n[0] == prev ? n[1] : n[0];
    }
    for (GO q : v2q_[c])
      for (GO w : neighbours_in_quad(q, c))
        if (std::find(side.begin(), side.end(), w) == side.end()) return w;
    QSMESH_CHECK(false, "layout: no straight continuation at vertex " << c);
    return -1;
  }

  // The patch `members` (sorted quad ids) as an ni x nj grid; none when it is not one.
  [[nodiscard]] std::optional<Grid> grid(const std::vector<GO>& members, LO face) const {
    auto in_patch = [&](GO q) { return std::binary_search(members.begin(), members.end(), q); };
    auto across = [&](GO q, GO a, GO b) -> GO {  // the patch quad across edge (a, b) of q, or -1
      const EdgeInfo& e = edges_.at({mesh::edge_key(a, b), face});
      if (!crossable(e)) return -1;
      const GO other = e.quads[0] == q ? e.quads[1] : e.quads[0];
      return in_patch(other) ? other : -1;
    };
    auto g = detail::patch_grid(m_, members, face, across);
    if (g) g->quads = members;
    return g;
  }

  const mesh::SurfaceMesh& m_;
  GO nv_;
  std::vector<char> face_unblocked_;
  detail::VertexQuads v2q_;
  std::unordered_map<FaceEdge, EdgeInfo, FaceEdgeHash> edges_;
};

// Merges blocks of one face that share a whole side, not along a CAD curve, while any do: the
// union of two such grids is a grid. Blocks are visited in order and each merge keeps the lower
// index, so the result depends on the layout only.
void merge_blocks(std::vector<Grid>& grids, const mesh::SurfaceMesh& mesh) {
  const std::unordered_map<std::uint64_t, LO> on_curve = mesh::bar_curves(mesh);
  std::vector<char> alive(grids.size(), 1);
  auto side_key = [](const std::vector<GO>& seq) {
    return std::array<GO, 3>{seq.front(), seq.back(), static_cast<GO>(seq.size())};
  };
  for (bool changed = true; changed;) {
    changed = false;
    std::map<std::array<GO, 3>, std::vector<std::pair<std::size_t, int>>> sides;
    for (std::size_t k = 0; k < grids.size(); ++k)
      for (int s = 0; alive[k] && s < 4; ++s) sides[side_key(grids[k].side(s))].emplace_back(k, s);
    std::vector<char> touched(grids.size(), 0);
    for (std::size_t a = 0; a < grids.size(); ++a) {
      for (int s = 0; alive[a] && !touched[a] && s < 4; ++s) {
        const std::vector<GO> seq = grids[a].side(s);
        bool along_curve = false;
        for (std::size_t i = 0; i + 1 < seq.size(); ++i)
          along_curve = along_curve || on_curve.count(mesh::edge_key(seq[i], seq[i + 1])) > 0;
        // The partner's side runs the other way round: its key has the ends swapped.
        const auto it = sides.find({seq.back(), seq.front(), static_cast<GO>(seq.size())});
        if (along_curve || it == sides.end()) continue;
        for (const auto& [b, t] : it->second) {
          if (b == a || !alive[b] || touched[b] || grids[b].face != grids[a].face) continue;
          std::vector<GO> other = grids[b].side(t);
          std::reverse(other.begin(), other.end());
          if (other != seq) continue;
          Grid ga = grids[a], gb = std::move(grids[b]);
          for (int sa = s; sa != 1; sa = (sa + 3) % 4) ga.rotate();
          for (int sb = t; sb != 3; sb = (sb + 3) % 4) gb.rotate();
          Grid m{ga.face, ga.ni + gb.ni, ga.nj, {}, std::move(ga.quads)};
          m.v.resize(static_cast<std::size_t>(m.ni + 1) * static_cast<std::size_t>(m.nj + 1));
          for (LO j = 0; j <= m.nj; ++j)
            for (LO i = 0; i <= m.ni; ++i)
              m.v[static_cast<std::size_t>(j) * static_cast<std::size_t>(m.ni + 1) +
                  static_cast<std::size_t>(i)] = i <= ga.ni ? ga.at(i, j) : gb.at(i - ga.ni, j);
          m.quads.insert(m.quads.end(), gb.quads.begin(), gb.quads.end());
          grids[a] = std::move(m);
          alive[b] = 0;
          touched[a] = touched[b] = 1;
          changed = true;
          break;
        }
      }
    }
  }
  std::size_t kept = 0;
  for (std::size_t k = 0; k < grids.size(); ++k)
    if (alive[k] && kept++ != k) grids[kept - 1] = std::move(grids[k]);
  grids.resize(kept);
}

// The given blocks as grids with their quads, by face (faces with none: empty); a face keeps none
// unless its blocks cover its quads exactly once, each cell a quad of the face in its orientation
// (its vertices in the order of the quad, up to the starting one).
std::vector<std::vector<Grid>> given_grids(const mesh::SurfaceMesh& mesh,
                                           std::span<const GivenBlock> given) {
  const auto nf = static_cast<std::size_t>(std::max<LO>(mesh.num_cad_faces, 0));
  std::vector<std::vector<Grid>> out(nf);
  if (given.empty()) return out;
  std::vector<char> has(nf, 0);
  for (const GivenBlock& b : given) {
    QSMESH_CHECK(b.face >= 0 && static_cast<std::size_t>(b.face) < nf,
                 "layout: given block of unknown face " << b.face);
    has[static_cast<std::size_t>(b.face)] = 1;
  }
  // The quad of `face` whose vertex cycle is c, up to its starting vertex (its orientation
  // too); -1: none.
  const detail::VertexQuads v2q(mesh);
  const auto quad_of = [&](LO face, const std::array<GO, 4>& c) -> GO {
    for (const GO q : v2q[c[0]]) {
      if (mesh.quad_face[static_cast<std::size_t>(q)] != face) continue;
      const auto& qd = mesh.quads[static_cast<std::size_t>(q)];
      int k = 0;
      while (k < 4 && qd[k] != c[0]) ++k;
      if (k < 4 && qd[(k + 1) % 4] == c[1] && qd[(k + 2) % 4] == c[2] && qd[(k + 3) % 4] == c[3])
        return q;
    }
    return -1;
  };
  std::vector<GO> face_quads(nf, 0);
  for (const LO f : mesh.quad_face)
    if (has[static_cast<std::size_t>(f)]) ++face_quads[static_cast<std::size_t>(f)];
  std::vector<char> covered(mesh.quads.size(), 0), bad(nf, 0);
  for (LO t : mesh.triangle_face) bad[static_cast<std::size_t>(t)] = 1;  // no blocks there
  std::vector<GO> cells(nf, 0);
  for (const GivenBlock& b : given) {
    const auto f = static_cast<std::size_t>(b.face);
    if (b.ni < 1 || b.nj < 1 ||
        b.vertices.size() !=
            static_cast<std::size_t>(b.ni + 1) * static_cast<std::size_t>(b.nj + 1))
      bad[f] = 1;
    if (bad[f]) continue;
    Grid g{b.face, b.ni, b.nj, b.vertices, {}};
    for (LO j = 0; j < b.nj && !bad[f]; ++j)
      for (LO i = 0; i < b.ni && !bad[f]; ++i) {
        const GO q =
            quad_of(b.face, {g.at(i, j), g.at(i + 1, j), g.at(i + 1, j + 1), g.at(i, j + 1)});
        if (q < 0 || covered[static_cast<std::size_t>(q)]) {
          bad[f] = 1;
          break;
        }
        covered[static_cast<std::size_t>(q)] = 1;
        g.quads.push_back(q);
      }
    cells[f] += static_cast<GO>(g.quads.size());
    std::sort(g.quads.begin(), g.quads.end());
    out[f].push_back(std::move(g));
  }
  for (std::size_t f = 0; f < nf; ++f) {
    if (bad[f] || cells[f] != face_quads[f]) out[f].clear();
    // In the order of the traced ones: by their smallest quad.
    std::sort(out[f].begin(), out[f].end(),
              [](const Grid& a, const Grid& b) { return a.quads.front() < b.quads.front(); });
  }
  return out;
}

}  // namespace

QuadLayout extract_quad_layout(const mesh::SurfaceMesh& mesh, const LayoutOptions& options,
                               std::span<const GivenBlock> given) {
  QSMESH_CHECK(
      mesh.quad_face.size() == mesh.quads.size() && mesh.vclass.size() == mesh.points.size(),
      "layout: inconsistent mesh arrays");
  const auto nf = static_cast<std::size_t>(std::max<LO>(mesh.num_cad_faces, 0));
  Layouter layouter(mesh);
  std::vector<char> bad = layouter.face_unblocked();  // faces that get no block
  const std::vector<std::vector<Grid>> kept = given_grids(mesh, given);
  std::vector<char> faces(nf, 0);  // the faces traced
  for (std::size_t f = 0; f < nf; ++f) faces[f] = bad[f] || !kept[f].empty() ? 0 : 1;

  QuadLayout out;
  layouter.trace(layouter.starts(&faces), options.motorcycle);
  std::vector<Grid> grids;
  const std::vector<LO> failed = layouter.patches(faces, grids);
  std::vector<char> again(nf, 0);
  for (LO f : failed) again[static_cast<std::size_t>(f)] = 1;
  if (!failed.empty() && options.motorcycle) {
    // Those faces' first grids go; their traces are run again, extended.
    std::erase_if(grids,
                  [&](const Grid& g) { return again[static_cast<std::size_t>(g.face)] != 0; });
    layouter.clear_traces(again);
    layouter.trace(layouter.starts(&again), false);
    for (LO f : layouter.patches(again, grids)) bad[static_cast<std::size_t>(f)] = 1;
    out.faces_with_extended_traces = static_cast<LO>(failed.size());
  } else {
    for (LO f : failed) bad[static_cast<std::size_t>(f)] = 1;
  }
  std::erase_if(grids, [&](const Grid& g) { return bad[static_cast<std::size_t>(g.face)] != 0; });
  // By face; within a face the grids are already in the order of their smallest quad.
  std::stable_sort(grids.begin(), grids.end(),
                   [](const Grid& a, const Grid& b) { return a.face < b.face; });
  if (options.merge) merge_blocks(grids, mesh);
  // The given blocks join the traced ones, by face (a stable merge keeps each face's order).
  const auto traced = static_cast<std::ptrdiff_t>(grids.size());
  for (std::size_t f = 0; f < nf; ++f) {
    if (kept[f].empty()) continue;
    ++out.faces_with_given_blocks;
    grids.insert(grids.end(), kept[f].begin(), kept[f].end());
  }
  std::inplace_merge(grids.begin(), grids.begin() + traced, grids.end(),
                     [](const Grid& a, const Grid& b) { return a.face < b.face; });

  out.quad2block.assign(mesh.quads.size(), -1);
  for (Grid& g : grids) {
    for (GO q : g.quads)
      out.quad2block[static_cast<std::size_t>(q)] = static_cast<GO>(out.blocks.size());
    out.blocks.push_back({g.face, g.ni, g.nj, static_cast<std::int64_t>(out.vertices.size())});
    out.vertices.insert(out.vertices.end(), g.v.begin(), g.v.end());
  }
  for (std::size_t f = 0; f < nf; ++f)
    if (bad[f]) out.unblocked_faces.push_back(static_cast<LO>(f));
  return out;
}

}  // namespace qsmesh::layout
