// Size map (paper 000 Sec. 4.1, 4.2) on OpenCASCADE-built models.
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepTools.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Wire.hxx>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <gp_Circ.hxx>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <utility>
#include <vector>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/sizemap/size_map.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::sizemap {
namespace {

std::string tmp(const std::string& name) { return qsmesh::test::tmp_dir() + "/" + name; }

cad::CadModel load_shape(const TopoDS_Shape& s, const std::string& name) {
  const std::string path = tmp(name);
  if (!BRepTools::Write(s, path.c_str())) throw std::runtime_error("cannot write " + path);
  return cad::load_cad(path);
}

/// A planar face bounded by the polygon through `xy` (z = 0).
cad::CadModel polygon_face(const std::vector<std::pair<double, double>>& xy,
                           const std::string& name) {
  return cad::load_cad(test::write_polygon_face(xy, tmp(name)));
}

/// 10 x 10 plate with a slot 0.2 wide and 6 deep cut in from the top edge (x in [4.9, 5.1]).
cad::CadModel slot_plate() {
  return polygon_face(
      {{0, 0}, {10, 0}, {10, 10}, {5.1, 10}, {5.1, 4}, {4.9, 4}, {4.9, 10}, {0, 10}},
      "slot_plate.brep");
}

cad::CadModel disk(double r) {
  const gp_Circ c(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), r);
  const TopoDS_Wire w = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(c).Edge()).Wire();
  const TopoDS_Shape face = BRepBuilderAPI_MakeFace(w, true).Face();
  return load_shape(face, "disk.brep");
}

/// Background curve and face meshes (and cross fields) of a whole model.
struct Model {
  cad::CadModel cad;
  std::vector<mesh::CurveMesh> curves;
  std::vector<mesh::FaceMesh> faces;
  std::vector<crossfield::FaceCrossField> cf;
};
Model prepare(cad::CadModel cad, double size, bool with_cross_field) {
  Model m;
  m.cad = std::move(cad);
  background::BackgroundOptions options;
  options.sizes.size = size;
  const TaskArena tasks(1);
  m.curves = background::mesh_curves(m.cad, options.sizes, tasks);
  for (LO f = 0; f < m.cad.num_faces(); ++f) {
    background::FaceReport report;
    m.faces.push_back(background::mesh_face_background(m.cad, f, m.curves, options, &report));
    EXPECT_TRUE(report.ok) << report.error;
    if (with_cross_field)
      m.cf.push_back(crossfield::compute_face_cross_field(m.faces.back(), {}, nullptr));
  }
  return m;
}

/// Largest violation of Eq. 10 over the edges of a face mesh: max(|s1 - s2| - g d).
double gradation_excess(const mesh::FaceMesh& fm, const std::vector<double>& s, double g) {
  double worst = -std::numeric_limits<double>::infinity();
  for (const auto& t : fm.triangles)
    for (int k = 0; k < 3; ++k) {
      const LO a = t[k], b = t[(k + 1) % 3];
      worst = std::max(worst, std::abs(s[a] - s[b]) - g * distance(fm.points[a], fm.points[b]));
    }
  return worst;
}

double curve_gradation_excess(const Model& m, const CurveSizes& cs, double g) {
  double worst = -std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < m.curves.size(); ++c)
    for (std::size_t i = 0; i + 1 < cs.at[c].size(); ++i)
      worst = std::max(worst, std::abs(cs.at[c][i] - cs.at[c][i + 1]) -
                                  g * distance(m.curves[c].points[i], m.curves[c].points[i + 1]));
  return worst;
}

const crossfield::FaceCrossField* cf_of(const Model& m, LO f) {
  return m.cf.empty() ? nullptr : &m.cf[f];
}

/// The whole union flow of Sec. 4.2 as the distributed pipeline runs it, with the faces split
/// over `parts` simulated ranks (face f on rank f % parts): returns the final curve sizes and the
/// second-pass face fields.
std::pair<CurveSizes, std::vector<FaceSizes>> full_flow(const Model& m, const SizeMapOptions& o,
                                                        int parts) {
  const TaskArena tasks(2);
  const CurveSizes initial = initial_curve_sizes(m.cad, m.curves, o, tasks);
  const auto n = face_quad_targets(m.cad, o);
  std::vector<std::vector<double>> contributions;
  for (int r = 0; r < parts; ++r) {
    CurveSizes part = initial;
    for (LO f = r; f < m.cad.num_faces(); f += parts)
      fold_boundary_min(m.faces[f],
                        face_sizes(m.faces[f], cf_of(m, f), m.curves, initial, n[f], o).s, part);
    contributions.push_back(part.pack());
  }
  std::vector<double> reduced = contributions[0];
  for (const auto& c : contributions)
    for (std::size_t i = 0; i < c.size(); ++i) reduced[i] = std::min(reduced[i], c[i]);
  CurveSizes sizes = initial;
  sizes.unpack(reduced);
  grade_curves(m.cad, m.curves, o.gradation, sizes);
  std::vector<FaceSizes> final_fields;
  final_fields.reserve(static_cast<std::size_t>(m.cad.num_faces()));
  for (LO f = 0; f < m.cad.num_faces(); ++f)
    final_fields.push_back(face_sizes(m.faces[f], cf_of(m, f), m.curves, sizes, n[f], o));
  return {std::move(sizes), std::move(final_fields)};
}

