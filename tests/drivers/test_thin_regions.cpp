// Thin regions through the qsmesh executable (issue 29): a strip, a neck, a crescent between two
// arcs meeting at 1-degree cusps, a face with a 5-degree corner. A quad a strip of width w holds 2
// across and L along has SICN about w / L: the feature ratio and the size floor left L near the
// size, and --thin-aspect caps it.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <GC_MakeArcOfCircle.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Wire.hxx>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <gp_Circ.hxx>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "qsmesh/core/types.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace {

using qsmesh::Vec3;
using qsmesh::test::tmp;

/// The quads of a MSH 4.1 ASCII file as qsmesh writes it, with their face and the corner nodes.
struct MshQuads {
  std::vector<Vec3> points;    // by node tag - 1
  std::vector<int> corner_of;  // CAD corner tag of a node, or 0
  std::vector<std::array<std::size_t, 4>> quads;
  std::vector<int> quad_face;
};

MshQuads read_msh(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  MshQuads m;
  std::string line;
  while (std::getline(in, line)) {
    if (line == "$Nodes") {
      std::size_t blocks = 0, n = 0, lo = 0, hi = 0;
      in >> blocks >> n >> lo >> hi;
      m.points.resize(hi);
      m.corner_of.assign(hi, 0);
      for (std::size_t b = 0; b < blocks; ++b) {
        int dim = 0, tag = 0, parametric = 0;
        std::size_t count = 0;
        in >> dim >> tag >> parametric >> count;
        std::vector<std::size_t> tags(count);
        for (auto& t : tags) in >> t;
        for (const std::size_t t : tags) {
          Vec3 p;
          in >> p.x >> p.y >> p.z;
          for (int k = 0; k < parametric * dim; ++k) {
            double skip = 0;
            in >> skip;
          }
          m.points[t - 1] = p;
          if (dim == 0) m.corner_of[t - 1] = tag;
        }
      }
    } else if (line == "$Elements") {
      std::size_t blocks = 0, n = 0, lo = 0, hi = 0;
      in >> blocks >> n >> lo >> hi;
      for (std::size_t b = 0; b < blocks; ++b) {
        int dim = 0, tag = 0, type = 0;
        std::size_t count = 0;
        in >> dim >> tag >> type >> count;
        const int nodes = type == 15 ? 1 : type == 1 ? 2 : type == 2 ? 3 : type == 3 ? 4 : -1;
        if (nodes < 0) throw std::runtime_error("unexpected element type in " + path);
        for (std::size_t e = 0; e < count; ++e) {
          std::size_t id = 0;
          in >> id;
          std::array<std::size_t, 4> q{};
          for (int k = 0; k < nodes; ++k) in >> q[static_cast<std::size_t>(k)];
          if (type != 3) continue;
          for (auto& v : q) --v;
          m.quads.push_back(q);
          m.quad_face.push_back(tag);
        }
      }
    }
  }
  return m;
}

/// What the criterion looks at: the SICN of the quads away from sharp corners (no quad
/// touching a CAD corner whose angle in the face, summed over the face's quads there, is under 10
/// degrees), and how many quads hold each such corner.
struct ThinCheck {
  std::size_t quads = 0;
  double sicn_min_away = 1;  // over the quads touching no sharp corner
  double sicn_min = 1;
  std::vector<int> quads_at_sharp_corner;    // one entry per (face, sharp corner)
  std::map<int, std::size_t> quads_by_face;  // MSH face tag (CAD face id + 1) -> quads
};

