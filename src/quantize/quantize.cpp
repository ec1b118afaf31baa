#include "qsmesh/quantize/quantize.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>

#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/predicates.hpp"

namespace qsmesh::quantize {

namespace {

// ∫ dl / s over a straight segment of length len with s linear from s0 to s1: len/s0 * ln(1+r)/r,
// r = (s1 - s0)/s0. The series keeps it accurate when s barely varies (r -> 0).
double segment_integral(double len, double s0, double s1) {
  const double r = (s1 - s0) / s0;
  const double phi = std::abs(r) < 1e-4 ? 1 - r / 2 + r * r / 3 - r * r * r / 4 : std::log1p(r) / r;
  return len / s0 * phi;
}

// Inverse of the above: the fraction a/len of the segment where ∫_0^a dl / s reaches g.
double segment_fraction(double len, double s0, double s1, double g) {
  if (len <= 0) return 0;
  const double r = (s1 - s0) / s0;
  const double k = g * s0 / len;
  const double kr = k * r;
  const double f = std::abs(kr) < 1e-8 ? k * (1 + kr / 2) : std::expm1(kr) / r;
  return std::clamp(f, 0.0, 1.0);
}

void check_sizes(LO c, const mesh::CurveMesh& m, const std::vector<double>& s) {
  QSMESH_CHECK(s.size() == m.points.size(), "curve " << c << ": " << s.size() << " sizes for "
                                                     << m.points.size() << " background vertices");
  QSMESH_CHECK(m.t.size() == m.points.size() && m.points.size() >= 2,
               "curve " << c << ": background mesh has " << m.points.size() << " points and "
                        << m.t.size() << " parameters");
  for (std::size_t i = 0; i < s.size(); ++i)
    QSMESH_CHECK(std::isfinite(s[i]) && s[i] > 0,
                 "curve " << c << ": size " << s[i] << " at background vertex " << i);
}

// Cumulative ∫ dl / s at the background vertices of one curve.
std::vector<double> cumulative(const mesh::CurveMesh& m, const std::vector<double>& s) {
  std::vector<double> f(m.points.size(), 0.0);
  for (std::size_t i = 0; i + 1 < m.points.size(); ++i)
    f[i + 1] = f[i] + segment_integral(distance(m.points[i], m.points[i + 1]), s[i], s[i + 1]);
  return f;
}

struct UnionFind {
  std::vector<LO> parent;
  explicit UnionFind(LO n) : parent(static_cast<std::size_t>(n)) {
    std::iota(parent.begin(), parent.end(), 0);
  }
  LO find(LO a) {
    while (parent[a] != a) {
      parent[a] = parent[parent[a]];
      a = parent[a];
    }
    return a;
  }
  // The smaller id becomes the root: the result does not depend on the order of the unions.
  void join(LO a, LO b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (b < a) std::swap(a, b);
    parent[b] = a;
  }
};

// Arc length at the background vertices of one curve.
std::vector<double> arc_lengths(const mesh::CurveMesh& m) {
  std::vector<double> arc(m.points.size(), 0.0);
  for (std::size_t i = 0; i + 1 < m.points.size(); ++i)
    arc[i + 1] = arc[i] + distance(m.points[i], m.points[i + 1]);
  return arc;
}

// Normalised ∫ dl / s of a curve (0 at its start, 1 at its end) at the arc-length fractions
// k / samples, k = 0 .. samples. Empty when the curve has no length or no size integral.
std::vector<double> normalised_profile(const mesh::CurveMesh& m, const std::vector<double>& s,
                                       int samples) {
  const std::vector<double> f = cumulative(m, s);
  const std::vector<double> arc = arc_lengths(m);
  if (!(f.back() > 0) || !(arc.back() > 0)) return {};
  std::vector<double> g(static_cast<std::size_t>(samples) + 1);
  std::size_t j = 0;
  const std::size_t last = arc.size() - 2;
  for (int k = 0; k <= samples; ++k) {
    const double x = arc.back() * k / samples;
    while (j < last && arc[j + 1] < x) ++j;
    const double len = arc[j + 1] - arc[j];
    const double a = std::clamp(x - arc[j], 0.0, len);
    const double sx = len > 0 ? s[j] + (s[j + 1] - s[j]) * a / len : s[j];
    g[k] = (f[j] + segment_integral(a, s[j], sx)) / f.back();
  }
  g.front() = 0;
  g.back() = 1;
  return g;
}

// Per curve: the profile it shares with the curves it faces across four-sided faces whose two
// pairs of opposite sides are joined in chords and about as long (empty: the curve keeps its own
// size integral). Why only those faces: they are the ones a grid or a transition pattern fills,
// whose rows run from one side to the other and shear when the two sides are graded differently
// (two circles of Block.stp 0.8 apart, graded 3:1 toward one end at different rates, gave a
// 44 x 4 grid SICN avg 0.62). Joining the faces with one joined pair as well also blends, say,
// a wing's leading and trailing edges, whose sizes differ for good reasons: wing_fuselage.step
// went from 873 to 984 interior irregular vertices that way. Opposite sides of very different
// lengths (the built-in example's wing root and tip, 4296 and 1828 long) bound a tapered face
// that no pattern fills well anyway; blending them cost its unstructured mesh SICN avg 0.895 ->
// 0.878. The curves of a set are oriented through the faces (opposite uses of a loop run in
// opposite directions); a set the faces orient inconsistently (a twisted band) keeps its own
// profiles.
std::vector<std::vector<double>> shared_profiles(const cad::CadModel& model,
                                                 std::span<const mesh::CurveMesh> curves,
                                                 std::span<const std::vector<double>> sizes,
                                                 const Quantization& q,
                                                 const PlaceOptions& options) {
  const int samples = options.profile_samples;
  const LO nc = model.num_curves();
  const auto cv = model.curves();
  const auto joined = [&](LO a, LO b) {
    return q.curve2chord[a] != kNoIndex && q.curve2chord[a] == q.curve2chord[b];
  };
  // Opposite pairs of the four-sided faces whose both pairs are joined (the faces a grid or a
  // transition pattern fills), with 0 when the two curves run the same way.
  std::vector<std::vector<std::pair<LO, int>>> links(static_cast<std::size_t>(nc));
  for (const cad::Face& face : model.faces()) {
    if (face.loops.size() != 1 || face.loops[0].uses.size() != 4 || !face.loops_closed) continue;
    const auto& uses = face.loops[0].uses;
    if (!(joined(uses[0].curve, uses[2].curve) && joined(uses[1].curve, uses[3].curve))) continue;
    for (int k = 0; k < 2; ++k) {
      const LO a = uses[k].curve, b = uses[k + 2].curve;
      if (!joined(a, b)) continue;
      const double la = cv[a].length, lb = cv[b].length;
      if (std::max(la, lb) > options.align_length_ratio * std::min(la, lb)) continue;
      const int flip = uses[k].reversed == uses[k + 2].reversed ? 1 : 0;
      links[a].emplace_back(b, flip);
      links[b].emplace_back(a, flip);
    }
  }
  std::vector<int> flip(static_cast<std::size_t>(nc), -1);
  std::vector<std::vector<double>> out(static_cast<std::size_t>(nc));
  for (LO root = 0; root < nc; ++root) {
    if (flip[root] != -1 || links[root].empty()) continue;
    std::vector<LO> mem{root};
    bool consistent = true;
    std::vector<LO> stack{root};
    flip[root] = 0;
    while (!stack.empty()) {
      const LO c = stack.back();
      stack.pop_back();
      for (const auto& [o, f] : links[c]) {
        const int want = flip[c] ^ f;
        if (flip[o] == -1) {
          flip[o] = want;
          stack.push_back(o);
          mem.push_back(o);
        } else if (flip[o] != want) {
          consistent = false;
        }
      }
    }
    if (!consistent || mem.size() < 2) continue;
    // Chords never hold degenerate curves (quantize_curves), so every member has a polyline.
    std::vector<double> shared(static_cast<std::size_t>(samples) + 1, 0.0);
    for (const LO c : mem) {
      const std::vector<double> g = normalised_profile(curves[c], sizes[c], samples);
      if (g.empty()) {
        consistent = false;
        break;
      }
      for (int k = 0; k <= samples; ++k) shared[k] += flip[c] != 0 ? 1 - g[samples - k] : g[k];
    }
    if (!consistent) continue;
    for (double& v : shared) v /= static_cast<double>(mem.size());
    for (const LO c : mem) {
      auto& p = out[c];
      p.resize(shared.size());
      for (int k = 0; k <= samples; ++k) p[k] = flip[c] != 0 ? 1 - shared[samples - k] : shared[k];
    }
  }
  return out;
}

}  // namespace

std::vector<double> ideal_edge_counts(std::span<const mesh::CurveMesh> curves,
                                      std::span<const std::vector<double>> sizes) {
  QSMESH_CHECK(sizes.size() == curves.size(),
               sizes.size() << " size lists for " << curves.size() << " curves");
  std::vector<double> ideal(curves.size(), 0.0);
  for (std::size_t c = 0; c < curves.size(); ++c) {
    check_sizes(static_cast<LO>(c), curves[c], sizes[c]);
    ideal[c] = cumulative(curves[c], sizes[c]).back();
  }
  return ideal;
}

Quantization quantize_curves(const cad::CadModel& model, std::span<const double> ideal,
                             const QuantizeOptions& options) {
  const LO nc = model.num_curves();
  const auto curves = model.curves();
  QSMESH_CHECK(static_cast<LO>(ideal.size()) == nc,
               ideal.size() << " ideal edge counts for " << nc << " curves");
  for (LO c = 0; c < nc; ++c)
    QSMESH_CHECK(std::isfinite(ideal[c]) && ideal[c] >= 0,
                 "curve " << c << ": ideal edge count " << ideal[c]);
  QSMESH_CHECK(options.chord_ratio_limit >= 1,
               "chord_ratio_limit " << options.chord_ratio_limit << " is below 1");
  QSMESH_CHECK(options.chord_length_ratio_limit >= 1,
               "chord_length_ratio_limit " << options.chord_length_ratio_limit << " is below 1");

  Quantization q;
  q.ideal.assign(ideal.begin(), ideal.end());
  q.edges.assign(static_cast<std::size_t>(nc), 0);
  q.curve2chord.assign(static_cast<std::size_t>(nc), kNoIndex);

  // Curves joining the same two corners: each needs 2 edges or the two meshes would coincide.
  std::vector<bool> parallel(static_cast<std::size_t>(nc), false);
  {
    std::map<std::pair<LO, LO>, LO> first;
    for (LO c = 0; c < nc; ++c) {
      const auto& cv = curves[c];
      if (cv.degenerate || cv.corners[0] == cv.corners[1]) continue;
      const std::pair<LO, LO> key = std::minmax(cv.corners[0], cv.corners[1]);
      const auto [it, inserted] = first.emplace(key, c);
      if (!inserted) parallel[c] = parallel[it->second] = true;
    }
  }
  const auto closed = [&](LO c) { return curves[c].corners[0] == curves[c].corners[1]; };
  // Smallest count the rounding may give.
  const auto minimum = [&](LO c) {
    const bool coarse = options.even && options.halved_minimums;
    if (closed(c)) return options.even ? (coarse ? 6 : 4) : 3;
    if (parallel[c]) return coarse ? 4 : 2;
    return options.even ? 2 : 1;
  };
  // Smallest count a prescription may ask for: what makes a valid curve mesh.
  const auto hard_minimum = [&](LO c) { return closed(c) ? 3 : (parallel[c] ? 2 : 1); };

  // Chords of conformal four-sided faces.
  UnionFind uf(nc);
  std::vector<bool> in_chord(static_cast<std::size_t>(nc), false);
  for (const cad::Face& face : model.faces()) {
    if (face.loops.size() != 1 || face.loops[0].uses.size() != 4 || !face.loops_closed) continue;
    const auto& uses = face.loops[0].uses;
    for (int k = 0; k < 2; ++k) {
      const LO a = uses[k].curve, b = uses[k + 2].curve;
      if (curves[a].degenerate || curves[b].degenerate) continue;
      const double lo = std::min(ideal[a], ideal[b]), hi = std::max(ideal[a], ideal[b]);
      if (hi > options.chord_ratio_limit * lo) continue;
      const double short_side = std::min(curves[a].length, curves[b].length);
      const double long_side = std::max(curves[a].length, curves[b].length);
      if (long_side > options.chord_length_ratio_limit * short_side) continue;
      uf.join(a, b);
      in_chord[a] = in_chord[b] = true;
    }
  }
  std::vector<LO> root2chord(static_cast<std::size_t>(nc), kNoIndex);
  std::vector<std::vector<LO>> chords;
  for (LO c = 0; c < nc; ++c) {
    if (!in_chord[c]) continue;
    LO& id = root2chord[uf.find(c)];
    if (id == kNoIndex) {
      id = static_cast<LO>(chords.size());
      chords.emplace_back();
    }
    q.curve2chord[c] = id;
    chords[id].push_back(c);
  }
  q.num_chords = static_cast<LO>(chords.size());
  const auto members = [&](LO c) -> std::vector<LO> {
    return q.curve2chord[c] == kNoIndex ? std::vector<LO>{c} : chords[q.curve2chord[c]];
  };

  // Prescriptions, checked in the order given; the first one of a chord fixes it.
  std::vector<int> fixed(static_cast<std::size_t>(nc), 0);
  std::vector<LO> fixed_by(static_cast<std::size_t>(nc), kNoIndex);
  for (const auto& [c, n] : options.prescribed) {
    if (c < 0 || c >= nc) {
      std::ostringstream os;
      os << "curve " << c
         << ": edge count prescribed for a curve that does not exist (the model has " << nc
         << " curves)";
      throw InputError(os.str());
    }
    if (curves[c].degenerate)
      throw InputError("curve " + std::to_string(c) + ": " + std::to_string(n) +
                       " edges prescribed on a degenerate curve (a pole), which has no length");
    if (n <= 0)
      throw InputError("curve " + std::to_string(c) + ": " + std::to_string(n) +
                       " edges prescribed, but a curve needs at least 1");
    if (options.even && n % 2 != 0)
      throw InputError("curve " + std::to_string(c) + ": " + std::to_string(n) +
                       " edges prescribed, but all-quad meshing by midpoint subdivision needs an "
                       "even count (odd counts are not supported yet)");
    for (const LO m : members(c)) {
      if (fixed[m] != 0 && fixed[m] != n) {
        const LO other = fixed_by[m];
        std::ostringstream os;
        if (other == c)
          os << "curve " << c << ": prescribed both " << fixed[m] << " and " << n << " edges";
        else
          os << "curves " << other << " and " << c
             << " are topologically parallel (one chord of four-sided faces) but are prescribed "
             << "different edge counts (" << fixed[m] << " and " << n << ")";
        throw InputError(os.str());
      }
      if (n < hard_minimum(m)) {
        std::ostringstream os;
        os << "curve " << c << ": " << n << " edges prescribed, but ";
        if (m != c) os << "curve " << m << ", in its chord, ";
        os << (closed(m) ? "is closed and needs at least 3"
                         : "shares both end corners with another curve and needs at least 2");
        throw InputError(os.str());
      }
      fixed[m] = n;
      fixed_by[m] = c;
    }
  }

  const auto round = [&](double x, int lo) {
    const long n = options.even ? 2 * std::lround(x / 2) : std::lround(x);
    return std::max(static_cast<int>(n), lo);
  };
  for (LO c = 0; c < nc; ++c) {
    if (curves[c].degenerate) continue;
    if (fixed[c] != 0) {
      q.edges[c] = fixed[c];
    } else if (q.curve2chord[c] == kNoIndex) {
      q.edges[c] = round(ideal[c], minimum(c));
    } else if (chords[q.curve2chord[c]].front() == c) {
      // Average the ideal values over the chord, each curve once, in increasing id (deterministic).
      const auto& chord = chords[q.curve2chord[c]];
      double sum = 0;
      int lo = 0;
      for (const LO m : chord) {
        sum += ideal[m];
        lo = std::max(lo, minimum(m));
      }
      const int n = round(sum / static_cast<double>(chord.size()), lo);
      for (const LO m : chord) q.edges[m] = n;
    }
  }
  q.total_edges = std::accumulate(q.edges.begin(), q.edges.end(), std::int64_t{0});
  return q;
}

std::vector<mesh::CurveMesh> place_vertices(const cad::CadModel& model,
                                            std::span<const mesh::CurveMesh> curves,
                                            std::span<const std::vector<double>> sizes,
                                            const Quantization& q, bool halved,
                                            const TaskArena& tasks, const PlaceOptions& options) {
  const LO nc = model.num_curves();
  QSMESH_CHECK(static_cast<LO>(curves.size()) == nc,
               curves.size() << " background curve meshes for " << nc << " curves");
  QSMESH_CHECK(static_cast<LO>(sizes.size()) == nc, sizes.size()
                                                        << " size lists for " << nc << " curves");
  QSMESH_CHECK(static_cast<LO>(q.edges.size()) == nc,
               q.edges.size() << " edge counts for " << nc << " curves");
  std::vector<mesh::CurveMesh> out(static_cast<std::size_t>(nc));
  QSMESH_CHECK(!options.align_chords || options.profile_samples >= 2,
               "profile_samples " << options.profile_samples << " is below 2");
  QSMESH_CHECK(!options.align_chords || options.align_length_ratio >= 1,
               "align_length_ratio " << options.align_length_ratio << " is below 1");
  for (LO c = 0; c < nc; ++c)
    if (!model.curves()[c].degenerate) check_sizes(c, curves[c], sizes[c]);
  const std::vector<std::vector<double>> profiles =
      options.align_chords ? shared_profiles(model, curves, sizes, q, options)
                           : std::vector<std::vector<double>>{};
  tasks.parallel_for(nc, [&](std::int64_t ci) {
    const LO c = static_cast<LO>(ci);
    const cad::Curve& curve = model.curves()[c];
    const mesh::CurveMesh& bg = curves[c];
    mesh::CurveMesh& m = out[c];
    if (curve.degenerate) {
      m = bg;
      m.curve = c;
      return;
    }
    const int total_edges = q.edges[c];
    QSMESH_CHECK(!halved || total_edges % 2 == 0,
                 "curve " << c << ": " << total_edges << " edges cannot be halved");
    const int n = halved ? total_edges / 2 : total_edges;
    QSMESH_CHECK(n >= 1, "curve " << c << ": " << n << " edges asked for");

    const std::vector<double> f = cumulative(bg, sizes[c]);
    const double total = f.back();
    m.curve = c;
    m.t.resize(static_cast<std::size_t>(n) + 1);
    m.t.front() = bg.t.front();
    m.t.back() = bg.t.back();
    if (!profiles.empty() && !profiles[c].empty()) {
      // The shared profile: vertex i where it reaches i/n, at that arc-length fraction.
      const auto& g = profiles[c];
      const std::vector<double> arc = arc_lengths(bg);
      std::size_t k = 0, j = 0;
      const std::size_t last_k = g.size() - 2, last_j = arc.size() - 2;
      for (int i = 1; i < n; ++i) {
        const double target = static_cast<double>(i) / n;
        while (k < last_k && g[k + 1] < target) ++k;
        const double dg = g[k + 1] - g[k];
        const double u = (static_cast<double>(k) + (dg > 0 ? (target - g[k]) / dg : 0.0)) /
                         static_cast<double>(g.size() - 1);
        const double x = arc.back() * std::clamp(u, 0.0, 1.0);
        while (j < last_j && arc[j + 1] < x) ++j;
        const double len = arc[j + 1] - arc[j];
        const double frac = len > 0 ? std::clamp((x - arc[j]) / len, 0.0, 1.0) : 0.0;
        m.t[i] = bg.t[j] + frac * (bg.t[j + 1] - bg.t[j]);
      }
    } else if (!(total > 0)) {
      // A background polyline of zero length (a curve shorter than its tolerance): equal steps in
      // t.
      for (int i = 1; i < n; ++i) m.t[i] = bg.t.front() + (bg.t.back() - bg.t.front()) * i / n;
    } else {
      std::size_t j = 0;
      const std::size_t last = f.size() - 2;
      for (int i = 1; i < n; ++i) {
        const double target = total * i / n;
        while (j < last && f[j + 1] < target) ++j;
        const double len = distance(bg.points[j], bg.points[j + 1]);
        const double frac = segment_fraction(len, sizes[c][j], sizes[c][j + 1], target - f[j]);
        m.t[i] = bg.t[j] + frac * (bg.t[j + 1] - bg.t[j]);
      }
    }
    m.points.resize(m.t.size());
    m.points.front() = model.corners()[curve.corners[0]].point;
    m.points.back() = model.corners()[curve.corners[1]].point;
    if (n > 1) {
      const auto geometry = model.curve_geometry(c);
      for (int i = 1; i < n; ++i) m.points[i] = geometry->point(m.t[i]);
    }
  });
  return out;
}

std::vector<LO> crossing_curves(const cad::CadModel& model, LO f,
                                std::span<const mesh::CurveMesh> curves) {
  const auto surface = model.face_geometry(f);
  const auto loops = background::face_boundary(model, f, *surface, curves);
  // Segments of every loop, with their curve (face_boundary gives each use its curve mesh's
  // edges in order) and their loop position (neighbours share a vertex and are not tested).
  struct Segment {
    Vec2 a, b;
    LO curve;
    LO loop, index, loop_size;
  };
  std::vector<Segment> segments;
  const cad::Face& face = model.faces()[f];
  for (LO l = 0; l < static_cast<LO>(loops.size()); ++l) {
    const auto& pts = loops[l].points;
    const auto n = static_cast<LO>(pts.size());
    LO k = 0;
    for (const cad::CurveUse& use : face.loops[l].uses)
      for (LO e = 0; e < curves[use.curve].num_edges() && k < n; ++e, ++k)
        segments.push_back({pts[k].uv, pts[(k + 1) % n].uv, use.curve, l, k, n});
  }
  std::vector<LO> out;
  // A loop of one or two segments encloses nothing (two curves joining the same corners, one
  // edge each on the halved meshes).
  for (std::size_t l = 0; l < loops.size(); ++l)
    if (!loops[l].points.empty() && loops[l].points.size() < 3)
      for (const cad::CurveUse& use : face.loops[l].uses) out.push_back(use.curve);
  const auto sorted_once = [&] {
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  };
  if (segments.size() < 2) return sorted_once();
  // A uniform grid over the loops' box, about one segment per cell, keeps this near-linear.
  Vec2 lo = segments[0].a, hi = segments[0].a;
  for (const Segment& s : segments)
    for (const Vec2& p : {s.a, s.b}) {
      lo = {std::min(lo.u, p.u), std::min(lo.v, p.v)};
      hi = {std::max(hi.u, p.u), std::max(hi.v, p.v)};
    }
  const int cells = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(segments.size()))));
  const double wu = std::max(hi.u - lo.u, 1e-300) / cells,
               wv = std::max(hi.v - lo.v, 1e-300) / cells;
  const auto cell_u = [&](double u) {
    return std::clamp(static_cast<int>((u - lo.u) / wu), 0, cells - 1);
  };
  const auto cell_v = [&](double v) {
    return std::clamp(static_cast<int>((v - lo.v) / wv), 0, cells - 1);
  };
  std::vector<std::vector<std::size_t>> grid(static_cast<std::size_t>(cells) * cells);
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const Segment& s = segments[i];
    for (int cu = cell_u(std::min(s.a.u, s.b.u)); cu <= cell_u(std::max(s.a.u, s.b.u)); ++cu)
      for (int cv = cell_v(std::min(s.a.v, s.b.v)); cv <= cell_v(std::max(s.a.v, s.b.v)); ++cv)
        grid[static_cast<std::size_t>(cu) * cells + cv].push_back(i);
  }
  const auto neighbours = [](const Segment& x, const Segment& y) {
    if (x.loop != y.loop) return false;
    const LO d = std::abs(x.index - y.index);
    return d <= 1 || d == x.loop_size - 1;
  };
  const auto sign = [](double x) { return (x > 0) - (x < 0); };
  // Collinear segments overlapping over a length: the boundary runs back over itself.
  const auto overlap = [](const Segment& x, const Segment& y) {
    const Vec2 d = x.b - x.a;
    const double len2 = d.u * d.u + d.v * d.v;
    if (!(len2 > 0)) return false;
    const auto at = [&](const Vec2& p) {
      return ((p.u - x.a.u) * d.u + (p.v - x.a.v) * d.v) / len2;
    };
    const double from = std::max(0.0, std::min(at(y.a), at(y.b)));
    const double to = std::min(1.0, std::max(at(y.a), at(y.b)));
    return to - from > 1e-12;
  };
  for (const auto& cell : grid)
    for (std::size_t i = 0; i < cell.size(); ++i)
      for (std::size_t j = i + 1; j < cell.size(); ++j) {
        const Segment& x = segments[cell[i]];
        const Segment& y = segments[cell[j]];
        const int o1 = sign(mesh::orient2d(x.a, x.b, y.a)),
                  o2 = sign(mesh::orient2d(x.a, x.b, y.b));
        const int o3 = sign(mesh::orient2d(y.a, y.b, x.a)),
                  o4 = sign(mesh::orient2d(y.a, y.b, x.b));
        const bool crossing = !neighbours(x, y) && o1 * o2 < 0 && o3 * o4 < 0;
        const bool folded = o1 == 0 && o2 == 0 && o3 == 0 && o4 == 0 && overlap(x, y);
        if (crossing || folded) {
          out.push_back(x.curve);
          out.push_back(y.curve);
        }
      }
  return sorted_once();
}