TEST(SizeMap, NarrowSlotGetsSmallSizesAndGradesOut) {
  const Model m = prepare(slot_plate(), 1.0, true);
  for (const Method method : {Method::Features, Method::CrossField}) {
    SizeMapOptions o;
    o.method = method;
    o.size_max = 1.0;
    o.feature_ratio = 0;  // every feature resolved, as Sec. 4.1 reads
    const TaskArena tasks(2);
    const CurveSizes cs = initial_curve_sizes(m.cad, m.curves, o, tasks);
    const auto n = face_quad_targets(m.cad, o);
    const FaceSizes fs = face_sizes(m.faces[0], cf_of(m, 0), m.curves, cs, n[0], o);
    const auto& fm = m.faces[0];
    double slot_max = 0, slot_min = 1e300, far_max = 0;
    for (LO v = 0; v < fm.num_vertices(); ++v) {
      const Vec3& p = fm.points[v];
      if (p.x >= 4.9 - 1e-9 && p.x <= 5.1 + 1e-9 && p.y >= 4.5) {  // on the slot's sides
        slot_max = std::max(slot_max, fs.s[v]);
        slot_min = std::min(slot_min, fs.s[v]);
      }
      if (std::abs(p.x - 5) > 4 || p.y < 0.5) far_max = std::max(far_max, fs.s[v]);
    }
    const double excess = gradation_excess(fm, fs.s, o.gradation);
    std::printf(
        "[sizemap] slot (%s): slot sizes [%.4f, %.4f], far max %.3f, gradation excess %.2e, "
        "curve gradation excess %.2e\n",
        method == Method::Features ? "features" : "crossfield", slot_min, slot_max, far_max, excess,
        curve_gradation_excess(m, cs, o.gradation));
    EXPECT_LE(slot_max, 0.2 + 1e-9);
    EXPECT_GE(slot_min, 0.15);
    EXPECT_GT(far_max, 0.8);  // grades out, not uniformly small
    EXPECT_LE(excess, 1e-9);
    EXPECT_LE(gradation_excess(fm, fs.s_min, o.gradation), 1e-9);
    EXPECT_LE(curve_gradation_excess(m, cs, o.gradation), 1e-9);
    // Sizes on curves never exceed the curve's length.
    for (LO c = 0; c < m.cad.num_curves(); ++c)
      for (double s : cs.at[c]) EXPECT_LE(s, m.cad.curves()[c].length + 1e-12) << "curve " << c;
    for (LO v = 0; v < fm.num_vertices(); ++v) {
      EXPECT_LE(fs.s[v], o.size_max);
      EXPECT_GE(fs.s[v], o.size_max / 100);
      if (fm.vclass[v].dim == 1) {
        EXPECT_LE(fs.s[v], m.cad.curves()[fm.vclass[v].entity].length + 1e-12);
      }
    }
  }
}

TEST(SizeMap, FeatureRatioBoundsHowFarTheSlotRefinesItsSides) {
  // The slot's sides are 0.2 apart: rule (ii) asks for 0.2 there, the ratio keeps at least
  // ratio x 1 (the size without the rule). Near the slot's bottom (0.2 long, rule (i)) the sides
  // grade up from 0.2 whatever the ratio, so only their upper part is looked at.
  const Model m = prepare(slot_plate(), 1.0, false);
  SizeMapOptions o;
  o.method = Method::Features;
  o.size_max = 1.0;
  for (const double ratio : {0.0, 0.5, 1.0}) {
    o.feature_ratio = ratio;
    const CurveSizes cs = initial_curve_sizes(m.cad, m.curves, o, TaskArena(2));
    int seen = 0;
    for (LO c = 0; c < m.cad.num_curves(); ++c)
      for (std::size_t i = 0; i < cs.at[c].size(); ++i) {
        const Vec3& p = m.curves[c].points[i];
        const bool side = std::abs(p.x - 4.9) < 1e-9 || std::abs(p.x - 5.1) < 1e-9;
        if (!side || p.y < 8.0 || p.y > 9.5) continue;
        ++seen;
        EXPECT_NEAR(cs.at[c][i], std::max(0.2, ratio), 1e-6) << "ratio " << ratio << " y " << p.y;
      }
    EXPECT_GT(seen, 2);
    EXPECT_LE(curve_gradation_excess(m, cs, o.gradation), 1e-9);
  }
  o.feature_ratio = 1.5;
  EXPECT_THROW((void)initial_curve_sizes(m.cad, m.curves, o, TaskArena(1)), InputError);
}

TEST(SizeMap, OneEdgeSliverCornersAreTenTimesItsLength) {
  // The square of GivenFloorStopsSliverCurvesFromRefining: its sliver (0.005) is below a tenth of
  // the floor (0.2), so with one_edge_slivers it takes one edge and its corners are at most
  // 10 x its length (twice rule (i')'s 5 x for two edges: the same edge-to-neighbour ratio).
  const Model m = prepare(
      polygon_face({{0, 0}, {10, 0}, {10, 10}, {0.003, 10}, {0, 9.996}}, "sliver_one_edge.brep"),
      1.0, false);
  LO sliver = kNoIndex;
  for (LO c = 0; c < m.cad.num_curves(); ++c)
    if (m.cad.curves()[c].length < 0.1) sliver = c;
  ASSERT_NE(sliver, kNoIndex);
  const double length = m.cad.curves()[sliver].length;
  SizeMapOptions o;
  o.method = Method::Features;
  o.size_max = 1.0;
  o.size_min = 0.2;
  EXPECT_EQ(sliver_length(o), 0.0);  // off
  o.one_edge_slivers = true;
  EXPECT_NEAR(sliver_length(o), 0.02, 1e-15);
  const CurveSizes cs = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  for (const LO k : m.cad.curves()[sliver].corners) EXPECT_NEAR(cs.corner[k], 10 * length, 1e-12);
  EXPECT_LE(curve_gradation_excess(m, cs, o.gradation), 1e-9);
  // A curve above a tenth of the floor is no one-edge sliver: rule (i') as before (5 x).
  o.size_min = 0.04;
  EXPECT_GT(length, sliver_length(o));
  const CurveSizes two = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  for (const LO k : m.cad.curves()[sliver].corners) EXPECT_NEAR(two.corner[k], 5 * length, 1e-12);
}

