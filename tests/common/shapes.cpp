#include "shapes.hpp"

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepFilletAPI_MakeFillet.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <GC_MakeArcOfCircle.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <STEPControl_Writer.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>
#include <cmath>
#include <gp_Ax2.hxx>
#include <gp_Circ.hxx>
#include <gp_Vec.hxx>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace qsmesh::test {

namespace {
std::string write(const TopoDS_Shape& s, const std::string& path) {
  if (!BRepTools::Write(s, path.c_str())) throw std::runtime_error("cannot write " + path);
  return path;
}

// BREP, or STEP when the path ends in .step or .stp.
std::string write_brep_or_step(const TopoDS_Shape& s, const std::string& path) {
  const std::string_view p(path);
  if (!p.ends_with(".step") && !p.ends_with(".stp")) return write(s, path);
  STEPControl_Writer w;
  if (w.Transfer(s, STEPControl_AsIs) != IFSelect_RetDone ||
      w.Write(path.c_str()) != IFSelect_RetDone)
    throw std::runtime_error("cannot write " + path);
  return path;
}

// A new face entity on the surface of `f`, bounded by its wires (hence the same edges): what a
// STEP file that gives a face twice holds.
TopoDS_Face given_again(const TopoDS_Face& f) {
  TopoDS_Face copy = TopoDS::Face(f.EmptyCopied());
  BRep_Builder builder;
  for (TopoDS_Iterator w(f); w.More(); w.Next()) builder.Add(copy, w.Value());
  return copy;
}

// The planar face bounded by `wire`, written as BREP; `what` names the shape in errors.
std::string write_planar_face(const TopoDS_Wire& wire, const char* what, const std::string& path) {
  BRepBuilderAPI_MakeFace face(wire, /*OnlyPlane=*/true);
  if (!face.IsDone()) throw std::runtime_error(std::string(what) + " face construction failed");
  return write(face.Face(), path);
}
}  // namespace

std::string write_box_with_hole(const std::string& path) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(10.0, 6.0, 4.0).Shape();
  const gp_Ax2 axis(gp_Pnt(5.0, 3.0, -1.0), gp_Dir(0, 0, 1));
  const TopoDS_Shape hole = BRepPrimAPI_MakeCylinder(axis, 1.5, 6.0).Shape();
  BRepAlgoAPI_Cut cut(box, hole);
  cut.Build();
  if (!cut.IsDone()) throw std::runtime_error("boolean cut failed");
  return write(cut.Shape(), path);
}

std::string write_pipe_cross(const std::string& path) {
  const auto pipe = [](gp_Pnt origin, gp_Dir dir, double radius) {
    return BRepPrimAPI_MakeCylinder(gp_Ax2(origin, dir), radius, 6.0).Shape();
  };
  BRepAlgoAPI_Fuse two(pipe(gp_Pnt(-3, 0, 0), gp_Dir(1, 0, 0), 1.0),
                       pipe(gp_Pnt(0, -3, 0.2), gp_Dir(0, 1, 0), 0.8));
  two.Build();
  if (!two.IsDone()) throw std::runtime_error("boolean fuse failed");
  BRepAlgoAPI_Fuse three(two.Shape(), pipe(gp_Pnt(0.5, 0, -3), gp_Dir(0, 0, 1), 0.6));
  three.Build();
  if (!three.IsDone()) throw std::runtime_error("boolean fuse failed");
  return write(three.Shape(), path);
}

std::string write_cylinder(const std::string& path) {
  return write(BRepPrimAPI_MakeCylinder(2.0, 5.0).Shape(), path);
}

std::string write_sphere(const std::string& path) {
  return write(BRepPrimAPI_MakeSphere(3.0).Shape(), path);
}

std::string write_sphere_octant(const std::string& path) {
  const double quarter = std::acos(0.0);
  return write(BRepPrimAPI_MakeSphere(3.0, 0.0, quarter, quarter).Shape(), path);
}

std::string write_sphere_lune(const std::string& path) {
  const double quarter = std::acos(0.0);
  return write(BRepPrimAPI_MakeSphere(3.0, -quarter, quarter, quarter).Shape(), path);
}

std::string write_polygon_face(const std::vector<std::pair<double, double>>& xy,
                               const std::string& path) {
  BRepBuilderAPI_MakePolygon poly;
  for (const auto& [x, y] : xy) poly.Add(gp_Pnt(x, y, 0));
  poly.Close();
  return write_planar_face(poly.Wire(), "polygon", path);
}

