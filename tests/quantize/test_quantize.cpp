#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepTools.hxx>
#include <TopoDS_Shape.hxx>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <gp_Pnt.hxx>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/quantize/quantize.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::quantize {
namespace {

std::string tmp(const std::string& name) { return qsmesh::test::tmp_dir() + "/" + name; }

cad::CadModel load(const TopoDS_Shape& shape, const std::string& name) {
  const std::string path = tmp(name);
  if (!BRepTools::Write(shape, path.c_str())) throw std::runtime_error("cannot write " + path);
  return cad::load_cad(path);
}

// A planar polygonal face through the given (x, y) points.
cad::CadModel polygon_face(const std::vector<std::pair<double, double>>& xy,
                           const std::string& name) {
  return cad::load_cad(test::write_polygon_face(xy, tmp(name)));
}

// Curves of face 0's outer loop, in loop order.
std::vector<LO> loop_curves(const cad::CadModel& model) {
  std::vector<LO> out;
  for (const auto& use : model.faces()[0].loops[0].uses) out.push_back(use.curve);
  return out;
}

// Ideal values given per loop use of face 0.
std::vector<double> ideal_by_use(const cad::CadModel& model, const std::vector<double>& by_use) {
  std::vector<double> ideal(static_cast<std::size_t>(model.num_curves()), 0.0);
  const auto loop = loop_curves(model);
  EXPECT_EQ(loop.size(), by_use.size());
  for (std::size_t k = 0; k < loop.size(); ++k) ideal[loop[k]] = by_use[k];
  return ideal;
}

std::vector<int> edges_by_use(const cad::CadModel& model, const Quantization& q) {
  std::vector<int> out;
  for (const LO c : loop_curves(model)) out.push_back(q.edges[c]);
  return out;
}

// Arc length along a polyline, at each vertex.
std::vector<double> arc_length(const std::vector<Vec3>& p) {
  std::vector<double> x(p.size(), 0.0);
  for (std::size_t i = 1; i < p.size(); ++i) x[i] = x[i - 1] + distance(p[i - 1], p[i]);
  return x;
}

const cad::CadModel& rectangle() {
  static const cad::CadModel model =
      polygon_face({{0, 0}, {10, 0}, {10, 4}, {0, 4}}, "q_rect.brep");
  return model;
}

const cad::CadModel& box() {
  static const cad::CadModel model =
      load(BRepPrimAPI_MakeBox(10.0, 6.0, 4.0).Shape(), "q_box.brep");
  return model;
}

// Box ideals: curves of length 10, 6, 4 around 14.6, 8.6, 6.4, alternately 0.9 below and above,
// so that rounding each curve alone would give different counts within a chord.
std::vector<double> box_ideals(const cad::CadModel& model) {
  const std::map<long, double> base{{10, 14.6}, {6, 8.6}, {4, 6.4}};
  std::map<long, int> seen;
  std::vector<double> ideal;
  for (const auto& c : model.curves()) {
    const long len = std::lround(c.length);
    ideal.push_back(base.at(len) + (seen[len]++ % 2 == 0 ? -0.9 : 0.9));
  }
  return ideal;
}

TEST(Quantize, PaperRectangleGetsEqualOppositeSides) {
  const auto& model = rectangle();
  ASSERT_EQ(model.num_faces(), 1);
  ASSERT_EQ(model.faces()[0].loops[0].uses.size(), 4u);
  const auto ideal = ideal_by_use(model, {9.4, 4.1, 10.6, 3.9});
  const Quantization q = quantize_curves(model, ideal, {});
  EXPECT_EQ(edges_by_use(model, q), (std::vector<int>{10, 4, 10, 4}));
  EXPECT_EQ(q.num_chords, 2);
  const auto loop = loop_curves(model);
  EXPECT_EQ(q.curve2chord[loop[0]], q.curve2chord[loop[2]]);
  EXPECT_EQ(q.curve2chord[loop[1]], q.curve2chord[loop[3]]);
  EXPECT_NE(q.curve2chord[loop[0]], q.curve2chord[loop[1]]);
  EXPECT_EQ(q.total_edges, 28);
  EXPECT_EQ(q.ideal, ideal);

  QuantizeOptions odd_ok;
  odd_ok.even = false;  // plain rounding would give [9, 4, 11, 4]
  EXPECT_EQ(edges_by_use(model, quantize_curves(model, ideal, odd_ok)),
            (std::vector<int>{10, 4, 10, 4}));
}

TEST(Quantize, FiveSidedFaceIsRoundedCurveByCurve) {
  const auto model = polygon_face({{0, 0}, {10, 0}, {12, 3}, {6, 7}, {0, 4}}, "q_penta.brep");
  ASSERT_EQ(model.faces()[0].loops[0].uses.size(), 5u);
  const auto ideal = ideal_by_use(model, {9.4, 4.1, 11.2, 3.9, 6.8});
  const Quantization q = quantize_curves(model, ideal, {});
  EXPECT_EQ(edges_by_use(model, q), (std::vector<int>{10, 4, 12, 4, 6}));
  EXPECT_EQ(q.num_chords, 0);
  for (const LO ch : q.curve2chord) EXPECT_EQ(ch, kNoIndex);

  QuantizeOptions odd_ok;
  odd_ok.even = false;
  EXPECT_EQ(edges_by_use(model, quantize_curves(model, ideal, odd_ok)),
            (std::vector<int>{9, 4, 11, 4, 7}));
}

TEST(Quantize, BoxChordsGoAroundTheBox) {
  const auto& model = box();
  ASSERT_EQ(model.num_curves(), 12);
  ASSERT_EQ(model.num_faces(), 6);
  const auto ideal = box_ideals(model);
  const Quantization q = quantize_curves(model, ideal, {});
  EXPECT_EQ(q.num_chords, 3);
  // Each chord holds the 4 curves of one direction (one length), all with the same count: the
  // even rounding of their average ideal value (14.6, 8.6, 6.4 -> 14, 8, 6).
  const std::map<long, int> expected{{10, 14}, {6, 8}, {4, 6}};
  std::map<LO, std::set<long>> chord_lengths;
  std::map<LO, int> chord_size;
  std::int64_t total = 0;
  for (LO c = 0; c < model.num_curves(); ++c) {
    const long len = std::lround(model.curves()[c].length);
    ASSERT_NE(q.curve2chord[c], kNoIndex) << "curve " << c;
    chord_lengths[q.curve2chord[c]].insert(len);
    ++chord_size[q.curve2chord[c]];
    EXPECT_EQ(q.edges[c], expected.at(len)) << "curve " << c << " ideal " << ideal[c];
    total += q.edges[c];
  }
  for (const auto& [ch, lengths] : chord_lengths) {
    EXPECT_EQ(lengths.size(), 1u) << "chord " << ch;
    EXPECT_EQ(chord_size[ch], 4) << "chord " << ch;
  }
  EXPECT_EQ(q.total_edges, total);
  EXPECT_EQ(total, 4 * (14 + 8 + 6));
  // Deterministic.
  const Quantization again = quantize_curves(model, ideal, {});
  EXPECT_EQ(again.edges, q.edges);
  EXPECT_EQ(again.curve2chord, q.curve2chord);
}

TEST(Quantize, PrescribedEvenCountFixesItsChord) {
  const auto& model = box();
  const auto ideal = box_ideals(model);
  const Quantization free = quantize_curves(model, ideal, {});
  QuantizeOptions options;
  options.prescribed = {{0, 20}};
  const Quantization q = quantize_curves(model, ideal, options);
  EXPECT_EQ(q.edges[0], 20);
  for (LO c = 0; c < model.num_curves(); ++c) {
    if (q.curve2chord[c] == q.curve2chord[0])
      EXPECT_EQ(q.edges[c], 20) << "curve " << c;
    else
      EXPECT_EQ(q.edges[c], free.edges[c]) << "curve " << c;
  }
  // Two agreeing prescriptions in one chord are fine.
  LO partner = kNoIndex;
  for (LO c = 1; c < model.num_curves(); ++c)
    if (q.curve2chord[c] == q.curve2chord[0]) partner = c;
  ASSERT_NE(partner, kNoIndex);
  options.prescribed = {{0, 20}, {partner, 20}};
  EXPECT_EQ(quantize_curves(model, ideal, options).edges[partner], 20);
  // An odd prescription is kept when odd counts are allowed.
  options.prescribed = {{0, 7}};
  options.even = false;
  const Quantization odd = quantize_curves(model, ideal, options);
  EXPECT_EQ(odd.edges[0], 7);
  EXPECT_EQ(odd.edges[partner], 7);
}

// Every loop of every face even, and every stretch of a loop between two of its poles: what
// midpoint subdivision of the halved boundaries needs.
void expect_even_loops(const cad::CadModel& model, const Quantization& q, const char* what) {
  for (LO f = 0; f < model.num_faces(); ++f)
    for (std::size_t l = 0; l < model.faces()[f].loops.size(); ++l) {
      const auto& uses = model.faces()[f].loops[l].uses;
      int sum = 0;
      std::vector<int> between_poles{0};
      for (const auto& use : uses) {
        sum += q.edges[use.curve];
        if (model.curves()[use.curve].degenerate)
          between_poles.push_back(0);
        else
          between_poles.back() += q.edges[use.curve];
      }
      EXPECT_EQ(sum % 2, 0) << what << ": face " << f << " loop " << l;
      if (between_poles.size() > 2) {
        between_poles.front() += between_poles.back();  // the stretch through the loop's start
        between_poles.pop_back();
        for (const int s : between_poles) EXPECT_EQ(s % 2, 0) << what << ": face " << f;
      }
    }
}

const cad::CadModel& pentagon() {
  static const cad::CadModel model =
      polygon_face({{0, 0}, {10, 0}, {12, 5}, {5, 9}, {-2, 5}}, "q_pentagon.brep");
  return model;
}

TEST(Quantize, OddPrescriptionsOnTwoCurvesOfOneLoopAreKept) {
  const auto& model = pentagon();
  const auto ideal = ideal_by_use(model, {6.2, 8.1, 5.9, 7.0, 6.4});
  const auto loop = loop_curves(model);
  EXPECT_EQ(edges_by_use(model, quantize_curves(model, ideal, {})),
            (std::vector<int>{6, 8, 6, 8, 6}));
  QuantizeOptions options;
  // Two odd counts: the loop is even as it stands, the other curves keep their even counts.
  options.prescribed = {{loop[0], 7}, {loop[2], 5}};
  const Quantization two = quantize_curves(model, ideal, options);
  EXPECT_EQ(edges_by_use(model, two), (std::vector<int>{7, 8, 5, 8, 6}));
  // One odd count: the curve that changes least for it takes an odd count too (7.0 ideal: 7).
  options.prescribed = {{loop[0], 7}};
  const Quantization one = quantize_curves(model, ideal, options);
  EXPECT_EQ(edges_by_use(model, one), (std::vector<int>{7, 8, 6, 7, 6}));
  // Without parity (odd counts everywhere allowed) nothing is adjusted.
  options.even = false;
  EXPECT_EQ(edges_by_use(model, quantize_curves(model, ideal, options)),
            (std::vector<int>{7, 8, 6, 7, 6}));
}

TEST(Quantize, OddCountOnAFourSidedFaceIsHonouredByItsOppositeSide) {
  const auto& model = rectangle();
  const auto loop = loop_curves(model);
  QuantizeOptions options;
  options.prescribed = {{loop[1], 5}};
  // Joined opposite sides (a chord): the opposite side takes the prescription.
  const Quantization joined =
      quantize_curves(model, ideal_by_use(model, {9.4, 4.1, 10.6, 3.9}), options);
  EXPECT_EQ(edges_by_use(model, joined), (std::vector<int>{10, 5, 10, 5}));
  // Sides too different to be joined (3.1 against 7.4 ideal edges): parity alone makes the
  // opposite side odd, at the odd count nearest its ideal, rather than a long side.
  options.prescribed = {{loop[1], 3}};
  const Quantization apart =
      quantize_curves(model, ideal_by_use(model, {10.2, 3.1, 9.8, 7.4}), options);
  EXPECT_EQ(apart.curve2chord[loop[1]], kNoIndex);
  EXPECT_EQ(edges_by_use(model, apart), (std::vector<int>{10, 3, 10, 7}));
}

TEST(Quantize, OddPrescriptionsOnABoxKeepEveryLoopEven) {
  const auto& model = box();
  const auto ideal = box_ideals(model);
  const Quantization free = quantize_curves(model, ideal, {});
  // Curve 0 and a curve of another chord, both odd.
  LO other = kNoIndex;
  for (LO c = 1; c < model.num_curves() && other == kNoIndex; ++c)
    if (free.curve2chord[c] != free.curve2chord[0]) other = c;
  ASSERT_NE(other, kNoIndex);
  QuantizeOptions options;
  options.prescribed = {{0, 7}, {other, 5}};
  const Quantization q = quantize_curves(model, ideal, options);
  EXPECT_EQ(q.edges[0], 7);
  EXPECT_EQ(q.edges[other], 5);
  for (LO c = 0; c < model.num_curves(); ++c) {
    if (q.curve2chord[c] == q.curve2chord[0]) {
      EXPECT_EQ(q.edges[c], 7) << "curve " << c;
    }
    if (q.curve2chord[c] == q.curve2chord[other]) {
      EXPECT_EQ(q.edges[c], 5) << "curve " << c;
    }
  }
  expect_even_loops(model, q, "box");
  EXPECT_NO_THROW(check_prescription_parity(model, options.prescribed));
}

// The message of quantize_curves and of check_prescription_parity for `prescribed`.
std::pair<std::string, std::string> refusals(const cad::CadModel& model,
                                             const std::vector<std::pair<LO, int>>& prescribed,
                                             const std::vector<double>& ideal) {
  std::pair<std::string, std::string> out;
  QuantizeOptions options;
  options.prescribed = prescribed;
  try {
    (void)quantize_curves(model, ideal, options);
  } catch (const InputError& e) {
    out.first = e.what();
  }
  try {
    check_prescription_parity(model, prescribed);
  } catch (const InputError& e) {
    out.second = e.what();
  }
  return out;
}

TEST(Quantize, OddPrescriptionNoEvenLoopCanHoldIsRefusedNamingTheLoop) {
  // A triangle whose three curves are prescribed 7, 4 and 4: an odd loop whatever happens.
  const auto tri = polygon_face({{0, 0}, {10, 0}, {4, 7}}, "q_triangle.brep");
  const auto loop = loop_curves(tri);
  const auto ideal = ideal_by_use(tri, {8, 8, 8});
  std::vector<std::pair<LO, int>> all{{loop[0], 7}, {loop[1], 4}, {loop[2], 4}};
  const auto [late, early] = refusals(tri, all, ideal);
  std::ostringstream want;
  std::vector<LO> sorted = loop;
  std::sort(sorted.begin(), sorted.end());
  std::map<LO, int> count{{loop[0], 7}, {loop[1], 4}, {loop[2], 4}};
  want << "face 0 (loop 0): its prescribed curves " << sorted[0] << ":" << count[sorted[0]] << ", "
       << sorted[1] << ":" << count[sorted[1]] << ", " << sorted[2] << ":" << count[sorted[2]]
       << " sum to 15 edges and no other curve of it can make the count even; all-quad meshing "
          "by midpoint subdivision needs an even count on every loop";
  EXPECT_EQ(late, want.str());
  EXPECT_EQ(early, want.str());
  // Two of them prescribed: the third takes what the loop needs.
  QuantizeOptions options;
  options.prescribed = {{loop[0], 7}, {loop[1], 4}};
  EXPECT_EQ(quantize_curves(tri, ideal, options).edges[loop[2]] % 2, 1);
  // Two faces of a box sharing the one curve that neither prescribes: the first needs it odd, the
  // second even. No single loop is at fault; the message names both.
  const auto& box_model = box();
  const auto& faces = box_model.faces();
  LO shared = kNoIndex, other_face = kNoIndex;
  for (LO g = 1; g < box_model.num_faces() && shared == kNoIndex; ++g)
    for (const auto& u : faces[0].loops[0].uses)
      for (const auto& w : faces[g].loops[0].uses)
        if (u.curve == w.curve) {
          shared = u.curve;
          other_face = g;
        }
  ASSERT_NE(shared, kNoIndex);
  std::vector<std::pair<LO, int>> split;
  int k = 0;
  for (const LO f : {LO{0}, other_face})
    for (const auto& u : faces[f].loops[0].uses)
      if (u.curve != shared) split.emplace_back(u.curve, f == 0 && k++ == 0 ? 3 : 2);
  try {
    check_prescription_parity(box_model, split);
    ADD_FAILURE() << "two loops of opposite needs accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("the loops of face 0 (loop 0), face " + std::to_string(other_face) +
                            " (loop 0) cannot all have even counts",
                        0),
              0u)
        << msg;
    EXPECT_NE(msg.find("(13 edges)"), std::string::npos) << msg;
  }
}

