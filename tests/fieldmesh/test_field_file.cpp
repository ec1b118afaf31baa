// The cross-field file of `qsmesh mesh --cross-field` (both forms), the per-face method policy,
// and the face-level entry on a square.
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepTools.hxx>
#include <TopoDS_Face.hxx>
#include <fstream>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/fieldmesh/field_file.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/quantize/quantize.hpp"
#include "tmp_dir.hpp"

namespace qsmesh {
namespace {

std::string write_text(const std::string& name, const std::string& text) {
  const std::string path = test::tmp_dir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::string input_error(const std::string& path, LO faces) {
  try {
    (void)fieldmesh::read_cross_field_file(path, faces);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(FieldFile, SingularPointsPerFace) {
  const std::string path = write_text("points.txt",
                                      "# two faces\n"
                                      "qsmesh-cross-field   singular-points 1\n"
                                      "face 2\n"
                                      "  point 0.37 0.5 0 1   # valence 3\n"
                                      "  point 0.63 0.5 0 -1\n"
                                      "face 0\n");
  const auto g = fieldmesh::read_cross_field_file(path, 3);
  EXPECT_EQ(g.format, "singular-points");
  ASSERT_EQ(g.faces.size(), 2u);
  EXPECT_EQ(g.faces[0].face, 0);
  EXPECT_TRUE(g.faces[0].points.empty());
  ASSERT_EQ(g.faces[1].points.size(), 2u);
  EXPECT_EQ(g.faces[1].points[1].d, -1);
  EXPECT_DOUBLE_EQ(g.faces[1].points[0].position.x, 0.37);
  EXPECT_EQ(g.find(1), nullptr);
  EXPECT_EQ(g.find(2), &g.faces[1]);
}

TEST(FieldFile, BadFilesGiveOneLineNamingTheLine) {
  EXPECT_NE(input_error(write_text("h.txt", "face 0\n"), 3).find("line 1: expected the header"),
            std::string::npos);
  const std::string h = "qsmesh-cross-field singular-points 1\n";
  EXPECT_NE(input_error(write_text("a.txt", h + "point 0 0 0 1\n"), 3)
                .find("line 2: 'point' before any 'face'"),
            std::string::npos);
  EXPECT_NE(input_error(write_text("b.txt", h + "face 3\n"), 3)
                .find("line 2: 'face ID' with ID in [0, 3)"),
            std::string::npos);
  EXPECT_NE(
      input_error(write_text("c.txt", h + "face 0\npoint 0 0 0 0\n"), 3).find("line 3: D must be"),
      std::string::npos);
  EXPECT_NE(input_error(write_text("d.txt", h + "face 0\nface 0\n"), 3).find("given twice"),
            std::string::npos);
  EXPECT_NE(
      input_error(write_text("e.txt", h + "face 0\npoint 0 0 1\n"), 3).find("'point X Y Z D'"),
      std::string::npos);
  EXPECT_NE(input_error(test::tmp_dir() + "/none.txt", 3).find("cannot read"), std::string::npos);
  EXPECT_NE(input_error(write_text("v.vtu", "<VTKFile type=\"UnstructuredGrid\"></VTKFile>"), 3)
                .find("no array"),
            std::string::npos);
  for (const char* name : {"h.txt", "a.txt"})
    EXPECT_EQ(input_error(write_text(name, "face 0\n"), 3).find('\n'), std::string::npos);
}

TEST(FieldFile, ReadsTheVtuOfQsmeshCrossfieldBinaryAndAscii) {
  // Two triangles on face 1 and one on face 0, cross_u as the crossfield command writes it.
  mesh::SurfaceMesh m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.vclass.assign(4, mesh::VertexClass{});
  m.triangles = {{0, 1, 2}, {0, 2, 3}, {1, 2, 3}};
  m.triangle_face = {1, 1, 0};
  m.num_cad_faces = 2;
  for (bool binary : {true, false}) {
    io::WriteOptions opt;
    opt.vtu_binary = binary;
    opt.vtu_markers.push_back({{0.5, 0.5, 0}, 1});
    opt.cell_fields = {{"cross_u", 3, {1, 0, 0, 0, 1, 0, 0.6, 0.8, 0, 0, 0, 0}},
                       {"singularity_index", 1, {0, 0, 0, -1}}};
    const std::string path = test::tmp_dir() + (binary ? "/b.vtu" : "/a.vtu");
    io::write_vtu(m, path, opt);
    const auto g = fieldmesh::read_cross_field_file(path, 2);
    EXPECT_EQ(g.format, "crossfield-vtu");
    ASSERT_EQ(g.faces.size(), 2u);
    EXPECT_TRUE(g.faces[1].sampled);
    ASSERT_EQ(g.faces[1].samples.positions.size(), 2u);
    EXPECT_NEAR(g.faces[1].samples.positions[0].x, 2.0 / 3, 1e-12);
    EXPECT_EQ(g.faces[1].samples.directions[1].y, 1.0);
    EXPECT_EQ(g.faces[0].samples.directions[0].x, 0.6);
    ASSERT_EQ(g.faces[1].samples.singular.size(), 1u);
    EXPECT_EQ(g.faces[1].samples.singular[0].d, -1);
    EXPECT_EQ(g.faces[1].samples.singular[0].position.y, 0.5);
    EXPECT_TRUE(g.faces[0].samples.singular.empty());
    EXPECT_NE(input_error(path, 1).find("face 1 is not a face of the model"), std::string::npos);
  }
}

TEST(FieldFile, MethodPolicyPerFace) {
  fieldmesh::GivenFields g;
  g.faces.resize(1);
  g.faces[0].face = 4;
  using fieldmesh::FaceMethod;
  EXPECT_EQ(fieldmesh::face_method(4, &g, false), FaceMethod::GivenField);
  EXPECT_EQ(fieldmesh::face_method(4, &g, true), FaceMethod::GivenField);
  EXPECT_EQ(fieldmesh::face_method(3, &g, false), FaceMethod::Default);
  EXPECT_EQ(fieldmesh::face_method(3, &g, true), FaceMethod::Separatrix);
  EXPECT_EQ(fieldmesh::face_method(0, nullptr, false), FaceMethod::Default);
  EXPECT_EQ(fieldmesh::face_method(0, nullptr, true), FaceMethod::Separatrix);
}

TEST(FieldFile, SampledFieldMeshesLikeItsSource) {
  // A square's field sampled at scattered points (rotated by 0.3 rad: not aligned) gives the
  // grid, as the crossfield round trip does; with singular points, Eq. 2.
  BRepBuilderAPI_MakePolygon poly;
  for (auto [x, y] : {std::pair{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}})
    poly.Add(gp_Pnt(x, y, 0));
  poly.Close();
  const std::string path = test::tmp_dir() + "/sq.brep";
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(poly.Wire(), true).Face();
  ASSERT_TRUE(BRepTools::Write(face, path.c_str()));
  const auto model = cad::load_cad(path);
  const TaskArena tasks(1);
  background::SizeOptions sizes;
  sizes.size = 0.1;
  const auto bg = background::mesh_curves(model, sizes, tasks);
  std::vector<std::vector<double>> at;
  for (const auto& c : bg) at.emplace_back(c.points.size(), 0.1);
  const auto q = quantize::quantize_curves(model, quantize::ideal_edge_counts(bg, at), {});
  const auto curves = quantize::place_vertices(model, bg, at, q, false, tasks);
  fieldmesh::FieldSamples samples;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      samples.positions.push_back({i / 20.0, j / 20.0, 0});
      samples.directions.push_back({std::cos(0.3), std::sin(0.3), 0});
    }
  fieldmesh::FieldMeshReport rep;
  const auto m = fieldmesh::mesh_face_by_method(model, 0, curves, fieldmesh::FaceMethod::Separatrix,
                                                nullptr, &samples, {}, nullptr, &rep);
  ASSERT_TRUE(rep.ok) << rep.stage << ": " << rep.reason;
  EXPECT_EQ(m.quads.size(), 100u);
  EXPECT_EQ(rep.stats.irregular_interior, 0);
  EXPECT_GT(rep.stats.sicn_min, 0.9);
  // The method needs its field.
  const auto none = fieldmesh::mesh_face_by_method(
      model, 0, curves, fieldmesh::FaceMethod::Separatrix, nullptr, nullptr, {}, nullptr, &rep);
  EXPECT_FALSE(rep.ok);
  EXPECT_TRUE(none.quads.empty());
}

}  // namespace
}  // namespace qsmesh
