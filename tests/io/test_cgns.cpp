// CGNS output read back through cgnslib, and validated by cgnscheck when it is installed.
#include <cgnslib.h>
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "io_test_mesh.hpp"
#include "qsmesh/io/writer.hpp"

namespace qsmesh::io {
namespace {

namespace fs = std::filesystem;
using test::fresh_dir;
using test::make_test_mesh;

#define CG(call) ASSERT_EQ((call), CG_OK) << #call << ": " << cg_get_error()

struct Section {
  std::string name;
  CGNS_ENUMT(ElementType_t) type;
  cgsize_t start, end;
  std::vector<cgsize_t> conn, offsets;
};

TEST(Cgns, ReadBack) {
  const fs::path dir = fresh_dir("cgns_readback");
  const std::string path = (dir / "mesh.cgns").string();
  const mesh::SurfaceMesh m = make_test_mesh();
  write_mesh(m, path);

  int fn = -1;
  CG(cg_open(path.c_str(), CG_MODE_READ, &fn));
  int nbases = 0;
  CG(cg_nbases(fn, &nbases));
  ASSERT_EQ(nbases, 1);
  char name[33];
  int cell_dim = 0, phys_dim = 0;
  CG(cg_base_read(fn, 1, name, &cell_dim, &phys_dim));
  EXPECT_STREQ(name, "qsmesh");
  EXPECT_EQ(cell_dim, 2);
  EXPECT_EQ(phys_dim, 3);

  CG(cg_goto(fn, 1, "end"));
  CGNS_ENUMT(DataClass_t) dclass;
  CG(cg_dataclass_read(&dclass));
  EXPECT_EQ(dclass, CGNS_ENUMV(Dimensional));
  CGNS_ENUMT(MassUnits_t) mass;
  CGNS_ENUMT(LengthUnits_t) length;
  CGNS_ENUMT(TimeUnits_t) time;
  CGNS_ENUMT(TemperatureUnits_t) temp;
  CGNS_ENUMT(AngleUnits_t) angle;
  CG(cg_units_read(&mass, &length, &time, &temp, &angle));
  EXPECT_EQ(length, CGNS_ENUMV(Millimeter));

  int nzones = 0;
  CG(cg_nzones(fn, 1, &nzones));
  ASSERT_EQ(nzones, 1);
  cgsize_t size[3];
  CG(cg_zone_read(fn, 1, 1, name, size));
  EXPECT_STREQ(name, "Surface");
  EXPECT_EQ(size[0], 12);  // vertices
  EXPECT_EQ(size[1], 9);   // 2D cells
  CGNS_ENUMT(ZoneType_t) ztype;
  CG(cg_zone_type(fn, 1, 1, &ztype));
  EXPECT_EQ(ztype, CGNS_ENUMV(Unstructured));

  int ncoords = 0;
  CG(cg_ncoords(fn, 1, 1, &ncoords));
  EXPECT_EQ(ncoords, 3);
  std::vector<double> x(12), z(12);
  cgsize_t r1 = 1, r2 = 12;
  CG(cg_coord_read(fn, 1, 1, "CoordinateX", CGNS_ENUMV(RealDouble), &r1, &r2, x.data()));
  CG(cg_coord_read(fn, 1, 1, "CoordinateZ", CGNS_ENUMV(RealDouble), &r1, &r2, z.data()));
  for (int v = 0; v < 12; ++v) {
    EXPECT_EQ(x[v], m.points[v].x);
    EXPECT_EQ(z[v], m.points[v].z);
  }

  int nsections = 0;
  CG(cg_nsections(fn, 1, 1, &nsections));
  ASSERT_EQ(nsections, 12);  // faces 0, 1, 3 (face 2 is empty) and 9 meshed curves (not 7)
  std::vector<Section> sections(static_cast<std::size_t>(nsections));
  for (int s = 1; s <= nsections; ++s) {
    Section& sec = sections[s - 1];
    int nbndry = 0, parent = 0;
    CG(cg_section_read(fn, 1, 1, s, name, &sec.type, &sec.start, &sec.end, &nbndry, &parent));
    sec.name = name;
    cgsize_t data_size = 0;
    CG(cg_ElementDataSize(fn, 1, 1, s, &data_size));
    sec.conn.resize(static_cast<std::size_t>(data_size));
    if (sec.type == CGNS_ENUMV(MIXED)) {
      sec.offsets.resize(static_cast<std::size_t>(sec.end - sec.start + 2));
      CG(cg_poly_elements_read(fn, 1, 1, s, sec.conn.data(), sec.offsets.data(), nullptr));
    } else {
      CG(cg_elements_read(fn, 1, 1, s, sec.conn.data(), nullptr));
    }
  }
  const std::vector<std::string> names = {"Face_0",  "Face_1",  "Face_3",  "Curve_0",
                                          "Curve_1", "Curve_2", "Curve_3", "Curve_4",
                                          "Curve_5", "Curve_6", "Curve_8", "Curve_9"};
  cgsize_t next = 1;
  for (std::size_t s = 0; s < sections.size(); ++s) {
    EXPECT_EQ(sections[s].name, names[s]);
    EXPECT_EQ(sections[s].start, next) << names[s];
    next = sections[s].end + 1;
  }
  EXPECT_EQ(next - 1, 9 + 13);
  EXPECT_EQ(sections[0].type, CGNS_ENUMV(QUAD_4));
  EXPECT_EQ(sections[0].conn, (std::vector<cgsize_t>{1, 8, 9, 4, 8, 2, 3, 9}));
  EXPECT_EQ(sections[1].type, CGNS_ENUMV(MIXED));
  EXPECT_EQ(sections[1].end - sections[1].start + 1, 5);
  // face 1: its triangles in mesh order, then its quad, each after its type code
  EXPECT_EQ(sections[1].conn, (std::vector<cgsize_t>{CGNS_ENUMV(TRI_3),
                                                     10,
                                                     5,
                                                     12,
                                                     CGNS_ENUMV(TRI_3),
                                                     5,
                                                     6,
                                                     12,
                                                     CGNS_ENUMV(TRI_3),
                                                     6,
                                                     11,
                                                     12,
                                                     CGNS_ENUMV(TRI_3),
                                                     11,
                                                     10,
                                                     12,
                                                     CGNS_ENUMV(QUAD_4),
                                                     2,
                                                     10,
                                                     11,
                                                     3}));
  EXPECT_EQ(sections[1].offsets, (std::vector<cgsize_t>{0, 4, 8, 12, 16, 21}));
  EXPECT_EQ(sections[2].type, CGNS_ENUMV(TRI_3));
  EXPECT_EQ(sections[2].conn, (std::vector<cgsize_t>{3, 7, 9, 9, 7, 4}));
  for (std::size_t s = 3; s < sections.size(); ++s) EXPECT_EQ(sections[s].type, CGNS_ENUMV(BAR_2));
  EXPECT_EQ(sections[3].conn, (std::vector<cgsize_t>{1, 8, 8, 2}));

  int nfamilies = 0;
  CG(cg_nfamilies(fn, 1, &nfamilies));
  ASSERT_EQ(nfamilies, 12);
  for (int f = 1; f <= nfamilies; ++f) {
    int nbc = 0, ngeo = 0;
    CG(cg_family_read(fn, 1, f, name, &nbc, &ngeo));
    EXPECT_EQ(name, names[f - 1]);
    EXPECT_EQ(nbc, std::string(name).rfind("Curve_", 0) == 0 ? 1 : 0) << name;
  }

  int nbocos = 0;
  CG(cg_nbocos(fn, 1, 1, &nbocos));
  ASSERT_EQ(nbocos, 9);
  for (int b = 1; b <= nbocos; ++b) {
    CGNS_ENUMT(BCType_t) bctype;
    CGNS_ENUMT(PointSetType_t) ptset;
    cgsize_t npts = 0, normal_list = 0;
    int normal_index[3], ndataset = 0;
    CGNS_ENUMT(DataType_t) normal_type;
    CG(cg_boco_info(fn, 1, 1, b, name, &bctype, &ptset, &npts, normal_index, &normal_list,
                    &normal_type, &ndataset));
    const Section& sec = sections[static_cast<std::size_t>(b + 2)];
    EXPECT_EQ(name, sec.name);
    EXPECT_EQ(bctype, CGNS_ENUMV(FamilySpecified));
    EXPECT_EQ(ptset, CGNS_ENUMV(PointRange));
    ASSERT_EQ(npts, 2);
    cgsize_t range[2];
    CG(cg_boco_read(fn, 1, 1, b, range, nullptr));
    EXPECT_EQ(range[0], sec.start);
    EXPECT_EQ(range[1], sec.end);
    CGNS_ENUMT(GridLocation_t) loc;
    CG(cg_boco_gridlocation_read(fn, 1, 1, b, &loc));
    EXPECT_EQ(loc, CGNS_ENUMV(EdgeCenter));
    CG(cg_goto(fn, 1, "Zone_t", 1, "ZoneBC_t", 1, "BC_t", b, "end"));
    char fam[33];
    CG(cg_famname_read(fam));
    EXPECT_EQ(sec.name, fam);
  }
  CG(cg_close(fn));
}

TEST(Cgns, MeterUnitAndAllQuads) {
  const fs::path dir = fresh_dir("cgns_meter");
  const std::string path = (dir / "m.cgns").string();
  mesh::SurfaceMesh m = make_test_mesh();
  m.length_unit = "m";
  write_cgns(m, path);
  int fn = -1;
  CG(cg_open(path.c_str(), CG_MODE_READ, &fn));
  CG(cg_goto(fn, 1, "end"));
  CGNS_ENUMT(MassUnits_t) mass;
  CGNS_ENUMT(LengthUnits_t) length;
  CGNS_ENUMT(TimeUnits_t) time;
  CGNS_ENUMT(TemperatureUnits_t) temp;
  CGNS_ENUMT(AngleUnits_t) angle;
  CG(cg_units_read(&mass, &length, &time, &temp, &angle));
  EXPECT_EQ(length, CGNS_ENUMV(Meter));
  CG(cg_close(fn));
}

TEST(Cgns, NoHdf5Timestamps) {
  // HDF5 object headers carry times; the writer zeroes them so that files do not depend on the
  // clock (a byte comparison of two writes within one second would not show this).
  const fs::path dir = fresh_dir("cgns_times");
  write_mesh(make_test_mesh(), (dir / "t.cgns").string());
  const std::string data = test::read_all(dir / "t.cgns");
  int headers = 0;
  for (std::size_t p = 0; (p = data.find("OHDR", p)) != std::string::npos; p += 4) {
    if (p + 22 > data.size() || data[p + 4] != 2 || (data[p + 5] & 0x20) == 0) continue;
    ++headers;
    EXPECT_EQ(data.substr(p + 6, 16), std::string(16, '\0')) << "object header at " << p;
  }
  EXPECT_GT(headers, 10);
}

#ifdef QSMESH_CGNSCHECK
// cgnscheck exits 0 whatever it finds: its report is read instead.
std::string run_cgnscheck(const std::string& path) {
  const std::string cmd = std::string(QSMESH_CGNSCHECK) + " -w3 '" + path + "' 2>&1";
  std::FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return "popen failed";
  std::string out;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  ::pclose(p);
  return out;
}

std::vector<std::string> issue_lines(const std::string& report) {
  std::vector<std::string> issues;
  std::istringstream in(report);
  for (std::string line; std::getline(in, line);) {
    std::string upper = line;
    for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (upper.find("ERROR") != std::string::npos || upper.find("WARNING") != std::string::npos) {
      issues.push_back(line);
    }
  }
  return issues;
}

TEST(Cgns, CgnscheckFindsNothing) {
  const fs::path dir = fresh_dir("cgns_check");
  const std::string path = (dir / "mesh.cgns").string();
  write_mesh(make_test_mesh(), path);
  const std::string report = run_cgnscheck(path);
  EXPECT_NE(report.find("checking zone \"Surface\""), std::string::npos) << report;
  EXPECT_TRUE(issue_lines(report).empty()) << report;
}

TEST(Cgns, CgnscheckReportsABrokenFile) {
  // The check above must be able to fail: a BC pointing past the last element is reported.
  const fs::path dir = fresh_dir("cgns_check_broken");
  const std::string path = (dir / "broken.cgns").string();
  write_mesh(make_test_mesh(), path);
  int fn = -1;
  CG(cg_open(path.c_str(), CG_MODE_MODIFY, &fn));
  const cgsize_t range[2] = {90, 95};
  int bc = 0;
  CG(cg_boco_write(fn, 1, 1, "Broken", CGNS_ENUMV(BCWall), CGNS_ENUMV(PointRange), 2, range, &bc));
  CG(cg_boco_gridlocation_write(fn, 1, 1, bc, CGNS_ENUMV(EdgeCenter)));
  CG(cg_close(fn));
  EXPECT_FALSE(issue_lines(run_cgnscheck(path)).empty());
}
#else
TEST(Cgns, CgnscheckFindsNothing) { GTEST_SKIP() << "cgnscheck not found at configure time"; }
#endif

}  // namespace
}  // namespace qsmesh::io
