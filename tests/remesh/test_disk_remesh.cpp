#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepTools.hxx>
#include <TopoDS_Face.hxx>
#include <algorithm>
#include <gp_Pln.hxx>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <tuple>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/remesh/disk_remesh.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::remesh {
namespace {

Cavity interior_cavity(std::vector<int> out) {
  Cavity c;
  for (int o : out) {
    c.kind.push_back(VertexKind::interior);
    c.out_valence.push_back(o);
    c.ideal_valence.push_back(4);
    c.current_valence.push_back(o + 1);
  }
  return c;
}

// In-cavity valence at each cavity vertex under a replacement.
std::vector<int> in_valences(const DiskQuadTable& t, const Replacement& r, int b) {
  std::vector<int> in(b, 0);
  for (int k = 0; k < b; ++k) in[cavity_vertex(r, k, b)] = t.valences(r.entry)[k];
  return in;
}

TEST(DiskChoice, HexagonCavitiesPickTheEq15Optimum) {
  const DiskQuadTable t = DiskQuadTable::builtin();
  // Outside valences 2,3,3,2,3,3: two quads split along the diagonal 0-3 (inside 2,1,1,2,1,1)
  // make every total 4: I_r = 0, no interior vertex.
  {
    const Replacement r = best_replacement(t, interior_cavity({2, 3, 3, 2, 3, 3}), {});
    ASSERT_NE(r.entry, kNoIndex);
    EXPECT_EQ(r.irregularity, 0);
    EXPECT_EQ(r.num_interior, 0);
    EXPECT_EQ(in_valences(t, r, 6), (std::vector<int>{2, 1, 1, 2, 1, 1}));
  }
  // Outside 3,2,3,2,3,2: the three-quad fan (inside 1,2,1,2,1,2) gives totals 4 and one interior
  // vertex of valence 3: I_r = 1. The two-quad split leaves three totals at 3 or 5 (I_r = 3);
  // every other hexagon filling has at least two interior vertices away from 4.
  {
    const Replacement r = best_replacement(t, interior_cavity({3, 2, 3, 2, 3, 2}), {});
    ASSERT_NE(r.entry, kNoIndex);
    EXPECT_EQ(r.irregularity, 1);
    EXPECT_EQ(r.num_interior, 1);
    EXPECT_EQ(in_valences(t, r, 6), (std::vector<int>{1, 2, 1, 2, 1, 2}));
  }
  // Vertex 0 on a curve (ideal 2, no quad outside, 3 today): enforced, it must get exactly 2 quads
  // inside. The fan can only give it 2 as (2,1,2,1,2,1): totals 2,3,5,3,5,3 and the centre, I_r
  // = 6. The two-quad split (2,1,1,2,1,1) gives totals 2,3,4,4,4,3: I_r = 2. Entries with interior
  // vertices cost at least 2 there already, so the split wins (fewer vertices on a tie).
  {
    Cavity c = interior_cavity({3, 2, 3, 2, 3, 2});
    c.kind[0] = VertexKind::curve;
    c.ideal_valence[0] = 2;
    c.out_valence[0] = 0;
    c.current_valence[0] = 3;
    const Replacement r = best_replacement(t, c, {});
    ASSERT_NE(r.entry, kNoIndex);
    EXPECT_EQ(in_valences(t, r, 6), (std::vector<int>{2, 1, 1, 2, 1, 1}));
    EXPECT_EQ(r.irregularity, 2);
    EXPECT_EQ(r.num_interior, 0);
    // Relaxed (fixing a corner), the curve vertex may take 1..3 quads and Eq. 15 alone decides.
    ChoiceOptions relaxed;
    relaxed.enforce_up_to = VertexKind::corner;
    const Replacement free_choice = best_replacement(t, c, relaxed);
    EXPECT_LE(free_choice.irregularity, r.irregularity);
  }
  // No table entry has 14 boundary vertices.
  EXPECT_EQ(best_replacement(t, interior_cavity(std::vector<int>(14, 2)), {}).entry, kNoIndex);
}

TEST(DiskChoice, PlacedQuadsFollowTheCavityInBothDirections) {
  const DiskQuadTable t = DiskQuadTable::builtin();
  const std::vector<LO> cycle{10, 11, 12, 13, 14, 15, 16, 17};  // an octagon cavity
  for (LO e : t.with_boundary(8))
    for (int rot = 0; rot < 8; ++rot)
      for (bool rev : {false, true}) {
        const Replacement r{e, rot, rev, 0, t.interior_size(e)};
        const auto quads = place_replacement(t, r, cycle, 100);
        std::set<std::pair<LO, LO>> directed;
        for (const auto& q : quads)
          for (int k = 0; k < 4; ++k) ASSERT_TRUE(directed.emplace(q[k], q[(k + 1) % 4]).second);
        std::set<std::pair<LO, LO>> boundary;
        for (const auto& [a, c] : directed)
          if (!directed.count({c, a})) boundary.emplace(a, c);
        std::set<std::pair<LO, LO>> expected;
        for (int j = 0; j < 8; ++j) expected.emplace(cycle[j], cycle[(j + 1) % 8]);
        EXPECT_EQ(boundary, expected)
            << "entry " << e << " rotation " << rot << " reversed " << rev;
        // The in-valences the choice assumed are those of the placed quads.
        for (int k = 0; k < 8; ++k) {
          int in = 0;
          for (const auto& q : quads)
            in += std::count(q.begin(), q.end(), cycle[cavity_vertex(r, k, 8)]);
          EXPECT_EQ(in, t.valences(e)[k]);
        }
      }
}

TEST(DiskChoice, AllowedRanges) {
  const ChoiceOptions all;  // everything enforced
  EXPECT_TRUE(valence_allowed(VertexKind::interior, 4, 4, 3, all));
  EXPECT_TRUE(valence_allowed(VertexKind::interior, 4, 4, 5, all));
  EXPECT_FALSE(valence_allowed(VertexKind::interior, 4, 4, 6, all));
  EXPECT_FALSE(valence_allowed(VertexKind::interior, 4, 4, 2, all));
  EXPECT_TRUE(valence_allowed(VertexKind::interior, 4, 6, 6, all));  // kept, not created
  EXPECT_FALSE(valence_allowed(VertexKind::curve, 2, 2, 3, all));
  EXPECT_TRUE(valence_allowed(VertexKind::curve, 2, 3, 2, all));
  EXPECT_FALSE(valence_allowed(VertexKind::corner, 3, 2, 4, all));
  ChoiceOptions corners;
  corners.enforce_up_to = VertexKind::corner;  // fixing a corner: curve and interior relaxed
  EXPECT_TRUE(valence_allowed(VertexKind::interior, 4, 4, 6, corners));
  EXPECT_TRUE(valence_allowed(VertexKind::curve, 2, 2, 3, corners));
  EXPECT_FALSE(valence_allowed(VertexKind::corner, 3, 2, 4, corners));
}

// 6 x 6 plate in z = 0, u = x, v = y.
struct Plate {
  cad::CadModel model;
  std::unique_ptr<cad::FaceGeometry> geometry;
};

Plate load_plate() {
  const std::string path = qsmesh::test::tmp_dir() + "/remesh_plate.brep";
  const auto face =
      BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 0.0, 6.0, 0.0, 6.0).Face();
  if (!BRepTools::Write(face, path.c_str())) throw std::runtime_error("cannot write " + path);
  Plate p{cad::load_cad(path), nullptr};
  p.geometry = p.model.face_geometry(0);
  return p;
}

