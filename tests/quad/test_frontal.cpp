// Frontal point insertion guided by the cross field (paper 000 Sec. 5.1) and the unstructured
// quad stage built on it (Sec. 5.2).
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepLib.hxx>
#include <BRepTools.hxx>
#include <Geom2d_BezierCurve.hxx>
#include <Geom2d_Line.hxx>
#include <Geom_ToroidalSurface.hxx>
#include <TColgp_Array1OfPnt2d.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Wire.hxx>
#include <cmath>
#include <cstdio>
#include <gp_Ax2.hxx>
#include <gp_Ax3.hxx>
#include <gp_Circ.hxx>
#include <gp_Dir2d.hxx>
#include <gp_Pnt.hxx>
#include <gp_Pnt2d.hxx>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "load_shape.hpp"
#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/quad/frontal.hpp"
#include "qsmesh/quad/unstructured.hpp"
#include "qsmesh/quantize/quantize.hpp"
#include "quantized_curves.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::quad {
namespace {

cad::CadModel rectangle(double w, double h) {
  BRepBuilderAPI_MakePolygon poly;
  for (const auto& [x, y] : std::vector<std::pair<double, double>>{{0, 0}, {w, 0}, {w, h}, {0, h}})
    poly.Add(gp_Pnt(x, y, 0));
  poly.Close();
  BRepBuilderAPI_MakeFace face(poly.Wire(), /*OnlyPlane=*/true);
  if (!face.IsDone()) throw std::runtime_error("face construction failed");
  return test::load_shape(face.Shape(), "fr_rect.brep");
}

cad::CadModel disk(double r) {
  const gp_Circ c(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), r);
  const TopoDS_Wire w = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(c).Edge()).Wire();
  return test::load_shape(BRepBuilderAPI_MakeFace(w).Face(), "fr_disk.brep");
}

// A strip of a torus (major radius 12, minor 0.5) over half a turn of u and a quarter turn of v,
// as a fillet along a round edge: about 0.8 wide and 38 long, 24 times finer across than along in
// (u, v). Its top side bulges out of the strip by 1% of the width in the parameter plane, as the
// approximated pcurves of such fillets do (Block.stp's face 82), so that three consecutive
// vertices of it make a strictly convex, nearly flat triangle there.
cad::CadModel thin_torus_fillet() {
  const double pi = std::numbers::pi;
  const Handle(Geom_ToroidalSurface) s =
      new Geom_ToroidalSurface(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 12, 0.5);
  TColgp_Array1OfPnt2d top(1, 3);
  top(1) = gp_Pnt2d(pi, pi / 2);
  top(2) = gp_Pnt2d(pi / 2, pi / 2 + 0.03);
  top(3) = gp_Pnt2d(0, pi / 2);
  const Handle(Geom2d_Curve)
      pcurves[4] = {new Geom2d_Line(gp_Pnt2d(0, 0), gp_Dir2d(1, 0)),
                    new Geom2d_Line(gp_Pnt2d(pi, 0), gp_Dir2d(0, 1)), new Geom2d_BezierCurve(top),
                    new Geom2d_Line(gp_Pnt2d(0, pi / 2), gp_Dir2d(0, -1))};
  const double ranges[4][2] = {{0, pi}, {0, pi / 2}, {0, 1}, {0, pi / 2}};
  BRepBuilderAPI_MakeWire wire;
  for (int k = 0; k < 4; ++k) {
    TopoDS_Edge e = BRepBuilderAPI_MakeEdge(pcurves[k], s, ranges[k][0], ranges[k][1]).Edge();
    BRepLib::BuildCurves3d(e);
    wire.Add(e);
  }
  if (!wire.IsDone()) throw std::runtime_error("wire construction failed");
  BRepBuilderAPI_MakeFace face(s, wire.Wire(), true);
  if (!face.IsDone()) throw std::runtime_error("face construction failed");
  return test::load_shape(face.Shape(), "fr_thin_torus_fillet.brep");
}

