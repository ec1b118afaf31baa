// Paper 003 on OpenCASCADE-built faces: each test gives a field as in one of the paper's figures
// and checks the all-quad mesh (irregular vertices exactly at the given singular points, SICN).
#include <gtest/gtest.h>

#include <BRepAlgoAPI_Common.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepPrimAPI_MakeHalfSpace.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <GC_MakeArcOfCircle.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Solid.hxx>
#include <TopoDS_Wire.hxx>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <gp_Ax3.hxx>
#include <gp_Circ.hxx>
#include <gp_Pln.hxx>
#include <map>
#include <numbers>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/fieldmesh/field_file.hpp"
#include "qsmesh/fieldmesh/field_mesh.hpp"
#include "qsmesh/quantize/quantize.hpp"
#include "tmp_dir.hpp"

namespace qsmesh {
namespace {

constexpr double kPi = std::numbers::pi;

std::string tmp(const std::string& name) { return test::tmp_dir() + "/" + name; }

std::string write(const TopoDS_Shape& s, const std::string& name) {
  const std::string path = tmp(name);
  if (!BRepTools::Write(s, path.c_str())) throw std::runtime_error("cannot write " + path);
  return path;
}

TopoDS_Edge circle_edge(double cx, double cy, double r) {
  return BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(gp_Pnt(cx, cy, 0), gp_Dir(0, 0, 1)), r)).Edge();
}

std::string write_polygon(const std::vector<std::pair<double, double>>& xy) {
  BRepBuilderAPI_MakePolygon poly;
  for (auto [x, y] : xy) poly.Add(gp_Pnt(x, y, 0));
  poly.Close();
  return write(BRepBuilderAPI_MakeFace(poly.Wire(), true).Face(), "fm_polygon.brep");
}

std::string write_square(double side) {
  return write_polygon({{0, 0}, {side, 0}, {side, side}, {0, side}});
}

std::string write_disk(double r) {
  const TopoDS_Wire w = BRepBuilderAPI_MakeWire(circle_edge(0, 0, r)).Wire();
  return write(BRepBuilderAPI_MakeFace(w, true).Face(), "fm_disk.brep");
}

// Square [-a, a]^2 with a hole of radius r about the origin.
std::string write_plate_with_hole(double a, double r) {
  BRepBuilderAPI_MakePolygon poly;
  for (auto [x, y] : {std::pair{-a, -a}, {a, -a}, {a, a}, {-a, a}}) poly.Add(gp_Pnt(x, y, 0));
  poly.Close();
  BRepBuilderAPI_MakeFace face(poly.Wire(), true);
  TopoDS_Wire hole = BRepBuilderAPI_MakeWire(circle_edge(0, 0, r)).Wire();
  hole.Reverse();
  face.Add(hole);
  return write(face.Face(), "fm_plate_hole.brep");
}

// Fig. 14: a plate [-a, a]^2 whose hole of radius r is filled by two half discs; shared edges.
std::string write_two_materials(double a, double r) {
  const gp_Pnt e(r, 0, 0), w(-r, 0, 0);
  const TopoDS_Edge top =
      BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(e, gp_Pnt(0, r, 0), w).Value()).Edge();
  const TopoDS_Edge bottom =
      BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(w, gp_Pnt(0, -r, 0), e).Value()).Edge();
  const TopoDS_Edge diameter = BRepBuilderAPI_MakeEdge(w, e).Edge();
  BRepBuilderAPI_MakeWire upper(top, diameter), lower(bottom, TopoDS::Edge(diameter.Reversed()));
  BRepBuilderAPI_MakePolygon poly;
  for (auto [x, y] : {std::pair{-a, -a}, {a, -a}, {a, a}, {-a, a}}) poly.Add(gp_Pnt(x, y, 0));
  poly.Close();
  BRepBuilderAPI_MakeFace plate(poly.Wire(), true);
  TopoDS_Wire hole = BRepBuilderAPI_MakeWire(top, bottom).Wire();
  hole.Reverse();
  plate.Add(hole);
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  b.Add(c, plate.Face());
  b.Add(c, BRepBuilderAPI_MakeFace(upper.Wire(), true).Face());
  b.Add(c, BRepBuilderAPI_MakeFace(lower.Wire(), true).Face());
  return write(c, "fm_two_materials.brep");
}