TEST(SizeMap, GivenFloorStopsSliverCurvesFromRefining) {
  // A 10 x 10 square with one corner cut by a sliver edge 0.005 long. Rule (i) sizes the sliver
  // by its length, below the default floor (size cap / 100); a floor the user gives holds there
  // too, and everywhere else but around the sliver's corners, which rule (i') sets at 5 x its
  // length (the quantization gives the sliver 2 edges whatever its size, and the sizes grade
  // toward them instead of dropping from the floor in one row).
  const Model m = prepare(
      polygon_face({{0, 0}, {10, 0}, {10, 10}, {0.003, 10}, {0, 9.996}}, "sliver_corner.brep"), 1.0,
      false);
  LO sliver = kNoIndex;
  for (LO c = 0; c < m.cad.num_curves(); ++c)
    if (m.cad.curves()[c].length < 0.1) sliver = c;
  ASSERT_NE(sliver, kNoIndex);
  const double length = m.cad.curves()[sliver].length;
  SizeMapOptions o;
  o.method = Method::Features;
  o.size_max = 1.0;
  EXPECT_LT(length, effective_size_min(o));
  const CurveSizes paper = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  for (const double s : paper.at[sliver]) EXPECT_LE(s, length + 1e-12);
  o.size_min = 0.2;
  const CurveSizes floored = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  // No size below the floor or below the growth from the sliver's corners, whichever is less.
  const auto& ends = m.cad.curves()[sliver].corners;
  auto lower_bound = [&](const Vec3& p) {
    double d = std::numeric_limits<double>::infinity();
    for (const LO k : ends) d = std::min(d, distance(p, m.cad.corners()[k].point));
    return std::min(0.2, 5 * length + o.gradation * d);
  };
  int below_floor = 0;
  for (LO c = 0; c < m.cad.num_curves(); ++c)
    for (std::size_t i = 0; i < floored.at[c].size(); ++i) {
      EXPECT_GE(floored.at[c][i], lower_bound(m.curves[c].points[i]) * (1 - 1e-12))
          << "curve " << c;
      below_floor += floored.at[c][i] < 0.2 - 1e-12 ? 1 : 0;
    }
  EXPECT_GT(below_floor, 0);  // the sliver's neighbourhood is graded
  for (LO k = 0; k < m.cad.num_corners(); ++k) {
    const bool end = k == ends[0] || k == ends[1];
    if (end)
      EXPECT_NEAR(floored.corner[k], 5 * length, 1e-12);
    else
      EXPECT_GE(floored.corner[k], 0.2 - 1e-12);
  }
  EXPECT_LE(curve_gradation_excess(m, floored, o.gradation), 1e-9);
  // A user size below the floor still wins (the floor drops to it).
  o.curve_sizes = {{sliver, 0.05}};
  const CurveSizes user = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  for (const double s : user.at[sliver]) EXPECT_LE(s, 0.05 + 1e-12);
}

TEST(SizeMap, SlotWithWrongGradationFailsTheBound) {
  // The check above can fail: a field graded at 0.5 violates the 0.2 bound somewhere.
  const Model m = prepare(slot_plate(), 1.0, false);
  SizeMapOptions o;
  o.method = Method::Features;
  o.size_max = 1.0;
  o.gradation = 0.5;
  const CurveSizes cs = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  const FaceSizes fs = face_sizes(m.faces[0], nullptr, m.curves, cs, 0, o);
  EXPECT_GT(gradation_excess(m.faces[0], fs.s, 0.2), 1e-3);
  EXPECT_LE(gradation_excess(m.faces[0], fs.s, 0.5), 1e-9);
}

