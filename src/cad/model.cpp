// Topology of a CAD shape: ids from OpenCASCADE's unique-shape maps, loops of the FORWARD faces,
// adjacency maps.
#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepGProp.hxx>
#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GCPnts_AbscissaPoint.hxx>
#include <GProp_GProps.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>
#include <algorithm>
#include <cmath>
#include <gp_Circ.hxx>
#include <gp_Vec.hxx>
#include <numbers>
#include <utility>

#include "impl.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::cad {

const char* to_string(SurfaceType t) {
  switch (t) {
    case SurfaceType::Plane:
      return "plane";
    case SurfaceType::Cylinder:
      return "cylinder";
    case SurfaceType::Cone:
      return "cone";
    case SurfaceType::Sphere:
      return "sphere";
    case SurfaceType::Torus:
      return "torus";
    case SurfaceType::Bezier:
      return "bezier";
    case SurfaceType::BSpline:
      return "bspline";
    case SurfaceType::Revolution:
      return "revolution";
    case SurfaceType::Extrusion:
      return "extrusion";
    case SurfaceType::Offset:
      return "offset";
    case SurfaceType::Other:
      return "other";
  }
  return "other";
}

const char* to_string(CurveType t) {
  switch (t) {
    case CurveType::Line:
      return "line";
    case CurveType::Circle:
      return "circle";
    case CurveType::Ellipse:
      return "ellipse";
    case CurveType::Hyperbola:
      return "hyperbola";
    case CurveType::Parabola:
      return "parabola";
    case CurveType::Bezier:
      return "bezier";
    case CurveType::BSpline:
      return "bspline";
    case CurveType::Offset:
      return "offset";
    case CurveType::Other:
      return "other";
    case CurveType::Degenerate:
      return "degenerate";
  }
  return "other";
}

CadModel::CadModel() : impl_(std::make_unique<Impl>()) {}
CadModel::~CadModel() = default;
CadModel::CadModel(CadModel&&) noexcept = default;
CadModel& CadModel::operator=(CadModel&&) noexcept = default;

std::unique_ptr<CurveGeometry> CadModel::curve_geometry(LO c) const {
  QSMESH_CHECK(c >= 0 && c < num_curves(), "curve id " << c << " out of range");
  const Curve& cu = curves_[c];
  const Vec3 p = cu.corners[0] != kNoIndex ? corners_[cu.corners[0]].point : Vec3{};
  return make_curve_geometry(*impl_, cu, p, c);
}

std::unique_ptr<FaceGeometry> CadModel::face_geometry(LO f, bool with_classifier) const {
  QSMESH_CHECK(f >= 0 && f < num_faces(), "face id " << f << " out of range");
  return make_face_geometry(*impl_, faces_[f], f, with_classifier);
}

bool planar_with_right_angle_lines(const CadModel& model, LO f) {
  QSMESH_CHECK(f >= 0 && f < model.num_faces(), "face " << f << " out of range");
  const Face& face = model.faces()[f];
  if (face.type != SurfaceType::Plane) return false;
  bool first = true;
  gp_Vec ref;
  for (const Loop& loop : face.loops)
    for (const CurveUse& use : loop.uses) {
      const Curve& curve = model.curves()[use.curve];
      if (curve.degenerate || curve.type != CurveType::Line) return false;
      const BRepAdaptor_Curve adaptor(model.impl().edges[use.curve]);
      if (adaptor.GetType() != GeomAbs_Line) return false;
      const gp_Vec d(adaptor.Line().Direction());
      if (first) {
        ref = d, first = false;
        continue;
      }
      // The angle between the two lines, in [0, pi]; 4x it must be a multiple of 2 pi.
      const double a = 4 * std::atan2(d.Crossed(ref).Magnitude(), d.Dot(ref));
      if (std::abs(std::remainder(a, 2 * std::numbers::pi)) > 1e-6) return false;
    }
  return !first;
}

