// Quad layouts of hand-built meshes, and their block-structured CGNS output read back.
#include <cgns_io.h>
#include <cgnslib.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cgns_blocks_check.hpp"
#include "qsmesh/io/block_connections.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/layout/quad_layout.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::layout {
namespace {

namespace fs = std::filesystem;

// Two rectangular faces side by side on the lattice [0, a + b] x [0, n] (unit spacing, z = 0):
// face 0 = [0, a] x [0, n], face 1 = [a, a + b] x [0, n], sharing the curve x = a. Corners at the
// six rectangle corners; curves: 0 bottom of face 0, 1 bottom of face 1, 2 top of face 0, 3 top
// of face 1, 4 x = 0, 5 x = a, 6 x = a + b. Quads counter-clockwise seen from +z.
mesh::SurfaceMesh two_faces(int a, int b, int n) {
  mesh::SurfaceMesh m;
  m.num_cad_faces = 2;
  m.num_cad_curves = 7;
  m.num_cad_corners = 6;
  const int nx = a + b;
  std::vector<GO> id(static_cast<std::size_t>((nx + 1) * (n + 1)));
  auto at = [&](int x, int y) -> GO& { return id[static_cast<std::size_t>(y * (nx + 1) + x)]; };
  auto corner_of = [&](int x, int y) {
    const int col = x == 0 ? 0 : (x == a ? 1 : 2);
    return (y == 0 ? 0 : 3) + col;
  };
  std::map<int, int> next_on_curve;
  for (int y = 0; y <= n; ++y) {
    for (int x = 0; x <= nx; ++x) {
      mesh::VertexClass c;
      const bool vertical = x == 0 || x == a || x == nx, horizontal = y == 0 || y == n;
      if (vertical && horizontal) {
        c.dim = 0;
        c.entity = corner_of(x, y);
      } else if (vertical || horizontal) {
        c.dim = 1;
        c.entity = vertical ? (x == 0 ? 4 : (x == a ? 5 : 6)) : (y == 0 ? 0 : 2) + (x > a ? 1 : 0);
        c.index = ++next_on_curve[c.entity];
      } else {
        c.dim = 2;
        c.entity = x < a ? 0 : 1;
      }
      at(x, y) = static_cast<GO>(m.points.size());
      m.points.push_back({static_cast<double>(x), static_cast<double>(y), 0.0});
      m.vclass.push_back(c);
    }
  }
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < nx; ++x) {
      m.quads.push_back({at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)});
      m.quad_face.push_back(x < a ? 0 : 1);
    }
  auto bar = [&](GO p, GO q, LO curve) {
    m.bars.push_back({p, q});
    m.bar_curve.push_back(curve);
  };
  for (int x = 0; x < nx; ++x) {
    bar(at(x, 0), at(x + 1, 0), x < a ? 0 : 1);
    bar(at(x, n), at(x + 1, n), x < a ? 2 : 3);
  }
  for (int y = 0; y < n; ++y) {
    bar(at(0, y), at(0, y + 1), 4);
    bar(at(a, y), at(a, y + 1), 5);
    bar(at(nx, y), at(nx, y + 1), 6);
  }
  m.curve_corners = {{0, 1}, {1, 2}, {3, 4}, {4, 5}, {0, 3}, {1, 4}, {2, 5}};
  m.face2curves =
      Adjacency::from_pairs(2, {{0, 0}, {0, 2}, {0, 4}, {0, 5}, {1, 1}, {1, 3}, {1, 5}, {1, 6}});
  return m;
}

// two_faces(2, 2, 2) with the last quad of face 1 split into two triangles.
mesh::SurfaceMesh two_faces_with_triangles() {
  mesh::SurfaceMesh m = two_faces(2, 2, 2);
  const auto q = m.quads.back();
  m.quads.pop_back();
  m.quad_face.pop_back();
  m.triangles = {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}};
  m.triangle_face = {1, 1};
  return m;
}

