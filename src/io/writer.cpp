#include "qsmesh/io/writer.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string_view>
#include <system_error>

#include "detail.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/atomic_file.hpp"
#include "qsmesh/layout/quad_layout.hpp"

namespace qsmesh::io {

namespace fs = std::filesystem;

void check_output_path(const std::string& path) {
  if (!is_supported_output(path)) {
    throw InputError(
        "output '" + path +
        "': unsupported format (the extension must be .cgns, .vtu, .msh, .h5, .xyz or .p3d)");
  }
  check_output_file("output", path);
  if (output_format(path) == Format::kHdf5) {
    // XDMF names its data "file:/dataset" and splits at the first colon.
    if (fs::path(path).filename().string().find(':') != std::string::npos)
      throw InputError("output '" + path +
                       "': an .h5 file name cannot contain ':' (the XDMF description beside it "
                       "could not refer to it); rename it");
    check_output_file("output", xdmf_path_for(path));
  }
  if (output_format(path) == Format::kPlot3d)
    check_output_file("output", plot3d_connections_path(path));
}

void check_output_file(const std::string& what, const std::string& path) {
  detail::check_output_folder(path, what);
  std::error_code ec;
  const auto status = fs::symlink_status(path, ec);
  if (fs::exists(status) && !fs::is_regular_file(status) && !fs::is_symlink(status))
    throw InputError(what + " '" + path +
                     "' exists and is not a regular file (a device or a pipe); give a file name");
  // The very temporary the writer will create (AtomicFile removes a stale one of its name too).
  const std::string temp = temporary_path(path, ::getpid());
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) {
    const fs::path p(path);
    throw InputError(what + " '" + path + "': cannot create a file in folder '" +
                     (p.has_parent_path() ? p.parent_path().string() : std::string(".")) +
                     "': " + std::strerror(errno));
  }
  ::close(fd);
  ::unlink(temp.c_str());
}

void prepare_output_libraries() {
  // Without this, a CGNS file whose write failed (disk full) stays half-open inside HDF5, and the
  // library's exit handler crashes on it after the run has already reported the error.
  H5dont_atexit();
}

namespace detail {

std::string function_name(const char* call) {
  const std::string_view text(call);
  return std::string(text.substr(0, text.find('(')));
}

void check_output_folder(const std::string& path, const std::string& what) {
  const fs::path p(path);
  std::error_code ec;
  const std::string named = what + " '" + path + "'";
  if (p.filename().empty()) throw InputError(named + " names no file");
  if (fs::is_directory(p, ec)) throw InputError(named + " is a folder");
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec))
    throw InputError(named + ": folder '" + dir.string() + "' does not exist");
  // access() also reports read-only file systems, which the permission bits do not show.
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw InputError(named + ": folder '" + dir.string() + "' is not writable");
}

}  // namespace detail

