// CGNS output through the cgnslib mid-level API (Debian: 32-bit cgsize_t, HDF5 serial backend).
// cgnslib keeps its own file table and the HDF5 library state; no HDF5 call is made here.
#include <cgns_io.h>
#include <cgnslib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <string_view>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "detail.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/atomic_file.hpp"
#include "qsmesh/io/block_connections.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/layout/quad_layout.hpp"
#include "qsmesh/mesh/edges.hpp"
#include "qsmesh/mesh/high_order_nodes.hpp"

namespace qsmesh::io {

namespace {

// Every cgnslib call goes through here: a nonzero return becomes an OutputError naming the file and
// the function (with cgnslib's reason: a full disk shows as a failed H5Dwrite).
void cg_check(int rc, const char* call, const std::string& path) {
  if (rc != CG_OK) {
    throw OutputError("cannot write " + path + ": CGNS " + detail::function_name(call) +
                      " failed: " + cg_get_error());
  }
}
#define QSMESH_CG(call) cg_check((call), #call, path)

void cgio_check(int rc, const char* call, const std::string& path) {
  if (rc != CGIO_ERR_NONE) {
    char msg[CGIO_MAX_ERROR_LENGTH + 1] = {};
    cgio_error_message(msg);
    throw OutputError("cannot write " + path + ": CGNS " + detail::function_name(call) +
                      " failed: " + msg);
  }
}
#define QSMESH_CGIO(call) cgio_check((call), #call, path)

// Closes the file on the error path; the success path closes explicitly to check the result.
struct CgFile {
  int fn = -1;
  CgFile() = default;
  CgFile(const CgFile&) = delete;
  CgFile& operator=(const CgFile&) = delete;
  ~CgFile() {
    if (fn >= 0) cg_close(fn);
  }
};

CGNS_ENUMT(LengthUnits_t) length_unit(const std::string& unit) {
  if (unit == "mm") return CGNS_ENUMV(Millimeter);
  if (unit == "cm") return CGNS_ENUMV(Centimeter);
  if (unit == "m") return CGNS_ENUMV(Meter);
  if (unit == "in") return CGNS_ENUMV(Inch);
  if (unit == "ft") return CGNS_ENUMV(Foot);
  throw Error("CGNS output: length unit '" + unit + "' is not one of mm, cm, m, in, ft");
}

cgsize_t to_cg(GO value, const std::string& path) {
  QSMESH_CHECK(value <= static_cast<GO>(std::numeric_limits<cgsize_t>::max()),
               "CGNS output " << path << ": id " << value
                              << " exceeds the 32-bit ids of this cgnslib build");
  return static_cast<cgsize_t>(value);
}

// Bob Jenkins' lookup3 hashlittle with initval 0: the checksum HDF5 stores in its metadata.
std::uint32_t lookup3(const unsigned char* k, std::size_t length) {
  auto rot = [](std::uint32_t x, int r) { return (x << r) | (x >> (32 - r)); };
  std::uint32_t a = 0xdeadbeef + static_cast<std::uint32_t>(length);
  std::uint32_t b = a;
  std::uint32_t c = a;
  auto word = [&](std::size_t i) {
    return std::uint32_t{k[i]} | (std::uint32_t{k[i + 1]} << 8) | (std::uint32_t{k[i + 2]} << 16) |
           (std::uint32_t{k[i + 3]} << 24);
  };
  while (length > 12) {
    a += word(0);
    b += word(4);
    c += word(8);
    a -= c;
    a ^= rot(c, 4);
    c += b;
    b -= a;
    b ^= rot(a, 6);
    a += c;
    c -= b;
    c ^= rot(b, 8);
    b += a;
    a -= c;
    a ^= rot(c, 16);
    c += b;
    b -= a;
    b ^= rot(a, 19);
    a += c;
    c -= b;
    c ^= rot(b, 4);
    b += a;
    length -= 12;
    k += 12;
  }
  if (length == 0) return c;
  unsigned char tail[12] = {};
  std::memcpy(tail, k, length);
  a += std::uint32_t{tail[0]} | (std::uint32_t{tail[1]} << 8) | (std::uint32_t{tail[2]} << 16) |
       (std::uint32_t{tail[3]} << 24);
  b += std::uint32_t{tail[4]} | (std::uint32_t{tail[5]} << 8) | (std::uint32_t{tail[6]} << 16) |
       (std::uint32_t{tail[7]} << 24);
  c += std::uint32_t{tail[8]} | (std::uint32_t{tail[9]} << 8) | (std::uint32_t{tail[10]} << 16) |
       (std::uint32_t{tail[11]} << 24);
  c ^= b;
  c -= rot(b, 14);
  a ^= c;
  a -= rot(c, 11);
  b ^= a;
  b -= rot(a, 25);
  c ^= b;
  c -= rot(b, 16);
  a ^= c;
  a -= rot(c, 4);
  b ^= a;
  b -= rot(a, 14);
  c ^= b;
  c -= rot(b, 24);
  return c;
}

// HDF5 (through cgnslib, which offers no switch) stores access/modification/change/birth times in
// every version-2 object header, so two writes of the same mesh differ. This zeroes those times and
// rewrites the header checksums. A candidate "OHDR" is only patched when its stored checksum
// verifies, so bytes in raw data that happen to read "OHDR" are left alone. The file is scanned in
// 1 MiB blocks (the whole file in memory was the largest allocation of a run on the writing rank:
// 50 MB of heap for a 17.5 MB file; docs/benchmarks.md); a header inside the block is patched
// there and the block written back once, one across its end through the file. Seeking and writing
// each header alone cost 1-2 s for the ~100,000 headers of a file of 3,000 zones.
void strip_hdf5_times(const std::string& file) {
  std::FILE* f = std::fopen(file.c_str(), "r+b");
  if (f == nullptr) throw Error("cannot reopen " + file + ": " + std::strerror(errno));
  const auto fail = [&](const char* what) {
    const std::string reason = std::strerror(errno);
    std::fclose(f);
    throw Error("cannot " + std::string(what) + " " + file + ": " + reason);
  };
  const auto read_at = [&](std::uint64_t at, unsigned char* to, std::size_t n) {
    if (std::fseek(f, static_cast<long>(at), SEEK_SET) != 0 || std::fread(to, 1, n, f) != n)
      fail("read back");
  };
  const auto write_at = [&](std::uint64_t at, const void* from, std::size_t n) {
    if (std::fseek(f, static_cast<long>(at), SEEK_SET) != 0 || std::fwrite(from, 1, n, f) != n)
      fail("rewrite");
  };
  if (std::fseek(f, 0, SEEK_END) != 0) fail("read back");
  const long end = std::ftell(f);
  if (end < 0) fail("read back");
  const auto size = static_cast<std::uint64_t>(end);

  constexpr std::uint64_t kBlock = std::uint64_t{1} << 20;
  std::vector<unsigned char> block;
  std::vector<unsigned char> header;
  std::uint64_t base = 0;
  bool dirty = false;  // the block holds patches not yet in the file
  // Bytes [at, at + n): from the block when it holds them all (with its patches), else the file
  // (a header across the block's end; the bytes of other headers patched in the block are not
  // among them, as headers do not overlap).
  const auto get = [&](std::uint64_t at, unsigned char* to, std::size_t n) {
    if (at >= base && at - base + n <= block.size())
      std::memcpy(to, block.data() + (at - base), n);
    else
      read_at(at, to, n);
  };
  // Patches [at, at + n) in the block when it holds them all, else in the file and in the part of
  // the block that holds some of them (so that writing the block back keeps the patch).
  const auto put = [&](std::uint64_t at, const void* from, std::size_t n) {
    if (at >= base && at - base + n <= block.size()) {
      std::memcpy(block.data() + (at - base), from, n);
      dirty = true;
      return;
    }
    write_at(at, from, n);
    const std::uint64_t lo = std::max(at, base), hi = std::min(at + n, base + block.size());
    if (lo < hi) {
      std::memcpy(block.data() + (lo - base), static_cast<const unsigned char*>(from) + (lo - at),
                  static_cast<std::size_t>(hi - lo));
      dirty = true;
    }
  };
  std::uint64_t next = 0;  // a header may start here or later (not inside one already patched)
  for (; base < size; base += kBlock) {
    // 3 bytes past the block, so that a tag across the border is seen from this block.
    block.resize(static_cast<std::size_t>(std::min(kBlock + 3, size - base)));
    read_at(base, block.data(), block.size());
    dirty = false;
    for (std::size_t i = 0; i < std::min<std::size_t>(block.size(), kBlock); ++i) {
      const auto* hit = static_cast<const unsigned char*>(
          std::memchr(block.data() + i, 'O', std::min<std::size_t>(block.size(), kBlock) - i));
      if (hit == nullptr) break;
      i = static_cast<std::size_t>(hit - block.data());
      if (i + 4 > block.size() || std::memcmp(hit, "OHDR", 4) != 0) continue;
      const std::uint64_t start = base + i;
      if (start < next || start + 6 > size) continue;
      unsigned char prefix[6 + 16 + 4 + 8];
      const std::size_t have =
          static_cast<std::size_t>(std::min<std::uint64_t>(sizeof prefix, size - start));
      get(start, prefix, have);
      if (prefix[4] != 2 || (prefix[5] & 0x20) == 0) continue;
      const unsigned flags = prefix[5];
      const std::size_t p = 6 + 16 + ((flags & 0x10) != 0 ? 4 : 0);
      const std::size_t width = std::size_t{1} << (flags & 3);
      if (p + width > have) continue;
      std::uint64_t chunk = 0;
      for (std::size_t k = 0; k < width; ++k) chunk |= std::uint64_t{prefix[p + k]} << (8 * k);
      const std::uint64_t body = start + p + width;  // the chunk's first byte
      if (chunk > size - body || body + chunk + 4 > size) continue;
      const std::uint64_t sum_at = body + chunk;
      header.resize(static_cast<std::size_t>(sum_at + 4 - start));
      get(start, header.data(), header.size());
      const std::size_t covered = header.size() - 4;
      std::uint32_t stored = 0;
      std::memcpy(&stored, header.data() + covered, 4);  // little-endian file, little-endian host
      if (lookup3(header.data(), covered) != stored) continue;
      std::memset(header.data() + 6, 0, 16);
      const std::uint32_t sum = lookup3(header.data(), covered);
      put(start + 6, header.data() + 6, 16);
      put(sum_at, &sum, 4);
      next = sum_at + 4;
    }
    if (dirty) write_at(base, block.data(), block.size());
  }
  if (std::fclose(f) != 0) throw Error("cannot rewrite " + file + ": " + std::strerror(errno));
}
static_assert(std::endian::native == std::endian::little, "strip_hdf5_times assumes little endian");

// Opens the temporary of `out` for writing; `file` closes it on the error path.
int open_for_write(const AtomicFile& out, CgFile& file, const std::string& path) {
  QSMESH_CG(cg_set_file_type(CG_FILE_HDF5));
  QSMESH_CG(cg_open(out.temp_path().c_str(), CG_MODE_WRITE, &file.fn));
  return file.fn;
}

// cgnslib 3.4 writes the 33-byte label of IndexRange_t nodes (BC point ranges) from an
// uninitialised stack buffer (bytes after "IndexRange_t" are garbage), so files would differ
// between runs: rewrites the label of the node at path `node` from a zero-padded buffer.
void fix_range_label(int cgio, double root, const std::string& node, const std::string& path) {
  double id = 0;
  QSMESH_CGIO(cgio_get_node_id(cgio, root, node.c_str(), &id));
  char label[CGIO_MAX_LABEL_LENGTH + 1] = {};
  std::strncpy(label, "IndexRange_t", CGIO_MAX_LABEL_LENGTH);
  QSMESH_CGIO(cgio_set_label(cgio, id, label));
  QSMESH_CGIO(cgio_release_id(cgio, id));
}

// The base of every qsmesh CGNS file: CellDimension 2, PhysicalDimension 3, dimensional data in
// the mesh's length unit.
int write_base(int fn, const WriteOptions& options, CGNS_ENUMT(LengthUnits_t) unit,
               const std::string& path) {
  int base = 0;
  QSMESH_CG(cg_base_write(fn, options.cgns_base_name.c_str(), 2, 3, &base));
  QSMESH_CG(cg_goto(fn, base, "end"));
  QSMESH_CG(cg_dataclass_write(CGNS_ENUMV(Dimensional)));
  QSMESH_CG(cg_units_write(CGNS_ENUMV(Kilogram), unit, CGNS_ENUMV(Second), CGNS_ENUMV(Kelvin),
                           CGNS_ENUMV(Degree)));
  return base;
}

// The coordinates of a zone, point(i) for i < n, with their dimensional exponents.
void write_coordinates(int fn, int base, int zone, std::size_t n,
                       const std::function<Vec3(std::size_t)>& point, const std::string& path) {
  std::vector<double> coord(n);
  const char* names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
  for (int d = 0; d < 3; ++d) {
    for (std::size_t v = 0; v < n; ++v) coord[v] = point(v)[d];
    int c = 0;
    QSMESH_CG(cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), names[d], coord.data(), &c));
    // Coordinates are lengths: exponents (mass, length, time, temperature, angle) = (0,1,0,0,0).
    QSMESH_CG(cg_goto(fn, base, "Zone_t", zone, "GridCoordinates_t", 1, "DataArray_t", c, "end"));
    const float exponents[5] = {0, 1, 0, 0, 0};
    QSMESH_CG(cg_exponents_write(CGNS_ENUMV(RealSingle), exponents));
  }
}

