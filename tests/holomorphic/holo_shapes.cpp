#include "holo_shapes.hpp"

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepFilletAPI_MakeFillet2d.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepTools.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <gp_Ax2.hxx>
#include <gp_Circ.hxx>
#include <gp_Pln.hxx>
#include <stdexcept>

namespace qsmesh::test {
namespace {

// The face minus a through cylinder of this radius about (x, y).
TopoDS_Shape drill(const TopoDS_Shape& face, double x, double y, double r) {
  const gp_Ax2 axis(gp_Pnt(x, y, -1.0), gp_Dir(0, 0, 1));
  BRepAlgoAPI_Cut cut(face, BRepPrimAPI_MakeCylinder(axis, r, 2.0).Shape());
  cut.Build();
  if (!cut.IsDone()) throw std::runtime_error("boolean cut failed");
  return cut.Shape();
}

std::string write(const TopoDS_Shape& s, const std::string& path) {
  if (!BRepTools::Write(s, path.c_str())) throw std::runtime_error("cannot write " + path);
  return path;
}

}  // namespace

std::string write_annulus(double inner, double outer, const std::string& path) {
  BRepBuilderAPI_MakeFace circle(
      gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)),
      BRepBuilderAPI_MakeWire(
          BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), outer)).Edge())
          .Wire());
  if (!circle.IsDone()) throw std::runtime_error("disk construction failed");
  return write(drill(circle.Face(), 0, 0, inner), path);
}

std::string write_plate_with_holes(double length, double width,
                                   const std::vector<std::array<double, 3>>& holes,
                                   const std::string& path) {
  BRepBuilderAPI_MakePolygon poly(gp_Pnt(0, 0, 0), gp_Pnt(length, 0, 0), gp_Pnt(length, width, 0),
                                  gp_Pnt(0, width, 0), /*Close=*/true);
  TopoDS_Shape plate = BRepBuilderAPI_MakeFace(poly.Wire(), /*OnlyPlane=*/true).Face();
  for (const auto& h : holes) plate = drill(plate, h[0], h[1], h[2]);
  return write(plate, path);
}

std::string write_disk_with_holes(double radius, const std::vector<std::array<double, 3>>& holes,
                                  const std::string& path) {
  BRepBuilderAPI_MakeFace disk(
      gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)),
      BRepBuilderAPI_MakeWire(
          BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), radius)).Edge())
          .Wire());
  if (!disk.IsDone()) throw std::runtime_error("disk construction failed");
  TopoDS_Shape shape = disk.Face();
  for (const auto& h : holes) shape = drill(shape, h[0], h[1], h[2]);
  return write(shape, path);
}

std::string write_rounded_plate_with_holes(double length, double width, double corner,
                                           const std::vector<std::array<double, 3>>& holes,
                                           const std::string& path) {
  BRepBuilderAPI_MakePolygon poly(gp_Pnt(0, 0, 0), gp_Pnt(length, 0, 0), gp_Pnt(length, width, 0),
                                  gp_Pnt(0, width, 0), /*Close=*/true);
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(poly.Wire(), /*OnlyPlane=*/true).Face();
  BRepFilletAPI_MakeFillet2d fillet(face);
  TopTools_IndexedMapOfShape vertices;
  TopExp::MapShapes(face, TopAbs_VERTEX, vertices);
  for (int i = 1; i <= vertices.Extent(); ++i)
    fillet.AddFillet(TopoDS::Vertex(vertices(i)), corner);
  fillet.Build();
  if (!fillet.IsDone()) throw std::runtime_error("fillet failed");
  TopoDS_Shape plate = fillet.Shape();
  for (const auto& h : holes) plate = drill(plate, h[0], h[1], h[2]);
  return write(plate, path);
}

}  // namespace qsmesh::test
