// Reads a block-structured CGNS file (io::write_cgns_blocks) back through cgio, node by node as
// the writer makes the zones (cgnslib's cg_open reads the whole tree first, walking the base's
// children once per label: 77 % of the time on A319's 3,590 zones, and Block's 73k zones did not
// finish in 42 min; docs/benchmarks.md), and checks it:
// - every GridConnectivity1to1 joins points with the same coordinates under its transform (a
//   signed permutation whose image of the range's end is the donor range's end), and has its
//   reciprocal in the donor zone;
// - every general GridConnectivity (a block abutting the unstructured zone) joins points with the
//   same coordinates, point by point, and has its reverse in the unstructured zone (the same
//   points, read there and checked there too);
// - every BC lies on a block side, on no edge another block side or an unstructured element also
//   has (that would be a wall inside the surface where a connection is missing);
// - every edge of every block side is covered exactly once, by an interface, a connectivity or a
//   BC (a side edge nothing covers would be an open boundary inside the surface); except where
//   m > 2 zone sides meet at one edge (a non-manifold CAD curve: three or more faces along it):
//   there each block side edge is covered m - 1 times, once by each of the other sides and by no
//   BC, every other side having the same partners at that edge (the interfaces at an edge join
//   every pair of its sides, each pair once, both ways: edge by edge, this is also what makes two
//   sides covered once each a reciprocal pair).
// Every node read is checked against the SIDS as cgnslib would read it (labels, data types,
// dimensions, GridConnectivityType and GridLocation defaulting to Overset and Vertex); every cgio
// return code is checked. Header-only; the test must link cgnslib (qsmesh_cgns).
#pragma once

#include <cgns_io.h>
#include <cgnslib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

namespace qsmesh::test {

struct BlockFileSummary {
  std::string error;  ///< empty when every check passed
  int structured_zones = 0;
  int unstructured_zones = 0;
  std::int64_t block_quads = 0;
  std::int64_t interfaces = 0;
  std::int64_t interface_points = 0;
  std::int64_t boundary_conditions = 0;  ///< BCs (free block edges), each checked to lie on a side
  std::int64_t abutments = 0;  ///< general connectivities between a block and the unstructured zone
  /// Cells along i and along j of each structured zone, in the file's order.
  std::vector<std::array<std::int64_t, 2>> block_cells;
};

namespace detail {

// One zone of the file as cgnslib's read calls would give it.
struct FileZone {
  std::string name;
  bool structured = false;
  std::vector<cgsize_t> vertex_size, cell_size;  // per index direction
  std::array<std::vector<double>, 3> xyz;
  struct OneToOne {
    std::string name, donor;
    cgsize_t range[4], donor_range[4];
    int transform[2];
  };
  struct Conn {
    std::string name, donor, location, type;
    CGNS_ENUMT(PointSetType_t) points = CGNS_ENUMV(PointSetTypeNull);
    std::vector<cgsize_t> pnts, donor_pnts;  // as cg_conn_read gives them
    cgsize_t npnts = 0, ndonor = 0;
  };
  struct Boco {
    std::string name;
    CGNS_ENUMT(PointSetType_t) points = CGNS_ENUMV(PointSetTypeNull);
    std::vector<cgsize_t> pnts;
  };
  struct Section {
    std::string name;
    int type = 0;
    std::vector<cgsize_t> data;  // ElementConnectivity (MIXED: each element led by its type)
  };
  std::vector<OneToOne> one_to_one;
  std::vector<Conn> conns;
  std::vector<Boco> bocos;
  std::vector<Section> sections;
};

// Reads the file's first base through cgio; `err` gets what cannot be read or breaks the SIDS.
class CgioReader {
 public:
  explicit CgioReader(std::ostringstream& err) : err_(err) {}
  ~CgioReader() {
    if (cgio_ >= 0) cgio_close_file(cgio_);
  }
  CgioReader(const CgioReader&) = delete;
  CgioReader& operator=(const CgioReader&) = delete;

  bool open(const std::string& path) {
    if (cgio_open_file(path.c_str(), CGIO_MODE_READ, CGIO_FILE_NONE, &cgio_) != CGIO_ERR_NONE) {
      cgio_ = -1;
      return fail("cgio_open_file " + path);
    }
    double root = 0;
    if (!ok(cgio_get_root_id(cgio_, &root), "cgio_get_root_id")) return false;
    for (const auto& [name, label] : children(root))
      if (label == "CGNSBase_t") {
        base_name_ = name;
        return ok(cgio_get_node_id(cgio_, root, name.c_str(), &base_), "base " + name);
      }
    return fail("no CGNSBase_t node");
  }

  // The zones' names, sorted as cgnslib numbers them (cgi_sort_names: by name).
  std::vector<std::string> zone_names() {
    std::vector<std::string> out;
    for (const auto& [name, label] : children(base_))
      if (label == "Zone_t") out.push_back(name);
    std::sort(out.begin(), out.end());
    return out;
  }