std::string write_long_plate(double length, double width, const std::string& path) {
  const double l = length, w = width;
  BRepBuilderAPI_MakePolygon outline;
  for (const auto& [x, y] : std::vector<std::pair<double, double>>{
           {0, 0}, {0.6 * l, 0}, {l, 0.2 * w}, {l, w}, {0.55 * l, w}, {0.45 * l, 0.8 * w}, {0, w}})
    outline.Add(gp_Pnt(x, y, 0));
  outline.Close();
  BRepBuilderAPI_MakeFace face(outline.Wire(), /*OnlyPlane=*/true);
  if (!face.IsDone()) throw std::runtime_error("long plate face construction failed");
  // Three holes: the face is not a disk, so no pattern fits it.
  for (const auto& [x, y] : std::vector<std::pair<double, double>>{
           {0.2 * l, 0.5 * w}, {0.5 * l, 0.4 * w}, {0.8 * l, 0.55 * w}}) {
    const gp_Circ circle(gp_Ax2(gp_Pnt(x, y, 0), gp_Dir(0, 0, 1)), 0.15 * w);
    const TopoDS_Wire hole = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circle).Edge()).Wire();
    face.Add(TopoDS::Wire(hole.Reversed()));
  }
  if (!face.IsDone()) throw std::runtime_error("long plate holes failed");
  return write(face.Face(), path);
}

std::string write_teardrop(double radius, const std::string& path) {
  // The tip (0, -r sqrt 2) sees the circle under 90 degrees; the tangent points close the arc.
  const double r = radius, h = r / std::sqrt(2.0);
  const gp_Pnt tip(0, -r * std::sqrt(2.0), 0), right(h, -h, 0), top(0, r, 0), left(-h, -h, 0);
  BRepBuilderAPI_MakeWire wire;
  wire.Add(BRepBuilderAPI_MakeEdge(tip, right).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(right, top, left).Value()).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(left, tip).Edge());
  if (!wire.IsDone()) throw std::runtime_error("teardrop wire construction failed");
  return write_planar_face(wire.Wire(), "teardrop", path);
}

std::string write_stadium(double length, double radius, bool arc_first, const std::string& path) {
  const double l = length, r = radius;
  const gp_Pnt a(0, -r, 0), b(l, -r, 0), c(l, r, 0), d(0, r, 0);
  const TopoDS_Edge bottom = BRepBuilderAPI_MakeEdge(a, b).Edge();
  const TopoDS_Edge right =
      BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(b, gp_Pnt(l + r, 0, 0), c).Value()).Edge();
  const TopoDS_Edge top = BRepBuilderAPI_MakeEdge(c, d).Edge();
  const TopoDS_Edge left =
      BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(d, gp_Pnt(-r, 0, 0), a).Value()).Edge();
  BRepBuilderAPI_MakeWire wire;
  for (const TopoDS_Edge& e : arc_first ? std::vector<TopoDS_Edge>{right, top, left, bottom}
                                        : std::vector<TopoDS_Edge>{bottom, right, top, left})
    wire.Add(e);
  if (!wire.IsDone()) throw std::runtime_error("stadium wire construction failed");
  return write_planar_face(wire.Wire(), "stadium", path);
}

std::string write_half_annulus(double inner, double outer, const std::string& path) {
  const double r = inner, R = outer;
  BRepBuilderAPI_MakeWire wire;
  wire.Add(BRepBuilderAPI_MakeEdge(
               GC_MakeArcOfCircle(gp_Pnt(R, 0, 0), gp_Pnt(0, R, 0), gp_Pnt(-R, 0, 0)).Value())
               .Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(-R, 0, 0), gp_Pnt(-r, 0, 0)).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(
               GC_MakeArcOfCircle(gp_Pnt(-r, 0, 0), gp_Pnt(0, r, 0), gp_Pnt(r, 0, 0)).Value())
               .Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(r, 0, 0), gp_Pnt(R, 0, 0)).Edge());
  if (!wire.IsDone()) throw std::runtime_error("half annulus wire construction failed");
  return write_planar_face(wire.Wire(), "half annulus", path);
}

std::string write_half_disk(double radius, const std::string& path) {
  const double r = radius;
  BRepBuilderAPI_MakeWire wire;
  wire.Add(BRepBuilderAPI_MakeEdge(
               GC_MakeArcOfCircle(gp_Pnt(r, 0, 0), gp_Pnt(0, r, 0), gp_Pnt(-r, 0, 0)).Value())
               .Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(-r, 0, 0), gp_Pnt(r, 0, 0)).Edge());
  if (!wire.IsDone()) throw std::runtime_error("half disk wire construction failed");
  return write_planar_face(wire.Wire(), "half disk", path);
}

