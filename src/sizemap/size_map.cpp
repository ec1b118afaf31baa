#include "qsmesh/sizemap/size_map.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <queue>
#include <sstream>
#include <string>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/feature_size.hpp"
#include "qsmesh/background/size.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::sizemap {

namespace {

/// Wedges sharper than this (degrees) have tips held by one quad (SizeMapOptions::thin_aspect).
constexpr double kSharpWedgeDeg = 10;
/// Where a sharp wedge's sides also bound other faces, its tail keeps their sizes (graded, its
/// counts would reach them: background::limit_by_face_width), and the tip takes the stretch
/// narrower than this fraction of the size. A quad past the tip, half the width across and the size
/// along, has SICN about width / size. t20_data (0-degree cusps of its chamfer slivers) at size
/// factors 0.02, 0.01 and its reference: the tips of 1/10 of the size left 24 avoidable quads below
/// SICN 0.1 at the reference, 1/6.3 none, 1/4 none but 136 interior irregular vertices (87 without
/// the tips, 78 with 1/6.3: the counts the faces beside the slivers get vary). 1/6 left the
/// trapezoids just past the tips at SICN 0.096 at size factor 0.01 (quads 1.2 x the size along:
/// 12 avoidable below 0.1); 0.18 takes them above 0.12 at 0.02, 0.01, 0.005 and the reference,
/// the reference mesh unchanged (docs/benchmarks.md, issue 29).
constexpr double kSharedTipWidth = 0.18;

/// Gaps narrower than this fraction of the floor do not make a face thin (curves touching). A tenth
/// of the floor, as rule (ii) uses, left strips 0.01-0.1 x the floor wide (Block's at size factor
/// 0.02) meshed at nearly the full size along them: 132 quads below SICN 0.1 there, 40 with a
/// hundredth (docs/benchmarks.md, issue 29). Inside sharp wedges and at blunted wedge tips the
/// tenth stays (background::limit_by_face_width): there the tip ends the graded tail.
constexpr double kThinTouching = 0.01;

/// Growth of the sizes along a thin face, as a fraction of the gradation (initial_curve_sizes):
/// 1 (the gradation itself) left the quads just past the test neck at SICN 0.198, 0.5 takes
/// them to 0.2 and above (76 -> 84 quads; docs/benchmarks.md, issue 29).
constexpr double kThinGradation = 0.5;

/// The cap past the tips of extruded sharp wedges, as a fraction of thin_aspect (see
/// initial_curve_sizes): the 5-degree prism's quads just past the tips at 0.75 0.192, at 0.6
/// above 0.2. Applied to wedges whose sides bound other faces everywhere, it took t20_data from
/// 72 to 132 interior irregular vertices (docs/benchmarks.md, issue 29).
constexpr double kSharedWedgeAspect = 0.6;

/// Rule (i'): the end corners of a curve shorter than the floor are no larger than this many times
/// its length. The floor keeps such a curve's size (and its corners') at the floor while the
/// quantization gives it 2 edges, so the quads against it went from half its length to the floor
/// in one row: beside a step 0.003 x the size high (floor 0.17) SICN 0.015, 0.188 graded from 5 x
/// the length (ThinRegions.StepShorterThanTheFloorGetsItsCornersGraded). Block at size factor 0.02
/// (steps 0.01 long at reflex corners, 4 faces) 20 -> 11 quads below SICN 0.1, A319 9 -> 0, the
/// reference meshes unchanged (docs/benchmarks.md, issue 29). Not at corners that a four-sided face
/// without the curve touches: its grid fill takes the curve's neighbourhood as it is, and finer
/// sizes at its corner carry finer counts through the grids. Capped there too, wing_fuselage's
/// wing-root slivers took it at its reference factor from 17926 to 19014 vertices and SICN avg
/// 0.927 to 0.915 (below its criterion, 0.918), at size factor 0.01 from 72 to 97 interior
/// irregular vertices; with the exception its meshes are unchanged.
constexpr double kSliverCornerRatio = 5;

/// Rule (i') for a sliver that takes one edge (SizeMapOptions::one_edge_slivers): its corners are
/// at most this many times its length, at every corner. Ten edge lengths, as kSliverCornerRatio
/// gives a 2-edge sliver: the quads against the edge then have SICN about 2 / 10 at the corner.
constexpr double kOneEdgeSliverCornerRatio = 10;

/// Sliver curves that take one edge are shorter than this fraction of the floor (sliver_length):
/// a tenth, as rule (ii) ignores gaps narrower than a tenth of the floor.
constexpr double kSliverFraction = 0.1;

constexpr double kInf = std::numeric_limits<double>::infinity();

[[noreturn]] void input_error(const std::string& what) { throw InputError("sizemap: " + what); }

void check_entities(const std::vector<std::pair<LO, double>>& list, LO count, const char* kind) {
  for (const auto& [id, value] : list) {
    if (id < 0 || id >= count) {
      std::ostringstream os;
      os << kind << " size constraint on " << kind << " " << id << ", but the model has " << count
         << " " << kind << "s";
      input_error(os.str());
    }
    if (!(value > 0) || !std::isfinite(value)) {
      std::ostringstream os;
      os << kind << " " << id << ": size " << value << " must be a positive number";
      input_error(os.str());
    }
  }
}

void validate(const cad::CadModel& model, const SizeMapOptions& options) {
  (void)effective_size_min(options);
  if (!(options.gradation >= 0) || !std::isfinite(options.gradation))
    input_error("gradation must be >= 0");
  if (!(options.feature_ratio >= 0 && options.feature_ratio <= 1))
    input_error("the feature ratio must be in [0, 1]");
  if (!(options.thin_aspect >= 0) || !std::isfinite(options.thin_aspect))
    input_error("the thin-face aspect ratio must be >= 0");
  check_entities(options.corner_sizes, model.num_corners(), "corner");
  check_entities(options.curve_sizes, model.num_curves(), "curve");
  check_entities(options.face_sizes, model.num_faces(), "face");
}

/// Eq. 10 to its fixed point by Dijkstra: s(v) = min(s0(v), min over edges (u, v) of s(u) + g d(u,
/// v)). The fixed point is unique, so the result does not depend on the order of equal keys; the
/// heap orders by (value, vertex) anyway.
void propagate(std::vector<double>& s, const std::vector<LO>& offsets,
               const std::vector<LO>& targets, const std::vector<double>& weights) {
  using Item = std::pair<double, LO>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> heap;
  for (LO v = 0; v < static_cast<LO>(s.size()); ++v)
    if (std::isfinite(s[v])) heap.emplace(s[v], v);
  while (!heap.empty()) {
    const auto [value, u] = heap.top();
    heap.pop();
    if (value > s[u]) continue;  // stale entry
    for (LO k = offsets[u]; k < offsets[u + 1]; ++k) {
      const LO v = targets[k];
      const double candidate = value + weights[k];
      if (candidate < s[v]) {
        s[v] = candidate;
        heap.emplace(candidate, v);
      }
    }
  }
}

/// CSR graph with weights g * |a - b| from an undirected edge list.
struct Graph {
  std::vector<LO> offsets, targets;
  std::vector<double> weights;
};
Graph make_graph(LO n, const std::vector<std::array<LO, 2>>& edges,
                 const std::vector<double>& lengths, double gradation) {
  Graph g;
  g.offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  for (const auto& [a, b] : edges) {
    ++g.offsets[a + 1];
    ++g.offsets[b + 1];
  }
  for (LO v = 0; v < n; ++v) g.offsets[v + 1] += g.offsets[v];
  g.targets.resize(g.offsets.back());
  g.weights.resize(g.offsets.back());
  std::vector<LO> fill(g.offsets.begin(), g.offsets.end() - 1);
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const auto [a, b] = edges[e];
    const double w = gradation * lengths[e];
    g.targets[fill[a]] = b;
    g.weights[fill[a]++] = w;
    g.targets[fill[b]] = a;
    g.weights[fill[b]++] = w;
  }
  return g;
}

