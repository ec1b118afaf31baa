// Multi-block PLOT3D grid (whole, binary, 3D blocks with kdim = 1) and its JSON sidecar.
#include <bit>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "detail.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/atomic_file.hpp"
#include "qsmesh/io/block_connections.hpp"
#include "qsmesh/io/writer.hpp"

namespace qsmesh::io {

namespace fs = std::filesystem;

namespace {

static_assert(std::endian::native == std::endian::little,
              "the PLOT3D writer documents little-endian files and writes native values");

// A JSON string of `s` (names are plain; a file name may hold anything).
std::string json_string(std::string_view s) {
  std::string out(1, '"');
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\u00";
      out += kHex[(static_cast<unsigned char>(c) >> 4) & 0xF];
      out += kHex[static_cast<unsigned char>(c) & 0xF];
    } else {
      out += c;
    }
  }
  out += '"';
  return out;
}

std::string range_json(const BlockRange& r) {
  return "[[" + std::to_string(r[0]) + ", " + std::to_string(r[1]) + "], [" + std::to_string(r[2]) +
         ", " + std::to_string(r[3]) + "]]";
}

// The binary grid: Fortran unformatted sequential records (a 4-byte length before and after
// each) or the same bytes without them.
class GridWriter {
 public:
  GridWriter(OutputFile& out, const WriteOptions& options, const std::string& path)
      : out_(out), records_(options.plot3d_fortran_records), path_(path) {}

  void record(const void* data, std::size_t bytes) {
    begin(bytes);
    out_.write(data, bytes);
    end(bytes);
  }
  void begin(std::size_t bytes) {
    if (!records_) return;
    // gfortran splits larger records into subrecords, which other Fortran runtimes (and CFL3D
    // builds with them) do not read; no surface block comes near this (89 million points).
    QSMESH_CHECK(bytes <= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()),
                 "PLOT3D output " << path_ << ": a record of " << bytes
                                  << " bytes is more than a 4-byte record length holds");
    const auto n = static_cast<std::int32_t>(bytes);
    out_.write(&n, sizeof n);
  }
  void end(std::size_t bytes) {
    if (!records_) return;
    const auto n = static_cast<std::int32_t>(bytes);
    out_.write(&n, sizeof n);
  }

 private:
  OutputFile& out_;
  bool records_;
  const std::string& path_;
};

template <typename Real>
void write_block_coordinates(GridWriter& grid, OutputFile& out, const mesh::SurfaceMesh& mesh,
                             const layout::QuadLayout& layout, const layout::Block& b) {
  const auto n = static_cast<std::size_t>(b.ni + 1) * static_cast<std::size_t>(b.nj + 1);
  std::vector<Real> values(n);
  grid.begin(3 * n * sizeof(Real));
  for (int d = 0; d < 3; ++d) {
    for (std::size_t i = 0; i < n; ++i)
      values[i] = static_cast<Real>(mesh.points[static_cast<std::size_t>(
          layout.vertices[static_cast<std::size_t>(b.first) + i])][d]);
    out.write(values.data(), n * sizeof(Real));
  }
  grid.end(3 * n * sizeof(Real));
}

}  // namespace

std::string plot3d_connections_path(const std::string& grid_path) { return grid_path + ".json"; }