std::string write_l_prism(const std::string& path) {
  BRepBuilderAPI_MakePolygon poly;
  for (const auto& [x, y] :
       std::vector<std::pair<double, double>>{{0, 0}, {8, 0}, {8, 3}, {3, 3}, {3, 6}, {0, 6}})
    poly.Add(gp_Pnt(x, y, 0));
  poly.Close();
  const TopoDS_Face base = BRepBuilderAPI_MakeFace(poly.Wire(), /*OnlyPlane=*/true).Face();
  const TopoDS_Shape prism = BRepPrimAPI_MakePrism(base, gp_Vec(0, 0, 2)).Shape();
  STEPControl_Writer w;
  if (w.Transfer(prism, STEPControl_AsIs) != IFSelect_RetDone ||
      w.Write(path.c_str()) != IFSelect_RetDone)
    throw std::runtime_error("cannot write " + path);
  return path;
}

std::string write_filleted_box(const std::string& path) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(8.0, 6.0, 4.0).Shape();
  BRepFilletAPI_MakeFillet fillet(box);
  for (TopExp_Explorer e(box, TopAbs_EDGE); e.More(); e.Next())
    fillet.Add(1.0, TopoDS::Edge(e.Current()));
  fillet.Build();
  if (!fillet.IsDone()) throw std::runtime_error("fillet failed");
  STEPControl_Writer w;
  if (w.Transfer(fillet.Shape(), STEPControl_AsIs) != IFSelect_RetDone ||
      w.Write(path.c_str()) != IFSelect_RetDone)
    throw std::runtime_error("cannot write " + path);
  return path;
}

std::string write_t_of_three_plates(const std::string& path) {
  // Vertices and edges are made once and shared, so the three faces hold the same TopoDS edge.
  auto vertex = [](double x, double y, double z) {
    return BRepBuilderAPI_MakeVertex(gp_Pnt(x, y, z)).Vertex();
  };
  const TopoDS_Vertex a0 = vertex(0, 0, 0), a1 = vertex(0, 2, 0), m0 = vertex(4, 0, 0),
                      m1 = vertex(4, 2, 0), b0 = vertex(8, 0, 0), b1 = vertex(8, 2, 0),
                      t0 = vertex(4, 0, 3), t1 = vertex(4, 2, 3);
  auto edge = [](const TopoDS_Vertex& p, const TopoDS_Vertex& q) {
    return BRepBuilderAPI_MakeEdge(p, q).Edge();
  };
  const TopoDS_Edge spine = edge(m0, m1);
  auto face = [&](const std::vector<TopoDS_Edge>& edges) {
    BRepBuilderAPI_MakeWire wire;
    for (const TopoDS_Edge& e : edges) wire.Add(e);
    if (!wire.IsDone()) throw std::runtime_error("T plate wire construction failed");
    BRepBuilderAPI_MakeFace f(wire.Wire(), /*OnlyPlane=*/true);
    if (!f.IsDone()) throw std::runtime_error("T plate face construction failed");
    return f.Face();
  };
  TopoDS_Shell t;
  BRep_Builder builder;
  builder.MakeShell(t);
  builder.Add(t, face({edge(a0, m0), spine, edge(m1, a1), edge(a1, a0)}));
  builder.Add(t, face({edge(m0, b0), edge(b0, b1), edge(b1, m1), spine}));
  builder.Add(t, face({spine, edge(m1, t1), edge(t1, t0), edge(t0, m0)}));
  return write_brep_or_step(t, path);
}