  // Zone `name`, all its nodes read and released.
  bool read_zone(const std::string& name, FileZone& z) {
    double id = 0;
    if (!ok(cgio_get_node_id(cgio_, base_, name.c_str(), &id), "zone " + name)) return false;
    z.name = name;
    bool good = read_zone_nodes(id, z);
    good = ok(cgio_release_id(cgio_, id), "cgio_release_id") && good;
    return good;
  }

 private:
  bool ok(int rc, const std::string& what) {
    if (rc == CGIO_ERR_NONE) return true;
    char msg[CGIO_MAX_ERROR_LENGTH + 1] = {};
    cgio_error_message(msg);
    err_ << what << ": " << msg << "; ";
    return false;
  }
  bool fail(const std::string& what) {
    err_ << what << "; ";
    return false;
  }

  // (name, label) of each child of `id`, without opening them.
  std::vector<std::pair<std::string, std::string>> children(double id) {
    std::vector<std::pair<std::string, std::string>> out;
    int n = 0;
    if (!ok(cgio_number_children(cgio_, id, &n), "cgio_number_children") || n == 0) return out;
    std::vector<char> names(static_cast<std::size_t>(n) * (CGIO_MAX_NAME_LENGTH + 1), 0);
    int got = 0;
    if (!ok(cgio_children_names(cgio_, id, 1, n, CGIO_MAX_NAME_LENGTH + 1, &got, names.data()),
            "cgio_children_names"))
      return out;
    for (int k = 0; k < got; ++k) {
      const char* c = names.data() + static_cast<std::size_t>(k) * (CGIO_MAX_NAME_LENGTH + 1);
      const std::string name(c, strnlen(c, CGIO_MAX_NAME_LENGTH));
      double child = 0;
      char label[CGIO_MAX_LABEL_LENGTH + 1] = {};
      if (!ok(cgio_get_node_id(cgio_, id, name.c_str(), &child), "child " + name)) continue;
      ok(cgio_get_label(cgio_, child, label), "cgio_get_label " + name);
      ok(cgio_release_id(cgio_, child), "cgio_release_id");
      out.emplace_back(name, label);
    }
    return out;
  }

  // A child node's id (released by the caller), or 0 with an error when it is missing.
  double child(double id, const std::string& name, const std::string& where) {
    double c = 0;
    if (cgio_get_node_id(cgio_, id, name.c_str(), &c) != CGIO_ERR_NONE) {
      fail(where + ": no " + name);
      return 0;
    }
    return c;
  }
  void release(double id) {
    if (id != 0) ok(cgio_release_id(cgio_, id), "cgio_release_id");
  }

  // The data of node `id` as type T ("I4"/"I8" for integers, "R8" for reals), with its
  // dimensions; false (and an error) when it has none or cannot be read.
  template <typename T>
  bool data(double id, const std::string& where, std::vector<T>& out,
            std::vector<cgsize_t>* dims = nullptr) {
    int nd = 0;
    cgsize_t d[CGIO_MAX_DIMENSIONS] = {};
    if (!ok(cgio_get_dimensions(cgio_, id, &nd, d), where + " dimensions")) return false;
    if (nd < 1) return fail(where + ": no data");
    std::size_t n = 1;
    for (int k = 0; k < nd; ++k) n *= static_cast<std::size_t>(d[k]);
    if (dims != nullptr) dims->assign(d, d + nd);
    out.resize(n);
    const char* type = std::is_same_v<T, double> ? "R8" : sizeof(T) == 8 ? "I8" : "I4";
    return n == 0 || ok(cgio_read_all_data_type(cgio_, id, type, out.data()), where + " data");
  }
  std::string text(double id, const std::string& where) {
    std::vector<char> c;
    int nd = 0;
    cgsize_t d[CGIO_MAX_DIMENSIONS] = {};
    char type[CGIO_MAX_DATATYPE_LENGTH + 1] = {};
    if (!ok(cgio_get_data_type(cgio_, id, type), where + " type") ||
        !ok(cgio_get_dimensions(cgio_, id, &nd, d), where + " dimensions"))
      return {};
    if (std::string(type) != "C1" || nd != 1) {
      fail(where + ": not a character string");
      return {};
    }
    c.resize(static_cast<std::size_t>(d[0]));
    if (!c.empty() && !ok(cgio_read_all_data(cgio_, id, c.data()), where + " data")) return {};
    return std::string(c.data(), strnlen(c.data(), c.size()));
  }
  // The string of child `name` of `id`, or `fallback` when there is none (a SIDS default).
  std::string child_text(double id, const std::string& name, const std::string& fallback,
                         const std::string& where) {
    double c = 0;
    if (cgio_get_node_id(cgio_, id, name.c_str(), &c) != CGIO_ERR_NONE) return fallback;
    std::string t = text(c, where + "/" + name);
    release(c);
    return t;
  }