// A fresh, empty folder under the test temp folder.
fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(qsmesh::test::tmp_dir()) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// A triangular face of three quads around a valence-3 vertex O: corners A, B, C; the midpoints of
// its three curves; the triangle pattern of paper 000 Fig. 4.
mesh::SurfaceMesh triangle_face() {
  mesh::SurfaceMesh m;
  m.num_cad_faces = 1;
  m.num_cad_curves = 3;
  m.num_cad_corners = 3;
  m.points = {{0, 0, 0},      {2, 0, 0},      {1, 1.7, 0}, {1, 0, 0},
              {1.5, 0.85, 0}, {0.5, 0.85, 0}, {1, 0.6, 0}};
  m.vclass = {{0, 0, kNoIndex, {0, 0}},    {0, 1, kNoIndex, {0, 0}}, {0, 2, kNoIndex, {0, 0}},
              {1, 0, 1, {0.5, 0}},         {1, 1, 1, {0.5, 0}},      {1, 2, 1, {0.5, 0}},
              {2, 0, kNoIndex, {0.5, 0.3}}};
  m.quads = {{0, 3, 6, 5}, {3, 1, 4, 6}, {6, 4, 2, 5}};
  m.quad_face = {0, 0, 0};
  m.bars = {{0, 3}, {3, 1}, {1, 4}, {4, 2}, {2, 5}, {5, 0}};
  m.bar_curve = {0, 0, 1, 1, 2, 2};
  m.curve_corners = {{0, 1}, {1, 2}, {2, 0}};
  m.face2curves = Adjacency::from_pairs(1, {{0, 0}, {0, 1}, {0, 2}});
  return m;
}

// Every block cell is a mesh quad (same vertices, same turning sense), every quad in one block.
void expect_blocks_cover_the_quads(const mesh::SurfaceMesh& m, const QuadLayout& l) {
  std::map<std::array<GO, 4>, GO> quad_of;  // the quad's vertices rotated to start at the smallest
  auto canonical = [](std::array<GO, 4> q) {
    std::rotate(q.begin(), std::min_element(q.begin(), q.end()), q.end());
    return q;
  };
  for (std::size_t q = 0; q < m.quads.size(); ++q)
    quad_of[canonical(m.quads[q])] = static_cast<GO>(q);
  std::vector<int> covered(m.quads.size(), 0);
  ASSERT_EQ(l.quad2block.size(), m.quads.size());
  for (std::size_t k = 0; k < l.blocks.size(); ++k) {
    const Block& b = l.blocks[k];
    for (LO j = 0; j < b.nj; ++j)
      for (LO i = 0; i < b.ni; ++i) {
        const std::array<GO, 4> cell{b.vertex(i, j, l.vertices), b.vertex(i + 1, j, l.vertices),
                                     b.vertex(i + 1, j + 1, l.vertices),
                                     b.vertex(i, j + 1, l.vertices)};
        const auto it = quad_of.find(canonical(cell));
        ASSERT_NE(it, quad_of.end()) << "block " << k << " cell " << i << "," << j;
        ++covered[static_cast<std::size_t>(it->second)];
        EXPECT_EQ(l.quad2block[static_cast<std::size_t>(it->second)], static_cast<GO>(k));
        EXPECT_EQ(m.quad_face[static_cast<std::size_t>(it->second)], b.face);
      }
  }
  for (std::size_t q = 0; q < covered.size(); ++q) EXPECT_EQ(covered[q], 1) << "quad " << q;
}

TEST(QuadLayout, RegularFacesAreOneBlockEach) {
  const mesh::SurfaceMesh m = two_faces(4, 2, 3);
  const QuadLayout l = extract_quad_layout(m);
  ASSERT_EQ(l.blocks.size(), 2u);
  EXPECT_TRUE(l.unblocked_faces.empty());
  EXPECT_EQ(l.blocks[0].face, 0);
  EXPECT_EQ(l.blocks[1].face, 1);
  // The grid starts at the corner of smallest vertex id, i along the first edge of its quad.
  EXPECT_EQ(l.blocks[0].ni * l.blocks[0].nj, 12);
  EXPECT_EQ(l.blocks[1].ni * l.blocks[1].nj, 6);
  EXPECT_EQ(l.blocks[0].vertex(0, 0, l.vertices), 0);
  EXPECT_EQ(l.blocks[0].ni, 4);
  EXPECT_EQ(l.blocks[0].nj, 3);
  expect_blocks_cover_the_quads(m, l);
}