ThinCheck check(const MshQuads& m) {
  ThinCheck c;
  c.quads = m.quads.size();
  for (const int f : m.quad_face) ++c.quads_by_face[f];
  std::map<std::pair<int, std::size_t>, double> angle;  // (face, node) -> degrees
  std::map<std::pair<int, std::size_t>, int> count;
  for (std::size_t i = 0; i < m.quads.size(); ++i) {
    const auto& q = m.quads[i];
    for (int k = 0; k < 4; ++k) {
      const std::size_t v = q[static_cast<std::size_t>(k)];
      if (m.corner_of[v] == 0) continue;
      const Vec3 a = m.points[q[static_cast<std::size_t>((k + 1) % 4)]] - m.points[v];
      const Vec3 b = m.points[q[static_cast<std::size_t>((k + 3) % 4)]] - m.points[v];
      const double cosine = qsmesh::dot(a, b) / (qsmesh::norm(a) * qsmesh::norm(b));
      angle[{m.quad_face[i], v}] +=
          std::acos(std::clamp(cosine, -1.0, 1.0)) * 180 / std::numbers::pi;
      ++count[{m.quad_face[i], v}];
    }
  }
  for (const auto& [key, degrees] : angle)
    if (degrees < 10) c.quads_at_sharp_corner.push_back(count[key]);
  for (std::size_t i = 0; i < m.quads.size(); ++i) {
    const auto& q = m.quads[i];
    const double s =
        qsmesh::mesh::quad_sicn({m.points[q[0]], m.points[q[1]], m.points[q[2]], m.points[q[3]]});
    c.sicn_min = std::min(c.sicn_min, s);
    bool sharp = false;
    for (const std::size_t v : q) {
      const auto it = angle.find({m.quad_face[i], v});
      sharp = sharp || (it != angle.end() && it->second < 10);
    }
    if (!sharp) c.sicn_min_away = std::min(c.sicn_min_away, s);
  }
  return c;
}

/// `qsmesh mesh MODEL -o NAME.msh OPTIONS -q`, then the check of its quads.
ThinCheck mesh_and_check(const std::string& model, const std::string& options,
                         const std::string& name) {
  const std::string out = tmp(name + ".msh"), err = tmp(name + ".err");
  const std::string cmd = std::string(QSMESH_EXE) + " mesh " + model + " -o " + out + " " +
                          options + " --threads 2 -q 2>" + err;
  const int status = std::system(cmd.c_str());
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error(cmd + " failed: " + qsmesh::test::slurp(err));
  return check(read_msh(out));
}

std::string write_face(const TopoDS_Wire& wire, const std::string& path) {
  BRepBuilderAPI_MakeFace face(wire, /*OnlyPlane=*/true);
  if (!face.IsDone()) throw std::runtime_error("face construction failed");
  const TopoDS_Shape& shape = face.Face();
  if (!BRepTools::Write(shape, path.c_str())) throw std::runtime_error("cannot write " + path);
  return path;
}

/// The crescent inside the circle of radius 5 about the origin and outside the circle of radius
/// 4.5 about (d, 0), d chosen so that the circles cross at `cusp_deg` degrees: two arcs, two
/// cusps, about 1 wide at its widest (x = -5).
std::string write_crescent(double cusp_deg, const std::string& path) {
  const double R = 5, r = 4.5;
  const double d =
      std::sqrt(R * R + r * r - 2 * R * r * std::cos(cusp_deg * std::numbers::pi / 180));
  const double x = (R * R - r * r + d * d) / (2 * d), y = std::sqrt(R * R - x * x);
  const gp_Pnt top(x, y, 0), bottom(x, -y, 0);
  BRepBuilderAPI_MakeWire wire;
  wire.Add(
      BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(top, gp_Pnt(-R, 0, 0), bottom).Value()).Edge());
  wire.Add(
      BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(bottom, gp_Pnt(d - r, 0, 0), top).Value()).Edge());
  if (!wire.IsDone()) throw std::runtime_error("crescent wire construction failed");
  return write_face(wire.Wire(), path);
}

// The three rectangles 10 x 4, 10 x 0.05, 10 x 4 at size 1: the strip is 0.05 x the size wide.
// Without the cap its quads were 0.025 x 0.77 (2 across, nearly the full size along it: the
// feature ratio and the floor, 0.17, keep it there): SICN 0.065.
TEST(ThinRegions, StripQuadsStayAboveSicnPointTwo) {
  const std::string model =
      qsmesh::test::write_plate_with_strip(10, 4, 0.05, tmp("thin_strip.brep"));
  const ThinCheck off = mesh_and_check(model, "--size 1 --thin-aspect 0", "thin_strip_off");
  const ThinCheck on = mesh_and_check(model, "--size 1", "thin_strip_on");
  EXPECT_LT(off.sicn_min, 0.1);  // what the cap is for
  EXPECT_TRUE(on.quads_at_sharp_corner.empty());
  EXPECT_GE(on.sicn_min_away, 0.2) << on.quads << " quads";
  // Local anisotropy: 10 / (4 x 0.05) = 50 along, 2 across (100 quads, 40 without the cap), not
  // quads as wide as they are long (800).
  EXPECT_LE(on.quads_by_face.at(2), 150u);
}