double user_size(const std::vector<std::pair<LO, double>>& list, LO id) {
  double s = kInf;
  for (const auto& [i, v] : list)
    if (i == id) s = std::min(s, v);
  return s;
}

void check_shape(const CurveSizes& sizes, std::span<const mesh::CurveMesh> curves, LO num_corners) {
  QSMESH_CHECK(sizes.at.size() == curves.size(), "sizemap: curve sizes for "
                                                     << sizes.at.size() << " curves, "
                                                     << curves.size() << " curve meshes");
  for (std::size_t c = 0; c < curves.size(); ++c)
    QSMESH_CHECK(sizes.at[c].size() == curves[c].t.size(),
                 "sizemap: curve " << c << " has " << sizes.at[c].size() << " size values for "
                                   << curves[c].t.size() << " vertices");
  QSMESH_CHECK(
      num_corners < 0 || sizes.corner.size() == static_cast<std::size_t>(num_corners),
      "sizemap: " << sizes.corner.size() << " corner sizes for " << num_corners << " corners");
}

/// Whether a four-sided face (one loop of four curve uses) that does not use curve `c` touches
/// corner `k`: rule (i') leaves such corners alone (kSliverCornerRatio).
bool grid_face_without_curve_at(const cad::CadModel& model, LO k, LO c) {
  for (const LO d : model.corner2curves()[k])
    for (const LO f : model.curve2faces()[d]) {
      const auto& loops = model.faces()[f].loops;
      if (loops.size() != 1 || loops[0].uses.size() != 4) continue;
      bool uses_c = false;
      for (const auto& use : loops[0].uses) uses_c = uses_c || use.curve == c;
      if (!uses_c) return true;
    }
  return false;
}

}  // namespace