  bool read_zone_nodes(double id, FileZone& z) {
    const std::string& w = z.name;
    std::vector<cgsize_t> size, dims;
    if (!data(id, w, size, &dims)) return false;
    if (dims.size() != 2 || dims[1] != 3) return fail(w + ": zone size is not IndexDimension x 3");
    const auto idim = static_cast<std::size_t>(dims[0]);
    z.vertex_size.assign(size.begin(), size.begin() + static_cast<std::ptrdiff_t>(idim));
    z.cell_size.assign(size.begin() + static_cast<std::ptrdiff_t>(idim),
                       size.begin() + static_cast<std::ptrdiff_t>(2 * idim));
    const std::string type = child_text(id, "ZoneType", "", w);
    if (type != "Structured" && type != "Unstructured") return fail(w + ": zone type " + type);
    z.structured = type == "Structured";
    if (z.structured != (idim == 2)) return fail(w + ": index dimension");
    const double coords = child(id, "GridCoordinates", w);
    bool good = coords != 0;
    const char* names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    for (int d = 0; d < 3 && good; ++d) {
      const double c = child(coords, names[d], w + "/GridCoordinates");
      std::vector<cgsize_t> cd;
      good = c != 0 && data(c, w + " " + names[d], z.xyz[static_cast<std::size_t>(d)], &cd);
      if (good && cd != z.vertex_size) good = fail(w + " " + names[d] + ": not the zone's size");
      release(c);
    }
    release(coords);
    if (!good) return false;
    for (const auto& [name, label] : children(id)) {
      if (label == "ZoneGridConnectivity_t") {
        const double zgc = child(id, name, w);
        if (zgc == 0) continue;
        for (const auto& [cname, clabel] : children(zgc)) {
          if (clabel == "GridConnectivity1to1_t") read_1to1(zgc, cname, z);
          if (clabel == "GridConnectivity_t") read_conn(zgc, cname, z);
        }
        release(zgc);
      } else if (label == "ZoneBC_t") {
        const double zbc = child(id, name, w);
        if (zbc == 0) continue;
        for (const auto& [bname, blabel] : children(zbc))
          if (blabel == "BC_t") read_boco(zbc, bname, z);
        release(zbc);
      } else if (label == "Elements_t") {
        read_section(id, name, z);
      }
    }
    return true;
  }

  void read_1to1(double parent, const std::string& name, FileZone& z) {
    const std::string w = z.name + "/" + name;
    const double id = child(parent, name, w);
    if (id == 0) return;
    FileZone::OneToOne c{};
    c.name = name;
    c.donor = text(id, w);
    std::vector<cgsize_t> r, d, t, rd, dd;
    const double ri = child(id, "PointRange", w), di = child(id, "PointRangeDonor", w);
    bool good = ri != 0 && di != 0 && data(ri, w + "/PointRange", r, &rd) &&
                data(di, w + "/PointRangeDonor", d, &dd);
    release(ri);
    release(di);
    if (good && (r.size() != 4 || d.size() != 4)) good = fail(w + ": ranges are not 2 x 2");
    // Transform: cgnslib's default is the identity when the node is missing.
    c.transform[0] = 1;
    c.transform[1] = 2;
    double ti = 0;
    if (cgio_get_node_id(cgio_, id, "Transform", &ti) == CGIO_ERR_NONE) {
      if (data(ti, w + "/Transform", t) && t.size() == 2) {
        c.transform[0] = static_cast<int>(t[0]);
        c.transform[1] = static_cast<int>(t[1]);
      } else {
        good = fail(w + ": Transform");
      }
      release(ti);
    }
    release(id);
    if (!good) return;
    std::copy(r.begin(), r.end(), c.range);
    std::copy(d.begin(), d.end(), c.donor_range);
    z.one_to_one.push_back(std::move(c));
  }

