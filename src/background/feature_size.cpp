#include "qsmesh/background/feature_size.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <vector>

#include "qsmesh/core/error.hpp"

namespace qsmesh::background {

namespace {

/// Distance from p to the two polyline segments around vertex j.
double distance_to_polyline(const std::vector<Vec3>& line, LO j, const Vec3& p) {
  auto segment = [&](std::size_t a, std::size_t b) {
    const Vec3 ab = line[b] - line[a];
    const double l2 = norm2(ab);
    const double s = l2 > 0 ? std::clamp(dot(p - line[a], ab) / l2, 0.0, 1.0) : 0.0;
    return distance(p, line[a] + ab * s);
  };
  const auto i = static_cast<std::size_t>(j);
  double d = distance(p, line[i]);
  if (i > 0) d = std::min(d, segment(i - 1, i));
  if (i + 1 < line.size()) d = std::min(d, segment(i, i + 1));
  return d;
}

/// Static k-d tree over the polyline vertices of all curves. The search radius of a vertex is its
/// current size, which varies by orders of magnitude over a model whose background follows the
/// geometry (a far-field box next to a wing); a uniform grid sized for one end is quadratic at the
/// other, the tree is not.
class PointTree {
 public:
  explicit PointTree(std::span<const std::vector<Vec3>> lines) {
    for (LO c = 0; c < static_cast<LO>(lines.size()); ++c)
      for (LO i = 0; i < static_cast<LO>(lines[c].size()); ++i)
        items_.push_back({lines[c][i], c, i});
    splits_.assign(items_.size(), Split{});
    if (!items_.empty()) build(0, items_.size());
  }

  /// For each curve with `eligible(curve)` that has a sample within `radius` of p: its nearest
  /// sample's (curve, sample index), in increasing curve id; ties go to the smaller index.
  template <class Eligible>
  [[nodiscard]] std::vector<std::pair<LO, LO>> candidates(const Vec3& p, double radius,
                                                          const Eligible& eligible) const {
    std::vector<std::pair<LO, LO>> best;  // (curve, sample)
    std::vector<double> best_d2;
    if (items_.empty()) return best;
    const double r2 = radius * radius;
    search(0, items_.size(), p, r2, [&](const Item& it, double d2) {
      if (!eligible(it.curve)) return;
      std::size_t k = 0;
      while (k < best.size() && best[k].first != it.curve) ++k;
      if (k == best.size()) {
        best.emplace_back(it.curve, it.index);
        best_d2.push_back(d2);
      } else if (d2 < best_d2[k] || (d2 == best_d2[k] && it.index < best[k].second)) {
        best[k].second = it.index;
        best_d2[k] = d2;
      }
    });
    std::sort(best.begin(), best.end());
    return best;
  }

 private:
  struct Item {
    Vec3 p;
    LO curve, index;
  };
  struct Split {
    int axis = -1;  // -1: a leaf
    double value = 0;
  };
  static constexpr std::size_t kLeaf = 16;

  static double coord(const Vec3& p, int axis) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; }

  // Nodes are implicit: the range [lo, hi) splits at its middle, and splits_[middle] says how
  // (the middles of different nodes differ).
  void build(std::size_t lo, std::size_t hi) {
    if (hi - lo <= kLeaf) return;
    Box3 box;
    for (std::size_t i = lo; i < hi; ++i) box.add(items_[i].p);
    const Vec3 extent = box.hi - box.lo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0
                     : extent.y >= extent.z                       ? 1
                                                                  : 2;
    const std::size_t mid = lo + (hi - lo) / 2;
    // Ties on the coordinate are ordered by (curve, index), so the tree is the same on every run.
    std::nth_element(items_.begin() + static_cast<std::ptrdiff_t>(lo),
                     items_.begin() + static_cast<std::ptrdiff_t>(mid),
                     items_.begin() + static_cast<std::ptrdiff_t>(hi),
                     [axis](const Item& a, const Item& b) {
                       const double ca = coord(a.p, axis), cb = coord(b.p, axis);
                       if (ca != cb) return ca < cb;
                       return a.curve != b.curve ? a.curve < b.curve : a.index < b.index;
                     });
    splits_[mid] = {axis, coord(items_[mid].p, axis)};
    build(lo, mid);
    build(mid, hi);
  }