double effective_size_min(const SizeMapOptions& options) {
  if (!(options.size_max > 0) || !std::isfinite(options.size_max))
    input_error("the size cap (--size / --size-factor) must be > 0");
  if (!(options.size_min >= 0) || options.size_min > options.size_max)
    input_error("the smallest size must be >= 0 and no larger than the size cap");
  double floor = options.size_min > 0 ? options.size_min : options.size_max / 100;
  for (const auto* list : {&options.corner_sizes, &options.curve_sizes, &options.face_sizes})
    for (const auto& [id, v] : *list)
      if (v > 0) floor = std::min(floor, v);
  return floor;
}

double sliver_length(const SizeMapOptions& options) {
  return options.one_edge_slivers ? kSliverFraction * effective_size_min(options) : 0.0;
}

std::vector<double> CurveSizes::pack() const {
  std::vector<double> flat;
  std::size_t n = corner.size();
  for (const auto& a : at) n += a.size();
  flat.reserve(n);
  for (const auto& a : at) flat.insert(flat.end(), a.begin(), a.end());
  flat.insert(flat.end(), corner.begin(), corner.end());
  return flat;
}

void CurveSizes::unpack(std::span<const double> flat) {
  std::size_t n = corner.size();
  for (const auto& a : at) n += a.size();
  QSMESH_CHECK(flat.size() == n, "sizemap: unpack of " << flat.size() << " values into " << n);
  std::size_t k = 0;
  for (auto& a : at)
    for (double& x : a) x = flat[k++];
  for (double& x : corner) x = flat[k++];
}

CurveSizes make_curve_sizes(std::span<const mesh::CurveMesh> curves, LO num_corners, double value) {
  CurveSizes s;
  s.at.resize(curves.size());
  for (std::size_t c = 0; c < curves.size(); ++c) s.at[c].assign(curves[c].t.size(), value);
  s.corner.assign(static_cast<std::size_t>(std::max<LO>(num_corners, 0)), value);
  return s;
}