TEST(Quantize, SeamBetweenTwoPolesMustBeEven) {
  // A sphere: one loop (seam, pole, seam, pole); each pole must sit on a halved vertex, so the
  // seam's count alone must be even.
  const auto sphere = cad::load_cad(test::write_sphere(tmp("q_sphere.brep")));
  LO seam = kNoIndex;
  for (LO c = 0; c < sphere.num_curves(); ++c)
    if (!sphere.curves()[c].degenerate) seam = c;
  ASSERT_NE(seam, kNoIndex);
  const auto [late, early] =
      refusals(sphere, {{seam, 7}}, std::vector<double>(sphere.num_curves(), 6.0));
  EXPECT_NE(late.find("between two poles"), std::string::npos) << late;
  EXPECT_EQ(late, early);
  EXPECT_TRUE(
      refusals(sphere, {{seam, 8}}, std::vector<double>(sphere.num_curves(), 6.0)).first.empty());
}

TEST(Quantize, CylinderTakesAnOddCircleOnBothOfItsCircles) {
  // The side of a cylinder: its loop holds both circles once and the seam twice, so an odd
  // bottom circle makes the top one odd; each disk, though, is bounded by its circle alone.
  const auto cyl = cad::load_cad(test::write_cylinder(tmp("q_cyl.brep")));
  LO circle = kNoIndex;
  for (LO c = cyl.num_curves() - 1; c >= 0; --c)
    if (cyl.curves()[c].corners[0] == cyl.curves()[c].corners[1] && !cyl.curves()[c].degenerate)
      circle = c;
  ASSERT_NE(circle, kNoIndex);
  const auto [late, early] =
      refusals(cyl, {{circle, 9}}, std::vector<double>(cyl.num_curves(), 8.0));
  EXPECT_NE(late.find("(loop 0)"), std::string::npos) << late;
  EXPECT_EQ(late, early);
}

