// Reads a block-structured CGNS file (io::write_cgns_blocks) back through cgnslib and checks it:
// every zone structured, and every GridConnectivity1to1 joining points with the same coordinates
// under its transform. Header-only; the test must link cgnslib (qsmesh_cgns).
#pragma once

#include <cgnslib.h>

#include <array>
#include <cstdint>
#include <map>
#include <sstream>
#include <string>
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
};

inline BlockFileSummary check_block_file(const std::string& path) {
  BlockFileSummary out;
  std::ostringstream err;
  int fn = 0;
  if (cg_open(path.c_str(), CG_MODE_READ, &fn) != CG_OK) {
    out.error = std::string("cg_open: ") + cg_get_error();
    return out;
  }
  struct Zone {
    std::string name;
    cgsize_t ni = 0, nj = 0;  // vertices along i and j
    std::array<std::vector<double>, 3> xyz;
  };
  std::vector<Zone> zones;
  std::map<std::string, int> by_name;
  int nzones = 0;
  cg_nzones(fn, 1, &nzones);
  for (int z = 1; z <= nzones; ++z) {
    CGNS_ENUMT(ZoneType_t) type;
    cg_zone_type(fn, 1, z, &type);
    char name[33] = {};
    cgsize_t size[9] = {};
    cg_zone_read(fn, 1, z, name, size);
    Zone zone;
    zone.name = name;
    if (type != CGNS_ENUMV(Structured)) {
      ++out.unstructured_zones;
      zones.push_back(zone);
      continue;
    }
    ++out.structured_zones;
    zone.ni = size[0];
    zone.nj = size[1];
    out.block_quads += static_cast<std::int64_t>(size[2]) * size[3];
    if (size[2] != size[0] - 1 || size[3] != size[1] - 1) err << name << ": cell sizes; ";
    const char* names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    for (int d = 0; d < 3; ++d) {
      zone.xyz[static_cast<std::size_t>(d)].resize(static_cast<std::size_t>(zone.ni * zone.nj));
      cgsize_t lo[2] = {1, 1}, hi[2] = {zone.ni, zone.nj};
      if (cg_coord_read(fn, 1, z, names[d], CGNS_ENUMV(RealDouble), lo, hi,
                        zone.xyz[static_cast<std::size_t>(d)].data()) != CG_OK)
        err << name << ": " << names[d] << " unreadable; ";
    }
    by_name[zone.name] = z - 1;
    zones.push_back(std::move(zone));
  }
  auto point = [](const Zone& zone, cgsize_t i, cgsize_t j) {
    const auto k = static_cast<std::size_t>((j - 1) * zone.ni + (i - 1));
    return std::array<double, 3>{zone.xyz[0][k], zone.xyz[1][k], zone.xyz[2][k]};
  };
  for (int z = 1; z <= nzones; ++z) {
    const Zone& zone = zones[static_cast<std::size_t>(z - 1)];
    if (zone.ni == 0) continue;
    int nbc = 0;
    cg_nbocos(fn, 1, z, &nbc);
    for (int bc = 1; bc <= nbc; ++bc) {
      char bname[33] = {};
      CGNS_ENUMT(BCType_t) btype;
      CGNS_ENUMT(PointSetType_t) ptype;
      cgsize_t npnts = 0, normal_list = 0;
      int normal_index[2] = {};
      CGNS_ENUMT(DataType_t) ntype;
      int ndata = 0;
      cg_boco_info(fn, 1, z, bc, bname, &btype, &ptype, &npnts, normal_index, &normal_list, &ntype, &ndata);
      cgsize_t r[4] = {};
      cg_boco_read(fn, 1, z, bc, r, nullptr);
      ++out.boundary_conditions;
      const bool on_side = (r[0] == r[2] && (r[0] == 1 || r[0] == zone.ni)) ||
                           (r[1] == r[3] && (r[1] == 1 || r[1] == zone.nj));
      if (ptype != CGNS_ENUMV(PointRange) || !on_side) err << zone.name << "/" << bname << ": not a side range; ";
    }
    int n = 0;
    cg_n1to1(fn, 1, z, &n);
    for (int c = 1; c <= n; ++c) {
      char cname[33] = {}, dname[33] = {};
      cgsize_t range[4] = {}, donor[4] = {};
      int transform[2] = {};
      cg_1to1_read(fn, 1, z, c, cname, dname, range, donor, transform);
      ++out.interfaces;
      const auto it = by_name.find(dname);
      if (it == by_name.end()) {
        err << zone.name << "/" << cname << ": no donor zone " << dname << "; ";
        continue;
      }
      const Zone& dz = zones[static_cast<std::size_t>(it->second)];
      // donor index = T (index - begin) + donor begin, T the signed permutation of `transform`.
      const cgsize_t di = range[2] >= range[0] ? 1 : -1, dj = range[3] >= range[1] ? 1 : -1;
      for (cgsize_t i = range[0];; i += di) {
        for (cgsize_t j = range[1];; j += dj) {
          const std::array<cgsize_t, 2> delta{i - range[0], j - range[1]};
          std::array<cgsize_t, 2> d{donor[0], donor[1]};
          for (int k = 0; k < 2; ++k) {
            const int t = transform[k];
            const int axis = (t > 0 ? t : -t) - 1;
            if (axis < 0 || axis > 1) {
              err << zone.name << "/" << cname << ": transform; ";
              break;
            }
            d[static_cast<std::size_t>(axis)] +=
                (t > 0 ? 1 : -1) * delta[static_cast<std::size_t>(k)];
          }
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
  }
  cg_close(fn);
  out.error = err.str();
  return out;
}

}  // namespace qsmesh::test
