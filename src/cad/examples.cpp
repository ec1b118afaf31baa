// The built-in models of `qsmesh example`:
// - wing-body: a fuselage of revolution fused with a swept, tapered wing lofted from NACA 4-digit
//   sections. Millimetres; fuselage 10 m long along +x, span along y, up along z.
// - far-field: the wing-body cut out of a box 5 fuselage lengths long, the domain of an external
//   flow. Its six walls are planar faces 80 to 140 times the area of the largest skin face.
// - perforated-plate: a plate with a grid of holes of several radii, so its two large faces have
//   many inner loops each.
// They exercise what the shared models lack (huge planar faces, faces with many holes) in tests
// and benchmarks that must run without ../shared.
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepOffsetAPI_ThruSections.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeRevol.hxx>
#include <BRepTools.hxx>
#include <GC_MakeArcOfEllipse.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BezierCurve.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <TColgp_Array1OfPnt.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <cmath>
#include <gp_Ax1.hxx>
#include <gp_Ax2.hxx>
#include <gp_Elips.hxx>
#include <numbers>
#include <string>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::cad {

namespace {

constexpr double kLength = 10000;    // fuselage length
constexpr double kRadius = 600;      // fuselage radius
constexpr double kNose = 1500;       // nose length
constexpr double kTailStart = 6500;  // start of the tail cone
constexpr double kTailRadius = 120;  // radius of the flat tail end

// Fuselage: profile (nose ellipse, cylinder line, Bezier tail, flat end, axis) revolved about x.
// The axis segment is invariant under the revolution, so the result is a closed solid.
TopoDS_Shape make_fuselage() {
  // The profile lies in the xz plane (z >= 0) so that the seam of the revolved faces runs along
  // the top of the fuselage, away from the wing junction.
  const gp_Pnt nose_tip(0, 0, 0), nose_end(kNose, 0, kRadius), tail_start(kTailStart, 0, kRadius),
      tail_end(kLength, 0, kTailRadius), tail_axis(kLength, 0, 0);
  const gp_Elips ellipse(gp_Ax2(gp_Pnt(kNose, 0, 0), gp_Dir(0, -1, 0), gp::DX()), kNose, kRadius);
  GC_MakeArcOfEllipse nose(ellipse, nose_end, nose_tip, true);
  QSMESH_CHECK(nose.IsDone(), "wing-body example: nose arc failed");
  TColgp_Array1OfPnt poles(1, 4);
  poles(1) = tail_start;
  poles(2) = gp_Pnt(kTailStart + 1400, 0, kRadius);
  poles(3) = gp_Pnt(kLength - 1000, 0, kTailRadius + 0.35 * (kRadius - kTailRadius));
  poles(4) = tail_end;
  Handle(Geom_BezierCurve) tail = new Geom_BezierCurve(poles);

  BRepBuilderAPI_MakeWire wire;
  wire.Add(BRepBuilderAPI_MakeEdge(nose.Value()).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(nose_end, tail_start).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(tail).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(tail_end, tail_axis).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(tail_axis, nose_tip).Edge());
  QSMESH_CHECK(wire.IsDone(), "wing-body example: fuselage profile wire failed");
  BRepBuilderAPI_MakeFace face(wire.Wire(), true);
  QSMESH_CHECK(face.IsDone(), "wing-body example: fuselage profile face failed");
  BRepPrimAPI_MakeRevol revol(face.Face(), gp::OX(), 2 * std::numbers::pi);
  revol.Build();
  QSMESH_CHECK(revol.IsDone(), "wing-body example: fuselage revolution failed");
  return revol.Shape();
}

// Closed wire of a NACA 4-digit section (closed trailing edge): one BSpline edge through
// cosine-spaced points, from the trailing edge over the upper side to the leading edge and back.
TopoDS_Wire naca_section(int digits, double chord, const gp_Pnt& leading_edge) {
  const double m = (digits / 1000) / 100.0, pp = ((digits / 100) % 10) / 10.0,
               t = (digits % 100) / 100.0;
  constexpr int n = 36;
  auto shape = [&](double x, double& yc, double& dyc, double& yt) {
    yt = 5 * t *
         (0.2969 * std::sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x * x * x -
          0.1036 * x * x * x * x);
    if (m == 0) {
      yc = dyc = 0;
    } else if (x < pp) {
      yc = m / (pp * pp) * (2 * pp * x - x * x);
      dyc = 2 * m / (pp * pp) * (pp - x);
    } else {
      yc = m / ((1 - pp) * (1 - pp)) * (1 - 2 * pp + 2 * pp * x - x * x);
      dyc = 2 * m / ((1 - pp) * (1 - pp)) * (pp - x);
    }
  };
  std::vector<gp_Pnt> pts;
  auto add = [&](double xs, int side) {
    double yc, dyc, yt;
    shape(xs, yc, dyc, yt);
    const double th = std::atan(dyc);
    const double x = xs - side * yt * std::sin(th), z = yc + side * yt * std::cos(th);
    pts.emplace_back(leading_edge.X() + chord * x, leading_edge.Y(), leading_edge.Z() + chord * z);
  };
  for (int i = n; i >= 0; --i) add(0.5 * (1 - std::cos(std::numbers::pi * i / n)), +1);
  for (int i = 1; i <= n; ++i) add(0.5 * (1 - std::cos(std::numbers::pi * i / n)), -1);
  pts.back() = pts.front();  // exactly the same trailing-edge point
  Handle(TColgp_HArray1OfPnt) arr = new TColgp_HArray1OfPnt(1, static_cast<int>(pts.size()));
  for (std::size_t i = 0; i < pts.size(); ++i) arr->SetValue(static_cast<int>(i) + 1, pts[i]);
  GeomAPI_Interpolate interp(arr, false, 1e-7);
  interp.Perform();
  QSMESH_CHECK(interp.IsDone(), "wing-body example: NACA section interpolation failed");
  const TopoDS_Edge edge = BRepBuilderAPI_MakeEdge(interp.Curve()).Edge();
  BRepBuilderAPI_MakeWire wire(edge);
  QSMESH_CHECK(wire.IsDone(), "wing-body example: NACA section wire failed");
  return wire.Wire();
}

// One wing half from its root (inside the fuselage) to its tip; side = +1 or -1 along y.
TopoDS_Shape make_wing(double side) {
  const double root_y = side * 200, tip_y = side * 5200;
  const double root_x = 3400, root_z = -180, sweep = 1100, dihedral = 260;
  BRepOffsetAPI_ThruSections loft(true, false, 1e-6);
  loft.AddWire(naca_section(2412, 2200, gp_Pnt(root_x, root_y, root_z)));
  loft.AddWire(naca_section(2410, 900, gp_Pnt(root_x + sweep, tip_y, root_z + dihedral)));
  loft.CheckCompatibility(false);
  loft.Build();
  QSMESH_CHECK(loft.IsDone(), "wing-body example: wing loft failed");
  return loft.Shape();
}

TopoDS_Shape fuse(const TopoDS_Shape& a, const TopoDS_Shape& b) {
  BRepAlgoAPI_Fuse op(a, b);
  op.Build();
  QSMESH_CHECK(op.IsDone() && !op.HasErrors(), "wing-body example: boolean fuse failed");
  op.SimplifyResult();
  return op.Shape();
}

TopoDS_Shape make_wing_body() { return fuse(fuse(make_fuselage(), make_wing(+1)), make_wing(-1)); }

// The flow domain around the wing-body: a box from 2 lengths ahead of the nose to 3 behind it,
// 2.5 lengths to each side, 1.5 up and down, with the aircraft cut out (one solid, two shells).
TopoDS_Shape make_far_field() {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(gp_Pnt(-2 * kLength, -2.5 * kLength, -1.5 * kLength),
                                               gp_Pnt(3 * kLength, 2.5 * kLength, 1.5 * kLength))
                               .Shape();
  BRepAlgoAPI_Cut op(box, make_wing_body());
  op.Build();
  QSMESH_CHECK(op.IsDone() && !op.HasErrors(), "far-field example: boolean cut failed");
  op.SimplifyResult();
  return op.Shape();
}

// A 2000 x 1000 x 20 plate with 12 x 6 through holes whose radii cycle over 30, 45 and 60: its
// top and bottom faces have 73 loops each. All holes are cut in one operation.
TopoDS_Shape make_perforated_plate() {
  constexpr double kPlateX = 2000, kPlateY = 1000, kThickness = 20;
  constexpr int kHolesX = 12, kHolesY = 6;
  const TopoDS_Shape plate = BRepPrimAPI_MakeBox(kPlateX, kPlateY, kThickness).Shape();
  TopTools_ListOfShape holes;
  for (int i = 0; i < kHolesX; ++i)
    for (int j = 0; j < kHolesY; ++j) {
      const double r = 30 + 15 * ((i + 2 * j) % 3);
      const gp_Pnt c((i + 0.5) * kPlateX / kHolesX, (j + 0.5) * kPlateY / kHolesY, -kThickness);
      holes.Append(BRepPrimAPI_MakeCylinder(gp_Ax2(c, gp::DZ()), r, 3 * kThickness).Shape());
    }
  TopTools_ListOfShape arguments;
  arguments.Append(plate);
  BRepAlgoAPI_Cut op;
  op.SetArguments(arguments);
  op.SetTools(holes);
  op.Build();
  QSMESH_CHECK(op.IsDone() && !op.HasErrors(), "perforated-plate example: boolean cut failed");
  op.SimplifyResult();
  return op.Shape();
}

}  // namespace