std::optional<RevolutionAxis> revolution_axis(const CadModel& model, LO f) {
  QSMESH_CHECK(f >= 0 && f < model.num_faces(), "face " << f << " out of range");
  const BRepAdaptor_Surface s(model.impl().faces[static_cast<std::size_t>(f)]);
  gp_Ax1 axis;
  bool cylinder = false;
  switch (s.GetType()) {
    case GeomAbs_Plane: {
      // A plane is a surface of revolution about any normal line: about the common centre of
      // its circles, if they have one (a washer, a flange's face around a bore, an annular
      // sector).
      const gp_Dir normal = s.Plane().Axis().Direction();
      const Face& face = model.faces()[static_cast<std::size_t>(f)];
      const double tol = 1e-6 * face.box.diagonal();
      std::optional<gp_Pnt> centre;
      for (const Loop& loop : face.loops)
        for (const CurveUse& use : loop.uses) {
          const BRepAdaptor_Curve c(model.impl().edges[static_cast<std::size_t>(use.curve)]);
          if (c.GetType() != GeomAbs_Circle) continue;
          const gp_Circ circle = c.Circle();
          if (!circle.Axis().Direction().IsParallel(normal, 1e-9)) return std::nullopt;
          if (!centre) {
            centre = circle.Location();
          } else if (centre->Distance(circle.Location()) > tol) {
            return std::nullopt;
          }
        }
      if (!centre) return std::nullopt;
      axis = gp_Ax1(*centre, normal);
      break;
    }
    case GeomAbs_Cylinder:
      axis = s.Cylinder().Axis();
      cylinder = true;
      break;
    case GeomAbs_Cone:
      axis = s.Cone().Axis();
      break;
    case GeomAbs_Sphere:
      axis = s.Sphere().Position().Axis();
      break;
    case GeomAbs_Torus:
      axis = s.Torus().Axis();
      break;
    case GeomAbs_SurfaceOfRevolution:
      axis = s.AxeOfRevolution();
      break;
    default:
      return std::nullopt;
  }
  const gp_Pnt& p = axis.Location();
  const gp_Dir& d = axis.Direction();
  return RevolutionAxis{{p.X(), p.Y(), p.Z()}, {d.X(), d.Y(), d.Z()}, cylinder};
}

std::optional<RevolutionAxis> iso_line_revolution_axis(const CadModel& model, LO f) {
  const auto axis = revolution_axis(model, f);
  if (!axis) return std::nullopt;
  const Face& face = model.faces()[static_cast<std::size_t>(f)];
  const double tol = 1e-6 * face.box.diagonal();
  const Vec3 a = axis->direction;
  const auto height = [&](const Vec3& v) { return dot(v, a); };
  const auto off_axis = [&](const Vec3& v) { return v - a * dot(v, a); };
  bool any = false;
  for (const Loop& loop : face.loops)
    for (const CurveUse& use : loop.uses) {
      if (model.curves()[static_cast<std::size_t>(use.curve)].degenerate) return std::nullopt;
      const BRepAdaptor_Curve c(model.impl().edges[static_cast<std::size_t>(use.curve)]);
      std::array<Vec3, 5> q;
      for (int k = 0; k < 5; ++k) {
        const gp_Pnt p =
            c.Value(c.FirstParameter() + (c.LastParameter() - c.FirstParameter()) * double(k) / 4);
        q[static_cast<std::size_t>(k)] = Vec3{p.X(), p.Y(), p.Z()} - axis->point;
      }
      // A parallel: every point at the first one's height along the axis and distance from it.
      // A meridian: every point in the half-plane through the axis and the first point.
      const Vec3 r0 = off_axis(q[0]);
      bool parallel = true, meridian = norm(r0) > tol;
      const Vec3 side = meridian ? normalized(cross(a, r0)) : Vec3{0, 0, 0};
      for (const Vec3& v : q) {
        parallel = parallel && std::abs(height(v) - height(q[0])) <= tol &&
                   std::abs(norm(off_axis(v)) - norm(r0)) <= tol;
        meridian = meridian && std::abs(dot(v, side)) <= tol && dot(off_axis(v), r0) >= 0;
      }
      if (!parallel && !meridian) return std::nullopt;
      any = true;
    }
  if (!any) return std::nullopt;
  return axis;
}