// A quarter of the cylinder of radius r, height hgt.
std::string write_cylinder_patch(double r, double hgt) {
  Handle(Geom_CylindricalSurface) s = new Geom_CylindricalSurface(gp_Ax3(gp::XOY()), r);
  return write(BRepBuilderAPI_MakeFace(s, 0.0, kPi / 2, 0.0, hgt, 1e-7).Face(), "fm_cylinder.brep");
}

// The quarter cylinder of radius 1 below the plane z = 1.5 + 0.15 (x - y): straight sides of
// heights 1.65 (angle 0) and 1.35 (angle pi / 2), a bottom arc and an elliptic top arc.
std::string write_slanted_cylinder_patch() {
  Handle(Geom_CylindricalSurface) s = new Geom_CylindricalSurface(gp_Ax3(gp::XOY()), 1.0);
  const TopoDS_Face tall = BRepBuilderAPI_MakeFace(s, 0.0, kPi / 2, 0.0, 3.0, 1e-7).Face();
  const gp_Pln plane(gp_Pnt(0, 0, 1.5), gp_Dir(-0.15, 0.15, 1.0));
  const TopoDS_Face cutter = BRepBuilderAPI_MakeFace(plane, -5, 5, -5, 5).Face();
  const TopoDS_Solid below = BRepPrimAPI_MakeHalfSpace(cutter, gp_Pnt(0, 0, -10)).Solid();
  BRepAlgoAPI_Common common(tall, below);
  common.Build();
  if (!common.IsDone()) throw std::runtime_error("slanted cylinder patch failed");
  return write(common.Shape(), "fm_slanted_cylinder.brep");
}

struct Case {
  cad::CadModel model;
  std::vector<mesh::CurveMesh> curves;
};

// The curve meshes of the pipeline at a uniform size; chord_ratio_limit as in QuantizeOptions.
// `prescribe`, when given, names curve counts to keep (QuantizeOptions::prescribed).
Case make_case(
    const std::string& path, double size, double chord_ratio_limit = 2.0,
    const std::function<std::vector<std::pair<LO, int>>(const cad::CadModel&)>& prescribe = {}) {
  Case c{cad::load_cad(path), {}};
  const TaskArena tasks(1);
  background::SizeOptions sizes;
  sizes.size = size;
  const auto bg = background::mesh_curves(c.model, sizes, tasks);
  std::vector<std::vector<double>> at;
  for (const auto& m : bg) at.emplace_back(m.points.size(), size);
  quantize::QuantizeOptions qo;
  qo.chord_ratio_limit = chord_ratio_limit;
  if (prescribe) qo.prescribed = prescribe(c.model);
  const auto q = quantize::quantize_curves(c.model, quantize::ideal_edge_counts(bg, at), qo);
  c.curves = quantize::place_vertices(c.model, bg, at, q, false, tasks);
  return c;
}

struct FaceRun {
  mesh::FaceMesh tri;
  fieldmesh::Frame frame;
  mesh::FaceMesh quads;
  fieldmesh::FieldMeshReport report;
};

mesh::FaceMesh triangulate(const Case& c, LO f, double size) {
  background::BackgroundOptions bo;
  bo.sizes.size = size;
  background::FaceReport fr;
  return background::mesh_face_background(c.model, f, c.curves, bo, &fr);
}

FaceRun run_points(const Case& c, LO f, double size,
                   const std::vector<fieldmesh::SingularPoint>& pts) {
  FaceRun r;
  r.tri = triangulate(c, f, size);
  const auto surface = c.model.face_geometry(f);
  r.frame = fieldmesh::face_frame(r.tri, *surface, nullptr);
  const auto theta = fieldmesh::field_from_points(r.tri, *surface, pts);
  r.quads = fieldmesh::mesh_face_from_field(c.model, f, c.curves, r.tri, r.frame, theta, pts, {},
                                            nullptr, &r.report);
  return r;
}

