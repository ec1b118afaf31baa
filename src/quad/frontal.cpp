#include "qsmesh/quad/frontal.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numbers>
#include <unordered_map>

#include "qsmesh/core/error.hpp"

namespace qsmesh::quad {

// ------------------------------------------------------------------------------------ FaceGuide

FaceGuide::FaceGuide(const mesh::FaceMesh& background,
                     const crossfield::FaceCrossField& cross_field, std::span<const double> sizes)
    : bg_(background), cf_(cross_field), sizes_(sizes) {
  const LO nv = bg_.num_vertices();
  QSMESH_CHECK(static_cast<LO>(sizes_.size()) == nv,
               "frontal guide: " << sizes_.size() << " sizes for " << nv << " background vertices");
  QSMESH_CHECK(
      static_cast<LO>(cf_.input2glued.size()) == nv && static_cast<LO>(bg_.uv.size()) == nv,
      "frontal guide: cross field and background mesh do not match");
  QSMESH_CHECK(cf_.directions.size() == cf_.triangles.size(),
               "frontal guide: cross field has no directions");
  for (double s : sizes_)
    QSMESH_CHECK(s > 0 && std::isfinite(s), "frontal guide: non-positive size " << s);
  // The glued triangulation drops the triangles that gluing collapses, in order; replay that to
  // find each background triangle's cross.
  const auto nt = static_cast<LO>(bg_.triangles.size());
  tri2glued_.assign(static_cast<std::size_t>(nt), kNoIndex);
  LO g = 0;
  for (LO t = 0; t < nt; ++t) {
    const auto& T = bg_.triangles[t];
    const LO a = cf_.input2glued[T[0]], b = cf_.input2glued[T[1]], c = cf_.input2glued[T[2]];
    if (a == b || b == c || c == a) continue;
    const bool same =
        g < static_cast<LO>(cf_.triangles.size()) && cf_.triangles[g] == std::array<LO, 3>{a, b, c};
    QSMESH_CHECK(
        same, "frontal guide: glued triangle " << g << " does not match background triangle " << t);
    tri2glued_[t] = g++;
  }
  QSMESH_CHECK(g == static_cast<LO>(cf_.triangles.size()),
               "frontal guide: triangle count mismatch");
  QSMESH_CHECK(g > 0, "frontal guide: no triangle");

  for (LO t = 0; t < nt; ++t)
    if (tri2glued_[t] != kNoIndex)
      for (LO v : bg_.triangles[t]) box_.add(bg_.uv[v]);
  const double wu = std::max(box_.hi.u - box_.lo.u, 1e-300),
               wv = std::max(box_.hi.v - box_.lo.v, 1e-300);
  // About one triangle per cell, cells as square as the box allows.
  const double cells = std::max(1.0, static_cast<double>(g));
  nu_ = std::clamp(static_cast<int>(std::ceil(std::sqrt(cells * wu / wv))), 1, 2048);
  nv_ = std::clamp(static_cast<int>(std::ceil(cells / nu_)), 1, 2048);
  cu_ = wu / nu_;
  cv_ = wv / nv_;
  std::vector<std::array<int, 4>> range(static_cast<std::size_t>(nt));
  std::vector<LO> count(static_cast<std::size_t>(nu_) * nv_ + 1, 0);
  for (LO t = 0; t < nt; ++t) {
    if (tri2glued_[t] == kNoIndex) continue;
    Box2 b;
    for (LO v : bg_.triangles[t]) b.add(bg_.uv[v]);
    auto cell = [](double x, double lo, double c, int n) {
      return std::clamp(static_cast<int>(std::floor((x - lo) / c)), 0, n - 1);
    };
    range[t] = {cell(b.lo.u, box_.lo.u, cu_, nu_), cell(b.hi.u, box_.lo.u, cu_, nu_),
                cell(b.lo.v, box_.lo.v, cv_, nv_), cell(b.hi.v, box_.lo.v, cv_, nv_)};
    for (int j = range[t][2]; j <= range[t][3]; ++j)
      for (int i = range[t][0]; i <= range[t][1]; ++i)
        ++count[static_cast<std::size_t>(j) * nu_ + i + 1];
  }
  for (std::size_t k = 1; k < count.size(); ++k) count[k] += count[k - 1];
  cell_start_ = count;
  cell_tris_.resize(static_cast<std::size_t>(count.back()));
  for (LO t = 0; t < nt; ++t) {
    if (tri2glued_[t] == kNoIndex) continue;
    for (int j = range[t][2]; j <= range[t][3]; ++j)
      for (int i = range[t][0]; i <= range[t][1]; ++i)
        cell_tris_[static_cast<std::size_t>(count[static_cast<std::size_t>(j) * nu_ + i]++)] = t;
  }
}

std::pair<double, double> FaceGuide::size_range() const {
  const auto [lo, hi] = std::minmax_element(sizes_.begin(), sizes_.end());
  return {*lo, *hi};
}

bool FaceGuide::barycentric(LO t, const Vec2& uv, std::array<double, 3>& w) const {
  const auto& T = bg_.triangles[t];
  const Vec2 a = bg_.uv[T[0]], b = bg_.uv[T[1]], c = bg_.uv[T[2]];
  const double area = cross(b - a, c - a);
  if (!(std::fabs(area) > 0)) return false;
  w = {cross(b - uv, c - uv) / area, cross(c - uv, a - uv) / area, cross(a - uv, b - uv) / area};
  return true;
}

FaceGuide::Sample FaceGuide::at(const Vec2& uv) const {
  const int ci = std::clamp(static_cast<int>(std::floor((uv.u - box_.lo.u) / cu_)), 0, nu_ - 1);
  const int cj = std::clamp(static_cast<int>(std::floor((uv.v - box_.lo.v) / cv_)), 0, nv_ - 1);
  LO best = kNoIndex;
  double best_min = -std::numeric_limits<double>::infinity();
  std::array<double, 3> best_w{1.0 / 3, 1.0 / 3, 1.0 / 3};
  bool found = false;
  // Ring 0 is the cell itself; further rings only when uv is in no triangle of the cells so far.
  for (int r = 0; r <= std::max(nu_, nv_) && !found; ++r) {
    for (int j = cj - r; j <= cj + r && !found; ++j) {
      if (j < 0 || j >= nv_) continue;
      for (int i = ci - r; i <= ci + r && !found; ++i) {
        if (i < 0 || i >= nu_ || (std::abs(i - ci) != r && std::abs(j - cj) != r)) continue;
        const std::size_t cell = static_cast<std::size_t>(j) * nu_ + i;
        for (LO k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
          const LO t = cell_tris_[k];
          std::array<double, 3> w;
          if (!barycentric(t, uv, w)) continue;
          const double m = std::min({w[0], w[1], w[2]});
          if (m > best_min) {
            best_min = m;
            best = t;
            best_w = w;
          }
          if (m >= -1e-12) {
            found = true;
            break;
          }
        }
      }
    }
    if (best != kNoIndex && r >= 1) break;  // the least-outside triangle of the neighbourhood
  }
  Sample s;
  QSMESH_CHECK(best != kNoIndex,
               "frontal guide: no background triangle near (" << uv.u << ", " << uv.v << ")");
  s.found = found;
  s.cross = cf_.directions[tri2glued_[best]];
  const auto& T = bg_.triangles[best];
  if (!found) {  // clamp to the triangle so that the size stays within its vertex values
    for (double& x : best_w) x = std::max(x, 0.0);
    const double sum = best_w[0] + best_w[1] + best_w[2];
    for (double& x : best_w) x = sum > 0 ? x / sum : 1.0 / 3;
  }
  s.size = best_w[0] * sizes_[T[0]] + best_w[1] * sizes_[T[1]] + best_w[2] * sizes_[T[2]];
  return s;
}

// ------------------------------------------------------------------------------ frontal points

namespace {

// Even-odd point-in-domain test on the boundary loops in (u, v), with the segments binned in
// horizontal rows so that a test costs the segments of one row.
class LoopTest {
 public:
  explicit LoopTest(std::span<const mesh::BoundaryLoop> loops) {
    for (const auto& L : loops) {
      const std::size_t n = L.points.size();
      for (std::size_t i = 0; i < n; ++i) {
        const Vec2 a = L.points[i].uv, b = L.points[(i + 1) % n].uv;
        if (a.v == b.v) continue;  // never crossed by the half-open rule
        segs_.push_back({a, b});
        box_.add(a);
        box_.add(b);
      }
    }
    rows_ = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(segs_.size()))), 1, 4096);
    h_ = std::max(box_.hi.v - box_.lo.v, 1e-300) / rows_;
    start_.assign(static_cast<std::size_t>(rows_) + 1, 0);
    auto rows_of = [&](const std::array<Vec2, 2>& s) {
      return std::array<int, 2>{row(std::min(s[0].v, s[1].v)), row(std::max(s[0].v, s[1].v))};
    };
    for (const auto& s : segs_) {
      const auto r = rows_of(s);
      for (int k = r[0]; k <= r[1]; ++k) ++start_[static_cast<std::size_t>(k) + 1];
    }
    for (std::size_t k = 1; k < start_.size(); ++k) start_[k] += start_[k - 1];
    std::vector<LO> fill(start_.begin(), start_.end() - 1);
    items_.resize(static_cast<std::size_t>(start_.back()));
    for (LO i = 0; i < static_cast<LO>(segs_.size()); ++i) {
      const auto r = rows_of(segs_[i]);
      for (int k = r[0]; k <= r[1]; ++k) items_[static_cast<std::size_t>(fill[k]++)] = i;
    }
  }

  [[nodiscard]] bool inside(const Vec2& p) const {
    if (segs_.empty() || p.v < box_.lo.v || p.v > box_.hi.v || p.u < box_.lo.u || p.u > box_.hi.u)
      return false;
    const int r = row(p.v);
    bool in = false;
    for (LO k = start_[r]; k < start_[r + 1]; ++k) {
      const Vec2 a = segs_[items_[k]][0], b = segs_[items_[k]][1];
      if ((a.v <= p.v) == (b.v <= p.v)) continue;
      const double u = a.u + (p.v - a.v) * (b.u - a.u) / (b.v - a.v);
      if (u > p.u) in = !in;
    }
    return in;
  }

 private:
  std::vector<std::array<Vec2, 2>> segs_;
  Box2 box_;
  int rows_ = 1;
  double h_ = 1;
  std::vector<LO> start_, items_;
  [[nodiscard]] int row(double v) const {
    return std::clamp(static_cast<int>(std::floor((v - box_.lo.v) / h_)), 0, rows_ - 1);
  }
};