// The same plate with a strip 0.01 wide at size 1: under a tenth of the size floor (0.17 x the
// size by default), which the cap once took for curves touching and left alone (quads 0.005 x
// 0.77, SICN 0.013). A hundredth of the floor is the limit now: the strip is capped like a wider
// one, 4 x 0.01 along.
TEST(ThinRegions, StripNarrowerThanATenthOfTheFloorIsCapped) {
  const std::string model =
      qsmesh::test::write_plate_with_strip(10, 4, 0.01, tmp("thin_strip_narrow.brep"));
  const ThinCheck off = mesh_and_check(model, "--size 1 --thin-aspect 0", "thin_narrow_off");
  const ThinCheck on = mesh_and_check(model, "--size 1", "thin_narrow_on");
  EXPECT_LT(off.sicn_min, 0.1);
  EXPECT_TRUE(on.quads_at_sharp_corner.empty());
  EXPECT_GE(on.sicn_min_away, 0.2) << on.quads << " quads";
  // 10 / (4 x 0.01) = 250 along, 2 across: about 500 quads in the strip, not the 62500 of quads
  // as long as the strip is wide.
  EXPECT_LE(on.quads_by_face.at(2), 750u);
}

// A 10 x 3 plate whose top dips to a segment 0.4 long, 0.02 above the bottom (the neck, 0.02 x
// the size wide), through slopes of about 32 degrees: no corner sharper than 95 degrees. Without
// the cap SICN min 0.038. With the cap alone 0.184 (the worst quads where the neck widens), with
// the two sides aligned 0.198 (the quads just past the neck, their narrow side half its width),
// with the sizes along the neck grown at half the gradation 0.2 and above.
TEST(ThinRegions, NeckQuadsStayAboveSicnPointTwo) {
  const std::string model = qsmesh::test::write_polygon_face(
      {{0, 0}, {10, 0}, {10, 3}, {5.2, 0.02}, {4.8, 0.02}, {0, 3}}, tmp("thin_neck.brep"));
  const ThinCheck off = mesh_and_check(model, "--size 1 --thin-aspect 0", "thin_neck_off");
  const ThinCheck on = mesh_and_check(model, "--size 1", "thin_neck_on");
  EXPECT_LT(off.sicn_min, 0.1);
  EXPECT_TRUE(on.quads_at_sharp_corner.empty());
  EXPECT_GE(on.sicn_min_away, 0.2) << on.quads << " quads";
}

// The neck's two sides are aligned (quantize::align_thin_sides): the top segment, all of it
// facing the bottom 0.02 away, keeps its vertices, and the bottom curve has one below each of
// them. Without that the bottom's spacing (0.082 there) and the top's (0.067) sheared the quads
// across.
TEST(ThinRegions, NeckSidesHaveAlignedVertices) {
  const std::string model = qsmesh::test::write_polygon_face(
      {{0, 0}, {10, 0}, {10, 3}, {5.2, 0.02}, {4.8, 0.02}, {0, 3}}, tmp("thin_neck_aligned.brep"));
  const std::string out = tmp("thin_neck_aligned.msh");
  const std::string cmd =
      std::string(QSMESH_EXE) + " mesh " + model + " -o " + out + " --size 1 --threads 2 -q";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const MshQuads m = read_msh(out);
  std::vector<double> top, bottom;
  for (const Vec3& p : m.points) {
    if (std::abs(p.y - 0.02) < 1e-9 && p.x > 4.8 - 1e-9 && p.x < 5.2 + 1e-9) top.push_back(p.x);
    if (std::abs(p.y) < 1e-9) bottom.push_back(p.x);
  }
  ASSERT_GE(top.size(), 4u);
  for (const double x : top) {
    double nearest = 1e9;
    for (const double b : bottom) nearest = std::min(nearest, std::abs(b - x));
    EXPECT_LT(nearest, 1e-6) << "no bottom vertex below the top one at x = " << x;
  }
}