// Interior vertices of valence != 4, with their valence.
std::vector<std::pair<Vec3, int>> irregular(const mesh::FaceMesh& m) {
  std::vector<int> val(m.points.size(), 0);
  for (const auto& q : m.quads)
    for (LO v : q) ++val[v];
  std::vector<std::pair<Vec3, int>> out;
  for (std::size_t v = 0; v < m.points.size(); ++v)
    if (m.vclass[v].dim == 2 && val[v] != 4) out.emplace_back(m.points[v], val[v]);
  return out;
}

// Every given point is one irregular vertex of valence 4 - d nearby, and there is no other.
void expect_irregular_at(const FaceRun& r, const std::vector<fieldmesh::SingularPoint>& pts,
                         double tol) {
  const auto irr = irregular(r.quads);
  ASSERT_EQ(irr.size(), pts.size());
  for (const auto& p : pts) {
    int found = 0;
    for (const auto& [x, val] : irr)
      if (distance(x, p.position) < tol && val == 4 - p.d) ++found;
    EXPECT_EQ(found, 1) << "no irregular vertex of valence " << 4 - p.d << " near (" << p.position.x
                        << ", " << p.position.y << ", " << p.position.z << ")";
  }
}

// The report's grids are the partition's regions, one each, and they cover the quads once: the
// cell (i, j) of a grid is a quad of the mesh with the vertices (i, j), (i + 1, j), (i + 1, j + 1),
// (i, j + 1) in its order (up to the first), i.e. oriented as the face.
void expect_region_grids(const mesh::FaceMesh& quads, const fieldmesh::FieldMeshReport& report) {
  ASSERT_EQ(static_cast<int>(report.grids.size()), report.regions);
  auto key = [](std::array<GO, 4> c) {
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    return c;
  };
  std::map<std::array<GO, 4>, int> uses;
  for (const auto& q : quads.quads) uses[key({q[0], q[1], q[2], q[3]})] = 0;
  std::size_t cells = 0;
  for (const auto& g : report.grids) {
    ASSERT_GE(g.ni, 1);
    ASSERT_GE(g.nj, 1);
    ASSERT_EQ(g.vertices.size(), static_cast<std::size_t>((g.ni + 1) * (g.nj + 1)));
    auto at = [&](LO i, LO j) { return g.vertices[static_cast<std::size_t>(j * (g.ni + 1) + i)]; };
    for (LO j = 0; j < g.nj; ++j)
      for (LO i = 0; i < g.ni; ++i, ++cells) {
        const auto it = uses.find(key({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)}));
        ASSERT_NE(it, uses.end()) << "cell (" << i << ", " << j << ") is no quad of the face";
        EXPECT_EQ(++it->second, 1);
      }
  }
  EXPECT_EQ(cells, quads.quads.size());
}

void expect_valid(const FaceRun& r) {
  ASSERT_TRUE(r.report.ok) << r.report.stage << ": " << r.report.reason;
  expect_region_grids(r.quads, r.report);
  EXPECT_GT(r.quads.quads.size(), 0u);
  EXPECT_TRUE(r.quads.triangles.empty());
  EXPECT_GT(r.report.stats.sicn_min, 0.3);
  EXPECT_EQ(r.report.stats.irregular_boundary, 0);
}

// Fig. 3: the cross whose representation vector is the gradient of f (angle arg(grad f) / 4),
// sampled a little inside the unit square: grad f vanishes at its corners.
template <class Grad>
std::vector<double> quarter_angle_of_gradient(const mesh::FaceMesh& tri, Grad grad) {
  std::vector<double> theta;
  for (const auto& p : tri.points) {
    const double x = 0.5 + (p.x - 0.5) * 0.999, y = 0.5 + (p.y - 0.5) * 0.999;
    const Vec3 g = grad(x, y);
    theta.push_back(std::atan2(g.y, g.x) / 4);
  }
  return theta;
}