TEST(Quantize, SliversTakeOneEdgeWithTheOption) {
  // A strip 10 x 0.3 sized 1: its ends are slivers (0.3 ideal edges).
  const auto strip = polygon_face({{0, 0}, {10, 0}, {10, 0.3}, {0, 0.3}}, "q_strip.brep");
  const auto ideal = ideal_by_use(strip, {10.0, 0.3, 10.0, 0.3});
  EXPECT_EQ(edges_by_use(strip, quantize_curves(strip, ideal, {})),
            (std::vector<int>{10, 2, 10, 2}));
  QuantizeOptions options;
  options.odd_slivers = true;
  EXPECT_EQ(edges_by_use(strip, quantize_curves(strip, ideal, options)),
            (std::vector<int>{10, 1, 10, 1}));
  // A pentagon with one sliver: another curve becomes odd with it.
  const auto& model = pentagon();
  const auto pent = ideal_by_use(model, {6.2, 0.4, 5.9, 7.0, 6.4});
  const Quantization q = quantize_curves(model, pent, options);
  EXPECT_EQ(edges_by_use(model, q), (std::vector<int>{6, 1, 6, 7, 6}));
  expect_even_loops(model, q, "pentagon with a sliver");
}

TEST(Quantize, CurvesShorterThanTheSliverLengthTakeOneEdge) {
  // The strip 10 x 0.3 with ends sized as 2 edges each (ideal 2: no sliver by count): the ends
  // take 1 edge when shorter than sliver_length, 2 otherwise.
  const auto strip = polygon_face({{0, 0}, {10, 0}, {10, 0.3}, {0, 0.3}}, "q_strip_len.brep");
  const auto ideal = ideal_by_use(strip, {10.0, 2.0, 10.0, 2.0});
  QuantizeOptions options;
  options.odd_slivers = true;  // the count rule alone keeps them at 2
  EXPECT_EQ(edges_by_use(strip, quantize_curves(strip, ideal, options)),
            (std::vector<int>{10, 2, 10, 2}));
  options.odd_slivers = false;
  options.sliver_length = 0.5;
  const Quantization q = quantize_curves(strip, ideal, options);
  EXPECT_EQ(edges_by_use(strip, q), (std::vector<int>{10, 1, 10, 1}));
  expect_even_loops(strip, q, "strip with short ends");
  options.sliver_length = 0.2;
  EXPECT_EQ(edges_by_use(strip, quantize_curves(strip, ideal, options)),
            (std::vector<int>{10, 2, 10, 2}));
  // A prescription wins over the length rule.
  options.sliver_length = 0.5;
  LO end = kNoIndex;
  for (LO c = 0; c < strip.num_curves(); ++c)
    if (strip.curves()[c].length < 1) end = c;
  ASSERT_NE(end, kNoIndex);
  options.prescribed = {{end, 2}};
  const Quantization p = quantize_curves(strip, ideal, options);
  EXPECT_EQ(p.edges[end], 2);
  expect_even_loops(strip, p, "strip with a prescribed end");
}