// Two arcs crossing at 1 degree. Each cusp is held by one quad; the tails between them narrow to
// nothing, so their sizes are graded with the width (3/4 K w along each side, the sides sharing
// the cusp and bounding this face alone) and the tip, where the sides are closer than a tenth of
// the floor, is one edge. Before: SICN min away from the cusps -0.002 (a folded quad next to a
// cusp, the face fell back to the kernel's uniform refinement).
TEST(ThinRegions, CrescentQuadsAwayFromTheCuspsStayAboveSicnPointTwo) {
  const std::string model = write_crescent(1.0, tmp("thin_crescent.brep"));
  const ThinCheck off = mesh_and_check(model, "--size 1 --thin-aspect 0", "thin_crescent_off");
  const ThinCheck on = mesh_and_check(model, "--size 1", "thin_crescent");
  EXPECT_LT(off.sicn_min_away, 0.2);  // what the graded tails are for
  EXPECT_EQ(on.quads_at_sharp_corner, (std::vector<int>{1, 1}));
  EXPECT_GE(on.sicn_min_away, 0.2) << on.quads << " quads";
}

// A 10 x 4 plate with a wedge cut in: its corner at the origin is 5 degrees (between the bottom
// and the segment to (6, 0.525)), the corner at (6, 0.525) is reflex. One quad holds the corner
// (SICN about sin 5 degrees, forced); the tail behind it is graded as the crescent's. Before: the
// two quads next to the corner's at 0.102.
TEST(ThinRegions, FiveDegreeCornerQuadsAwayFromItStayAboveSicnPointTwo) {
  const double y = 6 * std::tan(5 * std::numbers::pi / 180);
  const std::string model = qsmesh::test::write_polygon_face(
      {{0, 0}, {10, 0}, {10, 4}, {6, 4}, {6, y}}, tmp("thin_wedge.brep"));
  const ThinCheck off = mesh_and_check(model, "--size 1 --thin-aspect 0", "thin_wedge_off");
  const ThinCheck on = mesh_and_check(model, "--size 1", "thin_wedge");
  EXPECT_LT(off.sicn_min_away, 0.2);
  EXPECT_EQ(on.quads_at_sharp_corner, (std::vector<int>{1}));
  EXPECT_GE(on.sicn_min_away, 0.2) << on.quads << " quads";
}

// The 5-degree wedge's polygon extruded by 2: the sides of each end face at the sharp corner also
// bound the prism's side faces, so the tail is left to the tip (graded, its counts would reach
// them), which takes the part of the tail thinner than 0.18 x the size. The quads just past it,
// half the width across and the size along, were at SICN 0.171. Each side face is four-sided and
// carries the counts to the other end's tail, which asks the same: there the stretch past the tip
// is capped at 0.6 K x its width, and those quads reach 0.2 (without the tips 0.102).
TEST(ThinRegions, PrismOfTheFiveDegreeCornerQuadsAwayFromItStayAboveSicnPointTwo) {
  const double y = 6 * std::tan(5 * std::numbers::pi / 180);
  BRepBuilderAPI_MakePolygon polygon;
  for (const auto& [px, py] :
       std::vector<std::pair<double, double>>{{0, 0}, {10, 0}, {10, 4}, {6, 4}, {6, y}})
    polygon.Add(gp_Pnt(px, py, 0));
  polygon.Close();
  const TopoDS_Shape prism =
      BRepPrimAPI_MakePrism(BRepBuilderAPI_MakeFace(polygon.Wire(), true).Face(), gp_Vec(0, 0, 2))
          .Shape();
  const std::string model = tmp("thin_wedge_prism.brep");
  ASSERT_TRUE(BRepTools::Write(prism, model.c_str()));
  const ThinCheck off = mesh_and_check(model, "--size 1 --thin-aspect 0", "thin_prism_off");
  const ThinCheck on = mesh_and_check(model, "--size 1", "thin_prism");
  std::printf(
      "5-degree prism: SICN min away from the sharp corners %.3f (%zu quads), %.3f without "
      "the tips (%zu quads)\n",
      on.sicn_min_away, on.quads, off.sicn_min_away, off.quads);
  EXPECT_EQ(on.quads_at_sharp_corner, (std::vector<int>{1, 1}));  // one per end face
  EXPECT_LT(off.sicn_min_away, 0.15);
  EXPECT_GE(on.sicn_min_away, 0.2) << on.quads << " quads";
}

/// The smallest SICN over the quads of `m` with a vertex within `radius` of `centre`, and how many
/// such quads there are.
std::pair<double, std::size_t> sicn_min_near(const MshQuads& m, const Vec3& centre, double radius) {
  double smallest = 1;
  std::size_t near = 0;
  for (const auto& q : m.quads) {
    bool close = false;
    for (const std::size_t v : q) close = close || qsmesh::distance(m.points[v], centre) < radius;
    if (!close) continue;
    ++near;
    smallest = std::min(smallest, qsmesh::mesh::quad_sicn({m.points[q[0]], m.points[q[1]],
                                                           m.points[q[2]], m.points[q[3]]}));
  }
  return {smallest, near};
}