TEST(FieldMesh, SquareEigenmodeFieldIsAlignedIntoAGrid) {
  // Fig. 3 / 5-6: the cross of quarter angle of grad f, f = cos(pi x) + cos(pi y) (a Neumann
  // eigenmode of the unit square), is not aligned with the boundary; Eq. 14 aligns it.
  const Case c = make_case(write_square(1.0), 0.1);
  FaceRun r;
  r.tri = triangulate(c, 0, 0.05);
  const auto surface = c.model.face_geometry(0);
  r.frame = fieldmesh::face_frame(r.tri, *surface, nullptr);
  const std::vector<double> theta = quarter_angle_of_gradient(r.tri, [](double x, double y) {
    return Vec3{-kPi * std::sin(kPi * x), -kPi * std::sin(kPi * y), 0};
  });
  r.quads = fieldmesh::mesh_face_from_field(c.model, 0, c.curves, r.tri, r.frame, theta, {}, {},
                                            nullptr, &r.report);
  expect_valid(r);
  EXPECT_EQ(r.report.singularities, 0);
  EXPECT_EQ(r.report.regions, 1);
  EXPECT_TRUE(irregular(r.quads).empty());
  EXPECT_EQ(r.quads.quads.size(), 100u);
  EXPECT_GT(r.report.stats.sicn_min, 0.9);
}

TEST(FieldMesh, SquareEigenmodeWithAnInteriorExtremumIsRefusedByEq11) {
  // f = cos(pi x) cos(pi y) (another Neumann eigenmode) has a saddle at the centre: the
  // quarter-angle cross has a singular point of index -1/4 there, while four right corners leave
  // room for none.
  const Case c = make_case(write_square(1.0), 0.1);
  const mesh::FaceMesh tri = triangulate(c, 0, 0.05);
  const auto surface = c.model.face_geometry(0);
  const auto frame = fieldmesh::face_frame(tri, *surface, nullptr);
  const std::vector<double> theta = quarter_angle_of_gradient(tri, [](double x, double y) {
    return Vec3{-kPi * std::sin(kPi * x) * std::cos(kPi * y),
                -kPi * std::cos(kPi * x) * std::sin(kPi * y), 0};
  });
  fieldmesh::FieldMeshReport rep;
  const auto m = fieldmesh::mesh_face_from_field(c.model, 0, c.curves, tri, frame, theta, {}, {},
                                                 nullptr, &rep);
  EXPECT_FALSE(rep.ok);
  EXPECT_TRUE(m.quads.empty());
  EXPECT_EQ(rep.stage, "compatibility");
  EXPECT_NE(rep.reason.find("Eq. 11"), std::string::npos) << rep.reason;
  EXPECT_EQ(rep.compatibility.loops.at(0).field, -0.25);
  EXPECT_EQ(rep.compatibility.loops.at(0).aligned, 0.0);
}

TEST(FieldMesh, QuadrilateralWithAValence3And5PairOfEq2) {
  // An aligned valence 3-5 pair is a transition: the side near the valence-3 point holds the two
  // chords that end between the pair more than the opposite side, so that side is longer here
  // (22 and 18 curve edges, the two sides left out of one chord); with equal counts on opposite
  // sides no quantization exists.
  const Case c = make_case(write_polygon({{0, 0}, {1, 0}, {1, 0.9}, {0, 1.1}}), 0.05, 1.0);
  const std::vector<fieldmesh::SingularPoint> pts{{{0.37, 0.5, 0}, 1}, {{0.63, 0.5, 0}, -1}};
  const FaceRun r = run_points(c, 0, 0.025, pts);
  expect_valid(r);
  expect_irregular_at(r, pts, 0.05);
}

TEST(FieldMesh, DiskWithFourSingularPointsOfEq2) {
  // Fig. 4: the field of Eq. 2 on a disk; a smooth boundary (one corner of 180 degrees, index 0)
  // asks for singular points whose indices sum to 1 (Eq. 11).
  const Case c = make_case(write_disk(1.0), 0.1);
  const double s = 0.4;
  const std::vector<fieldmesh::SingularPoint> pts{
      {{s, s, 0}, 1}, {{-s, s, 0}, 1}, {{-s, -s, 0}, 1}, {{s, -s, 0}, 1}};
  const FaceRun r = run_points(c, 0, 0.05, pts);
  expect_valid(r);
  expect_irregular_at(r, pts, 0.1);
  EXPECT_EQ(r.report.regions, 5);
}