CurveSizes initial_curve_sizes(const cad::CadModel& model, std::span<const mesh::CurveMesh> curves,
                               const SizeMapOptions& options, const TaskArena& tasks) {
  validate(model, options);
  const LO nc = model.num_curves();
  QSMESH_CHECK(static_cast<LO>(curves.size()) == nc,
               "sizemap: " << curves.size() << " curve meshes for " << nc << " curves");
  const double floor = effective_size_min(options);
  CurveSizes out = make_curve_sizes(curves, model.num_corners(), options.size_max);
  auto cap_curve = [&](LO c, double v) {
    for (double& x : out.at[c]) x = std::min(x, v);
  };
  for (const auto& [c, v] : options.curve_sizes) cap_curve(c, v);

  // (0) Curvature: 2 pi R / n along the curve (without it a half circle may get two edges and its
  //     faces fold), and across its faces with face_curvature.
  if (options.edges_per_turn > 0) {
    background::SizeOptions curvature;
    curvature.size = options.size_max;
    curvature.min_size = floor;
    curvature.edges_per_turn = options.edges_per_turn;
    // The faces' uses of each curve, needed only when their curvature counts.
    const auto uses = options.face_curvature ? background::curve_uses(model)
                                             : std::vector<std::vector<background::CurveUseRef>>{};
    tasks.parallel_for(nc, [&](std::int64_t i) {
      const auto c = static_cast<LO>(i);
      if (model.curves()[c].degenerate) return;
      const background::CurveCurvatureSize size(
          model, c,
          uses.empty() ? std::span<const background::CurveUseRef>()
                       : std::span<const background::CurveUseRef>(uses[c]),
          curvature);
      for (std::size_t k = 0; k < curves[c].t.size(); ++k)
        out.at[c][k] = std::min(out.at[c][k], size(curves[c].t[k]));
    });
  }
  for (const auto& [f, v] : options.face_sizes)
    for (const auto& loop : model.faces()[f].loops)
      for (const auto& use : loop.uses) cap_curve(use.curve, v);

  // (i) no larger than the curve's length, even below the default floor (the paper's rule): a
  //     curve gets at least one edge, and the faces around a very short curve grade out from it.
  //     A floor the user gave is a statement about the smallest elements wanted, so it holds here
  //     too: a sliver edge of the CAD still gets its edges (the quantization's minimum), and its
  //     surroundings stay at the floor, but for its corners (rule (i') below).
  const double length_floor = options.size_min > 0 ? floor : 0.0;
  for (LO c = 0; c < nc; ++c) {
    const auto& cc = model.curves()[c];
    if (!cc.degenerate) cap_curve(c, std::max(cc.length, length_floor));
  }

  // (ii) no larger than the distance to the nearest curve sharing no corner. The search only finds
  //      polyline vertices within the current size, so the curve meshes are densified: a segment
  //      much longer than the size could otherwise pass close by with both its ends out of reach.
  {
    std::vector<std::vector<Vec3>> dense(nc);
    std::vector<std::vector<double>> h(nc);
    std::vector<std::vector<LO>> original(nc);  // dense index of each curve-mesh vertex
    double cell = 0;
    for (LO c = 0; c < nc; ++c) {
      if (model.curves()[c].degenerate) continue;
      const auto& p = curves[c].points;
      const auto& s = out.at[c];
      for (std::size_t i = 0; i < p.size(); ++i) {
        original[c].push_back(static_cast<LO>(dense[c].size()));
        dense[c].push_back(p[i]);
        h[c].push_back(s[i]);
        cell = std::max(cell, s[i]);
        if (i + 1 == p.size()) break;
        const double piece = 0.5 * std::min(s[i], s[i + 1]);
        const double length = distance(p[i], p[i + 1]);
        const int pieces = std::clamp(static_cast<int>(std::ceil(length / piece)), 1, 16);
        for (int k = 1; k < pieces; ++k) {
          const double a = static_cast<double>(k) / pieces;
          dense[c].push_back(p[i] * (1 - a) + p[i + 1] * a);
          h[c].push_back(s[i] * (1 - a) + s[i + 1] * a);
        }
      }
    }
    if (cell > 0) {
      // Gaps narrower than a tenth of the floor are curves touching or lying on top of each other
      // (unsewn or sloppy models), not features a mesh could resolve.
      const double touching = 0.1 * floor;
      // The thin-face widths are searched within half the size before (ii): wider faces are not
      // thin. Taken from the same densified polylines, before h is lowered by (ii).
      std::vector<std::vector<double>> width, shared_width;
      std::vector<char> shared_ok;
      if (options.thin_aspect > 0) {
        width = h;
        for (auto& w : width)
          for (double& x : w) x *= 0.5;
        background::limit_by_face_width(model, dense, width, kThinTouching * floor, touching, floor,
                                        tasks);
        // The tails of sharp wedges whose sides also bound other faces are left to the tips
        // above, except where each such side's other faces are four-sided and carry the counts
        // to an opposite side that is such a tail too (an extruded wedge: the 5-degree prism of
        // tests/drivers/test_thin_regions.cpp, whose quads just past the tips were at SICN 0.171):
        // there the stretch past the tip narrower than a quarter of the size is capped at
        // kSharedWedgeAspect x K x its width.
        {
          shared_width = h;
          for (auto& w : shared_width)
            for (double& x : w) x *= 0.5;
          background::limit_by_face_width(model, dense, shared_width, kThinTouching * floor,
                                          touching, floor, tasks, true);
          std::vector<char> has(static_cast<std::size_t>(nc), 0);
          for (LO c = 0; c < nc; ++c)
            for (std::size_t k = 0; k < shared_width[c].size(); ++k)
              if (shared_width[c][k] < 0.5 * h[c][k] * (1 - 1e-12)) has[c] = 1;
          shared_ok.assign(static_cast<std::size_t>(nc), 0);
          for (LO c = 0; c < nc; ++c) {
            if (has[c] == 0) continue;
            // Besides the wedge's own face, every face of the side carries its counts across
            // to an opposite side that is such a tail too (an extruded wedge); elsewhere those
            // counts need transitions (t20_data's chamfer slivers beside five- and six-sided
            // faces).
            int others = 0;
            for (const LO f : model.curve2faces()[c]) {
              const auto& face = model.faces()[f];
              bool carried = false;
              if (face.loops.size() == 1 && face.loops[0].uses.size() == 4) {
                const auto& uses = face.loops[0].uses;
                for (std::size_t k = 0; k < 4; ++k)
                  if (uses[k].curve == c && has[uses[(k + 2) % 4].curve] != 0) carried = true;
              }
              if (!carried) ++others;
            }
            const bool ok = others <= 1;
            shared_ok[c] = ok ? 1 : 0;
          }
        }
        // The tip of a sharp wedge is one edge. Where the tail behind it is graded (its sides
        // bound that face alone), the tip is where the sides are closer than `touching`, never
        // longer than the size: graded with the width down to the corner, the tail's quads would
        // be as flat as ever and endless in number. Elsewhere the tip is all of the tail thinner
        // than kSharedTipWidth x the size.
        out.tips = background::sharp_wedge_tips(model, dense, h, touching, kSharedTipWidth,
                                                kSharpWedgeDeg);
        for (auto& tip : out.tips) {
          const auto& at = out.at[tip.curve];
          if (!tip.shared) tip.length = std::min(tip.length, tip.end == 0 ? at.front() : at.back());
        }
      }
      background::limit_by_feature_distance(model, dense, h, touching, floor, tasks);
      // thin[c][i]: the thin-face cap set the size at vertex i of curve c.
      std::vector<std::vector<char>> thin(static_cast<std::size_t>(nc));
      for (LO c = 0; c < nc; ++c) thin[c].assign(original[c].size(), 0);
      // h only ever lowers the sizes it started from, and the ratio is at most 1.
      for (LO c = 0; c < nc; ++c)
        for (std::size_t i = 0; i < original[c].size(); ++i) {
          double& s = out.at[c][i];
          const double before = s;
          s = std::max(h[c][original[c][i]], options.feature_ratio * s);
          // The feature ratio and the floor keep the size along a thin face near the full size:
          // its quads would be about width / size flat. Capped by the aspect ratio instead, below
          // the floor too (the floor is about the sizes the faces around may ask for, not the
          // shape of the quads inside a strip).
          if (!width.empty()) {
            const double w = width[c][original[c][i]];
            if (w < 0.5 * before && options.thin_aspect * w <= s) {
              s = options.thin_aspect * w;
              thin[c][i] = 1;
            }
            if (!shared_width.empty() && shared_ok[c] != 0) {
              const double sc = kSharedWedgeAspect;
              const double ws = shared_width[c][original[c][i]];
              bool in_tip = false;
              for (const auto& tip : out.tips)
                if (tip.curve == c &&
                    distance(curves[c].points[i],
                             tip.end == 0 ? curves[c].points.front() : curves[c].points.back()) <
                        tip.length * 1.0000001)
                  in_tip = true;
              if (!in_tip && options.thin_aspect * ws < before && sc * options.thin_aspect * ws < s)
                s = sc * options.thin_aspect * ws;
            }
          }
        }
      // Where the width changes, the quads at the narrow end of an edge are what counts: past a
      // neck, two across, their narrow side half the neck's width, they came out at SICN 0.19
      // with the gradation's growth (tests/drivers/test_thin_regions.cpp). Along a thin face the
      // sizes grow at most kThinGradation x the gradation, up to the first vertex outside it.
      for (LO c = 0; c < nc; ++c) {
        const auto& flags = thin[c];
        if (std::find(flags.begin(), flags.end(), 1) == flags.end()) continue;
        auto& at = out.at[c];
        const auto& p = curves[c].points;
        const double g = kThinGradation * options.gradation;
        for (std::size_t i = 1; i < at.size(); ++i)
          if (flags[i] != 0 || flags[i - 1] != 0)
            at[i] = std::min(at[i], at[i - 1] + g * distance(p[i], p[i - 1]));
        for (std::size_t i = at.size() - 1; i-- > 0;)
          if (flags[i] != 0 || flags[i + 1] != 0)
            at[i] = std::min(at[i], at[i + 1] + g * distance(p[i], p[i + 1]));
      }
    }
  }

  // (i') The corners of a curve shorter than the floor: at most kSliverCornerRatio x its length,
  //      so that the sizes grade toward it instead of dropping from the floor to its edges in one
  //      row (except where a grid face beside it takes the corner as it is, unless the curve takes
  //      one edge: one_edge_slivers).
  const double sliver = sliver_length(options);
  for (LO c = 0; c < nc; ++c) {
    const auto& cc = model.curves()[c];
    if (cc.degenerate || !(cc.length < floor)) continue;
    const bool one_edge = cc.length < sliver;
    const double cap = (one_edge ? kOneEdgeSliverCornerRatio : kSliverCornerRatio) * cc.length;
    for (const LO k : cc.corners)
      if (k >= 0 && cap < out.corner[k] && (one_edge || !grid_face_without_curve_at(model, k, c)))
        out.corner[k] = cap;
  }

  for (const auto& [k, v] : options.corner_sizes) out.corner[k] = std::min(out.corner[k], v);
  grade_curves(model, curves, options.gradation, out);
  return out;
}