// Structured 6 x 6 grid of the plate, then the diagonal (2,2)-(3,3) of one quad collapsed to its
// midpoint: an interior vertex of valence 6 next to two of valence 3 (Fig. 8 of paper 000).
mesh::FaceMesh grid_collapsed(const cad::FaceGeometry& g, int ci, int cj, bool keep_at_corner);
mesh::FaceMesh grid_with_valence6(const cad::FaceGeometry& g) {
  return grid_collapsed(g, 2, 2, false);
}

constexpr int kN = 6;
LO grid_id(int i, int j) { return static_cast<LO>(j * (kN + 1) + i); }

// The (kN + 1)^2 vertices of the structured kN x kN grid of the plate, classified (corners 0-3,
// curves 0 bottom, 1 right, 2 top, 3 left), no quads yet.
mesh::FaceMesh plate_grid_vertices(const cad::FaceGeometry& g) {
  constexpr int N = kN;
  mesh::FaceMesh m;
  m.face = 0;
  for (int j = 0; j <= N; ++j)
    for (int i = 0; i <= N; ++i) {
      mesh::VertexClass c;
      const bool bi = i == 0 || i == N, bj = j == 0 || j == N;
      if (bi && bj) {
        c.dim = 0;
        c.entity = (j == 0 ? 0 : 2) + (i == 0 ? 0 : 1);
      } else if (bi || bj) {
        c.dim = 1;
        c.entity = bj ? (j == 0 ? 0 : 2) : (i == 0 ? 3 : 1);
        c.index = bj ? i : j;
        c.param = {static_cast<double>(bj ? i : j), 0};
      } else {
        c.entity = 0;
        c.param = {double(i), double(j)};
      }
      m.uv.push_back({double(i), double(j)});
      m.points.push_back(g.eval({double(i), double(j)}).p);
      m.vclass.push_back(c);
    }
  return m;
}