TEST(SizeMap, UserCornerAndCurveSizesAreHonoured) {
  const Model m =
      prepare(polygon_face({{0, 0}, {10, 0}, {10, 10}, {0, 10}}, "square.brep"), 1.0, false);
  SizeMapOptions o;
  o.method = Method::Features;
  o.size_max = 1.0;
  const LO corner = 0;
  // A curve not ending at the corner.
  LO curve = kNoIndex;
  for (LO c = 0; c < m.cad.num_curves(); ++c)
    if (m.cad.curves()[c].corners[0] != corner && m.cad.curves()[c].corners[1] != corner) curve = c;
  ASSERT_NE(curve, kNoIndex);
  o.corner_sizes = {{corner, 0.05}};
  o.curve_sizes = {{curve, 0.3}};
  const CurveSizes cs = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  EXPECT_DOUBLE_EQ(cs.corner[corner], 0.05);
  for (double s : cs.at[curve]) EXPECT_LE(s, 0.3);
  const auto& mid = cs.at[curve][cs.at[curve].size() / 2];
  EXPECT_DOUBLE_EQ(mid, 0.3);
  // Every curve ending at the corner has the corner's value at that end.
  for (LO c = 0; c < m.cad.num_curves(); ++c) {
    const auto& cc = m.cad.curves()[c];
    if (cc.corners[0] == corner) {
      EXPECT_DOUBLE_EQ(cs.at[c].front(), 0.05);
    }
    if (cc.corners[1] == corner) {
      EXPECT_DOUBLE_EQ(cs.at[c].back(), 0.05);
    }
  }
  const FaceSizes fs = face_sizes(m.faces[0], nullptr, m.curves, cs, 0, o);
  const auto& fm = m.faces[0];
  bool seen = false;
  for (LO v = 0; v < fm.num_vertices(); ++v) {
    if (fm.vclass[v].dim == 0 && fm.vclass[v].entity == corner) {
      EXPECT_DOUBLE_EQ(fs.s[v], 0.05);
      seen = true;
    }
    // Near the corner the size is at most 0.05 + 0.2 x (the path length along mesh edges, which
    // on this Delaunay mesh is within 1.3 x the straight distance).
    const double d = distance(fm.points[v], m.cad.corners()[corner].point);
    EXPECT_LE(fs.s[v], 0.05 + o.gradation * 1.3 * d + 1e-9);
  }
  EXPECT_TRUE(seen);
  EXPECT_LE(gradation_excess(fm, fs.s, o.gradation), 1e-9);
  // A user face size caps the face and its curves.
  o.face_sizes = {{0, 0.4}};
  const CurveSizes cs2 = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  const FaceSizes fs2 = face_sizes(m.faces[0], nullptr, m.curves, cs2, 0, o);
  EXPECT_LE(*std::max_element(fs2.s.begin(), fs2.s.end()), 0.4);
  EXPECT_DOUBLE_EQ(*std::max_element(fs2.s.begin(), fs2.s.end()), 0.4);
  // Bad input is an InputError.
  SizeMapOptions bad = o;
  bad.curve_sizes = {{m.cad.num_curves(), 0.1}};
  EXPECT_THROW((void)initial_curve_sizes(m.cad, m.curves, bad, TaskArena(1)), InputError);
  bad = o;
  bad.size_max = 0;
  EXPECT_THROW((void)initial_curve_sizes(m.cad, m.curves, bad, TaskArena(1)), InputError);
  bad = o;
  bad.corner_sizes = {{0, -1.0}};
  EXPECT_THROW((void)initial_curve_sizes(m.cad, m.curves, bad, TaskArena(1)), InputError);
}

TEST(SizeMap, CrossFieldSizesVaryOnADiskAndFeaturesDoNot) {
  const Model m = prepare(disk(5), 0.5, true);
  SizeMapOptions o;
  o.size_max = 2.0;
  o.target_quads = 300;
  o.edges_per_turn = 0;  // this test is about features and the cross field, not curvature
  const auto n = face_quad_targets(m.cad, o);
  ASSERT_NEAR(n[0], 300, 1e-9);
  const auto& fm = m.faces[0];

  o.method = Method::Features;
  const CurveSizes cs_f = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  const FaceSizes f = face_sizes(fm, &m.cf[0], m.curves, cs_f, n[0], o);
  EXPECT_TRUE(f.s_cf.empty());
  const auto [fmin, fmax] = std::minmax_element(f.s.begin(), f.s.end());
  EXPECT_DOUBLE_EQ(*fmin, 2.0);  // only the cap: the circle is long, nothing is near it
  EXPECT_DOUBLE_EQ(*fmax, 2.0);

  o.method = Method::CrossField;
  const CurveSizes cs_c = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  const FaceSizes c = face_sizes(fm, &m.cf[0], m.curves, cs_c, n[0], o);
  ASSERT_EQ(c.s_cf.size(), static_cast<std::size_t>(fm.num_vertices()));
  const auto [cmin, cmax] = std::minmax_element(c.s_cf.begin(), c.s_cf.end());
  // The quad count of the conformal sizes: ∫ 1 / s_cf^2 = N (Sec. 3.3).
  double quads = 0;
  for (const auto& t : fm.triangles) {
    const Vec3 a = fm.points[t[1]] - fm.points[t[0]], b = fm.points[t[2]] - fm.points[t[0]];
    double mean = 0;
    for (LO v : t) mean += 1 / (c.s_cf[v] * c.s_cf[v]) / 3;
    quads += 0.5 * norm(cross(a, b)) * mean;
  }
  const double excess = gradation_excess(fm, c.s, o.gradation);
  std::printf(
      "[sizemap] disk: s_cf in [%.4f, %.4f] (ratio %.2f), quads of s_cf %.1f (N %.0f), s in "
      "[%.4f, %.4f], gradation excess %.2e\n",
      *cmin, *cmax, *cmax / *cmin, quads, n[0], *std::min_element(c.s.begin(), c.s.end()),
      *std::max_element(c.s.begin(), c.s.end()), excess);
  EXPECT_GT(*cmax / *cmin, 1.2);  // H varies over a disk (4 singularities inside)
  EXPECT_NEAR(quads, 300, 3);
  EXPECT_LT(*std::max_element(c.s.begin(), c.s.end()), 2.0);
  EXPECT_LE(excess, 1e-9);
  for (LO v = 0; v < fm.num_vertices(); ++v) {
    EXPECT_LE(c.s[v], c.s_cf[v] + 1e-12);
    EXPECT_LE(c.s[v], c.s_min[v] + 1e-12);
  }
}

