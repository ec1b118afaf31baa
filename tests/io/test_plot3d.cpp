// PLOT3D output (io::write_plot3d) read back by a reader written here from the format alone, its
// sidecar's interfaces checked point by point on the coordinates read, and the same connections
// as the block-structured CGNS writer's (both come from io::block_connections).
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <array>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "io_test_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/block_connections.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/layout/quad_layout.hpp"

namespace qsmesh::io {
namespace {

namespace fs = std::filesystem;
using test::dir_entries;
using test::fresh_dir;
using test::read_all;

// Two faces side by side on the unit lattice: face 0 = [0, a] x [0, n], face 1 = [a, a + b] x
// [0, n], sharing the curve x = a (curve 5). Curves: 0 / 1 bottom of face 0 / 1, 2 / 3 top, 4 x =
// 0, 6 x = a + b. With `triangles`, face 1's cells are split into two triangles each.
mesh::SurfaceMesh two_faces(int a, int b, int n, bool triangles = false) {
  mesh::SurfaceMesh m;
  m.num_cad_faces = 2;
  m.num_cad_curves = 7;
  m.num_cad_corners = 6;
  const int nx = a + b;
  auto at = [&](int x, int y) { return static_cast<GO>(y * (nx + 1) + x); };
  for (int y = 0; y <= n; ++y) {
    for (int x = 0; x <= nx; ++x) {
      mesh::VertexClass c;
      const bool vertical = x == 0 || x == a || x == nx, horizontal = y == 0 || y == n;
      if (vertical && horizontal) {
        c.dim = 0;
        c.entity = (y == 0 ? 0 : 3) + (x == 0 ? 0 : (x == a ? 1 : 2));
      } else if (vertical || horizontal) {
        c.dim = 1;
        c.entity = vertical ? (x == 0 ? 4 : (x == a ? 5 : 6)) : (y == 0 ? 0 : 2) + (x > a ? 1 : 0);
      } else {
        c.dim = 2;
        c.entity = x < a ? 0 : 1;
      }
      // A little z so that no two coordinates agree by accident.
      m.points.push_back({static_cast<double>(x), static_cast<double>(y), 0.001 * x * y});
      m.vclass.push_back(c);
    }
  }
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < nx; ++x) {
      if (triangles && x >= a) {
        m.triangles.push_back({at(x, y), at(x + 1, y), at(x + 1, y + 1)});
        m.triangles.push_back({at(x, y), at(x + 1, y + 1), at(x, y + 1)});
        m.triangle_face.insert(m.triangle_face.end(), {1, 1});
      } else {
        m.quads.push_back({at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)});
        m.quad_face.push_back(x < a ? 0 : 1);
      }
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
  m.length_unit = "mm";
  return m;
}

// A multi-block 3D whole PLOT3D grid file, read from the format's definition.
struct Grid {
  std::vector<std::array<std::int32_t, 3>> dims;
  std::vector<std::vector<double>> xyz;  // per block: x over its points, then y, then z
  std::string error;
};

Grid read_grid(const std::string& path, bool records, bool single) {
  Grid g;
  const std::string bytes = read_all(path);
  std::size_t at = 0;
  auto take = [&](void* to, std::size_t n) {
    if (at + n > bytes.size()) throw std::runtime_error("file ends early");
    std::memcpy(to, bytes.data() + at, n);
    at += n;
  };
  auto marker = [&](std::size_t expected) {
    if (!records) return;
    std::int32_t n = 0;
    take(&n, sizeof n);
    if (static_cast<std::size_t>(n) != expected)
      throw std::runtime_error("record length " + std::to_string(n) + ", expected " +
                               std::to_string(expected));
  };
  try {
    std::int32_t nb = 0;
    marker(4);
    take(&nb, 4);
    marker(4);
    g.dims.resize(static_cast<std::size_t>(nb));
    marker(12 * static_cast<std::size_t>(nb));
    for (auto& d : g.dims) take(d.data(), 12);
    marker(12 * static_cast<std::size_t>(nb));
    for (const auto& d : g.dims) {
      const std::size_t n = 3 * static_cast<std::size_t>(d[0]) * d[1] * d[2];
      const std::size_t size = single ? 4 : 8;
      marker(n * size);
      std::vector<double> v(n);
      for (double& x : v) {
        if (single) {
          float f = 0;
          take(&f, 4);
          x = f;
        } else {
          take(&x, 8);
        }
      }
      marker(n * size);
      g.xyz.push_back(std::move(v));
    }
    if (at != bytes.size()) throw std::runtime_error("bytes after the last block");
  } catch (const std::exception& e) {
    g.error = e.what();
  }
  return g;
}

// One interface line of the sidecar.
struct SidecarInterface {
  int block, donor;
  std::array<int, 4> range, donor_range;
  std::array<int, 2> transform;
};

struct Sidecar {
  std::vector<SidecarInterface> interfaces;
  std::vector<std::pair<int, std::string>> boundaries;  // block, family
  int against_left_out = 0;
  std::string left_out_faces;
};

Sidecar read_sidecar(const std::string& path) {
  Sidecar s;
  std::ifstream in(path);
  const std::regex block_re(R"(\{"block": (\d+),)");
  const std::regex iface_re(
      R"re(\{"side": "\w+", "range": \[\[(\d+), (\d+)\], \[(\d+), (\d+)\]\], "donor": (\d+), "donor_side": "\w+", "donor_range": \[\[(\d+), (\d+)\], \[(\d+), (\d+)\]\], "transform": \[(-?\d), (-?\d)\]\})re");
  const std::regex bc_re(R"re("family": "(Curve_\d+)", "curve")re");
  const std::regex abut_re(
      R"re(^\s*\{"side": "\w+", "range": \[\[\d+, \d+\], \[\d+, \d+\]\]\},?$)re");
  const std::regex left_re(R"re("left_out_faces": \[([^\]]*)\])re");
  int block = 0;
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_search(line, m, block_re)) block = std::stoi(m[1]);
    if (std::regex_search(line, m, iface_re)) {
      SidecarInterface i{};
      i.block = block;
      for (int k = 0; k < 4; ++k) i.range[k] = std::stoi(m[1 + k]);
      i.donor = std::stoi(m[5]);
      for (int k = 0; k < 4; ++k) i.donor_range[k] = std::stoi(m[6 + k]);
      i.transform = {std::stoi(m[10]), std::stoi(m[11])};
      s.interfaces.push_back(i);
    } else if (std::regex_search(line, m, bc_re)) {
      s.boundaries.emplace_back(block, m[1]);
    } else if (std::regex_search(line, m, abut_re)) {
      ++s.against_left_out;
    }
    if (std::regex_search(line, m, left_re)) s.left_out_faces = m[1];
  }
  return s;
}