// The grid with the diagonal (ci, cj)-(ci+1, cj+1) of one quad collapsed: to its midpoint, or onto
// (ci, cj) kept in place when keep_at_corner.
mesh::FaceMesh grid_collapsed(const cad::FaceGeometry& g, int ci, int cj, bool keep_at_corner) {
  constexpr int N = kN;
  const auto id = grid_id;
  mesh::FaceMesh m = plate_grid_vertices(g);
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i)
      if (!(i == ci && j == cj))
        m.quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  const LO keep = id(ci, cj), gone = id(ci + 1, cj + 1);
  if (!keep_at_corner) {
    m.uv[keep] = {ci + 0.5, cj + 0.5};
    m.points[keep] = g.eval(m.uv[keep]).p;
    m.vclass[keep].param = {ci + 0.5, cj + 0.5};
  }
  for (auto& q : m.quads)
    for (LO& v : q)
      if (v == gone) v = keep;
  // Drop the merged vertex (ids above it shift down by one).
  m.points.erase(m.points.begin() + gone);
  m.uv.erase(m.uv.begin() + gone);
  m.vclass.erase(m.vclass.begin() + gone);
  for (auto& q : m.quads)
    for (LO& v : q)
      if (v > gone) --v;
  return m;
}

// The grid with its 2 x 2 block [1,3] x [0,2] remeshed so that the curve vertex (2,0) has a single
// quad, (1,0)-(2,0)-(3,0)-c1, flat at (2,0) (SICN 0), as a seam vertex next to a pole can end up;
// (1,0) and (3,0) get three quads each. Two interior vertices: c1 = (2, 0.6) (valence 3) and
// c2 = (2, 1.4) (vertex (2,1) moved).
mesh::FaceMesh grid_with_flat_curve_quad(const cad::FaceGeometry& g) {
  const auto id = grid_id;
  mesh::FaceMesh m = plate_grid_vertices(g);
  for (int j = 0; j < kN; ++j)
    for (int i = 0; i < kN; ++i)
      if (!(j < 2 && (i == 1 || i == 2)))
        m.quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  const LO c2 = id(2, 1);
  const auto place = [&](LO v, Vec2 uv) {
    m.uv[v] = uv;
    m.points[v] = g.eval(uv).p;
    m.vclass[v].param = {uv.u, uv.v};
  };
  place(c2, {2.0, 1.4});
  const auto c1 = static_cast<LO>(m.points.size());
  m.points.emplace_back();
  m.uv.emplace_back();
  m.vclass.push_back(m.vclass[c2]);
  place(c1, {2.0, 0.6});
  m.quads.push_back({id(1, 0), id(2, 0), id(3, 0), c1});
  m.quads.push_back({id(3, 0), id(3, 1), c2, c1});
  m.quads.push_back({id(3, 1), id(3, 2), id(2, 2), c2});
  m.quads.push_back({id(1, 0), c1, c2, id(1, 1)});
  m.quads.push_back({id(1, 1), c2, id(2, 2), id(1, 2)});
  return m;
}

std::vector<int> valences(const mesh::FaceMesh& m) {
  std::vector<int> val(m.num_vertices(), 0);
  for (const auto& q : m.quads)
    for (LO v : q) ++val[v];
  return val;
}

