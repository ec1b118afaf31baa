// MSH 4.1 output parsed back section by section.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "io_test_mesh.hpp"
#include "qsmesh/io/writer.hpp"

namespace qsmesh::io {
namespace {

namespace fs = std::filesystem;
using test::fresh_dir;
using test::make_test_mesh;
using test::read_all;

std::string section(const std::string& text, const std::string& name) {
  const auto b = text.find("$" + name + "\n");
  const auto e = text.find("$End" + name + "\n");
  if (b == std::string::npos || e == std::string::npos) return {};
  return text.substr(b + name.size() + 2, e - b - name.size() - 2);
}

TEST(Msh, ReadBack) {
  const fs::path dir = fresh_dir("msh");
  const mesh::SurfaceMesh m = make_test_mesh();
  const std::string path = (dir / "m.msh").string();
  write_mesh(m, path);
  const std::string text = read_all(path);
  EXPECT_EQ(section(text, "MeshFormat"), "4.1 0 8\n");

  // $Entities
  std::istringstream ent(section(text, "Entities"));
  int np = 0, nc = 0, ns = 0, nvol = 0;
  ent >> np >> nc >> ns >> nvol;
  EXPECT_EQ(np, 7);
  EXPECT_EQ(nc, 10);
  EXPECT_EQ(ns, 4);
  EXPECT_EQ(nvol, 0);
  for (int k = 0; k < np; ++k) {
    int tag = 0, nphys = -1;
    double x, y, z;
    ent >> tag >> x >> y >> z >> nphys;
    EXPECT_EQ(tag, k + 1);
    EXPECT_EQ(x, m.points[k].x);
    EXPECT_EQ(y, m.points[k].y);
    EXPECT_EQ(nphys, 0);
  }
  std::map<int, std::vector<int>> curve_bounds, face_bounds;
  std::map<int, std::array<double, 6>> face_box;
  for (int c = 0; c < nc; ++c) {
    int tag = 0, nphys = -1, nb = 0;
    std::array<double, 6> box;
    ent >> tag;
    for (double& b : box) ent >> b;
    ent >> nphys >> nb;
    EXPECT_EQ(tag, c + 1);
    EXPECT_EQ(nphys, 0);
    for (int i = 0; i < nb; ++i) {
      int t;
      ent >> t;
      curve_bounds[tag].push_back(t);
    }
  }
  for (int f = 0; f < ns; ++f) {
    int tag = 0, nphys = -1, nb = 0;
    std::array<double, 6> box;
    ent >> tag;
    for (double& b : box) ent >> b;
    ent >> nphys >> nb;
    EXPECT_EQ(tag, f + 1);
    face_box[tag] = box;
    for (int i = 0; i < nb; ++i) {
      int t;
      ent >> t;
      face_bounds[tag].push_back(t);
    }
  }
  EXPECT_TRUE(static_cast<bool>(ent));
  EXPECT_EQ(curve_bounds[1], (std::vector<int>{1, -2}));
  EXPECT_EQ(curve_bounds[8], (std::vector<int>{1, -1}));  // closed curve
  EXPECT_EQ(face_bounds[2], (std::vector<int>{5, 6, 7, 2}));
  EXPECT_EQ(face_bounds[3], (std::vector<int>{8}));
  EXPECT_EQ(face_box[2], (std::array<double, 6>{2, 0, 0, 4, 1, 0.25}));

  // $Nodes: every vertex once, grouped by its classification.
  std::istringstream nodes(section(text, "Nodes"));
  std::size_t nblocks = 0, nnodes = 0, minTag = 0, maxTag = 0;
  nodes >> nblocks >> nnodes >> minTag >> maxTag;
  EXPECT_EQ(nnodes, 12u);
  EXPECT_EQ(minTag, 1u);
  EXPECT_EQ(maxTag, 12u);
  EXPECT_EQ(nblocks, 7u + 4u + 1u);  // corners, curves 0 2 4 6, face 1
  std::vector<int> seen(13, 0);
  for (std::size_t b = 0; b < nblocks; ++b) {
    int dim, tag, param;
    std::size_t n;
    nodes >> dim >> tag >> param >> n;
    EXPECT_EQ(param, 0);
    std::vector<int> tags(n);
    for (int& t : tags) nodes >> t;
    for (int t : tags) {
      ASSERT_TRUE(t >= 1 && t <= 12);
      ++seen[t];
      EXPECT_EQ(m.vclass[t - 1].dim, dim);
      EXPECT_EQ(m.vclass[t - 1].entity + 1, tag);
      double x, y, z;
      nodes >> x >> y >> z;
      EXPECT_EQ(x, m.points[t - 1].x);
      EXPECT_EQ(z, m.points[t - 1].z);
    }
  }
  for (int t = 1; t <= 12; ++t) EXPECT_EQ(seen[t], 1) << t;
  EXPECT_TRUE(static_cast<bool>(nodes));

  // $Elements: contiguous tags, blocks per entity.
  std::istringstream elems(section(text, "Elements"));
  std::size_t neb = 0, nelem = 0, minE = 0, maxE = 0;
  elems >> neb >> nelem >> minE >> maxE;
  EXPECT_EQ(nelem, 7u + 13u + 9u);
  EXPECT_EQ(minE, 1u);
  EXPECT_EQ(maxE, nelem);
  EXPECT_EQ(neb,
            7u + 9u + 4u);  // corners, 9 meshed curves, face 0 quads, face 1 tris+quads, face 3
  std::size_t expect_tag = 1;
  std::map<std::pair<int, int>, int> count;  // (dim, type) -> elements
  std::map<int, int> face_elems;
  for (std::size_t b = 0; b < neb; ++b) {
    int dim, tag, type;
    std::size_t n;
    elems >> dim >> tag >> type >> n;
    const int nn = type == 15 ? 1 : type == 1 ? 2 : type == 2 ? 3 : 4;
    EXPECT_EQ(dim, type == 15 ? 0 : type == 1 ? 1 : 2);
    for (std::size_t e = 0; e < n; ++e) {
      std::size_t t;
      elems >> t;
      EXPECT_EQ(t, expect_tag++);
      for (int i = 0; i < nn; ++i) {
        int v;
        elems >> v;
        EXPECT_TRUE(v >= 1 && v <= 12);
      }
    }
    count[{dim, type}] += static_cast<int>(n);
    if (dim == 2) face_elems[tag] += static_cast<int>(n);
  }
  EXPECT_TRUE(static_cast<bool>(elems));
  EXPECT_EQ((count[{0, 15}]), 7);
  EXPECT_EQ((count[{1, 1}]), 13);
  EXPECT_EQ((count[{2, 2}]), 6);
  EXPECT_EQ((count[{2, 3}]), 3);
  EXPECT_EQ(face_elems[1], 2);
  EXPECT_EQ(face_elems[2], 5);
  EXPECT_EQ(face_elems.count(3), 0u);
  EXPECT_EQ(face_elems[4], 2);
}

TEST(Msh, WithoutCornerElements) {
  const fs::path dir = fresh_dir("msh_nocorner");
  WriteOptions opt;
  opt.msh_corner_elements = false;
  write_msh(make_test_mesh(), (dir / "m.msh").string(), opt);
  std::istringstream elems(section(read_all(dir / "m.msh"), "Elements"));
  std::size_t neb = 0, nelem = 0, minE = 0, maxE = 0;
  elems >> neb >> nelem >> minE >> maxE;
  EXPECT_EQ(neb, 13u);
  EXPECT_EQ(nelem, 22u);
  EXPECT_EQ(maxE, 22u);
}

}  // namespace
}  // namespace qsmesh::io
