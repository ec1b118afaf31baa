#include "qsmesh/qstruct/patterns.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

#include "pattern_data.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::qstruct {

namespace {

LO find_root(std::vector<LO>& parent, LO a) {
  while (parent[a] != a) {
    parent[a] = parent[parent[a]];
    a = parent[a];
  }
  return a;
}

}  // namespace

Pattern make_pattern(std::string name, std::vector<Vec2> xy, std::vector<std::array<LO, 4>> quads) {
  Pattern p;
  p.name = std::move(name);
  p.xy = std::move(xy);
  p.quads = std::move(quads);
  const LO nv = p.num_vertices();
  const LO nq = static_cast<LO>(p.quads.size());
  QSMESH_CHECK(nv > 0 && nq > 0, "pattern " << p.name << ": no vertex or no quad");

  p.valence.assign(nv, 0);
  std::map<std::array<LO, 2>, LO> edge_id;
  // Per edge: uses, and the direction of its first use (orientation consistency).
  std::vector<int> uses;
  std::vector<std::array<LO, 2>> first_dir;
  p.quad_edges.resize(nq);
  for (LO q = 0; q < nq; ++q) {
    const auto& quad = p.quads[q];
    for (int k = 0; k < 4; ++k) {
      QSMESH_CHECK(quad[k] >= 0 && quad[k] < nv, "pattern " << p.name << ": quad " << q
                                                            << " has vertex " << quad[k]
                                                            << " out of range [0, " << nv << ")");
      for (int l = 0; l < k; ++l)
        QSMESH_CHECK(quad[k] != quad[l],
                     "pattern " << p.name << ": quad " << q << " repeats vertex " << quad[k]);
      ++p.valence[quad[k]];
    }
    for (int k = 0; k < 4; ++k) {
      const LO a = quad[k], b = quad[(k + 1) % 4];
      const std::array<LO, 2> key{std::min(a, b), std::max(a, b)};
      auto [it, added] = edge_id.emplace(key, static_cast<LO>(p.edges.size()));
      if (added) {
        p.edges.push_back(key);
        uses.push_back(0);
        first_dir.push_back({a, b});
      } else {
        QSMESH_CHECK(
            first_dir[it->second] != (std::array<LO, 2>{a, b}),
            "pattern " << p.name << ": edge " << a << "-" << b
                       << " used twice in one direction (quads not consistently oriented)");
      }
      QSMESH_CHECK(++uses[it->second] <= 2,
                   "pattern " << p.name << ": edge " << a << "-" << b << " in more than two quads");
      p.quad_edges[q][k] = it->second;
    }
  }
  const LO ne = static_cast<LO>(p.edges.size());
  QSMESH_CHECK(nv - ne + nq == 1, "pattern " << p.name << ": Euler characteristic " << nv - ne + nq
                                             << " (a pattern is a disk: 1)");

  // Boundary: the edges with one quad, in that quad's direction, so the interior is on the left.
  std::vector<LO> next(nv, kNoIndex), next_edge(nv, kNoIndex);
  LO boundary_edges = 0;
  for (LO e = 0; e < ne; ++e) {
    if (uses[e] != 1) continue;
    const auto [a, b] = first_dir[e];
    QSMESH_CHECK(next[a] == kNoIndex,
                 "pattern " << p.name << ": boundary vertex " << a << " is pinched");
    next[a] = b;
    next_edge[a] = e;
    ++boundary_edges;
  }
  LO start = kNoIndex;
  for (LO v = 0; v < nv && start == kNoIndex; ++v)
    if (next[v] != kNoIndex && p.valence[v] == 1) start = v;
  // A pattern without corner (a disk bounded by one smooth loop) is one side, starting at the
  // boundary vertex with the smallest id.
  for (LO v = 0; v < nv && start == kNoIndex; ++v)
    if (next[v] != kNoIndex) start = v;
  QSMESH_CHECK(start != kNoIndex, "pattern " << p.name << ": no boundary");
  for (LO v = start;;) {
    p.boundary.push_back(v);
    p.boundary_edge.push_back(next_edge[v]);
    v = next[v];
    QSMESH_CHECK(v != kNoIndex, "pattern " << p.name << ": open boundary");
    if (v == start) break;
    QSMESH_CHECK(static_cast<LO>(p.boundary.size()) < boundary_edges,
                 "pattern " << p.name << ": boundary is not a simple loop");
  }
  QSMESH_CHECK(static_cast<LO>(p.boundary.size()) == boundary_edges,
               "pattern " << p.name << ": boundary is not one loop (" << p.boundary.size() << " of "
                          << boundary_edges << " edges)");
  for (LO k = 0; k < static_cast<LO>(p.boundary.size()); ++k)
    if (p.valence[p.boundary[k]] == 1) p.side_start.push_back(k);
  if (p.side_start.empty()) p.side_start.push_back(0);

  // Chords: opposite edges of a quad belong to the same chord.
  std::vector<LO> parent(ne);
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& qe : p.quad_edges)
    for (int k = 0; k < 2; ++k) {
      const LO a = find_root(parent, qe[k]), b = find_root(parent, qe[k + 2]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  // Chords numbered in order of first appearance along the boundary, so that w reads like the
  // paper's systems (a, b, c, ... along side 1 first).
  // Closed chords (rings that reach no side, e.g. around the centre quad of the disk pattern)
  // come last: their columns of w are zero.
  std::vector<LO> root2chord(ne, kNoIndex);
  for (const LO e : p.boundary_edge) {
    const LO r = find_root(parent, e);
    if (root2chord[r] == kNoIndex) root2chord[r] = p.num_chords++;
  }
  p.edge_chord.resize(ne);
  for (LO e = 0; e < ne; ++e) {
    const LO r = find_root(parent, e);
    if (root2chord[r] == kNoIndex) root2chord[r] = p.num_chords++;
    p.edge_chord[e] = root2chord[r];
  }

  const int m = p.num_sides();
  p.w.assign(static_cast<std::size_t>(m) * p.num_chords, 0);
  for (int i = 0; i < m; ++i) {
    const LO end =
        i + 1 < m ? p.side_start[i + 1] : static_cast<LO>(p.boundary.size()) + p.side_start[0];
    for (LO k = p.side_start[i]; k < end; ++k) {
      const LO e = p.boundary_edge[k % static_cast<LO>(p.boundary.size())];
      ++p.w[static_cast<std::size_t>(i) * p.num_chords + p.edge_chord[e]];
    }
  }
  std::vector<char> on_boundary(nv, 0);
  for (const LO v : p.boundary) on_boundary[v] = 1;
  for (LO v = 0; v < nv; ++v)
    if (on_boundary[v] ? (p.valence[v] != 1 && p.valence[v] != 2) : p.valence[v] != 4)
      ++p.irregular;
  return p;
}

std::vector<Pattern> builtin_patterns() {
  std::vector<Pattern> out;
  for (const auto& raw : detail::raw_patterns()) {
    std::vector<Vec2> xy(raw.num_vertices);
    for (LO v = 0; v < raw.num_vertices; ++v) xy[v] = {raw.xy[2 * v], raw.xy[2 * v + 1]};
    std::vector<std::array<LO, 4>> quads(raw.num_quads);
    for (LO q = 0; q < raw.num_quads; ++q)
      quads[q] = {raw.quads[4 * q], raw.quads[4 * q + 1], raw.quads[4 * q + 2],
                  raw.quads[4 * q + 3]};
    out.push_back(make_pattern(raw.name, std::move(xy), std::move(quads)));
  }
  return out;
}

RefinedPattern refine_pattern(const Pattern& pattern, std::span<const LO> chords) {
  QSMESH_CHECK(static_cast<LO>(chords.size()) == pattern.num_chords,
               "pattern " << pattern.name << ": " << chords.size() << " chord subdivisions for "
                          << pattern.num_chords << " chords");
  for (const LO s : chords)
    QSMESH_CHECK(s >= 1, "pattern " << pattern.name << ": chord subdivision " << s);
  RefinedPattern r;
  r.num_vertices = pattern.num_vertices();
  r.coarse_vertex.resize(pattern.num_vertices());
  std::iota(r.coarse_vertex.begin(), r.coarse_vertex.end(), 0);

  // Vertices along each coarse edge, from its lower id to its higher id, edge e's at
  // along[first[e]] .. along[first[e + 1] - 1] (flat: this runs for every layout a search tries).
  std::vector<LO> first(pattern.edges.size() + 1, 0), along;
  for (std::size_t e = 0; e < pattern.edges.size(); ++e)
    first[e + 1] = first[e] + chords[pattern.edge_chord[e]] + 1;
  along.reserve(static_cast<std::size_t>(first.back()));
  for (std::size_t e = 0; e < pattern.edges.size(); ++e) {
    const LO s = chords[pattern.edge_chord[e]];
    along.push_back(pattern.edges[e][0]);
    for (LO t = 1; t < s; ++t) along.push_back(r.num_vertices++);
    along.push_back(pattern.edges[e][1]);
  }
  // Vertex t of the edge walked from a (t = 0) to b.
  const auto at = [&](LO e, LO a, LO t) {
    return a == pattern.edges[e][0] ? along[first[e] + t] : along[first[e + 1] - 1 - t];
  };

  std::size_t num_quads = 0;
  for (const auto& qe : pattern.quad_edges)
    num_quads += static_cast<std::size_t>(chords[pattern.edge_chord[qe[0]]]) *
                 static_cast<std::size_t>(chords[pattern.edge_chord[qe[1]]]);
  r.quads.reserve(num_quads);
  std::vector<LO> grid;
  for (std::size_t q = 0; q < pattern.quads.size(); ++q) {
    const auto& v = pattern.quads[q];
    const auto& qe = pattern.quad_edges[q];
    const LO n = chords[pattern.edge_chord[qe[0]]];  // along v0 -> v1 (and v3 -> v2)
    const LO m = chords[pattern.edge_chord[qe[1]]];  // along v1 -> v2 (and v0 -> v3)
    // Grid (i, k): (0,0) = v0, (n,0) = v1, (n,m) = v2, (0,m) = v3.
    grid.assign(static_cast<std::size_t>(n + 1) * (m + 1), 0);
    const auto id = [&](LO i, LO k) -> LO& {
      return grid[static_cast<std::size_t>(k) * (n + 1) + i];
    };
    for (LO i = 0; i <= n; ++i) {
      id(i, 0) = at(qe[0], v[0], i);
      id(i, m) = at(qe[2], v[3], i);  // edge 2 joins v2 and v3
    }
    for (LO k = 0; k <= m; ++k) {
      id(n, k) = at(qe[1], v[1], k);
      id(0, k) = at(qe[3], v[0], k);  // edge 3 joins v3 and v0
    }
    for (LO k = 1; k < m; ++k)
      for (LO i = 1; i < n; ++i) id(i, k) = r.num_vertices++;
    for (LO k = 0; k < m; ++k)
      for (LO i = 0; i < n; ++i)
        r.quads.push_back({id(i, k), id(i + 1, k), id(i + 1, k + 1), id(i, k + 1)});
  }

  const LO nb = static_cast<LO>(pattern.boundary.size());
  LO side = 0;
  for (LO k = 0; k < nb; ++k) {
    if (side < pattern.num_sides() && pattern.side_start[side] == k) {
      r.side_start.push_back(static_cast<LO>(r.boundary.size()));
      ++side;
    }
    const LO e = pattern.boundary_edge[k];
    const LO s = chords[pattern.edge_chord[e]];
    for (LO t = 0; t < s; ++t) r.boundary.push_back(at(e, pattern.boundary[k], t));
  }
  return r;
}

std::vector<std::vector<LO>> chord_moves(const Pattern& pattern) {
  const int rows = pattern.num_sides();
  const int cols = static_cast<int>(pattern.num_chords);
  // Reduced row echelon form of w in rationals (exact: w holds 0, 1, 2 and the patterns are
  // small, so doubles carry the fractions without rounding trouble at this size).
  std::vector<std::vector<double>> a(static_cast<std::size_t>(rows), std::vector<double>(cols));
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) a[i][j] = pattern.weight(i, j);
  std::vector<int> pivot_col;
  int r = 0;
  for (int j = 0; j < cols && r < rows; ++j) {
    int p = r;
    for (int i = r + 1; i < rows; ++i)
      if (std::abs(a[i][j]) > std::abs(a[p][j])) p = i;
    if (std::abs(a[p][j]) < 1e-9) continue;
    std::swap(a[p], a[r]);
    const double d = a[r][j];
    for (double& x : a[r]) x /= d;
    for (int i = 0; i < rows; ++i) {
      if (i == r || std::abs(a[i][j]) < 1e-12) continue;
      const double k = a[i][j];
      for (int jj = 0; jj < cols; ++jj) a[i][jj] -= k * a[r][jj];
    }
    pivot_col.push_back(j);
    ++r;
  }
  std::vector<char> is_pivot(static_cast<std::size_t>(cols), 0);
  for (const int j : pivot_col) is_pivot[j] = 1;
  std::vector<std::vector<LO>> out;
  for (int f = 0; f < cols; ++f) {
    if (is_pivot[f]) continue;
    std::vector<double> x(static_cast<std::size_t>(cols), 0.0);
    x[f] = 1;
    for (int i = 0; i < static_cast<int>(pivot_col.size()); ++i) x[pivot_col[i]] = -a[i][f];
    // Smallest multiplier making every entry an integer.
    for (int m = 1; m <= 64; ++m) {
      bool integral = true;
      for (const double v : x) integral = integral && std::abs(v * m - std::round(v * m)) < 1e-6;
      if (!integral) continue;
      std::vector<LO> v(static_cast<std::size_t>(cols));
      for (int j = 0; j < cols; ++j) v[j] = static_cast<LO>(std::lround(x[j] * m));
      out.push_back(std::move(v));
      break;
    }
  }
  return out;
}

}  // namespace qsmesh::qstruct
