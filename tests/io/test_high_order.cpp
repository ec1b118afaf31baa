// High-order meshes (SurfaceMesh::order 2..5) through each writer, read back: element types,
// node counts and each format's node order, checked on the cubic quad against hand-written lists.
#include <cgnslib.h>
#include <gtest/gtest.h>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "io_test_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/mesh/high_order_nodes.hpp"

namespace qsmesh::io {
namespace {

namespace fs = std::filesystem;
using test::fresh_dir;
using test::read_all;

#define CG(call) ASSERT_EQ((call), CG_OK) << cg_get_error()

// Two quads of order n on the lattice of points (x / n, y / n, y / 2n), 0 <= x <= 2n, 0 <= y <= n
// (point id x + (2n + 1) y): [0, 1] x [0, 1] and [1, 2] x [0, 1] of face 0, bounded by six bars
// of the closed curve 0 (corner 0 at the origin).
mesh::SurfaceMesh lattice_mesh(int n) {
  mesh::SurfaceMesh m;
  m.num_cad_corners = 1;
  m.num_cad_curves = 1;
  m.num_cad_faces = 1;
  const int w = 2 * n + 1;
  auto id = [w](int x, int y) { return static_cast<GO>(x + w * y); };
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x < w; ++x) {
      m.points.push_back({static_cast<double>(x) / n, static_cast<double>(y) / n, 0.5 * y / n});
      const bool boundary = x == 0 || x == 2 * n || y == 0 || y == n;
      m.vclass.push_back(boundary ? mesh::VertexClass{1, 0, kNoIndex, {0, 0}}
                                  : mesh::VertexClass{2, 0, kNoIndex, {0, 0}});
    }
  m.vclass[0] = {0, 0, kNoIndex, {0, 0}};
  m.order = n;
  const auto positions = mesh::quad_grid_positions(n);
  for (int x0 : {0, n}) {
    m.quads.push_back({id(x0, 0), id(x0 + n, 0), id(x0 + n, n), id(x0, n)});
    m.quad_face.push_back(0);
    for (std::size_t k = 4; k < positions.size(); ++k)
      m.quad_nodes.push_back(id(x0 + positions[k][0], positions[k][1]));
  }
  // The boundary, counter-clockwise, as six bars of n lattice steps.
  const std::vector<std::array<int, 2>> loop{{0, 0},     {n, 0}, {2 * n, 0},
                                             {2 * n, n}, {n, n}, {0, n}};
  for (std::size_t b = 0; b < loop.size(); ++b) {
    const auto a = loop[b], c = loop[(b + 1) % loop.size()];
    m.bars.push_back({id(a[0], a[1]), id(c[0], c[1])});
    m.bar_curve.push_back(0);
    for (int s = 1; s < n; ++s)
      m.bar_nodes.push_back(id(a[0] + (c[0] - a[0]) * s / n, a[1] + (c[1] - a[1]) * s / n));
  }
  m.curve_corners = {{0, 0}};
  m.face2curves = Adjacency::from_pairs(1, {{0, 0}});
  return m;
}

// The first quad of lattice_mesh(3) (lattice width 7) in each format's order, 0-based.
// CGNS QUAD_16 and Gmsh's 16-node quad: corners, edges in their direction, interior
// counter-clockwise from the node next to corner 0.
const std::vector<GO> kCgnsQuad16{0, 3, 24, 21, 1, 2, 10, 17, 23, 22, 14, 7, 8, 9, 16, 15};
// The first quad of lattice_mesh(4) (lattice width 9): corners, edges, then the interior, which
// Gmsh numbers as a 9-node quad and CGNS QUAD_25 as a ring from (1,1), then the centre.
const std::vector<GO> kQuad25Outer{0, 4, 40, 36, 1, 2, 3, 13, 22, 31, 39, 38, 37, 27, 18, 9};
const std::vector<GO> kGmshQuad25Inner{10, 12, 30, 28, 11, 21, 29, 19, 20};
const std::vector<GO> kCgnsQuad25Inner{10, 11, 12, 21, 30, 29, 28, 19, 20};
// VTK's Lagrange quadrilateral: edges 2-3 and 3-0 with i and j increasing, interior row by row.
const std::vector<GO> kVtkQuad16{0, 3, 24, 21, 1, 2, 10, 17, 22, 23, 7, 14, 8, 9, 15, 16};

std::string msh_section(const std::string& text, const std::string& name) {
  const auto a = text.find("$" + name + "\n");
  const auto b = text.find("$End" + name);
  return a == std::string::npos || b == std::string::npos ? "" : text.substr(a, b - a);
}

TEST(HighOrderOutput, MshTypesAndGmshNodeOrder) {
  const int quad_type[] = {0, 3, 10, 36, 37, 38}, line_type[] = {0, 1, 8, 26, 27, 28};
  for (int n = 2; n <= 5; ++n) {
    const fs::path dir = fresh_dir("ho_msh" + std::to_string(n));
    const std::string path = (dir / "m.msh").string();
    write_mesh(lattice_mesh(n), path);
    std::istringstream in(msh_section(read_all(path), "Elements"));
    std::string line;
    std::getline(in, line);  // $Elements
    std::getline(in, line);  // counts
    bool quads = false, lines = false;
    for (int dim = 0, tag = 0, type = 0, count = 0; in >> dim >> tag >> type >> count;) {
      std::getline(in, line);
      for (int e = 0; e < count; ++e) {
        std::getline(in, line);
        std::istringstream row(line);
        std::vector<GO> ids;
        for (GO v = 0; row >> v;) ids.push_back(v);
        if (dim == 2) {
          EXPECT_EQ(type, quad_type[n]);
          ASSERT_EQ(static_cast<int>(ids.size()), 1 + (n + 1) * (n + 1));
          if (n == 3 && e == 0) {
            for (std::size_t k = 0; k < kCgnsQuad16.size(); ++k)
              EXPECT_EQ(ids[k + 1], kCgnsQuad16[k] + 1) << k;
          }
          if (n == 4 && e == 0) {
            std::vector<GO> expected = kQuad25Outer;
            expected.insert(expected.end(), kGmshQuad25Inner.begin(), kGmshQuad25Inner.end());
            for (std::size_t k = 0; k < expected.size(); ++k)
              EXPECT_EQ(ids[k + 1], expected[k] + 1) << k;
          }
          quads = true;
        } else if (dim == 1) {
          EXPECT_EQ(type, line_type[n]);
          ASSERT_EQ(static_cast<int>(ids.size()), 2 + n);
          if (e == 0) {  // the bar (0,0) -> (n,0): ends, then 1 .. n - 1
            for (int k = 0; k < n + 1; ++k)
              EXPECT_EQ(ids[static_cast<std::size_t>(k + 1)], (k == 0 ? 1 : (k == 1 ? n + 1 : k)));
          }
          lines = true;
        }
      }
    }
    EXPECT_TRUE(quads && lines) << n;
  }
}

// The ASCII text of DataArray `name` in a .vtu file.
std::vector<long long> vtu_array(const std::string& xml, const std::string& name) {
  const auto at = xml.find("Name=\"" + name + "\"");
  std::vector<long long> out;
  if (at == std::string::npos) return out;
  const auto open = xml.find('>', at);
  const auto close = xml.find("</DataArray>", open);
  std::istringstream in(xml.substr(open + 1, close - open - 1));
  for (long long v = 0; in >> v;) out.push_back(v);
  return out;
}

TEST(HighOrderOutput, VtuLagrangeCellsInVtkOrder) {
  for (int n = 2; n <= 5; ++n) {
    const fs::path dir = fresh_dir("ho_vtu" + std::to_string(n));
    const std::string path = (dir / "m.vtu").string();
    WriteOptions options;
    options.vtu_binary = false;
    options.vtu_include_bars = true;
    write_mesh(lattice_mesh(n), path, options);
    const std::string xml = read_all(path);
    const auto types = vtu_array(xml, "types");
    const long long quad = n == 2 ? 28 : 70, bar = n == 2 ? 21 : 68;
    EXPECT_EQ(types, (std::vector<long long>{quad, quad, bar, bar, bar, bar, bar, bar})) << n;
    const auto offsets = vtu_array(xml, "offsets");
    ASSERT_EQ(offsets.size(), 8U);
    EXPECT_EQ(offsets[0], (n + 1) * (n + 1));
    EXPECT_EQ(offsets[7] - offsets[6], n + 1);
    if (n == 3) {
      const auto conn = vtu_array(xml, "connectivity");
      for (std::size_t k = 0; k < kVtkQuad16.size(); ++k) EXPECT_EQ(conn[k], kVtkQuad16[k]) << k;
    }
  }
}

#ifdef QSMESH_CGNSCHECK
// cgnscheck's lines that report an error or a warning (it exits 0 whatever it finds).
std::vector<std::string> cgnscheck_issues(const std::string& path) {
  const std::string cmd = std::string(QSMESH_CGNSCHECK) + " -w3 '" + path + "' 2>&1";
  std::FILE* p = ::popen(cmd.c_str(), "r");
  std::vector<std::string> issues;
  if (p == nullptr) return {"popen failed"};
  std::string out;
  char buf[4096];
  for (std::size_t k = 0; (k = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, k);
  ::pclose(p);
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) {
    std::string upper = line;
    for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (upper.find("ERROR") != std::string::npos || upper.find("WARNING") != std::string::npos)
      issues.push_back(line);
  }
  if (out.find("checking zone") == std::string::npos) issues.push_back("no zone checked: " + out);
  return issues;
}
#endif

TEST(HighOrderOutput, CgnsSectionsUpToOrderFour) {
  const CGNS_ENUMT(ElementType_t)
      quad_type[] = {CGNS_ENUMV(QUAD_4), CGNS_ENUMV(QUAD_4), CGNS_ENUMV(QUAD_9),
                     CGNS_ENUMV(QUAD_16), CGNS_ENUMV(QUAD_25)};
  const CGNS_ENUMT(ElementType_t)
      bar_type[] = {CGNS_ENUMV(BAR_2), CGNS_ENUMV(BAR_2), CGNS_ENUMV(BAR_3), CGNS_ENUMV(BAR_4),
                    CGNS_ENUMV(BAR_5)};
  for (int n = 2; n <= 4; ++n) {
    const fs::path dir = fresh_dir("ho_cgns" + std::to_string(n));
    const std::string path = (dir / "m.cgns").string();
    write_mesh(lattice_mesh(n), path);
    int fn = -1;
    CG(cg_open(path.c_str(), CG_MODE_READ, &fn));
    int nsections = 0;
    CG(cg_nsections(fn, 1, 1, &nsections));
    ASSERT_EQ(nsections, 2);
    for (int s = 1; s <= 2; ++s) {
      char name[33];
      CGNS_ENUMT(ElementType_t) type{};
      cgsize_t start = 0, end = 0;
      int nbndry = 0, parent = 0;
      CG(cg_section_read(fn, 1, 1, s, name, &type, &start, &end, &nbndry, &parent));
      const bool face = std::string(name) == "Face_0";
      EXPECT_EQ(type, face ? quad_type[n] : bar_type[n]) << name;
      int npe = 0;
      CG(cg_npe(type, &npe));
      EXPECT_EQ(npe, face ? (n + 1) * (n + 1) : n + 1);
      std::vector<cgsize_t> conn(static_cast<std::size_t>((end - start + 1) * npe));
      CG(cg_elements_read(fn, 1, 1, s, conn.data(), nullptr));
      if (face && n == 3) {
        for (std::size_t k = 0; k < kCgnsQuad16.size(); ++k)
          EXPECT_EQ(conn[k], kCgnsQuad16[k] + 1) << k;
      }
      if (face && n == 4) {
        std::vector<GO> expected = kQuad25Outer;
        expected.insert(expected.end(), kCgnsQuad25Inner.begin(), kCgnsQuad25Inner.end());
        for (std::size_t k = 0; k < expected.size(); ++k) EXPECT_EQ(conn[k], expected[k] + 1) << k;
      }
    }
    CG(cg_close(fn));
#ifdef QSMESH_CGNSCHECK
    const auto issues = cgnscheck_issues(path);
    EXPECT_TRUE(issues.empty()) << n << ": " << issues.front();
#endif
  }
  // CGNS has no quads of order 5.
  const fs::path dir = fresh_dir("ho_cgns5");
  EXPECT_THROW(write_mesh(lattice_mesh(5), (dir / "m.cgns").string()), InputError);
}

TEST(HighOrderOutput, Hdf5WholeElementsInCgnsOrder) {
  // Checked by name and shape through the XDMF text: order 3 shows the corner quads.
  const fs::path dir = fresh_dir("ho_h5");
  write_mesh(lattice_mesh(3), (dir / "m.h5").string());
  const std::string x = read_all(dir / "m.xdmf");
  EXPECT_NE(x.find("TopologyType=\"Quadrilateral\" NumberOfElements=\"2\""), std::string::npos);
  EXPECT_EQ(x.find("Quadrilateral_9"), std::string::npos);
  const std::string h5 = read_all(dir / "m.h5");
  EXPECT_NE(h5.find("quad16"), std::string::npos);
  EXPECT_NE(h5.find("bar4"), std::string::npos);
}

}  // namespace
}  // namespace qsmesh::io