// CAD-classified (dim 0/1) vertices and their points: must come out bit-identical.
std::map<std::tuple<int, LO, LO>, std::tuple<double, double, double>> boundary(
    const mesh::FaceMesh& m) {
  std::map<std::tuple<int, LO, LO>, std::tuple<double, double, double>> b;
  for (LO v = 0; v < m.num_vertices(); ++v)
    if (m.vclass[v].dim != 2)
      b[{m.vclass[v].dim, m.vclass[v].entity, m.vclass[v].index}] = {m.points[v].x, m.points[v].y,
                                                                     m.points[v].z};
  return b;
}

double area_xy(const mesh::FaceMesh& m) {
  double a = 0;
  for (const auto& q : m.quads)
    for (int k = 0; k < 4; ++k) {
      const Vec3& p = m.points[q[k]];
      const Vec3& r = m.points[q[(k + 1) % 4]];
      a += 0.5 * (p.x * r.y - r.x * p.y);
    }
  return a;
}

TEST(DiskRemesh, RemovesAnInteriorValenceSixVertex) {
  const DiskQuadTable table = DiskQuadTable::builtin();
  const Plate plate = load_plate();
  const mesh::FaceMesh m = grid_with_valence6(*plate.geometry);
  {
    const auto val = valences(m);
    ASSERT_EQ(*std::max_element(val.begin(), val.end()), 6);
    for (const auto& q : m.quads)
      ASSERT_GT(mesh::quad_sicn({m.points[q[0]], m.points[q[1]], m.points[q[2]], m.points[q[3]]}),
                0);
  }
  const DiskRemeshOptions options;
  ASSERT_EQ(count_defects(m, options), 1);

  DiskRemeshStats stats;
  const mesh::FaceMesh out = remesh_disk_defects(m, *plate.geometry, table, options, &stats);
  EXPECT_EQ(stats.defects_before, 1);
  EXPECT_EQ(stats.defects_after, 0);
  EXPECT_GE(stats.replaced, 1);
  const auto val = valences(out);
  for (LO v = 0; v < out.num_vertices(); ++v) {
    EXPECT_GE(val[v], 1) << "orphan vertex " << v;
    if (out.vclass[v].dim == 2) {
      EXPECT_LE(val[v], 5) << "vertex " << v;
      EXPECT_GE(val[v], 3) << "vertex " << v;
    }
  }
  for (const auto& q : out.quads)
    EXPECT_GT(
        mesh::quad_sicn({out.points[q[0]], out.points[q[1]], out.points[q[2]], out.points[q[3]]}),
        0);
  EXPECT_EQ(boundary(out), boundary(m));
  EXPECT_NEAR(area_xy(out), 36.0, 1e-9);  // the quads still tile the plate, none reversed
  // A disk: V - E + F = 1.
  std::set<std::pair<LO, LO>> edges;
  for (const auto& q : out.quads)
    for (int k = 0; k < 4; ++k) edges.insert(std::minmax(q[k], q[(k + 1) % 4]));
  EXPECT_EQ(out.num_vertices() - static_cast<LO>(edges.size()) + static_cast<LO>(out.quads.size()),
            1);
  // Deterministic.
  const mesh::FaceMesh again = remesh_disk_defects(m, *plate.geometry, table, options);
  EXPECT_EQ(again.quads, out.quads);
}

TEST(DiskRemesh, FixesCurveVertices) {
  // Collapsing the quad [2,3]x[0,1] onto its curve corner (2,0): that curve vertex gets valence 4
  // and its neighbour (3,0) on the curve valence 1 (with a flat, SICN 0 corner): two curve defects.
  const DiskQuadTable table = DiskQuadTable::builtin();
  const Plate plate = load_plate();
  const mesh::FaceMesh m = grid_collapsed(*plate.geometry, 2, 0, true);
  const DiskRemeshOptions options;
  ASSERT_EQ(count_defects(m, options), 2);
  DiskRemeshStats stats;
  const mesh::FaceMesh out = remesh_disk_defects(m, *plate.geometry, table, options, &stats);
  EXPECT_EQ(stats.defects_after, 0);
  const auto val = valences(out);
  for (LO v = 0; v < out.num_vertices(); ++v) {
    if (out.vclass[v].dim == 1) {
      EXPECT_EQ(val[v], 2) << "curve vertex " << v;
    } else if (out.vclass[v].dim == 2) {
      EXPECT_TRUE(val[v] >= 3 && val[v] <= 5) << "vertex " << v;
    }
  }
  for (const auto& q : out.quads)
    EXPECT_GT(
        mesh::quad_sicn({out.points[q[0]], out.points[q[1]], out.points[q[2]], out.points[q[3]]}),
        0);
  EXPECT_EQ(boundary(out), boundary(m));
  EXPECT_NEAR(area_xy(out), 36.0, 1e-9);
}

