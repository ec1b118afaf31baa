// `qsmesh mesh --cross-field` and `--method separatrix` (paper 003) on a plate with a hole: the
// round trip of `qsmesh crossfield`'s VTU, a list of singular points, the separatrix method, and
// bad files refused up front; on a disk, boundary singular points; the partition's regions as the
// blocks of --block-structured.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepTools.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Wire.hxx>
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <gp_Circ.hxx>
#include <string>
#include <utility>
#include <vector>

#include "cgns_blocks_check.hpp"
#include "tmp_dir.hpp"

namespace {

using qsmesh::test::slurp;
using qsmesh::test::tmp;

int qsmesh(const std::string& args, const std::string& log) {
  const std::string cmd = std::string(QSMESH_EXE) + " " + args + " >" + log + " 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The square [-2, 2]^2 with a hole of radius 0.8 about the origin.
std::string plate_with_hole() {
  BRepBuilderAPI_MakePolygon poly;
  for (auto [x, y] : {std::pair{-2.0, -2.0}, {2.0, -2.0}, {2.0, 2.0}, {-2.0, 2.0}})
    poly.Add(gp_Pnt(x, y, 0));
  poly.Close();
  BRepBuilderAPI_MakeFace face(poly.Wire(), true);
  TopoDS_Wire hole =
      BRepBuilderAPI_MakeWire(
          BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 0.8)).Edge())
          .Wire();
  hole.Reverse();
  face.Add(hole);
  const std::string path = tmp("plate_hole.brep");
  const TopoDS_Face f = face.Face();
  if (!BRepTools::Write(f, path.c_str())) throw std::runtime_error("cannot write " + path);
  return path;
}

// The disk of radius 1 about the origin (one circle, its CAD vertex at (1, 0, 0)).
std::string disk() {
  const TopoDS_Wire w =
      BRepBuilderAPI_MakeWire(
          BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 1.0)).Edge())
          .Wire();
  const std::string path = tmp("disk.brep");
  const TopoDS_Face f = BRepBuilderAPI_MakeFace(w, true).Face();
  if (!BRepTools::Write(f, path.c_str())) throw std::runtime_error("cannot write " + path);
  return path;
}

bool has(const std::string& json, const std::string& what) {
  return json.find(what) != std::string::npos;
}

TEST(FieldMeshCli, CrossfieldOutputFedBackAndSingularPoints) {
  const std::string model = plate_with_hole(), log = tmp("fm.log");
  const std::string field = tmp("cf.vtu"), stats = tmp("rt.json");
  ASSERT_EQ(qsmesh("crossfield " + model + " --size 0.2 -o " + field, log), 0) << slurp(log);
  ASSERT_EQ(qsmesh("mesh " + model + " --size 0.2 --cross-field " + field + " -o " + tmp("rt.msh") +
                       " --stats " + stats,
                   log),
            0)
      << slurp(log);
  std::string json = slurp(stats);
  EXPECT_TRUE(has(json, "\"faces_meshed_by_field\": 1")) << json;
  EXPECT_TRUE(has(json, "\"method\": \"field:given-field\""));
  EXPECT_TRUE(has(json, "\"conforming\": true"));
  EXPECT_TRUE(has(json, "\"triangles\": 0"));

  // Four valence-5 points of Eq. 2 near the diagonals: Eq. 17 fails around the hole, corrected.
  const std::string points = tmp("pts.txt");
  std::ofstream(points) << "qsmesh-cross-field singular-points 1\nface 0\n"
                           "point 1.15 1.15 0 -1\npoint -1.15 1.15 0 -1\npoint -1.15 -1.15 0 -1\n"
                           "point 1.15 -1.15 0 -1\n";
  ASSERT_EQ(qsmesh("mesh " + model + " --size 0.2 --cross-field " + points + " -o " + tmp("p.vtu") +
                       " --stats " + stats,
                   log),
            0)
      << slurp(log);
  json = slurp(stats);
  EXPECT_TRUE(has(json, "\"faces_meshed_by_field\": 1")) << json;
  EXPECT_TRUE(has(json, "\"irregular_interior\": 4"));
  EXPECT_TRUE(has(json, "\"field_refusal\": \"\""));
}