TEST(SizeMap, UnionIsContinuousOnSharedCurvesAndIndependentOfThePartition) {
  const Model m =
      prepare(cad::load_cad(test::write_box_with_hole(tmp("box_hole.brep"))), 1.0, true);
  SizeMapOptions o;
  o.size_max = 1.5;
  o.target_quads = 600;
  // A face with many more quads than its share: its small sizes must spread over its neighbours.
  o.face_quads = {{0, 4 * face_quad_targets(m.cad, o)[0]}};
  const auto [sizes1, fields1] = full_flow(m, o, 1);
  const auto [sizes2, fields2] = full_flow(m, o, 2);
  const auto [sizes3, fields3] = full_flow(m, o, 3);
  EXPECT_EQ(sizes1.pack(), sizes2.pack());
  EXPECT_EQ(sizes1.pack(), sizes3.pack());
  for (std::size_t f = 0; f < fields1.size(); ++f) {
    EXPECT_EQ(fields1[f].s, fields2[f].s);
    EXPECT_EQ(fields1[f].s, fields3[f].s);
  }

  // Values at the same curve vertex / corner agree across faces, and with the curve sizes.
  std::map<std::pair<LO, LO>, std::vector<double>> at;  // (curve, index) or (-1 - corner, 0)
  double worst_gradation = -1e300, worst_mismatch = 0, s_lo = 1e300, s_hi = 0;
  for (LO f = 0; f < m.cad.num_faces(); ++f) {
    const auto& fm = m.faces[f];
    worst_gradation = std::max(worst_gradation, gradation_excess(fm, fields1[f].s, o.gradation));
    for (LO v = 0; v < fm.num_vertices(); ++v) {
      const auto& vc = fm.vclass[v];
      const double s = fields1[f].s[v];
      s_lo = std::min(s_lo, s);
      s_hi = std::max(s_hi, s);
      if (vc.dim == 1) {
        at[{vc.entity, vc.index}].push_back(s);
        worst_mismatch = std::max(worst_mismatch, std::abs(s - sizes1.at[vc.entity][vc.index]));
      } else if (vc.dim == 0) {
        at[{-1 - vc.entity, 0}].push_back(s);
        worst_mismatch = std::max(worst_mismatch, std::abs(s - sizes1.corner[vc.entity]));
      }
    }
  }
  std::size_t shared = 0;
  for (const auto& [key, values] : at) {
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    if (values.size() > 1) ++shared;
    EXPECT_EQ(*lo, *hi) << "curve/corner " << key.first << " vertex " << key.second;
  }
  std::printf(
      "[sizemap] box with hole: %zu shared boundary vertices, s in [%.4f, %.4f], face vs curve "
      "mismatch %.2e, gradation excess %.2e (faces), %.2e (curves)\n",
      shared, s_lo, s_hi, worst_mismatch, worst_gradation,
      curve_gradation_excess(m, sizes1, o.gradation));
  EXPECT_GT(shared, 50u);
  EXPECT_EQ(worst_mismatch, 0.0);
  EXPECT_LE(worst_gradation, 1e-9);
  EXPECT_LE(curve_gradation_excess(m, sizes1, o.gradation), 1e-9);
  // Without the union (second pass on the initial curve sizes) the faces disagree on shared curves.
  {
    const CurveSizes initial = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
    const auto n = face_quad_targets(m.cad, o);
    std::map<std::pair<LO, LO>, std::vector<double>> raw;
    for (LO f = 0; f < m.cad.num_faces(); ++f) {
      const FaceSizes fs = face_sizes(m.faces[f], &m.cf[f], m.curves, initial, n[f], o);
      for (LO v = 0; v < m.faces[f].num_vertices(); ++v)
        if (m.faces[f].vclass[v].dim == 1)
          raw[{m.faces[f].vclass[v].entity, m.faces[f].vclass[v].index}].push_back(fs.s[v]);
    }
    std::size_t disagree = 0;
    for (const auto& [key, values] : raw) {
      const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
      if (*hi > *lo * (1 + 1e-6)) ++disagree;
    }
    std::printf("[sizemap] box with hole without the union: %zu curve vertices disagree\n",
                disagree);
    EXPECT_GT(disagree, 10u);
  }
  // The small sizes of face 0 reached its neighbours' shared curves.
  double smallest_on_face0_boundary = 1e300;
  for (LO v = 0; v < m.faces[0].num_vertices(); ++v)
    if (m.faces[0].vclass[v].dim != 2)
      smallest_on_face0_boundary = std::min(smallest_on_face0_boundary, fields1[0].s[v]);
  EXPECT_LT(smallest_on_face0_boundary, 0.9 * o.size_max);
}

