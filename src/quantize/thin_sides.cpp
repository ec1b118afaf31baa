// Aligned vertices on the two sides of thin faces (issue 29): see align_thin_sides in
// quantize.hpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/quantize/quantize.hpp"

namespace qsmesh::quantize {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// The point of a background polyline nearest to p: its distance, curve parameter and arc length.
struct Foot {
  double d = kInf;
  double t = 0;
  double arc = 0;
  Vec3 p;
};

Foot nearest_on(const mesh::CurveMesh& bg, const std::vector<double>& arc, const Vec3& p) {
  Foot best;
  for (std::size_t k = 0; k + 1 < bg.points.size(); ++k) {
    const Vec3& a = bg.points[k];
    const Vec3 ab = bg.points[k + 1] - a;
    const double l2 = norm2(ab);
    const double s = l2 > 0 ? std::clamp(dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
    const double d = distance(p, a + ab * s);
    if (d < best.d) {
      best.d = d;
      best.t = bg.t[k] + s * (bg.t[k + 1] - bg.t[k]);
      best.arc = arc[k] + s * (arc[k + 1] - arc[k]);
      best.p = a + ab * s;
    }
  }
  return best;
}

double box_gap(const Box3& a, const Box3& b) {
  const double dx = std::max({0.0, a.lo.x - b.hi.x, b.lo.x - a.hi.x});
  const double dy = std::max({0.0, a.lo.y - b.hi.y, b.lo.y - a.hi.y});
  const double dz = std::max({0.0, a.lo.z - b.hi.z, b.lo.z - a.hi.z});
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

bool share_corner(const cad::Curve& a, const cad::Curve& b) {
  return a.corners[0] == b.corners[0] || a.corners[0] == b.corners[1] ||
         a.corners[1] == b.corners[0] || a.corners[1] == b.corners[1];
}

/// Vertex i of a master curve facing the slave across a thin face: where it goes on the slave.
struct Facing {
  int i;
  double t;  // slave parameter of the foot
};

/// An anchor of a slave curve: the slave parameter its vertex takes, and the master vertices it
/// faces ((master, index); two where consecutive masters share the corner).
struct Anchor {
  double t;
  std::vector<std::pair<LO, int>> from;
};

/// Fractional vertex index of parameter t on a curve mesh (t increasing), and its inverse.
double index_at(const std::vector<double>& ts, double t) {
  const auto it = std::upper_bound(ts.begin(), ts.end(), t);
  const auto j = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(
      it - ts.begin() - 1, 0, static_cast<std::ptrdiff_t>(ts.size()) - 2));
  const double span = ts[j + 1] - ts[j];
  return static_cast<double>(j) + (span > 0 ? std::clamp((t - ts[j]) / span, 0.0, 1.0) : 0.0);
}

double t_at_index(const std::vector<double>& ts, double x) {
  const auto last = static_cast<double>(ts.size() - 1);
  x = std::clamp(x, 0.0, last);
  const auto j = static_cast<std::size_t>(std::min(std::floor(x), last - 1));
  return ts[j] + (x - static_cast<double>(j)) * (ts[j + 1] - ts[j]);
}

/// The slave's vertex indices for anchors [lo, hi] (the first one j0), or empty when some piece
/// would change its spacing by more than 2:1; `cost` gets the largest |log| of those ratios.
std::vector<int> assign_indices(const std::vector<Anchor>& anchors, const std::vector<double>& f,
                                std::size_t lo, std::size_t hi, int j0, int n, double& cost) {
  const auto linked = [&](std::size_t k) {
    for (const auto& [m, i] : anchors[k].from)
      for (const auto& [m0, i0] : anchors[k - 1].from)
        if (m == m0 && std::abs(i - i0) == 1) return true;
    return false;
  };
  const auto parity = [&](std::size_t k) { return anchors[k].from.front().second & 1; };
  const auto ratio_ok = [&](double g, double old) {
    if (!(old > 0)) return false;
    const double r = g / old;
    cost = std::max(cost, std::abs(std::log(r)));
    return r >= 0.5 && r <= 2.0;
  };
  cost = 0;
  std::vector<int> j(hi - lo + 1);
  j[0] = j0;
  if (j0 < 1 || !ratio_ok(j0, f[lo])) return {};
  for (std::size_t k = lo + 1; k <= hi; ++k) {
    const double old = f[k] - f[k - 1];
    int g = 1;
    if (linked(k)) {
      // The master's spacing is the thin face's; the slave's may differ, not by much (both sides
      // are sized by the same width).
      if (!(old > 0.4 && old < 2.5)) return {};
    } else {
      const int want = (parity(k) - j[k - lo - 1]) & 1;
      g = std::max(1, static_cast<int>(std::lround(old)));
      if ((g & 1) != want) g += (old > g || g == 1) ? 1 : -1;
      if (!ratio_ok(g, old)) return {};
    }
    j[k - lo] = j[k - lo - 1] + g;
  }
  const int tail = n - j.back();
  if (tail < 1 || !ratio_ok(tail, n - f[hi])) return {};
  return j;
}

}  // namespace

std::vector<LO> align_thin_sides(const cad::CadModel& model,
                                 std::span<const mesh::CurveMesh> background, const Quantization& q,
                                 std::vector<mesh::CurveMesh>& full, const TaskArena& tasks,
                                 double width_ratio) {
  const LO nc = model.num_curves();
  QSMESH_CHECK(static_cast<LO>(full.size()) == nc && static_cast<LO>(background.size()) == nc,
               "align_thin_sides: " << full.size() << " curve meshes for " << nc << " curves");
  if (!(width_ratio > 0)) return {};
  const auto cv = model.curves();
  // Arc lengths of the background polylines and boxes of both meshes.
  std::vector<std::vector<double>> arc(static_cast<std::size_t>(nc));
  std::vector<Box3> bg_box(static_cast<std::size_t>(nc)), box(static_cast<std::size_t>(nc));
  std::vector<double> longest(static_cast<std::size_t>(nc), 0.0);
  for (LO c = 0; c < nc; ++c) {
    if (cv[c].degenerate || background[c].points.size() < 2 || full[c].points.size() < 2) continue;
    const auto& p = background[c].points;
    arc[c].assign(p.size(), 0.0);
    for (std::size_t k = 0; k + 1 < p.size(); ++k)
      arc[c][k + 1] = arc[c][k] + distance(p[k], p[k + 1]);
    for (const auto& x : p) bg_box[c].add(x);
    for (std::size_t k = 0; k < full[c].points.size(); ++k) {
      box[c].add(full[c].points[k]);
      if (k > 0)
        longest[c] = std::max(longest[c], distance(full[c].points[k - 1], full[c].points[k]));
    }
  }
  // Per face: the vertices of each curve facing another curve of the face across a thin face.
  const auto faces = model.faces();
  using PairKey = std::pair<LO, LO>;  // (master candidate, slave candidate)
  std::vector<std::map<PairKey, std::vector<Facing>>> per_face(faces.size());
  tasks.parallel_for(static_cast<std::int64_t>(faces.size()), [&](std::int64_t fi) {
    const cad::Face& face = faces[static_cast<std::size_t>(fi)];
    // Every loop even curve by curve: the halved boundary keeps the even vertices of each curve
    // (background::halved_face_boundary), so aligned vertices of equal parity stay aligned
    // before subdivision.
    std::map<LO, int> uses;
    for (const auto& loop : face.loops)
      for (const auto& use : loop.uses) {
        if (use.curve < 0 || use.curve >= nc) return;
        if ((q.edges[use.curve] & 1) != 0) return;
        ++uses[use.curve];
      }
    std::vector<LO> sides;
    for (const auto& [c, k] : uses)
      if (k == 1 && !cv[c].degenerate && cv[c].corners[0] != cv[c].corners[1] && !arc[c].empty() &&
          arc[c].back() > 0)
        sides.push_back(c);
    auto& out = per_face[static_cast<std::size_t>(fi)];
    for (const LO a : sides)
      for (const LO b : sides) {
        if (a == b || share_corner(cv[a], cv[b])) continue;
        // Opposite sides of four-sided grids share their profile already (PlaceOptions).
        if (q.curve2chord[a] != kNoIndex && q.curve2chord[a] == q.curve2chord[b]) continue;
        if (box_gap(box[a], bg_box[b]) >= width_ratio * longest[a]) continue;
        const auto& pa = full[a].points;
        const auto n = pa.size();
        std::vector<Facing> list;
        for (std::size_t i = 0; i < n; ++i) {
          const double before = i > 0 ? distance(pa[i - 1], pa[i]) : 0.0;
          const double after = i + 1 < n ? distance(pa[i], pa[i + 1]) : 0.0;
          const double h = i == 0 ? after : i + 1 == n ? before : 0.5 * (before + after);
          const double limit = width_ratio * h;
          Box3 at;
          at.add(pa[i]);
          if (box_gap(at, bg_box[b]) >= limit) continue;
          const Foot foot = nearest_on(background[b], arc[b], pa[i]);
          if (!(foot.d < limit) || !(foot.d > 1e-9 * arc[b].back())) continue;
          // Facing: the foot inside the other curve (not past its end) and the gap across this
          // curve, not along it.
          const double margin = 1e-6 * arc[b].back();
          if (!(foot.arc > margin && foot.arc < arc[b].back() - margin)) continue;
          const Vec3 tangent = pa[std::min(i + 1, n - 1)] - pa[i > 0 ? i - 1 : 0];
          const Vec3 across = foot.p - pa[i];
          if (std::abs(dot(tangent, across)) > 0.5 * norm(tangent) * norm(across)) continue;
          list.push_back({static_cast<int>(i), foot.t});
        }
        if (list.size() >= 2) out[{a, b}] = std::move(list);
      }
  });
  // Of two curves facing each other, the one more of whose vertices face the other is the master
  // (a neck's short side, a slot's arc inside a ring): its vertices stay, and the other (the
  // slave) takes theirs where they face it, its own spacing elsewhere.
  std::map<PairKey, std::vector<Facing>> facing;
  for (auto& m : per_face)
    for (auto& [key, list] : m) {
      auto& into = facing[key];
      into.insert(into.end(), list.begin(), list.end());
    }
  for (auto& [key, list] : facing) {
    std::sort(list.begin(), list.end(), [](const Facing& x, const Facing& y) { return x.i < y.i; });
    list.erase(std::unique(list.begin(), list.end(),
                           [](const Facing& x, const Facing& y) { return x.i == y.i; }),
               list.end());
  }
  std::vector<char> is_master(static_cast<std::size_t>(nc), 0);
  std::vector<PairKey> links;  // (master, slave)
  for (const auto& [key, list] : facing) {
    const auto [a, b] = key;
    const double ca = static_cast<double>(list.size()) / static_cast<double>(full[a].points.size());
    const auto other = facing.find({b, a});
    const double cb = other == facing.end() ? 0.0
                                            : static_cast<double>(other->second.size()) /
                                                  static_cast<double>(full[b].points.size());
    if (ca > cb || (ca == cb && a < b)) {
      links.emplace_back(a, b);
      is_master[a] = 1;
    }
  }
  // A slave that is a master elsewhere keeps its vertices: other curves take theirs from them.
  std::map<LO, std::vector<LO>> masters_of;
  // A side of a four-sided face in a chord keeps its vertices too: the face's opposite side,
  // whose profile it may share (PlaceOptions::align_chords), would not follow it (Block.stp at
  // size factor 0.02: grids beside its thin faces from SICN min 0.92 to 0.45).
  for (const auto& [m, s] : links)
    if (is_master[s] == 0 && q.curve2chord[s] == kNoIndex) masters_of[s].push_back(m);
  std::vector<std::pair<LO, std::vector<LO>>> slaves(masters_of.begin(), masters_of.end());
  std::vector<char> changed(slaves.size(), 0);
  tasks.parallel_for(static_cast<std::int64_t>(slaves.size()), [&](std::int64_t si) {
    const auto& [s, masters] = slaves[static_cast<std::size_t>(si)];
    const auto geometry = model.curve_geometry(s);
    std::vector<Anchor> anchors;
    for (const LO m : masters)
      for (const Facing& x : facing.at({m, s})) {
        const double t =
            geometry->project(full[m].points[static_cast<std::size_t>(x.i)], x.t, nullptr);
        anchors.push_back({t, {{m, x.i}}});
      }
    std::sort(anchors.begin(), anchors.end(), [](const Anchor& x, const Anchor& y) {
      return x.t != y.t ? x.t < y.t : x.from < y.from;
    });
    const auto& ts = full[s].t;
    const int n = static_cast<int>(ts.size()) - 1;
    // Anchors at one point (the corner two masters share) merge; their parities must agree.
    const double tol = 1e-9 * (ts.back() - ts.front());
    std::vector<Anchor> merged;
    for (auto& x : anchors) {
      if (!merged.empty() && x.t - merged.back().t <= tol) {
        if ((x.from.front().second & 1) != (merged.back().from.front().second & 1)) return;
        merged.back().from.push_back(x.from.front());
      } else {
        merged.push_back(std::move(x));
      }
    }
    if (merged.size() < 2 || n < 3) return;
    std::vector<double> f(merged.size());
    for (std::size_t k = 0; k < merged.size(); ++k) f[k] = index_at(ts, merged[k].t);
    // The longest run of anchors (up to 3 dropped at each end) whose pieces between them keep
    // their spacing within 2:1, and the first index of the right parity that changes it least.
    std::vector<int> best;
    std::size_t best_lo = 0;
    double best_cost = kInf;
    const std::size_t na = merged.size();
    for (std::size_t trims = 0; trims <= 6 && best.empty(); ++trims)
      for (std::size_t tlo = 0; tlo <= std::min<std::size_t>(trims, 3); ++tlo) {
        const std::size_t thi = trims - tlo;
        if (thi > 3 || tlo + thi + 2 > na) continue;
        const std::size_t lo = tlo, hi = na - 1 - thi;
        const int parity = merged[lo].from.front().second & 1;
        const int base = static_cast<int>(std::floor(f[lo]));
        for (int j0 = base - 1; j0 <= base + 2; ++j0) {
          if ((j0 & 1) != parity) continue;
          double cost = 0;
          auto j = assign_indices(merged, f, lo, hi, j0, n, cost);
          if (!j.empty() && cost < best_cost) {
            best = std::move(j);
            best_lo = lo;
            best_cost = cost;
          }
        }
      }
    if (best.empty()) return;
    std::vector<double> nt(ts.size());
    nt.front() = ts.front();
    nt.back() = ts.back();
    const auto fill = [&](int ja, double fa, int jb, double fb) {
      for (int m = 1; m < jb - ja; ++m)
        nt[static_cast<std::size_t>(ja + m)] =
            t_at_index(ts, fa + (fb - fa) * m / static_cast<double>(jb - ja));
    };
    // The pieces beyond the first and the last anchor keep the spacing next to them, so that the
    // edges just past a thin face are not stretched: the index map is quadratic there, its slope
    // 1 at the anchor.
    const auto fill_end = [&](int j_anchor, double f_anchor, int j_end, double f_end) {
      const int g = std::abs(j_end - j_anchor);
      const double span = f_end - f_anchor;  // old index span, signed like j_end - j_anchor
      const double rho = static_cast<double>(g) / std::abs(span);
      const double a = rho, b = 1 - rho;  // old(u) = f_anchor + span (a u + b u^2), u from anchor
      if (!(a > 0 && a + 2 * b > 0)) return false;
      for (int m = 1; m < g; ++m) {
        const double u = static_cast<double>(m) / g;
        const int j = j_anchor + (j_end > j_anchor ? m : -m);
        nt[static_cast<std::size_t>(j)] = t_at_index(ts, f_anchor + span * (a * u + b * u * u));
      }
      return true;
    };
    if (!fill_end(best.front(), f[best_lo], 0, 0.0)) return;
    for (std::size_t k = 0; k < best.size(); ++k) {
      nt[static_cast<std::size_t>(best[k])] = merged[best_lo + k].t;
      if (k > 0) fill(best[k - 1], f[best_lo + k - 1], best[k], f[best_lo + k]);
    }
    if (!fill_end(best.back(), f[best_lo + best.size() - 1], n, static_cast<double>(n))) return;
    for (std::size_t k = 0; k + 1 < nt.size(); ++k)
      if (!(nt[k + 1] > nt[k])) return;
    auto& mesh = full[s];
    mesh.t = nt;
    for (std::size_t k = 1; k + 1 < nt.size(); ++k) mesh.points[k] = geometry->point(nt[k]);
    changed[static_cast<std::size_t>(si)] = 1;
  });
  std::vector<LO> out;
  for (std::size_t k = 0; k < slaves.size(); ++k)
    if (changed[k] != 0) out.push_back(slaves[k].first);
  return out;
}

}  // namespace qsmesh::quantize