TEST(Quantize, RefinementKeepsEachCountsParity) {
  Quantization q;
  q.edges = {7, 4, 1};
  q.curve2chord = {kNoIndex, kNoIndex, kNoIndex};
  refine_curves(q, std::vector<LO>{0, 1, 2});
  EXPECT_EQ(q.edges, (std::vector<int>{15, 8, 3}));
  EXPECT_EQ(q.total_edges, 26);
}

TEST(Quantize, ConflictingPrescriptionsAreRefused) {
  const auto& model = box();
  const auto ideal = box_ideals(model);
  const Quantization q = quantize_curves(model, ideal, {});
  LO partner = kNoIndex, other = kNoIndex;
  for (LO c = 1; c < model.num_curves(); ++c) {
    if (q.curve2chord[c] == q.curve2chord[0])
      partner = c;
    else
      other = c;
  }
  ASSERT_NE(partner, kNoIndex);
  QuantizeOptions options;
  options.prescribed = {{0, 14}, {partner, 16}};
  try {
    (void)quantize_curves(model, ideal, options);
    FAIL() << "conflicting prescriptions accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("curves 0 and " + std::to_string(partner) + " ", 0), 0u) << msg;
    EXPECT_NE(msg.find("14"), std::string::npos) << msg;
    EXPECT_NE(msg.find("16"), std::string::npos) << msg;
    std::cout << msg << "\n";
  }
  // Different counts on curves of different chords are fine.
  options.prescribed = {{0, 14}, {other, 16}};
  const Quantization ok = quantize_curves(model, ideal, options);
  EXPECT_EQ(ok.edges[0], 14);
  EXPECT_EQ(ok.edges[other], 16);
  // Unknown curve, non-positive count.
  options.prescribed = {{model.num_curves(), 4}};
  EXPECT_THROW((void)quantize_curves(model, ideal, options), InputError);
  options.prescribed = {{0, 0}};
  EXPECT_THROW((void)quantize_curves(model, ideal, options), InputError);
}

