// VTU output parsed back (ASCII and base64 binary arrays).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "io_test_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/writer.hpp"

namespace qsmesh::io {
namespace {

namespace fs = std::filesystem;
using test::fresh_dir;
using test::make_test_mesh;
using test::read_all;

std::vector<unsigned char> base64_decode(const std::string& s) {
  std::vector<unsigned char> out;
  std::uint32_t acc = 0;
  int bits = 0;
  for (char c : s) {
    int v = -1;
    if (c >= 'A' && c <= 'Z')
      v = c - 'A';
    else if (c >= 'a' && c <= 'z')
      v = c - 'a' + 26;
    else if (c >= '0' && c <= '9')
      v = c - '0' + 52;
    else if (c == '+')
      v = 62;
    else if (c == '/')
      v = 63;
    else
      continue;  // padding, blanks
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((acc >> bits) & 0xFF));
    }
  }
  return out;
}

struct Array {
  std::string type;
  int components = 1;
  std::vector<double> values;  // every type read back as double
};

std::string attribute(const std::string& tag, const std::string& key) {
  const auto p = tag.find(" " + key + "=\"");
  if (p == std::string::npos) return {};
  const auto b = p + key.size() + 3;
  return tag.substr(b, tag.find('"', b) - b);
}

template <class T>
void append_values(const std::vector<unsigned char>& bytes, std::vector<double>& out) {
  for (std::size_t i = 0; i + sizeof(T) <= bytes.size(); i += sizeof(T)) {
    T v;
    std::memcpy(&v, bytes.data() + i, sizeof(T));
    out.push_back(static_cast<double>(v));
  }
}

// Every DataArray by Name, decoded. Binary: a base64 block for the UInt64 byte count (12 chars
// with padding), then one for the data.
std::map<std::string, Array> parse_arrays(const std::string& xml) {
  std::map<std::string, Array> arrays;
  std::size_t pos = 0;
  while ((pos = xml.find("<DataArray", pos)) != std::string::npos) {
    const auto tag_end = xml.find('>', pos);
    const std::string tag = xml.substr(pos, tag_end - pos);
    const auto body_end = xml.find("</DataArray>", tag_end);
    const std::string body = xml.substr(tag_end + 1, body_end - tag_end - 1);
    Array a;
    a.type = attribute(tag, "type");
    if (!attribute(tag, "NumberOfComponents").empty())
      a.components = std::stoi(attribute(tag, "NumberOfComponents"));
    if (attribute(tag, "format") == "binary") {
      std::string text;
      for (char c : body)
        if (!std::isspace(static_cast<unsigned char>(c))) text += c;
      const auto header = base64_decode(text.substr(0, 12));
      std::uint64_t nbytes = 0;
      std::memcpy(&nbytes, header.data(), 8);
      const auto data = base64_decode(text.substr(12));
      EXPECT_EQ(data.size(), nbytes) << tag;
      if (a.type == "Float64")
        append_values<double>(data, a.values);
      else if (a.type == "Int32")
        append_values<std::int32_t>(data, a.values);
      else if (a.type == "Int64")
        append_values<std::int64_t>(data, a.values);
      else if (a.type == "UInt8")
        append_values<std::uint8_t>(data, a.values);
      else
        ADD_FAILURE() << "type " << a.type;
    } else {
      std::istringstream in(body);
      for (double v; in >> v;) a.values.push_back(v);
    }
    arrays[attribute(tag, "Name")] = a;
    pos = body_end;
  }
  return arrays;
}

void check_basic(const std::string& xml, const mesh::SurfaceMesh& m, std::size_t ncells) {
  EXPECT_NE(xml.find("<VTKFile type=\"UnstructuredGrid\""), std::string::npos);
  EXPECT_NE(xml.find("NumberOfPoints=\"12\" NumberOfCells=\"" + std::to_string(ncells) + "\""),
            std::string::npos);
  auto arrays = parse_arrays(xml);
  ASSERT_TRUE(arrays.count("Points"));
  EXPECT_EQ(arrays["Points"].components, 3);
  ASSERT_EQ(arrays["Points"].values.size(), 36u);
  EXPECT_EQ(arrays["Points"].values[3 * 11 + 2], 0.25);
  EXPECT_EQ(arrays["Points"].values[3 * 11 + 0], 3.5);
  EXPECT_EQ(arrays["cad_face"].type, "Int32");
  std::vector<double> face(ncells, -1);
  for (std::size_t e = 0; e < 6; ++e) face[e] = m.triangle_face[e];
  for (std::size_t e = 0; e < 3; ++e) face[6 + e] = m.quad_face[e];
  EXPECT_EQ(arrays["cad_face"].values, face);
  std::vector<double> dim, entity;
  for (const auto& vc : m.vclass) {
    dim.push_back(vc.dim);
    entity.push_back(vc.entity);
  }
  EXPECT_EQ(arrays["cad_dim"].values, dim);
  EXPECT_EQ(arrays["cad_entity"].values, entity);
  EXPECT_EQ(arrays["cad_entity"].type, "Int32");
  ASSERT_EQ(arrays["types"].values.size(), ncells);
  for (std::size_t e = 0; e < 6; ++e) EXPECT_EQ(arrays["types"].values[e], 5);
  for (std::size_t e = 6; e < 9; ++e) EXPECT_EQ(arrays["types"].values[e], 9);
  EXPECT_EQ(arrays["offsets"].values[5], 18);
  EXPECT_EQ(arrays["offsets"].values[8], 30);
  ASSERT_GE(arrays["connectivity"].values.size(), 30u);
  EXPECT_EQ(arrays["connectivity"].values[0], 2);   // first triangle {2, 6, 8}
  EXPECT_EQ(arrays["connectivity"].values[18], 0);  // first quad {0, 7, 8, 3}
  EXPECT_EQ(arrays["connectivity"].values[21], 3);
}