TEST(QuadLayout, FlatCornersDoNotCutTheFace) {
  // One face [0, 4] x [0, 2] whose bottom and top sides are two curves each, meeting at flat
  // corners (two quads on their side): one block, the corners on its sides.
  mesh::SurfaceMesh m = two_faces(2, 2, 2);
  m.num_cad_faces = 1;
  for (LO& f : m.quad_face) f = 0;
  std::vector<std::array<GO, 2>> bars;
  std::vector<LO> bar_curve;
  for (std::size_t k = 0; k < m.bars.size(); ++k) {
    if (m.bar_curve[k] == 5) continue;  // the curve between the two faces is gone
    bars.push_back(m.bars[k]);
    bar_curve.push_back(m.bar_curve[k]);
  }
  m.bars = bars;
  m.bar_curve = bar_curve;
  for (auto& c : m.vclass)
    if (c.dim == 1 && c.entity == 5) c = {2, 0, kNoIndex, {0, 0}};
  m.face2curves = Adjacency::from_pairs(1, {{0, 0}, {0, 1}, {0, 2}, {0, 3}, {0, 4}, {0, 6}});
  LayoutOptions unmerged;  // one block before any merging
  unmerged.merge = false;
  const QuadLayout l = extract_quad_layout(m, unmerged);
  ASSERT_EQ(l.blocks.size(), 1u);
  EXPECT_EQ(l.blocks[0].ni * l.blocks[0].nj, 8);
  expect_blocks_cover_the_quads(m, l);
}

TEST(QuadLayout, TracesFromAnIrregularVertexCutTheFace) {
  const mesh::SurfaceMesh m = triangle_face();
  LayoutOptions unmerged;
  unmerged.merge = false;
  const QuadLayout l = extract_quad_layout(m, unmerged);
  ASSERT_EQ(l.blocks.size(), 3u);
  for (const Block& b : l.blocks) {
    EXPECT_EQ(b.ni, 1);
    EXPECT_EQ(b.nj, 1);
  }
  expect_blocks_cover_the_quads(m, l);
  // Merged: the first two quads share the trace from the valence-3 vertex to the first curve's
  // midpoint, a whole side of each, and become one 2 x 1 block; the third shares no whole side.
  const QuadLayout merged = extract_quad_layout(m);
  ASSERT_EQ(merged.blocks.size(), 2u);
  EXPECT_EQ(merged.blocks[0].ni * merged.blocks[0].nj, 2);
  EXPECT_EQ(merged.blocks[1].ni * merged.blocks[1].nj, 1);
  expect_blocks_cover_the_quads(m, merged);
}

TEST(QuadLayout, BlocksAreNotMergedAcrossCurves) {
  // Two faces whose blocks match along the curve between them stay two blocks.
  const mesh::SurfaceMesh m = two_faces(2, 2, 2);
  EXPECT_EQ(extract_quad_layout(m).blocks.size(), 2u);
}

TEST(QuadLayout, FacesWithTrianglesAreLeftOut) {
  const mesh::SurfaceMesh m = two_faces_with_triangles();
  const QuadLayout l = extract_quad_layout(m);
  ASSERT_EQ(l.blocks.size(), 1u);
  EXPECT_EQ(l.blocks[0].face, 0);
  EXPECT_EQ(l.unblocked_faces, std::vector<LO>{1});
  for (std::size_t k = 0; k < m.quads.size(); ++k)
    EXPECT_EQ(l.quad2block[k], m.quad_face[k] == 1 ? -1 : 0);
}

TEST(CgnsBlocks, InterfacesJoinTheSamePoints) {
  const fs::path dir = fresh_dir("cgns_blocks");
  for (const bool triangle : {false, true}) {
    const mesh::SurfaceMesh m = triangle ? triangle_face() : two_faces(4, 2, 3);
    const QuadLayout l = extract_quad_layout(m);
    const std::string path = (dir / (triangle ? "tri.cgns" : "two.cgns")).string();
    io::write_cgns_blocks(m, l, path);
    const qsmesh::test::BlockFileSummary s = qsmesh::test::check_block_file(path);
    EXPECT_EQ(s.error, "");
    EXPECT_EQ(s.structured_zones, static_cast<int>(l.blocks.size()));
    EXPECT_EQ(s.unstructured_zones, 0);
    EXPECT_EQ(s.block_quads, static_cast<std::int64_t>(m.quads.size()));
    // Two faces: one interface each way along the shared curve (3 edges, 4 points). Triangle: the
    // 2 x 1 block's long side meets two sides of the 1 x 1 block, one edge each, both ways.
    EXPECT_EQ(s.interfaces, triangle ? 4 : 2);
    EXPECT_EQ(s.interface_points, 8);
    // Free edges get a BC per run on one curve: two faces, three sides each off the shared curve;
    // triangle, the 2 x 1 block's three free sides and the 1 x 1 block's two.
    EXPECT_EQ(s.boundary_conditions, triangle ? 5 : 6);
  }
}