TEST(Quantize, RatioLimitKeepsVeryDifferentSidesApart) {
  const auto& model = rectangle();
  const auto ideal = ideal_by_use(model, {10, 4, 40, 4});
  const auto loop = loop_curves(model);
  const Quantization q = quantize_curves(model, ideal, {});
  EXPECT_EQ(edges_by_use(model, q), (std::vector<int>{10, 4, 40, 4}));
  EXPECT_EQ(q.curve2chord[loop[0]], kNoIndex);
  EXPECT_EQ(q.curve2chord[loop[2]], kNoIndex);
  EXPECT_NE(q.curve2chord[loop[1]], kNoIndex);
  EXPECT_EQ(q.curve2chord[loop[1]], q.curve2chord[loop[3]]);
  EXPECT_EQ(q.num_chords, 1);
  // A looser limit joins them: average 25 -> 26.
  QuantizeOptions loose;
  loose.chord_ratio_limit = 5;
  const Quantization j = quantize_curves(model, ideal, loose);
  EXPECT_EQ(edges_by_use(model, j), (std::vector<int>{26, 4, 26, 4}));
  EXPECT_EQ(j.num_chords, 2);
}

// A trapezoid whose bases differ 2.5 times in length: a size map finer at the short base gives
// ideal counts only 1.5 times apart, within chord_ratio_limit, but a grid would have cells 2.5
// times wider at one end than at the other; the bases stay apart. Its legs, as long as each
// other, are joined.
TEST(Quantize, LengthLimitKeepsBasesOfATaperedFaceApart) {
  const cad::CadModel model =
      polygon_face({{0, 0}, {10, 0}, {7, 4}, {3, 4}}, "q_taper.brep");  // bases 10 and 4
  const auto ideal = ideal_by_use(model, {12, 5, 8, 5});
  const auto loop = loop_curves(model);
  const Quantization q = quantize_curves(model, ideal, {});
  EXPECT_EQ(q.curve2chord[loop[0]], kNoIndex);
  EXPECT_EQ(q.curve2chord[loop[2]], kNoIndex);
  EXPECT_NE(q.curve2chord[loop[1]], kNoIndex);
  EXPECT_EQ(q.curve2chord[loop[1]], q.curve2chord[loop[3]]);
  EXPECT_EQ(edges_by_use(model, q), (std::vector<int>{12, 6, 8, 6}));
  EXPECT_EQ(q.num_chords, 1);
  // Without the length limit the ideal counts alone join them: average 10 for both bases.
  QuantizeOptions by_counts;
  by_counts.chord_length_ratio_limit = 100;
  const Quantization j = quantize_curves(model, ideal, by_counts);
  EXPECT_NE(j.curve2chord[loop[0]], kNoIndex);
  EXPECT_EQ(j.curve2chord[loop[0]], j.curve2chord[loop[2]]);
  EXPECT_EQ(edges_by_use(model, j), (std::vector<int>{10, 6, 10, 6}));
  EXPECT_EQ(j.num_chords, 2);
}

TEST(Quantize, CoarseArcCuttingItsNeighbourIsFound) {
  // Half annulus of radii 9 and 10: the outer arc with 2 edges is the chord from (10, 0) to
  // (0, 10) and on to (-10, 0), 7.07 from the centre, across the inner arc (radius 9).
  const cad::CadModel model =
      cad::load_cad(test::write_half_annulus(9.0, 10.0, tmp("q_annulus.brep")));
  ASSERT_EQ(model.num_faces(), 1);
  const auto loop = loop_curves(model);
  ASSERT_EQ(loop.size(), 4u);
  LO outer = kNoIndex, inner = kNoIndex;
  for (const LO c : loop) {
    const double len = model.curves()[c].length;
    if (std::abs(len - 10 * M_PI) < 1e-6) outer = c;
    if (std::abs(len - 9 * M_PI) < 1e-6) inner = c;
  }
  ASSERT_NE(outer, kNoIndex);
  ASSERT_NE(inner, kNoIndex);
  const auto meshes = [&](LO outer_edges, LO inner_edges) {
    std::vector<mesh::CurveMesh> m;
    for (LO c = 0; c < model.num_curves(); ++c)
      m.push_back(test::uniform_curve_mesh(model, c,
                                           c == outer   ? outer_edges
                                           : c == inner ? inner_edges
                                                        : 2));
    return m;
  };
  EXPECT_EQ(crossing_curves(model, 0, meshes(2, 8)),
            (std::vector<LO>{std::min(outer, inner), std::max(outer, inner)}));
  // Equal counts give similar polygons, which do not cross; nor does a fine outer arc.
  EXPECT_TRUE(crossing_curves(model, 0, meshes(2, 2)).empty());
  EXPECT_TRUE(crossing_curves(model, 0, meshes(16, 8)).empty());
}

TEST(Quantize, LoopOfTwoSegmentsIsFound) {
  // A half disk: arc and diameter join the same two corners. With one edge each (halved meshes
  // of 2-edge curves) the loop encloses nothing; with two each it is a triangle.
  const cad::CadModel model = cad::load_cad(test::write_half_disk(5.0, tmp("q_half_disk.brep")));
  ASSERT_EQ(model.num_faces(), 1);
  ASSERT_EQ(model.num_curves(), 2);
  const auto meshes = [&](LO n) {
    std::vector<mesh::CurveMesh> m;
    for (LO c = 0; c < model.num_curves(); ++c) m.push_back(test::uniform_curve_mesh(model, c, n));
    return m;
  };
  EXPECT_EQ(crossing_curves(model, 0, meshes(1)), (std::vector<LO>{0, 1}));
  EXPECT_TRUE(crossing_curves(model, 0, meshes(2)).empty());
}

TEST(Quantize, RefinedCurvesTakeTheirChordAlong) {
  Quantization q;
  q.edges = {4, 4, 6, 2, 2, 0};
  q.curve2chord = {0, 0, kNoIndex, 1, 1, kNoIndex};
  q.num_chords = 2;
  refine_curves(q, std::vector<LO>{0, 2, 5});
  EXPECT_EQ(q.edges, (std::vector<int>{8, 8, 12, 2, 2, 0}));  // 5 is degenerate (no edges)
  EXPECT_EQ(q.total_edges, 32);
  // A chord holding a prescribed curve keeps its counts.
  refine_curves(q, std::vector<LO>{3}, std::vector<LO>{4});
  EXPECT_EQ(q.edges, (std::vector<int>{8, 8, 12, 2, 2, 0}));
  refine_curves(q, std::vector<LO>{4});
  EXPECT_EQ(q.edges, (std::vector<int>{8, 8, 12, 4, 4, 0}));
}