TEST(FieldMeshCli, BoundarySingularPointsOnADisk) {
  // Two valence-3 points and, as Eq. 11 asks, two boundary points of index 1/4 on the circle
  // (paper 003 Fig. 9, top). At size 0.4 the circle has 16 edges: the quad at a boundary point
  // has the polygon's angle, SICN about sin(22.5 deg). At 0.2 (32 edges) that corner would give
  // 0.195, below the floor of 0.2: the face keeps its default mesh and says why.
  const std::string model = disk(), log = tmp("disk.log"), stats = tmp("disk.json");
  const std::string points = tmp("disk_pts.txt");
  std::ofstream(points) << "qsmesh-cross-field singular-points 1\nface 0\n"
                           "point 0.3 0 0 1\npoint -0.3 0 0 1\n"
                           "point 1 0 0 1   # on the circle: boundary singular points\n"
                           "point -1 0 0 1\n";
  ASSERT_EQ(qsmesh("mesh " + model + " --size 0.4 --cross-field " + points + " -o " +
                       tmp("disk.msh") + " --stats " + stats,
                   log),
            0)
      << slurp(log);
  std::string json = slurp(stats);
  EXPECT_TRUE(has(json, "\"faces_meshed_by_field\": 1")) << json;
  EXPECT_TRUE(has(json, "\"irregular_interior\": 2")) << json;
  EXPECT_TRUE(has(json, "\"irregular_boundary\": 2")) << json;
  EXPECT_TRUE(has(json, "\"triangles\": 0"));

  ASSERT_EQ(qsmesh("mesh " + model + " --size 0.2 --cross-field " + points + " -o " +
                       tmp("disk2.msh") + " --stats " + stats,
                   log),
            0)
      << slurp(log);
  json = slurp(stats);
  EXPECT_TRUE(has(json, "\"faces_meshed_by_field\": 0")) << json;
  EXPECT_TRUE(has(json, "filling: SICN min 0.19")) << json;
}

TEST(FieldMeshCli, SeparatrixMethodAndRefusals) {
  const std::string model = plate_with_hole(), log = tmp("fm2.log"), stats = tmp("s.json");
  ASSERT_EQ(qsmesh("mesh " + model + " --size 0.2 --method separatrix -o " + tmp("s.vtu") +
                       " --stats " + stats,
                   log),
            0)
      << slurp(log);
  EXPECT_TRUE(has(slurp(stats), "\"method\": \"field:separatrix\"")) << slurp(stats);

  // An incompatible field keeps the default mesh and says why, naming the equation.
  const std::string two = tmp("two.txt");
  std::ofstream(two) << "qsmesh-cross-field singular-points 1\nface 0\npoint 1.15 1.15 0 -1\n";
  ASSERT_EQ(qsmesh("mesh " + model + " --size 0.2 --cross-field " + two + " -o " + tmp("t.vtu") +
                       " --stats " + stats,
                   log),
            0);
  const std::string json = slurp(stats);
  EXPECT_TRUE(has(json, "\"faces_meshed_by_field\": 0")) << json;
  EXPECT_TRUE(has(json, "compatibility: Eq. 16 violated")) << json;

  // Bad files: exit 2, one line, before any output.
  const std::string bad = tmp("bad.txt");
  std::ofstream(bad) << "qsmesh-cross-field singular-points 1\nface 7\n";
  EXPECT_EQ(qsmesh("mesh " + model + " --cross-field " + bad + " -o " + tmp("b.vtu"), log), 2);
  EXPECT_TRUE(has(slurp(log), "line 2: 'face ID' with ID in [0, 1)")) << slurp(log);
  EXPECT_EQ(
      qsmesh("mesh " + model + " --cross-field " + tmp("none.txt") + " -o " + tmp("b.vtu"), log),
      2);
  EXPECT_EQ(qsmesh("mesh " + model + " --method other -o " + tmp("b.vtu"), log), 2);
}