std::string write_plate_with_strip(double length, double side, double strip,
                                   const std::string& path) {
  auto vertex = [](double x, double y) {
    return BRepBuilderAPI_MakeVertex(gp_Pnt(x, y, 0)).Vertex();
  };
  const double y[4] = {0, side, side + strip, 2 * side + strip};
  std::vector<TopoDS_Vertex> left, right;
  for (const double v : y) {
    left.push_back(vertex(0, v));
    right.push_back(vertex(length, v));
  }
  auto edge = [](const TopoDS_Vertex& p, const TopoDS_Vertex& q) {
    return BRepBuilderAPI_MakeEdge(p, q).Edge();
  };
  // The three long edges between the rectangles are made once, so neighbours share them.
  std::vector<TopoDS_Edge> across;
  for (int k = 0; k < 4; ++k) across.push_back(edge(left[k], right[k]));
  TopoDS_Shell shell;
  BRep_Builder builder;
  builder.MakeShell(shell);
  for (int k = 0; k < 3; ++k) {
    BRepBuilderAPI_MakeWire wire;
    wire.Add(across[k]);
    wire.Add(edge(right[k], right[k + 1]));
    wire.Add(across[k + 1]);
    wire.Add(edge(left[k + 1], left[k]));
    if (!wire.IsDone()) throw std::runtime_error("plate wire construction failed");
    BRepBuilderAPI_MakeFace f(wire.Wire(), /*OnlyPlane=*/true);
    if (!f.IsDone()) throw std::runtime_error("plate face construction failed");
    builder.Add(shell, f.Face());
  }
  return write_brep_or_step(shell, path);
}

std::string write_box_with_duplicated_face(double depth, const std::string& path) {
  const double height = 4.0;
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(10.0, depth, height).Shape();
  TopoDS_Shell out;
  BRep_Builder builder;
  builder.MakeShell(out);
  TopoDS_Face top;
  for (TopExp_Explorer e(box, TopAbs_FACE); e.More(); e.Next()) {
    const TopoDS_Face f = TopoDS::Face(e.Current());
    builder.Add(out, f);
    double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
    BRepTools::UVBounds(f, u0, u1, v0, v1);
    const gp_Pnt mid = BRep_Tool::Surface(f)->Value(0.5 * (u0 + u1), 0.5 * (v0 + v1));
    if (std::abs(mid.Z() - height) < 1e-9) top = f;
  }
  if (top.IsNull()) throw std::runtime_error("box top face not found");
  builder.Add(out, given_again(top));
  return write_brep_or_step(out, path);
}

std::string write_rectangle_given_twice(double length, double width, const std::string& path) {
  BRepBuilderAPI_MakePolygon poly(gp_Pnt(0, 0, 0), gp_Pnt(length, 0, 0), gp_Pnt(length, width, 0),
                                  gp_Pnt(0, width, 0), /*Close=*/true);
  BRepBuilderAPI_MakeFace face(poly.Wire(), /*OnlyPlane=*/true);
  if (!face.IsDone()) throw std::runtime_error("rectangle face construction failed");
  TopoDS_Shell out;
  BRep_Builder builder;
  builder.MakeShell(out);
  builder.Add(out, face.Face());
  builder.Add(out, given_again(face.Face()));
  return write_brep_or_step(out, path);
}

mesh::CurveMesh uniform_curve_mesh(const cad::CadModel& model, LO c, LO n) {
  const auto& curve = model.curves()[c];
  const auto geometry = model.curve_geometry(c);
  mesh::CurveMesh cm;
  cm.curve = c;
  for (LO i = 0; i <= n; ++i) {
    const double t = curve.t0 + (curve.t1 - curve.t0) * i / n;
    cm.t.push_back(t);
    cm.points.push_back(geometry->point(t));
  }
  cm.points.front() = model.corners()[curve.corners[0]].point;
  cm.points.back() = model.corners()[curve.corners[1]].point;
  return cm;
}

std::vector<mesh::CurveMesh> polygon_curves(const cad::CadModel& model,
                                            const std::vector<std::pair<double, double>>& xy,
                                            const std::vector<LO>& counts) {
  std::vector<mesh::CurveMesh> out;
  const auto near = [](const Vec3& p, const std::pair<double, double>& q) {
    return std::abs(p.x - q.first) + std::abs(p.y - q.second) < 1e-9;
  };
  for (LO c = 0; c < model.num_curves(); ++c) {
    const auto& curve = model.curves()[c];
    const Vec3 a = model.corners()[curve.corners[0]].point,
               b = model.corners()[curve.corners[1]].point;
    LO n = 0;
    for (std::size_t k = 0; k < xy.size(); ++k) {
      const auto& p = xy[k];
      const auto& q = xy[(k + 1) % xy.size()];
      if ((near(a, p) && near(b, q)) || (near(a, q) && near(b, p))) n = counts[k];
    }
    if (n == 0) throw std::runtime_error("curve " + std::to_string(c) + " not on the polygon");
    out.push_back(uniform_curve_mesh(model, c, n));
  }
  return out;
}

}  // namespace qsmesh::test