TEST(Vtu, BinaryAndAsciiReadBack) {
  const fs::path dir = fresh_dir("vtu");
  const mesh::SurfaceMesh m = make_test_mesh();
  write_mesh(m, (dir / "b.vtu").string());
  WriteOptions ascii;
  ascii.vtu_binary = false;
  write_mesh(m, (dir / "a.vtu").string(), ascii);
  const std::string b = read_all(dir / "b.vtu");
  const std::string a = read_all(dir / "a.vtu");
  EXPECT_NE(b.find("format=\"binary\""), std::string::npos);
  EXPECT_EQ(b.find("format=\"ascii\""), std::string::npos);
  EXPECT_NE(a.find("format=\"ascii\""), std::string::npos);
  check_basic(b, m, 9);
  check_basic(a, m, 9);
  EXPECT_EQ(parse_arrays(a).size(), parse_arrays(b).size());
  for (const auto& [name, arr] : parse_arrays(a))
    EXPECT_EQ(arr.values, parse_arrays(b)[name].values) << name;
}

TEST(Vtu, ExtraFieldsAndBars) {
  const fs::path dir = fresh_dir("vtu_fields");
  const mesh::SurfaceMesh m = make_test_mesh();
  WriteOptions opt;
  opt.vtu_include_bars = true;
  Field cross{"cross<1>", 3, {}};
  for (int v = 0; v < 12; ++v) {
    cross.values.insert(cross.values.end(), {1.0 * v, 0.5, -0.125});
  }
  opt.point_fields.push_back(cross);
  Field quality{"quality", 1, {}};
  for (int e = 0; e < 9 + 13; ++e) quality.values.push_back(0.1 * e);
  opt.cell_fields.push_back(quality);
  for (bool binary : {true, false}) {
    opt.vtu_binary = binary;
    const std::string path = (dir / (binary ? "b.vtu" : "a.vtu")).string();
    write_vtu(m, path, opt);
    const std::string xml = read_all(path);
    check_basic(xml, m, 22);
    auto arrays = parse_arrays(xml);
    ASSERT_TRUE(arrays.count("cross&lt;1&gt;")) << "names are XML-escaped";
    EXPECT_EQ(arrays["cross&lt;1&gt;"].components, 3);
    EXPECT_EQ(arrays["cross&lt;1&gt;"].values, cross.values);
    EXPECT_EQ(arrays["quality"].values, quality.values);
    EXPECT_EQ(arrays["types"].values[21], 3);
    EXPECT_EQ(arrays["cad_curve"].values[9], 0);
    EXPECT_EQ(arrays["cad_curve"].values[21], 9);
    EXPECT_EQ(arrays["cad_curve"].values[0], -1);
    EXPECT_EQ(arrays["cad_face"].values[21], -1);
  }
  // Wrong sizes are refused before anything is written.
  opt.cell_fields[0].values.pop_back();
  EXPECT_THROW(write_vtu(m, (dir / "bad.vtu").string(), opt), Error);
  opt.cell_fields[0].values.push_back(0);
  opt.point_fields[0].components = 2;
  EXPECT_THROW(write_vtu(m, (dir / "bad.vtu").string(), opt), Error);
  EXPECT_FALSE(fs::exists(dir / "bad.vtu"));
}

TEST(Vtu, MarkersAreExtraPointsAndVertexCells) {
  const fs::path dir = fresh_dir("vtu_markers");
  const mesh::SurfaceMesh m = make_test_mesh();
  WriteOptions opt;
  opt.vtu_binary = false;
  opt.vtu_markers = {Marker{{0.5, 0.25, 0}, 3}, Marker{{1, 2, 3}, 0}};
  Field index{"singularity_index", 1, {}};
  for (int e = 0; e < 9; ++e) index.values.push_back(0);
  index.values.insert(index.values.end(), {1.0, -1.0});
  opt.cell_fields.push_back(index);
  const std::string path = (dir / "markers.vtu").string();
  write_vtu(m, path, opt);
  const std::string xml = read_all(path);
  EXPECT_NE(xml.find("NumberOfPoints=\"14\" NumberOfCells=\"11\""), std::string::npos);
  auto arrays = parse_arrays(xml);
  EXPECT_EQ(arrays["types"].values[9], 1);
  EXPECT_EQ(arrays["types"].values[10], 1);
  EXPECT_EQ(arrays["connectivity"].values.back(), 13);
  EXPECT_EQ(arrays["cad_face"].values[9], 3);
  EXPECT_EQ(arrays["cad_dim"].values[12], -1);
  EXPECT_EQ(arrays["Points"].values[3 * 13 + 2], 3.0);
  EXPECT_EQ(arrays["singularity_index"].values[10], -1.0);
}

}  // namespace
}  // namespace qsmesh::io