  template <class Visit>
  void search(std::size_t lo, std::size_t hi, const Vec3& p, double r2, const Visit& visit) const {
    if (hi - lo <= kLeaf) {
      for (std::size_t i = lo; i < hi; ++i) {
        const double d2 = norm2(items_[i].p - p);
        if (d2 < r2) visit(items_[i], d2);
      }
      return;
    }
    const std::size_t mid = lo + (hi - lo) / 2;
    const Split& s = splits_[mid];
    const double d = coord(p, s.axis) - s.value;
    // Items of [lo, mid) are at most s.value on the axis, those of [mid, hi) at least.
    if (d <= 0 || d * d < r2) search(lo, mid, p, r2, visit);
    if (d >= 0 || d * d < r2) search(mid, hi, p, r2, visit);
  }

  std::vector<Item> items_;
  std::vector<Split> splits_;
};

}  // namespace

namespace {

/// limit_by_distance on curve c alone, its sizes h, with the tree of all polylines: a curve's
/// result depends on no other curve's sizes (CurveFeatureSearch splits the curves by it).
template <class Eligible, class Accept>
void limit_curve_by_distance(const PointTree& tree, std::span<const std::vector<Vec3>> polylines,
                             LO c, std::vector<double>& h, double touching, double floor,
                             const Eligible& eligible, const Accept& accept) {
  const auto& line = polylines[c];
  for (std::size_t k = 0; k < line.size(); ++k) {
    for (const auto& [o, j] :
         tree.candidates(line[k], h[k], [&](LO x) { return eligible(c, x); })) {
      // The other curve near its nearest vertex is the polyline through the vertices around it:
      // exact enough for dense polylines, and far cheaper than a CAD projection.
      const double d = distance_to_polyline(polylines[o], j, line[k]);
      // The floor bounds what a feature may ask for, never a size already smaller.
      // accept gives the factor the distance counts with (false / 0: not at all).
      const double scale = d > touching ? static_cast<double>(accept(c, o, line[k], d)) : 0.0;
      if (scale > 0) h[k] = std::min(h[k], std::max(floor, scale * d));
    }
  }
}

/// Lowers sizes[c][k] to the distance d to the nearest curve `eligible(c, other)` admits where
/// `accept(c, other, point, d)`, within the current size; distances up to `touching` ignored,
/// never below `floor` from a feature.
template <class Eligible, class Accept>
void limit_by_distance(std::span<const std::vector<Vec3>> polylines,
                       std::vector<std::vector<double>>& sizes, double touching, double floor,
                       const TaskArena& tasks, const Eligible& eligible, const Accept& accept) {
  const PointTree tree(polylines);
  tasks.parallel_for(static_cast<std::int64_t>(polylines.size()), [&](std::int64_t i) {
    const auto c = static_cast<LO>(i);
    limit_curve_by_distance(tree, polylines, c, sizes[c], touching, floor, eligible, accept);
  });
}

bool share_corner(const cad::CadModel& model, LO a, LO b) {
  const auto& ca = model.curves()[a];
  const auto& cb = model.curves()[b];
  return a == b || cb.corners[0] == ca.corners[0] || cb.corners[0] == ca.corners[1] ||
         cb.corners[1] == ca.corners[0] || cb.corners[1] == ca.corners[1];
}

/// The faces using each curve (sorted, each once).
std::vector<std::vector<LO>> faces_of_curves(const cad::CadModel& model, std::size_t num_curves) {
  std::vector<std::vector<LO>> faces(num_curves);
  for (LO f = 0; f < model.num_faces(); ++f)
    for (const auto& loop : model.faces()[f].loops)
      for (const auto& use : loop.uses)
        if (use.curve >= 0 && use.curve < static_cast<LO>(faces.size()))
          faces[use.curve].push_back(f);
  for (auto& list : faces) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return faces;
}

/// The distance from p to the nearer corner curves a and b share (a crescent's sides share both);
/// infinite when they share none.
double shared_corner_distance(const cad::CadModel& model, LO a, LO b, const Vec3& p) {
  double r = std::numeric_limits<double>::infinity();
  for (const LO k : model.curves()[a].corners)
    if (k >= 0 && (k == model.curves()[b].corners[0] || k == model.curves()[b].corners[1]))
      r = std::min(r, distance(p, model.corners()[k].point));
  return r;
}

/// Two sides of a wedge whose tail is graded (thin_aspect): both bound one face and no other.
/// A side another face also uses carries the tail's counts into that face, which pays for them
/// with transitions across it: t20_data's chamfer slivers (0-degree cusps between faces filled
/// by grids) at their reference size went from 60 quads below SICN 0.1 to 2, but from 87 to 212
/// interior irregular vertices and SICN avg 0.984 to 0.925 (docs/benchmarks.md, issue 29).
bool own_wedge_sides(const std::vector<std::vector<LO>>& faces, LO a, LO b) {
  return faces[a].size() == 1 && faces[b].size() == 1 && faces[a][0] == faces[b][0];
}

// The curves limit_by_feature_distance counts, as limit_by_distance's `eligible` and `accept`.
struct FeatureRule {
  const cad::CadModel& model;
  // Curves sharing a corner are not features of each other (paper 000 Sec. 4.1: the nearest
  // non-adjacent curve). Counting them inside sharp wedges was tried and made things worse:
  // the boundary sizes then vary too fast near the corner.
  bool operator()(LO c, LO other) const { return !share_corner(model, c, other); }
  bool operator()(LO, LO, const Vec3&, double) const { return true; }
};

// The curves limit_in_sharp_wedges counts: the other side of a wedge of c's own face, where it is
// sharper than sin(sharp) (the sizes are halved before and doubled after).
struct WedgeRule {
  const cad::CadModel& model;
  const std::vector<std::vector<LO>>& faces;
  double sharp;
  bool operator()(LO c, LO other) const { return other != c && own_wedge_sides(faces, c, other); }
  bool operator()(LO c, LO other, const Vec3& p, double d) const {
    const double r = shared_corner_distance(model, c, other, p);
    return std::isfinite(r) && d < sharp * r;
  }
};

}  // namespace