TEST(CgnsBlocks, UnblockedFacesGoToAnUnstructuredZone) {
  const fs::path dir = fresh_dir("cgns_blocks_mixed");
  const mesh::SurfaceMesh m = two_faces_with_triangles();
  const QuadLayout l = extract_quad_layout(m);
  const std::string path = (dir / "mixed.cgns").string();
  io::write_cgns_blocks(m, l, path);
  const qsmesh::test::BlockFileSummary s = qsmesh::test::check_block_file(path);
  EXPECT_EQ(s.error, "");
  EXPECT_EQ(s.structured_zones, 1);
  EXPECT_EQ(s.unstructured_zones, 1);
  EXPECT_EQ(s.block_quads, 4);
  // The block's side on the curve shared with the triangles abuts the unstructured zone (one
  // connectivity, checked point by point, and its reverse there), not a wall: BCs only on the
  // block's three other sides.
  EXPECT_EQ(s.abutments, 1);
  EXPECT_EQ(s.boundary_conditions, 3);
}

// Deletes the node at `node` (a path from the root) of the CGNS file `path`, through cgio.
void delete_node(const std::string& path, const std::string& node) {
  int cgio = 0;
  ASSERT_EQ(cgio_open_file(path.c_str(), CGIO_MODE_MODIFY, CGIO_FILE_NONE, &cgio), CGIO_ERR_NONE);
  double root = 0, id = 0, parent = 0;
  ASSERT_EQ(cgio_get_root_id(cgio, &root), CGIO_ERR_NONE);
  ASSERT_EQ(cgio_get_node_id(cgio, root, node.c_str(), &id), CGIO_ERR_NONE) << node;
  ASSERT_EQ(cgio_get_node_id(cgio, root, node.substr(0, node.rfind('/')).c_str(), &parent),
            CGIO_ERR_NONE);
  ASSERT_EQ(cgio_delete_node(cgio, parent, id), CGIO_ERR_NONE);
  ASSERT_EQ(cgio_close_file(cgio), CGIO_ERR_NONE);
}

TEST(CgnsBlocks, TheReaderCatchesMissingConnections) {
  // The reader the other tests trust must fail on the files a broken writer would make: the
  // unstructured zone's connectivity back to the block missing, and the block's own connectivity
  // replaced by a wall BC over the same edges.
  const fs::path dir = fresh_dir("cgns_blocks_broken");
  const mesh::SurfaceMesh m = two_faces_with_triangles();
  const QuadLayout l = extract_quad_layout(m);
  const std::string good = (dir / "good.cgns").string();
  io::write_cgns_blocks(m, l, good);
  ASSERT_EQ(qsmesh::test::check_block_file(good).error, "");
  const std::string block = "/qsmesh/Block_000000_Face_000000";

  const std::string no_reverse = (dir / "no_reverse.cgns").string();
  fs::copy_file(good, no_reverse);
  delete_node(no_reverse, "/qsmesh/Unstructured/ZoneGridConnectivity");
  EXPECT_NE(qsmesh::test::check_block_file(no_reverse).error.find("not the same both ways"),
            std::string::npos);

  // The block's abutting range, then a wall BC over it in place of the connectivity.
  cgsize_t range[4] = {};
  {
    int fn = 0;
    ASSERT_EQ(cg_open(good.c_str(), CG_MODE_READ, &fn), CG_OK);
    std::vector<cgsize_t> donor(64);
    ASSERT_EQ(cg_conn_read(fn, 1, 1, 1, range, CGNS_ENUMV(Integer), donor.data()), CG_OK);
    cg_close(fn);
  }
  const std::string wall = (dir / "wall.cgns").string();
  fs::copy_file(good, wall);
  delete_node(wall, block + "/ZoneGridConnectivity");
  {
    int fn = 0, bc = 0;
    ASSERT_EQ(cg_open(wall.c_str(), CG_MODE_MODIFY, &fn), CG_OK);
    ASSERT_EQ(
        cg_boco_write(fn, 1, 1, "Wall", CGNS_ENUMV(BCWall), CGNS_ENUMV(PointRange), 2, range, &bc),
        CG_OK);
    cg_close(fn);
  }
  const std::string error = qsmesh::test::check_block_file(wall).error;
  EXPECT_NE(error.find("a BC on an edge another zone also has"), std::string::npos) << error;
}