// What the pipeline hands the quad stage for face 0 with a uniform size map `size`: the curve
// meshes at the final size (full) and at twice it (halved), the background mesh and its cross
// field.
struct Prepared {
  std::vector<mesh::CurveMesh> full, halved;
  mesh::FaceMesh background;
  crossfield::FaceCrossField cf;
  std::vector<double> sizes;
};

Prepared prepare(const cad::CadModel& model, double size) {
  const qsmesh::test::QuantizedCurves curves = qsmesh::test::quantized_curves(model, size);
  Prepared p;
  p.full = curves.full;
  p.halved = curves.halved;
  background::BackgroundOptions options;
  options.sizes.size = size;
  background::FaceReport report;
  p.background = background::mesh_face_background(model, 0, curves.background, options, &report);
  EXPECT_TRUE(report.ok) << report.error;
  p.cf = crossfield::compute_face_cross_field(p.background, {}, nullptr);
  p.sizes.assign(p.background.points.size(), size);
  return p;
}

// Interior vertices (dim 2) whose number of quads is not 4.
std::vector<LO> irregular_interior(const mesh::FaceMesh& m) {
  std::vector<int> valence(m.points.size(), 0);
  for (const auto& q : m.quads)
    for (LO v : q) ++valence[v];
  std::vector<LO> out;
  for (LO v = 0; v < m.num_vertices(); ++v)
    if (m.vclass[v].dim == 2 && valence[v] != 4) out.push_back(v);
  return out;
}

double sicn_min(const mesh::FaceMesh& m) {
  double worst = 1;
  for (const auto& q : m.quads)
    worst = std::min(
        worst, mesh::quad_sicn({m.points[q[0]], m.points[q[1]], m.points[q[2]], m.points[q[3]]}));
  return worst;
}

mesh::FaceMesh run_face(const cad::CadModel& model, const Prepared& p, UnstructuredReport& rep) {
  FaceFields fields{&p.background, &p.cf, p.sizes};
  UnstructuredOptions options;
  options.size = p.sizes.front();
  return mesh_face_unstructured(model, 0, p.full, fields, options, &rep);
}

// What frontal_points needs on a disk of radius 3 with a uniform size map `size`. Not copyable:
// the guide refers to the prepared fields.
struct DiskFront {
  explicit DiskFront(double size)
      : model(disk(3)),
        p(prepare(model, size)),
        guide(p.background, p.cf, p.sizes),
        surface(model.face_geometry(0)),
        loops(background::face_boundary(model, 0, *surface, p.halved)) {}
  DiskFront(const DiskFront&) = delete;
  DiskFront& operator=(const DiskFront&) = delete;
  [[nodiscard]] std::vector<Vec2> points(const FrontalOptions& options,
                                         FrontalStats* stats = nullptr) const {
    return frontal_points(*surface, loops, guide, options, stats);
  }
  /// The boundary points, then those of `pts` on the surface.
  [[nodiscard]] std::vector<Vec3> with_boundary(const std::vector<Vec2>& pts) const {
    std::vector<Vec3> all;
    for (const auto& L : loops)
      for (const auto& b : L.points) all.push_back(b.xyz);
    for (const Vec2& uv : pts) all.push_back(surface->eval(uv).p);
    return all;
  }
  cad::CadModel model;
  Prepared p;
  FaceGuide guide;
  std::unique_ptr<cad::FaceGeometry> surface;
  std::vector<mesh::BoundaryLoop> loops;
};