  void read_conn(double parent, const std::string& name, FileZone& z) {
    const std::string w = z.name + "/" + name;
    const double id = child(parent, name, w);
    if (id == 0) return;
    FileZone::Conn c;
    c.name = name;
    c.donor = text(id, w);
    c.type = child_text(id, "GridConnectivityType", "Overset", w);
    c.location = child_text(id, "GridLocation", "Vertex", w);
    std::vector<cgsize_t> dims;
    double pi = 0;
    if (cgio_get_node_id(cgio_, id, "PointRange", &pi) == CGIO_ERR_NONE) {
      c.points = CGNS_ENUMV(PointRange);
    } else if (cgio_get_node_id(cgio_, id, "PointList", &pi) == CGIO_ERR_NONE) {
      c.points = CGNS_ENUMV(PointList);
    } else {
      fail(w + ": no PointRange or PointList");
      release(id);
      return;
    }
    bool good = data(pi, w + " points", c.pnts, &dims);
    release(pi);
    const std::size_t idim = z.structured ? 2 : 1;
    if (good && (dims.size() != 2 || static_cast<std::size_t>(dims[0]) != idim))
      good = fail(w + ": points are not IndexDimension x n");
    if (good) c.npnts = dims[1];
    const double di = child(id, "PointListDonor", w);
    good = good && di != 0 && data(di, w + "/PointListDonor", c.donor_pnts, &dims);
    release(di);
    if (good && dims.size() != 2) good = fail(w + ": PointListDonor is not n x m");
    if (good) c.ndonor = dims[1];
    release(id);
    if (good) z.conns.push_back(std::move(c));
  }

  void read_boco(double parent, const std::string& name, FileZone& z) {
    const std::string w = z.name + "/" + name;
    const double id = child(parent, name, w);
    if (id == 0) return;
    FileZone::Boco b;
    b.name = name;
    double pi = 0;
    if (cgio_get_node_id(cgio_, id, "PointRange", &pi) == CGIO_ERR_NONE) {
      b.points = CGNS_ENUMV(PointRange);
      if (!data(pi, w + "/PointRange", b.pnts)) b.points = CGNS_ENUMV(PointSetTypeNull);
      release(pi);
    } else if (cgio_get_node_id(cgio_, id, "PointList", &pi) == CGIO_ERR_NONE) {
      b.points = CGNS_ENUMV(PointList);
      release(pi);
    } else {
      fail(w + ": no point set");
    }
    release(id);
    z.bocos.push_back(std::move(b));
  }

  void read_section(double parent, const std::string& name, FileZone& z) {
    const std::string w = z.name + "/" + name;
    const double id = child(parent, name, w);
    if (id == 0) return;
    FileZone::Section sec;
    sec.name = name;
    std::vector<cgsize_t> head;
    const double ci = child(id, "ElementConnectivity", w);
    const bool good = data(id, w, head) && head.size() == 2 && ci != 0 &&
                      data(ci, w + "/ElementConnectivity", sec.data);
    release(ci);
    release(id);
    if (!good) {
      fail(w + ": section not read");
      return;
    }
    sec.type = static_cast<int>(head[0]);
    z.sections.push_back(std::move(sec));
  }