// The CGNS element types of quads and bars of `order`; CGNS 3.4 defines them up to order 4.
CGNS_ENUMT(ElementType_t) quad_type(int order, const std::string& path) {
  switch (order) {
    case 1:
      return CGNS_ENUMV(QUAD_4);
    case 2:
      return CGNS_ENUMV(QUAD_9);
    case 3:
      return CGNS_ENUMV(QUAD_16);
    case 4:
      return CGNS_ENUMV(QUAD_25);
    default:
      throw InputError("CGNS output " + path + ": CGNS has no quads of order " +
                       std::to_string(order) + " (QUAD_25, order 4, is the highest)");
  }
}
CGNS_ENUMT(ElementType_t) bar_type(int order, const std::string& path) {
  switch (order) {
    case 1:
      return CGNS_ENUMV(BAR_2);
    case 2:
      return CGNS_ENUMV(BAR_3);
    case 3:
      return CGNS_ENUMV(BAR_4);
    case 4:
      return CGNS_ENUMV(BAR_5);
    default:
      throw InputError("CGNS output " + path + ": CGNS has no bars of order " +
                       std::to_string(order) + " (BAR_5, order 4, is the highest)");
  }
}

// One section "Face_<f>" per face of `faces` with elements (TRI_3, QUAD_4 / QUAD_9 / QUAD_16 /
// QUAD_25 by the mesh order, MIXED when both), element ids from `next` on, vertex v written as
// id(v); also the face's family when `families`. Returns the next free element id. cgnslib 3.4
// refuses FamilyName_t under Elements_t, so a section is tied to its family by the shared name
// only.
cgsize_t write_face_sections(int fn, int base, int zone, const mesh::SurfaceMesh& mesh,
                             const detail::ElementGroups& groups, const std::vector<LO>& faces,
                             const std::function<cgsize_t(GO)>& id, cgsize_t next, bool families,
                             const std::string& path) {
  const std::vector<int> perm =
      mesh::quad_permutation(mesh.order, mesh::quad_grid_positions_cgns(mesh.order));
  std::vector<cgsize_t> conn, offsets;
  for (LO f : faces) {
    const auto& tris = groups.face2tris[static_cast<std::size_t>(f)];
    const auto& quads = groups.face2quads[static_cast<std::size_t>(f)];
    const auto n = static_cast<cgsize_t>(tris.size() + quads.size());
    if (n == 0) continue;
    const std::string name = "Face_" + std::to_string(f);
    const bool mixed = !tris.empty() && !quads.empty();
    conn.clear();
    offsets.assign(1, 0);
    // MIXED connectivity: each element's type code, then its vertices; offsets into it.
    for (GO t : tris) {
      if (mixed) conn.push_back(CGNS_ENUMV(TRI_3));
      for (GO v : mesh.triangles[static_cast<std::size_t>(t)]) conn.push_back(id(v));
      offsets.push_back(static_cast<cgsize_t>(conn.size()));
    }
    for (GO q : quads) {
      if (mixed) conn.push_back(CGNS_ENUMV(QUAD_4));
      for (int k : perm)
        conn.push_back(id(detail::quad_node(mesh, static_cast<std::size_t>(q), k)));
      offsets.push_back(static_cast<cgsize_t>(conn.size()));
    }
    int section = 0;
    if (mixed) {
      QSMESH_CG(cg_poly_section_write(fn, base, zone, name.c_str(), CGNS_ENUMV(MIXED), next,
                                      next + n - 1, 0, conn.data(), offsets.data(), &section));
    } else {
      QSMESH_CG(cg_section_write(fn, base, zone, name.c_str(),
                                 tris.empty() ? quad_type(mesh.order, path) : CGNS_ENUMV(TRI_3),
                                 next, next + n - 1, 0, conn.data(), &section));
    }
    if (families) {
      int family = 0;
      QSMESH_CG(cg_family_write(fn, base, name.c_str(), &family));
    }
    next += n;
  }
  return next;
}

}  // namespace

