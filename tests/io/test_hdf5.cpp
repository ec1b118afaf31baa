// HDF5 output read back through the HDF5 C API, and its XDMF description.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/resource.h>

#include <chrono>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "io_test_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/writer.hpp"

namespace qsmesh::io {
namespace {

namespace fs = std::filesystem;
using test::dir_entries;
using test::fresh_dir;
using test::make_test_mesh;
using test::read_all;

// A dataset read back: its dimensions and values converted to T by HDF5.
template <typename T>
struct Data {
  std::vector<hsize_t> dims;
  std::vector<T> values;
};

template <typename T>
Data<T> read_dataset(hid_t file, const char* name, hid_t mem_type) {
  Data<T> d;
  const hid_t set = H5Dopen2(file, name, H5P_DEFAULT);
  EXPECT_GE(set, 0) << name;
  if (set < 0) return d;
  const hid_t space = H5Dget_space(set);
  const int rank = H5Sget_simple_extent_ndims(space);
  d.dims.resize(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space, d.dims.data(), nullptr);
  hsize_t n = 1;
  for (hsize_t x : d.dims) n *= x;
  d.values.resize(n);
  if (n > 0) {
    EXPECT_GE(H5Dread(set, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, d.values.data()), 0) << name;
  }
  H5Sclose(space);
  H5Dclose(set);
  return d;
}

std::int64_t read_int_attribute(hid_t file, const char* name) {
  std::int64_t v = -12345;
  const hid_t a = H5Aopen(file, name, H5P_DEFAULT);
  EXPECT_GE(a, 0) << name;
  if (a < 0) return v;
  EXPECT_GE(H5Aread(a, H5T_NATIVE_INT64, &v), 0) << name;
  H5Aclose(a);
  return v;
}

std::string read_string_attribute(hid_t file, const char* name) {
  const hid_t a = H5Aopen(file, name, H5P_DEFAULT);
  EXPECT_GE(a, 0) << name;
  if (a < 0) return {};
  const hid_t type = H5Aget_type(a);
  std::string s(H5Tget_size(type), '\0');
  EXPECT_GE(H5Aread(a, type, s.data()), 0) << name;
  H5Tclose(type);
  H5Aclose(a);
  return s.substr(0, s.find('\0'));
}

std::vector<hsize_t> dims(std::initializer_list<hsize_t> d) { return d; }

// Dataset `name` holds `elements` (rows of N ids, in order) and `cad_name` their CAD ids.
template <std::size_t N>
void expect_elements(hid_t file, const char* name, const char* cad_name,
                     const std::vector<std::array<GO, N>>& elements, const std::vector<LO>& cad) {
  const auto ids = read_dataset<std::int64_t>(file, name, H5T_NATIVE_INT64);
  const auto entity = read_dataset<std::int32_t>(file, cad_name, H5T_NATIVE_INT32);
  EXPECT_EQ(ids.dims, (std::vector<hsize_t>{elements.size(), N})) << name;
  ASSERT_EQ(ids.values.size(), N * elements.size()) << name;
  ASSERT_EQ(entity.values.size(), elements.size()) << cad_name;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    for (std::size_t k = 0; k < N; ++k) EXPECT_EQ(ids.values[N * e + k], elements[e][k]) << name;
    EXPECT_EQ(entity.values[e], cad[e]) << cad_name;
  }
}

TEST(Hdf5, ReadBack) {
  const fs::path dir = fresh_dir("hdf5_read");
  const mesh::SurfaceMesh m = make_test_mesh();
  const std::string path = (dir / "m.h5").string();
  write_mesh(m, path);
  EXPECT_EQ(dir_entries(dir), (std::vector<std::string>{"m.h5", "m.xdmf"}));

  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  EXPECT_EQ(read_string_attribute(file, "format"), "qsmesh surface mesh");
  EXPECT_EQ(read_int_attribute(file, "format_version"), 2);
  EXPECT_EQ(read_string_attribute(file, "length_unit"), "mm");
  EXPECT_EQ(read_int_attribute(file, "num_cad_corners"), 7);
  EXPECT_EQ(read_int_attribute(file, "num_cad_curves"), 10);
  EXPECT_EQ(read_int_attribute(file, "num_cad_faces"), 4);

  const auto xyz = read_dataset<double>(file, "coordinates", H5T_NATIVE_DOUBLE);
  EXPECT_EQ(xyz.dims, dims({12, 3}));
  ASSERT_EQ(xyz.values.size(), 36u);
  for (std::size_t v = 0; v < 12; ++v)
    for (int d = 0; d < 3; ++d) EXPECT_EQ(xyz.values[3 * v + d], m.points[v][d]) << v;

  const auto dim = read_dataset<std::int32_t>(file, "vertex_cad_dim", H5T_NATIVE_INT32);
  const auto entity = read_dataset<std::int32_t>(file, "vertex_cad_entity", H5T_NATIVE_INT32);
  const auto param = read_dataset<double>(file, "vertex_cad_param", H5T_NATIVE_DOUBLE);
  EXPECT_EQ(dim.dims, dims({12}));
  EXPECT_EQ(param.dims, dims({12, 2}));
  ASSERT_EQ(entity.values.size(), 12u);
  ASSERT_EQ(param.values.size(), 24u);
  for (std::size_t v = 0; v < 12; ++v) {
    EXPECT_EQ(dim.values[v], m.vclass[v].dim) << v;
    EXPECT_EQ(entity.values[v], m.vclass[v].entity) << v;
    EXPECT_EQ(param.values[2 * v], m.vclass[v].param[0]) << v;
    EXPECT_EQ(param.values[2 * v + 1], m.vclass[v].param[1]) << v;
  }

  // Elements in mesh order, 0-based, with their CAD entity.
  expect_elements(file, "quads", "quad_cad_face", m.quads, m.quad_face);
  expect_elements(file, "triangles", "triangle_cad_face", m.triangles, m.triangle_face);
  expect_elements(file, "bars", "bar_cad_curve", m.bars, m.bar_curve);

  // CAD topology.
  const auto cc = read_dataset<std::int32_t>(file, "curve_corners", H5T_NATIVE_INT32);
  EXPECT_EQ(cc.dims, dims({10, 2}));
  ASSERT_EQ(cc.values.size(), 20u);
  for (std::size_t c = 0; c < 10; ++c) {
    EXPECT_EQ(cc.values[2 * c], m.curve_corners[c][0]);
    EXPECT_EQ(cc.values[2 * c + 1], m.curve_corners[c][1]);
  }
  const auto off = read_dataset<std::int64_t>(file, "face_curve_offsets", H5T_NATIVE_INT64);
  const auto fc = read_dataset<std::int32_t>(file, "face_curves", H5T_NATIVE_INT32);
  ASSERT_EQ(off.values.size(), m.face2curves.offsets.size());
  for (std::size_t i = 0; i < off.values.size(); ++i)
    EXPECT_EQ(off.values[i], m.face2curves.offsets[i]);
  EXPECT_EQ(fc.values, m.face2curves.targets);
  H5Fclose(file);

  // The XDMF description names the datasets with their shapes, one grid per element kind.
  const std::string x = read_all(dir / "m.xdmf");
  EXPECT_EQ(x.rfind("<?xml", 0), 0u);
  for (const char* s :
       {"TopologyType=\"Quadrilateral\" NumberOfElements=\"3\"",
        "Dimensions=\"3 4\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">m.h5:/quads<",
        "TopologyType=\"Triangle\" NumberOfElements=\"6\"",
        "Dimensions=\"6 3\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">m.h5:/triangles<",
        "TopologyType=\"Polyline\" NumberOfElements=\"13\" NodesPerElement=\"2\"",
        "Dimensions=\"12 3\" NumberType=\"Float\" Precision=\"8\" "
        "Format=\"HDF\">m.h5:/coordinates<",
        ">m.h5:/quad_cad_face<", ">m.h5:/bar_cad_curve<", "Name=\"cad_entity\"", "</Xdmf>"})
    EXPECT_NE(x.find(s), std::string::npos) << s;
}

TEST(Hdf5, EmptyKindsAreZeroRowsAndNoGrid) {
  const fs::path dir = fresh_dir("hdf5_empty");
  mesh::SurfaceMesh m = make_test_mesh();
  m.triangles.clear();
  m.triangle_face.clear();
  const std::string path = (dir / "q.h5").string();
  write_hdf5(m, path);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  EXPECT_EQ(read_dataset<std::int64_t>(file, "triangles", H5T_NATIVE_INT64).dims, dims({0, 3}));
  EXPECT_EQ(read_dataset<std::int32_t>(file, "triangle_cad_face", H5T_NATIVE_INT32).dims,
            dims({0}));
  EXPECT_EQ(read_dataset<std::int64_t>(file, "quads", H5T_NATIVE_INT64).dims, dims({3, 4}));
  H5Fclose(file);
  const std::string x = read_all(dir / "q.xdmf");
  EXPECT_EQ(x.find("Triangle"), std::string::npos);
  EXPECT_NE(x.find("Quadrilateral"), std::string::npos);
}

// Two quads [0,1]x[0,1] and [1,2]x[0,1] of face 0, bounded by the closed curve 0 at corner 0,
// with second-order nodes: edge midpoints 6..12, centres 13 and 14.
mesh::SurfaceMesh make_quadratic_mesh() {
  mesh::SurfaceMesh m;
  m.num_cad_corners = 1;
  m.num_cad_curves = 1;
  m.num_cad_faces = 1;
  m.points = {{0, 0, 0},   {1, 0, 0},   {2, 0, 0},   {0, 1, 0},       {1, 1, 0},
              {2, 1, 0},   {0.5, 0, 0}, {1, 0.5, 0}, {0.5, 1, 0},     {0, 0.5, 0},
              {1.5, 0, 0}, {2, 0.5, 0}, {1.5, 1, 0}, {0.5, 0.5, 0.1}, {1.5, 0.5, 0.1}};
  m.vclass.assign(m.points.size(), {1, 0, kNoIndex, {0, 0}});
  m.vclass[0] = {0, 0, kNoIndex, {0, 0}};
  for (std::size_t v : {std::size_t{7}, std::size_t{13}, std::size_t{14}})
    m.vclass[v] = {2, 0, kNoIndex, {0.25, 0.25}};
  m.quads = {{0, 1, 4, 3}, {1, 2, 5, 4}};
  m.quad_face = {0, 0};
  m.order = 2;
  m.quad_nodes = {6, 7, 8, 9, 13, 10, 11, 12, 7, 14};
  m.bars = {{0, 1}, {1, 2}, {2, 5}, {5, 4}, {4, 3}, {3, 0}};
  m.bar_curve.assign(m.bars.size(), 0);
  m.bar_nodes = {6, 10, 11, 12, 8, 9};
  m.curve_corners = {{0, 0}};
  m.face2curves = Adjacency::from_pairs(1, {{0, 0}});
  return m;
}

TEST(Hdf5, SecondOrderWholeConnectivitiesAndXdmf) {
  // quad9 / bar3 hold corners then nodes (the order of CGNS QUAD_9 / BAR_3), and the XDMF
  // description shows them as 9-node quads and 3-node edges.
  const fs::path dir = fresh_dir("hdf5_order2");
  const mesh::SurfaceMesh m = make_quadratic_mesh();
  const std::string path = (dir / "q2.h5").string();
  write_mesh(m, path);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const auto quad9 = read_dataset<std::int64_t>(file, "quad9", H5T_NATIVE_INT64);
  EXPECT_EQ(quad9.dims, dims({2, 9}));
  EXPECT_EQ(quad9.values,
            (std::vector<std::int64_t>{0, 1, 4, 3, 6, 7, 8, 9, 13, 1, 2, 5, 4, 10, 11, 12, 7, 14}));
  const auto bar3 = read_dataset<std::int64_t>(file, "bar3", H5T_NATIVE_INT64);
  EXPECT_EQ(bar3.dims, dims({6, 3}));
  EXPECT_EQ(bar3.values,
            (std::vector<std::int64_t>{0, 1, 6, 1, 2, 10, 2, 5, 11, 5, 4, 12, 4, 3, 8, 3, 0, 9}));
  const auto quads = read_dataset<std::int64_t>(file, "quads", H5T_NATIVE_INT64);
  EXPECT_EQ(quads.dims, dims({2, 4}));
  H5Fclose(file);
  const std::string x = read_all(dir / "q2.xdmf");
  for (const char* s :
       {"TopologyType=\"Quadrilateral_9\" NumberOfElements=\"2\"",
        "Dimensions=\"2 9\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">q2.h5:/quad9<",
        "TopologyType=\"Edge_3\" NumberOfElements=\"6\"",
        "Dimensions=\"6 3\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">q2.h5:/bar3<"})
    EXPECT_NE(x.find(s), std::string::npos) << s;
  EXPECT_EQ(x.find("TopologyType=\"Quadrilateral\""), std::string::npos);
}

TEST(Hdf5, FullDiskIsOneOutputErrorAndLeavesNothing) {
  // A file size limit below the file's size: the write fails as the disk being full does. The
  // writer reports it as one OutputError naming the file, leaves no temporary, and the file of an
  // earlier run under the same name is untouched.
  const fs::path dir = fresh_dir("hdf5_full");
  {
    std::ofstream old(dir / "m.h5");
    old << "an earlier run";
  }
  mesh::SurfaceMesh m = make_test_mesh();
  for (int k = 0; k < 20000; ++k) {  // unused points, to make the file larger than the limit
    m.points.push_back({static_cast<double>(k), 0, 0});
    m.vclass.push_back({2, 1, kNoIndex, {0, 0}});
  }
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  rlimit small = old;
  small.rlim_cur = 64 * 1024;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string message;
  try {
    write_mesh(m, (dir / "m.h5").string());
  } catch (const OutputError& e) {
    message = e.what();
  }
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_NE(message.find("cannot write " + (dir / "m.h5").string()), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(dir_entries(dir), std::vector<std::string>{"m.h5"});
  EXPECT_EQ(read_all(dir / "m.h5"), "an earlier run");
}

TEST(Hdf5, TheTwoFilesLandTogether) {
  // The description cannot land (its name is a folder with something in it): the new .h5 is not
  // left beside the earlier description, and the earlier .h5 is back, as before the run.
  const fs::path dir = fresh_dir("hdf5_pair");
  {
    std::ofstream old(dir / "m.h5");
    old << "an earlier run";
  }
  fs::create_directories(dir / "m.xdmf");
  {
    std::ofstream inside(dir / "m.xdmf" / "x");
    inside << "x";
  }
  EXPECT_THROW(write_hdf5(make_test_mesh(), (dir / "m.h5").string()), OutputError);
  EXPECT_EQ(dir_entries(dir), (std::vector<std::string>{"m.h5", "m.xdmf"}));
  EXPECT_EQ(read_all(dir / "m.h5"), "an earlier run");
  // Without an earlier .h5 nothing is left at all.
  fs::remove(dir / "m.h5");
  EXPECT_THROW(write_hdf5(make_test_mesh(), (dir / "m.h5").string()), OutputError);
  EXPECT_EQ(dir_entries(dir), std::vector<std::string>{"m.xdmf"});
}

TEST(Hdf5, NoClockInTheBytes) {
  // Two writes more than a second apart (HDF5 object times have one-second resolution).
  const fs::path dir = fresh_dir("hdf5_clock");
  write_mesh(make_test_mesh(), (dir / "a.h5").string());
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  write_mesh(make_test_mesh(), (dir / "b.h5").string());
  const std::string a = read_all(dir / "a.h5");
  EXPECT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == read_all(dir / "b.h5"));
}

TEST(Hdf5, FailuresLeaveNothing) {
  const fs::path dir = fresh_dir("hdf5_fail");
  // The description's name is taken by a folder: refused before any work.
  fs::create_directories(dir / "m.xdmf");
  EXPECT_THROW(check_output_path((dir / "m.h5").string()), InputError);
  EXPECT_THROW(write_mesh(make_test_mesh(), (dir / "m.h5").string()), InputError);
  EXPECT_EQ(dir_entries(dir), std::vector<std::string>{"m.xdmf"});
  // XDMF splits "file:/dataset" at the first colon: such a name is refused before any work.
  EXPECT_THROW(check_output_path((dir / "a:b.h5").string()), InputError);
  // An inconsistent mesh: Error, and neither file nor temporary.
  mesh::SurfaceMesh bad = make_test_mesh();
  bad.quads[0][2] = 99;
  EXPECT_THROW(write_hdf5(bad, (dir / "n.h5").string()), Error);
  EXPECT_EQ(dir_entries(dir), std::vector<std::string>{"m.xdmf"});
}

}  // namespace
}  // namespace qsmesh::io