// A 10 x 4 plate whose top edge steps down by 0.003 at x = 5: the step is a curve 0.003 x the
// size long, far below the floor (0.17 x the size by default) and below a tenth of it, where the
// thin-face cap takes the sides it joins for a blunted wedge's tip and leaves them alone. The
// floor kept the step's corners at 0.17 while the step has its 2 edges of 0.0015, so the quads
// against it went from one to the other in one row: SICN 0.015 (0.023 for a step of 0.005, 0.115
// for 0.01; one of 0.02, above a tenth of the floor, the thin-face cap grades: 0.238). Rule (i')
// of the size map caps the step's corners at 5 x its length and the sizes grade toward it: 0.188.
// --sizing paper (rule (i) below the floor) sets them at the step's length anyway.
TEST(ThinRegions, StepShorterThanTheFloorGetsItsCornersGraded) {
  const std::string model = qsmesh::test::write_polygon_face(
      {{0, 0}, {10, 0}, {10, 4}, {5, 4}, {5, 3.997}, {0, 3.997}}, tmp("thin_step.brep"));
  const std::string out = tmp("thin_step.msh"), err = tmp("thin_step.err");
  const std::string cmd = std::string(QSMESH_EXE) + " mesh " + model + " -o " + out +
                          " --size 1 --threads 2 -q 2>" + err;
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd << ": " << qsmesh::test::slurp(err);
  const auto [sicn, near] = sicn_min_near(read_msh(out), Vec3{5, 3.9985, 0}, 1.0);
  std::printf("step 0.003 high: SICN min %.3f over the %zu quads within 1 of it\n", sicn, near);
  ASSERT_GT(near, 0u);
  EXPECT_GE(sicn, 0.15);
}

// A sliver between two faces, as at wing_fuselage's wing roots: four coplanar faces sharing their
// edges around the curve x = 0, 0 <= y <= s (s = 0.005 at --size 1, below a tenth of the floor,
// 0.17). A = [0, 10] x [0, 4] and B = [-4, 0] x [-4, s] both hold it, each with a straight
// (180-degree) corner at one of its ends; the four-sided C = [0, 10] x [-4, 0] and D = [-4, 0] x
// [s, 4] touch its corners without it. Rule (i') leaves corners that a four-sided face touches at
// the floor, and the quads against the sliver's two edges of s / 2 were 0.28 long at the straight
// corner: SICN 0.016 (about 2 (s / 2) / L), which no vertex move lifts. With one edge on the
// sliver and its corners at most 10 x s at every corner (--one-edge-slivers,
// SizeMapOptions::one_edge_slivers) the lift after the smoothing takes them to 0.1 (0.101; s =
// 0.003: 0.009 -> 0.114, s = 0.01: 0.085 -> 0.136).
std::string write_sliver_between_grids(double s, const std::string& path) {
  const auto v = [](double x, double y) {
    return BRepBuilderAPI_MakeVertex(gp_Pnt(x, y, 0)).Vertex();
  };
  const TopoDS_Vertex p6 = v(0, 0), p7 = v(0, s), a = v(0, 4), b = v(10, 4), c = v(10, 0),
                      d = v(10, -4), e = v(0, -4), f = v(-4, -4), g = v(-4, s), h = v(-4, 4);
  const auto edge = [](const TopoDS_Vertex& p, const TopoDS_Vertex& q) {
    return BRepBuilderAPI_MakeEdge(p, q).Edge();
  };
  const TopoDS_Edge sliver = edge(p6, p7), p7a = edge(p7, a), ab = edge(a, b), bc = edge(b, c),
                    cp6 = edge(c, p6), cd = edge(c, d), de = edge(d, e), ep6 = edge(e, p6),
                    ef = edge(e, f), fg = edge(f, g), gp7 = edge(g, p7), gh = edge(g, h),
                    ha = edge(h, a);
  TopoDS_Shell shell;
  BRep_Builder builder;
  builder.MakeShell(shell);
  for (const std::vector<TopoDS_Edge>& loop :
       {std::vector<TopoDS_Edge>{sliver, p7a, ab, bc, cp6},
        std::vector<TopoDS_Edge>{ep6, sliver, gp7, fg, ef},
        std::vector<TopoDS_Edge>{cp6, cd, de, ep6}, std::vector<TopoDS_Edge>{p7a, ha, gh, gp7}}) {
    BRepBuilderAPI_MakeWire wire;
    for (const TopoDS_Edge& x : loop) wire.Add(x);
    if (!wire.IsDone()) throw std::runtime_error("sliver wire construction failed");
    BRepBuilderAPI_MakeFace face(wire.Wire(), /*OnlyPlane=*/true);
    if (!face.IsDone()) throw std::runtime_error("sliver face construction failed");
    builder.Add(shell, face.Face());
  }
  if (!BRepTools::Write(shell, path.c_str())) throw std::runtime_error("cannot write " + path);
  return path;
}