TEST(Quantize, ClosedAndDegenerateCurves) {
  const cad::CadModel cyl = cad::load_cad(test::write_cylinder(tmp("q_cyl.brep")));
  std::vector<double> ideal(static_cast<std::size_t>(cyl.num_curves()), 1.0);
  std::vector<LO> circles;
  for (LO c = 0; c < cyl.num_curves(); ++c)
    if (cyl.curves()[c].corners[0] == cyl.curves()[c].corners[1]) circles.push_back(c);
  ASSERT_EQ(circles.size(), 2u);
  ideal[circles[0]] = 0.5;
  ideal[circles[1]] = 0.7;
  // Small circles: at least 4 edges (closed), the two circles in one chord (side face).
  Quantization q = quantize_curves(cyl, ideal, {});
  EXPECT_EQ(q.edges[circles[0]], 4);
  EXPECT_EQ(q.edges[circles[1]], 4);
  EXPECT_NE(q.curve2chord[circles[0]], kNoIndex);
  EXPECT_EQ(q.curve2chord[circles[0]], q.curve2chord[circles[1]]);
  // 4.9 and 7.0 alone would round to 4 and 8; the chord average 5.95 gives 6 to both.
  ideal[circles[0]] = 4.9;
  ideal[circles[1]] = 7.0;
  q = quantize_curves(cyl, ideal, {});
  EXPECT_EQ(q.edges[circles[0]], 6);
  EXPECT_EQ(q.edges[circles[1]], 6);
  QuantizeOptions coarse;
  coarse.halved_minimums = true;
  ideal[circles[0]] = ideal[circles[1]] = 0.5;
  q = quantize_curves(cyl, ideal, coarse);
  EXPECT_EQ(q.edges[circles[0]], 6);  // 3 before midpoint subdivision
  QuantizeOptions bad;
  bad.even = false;
  bad.prescribed = {{circles[0], 2}};
  EXPECT_THROW((void)quantize_curves(cyl, ideal, bad), InputError);

  // Sphere: the poles are degenerate: 0 edges, and place_vertices keeps their single edge.
  const cad::CadModel sphere = cad::load_cad(test::write_sphere(tmp("q_sphere.brep")));
  background::SizeOptions so;
  so.size = 0.5;
  const TaskArena tasks(2);
  const auto bg = background::mesh_curves(sphere, so, tasks);
  std::vector<std::vector<double>> sizes;
  for (const auto& m : bg) sizes.emplace_back(m.points.size(), 0.5);
  const auto sq = quantize_curves(sphere, ideal_edge_counts(bg, sizes), {});
  const auto meshes = place_vertices(sphere, bg, sizes, sq, false, tasks);
  int poles = 0;
  for (LO c = 0; c < sphere.num_curves(); ++c) {
    if (!sphere.curves()[c].degenerate) {
      EXPECT_EQ(meshes[c].num_edges(), sq.edges[c]);
      continue;
    }
    ++poles;
    EXPECT_EQ(sq.edges[c], 0);
    EXPECT_EQ(sq.curve2chord[c], kNoIndex);
    EXPECT_EQ(meshes[c].num_edges(), 1);
  }
  EXPECT_EQ(poles, 2);
}

TEST(IdealEdgeCounts, StraightLine) {
  const auto& model = rectangle();
  std::vector<mesh::CurveMesh> bg;
  for (LO c = 0; c < model.num_curves(); ++c) bg.push_back(test::uniform_curve_mesh(model, c, 17));
  // Constant size: L / s.
  std::vector<std::vector<double>> sizes;
  for (const auto& m : bg) sizes.emplace_back(m.points.size(), 0.37);
  auto ideal = ideal_edge_counts(bg, sizes);
  for (LO c = 0; c < model.num_curves(); ++c)
    EXPECT_NEAR(ideal[c], model.curves()[c].length / 0.37, 1e-9) << "curve " << c;
  // Size linear in arc length, s = a + b x: (1/b) ln((a + b L) / a).
  sizes.clear();
  for (const auto& m : bg) {
    std::vector<double> s;
    for (const double x : arc_length(m.points)) s.push_back(0.2 + 0.08 * x);
    sizes.push_back(s);
  }
  ideal = ideal_edge_counts(bg, sizes);
  for (LO c = 0; c < model.num_curves(); ++c) {
    const double len = model.curves()[c].length;
    EXPECT_NEAR(ideal[c], std::log((0.2 + 0.08 * len) / 0.2) / 0.08, 1e-9) << "curve " << c;
  }
  sizes[0][3] = 0;
  EXPECT_THROW((void)ideal_edge_counts(bg, sizes), Error);
}

