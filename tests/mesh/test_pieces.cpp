// Cutting a face's quad mesh into pieces and putting them back (issue 28, mesh/pieces.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <set>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/pieces.hpp"

namespace qsmesh::mesh {
namespace {

// An nx x ny grid of quads on [0, nx] x [0, ny] (z = 0), uv = xy; the four corners dim 0, the
// other boundary vertices dim 1 (curve 0..3 by side), inside dim 2. The vertices are numbered
// in a scrambled order, so that face order and grid order differ.
FaceMesh grid(int nx, int ny) {
  const int nv = (nx + 1) * (ny + 1);
  std::vector<LO> id(static_cast<std::size_t>(nv));
  for (int k = 0; k < nv; ++k)
    id[static_cast<std::size_t>(k)] = static_cast<LO>((std::int64_t{k} * 7919) % nv);
  FaceMesh m;
  m.face = 3;
  m.points.resize(static_cast<std::size_t>(nv));
  m.uv.resize(static_cast<std::size_t>(nv));
  m.vclass.resize(static_cast<std::size_t>(nv));
  const auto at = [&](int i, int j) { return id[static_cast<std::size_t>(j * (nx + 1) + i)]; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const auto v = static_cast<std::size_t>(at(i, j));
      m.points[v] = {double(i), double(j), 0.0};
      m.uv[v] = {double(i), double(j)};
      const bool bx = i == 0 || i == nx, by = j == 0 || j == ny;
      if (bx && by)
        m.vclass[v] = {0, (i == 0 ? 0 : 1) + (j == 0 ? 0 : 2), kNoIndex, {0, 0}};
      else if (bx || by)
        m.vclass[v] = {1, j == 0 ? 0 : i == nx ? 1 : j == ny ? 2 : 3, by ? i : j, {0, 0}};
      else
        m.vclass[v] = {2, 3, kNoIndex, {double(i), double(j)}};
    }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      m.quads.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
  return m;
}

// The quads as sets of corner points, and the points used: what "the same mesh" means up to
// the numbering.
using Corners = std::array<std::array<double, 3>, 4>;
std::multiset<Corners> quads_by_points(const FaceMesh& m) {
  std::multiset<Corners> out;
  for (const auto& q : m.quads) {
    // Rotate so the smallest corner comes first: the same quad, whatever its first corner.
    std::array<std::array<double, 3>, 4> c{};
    for (int k = 0; k < 4; ++k) {
      const Vec3& p = m.points[static_cast<std::size_t>(q[static_cast<std::size_t>(k)])];
      c[static_cast<std::size_t>(k)] = {p.x, p.y, p.z};
    }
    const auto first = std::min_element(c.begin(), c.end()) - c.begin();
    std::rotate(c.begin(), c.begin() + first, c.end());
    out.insert(c);
  }
  return out;
}

TEST(Pieces, BisectionGivesBalancedDeterministicPieces) {
  const FaceMesh m = grid(40, 8);
  for (const LO k : {1, 2, 3, 5, 8}) {
    const std::vector<LO> part = bisect_quads(m, k, false);
    ASSERT_EQ(part.size(), m.quads.size());
    std::vector<int> count(static_cast<std::size_t>(k), 0);
    for (const LO p : part) {
      ASSERT_GE(p, 0);
      ASSERT_LT(p, k);
      ++count[static_cast<std::size_t>(p)];
    }
    const auto [lo, hi] = std::minmax_element(count.begin(), count.end());
    EXPECT_LE(*hi - *lo, 2) << k << " pieces";
    EXPECT_EQ(part, bisect_quads(m, k, false));
  }
}

// A square in 9 pieces is cut across both axes (strips would be 9 times longer than wide); a
// long grid in 8 pieces is cut into strips.
TEST(Pieces, StripsWhereThinEnoughElseBothAxes) {
  const auto spans_across = [](const FaceMesh& m, const std::vector<LO>& part, LO p) {
    double lo = 1e300, hi = -1e300;
    for (std::size_t q = 0; q < m.quads.size(); ++q)
      if (part[q] == p)
        for (const LO v : m.quads[q]) {
          lo = std::min(lo, m.points[static_cast<std::size_t>(v)].y);
          hi = std::max(hi, m.points[static_cast<std::size_t>(v)].y);
        }
    return hi - lo;
  };
  const FaceMesh square = grid(24, 24);
  const std::vector<LO> sq = bisect_quads(square, 9, false);
  int full = 0;
  for (LO p = 0; p < 9; ++p) full += spans_across(square, sq, p) == 24 ? 1 : 0;
  EXPECT_LT(full, 9);
  const FaceMesh strip = grid(96, 24);
  const std::vector<LO> st = bisect_quads(strip, 8, false);
  for (LO p = 0; p < 8; ++p) EXPECT_EQ(spans_across(strip, st, p), 24) << p;
}

// On a strip the shifted cuts fall halfway between the unshifted ones: 4 pieces of 10 columns
// cut at x = 10, 20, 30; shifted, 5 pieces cut at x = 5, 15, 25, 35.
TEST(Pieces, ShiftedBisectionCutsHalfwayOnAStrip) {
  const FaceMesh m = grid(40, 4);
  const auto cuts = [&](const std::vector<LO>& part) {
    std::set<double> xs;  // x of the vertical edges between quads of two pieces
    for (std::size_t q = 0; q + 1 < m.quads.size(); ++q) {
      const auto& a = m.quads[q];
      const double x = m.points[static_cast<std::size_t>(a[1])].x;
      if (x < 40 && part[q] != part[q + 1]) xs.insert(x);
    }
    return xs;
  };
  EXPECT_EQ(cuts(bisect_quads(m, 4, false)), (std::set<double>{10, 20, 30}));
  const std::vector<LO> shifted = bisect_quads(m, 4, true);
  EXPECT_EQ(*std::max_element(shifted.begin(), shifted.end()), 4);
  EXPECT_EQ(cuts(shifted), (std::set<double>{5, 15, 25, 35}));
}

TEST(Pieces, SplitThenMergeGivesTheSameMesh) {
  const FaceMesh m = grid(30, 12);
  const LO k = 6;
  const std::vector<LO> part = bisect_quads(m, k, false);
  const std::vector<FacePiece> pieces = split_face_mesh(m, part, k);
  ASSERT_EQ(pieces.size(), static_cast<std::size_t>(k));
  std::size_t quads = 0;
  std::map<LO, int> uses;  // face vertex -> pieces holding it
  for (const FacePiece& p : pieces) {
    quads += p.mesh.quads.size();
    ASSERT_EQ(p.vertex.size(), p.mesh.points.size());
    for (LO i = 0; i < p.mesh.num_vertices(); ++i) {
      const auto v = static_cast<std::size_t>(p.vertex[static_cast<std::size_t>(i)]);
      ++uses[p.vertex[static_cast<std::size_t>(i)]];
      EXPECT_EQ(p.mesh.points[static_cast<std::size_t>(i)], m.points[v]);
      const VertexClass& c = p.mesh.vclass[static_cast<std::size_t>(i)];
      // Fixed ones first, and only those: the face's boundary and the cut vertices.
      EXPECT_EQ(i < p.boundary, c.dim < 2) << "piece vertex " << i;
      // (no seam here: each cut vertex's own id)
      if (is_cut_vertex(c)) {
        EXPECT_EQ(c.entity, kCutEntity - static_cast<LO>(v));
      }
    }
  }
  EXPECT_EQ(quads, m.quads.size());
  // A vertex held by two pieces or more is a cut vertex in each of them.
  for (const FacePiece& p : pieces)
    for (LO i = 0; i < p.mesh.num_vertices(); ++i)
      EXPECT_EQ(is_cut_vertex(p.mesh.vclass[static_cast<std::size_t>(i)]),
                uses[p.vertex[static_cast<std::size_t>(i)]] > 1);

  std::vector<FaceMesh> same;
  same.reserve(pieces.size());
  for (const FacePiece& p : pieces) same.push_back(p.mesh);
  const FaceMesh merged = merge_face_pieces(m, pieces, same);
  EXPECT_EQ(merged.face, m.face);
  EXPECT_EQ(merged.num_vertices(), m.num_vertices());
  EXPECT_EQ(quads_by_points(merged), quads_by_points(m));
  // Every vertex comes back with its class in the face (cut vertices are interior again).
  std::map<std::array<double, 2>, VertexClass> cls;
  for (LO v = 0; v < m.num_vertices(); ++v)
    cls[{m.uv[static_cast<std::size_t>(v)].u, m.uv[static_cast<std::size_t>(v)].v}] =
        m.vclass[static_cast<std::size_t>(v)];
  for (LO v = 0; v < merged.num_vertices(); ++v) {
    const VertexClass& want = cls.at(
        {merged.uv[static_cast<std::size_t>(v)].u, merged.uv[static_cast<std::size_t>(v)].v});
    EXPECT_EQ(merged.vclass[static_cast<std::size_t>(v)].dim, want.dim);
    EXPECT_EQ(merged.vclass[static_cast<std::size_t>(v)].entity, want.entity);
  }
  // Quads keep the orientation: the signed area in uv stays positive.
  for (const auto& q : merged.quads) {
    double a = 0;
    for (int k2 = 0; k2 < 4; ++k2) {
      const Vec2& p = merged.uv[static_cast<std::size_t>(q[static_cast<std::size_t>(k2)])];
      const Vec2& r =
          merged.uv[static_cast<std::size_t>(q[static_cast<std::size_t>((k2 + 1) % 4)])];
      a += p.u * r.v - r.u * p.v;
    }
    EXPECT_GT(a, 0);
  }
}

// A piece's interior may be redone (vertices dropped, added, renumbered): the merge takes what
// it has. A moved cut vertex would tear the face open: the merge refuses it.
TEST(Pieces, MergeTakesNewInteriorsAndRefusesMovedCutVertices) {
  const FaceMesh m = grid(16, 8);
  const std::vector<LO> part = bisect_quads(m, 2, false);
  const std::vector<FacePiece> pieces = split_face_mesh(m, part, 2);
  std::vector<FaceMesh> out{pieces[0].mesh, pieces[1].mesh};
  // Piece 0: its interior vertices listed backwards (a renumbering of its own).
  FaceMesh& r = out[0];
  const LO nb = pieces[0].boundary;
  std::vector<LO> renumber(r.points.size());
  for (LO i = 0; i < r.num_vertices(); ++i)
    renumber[static_cast<std::size_t>(i)] = i < nb ? i : r.num_vertices() - 1 - (i - nb);
  FaceMesh back = r;
  for (LO i = 0; i < r.num_vertices(); ++i) {
    const auto to = static_cast<std::size_t>(renumber[static_cast<std::size_t>(i)]);
    back.points[to] = r.points[static_cast<std::size_t>(i)];
    back.uv[to] = r.uv[static_cast<std::size_t>(i)];
    back.vclass[to] = r.vclass[static_cast<std::size_t>(i)];
  }
  for (auto& q : back.quads)
    for (LO& v : q) v = renumber[static_cast<std::size_t>(v)];
  out[0] = back;
  const FaceMesh merged = merge_face_pieces(m, pieces, out);
  EXPECT_EQ(quads_by_points(merged), quads_by_points(m));

  LO cut = kNoIndex;
  for (LO i = 0; i < pieces[1].boundary; ++i)
    if (is_cut_vertex(pieces[1].mesh.vclass[static_cast<std::size_t>(i)])) cut = i;
  ASSERT_NE(cut, kNoIndex);
  out[1].points[static_cast<std::size_t>(cut)].y += 1e-12;
  EXPECT_THROW((void)merge_face_pieces(m, pieces, out), Error);
}

}  // namespace
}  // namespace qsmesh::mesh