TEST(SizeMap, FaceQuadTargetsFollowAreas) {
  const cad::CadModel model =
      cad::load_cad(test::write_box_with_hole(tmp("box_hole_targets.brep")));
  SizeMapOptions o;
  o.size_max = 1;
  o.target_quads = 1000;
  const auto n = face_quad_targets(model, o);
  double sum = 0;
  for (double x : n) sum += x;
  EXPECT_NEAR(sum, 1000, 1e-9);
  const double ratio = n[0] / model.faces()[0].area;
  for (LO f = 0; f < model.num_faces(); ++f)
    EXPECT_NEAR(n[f] / model.faces()[f].area, ratio, 1e-12 * ratio);
  // Default N: total area / size_max^2.
  o.target_quads = 0;
  double area = 0;
  for (const auto& f : model.faces()) area += f.area;
  const auto d = face_quad_targets(model, o);
  EXPECT_NEAR(std::accumulate(d.begin(), d.end(), 0.0), area, 1e-9 * area);
  // A user count replaces the face's share.
  o.face_quads = {{2, 77}};
  EXPECT_DOUBLE_EQ(face_quad_targets(model, o)[2], 77);
  EXPECT_DOUBLE_EQ(face_quad_targets(model, o)[1], d[1]);
  o.face_quads = {{model.num_faces(), 1}};
  EXPECT_THROW((void)face_quad_targets(model, o), InputError);
}

TEST(SizeMap, ExpectedQuadsIsAreaOverSizeSquared) {
  // A 2 x 1 rectangle in two triangles: 200 quads of size 0.1, 50 of size 0.2.
  mesh::FaceMesh m;
  m.points = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  EXPECT_NEAR(expected_quads(m, std::vector<double>(4, 0.1)), 200, 1e-9);
  EXPECT_NEAR(expected_quads(m, std::vector<double>(4, 0.2)), 50, 1e-9);
  // A triangle whose sizes are not positive counts for nothing.
  EXPECT_NEAR(expected_quads(m, std::vector<double>{0.1, 0.1, 0.1, -1}), 100, 1e-9);
  EXPECT_THROW((void)expected_quads(m, std::vector<double>(3, 0.1)), Error);
}

TEST(SizeMap, DeterministicWhateverTheThreadCount) {
  const Model m = prepare(cad::load_cad(test::write_cylinder(tmp("cylinder.brep"))), 0.8, true);
  SizeMapOptions o;
  o.size_max = 1;
  const auto a = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1)).pack();
  const auto b = initial_curve_sizes(m.cad, m.curves, o, TaskArena(2)).pack();
  EXPECT_EQ(a, b);
  const auto n = face_quad_targets(m.cad, o);
  const CurveSizes cs = initial_curve_sizes(m.cad, m.curves, o, TaskArena(2));
  for (LO f = 0; f < m.cad.num_faces(); ++f) {
    const FaceSizes x = face_sizes(m.faces[f], &m.cf[f], m.curves, cs, n[f], o);
    const FaceSizes y = face_sizes(m.faces[f], &m.cf[f], m.curves, cs, n[f], o);
    EXPECT_EQ(x.s, y.s);
    // Seam copies (glued) get the same value.
    EXPECT_LE(gradation_excess(m.faces[f], x.s, o.gradation), 1e-9);
  }
}

TEST(SizeMap, CurvatureBoundsTheSizeOnCurvedCurves) {
  // A disk of radius 5: with 16 edges per turn its circle asks for 2 pi 5 / 16 = 1.963, below the
  // cap of 2; with the curvature switched off the cap alone remains.
  const Model m = prepare(disk(5), 0.5, false);
  SizeMapOptions o;
  o.size_max = 2.0;
  o.method = Method::Features;
  const CurveSizes with = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  o.edges_per_turn = 0;
  const CurveSizes without = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  const double expected = 2 * std::numbers::pi * 5 / 16;
  int checked = 0;
  for (std::size_t c = 0; c < with.at.size(); ++c)
    for (std::size_t i = 0; i < with.at[c].size(); ++i) {
      EXPECT_NEAR(with.at[c][i], expected, 1e-6);
      EXPECT_DOUBLE_EQ(without.at[c][i], 2.0);
      ++checked;
    }
  EXPECT_GT(checked, 0);
}

TEST(SizeMap, FaceCurvatureBoundsStraightCurvesOnlyWhenAskedFor) {
  // A cylinder of radius 2: its seam is straight, its side face curved across it. By default the
  // seam grows from the circles' 2 pi 2 / 16 at its ends by the gradation (paper 000's size map
  // has no curvature term); with face_curvature the face holds it at 2 pi 2 / 16 all along.
  const Model m = prepare(cad::load_cad(test::write_cylinder(tmp("sm_cyl.brep"))), 0.5, false);
  SizeMapOptions o;
  o.size_max = 2.0;
  o.method = Method::Features;
  const CurveSizes plain = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  o.face_curvature = true;
  const CurveSizes curved = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  const double across = 2 * std::numbers::pi * 2 / 16;
  int seams = 0;
  for (LO c = 0; c < m.cad.num_curves(); ++c) {
    if (m.cad.curves()[c].type != cad::CurveType::Line) continue;
    ++seams;
    double largest = 0;
    for (std::size_t i = 0; i < plain.at[c].size(); ++i) {
      largest = std::max(largest, plain.at[c][i]);
      EXPECT_NEAR(curved.at[c][i], across, 1e-6);
    }
    EXPECT_GT(largest, across + 0.2 * 2.0);  // halfway up the seam, 2.5 from either end
    EXPECT_LE(largest, 2.0);
  }
  EXPECT_EQ(seams, 1);
}