void check_mesh_for_output(const mesh::SurfaceMesh& m) {
  const GO nv = m.num_vertices();
  QSMESH_CHECK(m.vclass.size() == m.points.size(),
               "output: " << m.vclass.size() << " classifications for " << nv << " vertices");
  QSMESH_CHECK(m.triangle_face.size() == m.triangles.size(),
               "output: triangle_face has " << m.triangle_face.size() << " entries for "
                                            << m.triangles.size() << " triangles");
  QSMESH_CHECK(m.quad_face.size() == m.quads.size(), "output: quad_face has "
                                                         << m.quad_face.size() << " entries for "
                                                         << m.quads.size() << " quads");
  QSMESH_CHECK(m.bar_curve.size() == m.bars.size(), "output: bar_curve has "
                                                        << m.bar_curve.size() << " entries for "
                                                        << m.bars.size() << " bars");
  QSMESH_CHECK(m.num_cad_faces >= 0 && m.num_cad_curves >= 0 && m.num_cad_corners >= 0,
               "output: negative CAD entity count");
  QSMESH_CHECK(
      m.curve_corners.empty() || static_cast<LO>(m.curve_corners.size()) == m.num_cad_curves,
      "output: curve_corners has " << m.curve_corners.size() << " entries for " << m.num_cad_curves
                                   << " curves");
  QSMESH_CHECK(
      m.face2curves.size() == 0 || m.face2curves.size() == m.num_cad_faces,
      "output: face2curves has " << m.face2curves.size() << " faces, mesh has " << m.num_cad_faces);
  for (const auto& cc : m.curve_corners) {
    for (LO k : cc) {
      QSMESH_CHECK(k == kNoIndex || (k >= 0 && k < m.num_cad_corners),
                   "output: curve corner " << k << " out of range");
    }
  }
  for (LO c : m.face2curves.targets) {
    QSMESH_CHECK(c >= 0 && c < m.num_cad_curves,
                 "output: face2curves curve " << c << " out of range");
  }
  auto check_vertices = [&](const auto& elements, const char* what) {
    for (std::size_t e = 0; e < elements.size(); ++e) {
      for (GO v : elements[e]) {
        QSMESH_CHECK(v >= 0 && v < nv, "output: " << what << ' ' << e << " has vertex " << v
                                                  << " out of [0, " << nv << ")");
      }
    }
  };
  QSMESH_CHECK(m.order >= 1 && m.order <= 5, "output: element order " << m.order);
  const auto per_quad = static_cast<std::size_t>(m.quad_nodes_per_quad());
  const auto per_bar = static_cast<std::size_t>(m.bar_nodes_per_bar());
  QSMESH_CHECK((m.order == 1 && m.quad_nodes.empty() && m.bar_nodes.empty()) ||
                   (m.order > 1 && m.quad_nodes.size() == m.quads.size() * per_quad &&
                    m.bar_nodes.size() == m.bars.size() * per_bar && m.triangles.empty()),
               "output: order " << m.order << " with " << m.quad_nodes.size()
                                << " high-order nodes for " << m.quads.size() << " quads and "
                                << m.bar_nodes.size() << " for " << m.bars.size() << " bars, "
                                << m.triangles.size() << " triangles");
  for (std::size_t k = 0; k < m.quad_nodes.size(); ++k)
    QSMESH_CHECK(
        m.quad_nodes[k] >= 0 && m.quad_nodes[k] < nv,
        "output: quad " << k / per_quad << " has node " << m.quad_nodes[k] << " out of range");
  for (std::size_t k = 0; k < m.bar_nodes.size(); ++k)
    QSMESH_CHECK(
        m.bar_nodes[k] >= 0 && m.bar_nodes[k] < nv,
        "output: bar " << k / per_bar << " has node " << m.bar_nodes[k] << " out of range");
  check_vertices(m.triangles, "triangle");
  check_vertices(m.quads, "quad");
  check_vertices(m.bars, "bar");
  auto check_ids = [](const std::vector<LO>& ids, LO n, const char* what) {
    for (std::size_t e = 0; e < ids.size(); ++e) {
      QSMESH_CHECK(ids[e] >= 0 && ids[e] < n, "output: " << what << ' ' << e << " on CAD entity "
                                                         << ids[e] << " out of [0, " << n << ")");
    }
  };
  check_ids(m.triangle_face, m.num_cad_faces, "triangle");
  check_ids(m.quad_face, m.num_cad_faces, "quad");
  check_ids(m.bar_curve, m.num_cad_curves, "bar");
}

void write_mesh(const mesh::SurfaceMesh& mesh, const std::string& path,
                const WriteOptions& options) {
  check_output_path(path);
  switch (output_format(path)) {
    case Format::kCgns:
      write_cgns(mesh, path, options);
      return;
    case Format::kVtu:
      write_vtu(mesh, path, options);
      return;
    case Format::kMsh:
      write_msh(mesh, path, options);
      return;
    case Format::kHdf5:
      write_hdf5(mesh, path, options);
      return;
    case Format::kPlot3d:
      (void)write_plot3d(mesh, layout::extract_quad_layout(mesh), path, options);
      return;
    case Format::kNone:
      break;
  }
  QSMESH_CHECK(false, "unreachable: unsupported output " << path);
}

namespace detail {

ElementGroups group_elements(const mesh::SurfaceMesh& m) {
  ElementGroups g;
  g.face2tris.resize(static_cast<std::size_t>(m.num_cad_faces));
  g.face2quads.resize(static_cast<std::size_t>(m.num_cad_faces));
  g.curve2bars.resize(static_cast<std::size_t>(m.num_cad_curves));
  for (std::size_t e = 0; e < m.triangles.size(); ++e) {
    g.face2tris[static_cast<std::size_t>(m.triangle_face[e])].push_back(static_cast<GO>(e));
  }
  for (std::size_t e = 0; e < m.quads.size(); ++e) {
    g.face2quads[static_cast<std::size_t>(m.quad_face[e])].push_back(static_cast<GO>(e));
  }
  for (std::size_t e = 0; e < m.bars.size(); ++e) {
    g.curve2bars[static_cast<std::size_t>(m.bar_curve[e])].push_back(static_cast<GO>(e));
  }
  return g;
}

}  // namespace detail

}  // namespace qsmesh::io