Plot3dReport write_plot3d(const mesh::SurfaceMesh& mesh, const layout::QuadLayout& layout,
                          const std::string& path, const WriteOptions& options) {
  detail::check_output_folder(path);
  check_mesh_for_output(mesh);
  QSMESH_CHECK(mesh.quad_nodes.empty(),
               "PLOT3D output " << path << ": blocks of second-order quads are not written");
  check_layout_for_output(mesh, layout, "PLOT3D output " + path);
  const auto nb = static_cast<GO>(layout.blocks.size());
  QSMESH_CHECK(nb <= std::numeric_limits<std::int32_t>::max(),
               "PLOT3D output " << path << ": " << nb << " blocks");
  const BlockConnections joined = block_connections(mesh, layout);

  Plot3dReport report;
  report.blocks = nb;
  {
    const detail::ElementGroups groups = detail::group_elements(mesh);
    for (LO f : layout.unblocked_faces) {
      const auto& tris = groups.face2tris[static_cast<std::size_t>(f)];
      const auto& quads = groups.face2quads[static_cast<std::size_t>(f)];
      if (tris.empty() && quads.empty()) continue;
      report.skipped_faces.push_back(f);
      report.skipped_triangles += static_cast<GO>(tris.size());
      report.skipped_quads += static_cast<GO>(quads.size());
    }
  }

  const std::string sidecar = plot3d_connections_path(path);
  AtomicFile grid_file(path);
  AtomicFile json_file(sidecar);
  {
    OutputFile out(grid_file);
    GridWriter grid(out, options, path);
    const auto count = static_cast<std::int32_t>(nb);
    grid.record(&count, sizeof count);
    std::vector<std::int32_t> dims;
    dims.reserve(static_cast<std::size_t>(3 * nb));
    for (const layout::Block& b : layout.blocks) {
      dims.push_back(b.ni + 1);
      dims.push_back(b.nj + 1);
      dims.push_back(1);
    }
    grid.record(dims.data(), dims.size() * sizeof(std::int32_t));
    for (const layout::Block& b : layout.blocks) {
      if (options.plot3d_single_precision)
        write_block_coordinates<float>(grid, out, mesh, layout, b);
      else
        write_block_coordinates<double>(grid, out, mesh, layout, b);
    }
    out.close();
  }
  {
    OutputFile out(json_file);
    out << "{\n  \"format\": \"qsmesh plot3d connectivity\",\n  \"format_version\": 1,\n";
    out << "  \"grid_file\": " << json_string(fs::path(path).filename().string()) << ",\n";
    out << "  \"grid\": {\"form\": "
        << (options.plot3d_fortran_records ? "\"fortran-unformatted\"" : "\"stream\"")
        << ", \"precision\": " << (options.plot3d_single_precision ? "\"single\"" : "\"double\"")
        << ", \"byte_order\": \"little\", \"blocks\": " << nb << "},\n";
    out << "  \"length_unit\": " << json_string(mesh.length_unit) << ",\n";
    out << "  \"index_base\": 1,\n";
    out << "  \"blocks\": [";
    for (GO k = 0; k < nb; ++k) {
      const layout::Block& b = layout.blocks[static_cast<std::size_t>(k)];
      const BlockLinks& links = joined.blocks[static_cast<std::size_t>(k)];
      out << (k > 0 ? ",\n" : "\n") << "    {\"block\": " << k + 1
          << ", \"name\": " << json_string(block_name(layout, k, mesh.num_cad_faces))
          << ", \"face\": " << b.face << ", \"family\": \"Face_" << b.face
          << "\", \"idim\": " << b.ni + 1 << ", \"jdim\": " << b.nj + 1 << ", \"kdim\": 1,\n";
      out << "     \"interfaces\": [";
      bool first = true;
      for (const BlockInterface& i : links.interfaces) {
        out << (first ? "\n" : ",\n") << "       {\"side\": \""
            << kBlockSideNames[static_cast<std::size_t>(i.side)]
            << "\", \"range\": " << range_json(i.range) << ", \"donor\": " << i.donor + 1
            << ", \"donor_side\": \"" << kBlockSideNames[static_cast<std::size_t>(i.donor_side)]
            << "\", \"donor_range\": " << range_json(i.donor_range) << ", \"transform\": ["
            << i.transform[0] << ", " << i.transform[1] << "]}";
        first = false;
      }
      out << (first ? "],\n" : "\n     ],\n");
      out << "     \"boundaries\": [";
      first = true;
      for (const BlockBoundary& r : links.boundaries) {
        out << (first ? "\n" : ",\n") << "       {\"side\": \""
            << kBlockSideNames[static_cast<std::size_t>(r.side)]
            << "\", \"range\": " << range_json(r.range) << ", \"family\": \"Curve_" << r.curve
            << "\", \"curve\": " << r.curve << ", \"bc\": \"BCWall\"}";
        first = false;
      }
      out << (first ? "],\n" : "\n     ],\n");
      out << "     \"against_left_out_faces\": [";
      first = true;
      for (const BlockAbutment& a : links.abutments) {
        out << (first ? "\n" : ",\n") << "       {\"side\": \""
            << kBlockSideNames[static_cast<std::size_t>(a.side)]
            << "\", \"range\": " << range_json(a.range) << "}";
        first = false;
      }
      out << (first ? "]}" : "\n     ]}");
    }
    out << (nb > 0 ? "\n  ],\n" : "],\n");
    out << "  \"left_out_faces\": [";
    for (std::size_t i = 0; i < report.skipped_faces.size(); ++i)
      out << (i > 0 ? ", " : "") << report.skipped_faces[i];
    out << "],\n  \"left_out_triangles\": " << report.skipped_triangles
        << ",\n  \"left_out_quads\": " << report.skipped_quads << "\n}\n";
    out.close();
  }
  commit_together(grid_file, json_file);
  return report;
}

}  // namespace qsmesh::io