double expected_quads(const mesh::FaceMesh& background, std::span<const double> s) {
  QSMESH_CHECK(s.size() == background.points.size(),
               "sizemap: " << s.size() << " sizes for " << background.points.size() << " vertices");
  double sum = 0;
  for (const auto& t : background.triangles) {
    const double h = (s[t[0]] + s[t[1]] + s[t[2]]) / 3.0;
    const Vec3& a = background.points[t[0]];
    const double area = 0.5 * norm(cross(background.points[t[1]] - a, background.points[t[2]] - a));
    if (h > 0) sum += area / (h * h);
  }
  return sum;
}

std::vector<double> face_quad_targets(const cad::CadModel& model, const SizeMapOptions& options) {
  const LO nf = model.num_faces();
  double total = 0;
  for (const auto& f : model.faces()) total += f.area;
  double n = options.target_quads;
  if (!(n >= 0) || !std::isfinite(n)) input_error("the target number of quads must be >= 0");
  if (n == 0) {
    if (!(options.size_max > 0)) input_error("the size cap (--size / --size-factor) must be > 0");
    n = total / (options.size_max * options.size_max);
  }
  std::vector<double> out(static_cast<std::size_t>(nf), 0.0);
  for (LO f = 0; f < nf; ++f) out[f] = total > 0 ? model.faces()[f].area / total * n : n / nf;
  for (const auto& [f, q] : options.face_quads) {
    if (f < 0 || f >= nf) {
      std::ostringstream os;
      os << "quad count given for face " << f << ", but the model has " << nf << " faces";
      input_error(os.str());
    }
    if (!(q >= 0) || !std::isfinite(q)) {
      std::ostringstream os;
      os << "face " << f << ": quad count " << q << " must be >= 0";
      input_error(os.str());
    }
    out[f] = q;
  }
  return out;
}