#ifdef QSMESH_CGNSCHECK
// cgnscheck's error lines for `path` (it exits 0 whatever it finds, so its report is read).
std::vector<std::string> cgnscheck_errors(const std::string& path, std::string* report) {
  const std::string cmd = std::string(QSMESH_CGNSCHECK) + " -w3 '" + path + "' 2>&1";
  std::FILE* p = ::popen(cmd.c_str(), "r");
  EXPECT_NE(p, nullptr);
  if (p == nullptr) return {"popen failed"};
  std::string out;
  char buf[4096];
  for (std::size_t n = 0; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  ::pclose(p);
  std::vector<std::string> errors;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) {
    std::string upper = line;
    for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (upper.find("ERROR") != std::string::npos) errors.push_back(line);
  }
  *report = out;
  return errors;
}

TEST(CgnsBlocks, CgnscheckFindsNoErrorInTheZonesMadeThroughCgio) {
  // The block zones are written node by node through cgio (not cg_zone_write, which is quadratic
  // in the zone count): cgnscheck must find each of them a valid structured zone, with its
  // coordinates, family, interfaces and BCs, whatever the layout (two faces; a face whose blocks
  // meet in a T-junction; blocks beside an unstructured zone).
  const fs::path dir = fresh_dir("cgns_blocks_cgnscheck");
  int n = 0;
  for (const mesh::SurfaceMesh& m :
       {two_faces(4, 2, 3), triangle_face(), two_faces_with_triangles()}) {
    const QuadLayout l = extract_quad_layout(m);
    // Appended rather than "m" + ...: GCC 12 reports a false -Wrestrict on that concatenation.
    std::string name(1, 'm');
    name += std::to_string(n++);
    name += ".cgns";
    const std::string path = (dir / name).string();
    io::write_cgns_blocks(m, l, path);
    std::string report;
    const std::vector<std::string> errors = cgnscheck_errors(path, &report);
    EXPECT_TRUE(errors.empty()) << report;
    for (std::size_t k = 0; k < l.blocks.size(); ++k)
      EXPECT_NE(report.find("checking zone \"" +
                            io::block_name(l, static_cast<GO>(k), m.num_cad_faces) + "\""),
                std::string::npos)
          << report;
  }
  // And the check can fail: a zone whose coordinates no longer match its size.
  const std::string good = (dir / "m0.cgns").string(), broken = (dir / "broken.cgns").string();
  fs::copy_file(good, broken, fs::copy_options::overwrite_existing);
  {
    int cgio = 0;
    ASSERT_EQ(cgio_open_file(broken.c_str(), CGIO_MODE_MODIFY, CGIO_FILE_NONE, &cgio),
              CGIO_ERR_NONE);
    double root = 0, id = 0;
    ASSERT_EQ(cgio_get_root_id(cgio, &root), CGIO_ERR_NONE);
    ASSERT_EQ(cgio_get_node_id(cgio, root, "/qsmesh/Block_000000_Face_000000", &id), CGIO_ERR_NONE);
    const cgsize_t wrong[6] = {9, 9, 8, 8, 0, 0};
    ASSERT_EQ(cgio_write_all_data(cgio, id, wrong), CGIO_ERR_NONE);
    ASSERT_EQ(cgio_close_file(cgio), CGIO_ERR_NONE);
  }
  std::string report;
  EXPECT_FALSE(cgnscheck_errors(broken, &report).empty()) << report;
}
#endif

}  // namespace
}  // namespace qsmesh::layout