TEST(PlaceVertices, Eq11SpacingFollowsTheSize) {
  const auto& model = rectangle();
  std::vector<mesh::CurveMesh> bg;
  std::vector<std::vector<double>> sizes;
  const auto s_at = [](double x) { return 0.2 + 0.08 * x; };
  for (LO c = 0; c < model.num_curves(); ++c) {
    bg.push_back(test::uniform_curve_mesh(model, c, 40));
    std::vector<double> s;
    for (const double x : arc_length(bg.back().points)) s.push_back(s_at(x));
    sizes.push_back(s);
  }
  const auto ideal = ideal_edge_counts(bg, sizes);
  const Quantization q = quantize_curves(model, ideal, {});
  const TaskArena tasks(2);
  PlaceOptions own;  // each curve by its own size integral (Eq. 11 as written)
  own.align_chords = false;
  for (const bool halved : {false, true}) {
    const auto meshes = place_vertices(model, bg, sizes, q, halved, tasks, own);
    ASSERT_EQ(static_cast<LO>(meshes.size()), model.num_curves());
    for (LO c = 0; c < model.num_curves(); ++c) {
      const auto& m = meshes[c];
      const auto& curve = model.curves()[c];
      const int n = halved ? q.edges[c] / 2 : q.edges[c];
      ASSERT_EQ(m.num_edges(), n) << "curve " << c;
      EXPECT_EQ(m.curve, c);
      EXPECT_EQ(m.points.front(), model.corners()[curve.corners[0]].point);
      EXPECT_EQ(m.points.back(), model.corners()[curve.corners[1]].point);
      EXPECT_EQ(m.t.front(), curve.t0);
      EXPECT_EQ(m.t.back(), curve.t1);
      for (LO i = 0; i < n; ++i) ASSERT_GT(m.t[i + 1], m.t[i]);
      if (std::lround(curve.length) != 10) continue;
      // The long sides: 20.1 ideal -> 20 edges (10 halved). Each edge holds 1/n of the integral
      // (Eq. 11, exact here: straight line, s linear), so edges grow with s.
      EXPECT_EQ(n, halved ? 10 : 20);
      const auto x = arc_length(m.points);
      double previous = 0;
      for (LO i = 0; i < n; ++i) {
        const double e = x[i + 1] - x[i];
        const double integral = std::log(s_at(x[i + 1]) / s_at(x[i])) / 0.08;
        EXPECT_NEAR(integral, ideal[c] / n, 1e-6) << "curve " << c << " edge " << i;
        const double predicted = s_at((x[i] + x[i + 1]) / 2) * ideal[c] / n;
        EXPECT_NEAR(e / predicted, 1.0, 0.1) << "curve " << c << " edge " << i;
        EXPECT_GT(e, previous);
        previous = e;
      }
      EXPECT_GT((x[n] - x[n - 1]) / (x[1] - x[0]), 3.0);
    }
  }
}

// Every curve of the model graded along its own direction, s = 0.2 + 0.08 x (3:1 over the
// rectangle's long sides): its top and bottom sides run in opposite directions, so by Eq. 11
// alone a grid fill would shear (bottom fine at x = 0, top fine at x = 10).
struct GradedCurves {
  std::vector<mesh::CurveMesh> bg;
  std::vector<std::vector<double>> sizes;
  explicit GradedCurves(const cad::CadModel& model) {
    for (LO c = 0; c < model.num_curves(); ++c) {
      bg.push_back(test::uniform_curve_mesh(model, c, 40));
      std::vector<double> s;
      for (const double x : arc_length(bg.back().points)) s.push_back(0.2 + 0.08 * x);
      sizes.push_back(s);
    }
  }
};

// Edge lengths of the long sides (length 10) in increasing x, bottom first.
std::vector<std::vector<double>> long_side_xs(const cad::CadModel& model,
                                              const std::vector<mesh::CurveMesh>& meshes) {
  std::vector<std::vector<double>> out;
  for (LO c = 0; c < model.num_curves(); ++c) {
    if (std::lround(model.curves()[c].length) != 10) continue;
    std::vector<double> x;
    for (const auto& p : meshes[c].points) x.push_back(p.x);
    std::sort(x.begin(), x.end());
    out.push_back(x);
  }
  return out;
}

TEST(PlaceVertices, OppositeSidesOfAGridFaceShareTheirSpacing) {
  const auto& model = rectangle();
  const GradedCurves r(model);
  const Quantization q = quantize_curves(model, ideal_edge_counts(r.bg, r.sizes), {});
  const TaskArena tasks(2);
  for (const bool halved : {false, true}) {
    const auto xs = long_side_xs(model, place_vertices(model, r.bg, r.sizes, q, halved, tasks));
    ASSERT_EQ(xs.size(), 2u);
    ASSERT_EQ(xs[0].size(), xs[1].size());
    const std::size_t n = xs[0].size() - 1;
    EXPECT_EQ(n, halved ? 10u : 20u);
    // Same x on both sides: the grid's columns are straight.
    for (std::size_t i = 0; i <= n; ++i) EXPECT_NEAR(xs[0][i], xs[1][i], 1e-9) << "vertex " << i;
    // The mean of a profile and its mirror image is symmetric: both ends get the same spacing,
    // finer than the middle (1 / s is convex along the side).
    const double first = xs[0][1] - xs[0][0], last = xs[0][n] - xs[0][n - 1];
    const double middle = xs[0][n / 2 + 1] - xs[0][n / 2];
    EXPECT_NEAR(first / last, 1.0, 1e-3);
    EXPECT_LT(first, middle);
  }
  // The same curves placed each by its own integral: the two sides graded in opposite senses.
  PlaceOptions own;
  own.align_chords = false;
  const auto xs = long_side_xs(model, place_vertices(model, r.bg, r.sizes, q, false, tasks, own));
  EXPECT_GT(std::abs(xs[0][10] - xs[1][10]), 1.0);
}

TEST(PlaceVertices, FacesWithOneJoinedPairKeepTheirOwnSpacing) {
  // The short sides out of their chord (as when their ideal counts differ beyond the chord ratio):
  // only the long sides are joined, so the face is no grid and its sides keep the spacing their
  // sizes ask for.
  const auto& model = rectangle();
  const GradedCurves r(model);
  std::vector<double> ideal = ideal_edge_counts(r.bg, r.sizes);
  const Quantization joined = quantize_curves(model, ideal, {});
  Quantization q = joined;
  const auto loop = loop_curves(model);
  for (std::size_t k = 0; k < loop.size(); ++k)
    if (std::lround(model.curves()[loop[k]].length) == 4) q.curve2chord[loop[k]] = kNoIndex;
  const TaskArena tasks(1);
  const auto xs = long_side_xs(model, place_vertices(model, r.bg, r.sizes, q, false, tasks));
  ASSERT_EQ(xs.size(), 2u);
  EXPECT_GT(std::abs(xs[0][10] - xs[1][10]), 1.0);
  PlaceOptions bad;
  bad.profile_samples = 1;
  EXPECT_THROW((void)place_vertices(model, r.bg, r.sizes, joined, false, tasks, bad), Error);
}