TEST(FieldMesh, DiskWithTwoSingularPointsIsRefusedByEq11) {
  // Two singular points of index 1/4 give deg(u) = 1/2 on a circle that asks for 1.
  const Case c = make_case(write_disk(1.0), 0.1);
  const std::vector<fieldmesh::SingularPoint> pts{{{0.4, 0, 0}, 1}, {{-0.4, 0, 0}, 1}};
  const FaceRun r = run_points(c, 0, 0.05, pts);
  EXPECT_FALSE(r.report.ok);
  EXPECT_TRUE(r.report.grids.empty());
  EXPECT_EQ(r.report.stage, "compatibility");
  EXPECT_NE(r.report.reason.find("Eq. 11"), std::string::npos) << r.report.reason;
}

// Boundary vertices of m away from their ideal valence (as mesh::face_quad_stats counts them),
// with their valence.
std::vector<std::pair<Vec3, int>> irregular_on_boundary(const mesh::FaceMesh& m) {
  std::vector<int> val(m.points.size(), 0);
  std::vector<double> angle(m.points.size(), 0.0);
  for (const auto& q : m.quads)
    for (int k = 0; k < 4; ++k) {
      ++val[q[k]];
      const Vec3 a = m.points[q[(k + 3) % 4]] - m.points[q[k]],
                 b = m.points[q[(k + 1) % 4]] - m.points[q[k]];
      angle[q[k]] += std::atan2(norm(cross(a, b)), dot(a, b));
    }
  std::vector<std::pair<Vec3, int>> out;
  for (std::size_t v = 0; v < m.points.size(); ++v) {
    if (m.vclass[v].dim == 2 || val[v] == 0) continue;
    const int ideal =
        m.vclass[v].dim == 1 ? 2 : std::max(1, static_cast<int>(std::lround(angle[v] / (kPi / 2))));
    if (val[v] != ideal) out.emplace_back(m.points[v], val[v]);
  }
  return out;
}

// The circle of radius 1 in 16 edges, a vertex at (1, 0, 0) (the circle's CAD vertex).
Case disk_of_16_edges() {
  return make_case(write_disk(1.0), 0.4, 2.0, [](const cad::CadModel&) {
    return std::vector<std::pair<LO, int>>{{0, 16}};
  });
}