TEST(SizeMap, ThinAspectCapsTheSizeAlongAStripOnly) {
  // Three 10-long rectangles, 4, 0.05 and 4 wide, sharing their long curves, at size 1 and the
  // default rules' floor 0.17. The strip's long curves are 0.05 apart and sides of one face:
  // without the cap they keep max(floor, 0.75 x 1) (the feature ratio), with K = 4 they get
  // 4 x 0.05 = 0.2 (below the floor too, with K = 2). The plate's outer long curves are 4 from
  // anything: untouched but for the gradation from the corners.
  const Model m = prepare(
      cad::load_cad(test::write_plate_with_strip(10, 4, 0.05, tmp("sm_strip.brep"))), 1.0, false);
  SizeMapOptions o;
  o.method = Method::Features;
  o.size_max = 1.0;
  o.size_min = 0.17;
  auto along = [&](const CurveSizes& cs, double y) {  // sizes on the curve y, 3.5 from its ends
    std::vector<double> out;
    for (LO c = 0; c < m.cad.num_curves(); ++c)
      for (std::size_t i = 0; i < cs.at[c].size(); ++i) {
        const Vec3& p = m.curves[c].points[i];
        const auto& a = m.curves[c].points.front();
        const auto& b = m.curves[c].points.back();
        if (std::abs(a.y - y) < 1e-9 && std::abs(b.y - y) < 1e-9 && p.x > 3.5 && p.x < 6.5)
          out.push_back(cs.at[c][i]);
      }
    return out;
  };
  const CurveSizes off = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  for (const double y : {4.0, 4.05}) {
    const auto s = along(off, y);
    ASSERT_GT(s.size(), 2u);
    for (const double x : s)
      EXPECT_NEAR(x, 0.75, 1e-6) << "y " << y;  // graded from 0.17 up to x = 3
  }
  for (const double k : {4.0, 2.0}) {
    o.thin_aspect = k;
    const CurveSizes on = initial_curve_sizes(m.cad, m.curves, o, TaskArena(2));
    for (const double y : {4.0, 4.05})
      for (const double x : along(on, y)) EXPECT_NEAR(x, k * 0.05, 1e-6) << "K " << k;
    for (const double y : {0.0, 8.05}) {
      const auto s = along(on, y);
      ASSERT_GT(s.size(), 2u);
      EXPECT_NEAR(*std::max_element(s.begin(), s.end()), 1.0, 1e-9);  // far from the strip
    }
    EXPECT_LE(curve_gradation_excess(m, on, o.gradation), 1e-9);
    EXPECT_EQ(on.pack(), initial_curve_sizes(m.cad, m.curves, o, TaskArena(1)).pack());
  }
  o.thin_aspect = -1;
  EXPECT_THROW((void)initial_curve_sizes(m.cad, m.curves, o, TaskArena(1)), InputError);
}

/// The triangle (0, 0), (8, 0), (8, 8 tan(corner)): a wedge of `corner` degrees at the origin.
std::vector<std::pair<double, double>> wedge(double corner_deg) {
  return {{0, 0}, {8, 0}, {8, 8 * std::tan(corner_deg * std::numbers::pi / 180)}};
}

TEST(SizeMap, ThinAspectLeavesWideFacesAndSidesMeetingAtACornerAlone) {
  // A 10 x 0.6 rectangle at size 1: 0.6 apart is more than half the size, not thin. A prism on a
  // triangle with a 3-degree corner: the long sides of its end faces are close near the corner and
  // share it (a cusp's tail), but each also bounds a side face of the prism, which takes the
  // tail's counts (see background::limit_by_face_width): the tail is not graded down to the
  // corner, and the tip is where it is thinner than 0.18 x the size, x < 0.18 / sin(3 degrees)
  // = 3.44. The side faces are four-sided and carry the counts to the other end's tail, which
  // asks the same (an extruded wedge): past the tip, where the width is under a quarter of the
  // size (x < 4.78), the sizes are capped at 0.6 K x the width, and the gradation takes them
  // back to the tail's own sizes within (1 - 0.6 K w) / 0.2 of there.
  SizeMapOptions o;
  o.method = Method::Features;
  o.size_max = 1.0;
  o.size_min = 0.17;
  BRepBuilderAPI_MakePolygon polygon;
  for (const auto& [x, y] : wedge(3)) polygon.Add(gp_Pnt(x, y, 0));
  polygon.Close();
  const TopoDS_Shape prism =
      BRepPrimAPI_MakePrism(BRepBuilderAPI_MakeFace(polygon.Wire(), true).Face(), gp_Vec(0, 0, 2))
          .Shape();
  const Model wide = prepare(
      polygon_face({{0, 0}, {10, 0}, {10, 0.6}, {0, 0.6}}, "sm_thin_alone.brep"), 1.0, false);
  const Model m = prepare(load_shape(prism, "sm_wedge_prism.brep"), 1.0, false);
  for (const Model* model : {&wide, &m}) {
    o.thin_aspect = 0;
    const CurveSizes off = initial_curve_sizes(model->cad, model->curves, o, TaskArena(1));
    o.thin_aspect = 4;
    const CurveSizes on = initial_curve_sizes(model->cad, model->curves, o, TaskArena(1));
    if (model == &wide) {
      EXPECT_EQ(off.pack(), on.pack());
      EXPECT_TRUE(on.tips.empty());
      continue;
    }
    // Two long sides at each of the prism's two sharp corners.
    ASSERT_EQ(on.tips.size(), 4u);
    const double limit = 0.18 / std::sin(3 * std::numbers::pi / 180);
    for (const auto& tip : on.tips) {
      EXPECT_TRUE(tip.shared);
      EXPECT_GT(tip.length, 0.8 * limit);
      EXPECT_LE(tip.length, limit * (1 + 1e-9));
      const auto& pts = m.curves[tip.curve].points;
      const Vec3 corner = tip.end == 0 ? pts.front() : pts.back();
      for (std::size_t i = 0; i < pts.size(); ++i) {
        if (distance(pts[i], corner) < tip.length) {
          EXPECT_DOUBLE_EQ(on.at[tip.curve][i], tip.length);
        } else {
          // Capped past the tip, never below 0.6 K x the tip's width (at least 0.8 x 0.18, as
          // its length above); the rest as without K.
          const double x = distance(pts[i], corner);
          const double w = x * std::sin(3 * std::numbers::pi / 180);
          EXPECT_LE(on.at[tip.curve][i], off.at[tip.curve][i] + 1e-12);
          EXPECT_GE(on.at[tip.curve][i], 0.6 * 4 * 0.8 * 0.18);
          if (w < 0.25 * 0.95) {
            EXPECT_LE(on.at[tip.curve][i], 0.6 * 4 * w * (1 + 1e-6));
          }
          if (x > 4.78 + 2.5) {
            EXPECT_DOUBLE_EQ(on.at[tip.curve][i], off.at[tip.curve][i]);
          }
        }
      }
    }
  }
}