namespace {

Vec3 to_vec(const gp_Pnt& p) { return {p.X(), p.Y(), p.Z()}; }

// Trims the ends of curve i's range where it runs past its corner (see Curve::t0): the curve's
// own projection (CurveGeometry::project, Newton from the end, then a global search) of the
// corner onto the half of the range at that end, so a closed curve keeps one corner per end. An
// end is trimmed when that point is nearer the corner than the end point by more than a
// millionth of the curve's length (below that, the gap is noise of the CAD kernel).
void trim_overshoots(const CadModel::Impl& impl, const std::vector<Corner>& corners, LO i,
                     Curve& c) {
  const double mid = (c.t0 + c.t1) / 2;
  const double eps = 1e-6 * c.length;
  const Curve before = c;
  for (int end = 0; end < 2; ++end) {
    if (c.corners[end] == kNoIndex) continue;
    const Vec3& p = corners[c.corners[end]].point;
    Curve half = before;
    (end == 0 ? half.t1 : half.t0) = mid;
    const auto g = make_curve_geometry(impl, half, p, i);
    const double t_end = end == 0 ? before.t0 : before.t1;
    Vec3 foot;
    const double t = g->project(p, t_end, &foot);
    if (t != t_end && distance(foot, p) < distance(g->point(t_end), p) - eps) {
      (end == 0 ? c.t0 : c.t1) = t;
      c.trimmed[end] = true;
    }
  }
  // Both ends trimmed to about the middle: no curve between the corners to speak of; the range is
  // left as the CAD kernel gave it rather than made degenerate.
  if (!(c.t1 - c.t0 > 1e-3 * (before.t1 - before.t0))) c = before;
}

CurveType curve_type(GeomAbs_CurveType t) {
  switch (t) {
    case GeomAbs_Line:
      return CurveType::Line;
    case GeomAbs_Circle:
      return CurveType::Circle;
    case GeomAbs_Ellipse:
      return CurveType::Ellipse;
    case GeomAbs_Hyperbola:
      return CurveType::Hyperbola;
    case GeomAbs_Parabola:
      return CurveType::Parabola;
    case GeomAbs_BezierCurve:
      return CurveType::Bezier;
    case GeomAbs_BSplineCurve:
      return CurveType::BSpline;
    case GeomAbs_OffsetCurve:
      return CurveType::Offset;
    default:
      return CurveType::Other;
  }
}

SurfaceType surface_type(GeomAbs_SurfaceType t) {
  switch (t) {
    case GeomAbs_Plane:
      return SurfaceType::Plane;
    case GeomAbs_Cylinder:
      return SurfaceType::Cylinder;
    case GeomAbs_Cone:
      return SurfaceType::Cone;
    case GeomAbs_Sphere:
      return SurfaceType::Sphere;
    case GeomAbs_Torus:
      return SurfaceType::Torus;
    case GeomAbs_BezierSurface:
      return SurfaceType::Bezier;
    case GeomAbs_BSplineSurface:
      return SurfaceType::BSpline;
    case GeomAbs_SurfaceOfRevolution:
      return SurfaceType::Revolution;
    case GeomAbs_SurfaceOfExtrusion:
      return SurfaceType::Extrusion;
    case GeomAbs_OffsetSurface:
      return SurfaceType::Offset;
    default:
      return SurfaceType::Other;
  }
}

bool is_boundary_edge(const TopoDS_Shape& e) {
  return e.Orientation() == TopAbs_FORWARD || e.Orientation() == TopAbs_REVERSED;
}

// Edges of a wire in traversal order on the face. BRepTools_WireExplorer orders connected
// edges (seams and degenerate edges included); edges it skips on broken wires are appended in
// stored order so that no use is lost.
std::vector<TopoDS_Edge> ordered_edges(const TopoDS_Wire& wire, const TopoDS_Face& face) {
  std::vector<TopoDS_Edge> all;
  for (TopoDS_Iterator it(wire); it.More(); it.Next())
    if (it.Value().ShapeType() == TopAbs_EDGE && is_boundary_edge(it.Value()))
      all.push_back(TopoDS::Edge(it.Value()));
  std::vector<TopoDS_Edge> out;
  try {
    for (BRepTools_WireExplorer ex(wire, face); ex.More(); ex.Next())
      if (is_boundary_edge(ex.Current())) out.push_back(ex.Current());
  } catch (const Standard_Failure&) {
    out.clear();
  }
  if (out.size() != all.size()) {
    for (const TopoDS_Edge& e : all) {
      const bool found =
          std::any_of(out.begin(), out.end(), [&](const TopoDS_Edge& o) { return o.IsEqual(e); });
      if (!found) out.push_back(e);
    }
  }
  return out;
}

Box3 to_box(const Bnd_Box& b) {
  Box3 box;
  if (b.IsVoid()) return box;
  double x0, y0, z0, x1, y1, z1;
  b.Get(x0, y0, z0, x1, y1, z1);
  box.add(Vec3{x0, y0, z0});
  box.add(Vec3{x1, y1, z1});
  return box;
}

}  // namespace