FaceSizes face_sizes(const mesh::FaceMesh& background, const crossfield::FaceCrossField* cf,
                     std::span<const mesh::CurveMesh> curves, const CurveSizes& curve,
                     double face_quads, const SizeMapOptions& options) {
  const double floor = effective_size_min(options);
  check_shape(curve, curves, -1);
  const LO n = background.num_vertices();
  FaceSizes out;
  if (n == 0 || background.triangles.empty()) return out;

  // Seams and poles must be interior for the propagation: work on the glued triangulation.
  crossfield::FaceCrossField local;
  const crossfield::FaceCrossField* glued = cf;
  if (glued == nullptr) {
    crossfield::glue_triangulation(background, local);
    glued = &local;
  }
  QSMESH_CHECK(glued->input2glued.size() == static_cast<std::size_t>(n),
               "sizemap: face " << background.face << ": the cross field is of another mesh ("
                                << glued->input2glued.size() << " vertices, the face has " << n
                                << ")");
  const auto ng = static_cast<LO>(glued->points.size());

  std::vector<double> s_min(ng, kInf);
  for (LO v = 0; v < n; ++v) {
    const auto& vc = background.vclass[v];
    double value = kInf;
    if (vc.dim == 1) {
      QSMESH_CHECK(vc.entity >= 0 && vc.entity < static_cast<LO>(curve.at.size()) &&
                       vc.index >= 0 && vc.index < static_cast<LO>(curve.at[vc.entity].size()),
                   "sizemap: face " << background.face << " vertex " << v << " on curve "
                                    << vc.entity << " index " << vc.index << " has no curve size");
      value = curve.at[vc.entity][vc.index];
    } else if (vc.dim == 0) {
      QSMESH_CHECK(vc.entity >= 0 && vc.entity < static_cast<LO>(curve.corner.size()),
                   "sizemap: face " << background.face << " vertex " << v << " on corner "
                                    << vc.entity << " has no corner size");
      value = curve.corner[vc.entity];
    } else {
      continue;
    }
    const LO g = glued->input2glued[v];
    s_min[g] = std::min(s_min[g], value);
  }

  std::vector<double> s_cf;
  if (options.method == Method::CrossField && cf != nullptr && face_quads > 0 &&
      cf->H.size() == static_cast<std::size_t>(ng)) {
    const double c = crossfield::scaling_constant(*cf, face_quads);
    s_cf.resize(ng);
    // H grows without bound near singularities: the floor keeps s_cf usable there.
    for (LO g = 0; g < ng; ++g) s_cf[g] = std::max(floor, std::exp(cf->H[g] + c));
  }

  std::vector<double> lengths(glued->edges.size());
  for (std::size_t e = 0; e < glued->edges.size(); ++e)
    lengths[e] = distance(glued->points[glued->edges[e][0]], glued->points[glued->edges[e][1]]);
  const Graph graph = make_graph(ng, glued->edges, lengths, options.gradation);

  // s = min(s_cf, s_min) graded: Eq. 10 is min-plus linear, so grading the minimum of the two
  // initial fields gives the minimum of the two graded fields.
  std::vector<double> s = s_min;
  if (!s_cf.empty())
    for (LO g = 0; g < ng; ++g) s[g] = std::min(s[g], s_cf[g]);
  propagate(s_min, graph.offsets, graph.targets, graph.weights);
  propagate(s, graph.offsets, graph.targets, graph.weights);

  // A constant cap keeps the gradation bound (|min(a,c) - min(b,c)| <= |a - b|). No floor here:
  // the sources are already floored, except the sizes of curves shorter than the floor, which the
  // faces must follow.
  const double cap = std::min(options.size_max, user_size(options.face_sizes, background.face));
  auto clamp = [&](double x) { return std::min(cap, x); };
  out.s.resize(n);
  out.s_min.resize(n);
  if (!s_cf.empty()) out.s_cf.resize(n);
  for (LO v = 0; v < n; ++v) {
    const LO g = glued->input2glued[v];
    out.s[v] = clamp(s[g]);
    out.s_min[v] = clamp(s_min[g]);
    if (!s_cf.empty()) out.s_cf[v] = s_cf[g];
  }
  return out;
}