// The point (i, j) (1-based) of block b of the grid.
std::array<double, 3> point(const Grid& g, int b, int i, int j) {
  const auto& d = g.dims[static_cast<std::size_t>(b)];
  const auto& v = g.xyz[static_cast<std::size_t>(b)];
  const std::size_t n = static_cast<std::size_t>(d[0]) * d[1] * d[2];
  const std::size_t at = static_cast<std::size_t>(j - 1) * d[0] + (i - 1);
  return {v[at], v[n + at], v[2 * n + at]};
}

// Every interface of the sidecar joins the same coordinates point by point: this block's range
// walked from its first point to its last, the donor's in the same order.
void expect_interfaces_join_the_same_points(const Grid& g, const Sidecar& s) {
  for (const SidecarInterface& f : s.interfaces) {
    const int n = std::max(std::abs(f.range[2] - f.range[0]), std::abs(f.range[3] - f.range[1]));
    ASSERT_EQ(n, std::max(std::abs(f.donor_range[2] - f.donor_range[0]),
                          std::abs(f.donor_range[3] - f.donor_range[1])));
    auto step = [](int a, int b) { return a < b ? 1 : (a > b ? -1 : 0); };
    for (int t = 0; t <= n; ++t) {
      const auto p = point(g, f.block - 1, f.range[0] + t * step(f.range[0], f.range[2]),
                           f.range[1] + t * step(f.range[1], f.range[3]));
      const auto q =
          point(g, f.donor - 1, f.donor_range[0] + t * step(f.donor_range[0], f.donor_range[2]),
                f.donor_range[1] + t * step(f.donor_range[1], f.donor_range[3]));
      EXPECT_EQ(p, q) << "interface of block " << f.block << " with block " << f.donor;
    }
  }
}