TEST(ThinRegions, SliverBetweenGridFacesTakesOneEdgeAndGradedCorners) {
  const double s = 0.005;
  const std::string model = write_sliver_between_grids(s, tmp("thin_sliver_grids.brep"));
  const auto run = [&](const std::string& options, const std::string& name) {
    const std::string out = tmp(name + ".msh"), err = tmp(name + ".err");
    const std::string cmd = std::string(QSMESH_EXE) + " mesh " + model + " -o " + out +
                            " --size 1 " + options + " --threads 2 -q 2>" + err;
    if (std::system(cmd.c_str()) != 0)
      throw std::runtime_error(cmd + " failed: " + qsmesh::test::slurp(err));
    return read_msh(out);
  };
  const MshQuads off = run("", "thin_sliver_grids_off");
  const MshQuads on = run("--one-edge-slivers", "thin_sliver_grids");
  const auto [sicn_off, near_off] = sicn_min_near(off, Vec3{0, s / 2, 0}, 1.0);
  const auto [sicn, near] = sicn_min_near(on, Vec3{0, s / 2, 0}, 1.0);
  std::printf(
      "sliver %.3f between grid faces: SICN min within 1 of it %.3f (%zu quads), %.3f without "
      "--one-edge-slivers (%zu quads)\n",
      s, sicn, near, sicn_off, near_off);
  ASSERT_GT(near, 0u);
  EXPECT_LT(sicn_off, 0.1);  // the shape this test is about
  EXPECT_GE(sicn, 0.1);
  EXPECT_TRUE(check(on).quads_at_sharp_corner.empty());
}

// A 10 x 4 plate with two round holes (radius 1 and 0.7, one closed curve each) meshed coarsely:
// 10 and 6 edges around them, so each curve vertex turns 36 or 60 degrees and the face's angle
// there is 216 or 240 degrees. The unstructured mesh split it between two quads as about 178 / 40
// and smoothing left it (SICN 0.024 at --size 0.8, 0.064 and 0.074 at 1.2): the smoother's kernels
// never look at the angle at the curve. The lift after the final smoothing
// (smooth::lift_poor_quads) moves the interior vertex until the split is even.
TEST(ThinRegions, HoleArcVertexSplitEvenly) {
  BRepBuilderAPI_MakePolygon outline;
  for (const auto& [x, y] :
       std::vector<std::pair<double, double>>{{0, 0}, {10, 0}, {10, 4}, {0, 4}})
    outline.Add(gp_Pnt(x, y, 0));
  outline.Close();
  BRepBuilderAPI_MakeFace face(outline.Wire(), /*OnlyPlane=*/true);
  for (const auto& [x, r] :
       std::vector<std::pair<double, double>>{{10.0 / 3, 1.0}, {20.0 / 3, 0.7}}) {
    const gp_Circ circle(gp_Ax2(gp_Pnt(x, 2, 0), gp_Dir(0, 0, 1)), r);
    const TopoDS_Wire hole = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circle).Edge()).Wire();
    face.Add(TopoDS::Wire(hole.Reversed()));
  }
  ASSERT_TRUE(face.IsDone());
  const std::string model = tmp("thin_holes.brep");
  ASSERT_TRUE(BRepTools::Write(face.Face(), model.c_str()));
  for (const char* size : {"0.8", "1.2"}) {
    const ThinCheck c =
        mesh_and_check(model, std::string("--size ") + size, std::string("thin_holes_") + size);
    std::printf("holes at --size %s: %zu quads, SICN min %.3f\n", size, c.quads, c.sicn_min);
    EXPECT_TRUE(c.quads_at_sharp_corner.empty());
    EXPECT_GE(c.sicn_min, 0.1) << "--size " << size;
  }
}

}  // namespace