  std::ostringstream& err_;
  int cgio_ = -1;
  double base_ = 0;
  std::string base_name_;
};

}  // namespace detail

/// whole_sides: also every 1-to-1 interface spans a whole side of its zone and of its donor (a
/// conforming layout: no T-junction; the dense layout of `--layout dense` has them).
inline BlockFileSummary check_block_file(const std::string& path, bool whole_sides = false) {
  BlockFileSummary out;
  std::ostringstream err;
  detail::CgioReader reader(err);
  if (!reader.open(path)) {
    out.error = err.str();
    return out;
  }
  bool failed = false;
  struct Zone {
    std::string name;
    bool structured = false;
    cgsize_t ni = 0, nj = 0;  // vertices along i and j (structured); ni vertices (unstructured)
    std::array<std::vector<double>, 3> xyz;
    // Side edges covered, per side (0: j = 1, 1: i = ni, 2: j = nj, 3: i = 1), by position; and
    // by BCs only.
    std::array<std::vector<int>, 4> covered, walls;
    detail::FileZone file;  // its nodes as read (connectivities, BCs, sections)
  };
  std::vector<Zone> zones;
  std::map<std::string, int> by_name;
  const std::vector<std::string> zone_names = reader.zone_names();
  const int nzones = static_cast<int>(zone_names.size());
  for (int z = 1; z <= nzones; ++z) {
    Zone zone;
    if (!reader.read_zone(zone_names[static_cast<std::size_t>(z - 1)], zone.file)) {
      failed = true;
      break;
    }
    detail::FileZone& f = zone.file;
    zone.name = f.name;
    zone.structured = f.structured;
    zone.xyz = std::move(f.xyz);
    if (zone.structured) {
      ++out.structured_zones;
      zone.ni = f.vertex_size[0];
      zone.nj = f.vertex_size[1];
      out.block_quads += static_cast<std::int64_t>(f.cell_size[0]) * f.cell_size[1];
      out.block_cells.push_back(
          {static_cast<std::int64_t>(f.cell_size[0]), static_cast<std::int64_t>(f.cell_size[1])});
      if (f.cell_size[0] != zone.ni - 1 || f.cell_size[1] != zone.nj - 1)
        err << zone.name << ": cell sizes; ";
      for (int s = 0; s < 4; ++s) {
        zone.covered[static_cast<std::size_t>(s)].assign(
            static_cast<std::size_t>(s % 2 == 0 ? zone.ni - 1 : zone.nj - 1), 0);
        zone.walls[static_cast<std::size_t>(s)] = zone.covered[static_cast<std::size_t>(s)];
      }
    } else {
      ++out.unstructured_zones;
      zone.ni = f.vertex_size[0];
    }
    by_name[zone.name] = z - 1;
    zones.push_back(std::move(zone));
  }
  auto point = [](const Zone& zone, cgsize_t i, cgsize_t j) {
    const auto k = static_cast<std::size_t>(zone.structured ? (j - 1) * zone.ni + (i - 1) : i - 1);
    return std::array<double, 3>{zone.xyz[0][k], zone.xyz[1][k], zone.xyz[2][k]};
  };
  // The side of a structured zone that the range r (one index constant) lies on, or -1.
  auto side_of = [](const Zone& zone, const cgsize_t r[4]) {
    if (r[0] == r[2] && r[1] == r[3]) return -1;
    if (r[1] == r[3] && r[1] == 1) return 0;
    if (r[0] == r[2] && r[0] == zone.ni) return 1;
    if (r[1] == r[3] && r[1] == zone.nj) return 2;
    if (r[0] == r[2] && r[0] == 1) return 3;
    return -1;
  };
  // Marks the side edges of the side range r (one index constant) of a structured zone as covered
  // (by a BC when `wall`).
  auto cover = [&](Zone& zone, const cgsize_t r[4], const std::string& what, bool wall = false) {
    const int side = side_of(zone, r);
    if (side < 0) {
      err << zone.name << "/" << what << ": not a side range; ";
      return false;
    }
    const int t = side % 2 == 0 ? 0 : 1;  // the index moving along the side
    const cgsize_t a = std::min(r[t], r[t + 2]), b = std::max(r[t], r[t + 2]);
    auto& c = zone.covered[static_cast<std::size_t>(side)];
    for (cgsize_t p = a; p < b; ++p) {
      if (p < 1 || static_cast<std::size_t>(p) > c.size()) {
        err << zone.name << "/" << what << ": range out of the zone; ";
        return false;
      }
      ++c[static_cast<std::size_t>(p - 1)];
      if (wall) ++zone.walls[static_cast<std::size_t>(side)][static_cast<std::size_t>(p - 1)];
    }
    return true;
  };
  // The side edges each block side edge is joined to, (zone, side, 0-based position); the
  // unstructured zone's edges as (zone, -1, 0). Checked at the end: each edge's partners are
  // distinct, and each block partner has the same partners, with this edge for itself.
  using EdgeRef = std::tuple<int, int, cgsize_t>;
  std::map<EdgeRef, std::vector<EdgeRef>> partners;
  // The edges of side range r of zone z, each with its two end points (i, j), in range order.
  auto range_edges = [](const cgsize_t r[4], const auto& f) {
    const int t = r[0] == r[2] ? 1 : 0;  // the index moving along the range
    const cgsize_t step = r[t + 2] >= r[t] ? 1 : -1;
    for (cgsize_t x = r[t]; x != r[t + 2]; x += step) {
      std::array<cgsize_t, 2> a{r[0], r[1]}, b{r[0], r[1]};
      a[static_cast<std::size_t>(t)] = x;
      b[static_cast<std::size_t>(t)] = x + step;
      f(a, b);
    }
  };
  // The side edge between the points a and b of side s of a structured zone.
  auto edge_ref = [](int z, int s, std::array<cgsize_t, 2> a, std::array<cgsize_t, 2> b) {
    const auto t = static_cast<std::size_t>(s % 2);
    return EdgeRef{z, s, std::min(a[t], b[t]) - 1};
  };
  // Abutments as (block zone, its points' (i, j), sorted), from the block side and from the
  // unstructured side: the two lists must be equal.
  std::multiset<std::pair<int, std::vector<std::array<cgsize_t, 2>>>> abut_blocks,
      abut_unstructured;
  // BC edges as (zone, point a, point b), checked at the end against every zone's edges.
  std::vector<std::array<std::array<double, 3>, 2>> bc_edges;
  std::vector<std::string> bc_names;
  // (zone, range, donor zone, donor range), ranges sorted so that both directions compare.
  std::set<std::tuple<int, std::array<cgsize_t, 4>, int, std::array<cgsize_t, 4>>> links;
  auto normal = [](const cgsize_t r[4]) {
    std::array<cgsize_t, 4> x{r[0], r[1], r[2], r[3]};
    if (std::tie(x[2], x[3]) < std::tie(x[0], x[1])) {
      std::swap(x[0], x[2]);
      std::swap(x[1], x[3]);
    }
    return x;
  };
  for (int z = 1; z <= nzones && !failed; ++z) {
    Zone& zone = zones[static_cast<std::size_t>(z - 1)];
    if (!zone.structured) continue;
    for (const detail::FileZone::Boco& bc : zone.file.bocos) {
      const std::string& bname = bc.name;
      if (bc.points != CGNS_ENUMV(PointRange) || bc.pnts.size() != 4) {
        err << zone.name << "/" << bname << ": not a point range; ";
        continue;
      }
      const cgsize_t r[4] = {bc.pnts[0], bc.pnts[1], bc.pnts[2], bc.pnts[3]};
      ++out.boundary_conditions;
      if (!cover(zone, r, bname, true)) continue;
      const int t = r[0] == r[2] ? 1 : 0;  // the index moving along the BC
      for (cgsize_t x = std::min(r[t], r[t + 2]); x < std::max(r[t], r[t + 2]); ++x) {
        const cgsize_t i0 = t == 0 ? x : r[0], j0 = t == 0 ? r[1] : x;
        bc_edges.push_back(
            {point(zone, i0, j0), point(zone, t == 0 ? x + 1 : i0, t == 0 ? j0 : x + 1)});
        bc_names.push_back(zone.name + "/" + bname);
      }
    }
    for (const detail::FileZone::OneToOne& one : zone.file.one_to_one) {
      const std::string& cname = one.name;
      const std::string& dname = one.donor;
      const cgsize_t* range = one.range;
      const cgsize_t* donor = one.donor_range;
      const int* transform = one.transform;
      ++out.interfaces;
      cover(zone, range, cname);
      const auto it = by_name.find(dname);
      if (it == by_name.end() || !zones[static_cast<std::size_t>(it->second)].structured) {
        err << zone.name << "/" << cname << ": no structured donor zone " << dname << "; ";
        continue;
      }
      links.insert({z - 1, normal(range), it->second, normal(donor)});
      const Zone& dz = zones[static_cast<std::size_t>(it->second)];
      if (whole_sides) {
        auto whole = [](const Zone& zz, const cgsize_t r[4]) {
          const bool along_i = r[1] == r[3];
          const cgsize_t lo = std::min(r[along_i ? 0 : 1], r[along_i ? 2 : 3]);
          const cgsize_t hi = std::max(r[along_i ? 0 : 1], r[along_i ? 2 : 3]);
          return lo == 1 && hi == (along_i ? zz.ni : zz.nj);
        };
        if (!whole(zone, range) || !whole(dz, donor))
          err << zone.name << "/" << cname << ": not a whole side to a whole side (T-junction); ";
      }
      if (std::abs(transform[0]) == std::abs(transform[1]) || std::abs(transform[0]) < 1 ||
          std::abs(transform[0]) > 2 || std::abs(transform[1]) < 1 || std::abs(transform[1]) > 2) {
        err << zone.name << "/" << cname << ": transform is not a signed permutation; ";
        continue;
      }
      // donor index = T (index - begin) + donor begin, T the signed permutation of `transform`.
      auto donor_of = [&](cgsize_t i, cgsize_t j) {
        const std::array<cgsize_t, 2> delta{i - range[0], j - range[1]};
        std::array<cgsize_t, 2> d{donor[0], donor[1]};
        for (int k = 0; k < 2; ++k) {
          const int t = transform[k];
          d[static_cast<std::size_t>(std::abs(t) - 1)] +=
              (t > 0 ? 1 : -1) * delta[static_cast<std::size_t>(k)];
        }
        return d;
      };
      const auto end = donor_of(range[2], range[3]);
      if (end[0] != donor[2] || end[1] != donor[3])
        err << zone.name << "/" << cname << ": PointRangeDonor's end is not the range's image; ";
      const int my_side = side_of(zone, range), donor_side = side_of(dz, donor);
      if (my_side < 0 || donor_side < 0) {
        err << zone.name << "/" << cname << ": not between two side ranges; ";
        continue;
      }
      range_edges(range, [&](std::array<cgsize_t, 2> a, std::array<cgsize_t, 2> b) {
        partners[edge_ref(z - 1, my_side, a, b)].push_back(
            edge_ref(it->second, donor_side, donor_of(a[0], a[1]), donor_of(b[0], b[1])));
      });
      const cgsize_t di = range[2] >= range[0] ? 1 : -1, dj = range[3] >= range[1] ? 1 : -1;
      for (cgsize_t i = range[0];; i += di) {
        for (cgsize_t j = range[1];; j += dj) {
          const auto d = donor_of(i, j);
          if (d[0] < 1 || d[1] < 1 || d[0] > dz.ni || d[1] > dz.nj) {
            err << zone.name << "/" << cname << ": donor index out of range; ";
          } else if (point(zone, i, j) != point(dz, d[0], d[1])) {
            err << zone.name << "/" << cname << ": point (" << i << "," << j
                << ") is not donor point (" << d[0] << "," << d[1] << ") of " << dname << "; ";
          }
          ++out.interface_points;
          if (j == range[3]) break;
        }
        if (i == range[2]) break;
      }
    }
    // General connectivities: a block abutting the unstructured zone, point by point.
    for (const detail::FileZone::Conn& info : zone.file.conns) {
      const std::string& cname = info.name;
      ++out.abutments;
      const auto it = by_name.find(info.donor);
      if (info.points != CGNS_ENUMV(PointRange) || info.npnts != 2 || info.pnts.size() != 4 ||
          it == by_name.end() || zones[static_cast<std::size_t>(it->second)].structured ||
          info.type != "Abutting1to1" || info.location != "Vertex" ||
          info.donor_pnts.size() != static_cast<std::size_t>(info.ndonor)) {
        err << zone.name << "/" << cname << ": not a vertex range abutting the unstructured zone; ";
        continue;
      }
      const cgsize_t range[4] = {info.pnts[0], info.pnts[1], info.pnts[2], info.pnts[3]};
      const std::vector<cgsize_t>& ids = info.donor_pnts;
      const std::string& dname = info.donor;
      if (!cover(zone, range, cname)) continue;
      range_edges(range, [&](std::array<cgsize_t, 2> a, std::array<cgsize_t, 2> b) {
        partners[edge_ref(z - 1, side_of(zone, range), a, b)].push_back({it->second, -1, 0});
      });
      const Zone& dz = zones[static_cast<std::size_t>(it->second)];
      const cgsize_t di = range[2] >= range[0] ? 1 : -1, dj = range[3] >= range[1] ? 1 : -1;
      std::vector<std::array<cgsize_t, 2>> ij;
      std::size_t k = 0;
      for (cgsize_t i = range[0];; i += di) {
        for (cgsize_t j = range[1];; j += dj) {
          if (k >= ids.size() || ids[k] < 1 || ids[k] > dz.ni) {
            err << zone.name << "/" << cname << ": donor point list too short or out of range; ";
          } else if (point(zone, i, j) != point(dz, ids[k], 1)) {
            err << zone.name << "/" << cname << ": point (" << i << "," << j << ") is not point "
                << ids[k] << " of " << dname << "; ";
          }
          ij.push_back({i, j});
          ++k;
          if (j == range[3]) break;
        }
        if (i == range[2]) break;
      }
      if (k != ids.size()) err << zone.name << "/" << cname << ": donor list length; ";
      std::sort(ij.begin(), ij.end());
      abut_blocks.insert({z - 1, ij});
    }
  }
  // The unstructured zone: its connectivities back to the blocks, and its element edges.
  std::map<std::array<double, 6>, int> edge_count;  // surface edges (both ends' coordinates)
  auto edge_key = [](std::array<double, 3> a, std::array<double, 3> b) {
    if (b < a) std::swap(a, b);
    return std::array<double, 6>{a[0], a[1], a[2], b[0], b[1], b[2]};
  };
  for (int z = 1; z <= nzones && !failed; ++z) {
    const Zone& zone = zones[static_cast<std::size_t>(z - 1)];
    if (zone.structured) {
      for (cgsize_t j = 1; j <= zone.nj; ++j)
        for (cgsize_t i = 1; i <= zone.ni; ++i) {
          const bool side_j = j == 1 || j == zone.nj, side_i = i == 1 || i == zone.ni;
          if (i < zone.ni && side_j)
            ++edge_count[edge_key(point(zone, i, j), point(zone, i + 1, j))];
          if (j < zone.nj && side_i)
            ++edge_count[edge_key(point(zone, i, j), point(zone, i, j + 1))];
        }
      continue;
    }
    for (const detail::FileZone::Section& sec : zone.file.sections) {
      const std::string& sname = sec.name;
      const auto etype = static_cast<CGNS_ENUMT(ElementType_t)>(sec.type);
      const std::vector<cgsize_t>& data = sec.data;  // MIXED: each element led by its type
      for (std::size_t at = 0; at < data.size();) {
        CGNS_ENUMT(ElementType_t) type = etype;
        if (etype == CGNS_ENUMV(MIXED)) type = static_cast<CGNS_ENUMT(ElementType_t)>(data[at++]);
        const std::size_t n = type == CGNS_ENUMV(QUAD_4) ? 4 : type == CGNS_ENUMV(TRI_3) ? 3 : 0;
        if (n == 0) {
          err << zone.name << "/" << sname << ": element type " << type << " not read; ";
          break;
        }
        if (at + n > data.size()) {
          err << zone.name << "/" << sname << ": connectivity ends inside an element; ";
          break;
        }
        for (std::size_t k = 0; k < n; ++k)
          ++edge_count[edge_key(point(zone, data[at + k], 1),
                                point(zone, data[at + (k + 1) % n], 1))];
        at += n;
      }
    }
    for (const detail::FileZone::Conn& info : zone.file.conns) {
      const std::string& cname = info.name;
      const std::string& dname = info.donor;
      const auto it = by_name.find(dname);
      if (info.points != CGNS_ENUMV(PointList) || it == by_name.end() ||
          !zones[static_cast<std::size_t>(it->second)].structured || info.ndonor != info.npnts ||
          info.type != "Abutting1to1" || info.location != "Vertex" ||
          info.pnts.size() != static_cast<std::size_t>(info.npnts) ||
          info.donor_pnts.size() != 2 * info.pnts.size()) {
        err << zone.name << "/" << cname << ": not a vertex list abutting a block; ";
        continue;
      }
      const std::vector<cgsize_t>& ids = info.pnts;
      const std::vector<cgsize_t>& donor = info.donor_pnts;
      const Zone& dz = zones[static_cast<std::size_t>(it->second)];
      std::vector<std::array<cgsize_t, 2>> ij;
      for (std::size_t k = 0; k < ids.size(); ++k) {
        const cgsize_t i = donor[2 * k], j = donor[2 * k + 1];
        if (ids[k] < 1 || ids[k] > zone.ni || i < 1 || j < 1 || i > dz.ni || j > dz.nj) {
          err << zone.name << "/" << cname << ": point out of range; ";
          continue;
        }
        if (point(zone, ids[k], 1) != point(dz, i, j))
          err << zone.name << "/" << cname << ": point " << ids[k] << " is not (" << i << "," << j
              << ") of " << dname << "; ";
        ij.push_back({i, j});
      }
      std::sort(ij.begin(), ij.end());
      abut_unstructured.insert({it->second, ij});
    }
  }
  if (abut_blocks != abut_unstructured)
    err << "the connectivities between blocks and the unstructured zone are not the same both "
           "ways; ";
  for (std::size_t e = 0; e < bc_edges.size(); ++e) {
    const auto found = edge_count.find(edge_key(bc_edges[e][0], bc_edges[e][1]));
    if (found != edge_count.end() && found->second > 1)
      err << bc_names[e] << ": a BC on an edge another zone also has; ";
  }
  for (const auto& [a, ra, b, rb] : links)
    if (links.count({b, rb, a, ra}) == 0)
      err << zones[static_cast<std::size_t>(a)].name << ": an interface to "
          << zones[static_cast<std::size_t>(b)].name << " has no reciprocal; ";
  // Edge by edge: partners distinct, and every block partner joined to the same others.
  for (auto& [x, list] : partners) {
    std::vector<EdgeRef> mine = list;
    std::sort(mine.begin(), mine.end());
    const std::string where = zones[static_cast<std::size_t>(std::get<0>(x))].name + ": side " +
                              std::to_string(std::get<1>(x)) + " edge " +
                              std::to_string(std::get<2>(x) + 1);
    if (std::adjacent_find(mine.begin(), mine.end()) != mine.end())
      err << where << " joined twice to the same edge; ";
    for (const EdgeRef& y : mine) {
      if (std::get<1>(y) < 0) continue;  // the unstructured zone: checked both ways above
      const auto found = partners.find(y);
      std::vector<EdgeRef> theirs =
          found == partners.end() ? std::vector<EdgeRef>{} : found->second;
      std::vector<EdgeRef> expected = mine;
      expected.erase(std::find(expected.begin(), expected.end(), y));
      expected.push_back(x);
      std::sort(theirs.begin(), theirs.end());
      std::sort(expected.begin(), expected.end());
      if (theirs != expected)
        err << where << ": the side edge it is joined to in "
            << zones[static_cast<std::size_t>(std::get<0>(y))].name
            << " is not joined to the same edges; ";
    }
  }
  // Once, by one interface, connectivity or BC; or, where m > 2 sides meet, m - 1 times, by the
  // other sides (the partners checked above) and no BC.
  for (std::size_t z = 0; z < zones.size(); ++z) {
    const Zone& zone = zones[z];
    for (int s = 0; s < 4; ++s)
      for (std::size_t p = 0; p < zone.covered[static_cast<std::size_t>(s)].size(); ++p) {
        const int c = zone.covered[static_cast<std::size_t>(s)][p];
        if (c == 1) continue;
        const auto found = partners.find({static_cast<int>(z), s, static_cast<cgsize_t>(p)});
        const bool joined_to_each_other_side =
            c > 1 && zone.walls[static_cast<std::size_t>(s)][p] == 0 && found != partners.end() &&
            static_cast<int>(found->second.size()) == c;
        if (!joined_to_each_other_side)
          err << zone.name << ": side " << s << " edge " << p + 1 << " covered " << c << " times; ";
      }
  }
  out.error = err.str();
  return out;
}

}  // namespace qsmesh::test