void limit_by_feature_distance(const cad::CadModel& model,
                               std::span<const std::vector<Vec3>> polylines,
                               std::vector<std::vector<double>>& sizes, double touching,
                               double floor, const TaskArena& tasks) {
  limit_by_distance(polylines, sizes, touching, floor, tasks, FeatureRule{model},
                    FeatureRule{model});
}

void limit_by_face_width(const cad::CadModel& model, std::span<const std::vector<Vec3>> polylines,
                         std::vector<std::vector<double>>& sizes, double touching,
                         double wedge_touching, double sliver, const TaskArena& tasks,
                         bool shared_wedges_only) {
  // The faces of each curve, sorted: two curves are sides of one face when the lists intersect.
  const std::vector<std::vector<LO>> faces = faces_of_curves(model, polylines.size());
  const auto share_face = [&](LO a, LO b) {
    const auto &fa = faces[a], &fb = faces[b];
    auto i = fa.begin(), j = fb.begin();
    while (i != fa.end() && j != fb.end()) {
      if (*i == *j) return true;
      if (*i < *j)
        ++i;
      else
        ++j;
    }
    return false;
  };
  // Corners joined by a curve shorter than `sliver`: (corner, corner, its length), both orders.
  struct Joint {
    LO a, b;
    double length;
    bool operator<(const Joint& o) const {
      return a != o.a ? a < o.a : b != o.b ? b < o.b : length < o.length;
    }
  };
  std::vector<Joint> joints;
  for (const auto& curve : model.curves())
    if (!curve.degenerate && curve.length < sliver && curve.corners[0] != curve.corners[1] &&
        curve.corners[0] >= 0 && curve.corners[1] >= 0) {
      joints.push_back({curve.corners[0], curve.corners[1], curve.length});
      joints.push_back({curve.corners[1], curve.corners[0], curve.length});
    }
  std::sort(joints.begin(), joints.end());
  // Two sides joined by a sliver curve are a strip whose end it is (as far apart as it is long),
  // or a wedge whose tip it cuts off (wing_fuselage's wing-root trailing edges, a 0.04-long curve
  // between sides 0.1-1 apart around it). The wedge's sides count only where they are closer than
  // sin(10 degrees) x the distance to the sliver, as a strip's do: the sizes graded toward the
  // blunted tip of an ordinary wedge gave its small faces irregular vertices (across
  // wing_fuselage's window up to 19 more, SICN avg 0.004-0.008 lower; docs/benchmarks.md), and
  // the quads at the sliver stayed flat.
  const double sharp = std::sin(10 * std::numbers::pi / 180);
  const auto corners = model.corners();
  // Sides meeting at a corner count only inside a wedge sharper than 10 degrees (a cusp's tail),
  // and not at its tip (sharp_wedge_tips: one edge there, so the grading toward the cusp stops).
  limit_by_distance(
      polylines, sizes, touching, 0.0, tasks,
      [&](LO c, LO other) { return other != c && share_face(c, other); },
      [&](LO c, LO other, const Vec3& p, double d) -> double {
        // Sides meeting at a corner count inside a wedge sharper than 10 degrees (a cusp's tail),
        // at 3/4 of their distance: the tail's quads are trapezoids whose inner row the smoothing
        // places, and came out at about 0.8 of the SICN of the rectangles the cap aims at (the
        // crescent and 5-degree corner of tests/drivers/test_thin_regions.cpp: 0.174 and 0.196
        // at the full distance, 0.211 and 0.246 at 3/4).
        double scale = 1;
        const double r = shared_corner_distance(model, c, other, p);
        if (std::isfinite(r)) {
          // The tip, where the sides are closer than wedge_touching, is one edge
          // (sharp_wedge_tips): the tail's grading stops there.
          if (!(d < sharp * r) || !(d > wedge_touching)) return 0;
          if (own_wedge_sides(faces, c, other) == shared_wedges_only) return 0;
          scale = shared_wedges_only ? 1.0 : 0.75;
        } else if (shared_wedges_only) {
          return 0;
        }
        for (const LO a : model.curves()[c].corners)
          for (const LO b : model.curves()[other].corners) {
            if (a < 0) continue;
            auto it = std::lower_bound(joints.begin(), joints.end(), Joint{a, b, 0.0});
            for (; it != joints.end() && it->a == a && it->b == b; ++it) {
              const double from_joint = distance(p, corners[a].point);
              // Sides closer than wedge_touching next to the sliver (within 4 x its length) are
              // the tip of a blunted wedge, not a strip: grading them toward the sliver gave
              // wing_fuselage's fairings (the wing roots' 0.036-long trailing edges) 20 more
              // interior irregular vertices at its reference size (docs/benchmarks.md).
              if (!(d > wedge_touching) && from_joint < 4 * it->length) return 0;
              if (!(d <= 2 * it->length || d < sharp * from_joint)) return 0;
            }
          }
        return scale;
      });
}