void write_cgns(const mesh::SurfaceMesh& mesh, const std::string& path,
                const WriteOptions& options) {
  detail::check_output_folder(path);
  check_mesh_for_output(mesh);
  const auto unit = length_unit(mesh.length_unit);
  const GO nv = mesh.num_vertices();
  const GO ncells = static_cast<GO>(mesh.triangles.size() + mesh.quads.size());
  (void)to_cg(nv, path);
  (void)to_cg(ncells + static_cast<GO>(mesh.bars.size()), path);
  const detail::ElementGroups groups = detail::group_elements(mesh);
  QSMESH_CHECK(mesh.order == 1 || mesh.triangles.empty(),
               "CGNS output " << path << ": high-order quads with triangles");
  (void)quad_type(mesh.order, path);

  AtomicFile out(path);
  CgFile file;
  const int fn = open_for_write(out, file, path);

  const int base = write_base(fn, options, unit, path);

  // Zone size for an unstructured zone: vertices, cells (the 2D elements), boundary vertices (0:
  // unsorted).
  cgsize_t size[3] = {to_cg(nv, path), to_cg(ncells, path), 0};
  int zone = 0;
  QSMESH_CG(cg_zone_write(fn, base, options.cgns_zone_name.c_str(), size, CGNS_ENUMV(Unstructured),
                          &zone));
  write_coordinates(
      fn, base, zone, mesh.points.size(), [&](std::size_t v) { return mesh.points[v]; }, path);

  std::vector<LO> all_faces(static_cast<std::size_t>(mesh.num_cad_faces));
  std::iota(all_faces.begin(), all_faces.end(), LO{0});
  cgsize_t next = write_face_sections(
      fn, base, zone, mesh, groups, all_faces, [](GO v) { return static_cast<cgsize_t>(v + 1); }, 1,
      true, path);
  std::vector<cgsize_t> conn;

  struct CurveRange {
    std::string name;
    cgsize_t first, last;
  };
  std::vector<CurveRange> curve_ranges;
  for (LO c = 0; c < mesh.num_cad_curves; ++c) {
    const auto& bars = groups.curve2bars[static_cast<std::size_t>(c)];
    if (bars.empty()) continue;
    const std::string name = "Curve_" + std::to_string(c);
    const auto n = static_cast<cgsize_t>(bars.size());
    conn.clear();
    for (GO b : bars) {
      for (int k = 0; k <= mesh.order; ++k)
        conn.push_back(
            static_cast<cgsize_t>(detail::bar_node(mesh, static_cast<std::size_t>(b), k) + 1));
    }
    int section = 0;
    QSMESH_CG(cg_section_write(fn, base, zone, name.c_str(), bar_type(mesh.order, path), next,
                               next + n - 1, 0, conn.data(), &section));
    int family = 0;
    QSMESH_CG(cg_family_write(fn, base, name.c_str(), &family));
    int fambc = 0;
    QSMESH_CG(cg_fambc_write(fn, base, family, "FamBC", CGNS_ENUMV(BCWall), &fambc));
    curve_ranges.push_back({name, next, next + n - 1});
    next += n;
  }

  int cgio = 0;
  double root = 0;
  QSMESH_CG(cg_get_cgio(fn, &cgio));
  QSMESH_CG(cg_root_id(fn, &root));
  // One BC per meshed curve over its bar elements (contiguous ids, hence a PointRange).
  for (const CurveRange& r : curve_ranges) {
    const cgsize_t range[2] = {r.first, r.last};
    int bc = 0;
    QSMESH_CG(cg_boco_write(fn, base, zone, r.name.c_str(), CGNS_ENUMV(FamilySpecified),
                            CGNS_ENUMV(PointRange), 2, range, &bc));
    QSMESH_CG(cg_boco_gridlocation_write(fn, base, zone, bc, CGNS_ENUMV(EdgeCenter)));
    fix_range_label(cgio, root,
                    "/" + options.cgns_base_name + "/" + options.cgns_zone_name + "/ZoneBC/" +
                        r.name + "/PointRange",
                    path);
    QSMESH_CG(cg_goto(fn, base, "Zone_t", zone, "ZoneBC_t", 1, "BC_t", bc, "end"));
    QSMESH_CG(cg_famname_write(r.name.c_str()));
  }

  file.fn = -1;
  QSMESH_CG(cg_close(fn));
  strip_hdf5_times(out.temp_path());
  out.commit();
}