TEST(FaceGuide, InterpolatesTheSizeAndFindsTheCross) {
  const auto model = rectangle(4, 3);
  Prepared p = prepare(model, 0.5);
  // A size growing with x: the guide must return the linear interpolant exactly on a plane.
  for (LO v = 0; v < p.background.num_vertices(); ++v)
    p.sizes[v] = 0.2 + 0.1 * p.background.points[v].x;
  const FaceGuide guide(p.background, p.cf, p.sizes);
  const auto surface = model.face_geometry(0);
  for (std::size_t t = 0; t < p.background.triangles.size(); t += 7) {
    const auto& T = p.background.triangles[t];
    const Vec2 uv =
        (p.background.uv[T[0]] * 0.2 + p.background.uv[T[1]] * 0.3 + p.background.uv[T[2]] * 0.5);
    const Vec3 x = surface->eval(uv).p;
    const FaceGuide::Sample s = guide.at(uv);
    EXPECT_TRUE(s.found);
    EXPECT_NEAR(s.size, 0.2 + 0.1 * x.x, 1e-9);
    // Axis-aligned cross on a rectangle.
    for (const Vec3& d : s.cross) EXPECT_GT(std::max(std::abs(d.x), std::abs(d.y)), 0.999);
  }
  Box2 box;
  for (const Vec2& uv : p.background.uv) box.add(uv);
  EXPECT_FALSE(guide.at(box.hi + Vec2{1, 1}).found);
  const auto [lo, hi] = guide.size_range();
  EXPECT_NEAR(lo, 0.2, 1e-9);
  EXPECT_NEAR(hi, 0.6, 1e-9);
}

TEST(Frontal, PointsRespectTheMinimumSpacingAndAreDeterministic) {
  const DiskFront f(0.4);
  FrontalOptions options;
  FrontalStats stats;
  const std::vector<Vec2> pts = f.points(options, &stats);
  ASSERT_GT(pts.size(), 20U);
  EXPECT_EQ(stats.accepted, static_cast<std::int64_t>(pts.size()));
  EXPECT_GT(stats.too_close, 0);
  const std::vector<Vec3> all = f.with_boundary(pts);
  const std::size_t nb = all.size() - pts.size();
  for (const Vec2& uv : pts) EXPECT_LT(uv.u * uv.u + uv.v * uv.v, 9.0) << "point outside the disk";
  const double spacing = options.spacing_factor * 0.4;
  double closest = 1e300;
  for (std::size_t i = nb; i < all.size(); ++i)
    for (std::size_t j = 0; j < i; ++j) closest = std::min(closest, distance(all[i], all[j]));
  EXPECT_GE(closest, options.min_distance * spacing * (1 - 1e-9));
  // The disk is covered: about area / spacing^2 points.
  const double expected = 3.14159 * 9 / (spacing * spacing);
  EXPECT_GT(static_cast<double>(pts.size() + nb), 0.7 * expected);
  EXPECT_EQ(pts, f.points(options));
}

// Points of `pts` (frontal points of `f`) whose nearest other point (boundary points included)
// is closer than 0.8 x spacing along a diagonal of the cross there (30 to 60 degrees from both
// branches): where two fronts offset by half a spacing interleave into a lattice turned by 45
// degrees.
int diagonal_neighbours(const DiskFront& f, const std::vector<Vec2>& pts, double spacing) {
  const std::vector<Vec3> all = f.with_boundary(pts);
  const std::size_t nb = all.size() - pts.size();
  int diagonal = 0;
  for (std::size_t i = nb; i < all.size(); ++i) {
    std::size_t best = i;
    double d_best = 1e300;
    for (std::size_t j = 0; j < all.size(); ++j) {
      const double d = j != i ? distance(all[i], all[j]) : d_best;
      if (d < d_best) d_best = d, best = j;
    }
    if (d_best >= 0.8 * spacing) continue;
    const Vec3 d = (all[best] - all[i]) / d_best;
    const auto cross = f.guide.at(pts[i - nb]).cross;
    const double c0 = std::abs(dot(d, normalized(cross[0])));
    const double c1 = std::abs(dot(d, normalized(cross[1])));
    if (c0 > 0.5 && c0 < 0.866 && c1 > 0.5 && c1 < 0.866) ++diagonal;
  }
  return diagonal;
}

