// Reads a block-structured CGNS file (io::write_cgns_blocks) back through cgnslib and checks it:
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
// Every cgnslib return code is checked. Header-only; the test must link cgnslib (qsmesh_cgns).
#pragma once

#include <cgnslib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
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

/// whole_sides: also every 1-to-1 interface spans a whole side of its zone and of its donor (a
/// conforming layout: no T-junction; the dense layout of `--layout dense` has them).
inline BlockFileSummary check_block_file(const std::string& path, bool whole_sides = false) {
  BlockFileSummary out;
  std::ostringstream err;
  int fn = 0;
  if (cg_open(path.c_str(), CG_MODE_READ, &fn) != CG_OK) {
    out.error = std::string("cg_open: ") + cg_get_error();
    return out;
  }
  bool failed = false;
  auto ok = [&](int rc, const std::string& what) {
    if (rc == CG_OK) return true;
    err << what << ": " << cg_get_error() << "; ";
    failed = true;
    return false;
  };
  struct Zone {
    std::string name;
    bool structured = false;
    cgsize_t ni = 0, nj = 0;  // vertices along i and j (structured); ni vertices (unstructured)
    std::array<std::vector<double>, 3> xyz;
    // Side edges covered, per side (0: j = 1, 1: i = ni, 2: j = nj, 3: i = 1), by position; and
    // by BCs only.
    std::array<std::vector<int>, 4> covered, walls;
  };
  std::vector<Zone> zones;
  std::map<std::string, int> by_name;
  int nzones = 0;
  ok(cg_nzones(fn, 1, &nzones), "cg_nzones");
  const char* coord_names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
  for (int z = 1; z <= nzones; ++z) {
    CGNS_ENUMT(ZoneType_t) type = CGNS_ENUMV(ZoneTypeNull);
    char name[33] = {};
    cgsize_t size[9] = {};
    ok(cg_zone_type(fn, 1, z, &type), "cg_zone_type");
    ok(cg_zone_read(fn, 1, z, name, size), "cg_zone_read");
    Zone zone;
    zone.name = name;
    zone.structured = type == CGNS_ENUMV(Structured);
    std::size_t n = 0;
    if (zone.structured) {
      ++out.structured_zones;
      zone.ni = size[0];
      zone.nj = size[1];
      n = static_cast<std::size_t>(zone.ni * zone.nj);
      out.block_quads += static_cast<std::int64_t>(size[2]) * size[3];
      out.block_cells.push_back(
          {static_cast<std::int64_t>(size[2]), static_cast<std::int64_t>(size[3])});
      if (size[2] != size[0] - 1 || size[3] != size[1] - 1) err << name << ": cell sizes; ";
      for (int s = 0; s < 4; ++s) {
        zone.covered[static_cast<std::size_t>(s)].assign(
            static_cast<std::size_t>(s % 2 == 0 ? zone.ni - 1 : zone.nj - 1), 0);
        zone.walls[static_cast<std::size_t>(s)] = zone.covered[static_cast<std::size_t>(s)];
      }
    } else {
      ++out.unstructured_zones;
      zone.ni = size[0];
      n = static_cast<std::size_t>(zone.ni);
    }
    for (int d = 0; d < 3; ++d) {
      auto& x = zone.xyz[static_cast<std::size_t>(d)];
      x.resize(n);
      cgsize_t lo[2] = {1, 1}, hi[2] = {zone.ni, zone.structured ? zone.nj : 1};
      ok(cg_coord_read(fn, 1, z, coord_names[d], CGNS_ENUMV(RealDouble), lo, hi, x.data()),
         zone.name + " " + coord_names[d]);
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
  // What cg_conn_info says of each general connectivity of zone z, with its index (those it
  // cannot read are reported and left out).
  struct Connection {
    std::string name, donor;
    CGNS_ENUMT(GridLocation_t) location;
    CGNS_ENUMT(GridConnectivityType_t) type;
    CGNS_ENUMT(PointSetType_t) points;
    cgsize_t npnts, ndonor;
  };
  auto connections = [&](int z) {
    std::vector<std::pair<int, Connection>> list;
    int n = 0;
    ok(cg_nconns(fn, 1, z, &n), "cg_nconns");
    for (int c = 1; c <= n; ++c) {
      char cname[33] = {}, dname[33] = {};
      Connection info{};
      CGNS_ENUMT(PointSetType_t) dptype;
      CGNS_ENUMT(ZoneType_t) dztype;
      CGNS_ENUMT(DataType_t) ddtype;
      if (!ok(cg_conn_info(fn, 1, z, c, cname, &info.location, &info.type, &info.points,
                           &info.npnts, dname, &dztype, &dptype, &ddtype, &info.ndonor),
              "cg_conn_info"))
        continue;
      info.name = cname;
      info.donor = dname;
      list.emplace_back(c, info);
    }
    return list;
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
    int nbc = 0;
    ok(cg_nbocos(fn, 1, z, &nbc), "cg_nbocos");
    for (int bc = 1; bc <= nbc; ++bc) {
      char bname[33] = {};
      CGNS_ENUMT(BCType_t) btype;
      CGNS_ENUMT(PointSetType_t) ptype;
      cgsize_t npnts = 0, normal_list = 0;
      int normal_index[2] = {};
      CGNS_ENUMT(DataType_t) ntype;
      int ndata = 0;
      if (!ok(cg_boco_info(fn, 1, z, bc, bname, &btype, &ptype, &npnts, normal_index, &normal_list,
                           &ntype, &ndata),
              "cg_boco_info"))
        continue;
      cgsize_t r[4] = {};
      if (ptype != CGNS_ENUMV(PointRange) || npnts != 2) {
        err << zone.name << "/" << bname << ": not a point range; ";
        continue;
      }
      if (!ok(cg_boco_read(fn, 1, z, bc, r, nullptr), "cg_boco_read")) continue;
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
    int n = 0;
    ok(cg_n1to1(fn, 1, z, &n), "cg_n1to1");
    for (int c = 1; c <= n; ++c) {
      char cname[33] = {}, dname[33] = {};
      cgsize_t range[4] = {}, donor[4] = {};
      int transform[2] = {};
      if (!ok(cg_1to1_read(fn, 1, z, c, cname, dname, range, donor, transform), "cg_1to1_read"))
        continue;
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
    for (const auto& [c, info] : connections(z)) {
      const auto& [cname, dname, location, type, ptype, npnts, ndonor] = info;
      ++out.abutments;
      const auto it = by_name.find(dname);
      if (ptype != CGNS_ENUMV(PointRange) || npnts != 2 || it == by_name.end() ||
          zones[static_cast<std::size_t>(it->second)].structured ||
          type != CGNS_ENUMV(Abutting1to1) || location != CGNS_ENUMV(Vertex)) {
        err << zone.name << "/" << cname << ": not a vertex range abutting the unstructured zone; ";
        continue;
      }
      cgsize_t range[4] = {};
      std::vector<cgsize_t> ids(static_cast<std::size_t>(ndonor));
      if (!ok(cg_conn_read(fn, 1, z, c, range, CGNS_ENUMV(Integer), ids.data()), "cg_conn_read"))
        continue;
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
    int nsections = 0;
    ok(cg_nsections(fn, 1, z, &nsections), "cg_nsections");
    for (int sec = 1; sec <= nsections; ++sec) {
      char sname[33] = {};
      CGNS_ENUMT(ElementType_t) etype;
      cgsize_t start = 0, end = 0, size = 0;
      int nbndry = 0, parent_flag = 0;
      if (!ok(cg_section_read(fn, 1, z, sec, sname, &etype, &start, &end, &nbndry, &parent_flag),
              "cg_section_read") ||
          !ok(cg_ElementDataSize(fn, 1, z, sec, &size), "cg_ElementDataSize"))
        continue;
      std::vector<cgsize_t> data(static_cast<std::size_t>(size));
      if (etype == CGNS_ENUMV(MIXED)) {  // with offsets; the data still lead with each type
        std::vector<cgsize_t> offsets(static_cast<std::size_t>(end - start + 2));
        if (!ok(cg_poly_elements_read(fn, 1, z, sec, data.data(), offsets.data(), nullptr),
                "cg_poly_elements_read"))
          continue;
      } else if (!ok(cg_elements_read(fn, 1, z, sec, data.data(), nullptr), "cg_elements_read")) {
        continue;
      }
      for (std::size_t at = 0; at < data.size();) {
        CGNS_ENUMT(ElementType_t) type = etype;
        if (etype == CGNS_ENUMV(MIXED)) type = static_cast<CGNS_ENUMT(ElementType_t)>(data[at++]);
        const std::size_t n = type == CGNS_ENUMV(QUAD_4) ? 4 : type == CGNS_ENUMV(TRI_3) ? 3 : 0;
        if (n == 0) {
          err << zone.name << "/" << sname << ": element type " << type << " not read; ";
          break;
        }
        for (std::size_t k = 0; k < n; ++k)
          ++edge_count[edge_key(point(zone, data[at + k], 1),
                                point(zone, data[at + (k + 1) % n], 1))];
        at += n;
      }
    }
    for (const auto& [c, info] : connections(z)) {
      const auto& [cname, dname, location, type, ptype, npnts, ndonor] = info;
      const auto it = by_name.find(dname);
      if (ptype != CGNS_ENUMV(PointList) || it == by_name.end() ||
          !zones[static_cast<std::size_t>(it->second)].structured || ndonor != npnts ||
          type != CGNS_ENUMV(Abutting1to1) || location != CGNS_ENUMV(Vertex)) {
        err << zone.name << "/" << cname << ": not a vertex list abutting a block; ";
        continue;
      }
      std::vector<cgsize_t> ids(static_cast<std::size_t>(npnts)), donor(2 * ids.size());
      if (!ok(cg_conn_read(fn, 1, z, c, ids.data(), CGNS_ENUMV(Integer), donor.data()),
              "cg_conn_read"))
        continue;
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
  ok(cg_close(fn), "cg_close");
  out.error = err.str();
  return out;
}

}  // namespace qsmesh::test