TEST(DiskRemesh, CurveVertexWithOneQuadIsFixedByPriority) {
  // (2,0) has one quad spanning 180 degrees. No replacement lowers Eq. 15 (giving it a second quad
  // costs an interior vertex of valence 3 or 5), and its one-quad cavity has none giving it two:
  // the rule of Eq. 15 alone on the defect's own quads leaves the flat quad. Sec. 6.3.2's
  // priorities (curves before the interior) on the cavity grown around c1 fix it.
  const DiskQuadTable table = DiskQuadTable::builtin();
  const Plate plate = load_plate();
  const mesh::FaceMesh m = grid_with_flat_curve_quad(*plate.geometry);
  ASSERT_NEAR(area_xy(m), 36.0, 1e-9);
  const auto val_in = valences(m);
  ASSERT_EQ(val_in[grid_id(2, 0)], 1);
  DiskRemeshOptions options;
  ASSERT_EQ(count_defects(m, options), 3);
  const auto worst = [](const mesh::FaceMesh& mesh) {
    double w = 1;
    for (const auto& q : mesh.quads)
      w = std::min(w, mesh::quad_sicn({mesh.points[q[0]], mesh.points[q[1]], mesh.points[q[2]],
                                       mesh.points[q[3]]}));
    return w;
  };
  ASSERT_LT(worst(m), 1e-12);

  DiskRemeshStats stats;
  const mesh::FaceMesh out = remesh_disk_defects(m, *plate.geometry, table, options, &stats);
  EXPECT_EQ(stats.defects_after, 0);
  const auto val = valences(out);
  for (LO v = 0; v < out.num_vertices(); ++v)
    if (out.vclass[v].dim == 1) {
      EXPECT_EQ(val[v], 2) << "curve vertex " << v;
    }
  EXPECT_GT(worst(out), 0.3);
  EXPECT_EQ(boundary(out), boundary(m));
  EXPECT_NEAR(area_xy(out), 36.0, 1e-9);

  // Without the grown cavity and the priority rule, the flat quad stays.
  options.larger_cavity = false;
  options.force_below_sicn = 0;
  DiskRemeshStats old_stats;
  const mesh::FaceMesh old = remesh_disk_defects(m, *plate.geometry, table, options, &old_stats);
  EXPECT_GT(old_stats.defects_after, 0);
  EXPECT_LT(worst(old), 1e-12);
}

// Each cell of an n x n grid of the plate split into two triangles, each triangle into three quads
// (centroid and edge midpoints): every interior grid vertex has valence 6.
mesh::FaceMesh split_triangles(const cad::FaceGeometry& g, int n) {
  mesh::FaceMesh m;
  m.face = 0;
  const double h = 6.0 / n;
  std::map<std::pair<int, int>, LO> index;  // key: position in sixths of a cell
  auto vertex = [&](int a, int b) {
    const auto [it, fresh] = index.emplace(std::make_pair(a, b), m.num_vertices());
    if (fresh) {
      const Vec2 uv{a * h / 6, b * h / 6};
      mesh::VertexClass c;
      const bool ba = a == 0 || a == 6 * n, bb = b == 0 || b == 6 * n;
      if (ba && bb) {
        c = {0, (b == 0 ? 0 : 2) + (a == 0 ? 0 : 1), kNoIndex, {0, 0}};
      } else if (ba || bb) {
        c = {1, bb ? (b == 0 ? 0 : 2) : (a == 0 ? 3 : 1), bb ? a : b, {0, 0}};
      } else {
        c = {2, 0, kNoIndex, {uv.u, uv.v}};
      }
      m.uv.push_back(uv);
      m.points.push_back(g.eval(uv).p);
      m.vclass.push_back(c);
    }
    return it->second;
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::array<std::pair<int, int>, 4> c{
          {{6 * i, 6 * j}, {6 * i + 6, 6 * j}, {6 * i + 6, 6 * j + 6}, {6 * i, 6 * j + 6}}};
      for (const auto& tri : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
        const auto p0 = c[tri[0]], p1 = c[tri[1]], p2 = c[tri[2]];
        const LO centre =
            vertex((p0.first + p1.first + p2.first) / 3, (p0.second + p1.second + p2.second) / 3);
        std::array<LO, 3> corner{}, mid{};
        const std::array<std::pair<int, int>, 3> p{p0, p1, p2};
        for (int k = 0; k < 3; ++k) {
          corner[k] = vertex(p[k].first, p[k].second);
          mid[k] = vertex((p[k].first + p[(k + 1) % 3].first) / 2,
                          (p[k].second + p[(k + 1) % 3].second) / 2);
        }
        for (int k = 0; k < 3; ++k)
          m.quads.push_back({corner[k], mid[k], centre, mid[(k + 2) % 3]});
      }
    }
  return m;
}