void write_example(const std::string& name, const std::string& path, ExampleFormat format) {
  TopoDS_Shape shape;
  try {
    if (name == "wing-body")
      shape = make_wing_body();
    else if (name == "far-field")
      shape = make_far_field();
    else if (name == "perforated-plate")
      shape = make_perforated_plate();
    else
      throw InputError("unknown example '" + name + "'");
  } catch (const Standard_Failure& e) {
    throw Error(name + " example: OpenCASCADE failed: " + e.GetMessageString());
  }
  int solids = 0;
  for (TopExp_Explorer ex(shape, TopAbs_SOLID); ex.More(); ex.Next()) ++solids;
  QSMESH_CHECK(solids == 1, name << " example: the model has " << solids << " solids");
  BRepCheck_Analyzer check(shape);
  QSMESH_CHECK(check.IsValid(), name << " example: the solid is not valid");

  if (format == ExampleFormat::Brep) {
    if (!BRepTools::Write(shape, path.c_str()))
      throw InputError("cannot write the " + name + " example to '" + path + "'");
    return;
  }
  STEPControl_Writer writer;
  if (writer.Transfer(shape, STEPControl_AsIs) != IFSelect_RetDone)
    throw Error(name + " example: STEP transfer failed");
  if (writer.Write(path.c_str()) != IFSelect_RetDone)
    throw InputError("cannot write the " + name + " example to '" + path + "'");
}

}  // namespace qsmesh::cad