void fold_boundary_min(const mesh::FaceMesh& background, std::span<const double> values,
                       CurveSizes& into) {
  const LO n = background.num_vertices();
  QSMESH_CHECK(values.size() == static_cast<std::size_t>(n),
               "sizemap: face " << background.face << ": " << values.size() << " values for " << n
                                << " vertices");
  for (LO v = 0; v < n; ++v) {
    const auto& vc = background.vclass[v];
    if (vc.dim == 1) {
      QSMESH_CHECK(vc.entity >= 0 && vc.entity < static_cast<LO>(into.at.size()) && vc.index >= 0 &&
                       vc.index < static_cast<LO>(into.at[vc.entity].size()),
                   "sizemap: face " << background.face << " vertex " << v << " on curve "
                                    << vc.entity << " index " << vc.index
                                    << " is outside the curve sizes");
      double& x = into.at[vc.entity][vc.index];
      x = std::min(x, values[v]);
    } else if (vc.dim == 0) {
      QSMESH_CHECK(vc.entity >= 0 && vc.entity < static_cast<LO>(into.corner.size()),
                   "sizemap: face " << background.face << " vertex " << v << " on corner "
                                    << vc.entity << " is outside the corner sizes");
      double& x = into.corner[vc.entity];
      x = std::min(x, values[v]);
    }
  }
}