TEST(Frontal, FrontsDoNotInterleaveAcrossTheCross) {
  // On a disk the fronts from the circle meet in the middle with every offset. With a disk-shaped
  // exclusion zone of radius 0.5 spacing a point half a spacing off diagonally passes (0.71), and
  // interleaved fronts form patches of a lattice turned by 45 degrees; the square zone along the
  // cross rejects it.
  const DiskFront f(0.2);
  FrontalOptions square;
  ASSERT_TRUE(square.cross_aligned_exclusion);
  FrontalOptions round = square;
  round.cross_aligned_exclusion = false;
  const double spacing = square.spacing_factor * 0.2;
  const std::vector<Vec2> a = f.points(square);
  const std::vector<Vec2> b = f.points(round);
  const int da = diagonal_neighbours(f, a, spacing);
  const int db = diagonal_neighbours(f, b, spacing);
  std::printf("points %zu / %zu, with a diagonal nearest neighbour: square %d, disk %d\n", a.size(),
              b.size(), da, db);
  EXPECT_LT(da, static_cast<int>(a.size()) / 12);  // near the singularities some are natural
  EXPECT_GT(db, 3 * da);
}

TEST(Unstructured, RectangleWithAxisAlignedFieldGivesARegularGrid) {
  const auto model = rectangle(6, 4);
  const Prepared p = prepare(model, 0.25);
  UnstructuredReport rep;
  const mesh::FaceMesh m = run_face(model, p, rep);
  EXPECT_TRUE(rep.ok) << rep.error;
  EXPECT_TRUE(rep.frontal) << rep.error;
  EXPECT_FALSE(rep.fell_back);
  EXPECT_TRUE(m.triangles.empty());
  const auto irr = irregular_interior(m);
  std::printf("[frontal] rectangle: %zu quads, %zu irregular interior vertices, SICN min %.3f\n",
              m.quads.size(), irr.size(), sicn_min(m));
  EXPECT_EQ(irr.size(), 0U);
  EXPECT_GT(sicn_min(m), 0.9);
  EXPECT_NEAR(static_cast<double>(m.quads.size()), 24.0 * 16.0, 1.0);
}

TEST(Unstructured, DiskHasIrregularVerticesAtTheSingularitiesAndFewerThanWithoutTheField) {
  const auto model = disk(3);
  const double size = 0.15;
  const Prepared p = prepare(model, size);
  UnstructuredReport rep;
  const mesh::FaceMesh m = run_face(model, p, rep);
  EXPECT_TRUE(rep.ok) << rep.error;
  EXPECT_TRUE(rep.frontal) << rep.error;
  const auto irr = irregular_interior(m);
  std::size_t near = 0;
  for (LO v : irr) {
    double d = 1e300;
    for (const auto& s : p.cf.singularities) d = std::min(d, distance(s.position, m.points[v]));
    near += d < 4 * 2 * size ? 1 : 0;
  }
  std::printf(
      "[frontal] disk: %zu quads, %zu irregular interior vertices (%zu near the %zu "
      "singularities), "
      "SICN min %.3f\n",
      m.quads.size(), irr.size(), near, p.cf.singularities.size(), sicn_min(m));
  EXPECT_EQ(p.cf.singularities.size(), 4U);
  // Every singularity of the field shows up as an irregular vertex nearby (the others come from
  // fronts meeting).
  for (const auto& sing : p.cf.singularities) {
    double d = 1e300;
    for (LO v : irr) d = std::min(d, distance(sing.position, m.points[v]));
    EXPECT_LT(d, 4 * 2 * size) << "no irregular vertex near a singularity";
  }
  EXPECT_GT(sicn_min(m), 0.3);
  // Against the same face meshed without the cross field (Delaunay refinement at uniform size,
  // recombination without alignment): fewer irregular vertices.
  UnstructuredOptions options;
  options.size = size;
  UnstructuredReport plain_rep;
  const mesh::FaceMesh plain =
      mesh_face_unstructured(model, 0, p.full, FaceFields{}, options, &plain_rep);
  const auto plain_irr = irregular_interior(plain);
  std::printf("[frontal] disk without cross field: %zu quads, %zu irregular interior vertices\n",
              plain.quads.size(), plain_irr.size());
  EXPECT_LT(static_cast<double>(irr.size()), 0.8 * static_cast<double>(plain_irr.size()));
}