TEST(DiskRemesh, ManyAdjacentDefects) {
  const DiskQuadTable table = DiskQuadTable::builtin();
  const Plate plate = load_plate();
  const mesh::FaceMesh m = split_triangles(*plate.geometry, 4);
  const DiskRemeshOptions options;
  const LO before = count_defects(m, options);
  // 9 interior grid vertices (valence 6), 12 curve grid vertices (3), 2 corners on a diagonal (2).
  ASSERT_EQ(before, 23);
  DiskRemeshStats stats;
  const mesh::FaceMesh out = remesh_disk_defects(m, *plate.geometry, table, options, &stats);
  std::cout << "defects " << stats.defects_before << " -> " << stats.defects_after << ", replaced "
            << stats.replaced << ", no candidate " << stats.no_candidate << ", rejected "
            << stats.rejected_geometry << ", skipped " << stats.skipped << "\n";
  EXPECT_LT(stats.defects_after, before);
  const auto val = valences(out);
  std::array<int, 3> left{};  // corners, curves, interior
  for (LO v = 0; v < out.num_vertices(); ++v)
    if ((out.vclass[v].dim == 2 && val[v] >= 6) || (out.vclass[v].dim == 1 && val[v] != 2))
      ++left[out.vclass[v].dim];
  std::cout << "left: curve " << left[1] << ", interior " << left[2] << "\n";
  EXPECT_EQ(left[2], 0);  // every valence-6 vertex removed
  for (const auto& q : out.quads)
    EXPECT_GT(
        mesh::quad_sicn({out.points[q[0]], out.points[q[1]], out.points[q[2]], out.points[q[3]]}),
        0);
  EXPECT_EQ(boundary(out), boundary(m));
  EXPECT_NEAR(area_xy(out), 36.0, 1e-9);
}

TEST(DiskRemesh, RollsBackWhenTheGeometryCheckFails) {
  const DiskQuadTable table = DiskQuadTable::builtin();
  const Plate plate = load_plate();
  const mesh::FaceMesh m = grid_with_valence6(*plate.geometry);
  DiskRemeshOptions options;
  options.min_sicn = 2.0;  // nothing reaches it (SICN <= 1), and no fallback to "not worse"
  options.accept_if_not_worse = false;
  DiskRemeshStats stats;
  const mesh::FaceMesh out = remesh_disk_defects(m, *plate.geometry, table, options, &stats);
  EXPECT_EQ(stats.replaced, 0);
  EXPECT_GE(stats.rejected_geometry, 1);
  EXPECT_EQ(out.quads, m.quads);
  ASSERT_EQ(out.num_vertices(), m.num_vertices());
  for (LO v = 0; v < m.num_vertices(); ++v) {
    EXPECT_EQ(out.uv[v], m.uv[v]);
    EXPECT_EQ(out.points[v].x, m.points[v].x);
    EXPECT_EQ(out.points[v].y, m.points[v].y);
  }
}

TEST(DiskRemesh, RefusesTriangles) {
  const DiskQuadTable table = DiskQuadTable::builtin();
  const Plate plate = load_plate();
  mesh::FaceMesh m = grid_with_valence6(*plate.geometry);
  m.triangles.push_back({0, 1, 8});
  EXPECT_THROW((void)remesh_disk_defects(m, *plate.geometry, table, {}), Error);
}

}  // namespace
}  // namespace qsmesh::remesh