// Points in 3D, each stored in every level of a stack of uniform hash grids whose cell sizes
// double from level to level: a query of radius r reads the 27 cells of the first level whose
// cells are at least r wide, so that the cost does not depend on how much the sizes vary over
// the face. Hash collisions only add candidates; distances decide.
class PointIndex {
 public:
  PointIndex(double r_min, double r_max) : base_(r_min) {
    QSMESH_CHECK(r_min > 0 && std::isfinite(r_min) && r_max >= r_min, "frontal: bad spacing range");
    levels_ = std::clamp(static_cast<int>(std::ceil(std::log2(r_max / r_min))) + 1, 1, 24);
    grids_.resize(static_cast<std::size_t>(levels_));
  }

  void add(const Vec3& p, double weight) {
    const LO id = static_cast<LO>(pts_.size());
    pts_.push_back(p);
    weight_.push_back(weight);
    for (int l = 0; l < levels_; ++l) {
      const double c = cell(l);
      grids_[l][key(coord(p.x, c), coord(p.y, c), coord(p.z, c))].push_back(id);
    }
  }

  /// True when some point j lies closer to p than r x weight_j; with a frame (d1, d2: unit,
  /// orthogonal), when j lies in the square of half-width r x weight_j around p with sides along
  /// d1 and d2 and within its circumscribed sphere (which bounds the offset along the normal).
  [[nodiscard]] bool crowded(const Vec3& p, double r, const Vec3* d1 = nullptr,
                             const Vec3* d2 = nullptr) const {
    const bool square = d1 != nullptr && d2 != nullptr;
    const double reach = square ? r * std::numbers::sqrt2 : r;  // to the square's corners
    int l = 0;
    while (l + 1 < levels_ && cell(l) < reach) ++l;
    const double c = cell(l);
    const std::int64_t x = coord(p.x, c), y = coord(p.y, c), z = coord(p.z, c);
    const auto ring = static_cast<std::int64_t>(std::max(1.0, std::ceil(reach / c)));
    const auto& grid = grids_[l];
    for (std::int64_t i = x - ring; i <= x + ring; ++i)
      for (std::int64_t j = y - ring; j <= y + ring; ++j)
        for (std::int64_t k = z - ring; k <= z + ring; ++k) {
          const auto it = grid.find(key(i, j, k));
          if (it == grid.end()) continue;
          for (LO id : it->second) {
            const double rr = reach * weight_[id];
            const Vec3 d = pts_[id] - p;
            if (norm2(d) >= rr * rr) continue;
            if (!square) return true;
            const double half = r * weight_[id];
            if (std::abs(dot(d, *d1)) < half && std::abs(dot(d, *d2)) < half) return true;
          }
        }
    return false;
  }