void refine_curves(Quantization& q, std::span<const LO> curves, std::span<const LO> fixed) {
  const auto nc = static_cast<LO>(q.edges.size());
  const bool chords = q.curve2chord.size() == q.edges.size();
  std::vector<char> frozen(q.edges.size(), 0);
  std::vector<char> frozen_chord(static_cast<std::size_t>(std::max<LO>(q.num_chords, 0)), 0);
  for (const LO c : fixed) {
    if (c < 0 || c >= nc) continue;
    frozen[c] = 1;
    if (chords && q.curve2chord[c] >= 0 && q.curve2chord[c] < q.num_chords)
      frozen_chord[q.curve2chord[c]] = 1;
  }
  std::vector<int> target(q.edges.size(), 0);
  std::map<LO, int> chord_target;  // chord -> largest doubled count among its flagged curves
  for (const LO c : curves) {
    if (c < 0 || c >= nc || q.edges[c] <= 0 || frozen[c] != 0) continue;
    if (chords && q.curve2chord[c] >= 0 && q.curve2chord[c] < q.num_chords &&
        frozen_chord[q.curve2chord[c]] != 0)
      continue;
    const int doubled = 2 * q.edges[c];
    target[c] = std::max(target[c], doubled);
    if (chords && q.curve2chord[c] != kNoIndex) {
      int& t = chord_target[q.curve2chord[c]];
      t = std::max(t, doubled);
    }
  }
  q.total_edges = 0;
  for (LO c = 0; c < nc; ++c) {
    int e = std::max(q.edges[c], target[c]);
    if (chords && q.curve2chord[c] != kNoIndex) {
      const auto it = chord_target.find(q.curve2chord[c]);
      if (it != chord_target.end() && q.edges[c] > 0) e = std::max(e, it->second);
    }
    q.edges[c] = e;
    q.total_edges += e;
  }
}

}  // namespace qsmesh::quantize