// Each structured zone's cells as (smaller, larger), sorted: block dimensions up to the axes.
std::vector<std::pair<std::int64_t, std::int64_t>> block_sizes(
    const qsmesh::test::BlockFileSummary& s) {
  std::vector<std::pair<std::int64_t, std::int64_t>> out;
  for (const auto& c : s.block_cells) out.emplace_back(std::min(c[0], c[1]), std::max(c[0], c[1]));
  std::sort(out.begin(), out.end());
  return out;
}

TEST(FieldMeshCli, PartitionRegionsAreTheBlocks) {
  // The disk of BoundarySingularPointsOnADisk at size 0.4: four regions, of 2 x 2 and 4 x 2 quads
  // (tests/fieldmesh). --block-structured writes them as they are: no layout is traced there.
  const std::string model = disk(), log = tmp("pb.log"), stats = tmp("pb.json");
  const std::string points = tmp("pb_pts.txt"), out = tmp("pb.cgns");
  std::ofstream(points) << "qsmesh-cross-field singular-points 1\nface 0\n"
                           "point 0.3 0 0 1\npoint -0.3 0 0 1\npoint 1 0 0 1\npoint -1 0 0 1\n";
  ASSERT_EQ(qsmesh("mesh " + model + " --size 0.4 --cross-field " + points + " -o " + out +
                       " --block-structured --stats " + stats,
                   log),
            0)
      << slurp(log);
  std::string json = slurp(stats);
  EXPECT_TRUE(has(json, "\"faces_meshed_by_field\": 1")) << json;
  EXPECT_TRUE(has(json, "\"field_regions\": 4")) << json;
  EXPECT_TRUE(has(json, "\"blocks\": 4")) << json;
  EXPECT_TRUE(has(json, "\"faces_with_partition_blocks\": 1")) << json;
  qsmesh::test::BlockFileSummary s = qsmesh::test::check_block_file(out);
  EXPECT_TRUE(s.error.empty()) << s.error;
  EXPECT_EQ(s.unstructured_zones, 0);
  using Sizes = std::vector<std::pair<std::int64_t, std::int64_t>>;
  EXPECT_EQ(block_sizes(s), (Sizes{{2, 2}, {2, 2}, {2, 4}, {2, 4}}));

  // A box whose face 0 alone has a field (no singular point: one region, the whole face); its
  // neighbours keep the default pipeline and their traced blocks meet its block along the shared
  // curves. Each face takes the field in turn (faces of both orientations).
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(2.0, 1.0, 0.6).Shape();
  const std::string box_path = tmp("pb_box.brep");
  ASSERT_TRUE(BRepTools::Write(box, box_path.c_str()));
  for (int f = 0; f < 6; ++f) {
    std::ofstream(points) << "qsmesh-cross-field singular-points 1\nface " << f << "\n";
    ASSERT_EQ(qsmesh("mesh " + box_path + " --size 0.2 --cross-field " + points + " -o " + out +
                         " --block-structured --stats " + stats,
                     log),
              0)
        << slurp(log);
    json = slurp(stats);
    EXPECT_TRUE(has(json, "\"faces_meshed_by_field\": 1")) << "face " << f << ": " << json;
    EXPECT_TRUE(has(json, "\"faces_with_partition_blocks\": 1")) << "face " << f << ": " << json;
    s = qsmesh::test::check_block_file(out);
    EXPECT_TRUE(s.error.empty()) << "face " << f << ": " << s.error;
    EXPECT_EQ(s.unstructured_zones, 0);
  }
}

}  // namespace