struct CurveFeatureSearch::Impl {
  Impl(const cad::CadModel& m, std::vector<std::vector<Vec3>> lines)
      : model(m),
        polylines(std::move(lines)),
        faces(faces_of_curves(m, polylines.size())),
        tree(polylines) {}
  /// QSMESH_CHECK that h has one size per vertex of polyline c.
  void check_sizes(LO c, const std::vector<double>& h) const;
  const cad::CadModel& model;
  std::vector<std::vector<Vec3>> polylines;
  std::vector<std::vector<LO>> faces;
  PointTree tree;
};

CurveFeatureSearch::CurveFeatureSearch(const cad::CadModel& model,
                                       std::vector<std::vector<Vec3>> polylines)
    : impl_(std::make_unique<Impl>(model, std::move(polylines))) {}
CurveFeatureSearch::~CurveFeatureSearch() = default;
CurveFeatureSearch::CurveFeatureSearch(CurveFeatureSearch&&) noexcept = default;
CurveFeatureSearch& CurveFeatureSearch::operator=(CurveFeatureSearch&&) noexcept = default;

void CurveFeatureSearch::Impl::check_sizes(LO c, const std::vector<double>& h) const {
  QSMESH_CHECK(h.size() == polylines[c].size(), "curve " << c << ": " << h.size() << " sizes for "
                                                         << polylines[c].size() << " points");
}

