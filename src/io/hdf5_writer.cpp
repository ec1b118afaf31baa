// HDF5 output through the HDF5 C API (Debian: the serial library cgnslib also uses), with an XDMF 3
// description beside it. Its own handles only: nothing here touches cgnslib's files.
#include <hdf5.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "detail.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/atomic_file.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/mesh/high_order_nodes.hpp"

namespace qsmesh::io {

namespace fs = std::filesystem;

namespace {

static_assert(std::endian::native == std::endian::little,
              "the HDF5 writer hands little-endian file types its native arrays");

// HDF5 calls return a negative value on failure; every one goes through here.
template <typename T>
T h5_check(T rc, const char* call, const std::string& path) {
  if (rc < 0) throw Error("HDF5 " + detail::function_name(call) + " failed for " + path);
  return rc;
}
#define QSMESH_H5(call) h5_check((call), #call, path)

// Closes an HDF5 identifier on the error path; the success path calls close() to check the result.
class H5Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  H5Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  H5Handle(const H5Handle&) = delete;
  H5Handle& operator=(const H5Handle&) = delete;
  ~H5Handle() {
    if (id_ >= 0) closer_(id_);
  }
  [[nodiscard]] hid_t get() const { return id_; }
  herr_t close() {
    const herr_t rc = closer_(id_);
    id_ = -1;
    return rc;
  }

 private:
  hid_t id_;
  Closer closer_;
};

// HDF5's error stack printing off while the writer runs (its failures become one Error line), and
// back to what it was after.
class QuietHdf5Errors {
 public:
  QuietHdf5Errors() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  QuietHdf5Errors(const QuietHdf5Errors&) = delete;
  QuietHdf5Errors& operator=(const QuietHdf5Errors&) = delete;
  ~QuietHdf5Errors() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

// One file, built in memory (HDF5's core driver, no backing store) and every object created
// without timestamps, so that the same mesh gives the same bytes. HDF5 never touches the disk:
// image() hands the bytes to OutputFile, whose checked writes report a full disk as one error,
// where a failed HDF5 write would leave the library holding a half-closed file that its exit
// handler then crashes on.
class H5Writer {
 public:
  // `core_name`: the name HDF5 gives the image, a path that does not exist (the core driver
  // looks for a file of that name, and would open the user's old file if given its name);
  // `shown`: the file named in errors.
  H5Writer(const std::string& core_name, std::string shown)
      : path_(std::move(shown)),
        fapl_(H5Pcreate(H5P_FILE_ACCESS), H5Pclose),
        file_(create_in_memory(core_name, path_, fapl_.get()), H5Fclose),
        dcpl_(H5Pcreate(H5P_DATASET_CREATE), H5Pclose) {
    const std::string& path = path_;
    QSMESH_H5(file_.get());
    QSMESH_H5(dcpl_.get());
    QSMESH_H5(H5Pset_obj_track_times(dcpl_.get(), 0));
  }