// A strip narrower than the spacing holds no frontal point, and in (u, v) it is 24 times wider
// than in 3D: the kind of face where flat triangles along a curve made Block.stp's face 82 fall
// back to the uniform path at size factor 0.008 (this analytic fillet does not get them; the
// kernel-level tests cover the scaled triangulation). The frontal path holds at four sizes.
// The pipeline keeps only the crosses of a field once the size map is built
// (crossfield::shrink_cross_field): the frontal path must read nothing else.
TEST(Unstructured, CrossFieldShrunkToTheGuideGivesTheSameMesh) {
  const auto model = disk(3);
  const Prepared whole = prepare(model, 0.4);
  Prepared shrunk = whole;
  crossfield::shrink_cross_field(shrunk.cf, crossfield::CrossFieldUse::Guide);
  EXPECT_TRUE(shrunk.cf.points.empty() && shrunk.cf.edges.empty() && shrunk.cf.u.empty() &&
              shrunk.cf.H.empty() && shrunk.cf.tri2edges.empty());
  EXPECT_EQ(shrunk.cf.directions.size(), whole.cf.directions.size());
  EXPECT_EQ(shrunk.cf.singularities.size(), whole.cf.singularities.size());
  UnstructuredReport a, b;
  const mesh::FaceMesh from_whole = run_face(model, whole, a);
  const mesh::FaceMesh from_shrunk = run_face(model, shrunk, b);
  EXPECT_TRUE(a.frontal && b.frontal);
  EXPECT_GT(from_whole.quads.size(), 50u);
  EXPECT_EQ(from_whole.quads, from_shrunk.quads);
  EXPECT_EQ(from_whole.points, from_shrunk.points);

  // The size map's part stays with SizeMapAndGuide.
  Prepared sizing = whole;
  crossfield::shrink_cross_field(sizing.cf, crossfield::CrossFieldUse::SizeMapAndGuide);
  EXPECT_EQ(sizing.cf.points.size(), whole.cf.points.size());
  EXPECT_EQ(sizing.cf.edges.size(), whole.cf.edges.size());
  EXPECT_EQ(sizing.cf.H, whole.cf.H);
  EXPECT_TRUE(sizing.cf.u.empty() && sizing.cf.u_norm.empty() && sizing.cf.tri2edges.empty());
}

TEST(Unstructured, ThinTorusFilletKeepsTheFrontalPath) {
  const auto model = thin_torus_fillet();
  for (const double size : {0.5, 0.65, 0.8, 1.0}) {
    const Prepared p = prepare(model, size);
    UnstructuredReport rep;
    const mesh::FaceMesh m = run_face(model, p, rep);
    EXPECT_TRUE(rep.ok) << "size " << size << ": " << rep.error;
    EXPECT_TRUE(rep.frontal) << "size " << size << ": " << rep.error;
    EXPECT_FALSE(rep.fell_back) << "size " << size;
    EXPECT_GT(sicn_min(m), 0.1) << "size " << size;
  }
}

TEST(Unstructured, WithoutCrossFieldFallsBackToTheUniformPath) {
  const auto model = rectangle(3, 2);
  const Prepared p = prepare(model, 0.25);
  UnstructuredOptions options;
  options.size = 0.25;
  UnstructuredReport rep;
  const mesh::FaceMesh m = mesh_face_unstructured(model, 0, p.full, FaceFields{}, options, &rep);
  EXPECT_TRUE(rep.ok) << rep.error;
  EXPECT_FALSE(rep.frontal);
  EXPECT_TRUE(rep.fell_back);
  EXPECT_GT(m.quads.size(), 0U);
}

}  // namespace
}  // namespace qsmesh::quad