TEST(PlaceVertices, TaperedFacesKeepTheirOwnSpacing) {
  // A trapezoid: bottom 10, top 4 (2.5:1, beyond PlaceOptions::align_length_ratio), legs 5 and 5.
  // Both pairs are joined in chords (the bases by a length limit looser than the default's 2);
  // the legs share their spacing, the bottom and top do not.
  const cad::CadModel model = polygon_face({{0, 0}, {10, 0}, {7, 4}, {3, 4}}, "q_trapezoid.brep");
  const GradedCurves r(model);
  QuantizeOptions joined;
  joined.chord_length_ratio_limit = 3;
  const Quantization q = quantize_curves(model, ideal_edge_counts(r.bg, r.sizes), joined);
  const auto loop = loop_curves(model);
  ASSERT_EQ(loop.size(), 4u);
  ASSERT_NE(q.curve2chord[loop[0]], kNoIndex);
  ASSERT_EQ(q.curve2chord[loop[0]], q.curve2chord[loop[2]]);
  ASSERT_NE(q.curve2chord[loop[1]], kNoIndex);
  ASSERT_EQ(q.curve2chord[loop[1]], q.curve2chord[loop[3]]);
  const auto meshes = place_vertices(model, r.bg, r.sizes, q, false, TaskArena(1));
  // Each curve's first and last edge, along its own direction.
  const auto ends = [&](LO c) {
    const auto x = arc_length(meshes[c].points);
    return std::pair{x[1] - x[0], x.back() - x[x.size() - 2]};
  };
  for (const LO c : loop) {
    const auto [first, last] = ends(c);
    if (std::lround(model.curves()[c].length) == 5)
      EXPECT_NEAR(first / last, 1.0, 1e-3) << "leg " << c;  // the mean of mirrored profiles
    else
      EXPECT_GT(last / first, 1.5) << "curve " << c;  // its own grading, fine at its start
  }
}

TEST(PlaceVertices, BoxCountsAndChords) {
  const auto& model = box();
  background::SizeOptions so;
  so.size = 0.5;
  const TaskArena tasks(2);
  const auto bg = background::mesh_curves(model, so, tasks);
  std::vector<std::vector<double>> sizes;
  for (const auto& m : bg) {
    std::vector<double> s;
    const auto x = arc_length(m.points);
    for (const double xi : x) s.push_back(0.3 + 0.3 * xi / x.back());
    sizes.push_back(s);
  }
  const Quantization q = quantize_curves(model, ideal_edge_counts(bg, sizes), {});
  EXPECT_EQ(q.num_chords, 3);
  const auto full = place_vertices(model, bg, sizes, q, false, tasks);
  const auto half = place_vertices(model, bg, sizes, q, true, TaskArena(1));
  for (LO c = 0; c < model.num_curves(); ++c) {
    EXPECT_EQ(q.edges[c] % 2, 0);
    EXPECT_EQ(full[c].num_edges(), q.edges[c]);
    EXPECT_EQ(half[c].num_edges(), q.edges[c] / 2);
    for (LO d = 0; d < model.num_curves(); ++d)
      if (q.curve2chord[c] == q.curve2chord[d]) {
        EXPECT_EQ(q.edges[c], q.edges[d]);
      }
    const auto& curve = model.curves()[c];
    for (const auto* m : {&full[c], &half[c]}) {
      EXPECT_EQ(m->points.front(), model.corners()[curve.corners[0]].point);
      EXPECT_EQ(m->points.back(), model.corners()[curve.corners[1]].point);
    }
    // The halved mesh is the same Eq. 11 placement with n/2 steps: its vertices are the full
    // mesh's even vertices, so midpoint subdivision of the halved curve is the full one.
    for (LO i = 0; i <= half[c].num_edges(); ++i)
      EXPECT_NEAR(half[c].t[i], full[c].t[2 * i], 1e-9 * (curve.t1 - curve.t0 + 1));
  }
}

// Paper 000 Sec. 4.3 on a real model: opposite sides of every conformal four-sided face have the
// same count unless their ideal values are too different; every count is even.
TEST(Quantize, BlockModelOppositeSidesAgree) {
  const std::string path = std::string(QSMESH_SHARED_CAD_DIR) + "/Block.stp";
  if (!std::ifstream(path)) GTEST_SKIP() << path << " not found";
  const cad::CadModel model = cad::load_cad(path);
  background::SizeOptions so;
  so.size = model.diagonal() / 40;
  const TaskArena tasks(2);
  const auto bg = background::mesh_curves(model, so, tasks);
  std::vector<std::vector<double>> sizes;
  for (const auto& m : bg) sizes.emplace_back(m.points.size(), so.size);
  const auto ideal = ideal_edge_counts(bg, sizes);
  const Quantization q = quantize_curves(model, ideal, {});
  int pairs = 0;
  for (const auto& face : model.faces()) {
    if (face.loops.size() != 1 || face.loops[0].uses.size() != 4 || !face.loops_closed) continue;
    const auto& uses = face.loops[0].uses;
    for (int k = 0; k < 2; ++k) {
      const LO a = uses[k].curve, b = uses[k + 2].curve;
      if (model.curves()[a].degenerate || model.curves()[b].degenerate) continue;
      if (std::max(ideal[a], ideal[b]) > 2.0 * std::min(ideal[a], ideal[b])) continue;
      ++pairs;
      EXPECT_EQ(q.edges[a], q.edges[b]) << "curves " << a << " and " << b;
      EXPECT_EQ(q.curve2chord[a], q.curve2chord[b]);
    }
  }
  EXPECT_GT(pairs, 0);
  for (LO c = 0; c < model.num_curves(); ++c)
    if (!model.curves()[c].degenerate) {
      EXPECT_EQ(q.edges[c] % 2, 0) << "curve " << c;
    }
  const auto meshes = place_vertices(model, bg, sizes, q, true, tasks);
  for (LO c = 0; c < model.num_curves(); ++c)
    if (!model.curves()[c].degenerate) {
      EXPECT_EQ(meshes[c].num_edges(), q.edges[c] / 2);
    }
  std::cout << "Block.stp: " << model.num_curves() << " curves, " << q.num_chords << " chords, "
            << q.total_edges << " edges, " << pairs << " opposite pairs\n";
}

}  // namespace
}  // namespace qsmesh::quantize