  // Grows the image 4 MiB at a time.
  static hid_t create_in_memory(const std::string& core_name, const std::string& path, hid_t fapl) {
    QSMESH_H5(fapl);
    QSMESH_H5(H5Pset_fapl_core(fapl, std::size_t{1} << 22, 0));
    return H5Fcreate(core_name.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
  }

  // A dataset of rows x cols values (cols 0: one dimension), written from `data` (row-major).
  template <typename T>
  void dataset(const char* name, hid_t type, std::int64_t rows, int cols, const T* data) {
    const std::string& path = path_;
    const std::array<hsize_t, 2> dims{static_cast<hsize_t>(rows), static_cast<hsize_t>(cols)};
    H5Handle space(H5Screate_simple(cols > 0 ? 2 : 1, dims.data(), nullptr), H5Sclose);
    QSMESH_H5(space.get());
    H5Handle set(
        H5Dcreate2(file_.get(), name, type, space.get(), H5P_DEFAULT, dcpl_.get(), H5P_DEFAULT),
        H5Dclose);
    QSMESH_H5(set.get());
    if (rows > 0) QSMESH_H5(H5Dwrite(set.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data));
    QSMESH_H5(set.close());
    QSMESH_H5(space.close());
  }

  // Attributes of the root group.
  void attribute(const char* name, std::int64_t value) {
    scalar_attribute(name, H5T_STD_I64LE, H5T_NATIVE_INT64, &value);
  }
  void attribute(const char* name, const std::string& value) {
    const std::string& path = path_;
    H5Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
    QSMESH_H5(type.get());
    QSMESH_H5(H5Tset_size(type.get(), std::max<std::size_t>(1, value.size())));
    QSMESH_H5(H5Tset_strpad(type.get(), H5T_STR_NULLPAD));
    const std::string padded = value.empty() ? std::string(1, '\0') : value;
    scalar_attribute(name, type.get(), type.get(), padded.data());
    QSMESH_H5(type.close());
  }

  // The bytes of the finished file; the writer is closed afterwards.
  std::vector<unsigned char> image() {
    const std::string& path = path_;
    QSMESH_H5(H5Fflush(file_.get(), H5F_SCOPE_GLOBAL));
    const ssize_t size = QSMESH_H5(H5Fget_file_image(file_.get(), nullptr, 0));
    std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
    QSMESH_H5(H5Fget_file_image(file_.get(), bytes.data(), bytes.size()));
    QSMESH_H5(dcpl_.close());
    QSMESH_H5(file_.close());
    QSMESH_H5(fapl_.close());
    return bytes;
  }

 private:
  // A scalar attribute of the root group, stored as `file_type`, written from `value` of
  // `memory_type`.
  void scalar_attribute(const char* name, hid_t file_type, hid_t memory_type, const void* value) {
    const std::string& path = path_;
    H5Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    QSMESH_H5(space.get());
    H5Handle attr(H5Acreate2(file_.get(), name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                  H5Aclose);
    QSMESH_H5(attr.get());
    QSMESH_H5(H5Awrite(attr.get(), memory_type, value));
    QSMESH_H5(attr.close());
    QSMESH_H5(space.close());
  }

  std::string path_;
  H5Handle fapl_;
  H5Handle file_;
  H5Handle dcpl_;
};

// The XDMF DataItem of an HDF5 dataset.
std::string data_item(const std::string& h5_name, const char* dataset, std::int64_t rows, int cols,
                      const char* number_type, int precision) {
  std::ostringstream os;
  os << "<DataItem Dimensions=\"" << rows;
  if (cols > 0) os << ' ' << cols;
  os << "\" NumberType=\"" << number_type << "\" Precision=\"" << precision << "\" Format=\"HDF\">"
     << h5_name << ":/" << dataset << "</DataItem>";
  return os.str();
}

// XML-escapes a file name (the only free text in the XDMF file).
std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

std::string xdmf_path_for(const std::string& h5_path) {
  return fs::path(h5_path).replace_extension(".xdmf").string();
}

void write_hdf5(const mesh::SurfaceMesh& mesh, const std::string& path,
                const WriteOptions& options) {
  (void)options;
  check_mesh_for_output(mesh);
  const GO nv = mesh.num_vertices();
  const auto nt = static_cast<std::int64_t>(mesh.triangles.size());
  const auto nq = static_cast<std::int64_t>(mesh.quads.size());
  const auto nb = static_cast<std::int64_t>(mesh.bars.size());
  const auto nc = static_cast<std::int64_t>(mesh.curve_corners.size());
  static_assert(sizeof(std::array<GO, 4>) == 4 * sizeof(std::int64_t) && sizeof(GO) == 8,
                "elements are written as rows of 64-bit ids");
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "points are written as rows of 3 doubles");

  const std::string xdmf = xdmf_path_for(path);
  AtomicFile h5_out(path);
  AtomicFile xdmf_out(xdmf);
  const int order = mesh.order;
  const std::string quad_dataset = "quad" + std::to_string((order + 1) * (order + 1));
  const std::string bar_dataset = "bar" + std::to_string(order + 1);
  {
    const QuietHdf5Errors quiet;
    H5Writer h5(h5_out.temp_path(), path);
    h5.attribute("format", std::string("qsmesh surface mesh"));
    h5.attribute("format_version", std::int64_t{2});
    h5.attribute("order", std::int64_t{order});
    h5.attribute("length_unit", mesh.length_unit);
    h5.attribute("num_cad_corners", std::int64_t{mesh.num_cad_corners});
    h5.attribute("num_cad_curves", std::int64_t{mesh.num_cad_curves});
    h5.attribute("num_cad_faces", std::int64_t{mesh.num_cad_faces});

    h5.dataset("coordinates", H5T_IEEE_F64LE, nv, 3, mesh.points.data());
    {
      std::vector<std::int32_t> dim(static_cast<std::size_t>(nv)), entity(dim.size());
      std::vector<double> param(2 * dim.size());
      for (std::size_t v = 0; v < dim.size(); ++v) {
        // NOLINTNEXTLINE(bugprone-signed-char-misuse): a dimension, 0, 1 or 2, not a character
        dim[v] = static_cast<std::int32_t>(mesh.vclass[v].dim);
        entity[v] = mesh.vclass[v].entity;
        param[2 * v] = mesh.vclass[v].param[0];
        param[2 * v + 1] = mesh.vclass[v].param[1];
      }
      h5.dataset("vertex_cad_dim", H5T_STD_I32LE, nv, 0, dim.data());
      h5.dataset("vertex_cad_entity", H5T_STD_I32LE, nv, 0, entity.data());
      h5.dataset("vertex_cad_param", H5T_IEEE_F64LE, nv, 2, param.data());
    }
    h5.dataset("quads", H5T_STD_I64LE, nq, 4, mesh.quads.data());
    h5.dataset("quad_cad_face", H5T_STD_I32LE, nq, 0, mesh.quad_face.data());
    h5.dataset("triangles", H5T_STD_I64LE, nt, 3, mesh.triangles.data());
    h5.dataset("triangle_cad_face", H5T_STD_I32LE, nt, 0, mesh.triangle_face.data());
    h5.dataset("bars", H5T_STD_I64LE, nb, 2, mesh.bars.data());
    h5.dataset("bar_cad_curve", H5T_STD_I32LE, nb, 0, mesh.bar_curve.data());
    h5.dataset("curve_corners", H5T_STD_I32LE, nc, 2, mesh.curve_corners.data());
    if (order > 1) {
      // Whole high-order connectivities, corners first in Gmsh's order (quad9 / bar3 for order
      // 2, quad16 / bar4 for order 3, ...; defined for every order, where CGNS stops at 4), so
      // that a reader (and XDMF) needs one dataset per element kind.
      const std::vector<int> perm =
          mesh::quad_permutation(order, mesh::quad_grid_positions_recursive(order));
      std::vector<GO> quad_conn, bar_conn;
      quad_conn.reserve(mesh.quads.size() * perm.size());
      for (std::size_t q = 0; q < mesh.quads.size(); ++q)
        for (int k : perm) quad_conn.push_back(detail::quad_node(mesh, q, k));
      bar_conn.reserve(mesh.bars.size() * static_cast<std::size_t>(order + 1));
      for (std::size_t b = 0; b < mesh.bars.size(); ++b)
        for (int k = 0; k <= order; ++k) bar_conn.push_back(detail::bar_node(mesh, b, k));
      h5.dataset(quad_dataset.c_str(), H5T_STD_I64LE, nq, static_cast<int>(perm.size()),
                 quad_conn.data());
      h5.dataset(bar_dataset.c_str(), H5T_STD_I64LE, nb, order + 1, bar_conn.data());
    }
    {
      std::vector<std::int64_t> offsets(mesh.face2curves.offsets.begin(),
                                        mesh.face2curves.offsets.end());
      if (offsets.empty()) offsets.push_back(0);
      h5.dataset("face_curve_offsets", H5T_STD_I64LE, static_cast<std::int64_t>(offsets.size()), 0,
                 offsets.data());
      h5.dataset("face_curves", H5T_STD_I32LE,
                 static_cast<std::int64_t>(mesh.face2curves.targets.size()), 0,
                 mesh.face2curves.targets.data());
    }
    const std::vector<unsigned char> bytes = h5.image();
    OutputFile out(h5_out);
    out.write(bytes.data(), bytes.size());
    out.close();
  }

  // XDMF: a spatial collection of one grid per element kind, all on the same points; ParaView shows
  // each as a block with cell data cad_face (or cad_curve) and point data cad_dim / cad_entity.
  {
    const std::string h5_name = xml_escape(fs::path(path).filename().string());
    OutputFile x(xdmf_out);
    x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
      << "  <Grid Name=\"qsmesh\" GridType=\"Collection\" CollectionType=\"Spatial\">\n";
    auto grid = [&](const char* name, const char* topology, int nodes, std::int64_t n,
                    const char* conn, const char* cad_name, const char* cad_dataset) {
      if (n == 0) return;
      x << "   <Grid Name=\"" << name << "\" GridType=\"Uniform\">\n";
      x << "    <Topology TopologyType=\"" << topology << "\" NumberOfElements=\""
        << static_cast<long long>(n) << "\"";
      if (std::string(topology) == "Polyline") x << " NodesPerElement=\"" << nodes << "\"";
      x << ">\n     " << data_item(h5_name, conn, n, nodes, "Int", 8) << "\n    </Topology>\n";
      x << "    <Geometry GeometryType=\"XYZ\">\n     "
        << data_item(h5_name, "coordinates", nv, 3, "Float", 8) << "\n    </Geometry>\n";
      x << "    <Attribute Name=\"" << cad_name
        << "\" AttributeType=\"Scalar\" Center=\"Cell\">\n     "
        << data_item(h5_name, cad_dataset, n, 0, "Int", 4) << "\n    </Attribute>\n";
      for (const char* a : {"cad_dim", "cad_entity"}) {
        const std::string set = std::string("vertex_") + a;
        x << "    <Attribute Name=\"" << a << "\" AttributeType=\"Scalar\" Center=\"Node\">\n     "
          << data_item(h5_name, set.c_str(), nv, 0, "Int", 4) << "\n    </Attribute>\n";
      }
      x << "   </Grid>\n";
    };
    if (order == 2) {
      grid("quads", "Quadrilateral_9", 9, nq, "quad9", "cad_face", "quad_cad_face");
      grid("curves", "Edge_3", 3, nb, "bar3", "cad_curve", "bar_cad_curve");
    } else {
      grid("quads", "Quadrilateral", 4, nq, "quads", "cad_face", "quad_cad_face");
      grid("triangles", "Triangle", 3, nt, "triangles", "cad_face", "triangle_cad_face");
      grid("curves", "Polyline", 2, nb, "bars", "cad_curve", "bar_cad_curve");
    }
    x << "  </Grid>\n </Domain>\n</Xdmf>\n";
    x.close();
  }
  // The pair lands together: a description never points at data that are not there.
  commit_together(h5_out, xdmf_out);
}

}  // namespace qsmesh::io
