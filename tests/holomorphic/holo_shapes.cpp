#include "holo_shapes.hpp"

#include <BRepAdaptor_Surface.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepFilletAPI_MakeFillet.hxx>
#include <BRepFilletAPI_MakeFillet2d.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Shell.hxx>
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

std::string write_t_duct(double main_radius, double half_length, double branch_radius,
                         double branch_height, double fillet, const std::string& path) {
  // The main pipe's local x axis (its seam) points down, the branch's along -x.
  const gp_Ax2 main_axis(gp_Pnt(-half_length, 0, 0), gp_Dir(1, 0, 0), gp_Dir(0, 0, -1));
  const gp_Ax2 branch_axis(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1), gp_Dir(-1, 0, 0));
  const TopoDS_Shape main_pipe =
      BRepPrimAPI_MakeCylinder(main_axis, main_radius, 2 * half_length).Shape();
  const TopoDS_Shape branch =
      BRepPrimAPI_MakeCylinder(branch_axis, branch_radius, branch_height).Shape();
  BRepAlgoAPI_Fuse fuse(main_pipe, branch);
  fuse.Build();
  if (!fuse.IsDone()) throw std::runtime_error("boolean fuse failed");
  TopoDS_Shape solid = fuse.Shape();
  if (fillet > 0) {
    // The junction's edges: those of no planar face (the caps' circles are on planes).
    TopTools_IndexedMapOfShape cap_edges;
    for (TopExp_Explorer f(solid, TopAbs_FACE); f.More(); f.Next())
      if (BRepAdaptor_Surface(TopoDS::Face(f.Current())).GetType() == GeomAbs_Plane)
        TopExp::MapShapes(f.Current(), TopAbs_EDGE, cap_edges);
    BRepFilletAPI_MakeFillet round(solid);
    TopTools_IndexedMapOfShape edges;
    TopExp::MapShapes(solid, TopAbs_EDGE, edges);
    for (int i = 1; i <= edges.Extent(); ++i)
      if (!cap_edges.Contains(edges(i))) {
        // Seams (an edge used twice by one face) are not junctions either.
        bool seam = false;
        for (TopExp_Explorer f(solid, TopAbs_FACE); f.More() && !seam; f.Next()) {
          int uses = 0;
          for (TopExp_Explorer e(f.Current(), TopAbs_EDGE); e.More(); e.Next())
            if (e.Current().IsSame(edges(i))) ++uses;
          seam = uses == 2;
        }
        if (!seam) round.Add(fillet, TopoDS::Edge(edges(i)));
      }
    round.Build();
    if (!round.IsDone()) throw std::runtime_error("fillet failed");
    solid = round.Shape();
  }
  BRep_Builder builder;
  TopoDS_Shell shell;
  builder.MakeShell(shell);
  for (TopExp_Explorer f(solid, TopAbs_FACE); f.More(); f.Next())
    if (BRepAdaptor_Surface(TopoDS::Face(f.Current())).GetType() != GeomAbs_Plane)
      builder.Add(shell, f.Current());
  return write(shell, path);
}

std::string write_two_piece_pipe(double radius, double half_length, const std::string& path) {
  const TopoDS_Shape lower =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), radius, half_length)
          .Shape();
  const TopoDS_Shape upper =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, half_length), gp_Dir(0, 0, 1)), radius,
                               half_length)
          .Shape();
  BRepAlgoAPI_Fuse fuse(lower, upper);
  fuse.Build();
  if (!fuse.IsDone()) throw std::runtime_error("boolean fuse failed");
  BRep_Builder builder;
  TopoDS_Shell shell;
  builder.MakeShell(shell);
  for (TopExp_Explorer f(fuse.Shape(), TopAbs_FACE); f.More(); f.Next())
    if (BRepAdaptor_Surface(TopoDS::Face(f.Current())).GetType() != GeomAbs_Plane)
      builder.Add(shell, f.Current());
  return write(shell, path);
}

}  // namespace qsmesh::test
