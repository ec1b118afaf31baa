// mesh::MeshAssembler on background meshes of OpenCASCADE-made models: faces added in any order
// give the mesh of mesh::assemble, and wrong announcements are refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/assemble.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::mesh {
namespace {

struct Pieces {
  std::vector<CurveMesh> curves;
  std::vector<FaceMesh> faces;
};

Pieces background_pieces(const cad::CadModel& model, double size) {
  background::BackgroundOptions options;
  options.sizes.size = size;
  const TaskArena tasks(2);
  Pieces p;
  p.curves = background::mesh_curves(model, options.sizes, tasks);
  p.faces.resize(static_cast<std::size_t>(model.num_faces()));
  for (LO f = 0; f < model.num_faces(); ++f)
    p.faces[f] = background::mesh_face_background(model, f, p.curves, options, nullptr);
  return p;
}

void expect_same(const SurfaceMesh& a, const SurfaceMesh& b) {
  EXPECT_EQ(a.points, b.points);
  ASSERT_EQ(a.vclass.size(), b.vclass.size());
  for (std::size_t v = 0; v < a.vclass.size(); ++v) {
    EXPECT_EQ(a.vclass[v].dim, b.vclass[v].dim);
    EXPECT_EQ(a.vclass[v].entity, b.vclass[v].entity);
    EXPECT_EQ(a.vclass[v].index, b.vclass[v].index);
    EXPECT_EQ(a.vclass[v].param, b.vclass[v].param);
  }
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.triangle_face, b.triangle_face);
  EXPECT_EQ(a.quads, b.quads);
  EXPECT_EQ(a.quad_face, b.quad_face);
  EXPECT_EQ(a.bars, b.bars);
  EXPECT_EQ(a.bar_curve, b.bar_curve);
}

TEST(Assemble, FacesInAnyOrderGiveTheSameMesh) {
  for (const std::string& name : {std::string("as_sphere.brep"), std::string("as_box.brep")}) {
    const std::string path = test::tmp_dir() + "/" + name;
    const cad::CadModel model = cad::load_cad(
        name == "as_sphere.brep" ? test::write_sphere(path) : test::write_box_with_hole(path));
    Pieces p = background_pieces(model, 0.8);
    // A second uv image of a corner (as at a pole or on a seam) and a triangle it collapses: the
    // assembly merges the images and drops the triangle.
    FaceMesh& first = p.faces[0];
    const auto corner =
        static_cast<LO>(std::find_if(first.vclass.begin(), first.vclass.end(),
                                     [](const VertexClass& vc) { return vc.dim == 0; }) -
                        first.vclass.begin());
    ASSERT_LT(corner, first.num_vertices()) << name;
    first.points.push_back(first.points[corner]);
    first.uv.push_back(first.uv[corner]);
    first.vclass.push_back(first.vclass[corner]);
    first.triangles.push_back({corner, first.num_vertices() - 1, first.triangles[0][1]});

    const SurfaceMesh whole = assemble(model, p.curves, p.faces);
    GO kept = 0, given = 0;
    std::vector<FaceContribution> counts;
    for (const FaceMesh& f : p.faces) {
      counts.push_back(face_contribution(f));
      kept += counts.back().triangles;
      given += static_cast<GO>(f.triangles.size());
    }
    EXPECT_EQ(kept, given - 1) << name;
    EXPECT_EQ(static_cast<GO>(whole.triangles.size()), kept) << name;

    // Faces in reverse order, each dropped once added.
    std::vector<FaceMesh> faces = p.faces;
    MeshAssembler assembler(model, p.curves, counts);
    for (LO f = model.num_faces() - 1; f >= 0; --f) {
      assembler.add_face(f, faces[f]);
      faces[f] = FaceMesh{};
    }
    expect_same(assembler.finish(), whole);
  }
}