namespace {

// The zone of the faces the layout left out.
constexpr const char* kUnstructuredZone = "Unstructured";

// A new cgio node. cgio stores the name, label and data type as fixed-length fields (33, 33 and 3
// bytes) read from the pointers it is given, whatever the strings' lengths: given literals, the
// bytes that follow them in the program's memory went into the file, so files differed between
// builds. They go through zero-padded copies.
void new_node(int cgio, double parent, const std::string& name, const char* label, const char* type,
              int ndims, const cgsize_t* dims, const void* data, double* id,
              const std::string& path) {
  char n[CGIO_MAX_NAME_LENGTH + 1] = {}, l[CGIO_MAX_LABEL_LENGTH + 1] = {},
                                t[CGIO_MAX_DATATYPE_LENGTH + 1] = {};
  std::strncpy(n, name.c_str(), CGIO_MAX_NAME_LENGTH);
  std::strncpy(l, label, CGIO_MAX_LABEL_LENGTH);
  // memcpy: GCC's -Wstringop-truncation takes strncpy of a 2-character type into 2 bytes (the
  // array's last byte stays zero) for a lost terminator.
  std::memcpy(t, type, std::min<std::size_t>(std::strlen(type), CGIO_MAX_DATATYPE_LENGTH));
  QSMESH_CGIO(cgio_new_node(cgio, parent, n, l, t, ndims, dims, data, id));
}

// cgio (HDF5) keeps every node id it hands out open until it is released or the file closes; the
// open objects slow every later HDF5 call (docs/benchmarks.md, "Block CGNS write speed"), so the
// ids made or looked up here are released as soon as they are done with.
void release_node(int cgio, double id, const std::string& path) {
  QSMESH_CGIO(cgio_release_id(cgio, id));
}

// A new leaf node (no children added later): made and released.
void new_leaf(int cgio, double parent, const std::string& name, const char* label, const char* type,
              int ndims, const cgsize_t* dims, const void* data, const std::string& path) {
  double id = 0;
  new_node(cgio, parent, name, label, type, ndims, dims, data, &id, path);
  release_node(cgio, id, path);
}

// The ZoneGridConnectivity node of zone `zone` (made through cgio, as the connectivities under it).
double new_zone_grid_connectivity(int cgio, double root, const std::string& base,
                                  const std::string& zone, const std::string& path) {
  double zone_id = 0, id = 0;
  QSMESH_CGIO(cgio_get_node_id(cgio, root, ("/" + base + "/" + zone).c_str(), &zone_id));
  new_node(cgio, zone_id, "ZoneGridConnectivity", "ZoneGridConnectivity_t", "MT", 0, nullptr,
           nullptr, &id, path);
  release_node(cgio, zone_id, path);
  return id;
}

// A GridConnectivity_t node (Abutting1to1, at vertices) under the ZoneGridConnectivity `parent`:
// this zone's points as `points` (a PointRange or a PointList), the donor's as a PointListDonor
// in the same order. Written through cgio, as the 1-to-1 interfaces are: cgnslib does not know
// the ZoneGridConnectivity nodes made that way.
void write_abutment(int cgio, double parent, const std::string& name, const std::string& donor,
                    const char* points_name, const char* points_label,
                    std::array<cgsize_t, 2> points_dims, const cgsize_t* points,
                    std::array<cgsize_t, 2> donor_dims, const cgsize_t* donor_points,
                    const std::string& path) {
  double id = 0;
  const cgsize_t donor_size[1] = {static_cast<cgsize_t>(donor.size())};
  new_node(cgio, parent, name.c_str(), "GridConnectivity_t", "C1", 1, donor_size, donor.data(), &id,
           path);
  const std::string type = "Abutting1to1", location = "Vertex";
  const cgsize_t type_size[1] = {static_cast<cgsize_t>(type.size())};
  const cgsize_t location_size[1] = {static_cast<cgsize_t>(location.size())};
  new_leaf(cgio, id, "GridConnectivityType", "GridConnectivityType_t", "C1", 1, type_size,
           type.data(), path);
  new_leaf(cgio, id, "GridLocation", "GridLocation_t", "C1", 1, location_size, location.data(),
           path);
  new_leaf(cgio, id, points_name, points_label, "I4", 2, points_dims.data(), points, path);
  new_leaf(cgio, id, "PointListDonor", "IndexArray_t", "I4", 2, donor_dims.data(), donor_points,
           path);
  release_node(cgio, id, path);
}

// The name of connectivity node number n of a zone ("C1", "C2", ...).
std::string connection_name(int n) {
  // Appended rather than "C" + ...: GCC 12 reports a false -Wrestrict on that concatenation.
  std::string name(1, 'C');
  name += std::to_string(n);
  return name;
}

}  // namespace