void grade_curves(const cad::CadModel& model, std::span<const mesh::CurveMesh> curves,
                  double gradation, CurveSizes& sizes) {
  const LO nc = model.num_curves(), nk = model.num_corners();
  QSMESH_CHECK(static_cast<LO>(curves.size()) == nc,
               "sizemap: " << curves.size() << " curve meshes for " << nc << " curves");
  check_shape(sizes, curves, nk);

  // Graph nodes: corners first, then the interior vertices of every curve mesh.
  std::vector<LO> base(static_cast<std::size_t>(nc) + 1, nk);
  for (LO c = 0; c < nc; ++c)
    base[c + 1] = base[c] + std::max<LO>(static_cast<LO>(curves[c].t.size()) - 2, 0);
  auto node = [&](LO c, std::size_t i) -> LO {
    const auto& cc = model.curves()[c];
    if (i == 0) return cc.corners[0];
    if (i + 1 == curves[c].t.size()) return cc.corners[1];
    return base[c] + static_cast<LO>(i) - 1;
  };

  std::vector<double> s(static_cast<std::size_t>(base[nc]), kInf);
  for (LO k = 0; k < nk; ++k) s[k] = sizes.corner[k];
  std::vector<std::array<LO, 2>> edges;
  std::vector<double> lengths;
  for (LO c = 0; c < nc; ++c) {
    const auto& at = sizes.at[c];
    const auto& p = curves[c].points;
    for (std::size_t i = 0; i < at.size(); ++i) {
      const LO v = node(c, i);
      QSMESH_CHECK(v >= 0, "sizemap: curve " << c << " has no corner at an end");
      s[v] = std::min(s[v], at[i]);
    }
    if (model.curves()[c].degenerate) continue;
    for (std::size_t i = 0; i + 1 < at.size(); ++i) {
      const LO a = node(c, i), b = node(c, i + 1);
      if (a == b) continue;
      edges.push_back({a, b});
      lengths.push_back(distance(p[i], p[i + 1]));
    }
  }
  const Graph graph = make_graph(static_cast<LO>(s.size()), edges, lengths, gradation);
  propagate(s, graph.offsets, graph.targets, graph.weights);

  for (LO k = 0; k < nk; ++k) sizes.corner[k] = s[k];
  for (LO c = 0; c < nc; ++c)
    for (std::size_t i = 0; i < sizes.at[c].size(); ++i) sizes.at[c][i] = s[node(c, i)];
  // The tip of a sharp wedge is held by one quad: one edge of its own length, however fine the
  // sizes graded along the tail behind it (SizeMapOptions::thin_aspect).
  for (const auto& tip : sizes.tips) {
    const auto& p = curves[tip.curve].points;
    auto& at = sizes.at[tip.curve];
    const Vec3 corner = tip.end == 0 ? p.front() : p.back();
    for (std::size_t i = 0; i < at.size(); ++i)
      if (distance(p[i], corner) < tip.length) at[i] = tip.length;
  }
}

}  // namespace qsmesh::sizemap
