// Quad layouts and block-structured CGNS files of hand-built non-manifold meshes: a curve that
// three faces border (a T of three sheets), and a face given twice (two faces on one surface with
// one boundary, as a STEP file that repeats a face holds them).
#include <cgns_io.h>
#include <cgnslib.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "cgns_blocks_check.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/layout/quad_layout.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::layout {
namespace {

namespace fs = std::filesystem;

// One sheet: the nu x nv grid of quads whose vertex (u, v) lies at at(u, v), counter-clockwise in
// (u, v).
struct Sheet {
  int nu, nv;
  std::function<Vec3(int, int)> at;
};

// The surface mesh of `sheets`, one CAD face each. Each sheet's four sides are its curves and its
// four grid corners its CAD corners; sides and corners at the same place are one (that is how the
// sheets share a curve, three of them making it non-manifold). Boundary vertices at the same place
// are one vertex; interior vertices belong to their sheet.
mesh::SurfaceMesh sheets_mesh(const std::vector<Sheet>& sheets) {
  mesh::SurfaceMesh m;
  std::map<std::array<double, 3>, GO> boundary_vertex;
  std::map<std::array<double, 3>, LO> corner_at;
  std::map<std::set<std::array<double, 3>>, LO> curve_at;  // a side by its points
  auto key = [](const Vec3& p) { return std::array<double, 3>{p[0], p[1], p[2]}; };
  std::vector<std::pair<LO, LO>> face_curve;
  for (std::size_t f = 0; f < sheets.size(); ++f) {
    const Sheet& s = sheets[f];
    // The four sides, counter-clockwise: (u, v) from (0, 0) to (nu, 0), ... back to (0, 0).
    const std::array<std::array<int, 4>, 4> sides{
        {{0, 0, 1, 0}, {s.nu, 0, 0, 1}, {s.nu, s.nv, -1, 0}, {0, s.nv, 0, -1}}};
    std::map<std::pair<int, int>, std::pair<LO, LO>> on_side;  // (u, v) -> (curve, index)
    for (const auto& [u0, v0, du, dv] : sides) {
      const int n = du != 0 ? s.nu : s.nv;
      std::set<std::array<double, 3>> points;
      for (int k = 0; k <= n; ++k) points.insert(key(s.at(u0 + k * du, v0 + k * dv)));
      const auto [it, fresh] = curve_at.try_emplace(points, m.num_cad_curves);
      if (fresh) {
        ++m.num_cad_curves;
        std::array<LO, 2> ends{};
        for (int e = 0; e < 2; ++e) {
          const auto [c, made] =
              corner_at.try_emplace(key(s.at(u0 + e * n * du, v0 + e * n * dv)), m.num_cad_corners);
          if (made) ++m.num_cad_corners;
          ends[static_cast<std::size_t>(e)] = c->second;
        }
        m.curve_corners.push_back(ends);
      }
      face_curve.emplace_back(static_cast<LO>(f), it->second);
      for (int k = 1; k < n; ++k) on_side[{u0 + k * du, v0 + k * dv}] = {it->second, k};
    }
    std::vector<GO> id(static_cast<std::size_t>((s.nu + 1) * (s.nv + 1)));
    for (int v = 0; v <= s.nv; ++v)
      for (int u = 0; u <= s.nu; ++u) {
        const Vec3 p = s.at(u, v);
        mesh::VertexClass c;
        const bool boundary = u == 0 || v == 0 || u == s.nu || v == s.nv;
        if ((u == 0 || u == s.nu) && (v == 0 || v == s.nv)) {
          c.dim = 0;
          c.entity = corner_at.at(key(p));
        } else if (boundary) {
          c.dim = 1;
          std::tie(c.entity, c.index) = on_side.at({u, v});
        } else {
          c.entity = static_cast<LO>(f);
        }
        GO& slot = id[static_cast<std::size_t>(v * (s.nu + 1) + u)];
        const auto found = boundary_vertex.find(key(p));
        if (boundary && found != boundary_vertex.end()) {
          slot = found->second;
          continue;
        }
        slot = m.num_vertices();
        if (boundary) boundary_vertex[key(p)] = slot;
        m.points.push_back(p);
        m.vclass.push_back(c);
      }
    auto vid = [&](int u, int v) { return id[static_cast<std::size_t>(v * (s.nu + 1) + u)]; };
    for (int v = 0; v < s.nv; ++v)
      for (int u = 0; u < s.nu; ++u) {
        m.quads.push_back({vid(u, v), vid(u + 1, v), vid(u + 1, v + 1), vid(u, v + 1)});
        m.quad_face.push_back(static_cast<LO>(f));
      }
  }
  // Bars: each curve once, from the sheet that made it.
  std::set<LO> barred;
  for (std::size_t f = 0; f < sheets.size(); ++f) {
    const Sheet& s = sheets[f];
    auto vertex_at = [&](int u, int v) { return boundary_vertex.at(key(s.at(u, v))); };
    const std::array<std::array<int, 4>, 4> sides{
        {{0, 0, 1, 0}, {s.nu, 0, 0, 1}, {s.nu, s.nv, -1, 0}, {0, s.nv, 0, -1}}};
    for (const auto& [u0, v0, du, dv] : sides) {
      const int n = du != 0 ? s.nu : s.nv;
      std::set<std::array<double, 3>> points;
      for (int k = 0; k <= n; ++k) points.insert(key(s.at(u0 + k * du, v0 + k * dv)));
      const LO c = curve_at.at(points);
      if (!barred.insert(c).second) continue;
      for (int k = 0; k < n; ++k) {
        m.bars.push_back(
            {vertex_at(u0 + k * du, v0 + k * dv), vertex_at(u0 + (k + 1) * du, v0 + (k + 1) * dv)});
        m.bar_curve.push_back(c);
      }
    }
  }
  m.num_cad_faces = static_cast<LO>(sheets.size());
  m.face2curves = Adjacency::from_pairs(m.num_cad_faces, face_curve);
  return m;
}

// Three n x n sheets along the curve x = z = 0, 0 <= y <= n: two flat ones (x <= 0 and x >= 0 at
// z = 0) and an upright one (x = 0, z >= 0).
mesh::SurfaceMesh t_of_three_sheets(int n) {
  const auto d = [](int k) { return static_cast<double>(k); };
  return sheets_mesh({{n, n,
                       [&](int u, int v) {
                         return Vec3{d(u), d(v), 0};
                       }},
                      {n, n,
                       [&](int u, int v) {
                         return Vec3{-d(v), d(u), 0};
                       }},
                      {n, n, [&](int u, int v) {
                         return Vec3{0, d(v), d(u)};
                       }}});
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(qsmesh::test::tmp_dir()) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void delete_node(const std::string& file, const std::string& node) {
  int cgio = 0;
  ASSERT_EQ(cgio_open_file(file.c_str(), CGIO_MODE_MODIFY, CGIO_FILE_NONE, &cgio), CGIO_ERR_NONE);
  double root = 0, id = 0, parent = 0;
  ASSERT_EQ(cgio_get_root_id(cgio, &root), CGIO_ERR_NONE);
  ASSERT_EQ(cgio_get_node_id(cgio, root, node.c_str(), &id), CGIO_ERR_NONE) << node;
  const std::string up = node.substr(0, node.rfind('/'));
  ASSERT_EQ(cgio_get_node_id(cgio, root, up.c_str(), &parent), CGIO_ERR_NONE) << up;
  ASSERT_EQ(cgio_delete_node(cgio, parent, id), CGIO_ERR_NONE);
  ASSERT_EQ(cgio_close_file(cgio), CGIO_ERR_NONE);
}

// The 1-to-1 interfaces of zone z (1-based) as (name, donor).
std::vector<std::pair<std::string, std::string>> interfaces_of(const std::string& file, int z) {
  std::vector<std::pair<std::string, std::string>> out;
  int fn = 0, n = 0;
  EXPECT_EQ(cg_open(file.c_str(), CG_MODE_READ, &fn), CG_OK);
  EXPECT_EQ(cg_n1to1(fn, 1, z, &n), CG_OK);
  for (int c = 1; c <= n; ++c) {
    char name[33] = {}, donor[33] = {};
    cgsize_t range[4] = {}, donor_range[4] = {};
    int transform[2] = {};
    EXPECT_EQ(cg_1to1_read(fn, 1, z, c, name, donor, range, donor_range, transform), CG_OK);
    out.emplace_back(name, donor);
  }
  cg_close(fn);
  return out;
}

TEST(NonManifold, ThreeSheetsOnOneCurveAreThreeBlocksJoinedPairwise) {
  const mesh::SurfaceMesh m = t_of_three_sheets(3);
  const QuadLayout l = extract_quad_layout(m);
  ASSERT_EQ(l.blocks.size(), 3u);  // the spine is a curve: no trace crosses it, none starts on it
  for (const Block& b : l.blocks) EXPECT_EQ(b.ni * b.nj, 9);
  const fs::path dir = fresh_dir("nonmanifold_t");
  const std::string path = (dir / "t.cgns").string();
  io::write_cgns_blocks(m, l, path);
  const qsmesh::test::BlockFileSummary s = qsmesh::test::check_block_file(path);
  EXPECT_EQ(s.error, "");
  // Each block's spine side is joined once to each of the two others, both ways: 6 interfaces of
  // 4 points; the three other sides of each block are free (a BC per side).
  EXPECT_EQ(s.interfaces, 6);
  EXPECT_EQ(s.interface_points, 24);
  EXPECT_EQ(s.boundary_conditions, 9);
  for (int z = 1; z <= 3; ++z) {
    std::set<std::string> donors;
    for (const auto& [name, donor] : interfaces_of(path, z)) donors.insert(donor);
    EXPECT_EQ(donors.size(), 2u) << "zone " << z;
  }
}

TEST(NonManifold, TheReaderWantsEverySideAtAnEdgeJoinedToEveryOther) {
  // Three sides at the spine: blocks 1 and 2 each joined to block 0 only (their interface with
  // each other dropped, both ways) is an open junction; the reader must say so, though every
  // remaining interface is reciprocal and covers its edges once on blocks 1 and 2.
  const mesh::SurfaceMesh m = t_of_three_sheets(2);
  const QuadLayout l = extract_quad_layout(m);
  ASSERT_EQ(l.blocks.size(), 3u);
  const fs::path dir = fresh_dir("nonmanifold_open");
  const std::string good = (dir / "good.cgns").string();
  io::write_cgns_blocks(m, l, good);
  ASSERT_EQ(qsmesh::test::check_block_file(good).error, "");
  const std::string open = (dir / "open.cgns").string();
  fs::copy_file(good, open);
  const std::array<std::string, 3> zone{"Block_000000_Face_000000", "Block_000001_Face_000001",
                                        "Block_000002_Face_000002"};
  for (const auto& [from, to] : {std::pair{1, 2}, std::pair{2, 1}}) {
    for (const auto& [name, donor] : interfaces_of(good, from + 1))
      if (donor == zone[static_cast<std::size_t>(to)])
        delete_node(open, "/qsmesh/" + zone[static_cast<std::size_t>(from)] +
                              "/ZoneGridConnectivity/" + name);
  }
  ASSERT_EQ(interfaces_of(open, 2).size(), 1u);
  const std::string error = qsmesh::test::check_block_file(open).error;
  EXPECT_NE(error.find("is not joined to the same edges"), std::string::npos) << error;

  // And a side joined twice to the same other side is no junction of three.
  const std::string twice = (dir / "twice.cgns").string();
  fs::copy_file(good, twice);
  {
    int fn = 0;
    ASSERT_EQ(cg_open(twice.c_str(), CG_MODE_MODIFY, &fn), CG_OK);
    char name[33] = {}, donor[33] = {};
    cgsize_t range[4] = {}, donor_range[4] = {};
    int transform[2] = {}, added = 0;
    ASSERT_EQ(cg_1to1_read(fn, 1, 1, 1, name, donor, range, donor_range, transform), CG_OK);
    ASSERT_EQ(cg_1to1_write(fn, 1, 1, "Again", donor, range, donor_range, transform, &added),
              CG_OK);
    cg_close(fn);
  }
  const std::string again = qsmesh::test::check_block_file(twice).error;
  EXPECT_NE(again.find("joined twice to the same edge"), std::string::npos) << again;
}

TEST(NonManifold, AFaceGivenTwiceIsCutAlongItsOwnTracesOnly) {
  // A 3 x 1 strip meshed twice on the same vertices (a face given twice, each copy meshed the same:
  // one row of quads has no interior vertex), beside a 2 x 1 strip on one of its long sides. The
  // strip's cross edges join curve vertices; each copy has them, inside itself: each copy is one
  // block, joined to the other copy and to the neighbour along the curves only.
  const auto d = [](int k) { return static_cast<double>(k); };
  const mesh::SurfaceMesh m = sheets_mesh({{3, 1,
                                            [&](int u, int v) {
                                              return Vec3{d(u), d(v), 0};
                                            }},
                                           {3, 1,
                                            [&](int u, int v) {
                                              return Vec3{d(u), d(v), 0};
                                            }},
                                           {3, 2, [&](int u, int v) {
                                              return Vec3{d(3 - u), -d(v), 0};
                                            }}});
  ASSERT_EQ(m.quads[0], m.quads[3]);  // the copies' quads are the same
  // Each copy's patch is the whole copy, without merging blocks (the copies' edges taken together,
  // each cross edge had four quads: no patch crossed it, and each quad was a block).
  EXPECT_EQ(extract_quad_layout(m, {.motorcycle = true, .merge = false}).blocks.size(), 3u);
  const QuadLayout l = extract_quad_layout(m);
  ASSERT_EQ(l.blocks.size(), 3u);
  EXPECT_EQ(l.blocks[0].ni * l.blocks[0].nj, 3);
  EXPECT_EQ(l.blocks[1].ni * l.blocks[1].nj, 3);
  const fs::path dir = fresh_dir("nonmanifold_twice");
  const std::string path = (dir / "twice.cgns").string();
  io::write_cgns_blocks(m, l, path);
  const qsmesh::test::BlockFileSummary s = qsmesh::test::check_block_file(path);
  EXPECT_EQ(s.error, "");
  // The copies' long side on the neighbour (three sides: each pair, both ways), the copies' other
  // long side and their short ends (two sides: both ways): 6 + 2 * 3 = 12 interfaces.
  EXPECT_EQ(s.interfaces, 12);
}

}  // namespace
}  // namespace qsmesh::layout