TEST(Plot3d, ReadBack) {
  const fs::path dir = fresh_dir("plot3d_readback");
  const mesh::SurfaceMesh m = two_faces(4, 2, 3);
  const layout::QuadLayout l = layout::extract_quad_layout(m);
  ASSERT_EQ(l.blocks.size(), 2u);
  const std::string path = (dir / "two.xyz").string();
  const Plot3dReport report = write_plot3d(m, l, path);
  EXPECT_EQ(report.blocks, 2);
  EXPECT_TRUE(report.skipped_faces.empty());
  EXPECT_EQ(dir_entries(dir), (std::vector<std::string>{"two.xyz", "two.xyz.json"}));

  const Grid g = read_grid(path, true, false);
  ASSERT_EQ(g.error, "");
  ASSERT_EQ(g.dims.size(), 2u);
  std::int64_t points = 0;
  for (std::size_t k = 0; k < 2; ++k) {
    const layout::Block& b = l.blocks[k];
    EXPECT_EQ(g.dims[k], (std::array<std::int32_t, 3>{b.ni + 1, b.nj + 1, 1}));
    points += static_cast<std::int64_t>(g.dims[k][0]) * g.dims[k][1];
    for (LO j = 0; j <= b.nj; ++j)
      for (LO i = 0; i <= b.ni; ++i) {
        const Vec3& x = m.points[static_cast<std::size_t>(b.vertex(i, j, l.vertices))];
        EXPECT_EQ(point(g, static_cast<int>(k), i + 1, j + 1),
                  (std::array<double, 3>{x[0], x[1], x[2]}));
      }
  }
  // 5 x 4 points in face 0's block, 3 x 4 in face 1's: the shared curve's 4 points are in both.
  EXPECT_EQ(points, 5 * 4 + 3 * 4);

  const Sidecar s = read_sidecar(plot3d_connections_path(path));
  // One interface each way along the shared curve, 3 edges; BCs on the three other sides of each.
  ASSERT_EQ(s.interfaces.size(), 2u);
  EXPECT_EQ(s.interfaces[0].block, 1);
  EXPECT_EQ(s.interfaces[0].donor, 2);
  EXPECT_EQ(s.interfaces[1].block, 2);
  EXPECT_EQ(s.interfaces[1].donor, 1);
  expect_interfaces_join_the_same_points(g, s);
  EXPECT_EQ(s.boundaries.size(), 6u);
  std::map<std::string, int> families;
  for (const auto& [block, family] : s.boundaries) families[family] += 1;
  EXPECT_EQ(families, (std::map<std::string, int>{{"Curve_0", 1},
                                                  {"Curve_1", 1},
                                                  {"Curve_2", 1},
                                                  {"Curve_3", 1},
                                                  {"Curve_4", 1},
                                                  {"Curve_6", 1}}));
  EXPECT_EQ(s.against_left_out, 0);
  EXPECT_EQ(s.left_out_faces, "");

  // The sidecar's interfaces are block_connections' (what the CGNS block writer writes).
  const BlockConnections joined = block_connections(m, l);
  std::size_t at = 0;
  for (std::size_t k = 0; k < joined.blocks.size(); ++k)
    for (const BlockInterface& i : joined.blocks[k].interfaces) {
      ASSERT_LT(at, s.interfaces.size());
      const SidecarInterface& f = s.interfaces[at++];
      EXPECT_EQ(f.block, static_cast<int>(k) + 1);
      EXPECT_EQ(f.donor, static_cast<int>(i.donor) + 1);
      EXPECT_EQ(f.range, (std::array<int, 4>{i.range[0], i.range[1], i.range[2], i.range[3]}));
      EXPECT_EQ(f.donor_range, (std::array<int, 4>{i.donor_range[0], i.donor_range[1],
                                                   i.donor_range[2], i.donor_range[3]}));
      EXPECT_EQ(f.transform, i.transform);
    }
  EXPECT_EQ(at, s.interfaces.size());
}

TEST(Plot3d, StreamAndSinglePrecision) {
  const fs::path dir = fresh_dir("plot3d_forms");
  const mesh::SurfaceMesh m = two_faces(3, 2, 2);
  const layout::QuadLayout l = layout::extract_quad_layout(m);
  const std::string fortran = (dir / "f.xyz").string(), stream = (dir / "s.xyz").string(),
                    single = (dir / "single.p3d").string();
  (void)write_plot3d(m, l, fortran);
  WriteOptions o;
  o.plot3d_fortran_records = false;
  (void)write_plot3d(m, l, stream, o);
  o.plot3d_fortran_records = true;
  o.plot3d_single_precision = true;
  (void)write_plot3d(m, l, single, o);
  // The stream form is the Fortran form without its 2 + 2 + 2 x blocks record lengths.
  const std::size_t nb = l.blocks.size();
  EXPECT_EQ(fs::file_size(fortran), fs::file_size(stream) + 8 * (2 + nb));
  const Grid f = read_grid(fortran, true, false), s = read_grid(stream, false, false),
             g = read_grid(single, true, true);
  ASSERT_EQ(f.error, "");
  ASSERT_EQ(s.error, "");
  ASSERT_EQ(g.error, "");
  EXPECT_EQ(f.dims, s.dims);
  EXPECT_EQ(f.xyz, s.xyz);
  EXPECT_EQ(f.dims, g.dims);
  for (std::size_t k = 0; k < nb; ++k)
    for (std::size_t i = 0; i < f.xyz[k].size(); ++i)
      EXPECT_EQ(g.xyz[k][i], static_cast<double>(static_cast<float>(f.xyz[k][i])));
  // Read as the wrong form, the reader must notice (it is what the other tests trust).
  EXPECT_NE(read_grid(stream, true, false).error, "");
  EXPECT_NE(read_grid(fortran, false, false).error, "");
  EXPECT_NE(read_grid(single, true, false).error, "");
  // The sidecar says which form it describes.
  EXPECT_NE(read_all(plot3d_connections_path(stream)).find("\"form\": \"stream\""),
            std::string::npos);
  EXPECT_NE(read_all(plot3d_connections_path(single)).find("\"precision\": \"single\""),
            std::string::npos);
  // write_mesh picks PLOT3D from the extension and makes the layout itself: the same bytes.
  const std::string via = (dir / "via.xyz").string();
  write_mesh(m, via);
  EXPECT_EQ(read_all(via), read_all(fortran));
}