TEST(Assemble, WrongAnnouncementsAreRefused) {
  const cad::CadModel model =
      cad::load_cad(test::write_box_with_hole(test::tmp_dir() + "/as_refused.brep"));
  const Pieces p = background_pieces(model, 1.0);
  std::vector<FaceContribution> counts;
  for (const FaceMesh& f : p.faces) counts.push_back(face_contribution(f));

  // A face whose mesh differs from its announcement.
  std::vector<FaceContribution> off = counts;
  off[0].quads += 1;
  MeshAssembler wrong(model, p.curves, off);
  EXPECT_THROW(wrong.add_face(0, p.faces[0]), Error);

  // A face added twice, and a face announced but never added.
  MeshAssembler twice(model, p.curves, counts);
  twice.add_face(1, p.faces[1]);
  EXPECT_THROW(twice.add_face(1, p.faces[1]), Error);
  EXPECT_THROW((void)twice.finish(), Error);

  // One contribution per face.
  counts.pop_back();
  EXPECT_THROW(MeshAssembler(model, p.curves, counts), Error);
}

// A group of faces meshed as one surface (MeshAssembler::add_group): two quads of faces 0 and 1
// share two interior vertices, one of them lying on face 0 and one on face 1; each vertex is
// numbered once on the face it lies on, each quad on its face, and a curve inside the group gets
// no bars.
TEST(Assemble, AGroupSharesItsInteriorVerticesAcrossItsFaces) {
  const cad::CadModel model =
      cad::load_cad(test::write_box_with_hole(test::tmp_dir() + "/as_group.brep"));
  const Pieces p = background_pieces(model, 1.0);
  FaceMesh g;
  // Vertices 0-2 on face 0, 3-5 on face 1; quads (0 1 4 3) on face 0 and (1 2 5 4) on face 1.
  for (int i = 0; i < 6; ++i) {
    g.points.push_back({double(i % 3), double(i / 3), 0});
    g.uv.push_back({double(i % 3), double(i / 3)});
    g.vclass.push_back(VertexClass{2, i < 3 ? 0 : 1, kNoIndex, {double(i), 0}});
  }
  g.quads = {{0, 1, 4, 3}, {1, 2, 5, 4}};
  const std::vector<LO> quad_face{0, 1};
  std::vector<FaceContribution> counts(static_cast<std::size_t>(model.num_faces()));
  counts[0] = {3, 0, 1};
  counts[1] = {3, 0, 1};
  std::vector<char> inner(static_cast<std::size_t>(model.num_curves()), 0);
  inner[0] = 1;
  MeshAssembler assembler(model, p.curves, counts, inner);
  const std::vector<GO> ids = assembler.add_group(g, quad_face);
  ASSERT_EQ(ids.size(), 6u);
  std::vector<GO> sorted = ids;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(std::unique(sorted.begin(), sorted.end()), sorted.end()) << "one id per vertex";
  EXPECT_THROW(assembler.add_face(0, FaceMesh{}), Error);  // added with the group
  const SurfaceMesh m = assembler.finish();
  ASSERT_EQ(m.quads.size(), 2u);
  EXPECT_EQ(m.quad_face, (std::vector<LO>{0, 1}));
  // The shared edge 1-4 is one edge of both quads.
  EXPECT_EQ(m.quads[0][1], m.quads[1][0]);
  EXPECT_EQ(m.quads[0][2], m.quads[1][3]);
  EXPECT_EQ(m.vclass[static_cast<std::size_t>(ids[1])].entity, 0);
  EXPECT_EQ(m.vclass[static_cast<std::size_t>(ids[4])].entity, 1);
  for (const LO c : m.bar_curve) EXPECT_NE(c, 0);
  EXPECT_FALSE(m.bars.empty());

  // Counts that differ from the group's split are refused.
  std::vector<FaceContribution> off = counts;
  off[0] = {2, 0, 1};
  off[1] = {4, 0, 1};
  MeshAssembler wrong(model, p.curves, off);
  EXPECT_THROW((void)wrong.add_group(g, quad_face), Error);
}

}  // namespace
}  // namespace qsmesh::mesh