 private:
  double base_;
  int levels_ = 1;
  std::vector<Vec3> pts_;
  std::vector<double> weight_;
  std::vector<std::unordered_map<std::uint64_t, std::vector<LO>>> grids_;
  [[nodiscard]] double cell(int l) const { return std::ldexp(base_, l); }
  static std::int64_t coord(double x, double c) {
    return static_cast<std::int64_t>(std::floor(x / c));
  }
  static std::uint64_t key(std::int64_t i, std::int64_t j, std::int64_t k) {
    auto mix = [](std::uint64_t h, std::uint64_t v) {
      h ^= v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
      return h;
    };
    return mix(mix(mix(0, static_cast<std::uint64_t>(i)), static_cast<std::uint64_t>(j)),
               static_cast<std::uint64_t>(k));
  }
};

// (u, v) of the surface point nearest to `target`, from uv0, by damped Gauss-Newton on the
// surface Jacobian; false when it does not settle to a finite point.
bool map_to_surface(const cad::FaceGeometry& surface, const Vec2& uv0, const Vec3& target, Vec2& uv,
                    cad::SurfaceEval& e) {
  uv = uv0;
  e = surface.eval(uv);
  for (int it = 0; it < 8; ++it) {
    const Vec3 r = target - e.p;
    const double a = dot(e.du, e.du), b = dot(e.du, e.dv), c = dot(e.dv, e.dv);
    // Damping relative to the metric keeps the step bounded where the parametrisation degenerates
    // (poles), at the price of a slower approach there.
    const double lambda = 1e-10 * (a + c) + 1e-300;
    const double det = (a + lambda) * (c + lambda) - b * b;
    if (!(det > 0)) return false;
    const double ru = dot(e.du, r), rv = dot(e.dv, r);
    const Vec2 d{((c + lambda) * ru - b * rv) / det, ((a + lambda) * rv - b * ru) / det};
    if (!std::isfinite(d.u) || !std::isfinite(d.v)) return false;
    uv += d;
    e = surface.eval(uv);
    const double du = std::sqrt(a) * std::fabs(d.u) + std::sqrt(c) * std::fabs(d.v);
    if (du <= 1e-6 * norm(r) + 1e-300) break;
  }
  return std::isfinite(uv.u) && std::isfinite(uv.v) && std::isfinite(e.p.x);
}