void CurveFeatureSearch::limit_by_feature_distance(LO c, std::vector<double>& h, double touching,
                                                   double floor) const {
  impl_->check_sizes(c, h);
  const FeatureRule rule{impl_->model};
  limit_curve_by_distance(impl_->tree, impl_->polylines, c, h, touching, floor, rule, rule);
}

void CurveFeatureSearch::limit_in_sharp_wedges(LO c, std::vector<double>& h, double touching,
                                               double sharp_deg) const {
  impl_->check_sizes(c, h);
  // Searched within half the size, lowered to the width, then doubled: at most twice the width.
  const WedgeRule rule{impl_->model, impl_->faces, std::sin(sharp_deg * std::numbers::pi / 180)};
  for (double& x : h) x *= 0.5;
  limit_curve_by_distance(impl_->tree, impl_->polylines, c, h, touching, 0.0, rule, rule);
  for (double& x : h) x *= 2;
}

std::vector<SharpTip> sharp_wedge_tips(const cad::CadModel& model,
                                       std::span<const std::vector<Vec3>> polylines,
                                       std::span<const std::vector<double>> sizes, double touching,
                                       double shared_ratio, double sharp_deg) {
  const auto faces = faces_of_curves(model, polylines.size());
  const auto share_face = [&](LO a, LO b) {
    for (const LO f : faces[a])
      if (std::binary_search(faces[b].begin(), faces[b].end(), f)) return true;
    return false;
  };
  const auto distance_to = [&](const std::vector<Vec3>& line, const Vec3& p) {
    double d = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i + 1 < line.size(); ++i) {
      const Vec3 ab = line[i + 1] - line[i];
      const double l2 = norm2(ab);
      const double s = l2 > 0 ? std::clamp(dot(p - line[i], ab) / l2, 0.0, 1.0) : 0.0;
      d = std::min(d, distance(p, line[i] + ab * s));
    }
    return d;
  };
  const double sharp = std::sin(sharp_deg * std::numbers::pi / 180);
  const auto corners = model.corners();
  std::vector<SharpTip> tips;
  const auto nc = static_cast<LO>(polylines.size());
  for (LO c = 0; c < nc; ++c) {
    const auto& line = polylines[c];
    const auto& curve = model.curves()[c];
    if (curve.degenerate || line.size() < 2 || curve.corners[0] == curve.corners[1]) continue;
    for (int end = 0; end < 2; ++end) {
      const LO k = curve.corners[end];
      if (k < 0) continue;
      double tip = 0;
      bool shared = false;
      for (LO o = 0; o < nc; ++o) {
        const auto& other = model.curves()[o];
        if (o == c || other.degenerate || polylines[o].size() < 2 ||
            (other.corners[0] != k && other.corners[1] != k) || !share_face(c, o))
          continue;
        const bool own = own_wedge_sides(faces, c, o);
        // Walk away from the corner while the two sides stay inside a sharp wedge and closer
        // than the tip's width: that stretch is the tip, which one quad holds.
        for (std::size_t j = 1; j < line.size(); ++j) {
          const std::size_t i = end == 0 ? j : line.size() - 1 - j;
          const Vec3& p = line[i];
          const double r = distance(p, corners[k].point);
          const double d = distance_to(polylines[o], p);
          if (!(d < sharp * r) || !(d <= (own ? touching : shared_ratio * sizes[c][i]))) break;
          if (r > tip) {
            tip = r;
            shared = !own;
          }
        }
      }
      // Two tips of one curve never overlap.
      tip = std::min(tip, 0.5 * distance(line.front(), line.back()));
      if (tip > 0) tips.push_back({c, end, tip, shared});
    }
  }
  return tips;
}

}  // namespace qsmesh::background