TEST(FieldMesh, DiskWithTwoSingularPointsAndTwoBoundarySingularPoints) {
  // Fig. 4 with two singular points, as Fig. 9 (top): two valence-3 points of Eq. 2 give
  // deg(u) = 1/2 on the circle, so Eq. 11 asks for boundary singular points whose indices sum to
  // 1/2: two of index 1/4, at (1, 0) (the circle's CAD vertex, Table 1 index 0 replaced) and
  // (-1, 0) (a curve vertex). Each is the corner of one quad, whose angle there is the circle
  // polygon's, 180 - 360/16 degrees: SICN sin(2 pi / 16) = 0.383 bounds the face's. With the
  // points at +-0.3 (0.2 to 0.35 alike) their separatrices end at the circle's 45-degree vertices:
  // four regions of 2 x 2 and 4 x 2 quads. From +-0.4 on they end at 22.5 degrees and the two
  // middle regions are one row of wedges (SICN 0.23 to 0.29).
  const Case c = disk_of_16_edges();
  ASSERT_EQ(c.curves.at(0).points.size(), 17u);
  const std::vector<fieldmesh::SingularPoint> interior{{{0.3, 0, 0}, 1}, {{-0.3, 0, 0}, 1}};
  std::vector<fieldmesh::SingularPoint> pts = interior;
  pts.push_back({{1, 0, 0}, 1});
  pts.push_back({{-1, 0, 0}, 1});
  FaceRun r = run_points(c, 0, 0.1, pts);
  ASSERT_TRUE(r.report.ok) << r.report.stage << ": " << r.report.reason;
  EXPECT_EQ(r.report.compatibility.loops.at(0).field, 0.5);
  EXPECT_EQ(r.report.compatibility.loops.at(0).corner_indices, 0.5);
  EXPECT_EQ(r.report.singularities, 2);
  EXPECT_TRUE(r.quads.triangles.empty());
  EXPECT_GT(r.report.stats.sicn_min, 0.3);
  EXPECT_NEAR(r.report.stats.sicn_min, std::sin(2 * kPi / 16), 1e-3);
  EXPECT_EQ(r.report.regions, 4);
  EXPECT_EQ(r.quads.quads.size(), 24u);
  expect_region_grids(r.quads, r.report);
  std::vector<std::pair<LO, LO>> sizes;
  for (const auto& g : r.report.grids)
    sizes.emplace_back(std::min(g.ni, g.nj), std::max(g.ni, g.nj));
  std::sort(sizes.begin(), sizes.end());
  EXPECT_EQ(sizes, (std::vector<std::pair<LO, LO>>{{2, 2}, {2, 2}, {2, 4}, {2, 4}}));
  expect_irregular_at(r, interior, 1e-9);
  // The boundary irregular vertices are the two given ones, one quad each.
  const auto on_boundary = irregular_on_boundary(r.quads);
  EXPECT_EQ(r.report.stats.irregular_boundary, 2);
  ASSERT_EQ(on_boundary.size(), 2u);
  for (const auto& [x, val] : on_boundary) {
    EXPECT_EQ(val, 1);
    EXPECT_NEAR(std::abs(x.x), 1.0, 1e-9);
    EXPECT_NEAR(x.y, 0.0, 1e-9);
  }

  // The same points as a FIELD file gives them (mesh_face_by_method: its own triangulation).
  fieldmesh::GivenFaceField given;
  given.face = 0;
  given.points = pts;
  fieldmesh::FieldMeshReport rep;
  const auto m = fieldmesh::mesh_face_by_method(
      c.model, 0, c.curves, fieldmesh::FaceMethod::GivenField, &given, nullptr, {}, nullptr, &rep);
  ASSERT_TRUE(rep.ok) << rep.stage << ": " << rep.reason;
  expect_region_grids(m, rep);
  EXPECT_EQ(rep.stats.irregular_interior, 2);
  EXPECT_EQ(rep.stats.irregular_boundary, 2);
  EXPECT_GT(rep.stats.sicn_min, 0.3);

  // Index -1/4 at the two boundary points: Eq. 11 asks for deg(u) = 3/2.
  pts[2].d = pts[3].d = -1;
  r = run_points(c, 0, 0.1, pts);
  EXPECT_FALSE(r.report.ok);
  EXPECT_TRUE(r.report.grids.empty());
  EXPECT_EQ(r.report.stage, "compatibility");
  EXPECT_NE(r.report.reason.find("Eq. 11"), std::string::npos) << r.report.reason;
  EXPECT_NE(r.report.reason.find("2 given boundary points"), std::string::npos) << r.report.reason;
}

TEST(FieldMesh, TrapezoidWithoutSingularPointIsRefusedByItsCurveCounts) {
  // Four corners of about 72 and 108 degrees (index 1/4 each by Table 1) and no singular point:
  // the partition is the face itself, one region whose opposite sides the curve quantization gave
  // 10 and 6 edges. No separatrix end can change that: the refusal says so, with the counts.
  // chord_ratio_limit 1: the quantization keeps the opposite curves' own counts (10 and 6).
  const Case c = make_case(write_polygon({{0, 0}, {1, 0}, {0.8, 0.6}, {0.2, 0.6}}), 0.1, 1.0);
  const FaceRun r = run_points(c, 0, 0.05, {});
  EXPECT_FALSE(r.report.ok);
  EXPECT_TRUE(r.quads.quads.empty());
  EXPECT_TRUE(r.report.compatibility.ok);
  EXPECT_EQ(r.report.regions, 1);
  EXPECT_EQ(r.report.stage, "quantization");
  EXPECT_NE(r.report.reason.find("curve counts cannot fit the partition"), std::string::npos)
      << r.report.reason;
  EXPECT_NE(r.report.reason.find("hold 10 and 6 curve edges"), std::string::npos)
      << r.report.reason;
}

