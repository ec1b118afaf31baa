// VTK XML UnstructuredGrid (version 1.0, UInt64 headers). Binary arrays are inline base64: the
// 8-byte header (the byte count) and the data are encoded as two separate base64 blocks, as VTK
// writes them.
#include <bit>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "detail.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/atomic_file.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/mesh/high_order_nodes.hpp"

namespace qsmesh::io {

namespace {

static_assert(std::endian::native == std::endian::little,
              "the VTU writer assumes a little-endian host");

constexpr char kBase64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

void write_base64(OutputFile& out, const unsigned char* data, std::size_t n) {
  std::string chunk;
  chunk.reserve(4 * 3072 / 3);
  for (std::size_t i = 0; i < n; i += 3) {
    const std::uint32_t b0 = data[i];
    const std::uint32_t b1 = i + 1 < n ? data[i + 1] : 0;
    const std::uint32_t b2 = i + 2 < n ? data[i + 2] : 0;
    const std::uint32_t w = (b0 << 16) | (b1 << 8) | b2;
    chunk.push_back(kBase64[(w >> 18) & 63]);
    chunk.push_back(kBase64[(w >> 12) & 63]);
    chunk.push_back(i + 1 < n ? kBase64[(w >> 6) & 63] : '=');
    chunk.push_back(i + 2 < n ? kBase64[w & 63] : '=');
    if (chunk.size() >= 4096) {
      out << std::string_view(chunk);
      chunk.clear();
    }
  }
  out << std::string_view(chunk);
}

std::string xml_escape(const std::string& s) {
  std::string r;
  for (char c : s) {
    switch (c) {
      case '&':
        r += "&amp;";
        break;
      case '<':
        r += "&lt;";
        break;
      case '>':
        r += "&gt;";
        break;
      case '"':
        r += "&quot;";
        break;
      default:
        r += c;
    }
  }
  return r;
}

template <class T>
const char* vtk_type();
template <>
const char* vtk_type<double>() {
  return "Float64";
}
template <>
const char* vtk_type<std::int32_t>() {
  return "Int32";
}
template <>
const char* vtk_type<std::int64_t>() {
  return "Int64";
}
template <>
const char* vtk_type<std::uint8_t>() {
  return "UInt8";
}

template <class T>
void write_array(OutputFile& out, const std::string& name, int components, const std::vector<T>& v,
                 bool binary) {
  out << "        <DataArray type=\"" << vtk_type<T>() << '"';
  if (!name.empty()) out << " Name=\"" << xml_escape(name) << '"';
  if (components != 1) out << " NumberOfComponents=\"" << components << '"';
  out << " format=\"" << (binary ? "binary" : "ascii") << "\">\n";
  if (binary) {
    const std::uint64_t bytes = v.size() * sizeof(T);
    out << "          ";
    write_base64(out, reinterpret_cast<const unsigned char*>(&bytes), sizeof bytes);
    write_base64(out, reinterpret_cast<const unsigned char*>(v.data()), bytes);
    out << '\n';
  } else {
    const std::size_t per_line = components == 3 ? 3 : 12;
    for (std::size_t i = 0; i < v.size(); ++i) {
      out << (i % per_line == 0 ? "          " : " ");
      if constexpr (std::is_same_v<T, double>) {
        out << v[i];
      } else {
        out << static_cast<long long>(v[i]);
      }
      if (i % per_line == per_line - 1 || i + 1 == v.size()) out << '\n';
    }
  }
  out << "        </DataArray>\n";
}

void check_fields(const std::vector<Field>& fields, std::size_t n, const char* what,
                  const std::string& path) {
  for (const Field& f : fields) {
    QSMESH_CHECK(!f.name.empty(), "VTU output " << path << ": a " << what << " field has no name");
    QSMESH_CHECK(f.components == 1 || f.components == 3,
                 "VTU output " << path << ": " << what << " field '" << f.name << "' has "
                               << f.components << " components (1 or 3 allowed)");
    QSMESH_CHECK(f.values.size() == n * static_cast<std::size_t>(f.components),
                 "VTU output " << path << ": " << what << " field '" << f.name << "' has "
                               << f.values.size() << " values, expected "
                               << n * static_cast<std::size_t>(f.components));
  }
}

}  // namespace

void write_vtu(const mesh::SurfaceMesh& mesh, const std::string& path,
               const WriteOptions& options) {
  detail::check_output_folder(path);
  check_mesh_for_output(mesh);
  const std::size_t nm = options.vtu_markers.size();
  const std::size_t nmesh = mesh.points.size();
  const std::size_t nv = nmesh + nm;
  const std::size_t nt = mesh.triangles.size();
  const std::size_t nq = mesh.quads.size();
  const std::size_t nb = options.vtu_include_bars ? mesh.bars.size() : 0;
  const std::size_t ncells = nt + nq + nb + nm;
  check_fields(options.point_fields, nv, "point", path);
  check_fields(options.cell_fields, ncells, "cell", path);
  const bool bin = options.vtu_binary;

  AtomicFile atomic(path);
  OutputFile out(atomic);
  out << "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n"
         "  <UnstructuredGrid>\n"
      << "    <Piece NumberOfPoints=\"" << nv << "\" NumberOfCells=\"" << ncells << "\">\n";

  out << "      <PointData>\n";
  {
    std::vector<std::int32_t> dim(nv, -1), entity(nv, -1);
    for (std::size_t v = 0; v < nmesh; ++v) {
      dim[v] = mesh.vclass[v].dim;
      entity[v] = mesh.vclass[v].entity;
    }
    for (std::size_t m = 0; m < nm; ++m) entity[nmesh + m] = options.vtu_markers[m].face;
    write_array(out, "cad_dim", 1, dim, bin);
    write_array(out, "cad_entity", 1, entity, bin);
  }
  for (const Field& f : options.point_fields) write_array(out, f.name, f.components, f.values, bin);
  out << "      </PointData>\n";

  out << "      <CellData>\n";
  {
    std::vector<std::int32_t> face(ncells, -1);
    for (std::size_t e = 0; e < nt; ++e) face[e] = mesh.triangle_face[e];
    for (std::size_t e = 0; e < nq; ++e) face[nt + e] = mesh.quad_face[e];
    for (std::size_t m = 0; m < nm; ++m) face[nt + nq + nb + m] = options.vtu_markers[m].face;
    write_array(out, "cad_face", 1, face, bin);
    if (nb > 0) {
      std::vector<std::int32_t> curve(ncells, -1);
      for (std::size_t e = 0; e < nb; ++e) curve[nt + nq + e] = mesh.bar_curve[e];
      write_array(out, "cad_curve", 1, curve, bin);
    }
  }
  for (const Field& f : options.cell_fields) write_array(out, f.name, f.components, f.values, bin);
  out << "      </CellData>\n";

  out << "      <Points>\n";
  {
    std::vector<double> xyz(3 * nv);
    for (std::size_t v = 0; v < nv; ++v) {
      const Vec3& p = v < nmesh ? mesh.points[v] : options.vtu_markers[v - nmesh].position;
      xyz[3 * v] = p.x;
      xyz[3 * v + 1] = p.y;
      xyz[3 * v + 2] = p.z;
    }
    write_array(out, "Points", 3, xyz, bin);
  }
  out << "      </Points>\n";

  out << "      <Cells>\n";
  {
    std::vector<std::int64_t> conn;
    conn.reserve(3 * nt + 4 * nq + 2 * nb);
    std::vector<std::int64_t> offsets;
    offsets.reserve(ncells);
    std::vector<std::uint8_t> types;
    types.reserve(ncells);
    for (const auto& t : mesh.triangles) {
      conn.insert(conn.end(), t.begin(), t.end());
      offsets.push_back(static_cast<std::int64_t>(conn.size()));
      types.push_back(5);  // VTK_TRIANGLE
    }
    // Order 2 as VTK's biquadratic quad and quadratic edge (28, 21), higher orders as Lagrange
    // cells (70, 68), whose order VTK reads from the node count.
    const int order = mesh.order;
    const std::vector<int> perm = mesh::quad_permutation(
        order, order == 2 ? mesh::quad_grid_positions(2) : mesh::quad_grid_positions_vtk(order));
    const std::uint8_t quad_type = order == 1 ? 9 : (order == 2 ? 28 : 70);
    const std::uint8_t bar_type = order == 1 ? 3 : (order == 2 ? 21 : 68);
    for (std::size_t e = 0; e < mesh.quads.size(); ++e) {
      for (int k : perm) conn.push_back(detail::quad_node(mesh, e, k));
      offsets.push_back(static_cast<std::int64_t>(conn.size()));
      types.push_back(quad_type);
    }
    for (std::size_t e = 0; e < nb; ++e) {
      for (int k = 0; k <= order; ++k) conn.push_back(detail::bar_node(mesh, e, k));
      offsets.push_back(static_cast<std::int64_t>(conn.size()));
      types.push_back(bar_type);
    }
    for (std::size_t m = 0; m < nm; ++m) {
      conn.push_back(static_cast<std::int64_t>(nmesh + m));
      offsets.push_back(static_cast<std::int64_t>(conn.size()));
      types.push_back(1);  // VTK_VERTEX
    }
    write_array(out, "connectivity", 1, conn, bin);
    write_array(out, "offsets", 1, offsets, bin);
    write_array(out, "types", 1, types, bin);
  }
  out << "      </Cells>\n"
         "    </Piece>\n"
         "  </UnstructuredGrid>\n"
         "</VTKFile>\n";
  out.close();
  atomic.commit();
}

}  // namespace qsmesh::io