TEST(Plot3d, FacesWithTrianglesAreLeftOutAndListed) {
  const fs::path dir = fresh_dir("plot3d_triangles");
  const mesh::SurfaceMesh m = two_faces(2, 2, 2, true);
  const layout::QuadLayout l = layout::extract_quad_layout(m);
  ASSERT_EQ(l.unblocked_faces, std::vector<LO>{1});
  const std::string path = (dir / "mixed.xyz").string();
  const Plot3dReport report = write_plot3d(m, l, path);
  EXPECT_EQ(report.blocks, 1);
  EXPECT_EQ(report.skipped_faces, std::vector<LO>{1});
  EXPECT_EQ(report.skipped_triangles, 8);
  EXPECT_EQ(report.skipped_quads, 0);
  const Grid g = read_grid(path, true, false);
  ASSERT_EQ(g.error, "");
  ASSERT_EQ(g.dims.size(), 1u);
  const Sidecar s = read_sidecar(plot3d_connections_path(path));
  EXPECT_TRUE(s.interfaces.empty());
  // The block's side on the shared curve runs along the triangles (listed, not a wall); BCs on
  // its three other sides.
  EXPECT_EQ(s.against_left_out, 1);
  EXPECT_EQ(s.boundaries.size(), 3u);
  EXPECT_EQ(s.left_out_faces, "1");
}

TEST(Plot3d, NothingIsLeftWhenTheFolderIsMissing) {
  const fs::path dir = fresh_dir("plot3d_missing");
  const mesh::SurfaceMesh m = two_faces(2, 2, 2);
  const layout::QuadLayout l = layout::extract_quad_layout(m);
  EXPECT_THROW((void)write_plot3d(m, l, (dir / "no" / "x.xyz").string()), InputError);
  EXPECT_TRUE(dir_entries(dir).empty());
  // A layout that does not fit the mesh is refused before anything is written.
  layout::QuadLayout bad = l;
  bad.vertices.back() = m.num_vertices();
  EXPECT_THROW((void)write_plot3d(m, bad, (dir / "x.xyz").string()), Error);
  EXPECT_TRUE(dir_entries(dir).empty());
}

TEST(Plot3d, FullDiskIsOneOutputErrorAndLeavesTheEarlierPair) {
  // A file size limit below the grid file's size fails the write as a full disk does: one
  // OutputError naming the file, no temporary left, the earlier grid and sidecar untouched.
  const fs::path dir = fresh_dir("plot3d_full");
  std::ofstream(dir / "m.xyz") << "an earlier grid";
  std::ofstream(dir / "m.xyz.json") << "an earlier sidecar";
  const mesh::SurfaceMesh m = two_faces(60, 60, 60);  // 7381 points: 177 kB of coordinates
  const layout::QuadLayout l = layout::extract_quad_layout(m);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  rlimit small = old;
  small.rlim_cur = 64 * 1024;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string message;
  try {
    (void)write_plot3d(m, l, (dir / "m.xyz").string());
  } catch (const OutputError& e) {
    message = e.what();
  }
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_NE(message.find("m.xyz"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(dir_entries(dir), (std::vector<std::string>{"m.xyz", "m.xyz.json"}));
  EXPECT_EQ(read_all(dir / "m.xyz"), "an earlier grid");
  EXPECT_EQ(read_all(dir / "m.xyz.json"), "an earlier sidecar");
}

}  // namespace
}  // namespace qsmesh::io