void write_cgns_blocks(const mesh::SurfaceMesh& mesh, const layout::QuadLayout& layout,
                       const std::string& path, const WriteOptions& options) {
  static_assert(sizeof(cgsize_t) == sizeof(std::int32_t),
                "point ranges and lists are written as I4 cgio nodes from cgsize_t arrays");
  detail::check_output_folder(path);
  check_mesh_for_output(mesh);
  QSMESH_CHECK(mesh.order == 1,
               "CGNS block output " << path << ": blocks of high-order quads are not written");
  const auto unit = length_unit(mesh.length_unit);
  const auto nb = static_cast<GO>(layout.blocks.size());
  check_layout_for_output(mesh, layout, "CGNS block output " + path);
  const BlockConnections joined = block_connections(mesh, layout);

  // The faces left out go into one unstructured zone; its vertices are numbered in the order its
  // elements first use them.
  const detail::ElementGroups groups = detail::group_elements(mesh);
  std::vector<GO> local(static_cast<std::size_t>(mesh.num_vertices()), -1);
  std::vector<GO> used;
  GO unstructured_cells = 0;
  {
    auto element = [&](const auto& vertices) {
      for (GO v : vertices) {
        if (local[static_cast<std::size_t>(v)] < 0) {
          local[static_cast<std::size_t>(v)] = static_cast<GO>(used.size());
          used.push_back(v);
        }
      }
    };
    for (LO f : layout.unblocked_faces) {
      for (GO t : groups.face2tris[static_cast<std::size_t>(f)])
        element(mesh.triangles[static_cast<std::size_t>(t)]);
      for (GO q : groups.face2quads[static_cast<std::size_t>(f)])
        element(mesh.quads[static_cast<std::size_t>(q)]);
      unstructured_cells += static_cast<GO>(groups.face2tris[static_cast<std::size_t>(f)].size() +
                                            groups.face2quads[static_cast<std::size_t>(f)].size());
    }
  }
  // What the unstructured zone's connectivity to the blocks needs: per run of block side edges on
  // it, the block and the points' (i, j) and unstructured ids, in the same order.
  struct Abutment {
    GO block;
    std::vector<cgsize_t> ij;     // i1, j1, i2, j2, ...
    std::vector<cgsize_t> local;  // 1-based ids in the unstructured zone
  };
  std::vector<Abutment> abutments;

  AtomicFile out(path);
  CgFile file;
  const int fn = open_for_write(out, file, path);
  const int base = write_base(fn, options, unit, path);
  {
    std::vector<char> has(static_cast<std::size_t>(mesh.num_cad_faces), 0);
    for (const layout::Block& b : layout.blocks) has[static_cast<std::size_t>(b.face)] = 1;
    for (LO f : layout.unblocked_faces) has[static_cast<std::size_t>(f)] = 1;
    for (LO f = 0; f < mesh.num_cad_faces; ++f) {
      if (!has[static_cast<std::size_t>(f)]) continue;
      int family = 0;
      QSMESH_CG(cg_family_write(fn, base, ("Face_" + std::to_string(f)).c_str(), &family));
    }
  }
  // Curves with free block edges (no other block across: an open shell's border, a cut plane) get a
  // family and BCs on those edges, as in write_cgns.
  {
    std::vector<char> free_curve(static_cast<std::size_t>(mesh.num_cad_curves), 0);
    for (const BlockLinks& links : joined.blocks)
      for (const BlockBoundary& r : links.boundaries)
        free_curve[static_cast<std::size_t>(r.curve)] = 1;
    for (LO c = 0; c < mesh.num_cad_curves; ++c) {
      if (!free_curve[static_cast<std::size_t>(c)]) continue;
      int family = 0, fambc = 0;
      QSMESH_CG(cg_family_write(fn, base, ("Curve_" + std::to_string(c)).c_str(), &family));
      QSMESH_CG(cg_fambc_write(fn, base, family, "FamBC", CGNS_ENUMV(BCWall), &fambc));
    }
  }

  int cgio = 0;
  double root = 0;
  QSMESH_CG(cg_get_cgio(fn, &cgio));
  QSMESH_CG(cg_root_id(fn, &root));
  double base_id = 0;
  QSMESH_CGIO(cgio_get_node_id(cgio, root, ("/" + options.cgns_base_name).c_str(), &base_id));
  // The block zones are written through cgio, not cg_zone_write and friends: cgnslib 3.4 checks a
  // new node's name against every child of its parent (ADFH_Create iterates the parent's links),
  // so zone k made under the base costs time in k, O(zones^2) in all (A319's 3,565 zones: 19 s of
  // write). Each zone is made under a holder node with no other child, filled there, then moved
  // under the base (ADFH_Move_Child iterates the holder only, and HDF5's move into the base's
  // indexed group does not scan it); the holder is deleted at the end. cgnslib's own tree does
  // not know these zones, which is why everything under them goes through cgio too.
  double holder = 0;
  new_node(cgio, root, "qsmesh zones being written", "UserDefinedData_t", "MT", 0, nullptr, nullptr,
           &holder, path);
  auto zone_name = [&](GO k) { return block_name(layout, k, mesh.num_cad_faces); };
  const float exponents[5] = {0, 1, 0, 0, 0};  // lengths: (mass, length, time, temp., angle)
  const cgsize_t exponents_dims[1] = {5};
  std::vector<double> coord;
  for (GO k = 0; k < nb; ++k) {
    const layout::Block& b = layout.blocks[static_cast<std::size_t>(k)];
    const std::string name = zone_name(k);
    QSMESH_CHECK(name.size() <= 32,
                 "CGNS block output " << path << ": zone name " << name << " too long");
    // Zone_t: VertexSize, CellSize, VertexSizeBoundary per index, as cg_zone_write stores them.
    const cgsize_t size[6] = {b.ni + 1, b.nj + 1, b.ni, b.nj, 0, 0};
    const cgsize_t size_dims[2] = {2, 3};
    double zone_id = 0;
    new_node(cgio, holder, name, "Zone_t", "I4", 2, size_dims, size, &zone_id, path);
    const std::string structured = "Structured";
    const cgsize_t structured_size[1] = {static_cast<cgsize_t>(structured.size())};
    new_leaf(cgio, zone_id, "ZoneType", "ZoneType_t", "C1", 1, structured_size, structured.data(),
             path);
    double coords_id = 0;
    new_node(cgio, zone_id, "GridCoordinates", "GridCoordinates_t", "MT", 0, nullptr, nullptr,
             &coords_id, path);
    const auto n = static_cast<std::size_t>(b.ni + 1) * static_cast<std::size_t>(b.nj + 1);
    const cgsize_t coord_dims[2] = {b.ni + 1, b.nj + 1};
    coord.resize(n);
    const char* names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    for (int d = 0; d < 3; ++d) {
      for (std::size_t i = 0; i < n; ++i)
        coord[i] = mesh.points[static_cast<std::size_t>(
            layout.vertices[static_cast<std::size_t>(b.first) + i])][d];
      double array_id = 0;
      new_node(cgio, coords_id, names[d], "DataArray_t", "R8", 2, coord_dims, coord.data(),
               &array_id, path);
      new_leaf(cgio, array_id, "DimensionalExponents", "DimensionalExponents_t", "R4", 1,
               exponents_dims, exponents, path);
      release_node(cgio, array_id, path);
    }
    release_node(cgio, coords_id, path);
    {
      const std::string family = "Face_" + std::to_string(b.face);
      const cgsize_t family_size[1] = {static_cast<cgsize_t>(family.size())};
      new_leaf(cgio, zone_id, "FamilyName", "FamilyName_t", "C1", 1, family_size, family.data(),
               path);
    }

    // Per side: its 1-to-1 interfaces, its runs along the unstructured zone, its BCs.
    int connections = 0, boundaries = 0;
    double zgc_id = 0;  // the zone's ZoneGridConnectivity node, made with its first interface
    double zbc_id = 0;  // its ZoneBC node, made with its first BC
    // The name of the zone's next connectivity node, the ZoneGridConnectivity made with the first.
    auto next_connection = [&] {
      if (zgc_id == 0)
        new_node(cgio, zone_id, "ZoneGridConnectivity", "ZoneGridConnectivity_t", "MT", 0, nullptr,
                 nullptr, &zgc_id, path);
      return connection_name(++connections);
    };
    const BlockLinks& links = joined.blocks[static_cast<std::size_t>(k)];
    for (int s = 0; s < 4; ++s) {
      for (const BlockInterface& r : links.interfaces) {
        if (r.side != s) continue;
        const std::string cname = next_connection();
        const std::string donor_name = zone_name(r.donor);
        const cgsize_t name_size[1] = {static_cast<cgsize_t>(donor_name.size())};
        double conn_id = 0;
        new_node(cgio, zgc_id, cname.c_str(), "GridConnectivity1to1_t", "C1", 1, name_size,
                 donor_name.data(), &conn_id, path);
        const cgsize_t range_dims[2] = {2, 2}, transform_dims[1] = {2};
        new_leaf(cgio, conn_id, "Transform", "\"int[IndexDimension]\"", "I4", 1, transform_dims,
                 r.transform.data(), path);
        new_leaf(cgio, conn_id, "PointRange", "IndexRange_t", "I4", 2, range_dims, r.range.data(),
                 path);
        new_leaf(cgio, conn_id, "PointRangeDonor", "IndexRange_t", "I4", 2, range_dims,
                 r.donor_range.data(), path);
        release_node(cgio, conn_id, path);
      }
      // Runs of side edges on the unstructured zone: a GridConnectivity (Abutting1to1, vertex
      // ranges here, vertex lists there), written as cgio nodes beside the 1-to-1 ones.
      for (const BlockAbutment& r : links.abutments) {
        if (r.side != s) continue;
        Abutment a{k, {}, {}};
        for (std::size_t x = 0; x < r.ij.size(); ++x) {
          a.ij.insert(a.ij.end(), r.ij[x].begin(), r.ij[x].end());
          a.local.push_back(
              static_cast<cgsize_t>(local[static_cast<std::size_t>(r.vertices[x])] + 1));
        }
        const std::string cname = next_connection();  // makes zgc_id with the first
        write_abutment(cgio, zgc_id, cname, kUnstructuredZone, "PointRange", "IndexRange_t", {2, 2},
                       r.range.data(), {1, static_cast<cgsize_t>(a.local.size())}, a.local.data(),
                       path);
        abutments.push_back(std::move(a));
      }
      // Free edges: one BC per run of them on one curve (BC_t FamilySpecified, a vertex point
      // range, the curve's family), as cg_boco_write and cg_famname_write would make it.
      for (const BlockBoundary& r : links.boundaries) {
        if (r.side != s) continue;
        std::string bcname("BC");
        bcname += std::to_string(++boundaries);
        if (zbc_id == 0)
          new_node(cgio, zone_id, "ZoneBC", "ZoneBC_t", "MT", 0, nullptr, nullptr, &zbc_id, path);
        const std::string type = "FamilySpecified";
        const cgsize_t type_size[1] = {static_cast<cgsize_t>(type.size())};
        double bc_id = 0;
        new_node(cgio, zbc_id, bcname, "BC_t", "C1", 1, type_size, type.data(), &bc_id, path);
        const cgsize_t range_dims[2] = {2, 2};
        new_leaf(cgio, bc_id, "PointRange", "IndexRange_t", "I4", 2, range_dims, r.range.data(),
                 path);
        const std::string family = "Curve_" + std::to_string(r.curve);
        const cgsize_t family_size[1] = {static_cast<cgsize_t>(family.size())};
        new_leaf(cgio, bc_id, "FamilyName", "FamilyName_t", "C1", 1, family_size, family.data(),
                 path);
        release_node(cgio, bc_id, path);
      }
    }
    if (zgc_id != 0) release_node(cgio, zgc_id, path);
    if (zbc_id != 0) release_node(cgio, zbc_id, path);
    QSMESH_CGIO(cgio_move_node(cgio, holder, zone_id, base_id));
    release_node(cgio, zone_id, path);
  }
  QSMESH_CGIO(cgio_delete_node(cgio, root, holder));
  release_node(cgio, base_id, path);

  // Faces the layout could not cut into blocks: one unstructured zone with a section per face, and
  // a GridConnectivity back to every block run abutting it.
  if (!layout.unblocked_faces.empty()) {
    cgsize_t size[3] = {to_cg(static_cast<GO>(used.size()), path), to_cg(unstructured_cells, path),
                        0};
    int zone = 0;
    QSMESH_CG(cg_zone_write(fn, base, kUnstructuredZone, size, CGNS_ENUMV(Unstructured), &zone));
    write_coordinates(
        fn, base, zone, used.size(),
        [&](std::size_t i) { return mesh.points[static_cast<std::size_t>(used[i])]; }, path);
    (void)write_face_sections(
        fn, base, zone, mesh, groups, layout.unblocked_faces,
        [&](GO v) { return static_cast<cgsize_t>(local[static_cast<std::size_t>(v)] + 1); }, 1,
        false, path);
    if (!abutments.empty()) {
      const double zgc_id =
          new_zone_grid_connectivity(cgio, root, options.cgns_base_name, kUnstructuredZone, path);
      int connections = 0;
      for (const Abutment& a : abutments) {
        const auto n = static_cast<cgsize_t>(a.local.size());
        write_abutment(cgio, zgc_id, connection_name(++connections), zone_name(a.block),
                       "PointList", "IndexArray_t", {1, n}, a.local.data(), {2, n}, a.ij.data(),
                       path);
      }
      release_node(cgio, zgc_id, path);
    }
  }

  file.fn = -1;
  QSMESH_CG(cg_close(fn));
  strip_hdf5_times(out.temp_path());
  out.commit();
}

}  // namespace qsmesh::io