struct Node {
  Vec2 uv;
  Vec3 xyz;
};

}  // namespace

std::vector<Vec2> frontal_points(const cad::FaceGeometry& surface,
                                 std::span<const mesh::BoundaryLoop> loops, const FaceGuide& guide,
                                 const FrontalOptions& options, FrontalStats* stats) {
  QSMESH_CHECK(options.spacing_factor > 0 && options.min_distance > 0 && options.min_distance < 1,
               "frontal: spacing_factor must be > 0 and min_distance in (0, 1)");
  FrontalStats local;
  FrontalStats& st = stats != nullptr ? *stats : local;
  st = FrontalStats{};
  const LoopTest domain(loops);

  std::vector<Node> nodes;
  std::vector<double> spacing;  // per node: spacing_factor x s
  auto spacing_at = [&](const Vec2& uv) {
    const FaceGuide::Sample s = guide.at(uv);
    if (!s.found) ++st.off_guide;
    return options.spacing_factor * s.size;
  };
  for (const auto& L : loops)
    for (const auto& p : L.points) {
      nodes.push_back({p.uv, p.xyz});
      spacing.push_back(spacing_at(p.uv));
    }
  QSMESH_CHECK(!nodes.empty(), "frontal: no boundary point");
  // The hash levels span the smallest and largest spacing a query can use: the guide's sizes are
  // interpolated, so they stay within the background vertex values.
  double smin = *std::min_element(spacing.begin(), spacing.end());
  double smax = *std::max_element(spacing.begin(), spacing.end());
  const auto [gmin, gmax] = guide.size_range();
  smin = std::min(smin, options.spacing_factor * gmin);
  smax = std::max(smax, options.spacing_factor * gmax);
  PointIndex index(options.min_distance * smin * 0.5, options.min_distance * smax * 2);
  for (const auto& n : nodes) index.add(n.xyz, 1.0);
  // Samples along the boundary segments: a point must not hug a segment longer than its spacing.
  constexpr double kSegmentWeight = 0.6;
  for (const auto& L : loops) {
    const std::size_t n = L.points.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2 a = L.points[i].uv, b = L.points[(i + 1) % n].uv;
      const double len = distance(L.points[i].xyz, L.points[(i + 1) % n].xyz);
      if (!(len > 0)) continue;
      for (int k = 1; k < 4; ++k) {
        const double t = k / 4.0;
        index.add(surface.eval(a * (1 - t) + b * t).p, kSegmentWeight);
      }
    }
  }

  std::vector<Vec2> out;
  std::deque<LO> queue;
  for (LO i = 0; i < static_cast<LO>(nodes.size()); ++i) queue.push_back(i);
  while (!queue.empty() && st.accepted < options.max_points) {
    const LO i = queue.front();
    queue.pop_front();
    const Node x = nodes[i];
    const double h = spacing[i];
    const cad::SurfaceEval ex = surface.eval(x.uv);
    const FaceGuide::Sample g = guide.at(x.uv);
    Vec3 n = cross(ex.du, ex.dv);
    const double nn = norm(n);
    n = nn > 0 ? n / nn : Vec3{0, 0, 0};
    Vec3 d1 = g.cross[0] - n * dot(g.cross[0], n);
    if (!(norm(d1) > 1e-9)) d1 = ex.du;
    if (!(norm(d1) > 0)) continue;
    d1 = normalized(d1);
    Vec3 d2 = nn > 0 ? cross(n, d1) : g.cross[1];
    if (!(norm(d2) > 0)) continue;
    d2 = normalized(d2);
    for (const Vec3& d : {d1, d2, d1 * -1.0, d2 * -1.0}) {
      if (st.accepted >= options.max_points) break;
      ++st.proposed;
      Vec2 uv;
      cad::SurfaceEval ey;
      if (!map_to_surface(surface, x.uv, x.xyz + d * h, uv, ey) || !domain.inside(uv)) {
        ++st.outside;
        continue;
      }
      const double moved = distance(ey.p, x.xyz);
      if (!(moved > 0.5 * h && moved < 1.5 * h)) {  // the map went astray (pole, fold, trim)
        ++st.outside;
        continue;
      }
      const double hy = spacing_at(uv);
      const bool square = options.cross_aligned_exclusion;
      if (index.crowded(ey.p, options.min_distance * hy, square ? &d1 : nullptr,
                        square ? &d2 : nullptr)) {
        ++st.too_close;
        continue;
      }
      index.add(ey.p, 1.0);
      nodes.push_back({uv, ey.p});
      spacing.push_back(hy);
      queue.push_back(static_cast<LO>(nodes.size()) - 1);
      out.push_back(uv);
      ++st.accepted;
    }
  }
  return out;
}

}  // namespace qsmesh::quad
