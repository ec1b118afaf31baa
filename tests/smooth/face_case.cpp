#include "face_case.hpp"

#include <gtest/gtest.h>

#include <BRepTools.hxx>
#include <stdexcept>

#include "tmp_dir.hpp"

namespace qsmesh::test {

std::string tmp_path(const std::string& name) { return qsmesh::test::tmp_dir() + "/" + name; }

std::string write_face(const TopoDS_Shape& shape, const std::string& name) {
  const std::string path = tmp_path(name);
  if (!BRepTools::Write(shape, path.c_str())) throw std::runtime_error("cannot write " + path);
  return path;
}

FaceCase load_face(const std::string& path, cad::SurfaceType type) {
  FaceCase c{cad::load_cad(path), nullptr, kNoIndex};
  for (LO f = 0; f < c.model.num_faces(); ++f)
    if (c.model.faces()[f].type == type) c.face = f;
  if (c.face == kNoIndex) throw std::runtime_error("no face of the wanted type in " + path);
  c.geometry = c.model.face_geometry(c.face);
  return c;
}

FaceCase load_face(const TopoDS_Shape& shape, const std::string& name) {
  FaceCase c{cad::load_cad(write_face(shape, name)), nullptr, 0};
  c.geometry = c.model.face_geometry(0);
  return c;
}

void expect_locked_and_on_surface(const mesh::FaceMesh& in, const mesh::FaceMesh& out,
                                  const cad::FaceGeometry& g, double size, bool check_params) {
  ASSERT_EQ(in.points.size(), out.points.size());
  EXPECT_EQ(in.quads, out.quads);
  for (std::size_t v = 0; v < in.points.size(); ++v) {
    if (in.vclass[v].dim != 2) {
      EXPECT_TRUE(in.points[v] == out.points[v]) << "boundary vertex " << v << " moved";
      EXPECT_TRUE(in.uv[v] == out.uv[v]) << "boundary vertex " << v << " moved in uv";
    } else if (check_params) {
      EXPECT_EQ(out.vclass[v].param[0], out.uv[v].u);
      EXPECT_EQ(out.vclass[v].param[1], out.uv[v].v);
    }
    EXPECT_LT(distance(g.eval(out.uv[v]).p, out.points[v]), 1e-9 * size) << v;
  }
}

}  // namespace qsmesh::test