TEST(FieldMesh, PlateWithHoleAndTwoSingularPointsIsRefusedByEq16) {
  // Four right corners (index 1/4 each) and a hole: chi = 0, so the singular points' indices must
  // sum to -1 (Eq. 16); two valence-5 points give -1/2.
  const Case c = make_case(write_plate_with_hole(2.0, 0.8), 0.2);
  const std::vector<fieldmesh::SingularPoint> pts{{{1.15, 1.15, 0}, -1}, {{-1.15, -1.15, 0}, -1}};
  const FaceRun r = run_points(c, 0, 0.1, pts);
  EXPECT_FALSE(r.report.ok);
  EXPECT_TRUE(r.quads.quads.empty());
  EXPECT_EQ(r.report.stage, "compatibility");
  EXPECT_NE(r.report.reason.find("Eq. 16"), std::string::npos) << r.report.reason;
}

TEST(FieldMesh, PlateWithHoleUnalignedFieldIsCorrected) {
  // Figs. 10-11: four valence-5 points of Eq. 2 satisfy Eq. 16 but not Eq. 17 (the field does not
  // turn around the hole); the hole correction of Eqs. 18-20 makes it alignable.
  const Case c = make_case(write_plate_with_hole(2.0, 0.8), 0.2);
  const double s = 1.15;
  const std::vector<fieldmesh::SingularPoint> pts{
      {{s, s, 0}, -1}, {{-s, s, 0}, -1}, {{-s, -s, 0}, -1}, {{s, -s, 0}, -1}};
  const FaceRun r = run_points(c, 0, 0.1, pts);
  ASSERT_EQ(r.report.compatibility.loops.size(), 2u);
  EXPECT_TRUE(r.report.compatibility.needs_hole_correction);
  EXPECT_NE(r.report.compatibility.reason.find("Eq. 17"), std::string::npos);
  expect_valid(r);
  expect_irregular_at(r, pts, 0.2);
}

}  // namespace
}  // namespace qsmesh

