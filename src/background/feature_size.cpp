#include "qsmesh/background/feature_size.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

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

/// Uniform hash grid over the polyline vertices of all curves.
class PointGrid {
 public:
  PointGrid(std::span<const std::vector<Vec3>> lines, double cell) : cell_(cell) {
    for (LO c = 0; c < static_cast<LO>(lines.size()); ++c)
      for (LO i = 0; i < static_cast<LO>(lines[c].size()); ++i) cells_[key(lines[c][i])].push_back({c, i});
  }

  /// For each curve with `eligible(curve)` that has a sample within `radius` of p: its nearest
  /// sample's (curve, sample index), in increasing curve id.
  template <class Eligible>
  [[nodiscard]] std::vector<std::pair<LO, LO>> candidates(std::span<const std::vector<Vec3>> lines,
                                                          const Vec3& p, double radius,
                                                          const Eligible& eligible) const {
    std::vector<std::pair<LO, LO>> best;  // (curve, sample)
    std::vector<double> best_d2;
    const double r2 = radius * radius;
    const auto r = static_cast<std::int64_t>(std::ceil(radius / cell_));
    const auto [cx, cy, cz] = coords(p);
    for (std::int64_t x = cx - r; x <= cx + r; ++x)
      for (std::int64_t y = cy - r; y <= cy + r; ++y)
        for (std::int64_t z = cz - r; z <= cz + r; ++z) {
          const auto it = cells_.find(pack(x, y, z));
          if (it == cells_.end()) continue;
          for (const auto& [c, i] : it->second) {
            const double d2 = norm2(lines[c][i] - p);
            if (d2 >= r2 || !eligible(c)) continue;
            std::size_t k = 0;
            while (k < best.size() && best[k].first != c) ++k;
            if (k == best.size()) {
              best.emplace_back(c, i);
              best_d2.push_back(d2);
            } else if (d2 < best_d2[k] || (d2 == best_d2[k] && i < best[k].second)) {
              best[k].second = i;
              best_d2[k] = d2;
            }
          }
        }
    std::sort(best.begin(), best.end());
    return best;
  }

 private:
  [[nodiscard]] std::array<std::int64_t, 3> coords(const Vec3& p) const {
    return {static_cast<std::int64_t>(std::floor(p.x / cell_)), static_cast<std::int64_t>(std::floor(p.y / cell_)),
            static_cast<std::int64_t>(std::floor(p.z / cell_))};
  }
  static std::uint64_t pack(std::int64_t x, std::int64_t y, std::int64_t z) {
    constexpr std::int64_t kBias = 1 << 20;
    return (static_cast<std::uint64_t>(x + kBias) << 42) ^ (static_cast<std::uint64_t>(y + kBias) << 21) ^
           static_cast<std::uint64_t>(z + kBias);
  }
  [[nodiscard]] std::uint64_t key(const Vec3& p) const {
    const auto [x, y, z] = coords(p);
    return pack(x, y, z);
  }
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<std::pair<LO, LO>>> cells_;
};

}  // namespace

void limit_by_feature_distance(const cad::CadModel& model, std::span<const std::vector<Vec3>> polylines,
                               std::vector<std::vector<double>>& sizes, double touching, double floor,
                               double cell, const TaskArena& tasks) {
  const PointGrid grid(polylines, cell);
  tasks.parallel_for(static_cast<std::int64_t>(polylines.size()), [&](std::int64_t i) {
    const auto c = static_cast<LO>(i);
    const auto& cc = model.curves()[c];
    // Curves sharing a corner are not features of each other (paper 000 Sec. 4.1: the nearest
    // non-adjacent curve). Counting them inside sharp wedges was tried and made things worse:
    // the boundary sizes then vary too fast near the corner.
    const auto adjacent = [&](LO other) {
      const auto& oc = model.curves()[other];
      return other == c || oc.corners[0] == cc.corners[0] || oc.corners[0] == cc.corners[1] ||
             oc.corners[1] == cc.corners[0] || oc.corners[1] == cc.corners[1];
    };
    const auto& line = polylines[c];
    auto& h = sizes[c];
    for (std::size_t k = 0; k < line.size(); ++k) {
      for (const auto& [o, j] : grid.candidates(polylines, line[k], h[k], [&](LO x) { return !adjacent(x); })) {
        // The other curve near its nearest vertex is the polyline through the vertices around it:
        // exact enough for dense polylines, and far cheaper than a CAD projection.
        const double d = distance_to_polyline(polylines[o], j, line[k]);
        // The floor bounds what a feature may ask for, never a size already smaller.
        if (d > touching) h[k] = std::min(h[k], std::max(floor, d));
      }
    }
  });
}

}  // namespace qsmesh::background