CadModel ModelBuilder::build(const TopoDS_Shape& shape, std::string source,
                             const MeasureItems& measure_faces) {
  CadModel m;
  CadModel::Impl& im = *m.impl_;
  im.shape = shape;
  m.source_ = std::move(source);
  TopExp::MapShapes(shape, TopAbs_VERTEX, im.vertex_map);
  TopExp::MapShapes(shape, TopAbs_EDGE, im.edge_map);
  TopExp::MapShapes(shape, TopAbs_FACE, im.face_map);
  const LO nv = im.vertex_map.Extent(), ne = im.edge_map.Extent(), nf = im.face_map.Extent();

  m.corners_.resize(nv);
  for (LO i = 0; i < nv; ++i) {
    const TopoDS_Vertex& v = TopoDS::Vertex(im.vertex_map(i + 1));
    m.corners_[i].point = to_vec(BRep_Tool::Pnt(v));
    m.corners_[i].tolerance = BRep_Tool::Tolerance(v);
  }

  m.curves_.resize(ne);
  im.edges.resize(ne);
  for (LO i = 0; i < ne; ++i) {
    const TopoDS_Edge e = TopoDS::Edge(im.edge_map(i + 1).Oriented(TopAbs_FORWARD));
    im.edges[i] = e;
    Curve& c = m.curves_[i];
    TopoDS_Vertex v0, v1;
    TopExp::Vertices(e, v0, v1);
    c.corners[0] = v0.IsNull() ? kNoIndex : im.vertex_map.FindIndex(v0) - 1;
    c.corners[1] = v1.IsNull() ? kNoIndex : im.vertex_map.FindIndex(v1) - 1;
    BRep_Tool::Range(e, c.t0, c.t1);
    c.degenerate = BRep_Tool::Degenerated(e);
    if (c.degenerate) {
      c.type = CurveType::Degenerate;
      continue;
    }
    try {
      BRepAdaptor_Curve ac(e);
      c.type = curve_type(ac.GetType());
      c.length = GCPnts_AbscissaPoint::Length(ac, c.t0, c.t1);
      trim_overshoots(im, m.corners_, i, c);
      if (c.trimmed[0] || c.trimmed[1]) c.length = GCPnts_AbscissaPoint::Length(ac, c.t0, c.t1);
    } catch (const Standard_Failure&) {
      // An edge without usable geometry keeps length 0 and type Other.
      c.type = CurveType::Other;
      c.length = 0;
    }
  }

  m.faces_.resize(nf);
  im.faces.resize(nf);
  im.loop_edges.resize(nf);
  std::vector<std::pair<LO, LO>> face_curve;
  for (LO i = 0; i < nf; ++i) {
    const TopoDS_Shape& fs = im.face_map(i + 1);
    const TopoDS_Face ff = TopoDS::Face(fs.Oriented(TopAbs_FORWARD));
    im.faces[i] = ff;
    Face& f = m.faces_[i];
    f.reversed = fs.Orientation() == TopAbs_REVERSED;

    std::vector<TopoDS_Wire> wires;
    const TopoDS_Wire outer = BRepTools::OuterWire(ff);
    if (!outer.IsNull()) wires.push_back(outer);
    for (TopoDS_Iterator it(ff); it.More(); it.Next())
      if (it.Value().ShapeType() == TopAbs_WIRE && !it.Value().IsSame(outer))
        wires.push_back(TopoDS::Wire(it.Value()));

    std::vector<LO> used;
    for (std::size_t w = 0; w < wires.size(); ++w) {
      Loop loop;
      loop.outer = w == 0;
      std::vector<TopoDS_Edge> edges = ordered_edges(wires[w], ff);
      for (const TopoDS_Edge& e : edges) {
        CurveUse u;
        u.curve = im.edge_map.FindIndex(e) - 1;
        u.reversed = e.Orientation() == TopAbs_REVERSED;
        loop.uses.push_back(u);
        used.push_back(u.curve);
      }
      const std::size_t n = loop.uses.size();
      if (n == 0) f.loops_closed = false;
      for (std::size_t k = 0; k < n; ++k) {
        const CurveUse& a = loop.uses[k];
        const CurveUse& b = loop.uses[(k + 1) % n];
        if (a.curve < 0 || b.curve < 0) {
          f.loops_closed = false;
          continue;
        }
        const LO end = m.curves_[a.curve].corners[a.reversed ? 0 : 1];
        const LO start = m.curves_[b.curve].corners[b.reversed ? 1 : 0];
        if (end == kNoIndex || end != start) f.loops_closed = false;
      }
      f.loops.push_back(std::move(loop));
      im.loop_edges[i].push_back(std::move(edges));
    }
    if (wires.empty()) f.loops_closed = false;

    std::sort(used.begin(), used.end());
    for (std::size_t k = 0; k < used.size(); ++k) {
      if (used[k] < 0) continue;
      if (k + 1 < used.size() && used[k + 1] == used[k] &&
          (f.seams.empty() || f.seams.back() != used[k]))
        f.seams.push_back(used[k]);
      if (k == 0 || used[k - 1] != used[k]) face_curve.emplace_back(i, used[k]);
    }

    try {
      BRepAdaptor_Surface s(ff, false);
      f.type = surface_type(s.GetType());
      f.u_periodic = s.IsUPeriodic();
      f.v_periodic = s.IsVPeriodic();
      if (f.u_periodic) f.u_period = s.UPeriod();
      if (f.v_periodic) f.v_period = s.VPeriod();
    } catch (const Standard_Failure&) {
      f.type = SurfaceType::Other;
    }
    try {
      Bnd_Box b;
      BRepBndLib::Add(ff, b, false);
      f.box = to_box(b);
    } catch (const Standard_Failure&) {
    }
    try {
      double u0, u1, v0, v1;
      BRepTools::UVBounds(ff, u0, u1, v0, v1);
      f.uv_box.add(Vec2{u0, v0});
      f.uv_box.add(Vec2{u1, v1});
    } catch (const Standard_Failure&) {
    }
  }

  const auto area = [&im](LO f) {
    try {
      GProp_GProps props;
      BRepGProp::SurfaceProperties(im.faces[static_cast<std::size_t>(f)], props);
      return props.Mass();
    } catch (const Standard_Failure&) {
      return 0.0;
    }
  };
  if (measure_faces) {
    const std::vector<double> areas = measure_faces(nf, area);
    QSMESH_CHECK(static_cast<LO>(areas.size()) == nf,
                 "load: " << areas.size() << " face areas measured for " << nf << " faces");
    for (LO f = 0; f < nf; ++f) m.faces_[f].area = areas[static_cast<std::size_t>(f)];
  } else {
    for (LO f = 0; f < nf; ++f) m.faces_[f].area = area(f);
  }

  const Adjacency face2curves = Adjacency::from_pairs(nf, face_curve);
  m.curve2faces_ = face2curves.transpose(ne);

  std::vector<std::pair<LO, LO>> curve_corner;
  for (LO c = 0; c < ne; ++c) {
    const auto& cc = m.curves_[c].corners;
    if (cc[0] != kNoIndex) curve_corner.emplace_back(c, cc[0]);
    if (cc[1] != kNoIndex && cc[1] != cc[0]) curve_corner.emplace_back(c, cc[1]);
  }
  m.corner2curves_ = Adjacency::from_pairs(ne, std::move(curve_corner)).transpose(nv);

  std::vector<std::pair<LO, LO>> face_face;
  for (LO f = 0; f < nf; ++f) {
    std::vector<LO> nb;
    for (LO c : face2curves[f])
      for (LO g : m.curve2faces_[c])
        if (g != f) nb.push_back(g);
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    for (LO g : nb) face_face.emplace_back(f, g);
  }
  m.face2faces_ = Adjacency::from_pairs(nf, std::move(face_face));

  try {
    Bnd_Box b;
    BRepBndLib::Add(shape, b, false);
    m.box_ = to_box(b);
  } catch (const Standard_Failure&) {
  }
  for (const Corner& c : m.corners_) m.box_.add(c.point);
  return m;
}

}  // namespace qsmesh::cad