TEST(SizeMap, ThinAspectGradesASharpWedgeTailAndHoldsItsTipInOneEdge) {
  // The 3-degree wedge as one face at size 1, floor 0.17, K = 4. Its two long sides share the
  // corner: along the tail the width w = x sin(3 degrees) caps the sizes at 3/4 K w; where the
  // sides are closer than a tenth of the floor (x < 0.0170 / sin(3 degrees) = 0.325) is the tip,
  // one edge as long as that stretch.
  SizeMapOptions o;
  o.method = Method::Features;
  o.size_max = 1.0;
  o.size_min = 0.17;
  const double sine = std::sin(3 * std::numbers::pi / 180);
  const Model m = prepare(polygon_face(wedge(3), "sm_wedge.brep"), 1.0, false);
  const CurveSizes off = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  EXPECT_TRUE(off.tips.empty());
  o.thin_aspect = 4;
  const CurveSizes on = initial_curve_sizes(m.cad, m.curves, o, TaskArena(2));
  EXPECT_EQ(on.pack(), initial_curve_sizes(m.cad, m.curves, o, TaskArena(1)).pack());
  ASSERT_EQ(on.tips.size(), 2u);  // the bottom and the slanted side, at the origin
  int bottom = 0, tail = 0;
  for (const auto& tip : on.tips) {
    const auto& pts = m.curves[tip.curve].points;
    const Vec3 corner = tip.end == 0 ? pts.front() : pts.back();
    EXPECT_LT(norm(corner), 1e-9);
    EXPECT_GT(tip.length, 0.2);
    EXPECT_LE(tip.length, 0.0170 / sine + 1e-9);
    const bool flat = std::abs(pts.front().y) < 1e-9 && std::abs(pts.back().y) < 1e-9;
    bottom += flat ? 1 : 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double r = norm(pts[i]);
      if (r < tip.length) {
        EXPECT_DOUBLE_EQ(on.at[tip.curve][i], tip.length) << "r " << r;
      } else if (flat && r > 0.5 && r < 3) {
        ++tail;
        EXPECT_LE(on.at[tip.curve][i], 0.75 * 4 * r * sine * (1 + 1e-6)) << "r " << r;
        EXPECT_LT(on.at[tip.curve][i], off.at[tip.curve][i]) << "r " << r;
      }
    }
  }
  EXPECT_EQ(bottom, 1);
  // The background curve meshes resolve the tail (at most twice its width apart beyond a tenth of
  // the background floor): dozens of vertices where the size alone gave three.
  EXPECT_GT(tail, 15);
}

TEST(SizeMap, ThinAspectLeavesTheBluntedTipOfAWedgeAlone) {
  // A 20-degree wedge whose tip a curve 0.05 long cuts off (shorter than the floor 0.17): its two
  // long sides share no corner and are 0.05-0.5 apart near the tip, but they are a wedge, not a
  // strip (farther apart than twice the sliver, and than sin 10 degrees x the distance to it).
  const double slope = std::tan(20 * std::numbers::pi / 180);
  const Model m =
      prepare(polygon_face({{0, 0}, {8, 0}, {8, 0.05 + 8 * slope}, {0, 0.05}}, "sm_blunt.brep"),
              1.0, false);
  SizeMapOptions o;
  o.method = Method::Features;
  o.size_max = 1.0;
  o.size_min = 0.17;
  const CurveSizes off = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  o.thin_aspect = 4;
  const CurveSizes on = initial_curve_sizes(m.cad, m.curves, o, TaskArena(1));
  int seen = 0;
  for (LO c = 0; c < m.cad.num_curves(); ++c) {
    const auto& pts = m.curves[c].points;
    if (std::abs(pts.front().y) > 1e-9 || std::abs(pts.back().y) > 1e-9) continue;  // the bottom
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (pts[i].x > 0.5 && pts[i].x < 1.3) {
        ++seen;
        EXPECT_DOUBLE_EQ(on.at[c][i], off.at[c][i]) << "x " << pts[i].x;
      }
  }
  EXPECT_GT(seen, 0);
}

}  // namespace
}  // namespace qsmesh::sizemap