namespace qsmesh {
namespace {

TEST(FieldMesh, TwoMaterialsHalfDiscsInAPlateWithAHole) {
  // Fig. 14: the half discs (two corners of 90 degrees each, Table 1: index 1/4) take two valence-3
  // points each, the plate around them four valence-5 points and the hole correction; the three
  // faces are meshed on the same curve meshes, so the mesh is conforming by construction.
  const Case c = make_case(write_two_materials(2.0, 1.0), 0.2);
  ASSERT_EQ(c.model.num_faces(), 3);
  int meshed = 0;
  for (LO f = 0; f < 3; ++f) {
    const auto& face = c.model.faces()[f];
    std::vector<fieldmesh::SingularPoint> pts;
    if (face.loops.size() == 2) {
      const double s = 1.2;
      pts = {{{s, s, 0}, -1}, {{-s, s, 0}, -1}, {{-s, -s, 0}, -1}, {{s, -s, 0}, -1}};
    } else {
      // Upper or lower half: the side of the diameter its arc lies on.
      double y = 0;
      for (const auto& use : face.loops[0].uses)
        for (const auto& p : c.curves[use.curve].points) y += p.y;
      const double side = y > 0 ? 1.0 : -1.0;
      pts = {{{0.45, 0.4 * side, 0}, 1}, {{-0.45, 0.4 * side, 0}, 1}};
    }
    const FaceRun r = run_points(c, f, 0.1, pts);
    expect_valid(r);
    expect_irregular_at(r, pts, 1e-9);
    // Every vertex of the face's curve meshes is a vertex of its quads.
    std::size_t curve_vertices = 0, boundary = 0;
    for (const auto& loop : face.loops)
      for (const auto& use : loop.uses) curve_vertices += c.curves[use.curve].points.size() - 1;
    std::vector<int> used(r.quads.points.size(), 0);
    for (const auto& q : r.quads.quads)
      for (LO v : q) used[v] = 1;
    for (std::size_t v = 0; v < used.size(); ++v) boundary += used[v] && r.quads.vclass[v].dim != 2;
    EXPECT_EQ(boundary, curve_vertices);
    meshed += r.report.ok;
  }
  EXPECT_EQ(meshed, 3);
}

TEST(FieldMesh, CylinderPatchWithTheHeatMethodFrame) {
  // Sec. 4: on a quarter cylinder the angles are measured from the heat-method frame; a field at
  // a constant 0.4 rad from it is not aligned with the boundary and Eq. 14 aligns it.
  const Case c = make_case(write_cylinder_patch(1.0, 1.5), 0.1);
  ASSERT_EQ(c.model.num_faces(), 1);
  FaceRun r;
  r.tri = triangulate(c, 0, 0.05);
  const auto surface = c.model.face_geometry(0);
  r.frame = fieldmesh::face_frame(r.tri, *surface, nullptr);
  for (std::size_t v = 0; v < r.frame.ref.size(); ++v) {
    EXPECT_NEAR(norm(r.frame.ref[v]), 1.0, 1e-9);
    EXPECT_NEAR(dot(r.frame.ref[v], r.frame.normal[v]), 0.0, 1e-9);
  }
  const std::vector<double> theta(r.tri.points.size(), 0.4);
  r.quads = fieldmesh::mesh_face_from_field(c.model, 0, c.curves, r.tri, r.frame, theta, {}, {},
                                            nullptr, &r.report);
  expect_valid(r);
  EXPECT_EQ(r.report.regions, 1);
  EXPECT_TRUE(irregular(r.quads).empty());
  EXPECT_GT(r.report.stats.sicn_min, 0.9);
}

TEST(FieldMesh, HeatMethodFrameOnASliverTriangle) {
  // Two triangles of the cylinder patch, ABC and ACD, with B 5e-5 radians off the straight
  // segment AC (along the axis): the sliver ABC has cotangents of about +-1e4, clamped at +-1e3
  // each, and gives the edge AC a weight of -500 that ACD (a right angle at D) does not offset.
  // With t = diagonal^2 the heat system was then indefinite ('not positive definite', A319's
  // faces 1, 3 and 50). Summed per edge and clamped at 0, the weights keep it definite.
  const Case c = make_case(write_cylinder_patch(1.0, 1.5), 0.1);
  const auto surface = c.model.face_geometry(0);
  mesh::FaceMesh tri;
  tri.face = 0;
  for (const Vec2 uv : {Vec2{0.7, 0.2}, Vec2{0.70005, 0.7}, Vec2{0.7, 1.2}, Vec2{0.2, 0.7}}) {
    tri.uv.push_back(uv);
    tri.points.push_back(surface->eval(uv).p);
    mesh::VertexClass vc;
    vc.dim = 2;
    vc.entity = 0;
    tri.vclass.push_back(vc);
  }
  // A = 0, B = 1, C = 2, D = 3; counter-clockwise in the parameter plane.
  tri.triangles = {{0, 1, 2}, {0, 2, 3}};
  const fieldmesh::Frame frame = fieldmesh::face_frame(tri, *surface, nullptr);
  for (std::size_t v = 0; v < frame.ref.size(); ++v) {
    EXPECT_NEAR(norm(frame.ref[v]), 1.0, 1e-9);
    EXPECT_NEAR(dot(frame.ref[v], frame.normal[v]), 0.0, 1e-9);
  }
}

TEST(FieldMesh, CylinderPatchWithAValence3And5PairOfEq2) {
  // A valence-3 / valence-5 pair along the circumference: as on the plane, the straight side near
  // the valence-3 point must hold more edges than the other one; with the top cut aslant the two
  // sides differ (1.65 and 1.35 long, left out of one chord). With equal counts no quantization
  // exists and the face is refused at that stage.
  auto on = [&](double angle, double z) { return Vec3{std::cos(angle), std::sin(angle), z}; };
  const std::vector<fieldmesh::SingularPoint> pts{{on(0.6, 0.75), 1}, {on(0.95, 0.75), -1}};
  const Case c = make_case(write_slanted_cylinder_patch(), 0.1, 1.0);
  ASSERT_EQ(c.model.num_faces(), 1);
  const FaceRun r = run_points(c, 0, 0.05, pts);
  expect_valid(r);
  expect_irregular_at(r, pts, 1e-6);

  const Case equal = make_case(write_cylinder_patch(1.0, 1.5), 0.1);
  const FaceRun refused = run_points(equal, 0, 0.05, pts);
  EXPECT_FALSE(refused.report.ok);
  EXPECT_EQ(refused.report.stage, "quantization") << refused.report.reason;
  EXPECT_TRUE(refused.quads.quads.empty());
}

}  // namespace
}  // namespace qsmesh
