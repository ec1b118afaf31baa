// A small hand-built SurfaceMesh and file helpers for the io tests.
//
//   corner 6 (1,2)                 Faces: 0 = [0,2]x[0,1], two quads (QUAD_4)
//        /\   face 3 (2 triangles)        1 = [2,4]x[0,1], one quad + four triangles (MIXED)
//  3 ---8--- 2 ----10---- 5               2 = no elements (bounded by curve 7, no bars)
//  |  f0 |  f1 quad | tris|               3 = triangle on top, two triangles (TRI_3)
//  0 ---7--- 1 ----9----- 4        Vertex 11 (3.5, 0.5) is inside face 1.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "qsmesh/mesh/surface_mesh.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::io::test {

inline mesh::SurfaceMesh make_test_mesh() {
  mesh::SurfaceMesh m;
  m.num_cad_corners = 7;
  m.num_cad_curves = 10;
  m.num_cad_faces = 4;
  const Vec3 corners[7] = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0},
                           {4, 0, 0}, {4, 1, 0}, {1, 2, 0}};
  for (LO k = 0; k < 7; ++k) {
    m.points.push_back(corners[k]);
    m.vclass.push_back({0, k, kNoIndex, {0, 0}});
  }
  // interior curve vertices 7..10 (curves 0, 2, 4, 6), then face vertex 11 (face 1)
  m.points.push_back({1, 0, 0});
  m.vclass.push_back({1, 0, 1, {0.5, 0}});
  m.points.push_back({1, 1, 0});
  m.vclass.push_back({1, 2, 1, {0.5, 0}});
  m.points.push_back({3, 0, 0});
  m.vclass.push_back({1, 4, 1, {0.5, 0}});
  m.points.push_back({3, 1, 0});
  m.vclass.push_back({1, 6, 1, {0.5, 0}});
  m.points.push_back({3.5, 0.5, 0.25});
  m.vclass.push_back({2, 1, kNoIndex, {0.75, 0.5}});
  // triangles of faces 3 and 1 interleaved (writers must group them by face)
  m.triangles = {{2, 6, 8}, {9, 4, 11}, {8, 6, 3}, {4, 5, 11}, {5, 10, 11}, {10, 9, 11}};
  m.triangle_face = {3, 1, 3, 1, 1, 1};
  m.quads = {{0, 7, 8, 3}, {1, 9, 10, 2}, {7, 1, 2, 8}};
  m.quad_face = {0, 1, 0};
  m.bars = {{0, 7}, {7, 1}, {1, 2},  {2, 8},  {8, 3}, {3, 0}, {1, 9},
            {9, 4}, {4, 5}, {5, 10}, {10, 2}, {2, 6}, {6, 3}};
  m.bar_curve = {0, 0, 1, 2, 2, 3, 4, 4, 5, 6, 6, 8, 9};
  m.curve_corners = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {1, 4},
                     {4, 5}, {5, 2}, {0, 0}, {2, 6}, {6, 3}};
  m.face2curves = Adjacency::from_pairs(4, {{0, 0},
                                            {0, 1},
                                            {0, 2},
                                            {0, 3},
                                            {1, 4},
                                            {1, 5},
                                            {1, 6},
                                            {1, 1},
                                            {2, 7},
                                            {3, 2},
                                            {3, 8},
                                            {3, 9}});
  m.length_unit = "mm";
  return m;
}

/// A fresh, empty folder under the test temp folder.
inline std::filesystem::path fresh_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(qsmesh::test::tmp_dir()) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::string read_all(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Names of the entries of a folder (hidden ones included), sorted.
inline std::vector<std::string> dir_entries(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    names.push_back(e.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace qsmesh::io::test
