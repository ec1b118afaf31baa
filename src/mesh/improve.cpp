#include "qsmesh/mesh/improve.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>
#include <vector>

#include "qsmesh/mesh/predicates.hpp"

namespace qsmesh::mesh {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kGain = 1e-3;  // radians: smaller gains are noise and could cycle

std::uint64_t edge_key(LO a, LO b) {
  const auto lo = static_cast<std::uint32_t>(std::min(a, b));
  const auto hi = static_cast<std::uint32_t>(std::max(a, b));
  return (static_cast<std::uint64_t>(hi) << 32) | lo;
}

// Smallest angle (radians) of the 3D triangle abc; 0 for a degenerate one.
double min_angle(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double la = distance(b, c), lb = distance(c, a), lc = distance(a, b);
  if (la <= 0 || lb <= 0 || lc <= 0) return 0;
  // The smallest angle is opposite the shortest edge.
  double s = la, p = lb, q = lc;
  if (lb < s) std::swap(s, p);
  if (lc < s) std::swap(s, q);
  const double cosine = (p * p + q * q - s * s) / (2 * p * q);
  return std::acos(std::clamp(cosine, -1.0, 1.0));
}

class Improver {
 public:
  Improver(FaceMesh mesh, const cad::FaceGeometry& surface, bool reversed, const ImproveOptions& o)
      : m_(std::move(mesh)), surf_(surface), sign_(reversed ? -1.0 : 1.0), opt_(o) {
    const LO nv = m_.num_vertices();
    pole_.assign(static_cast<std::size_t>(nv), 0);
    // A pole is a corner where the parametrisation is singular: only its 3D position means
    // anything.
    for (LO v = 0; v < nv; ++v)
      if (m_.vclass[v].dim == 0 && norm(surf_.normal(m_.uv[v])) < 0.5) pole_[v] = 1;
    v2t_.assign(static_cast<std::size_t>(nv), {});
    for (LO t = 0; t < static_cast<LO>(m_.triangles.size()); ++t) {
      const auto& T = m_.triangles[t];
      for (int k = 0; k < 3; ++k) {
        v2t_[T[k]].push_back(t);
        auto& e =
            e2t_.try_emplace(edge_key(T[k], T[(k + 1) % 3]), std::array<LO, 2>{kNoIndex, kNoIndex})
                .first->second;
        if (e[0] == kNoIndex) {
          e[0] = t;
        } else {
          e[1] = t;
        }
      }
    }
  }

  FaceMesh run(ImproveStats* stats) {
    const double target = opt_.target_angle_deg * kPi / 180.0;
    if (stats != nullptr) stats->min_angle_before = mesh_min_angle();
    for (int round = 0; round < opt_.rounds; ++round) {
      std::int64_t changed = 0;
      for (LO t = 0; t < static_cast<LO>(m_.triangles.size()); ++t) {
        if (tri_angle(t) >= target) continue;
        for (int k = 0; k < 3; ++k) {
          const auto T = m_.triangles[t];
          if (try_flip(T[k], T[(k + 1) % 3])) {
            ++changed;
            ++flips_;
            break;
          }
        }
      }
      for (LO t = 0; opt_.move_vertices && t < static_cast<LO>(m_.triangles.size()); ++t) {
        if (tri_angle(t) >= target) continue;
        for (int k = 0; k < 3; ++k) {
          const LO v = m_.triangles[t][k];
          if (m_.vclass[v].dim == 2 && try_move(v)) {
            ++changed;
            ++moves_;
          }
        }
      }
      if (changed == 0) break;
    }
    if (stats != nullptr) {
      stats->flips = flips_;
      stats->moves = moves_;
      stats->min_angle_after = mesh_min_angle();
    }
    return std::move(m_);
  }

 private:
  double tri_angle(LO t) const {
    const auto& T = m_.triangles[t];
    return min_angle(m_.points[T[0]], m_.points[T[1]], m_.points[T[2]]);
  }

  double mesh_min_angle() const {
    double worst = kPi;
    for (LO t = 0; t < static_cast<LO>(m_.triangles.size()); ++t)
      worst = std::min(worst, tri_angle(t));
    return worst * 180.0 / kPi;
  }

  // Validity of triangle (a, b, c) with the given positions (see the header).
  bool valid(const std::array<LO, 3>& v, const std::array<Vec2, 3>& uv,
             const std::array<Vec3, 3>& p) const {
    const bool has_pole = pole_[v[0]] != 0 || pole_[v[1]] != 0 || pole_[v[2]] != 0;
    if (!has_pole) return sign_ * orient2d(uv[0], uv[1], uv[2]) > 0;
    Vec2 mid{0, 0};
    int n = 0;
    for (int k = 0; k < 3; ++k)
      if (pole_[v[k]] == 0) {
        mid += uv[k];
        ++n;
      }
    if (n == 0) return false;
    const Vec3 normal = surf_.normal(mid / n);
    return dot(cross(p[1] - p[0], p[2] - p[0]), normal) > 0;
  }

  bool valid(const std::array<LO, 3>& v) const {
    return valid(v, {m_.uv[v[0]], m_.uv[v[1]], m_.uv[v[2]]},
                 {m_.points[v[0]], m_.points[v[1]], m_.points[v[2]]});
  }

  // Third vertex of triangle t, and t rotated so that it reads (a, b, c).
  static bool orient_as(const std::array<LO, 3>& T, LO a, LO b, LO& c) {
    for (int k = 0; k < 3; ++k)
      if (T[k] == a && T[(k + 1) % 3] == b) {
        c = T[(k + 2) % 3];
        return true;
      }
    return false;
  }

  void replace_in(LO v, LO from, LO to) {
    auto& list = v2t_[v];
    std::replace(list.begin(), list.end(), from, to);
  }

  void remove_from(LO v, LO t) {
    auto& list = v2t_[v];
    list.erase(std::remove(list.begin(), list.end(), t), list.end());
  }

  void retarget(LO a, LO b, LO from, LO to) {
    auto& e = e2t_.at(edge_key(a, b));
    for (LO& x : e)
      if (x == from) x = to;
  }

  bool try_flip(LO a, LO b) {
    const auto it = e2t_.find(edge_key(a, b));
    if (it == e2t_.end() || it->second[1] == kNoIndex) return false;  // curve or seam edge
    LO t1 = it->second[0], t2 = it->second[1];
    LO c = kNoIndex, d = kNoIndex;
    if (!orient_as(m_.triangles[t1], a, b, c)) std::swap(t1, t2);
    if (!orient_as(m_.triangles[t1], a, b, c) || !orient_as(m_.triangles[t2], b, a, d))
      return false;
    if (c == d || e2t_.count(edge_key(c, d)) != 0) return false;
    const std::array<LO, 3> n1{c, a, d}, n2{d, b, c};
    const double before = std::min(tri_angle(t1), tri_angle(t2));
    const double after = std::min(min_angle(m_.points[c], m_.points[a], m_.points[d]),
                                  min_angle(m_.points[d], m_.points[b], m_.points[c]));
    if (after <= before + kGain || !valid(n1) || !valid(n2)) return false;
    m_.triangles[t1] = n1;
    m_.triangles[t2] = n2;
    e2t_.erase(edge_key(a, b));
    e2t_[edge_key(c, d)] = {t1, t2};
    retarget(a, d, t2, t1);
    retarget(b, c, t1, t2);
    remove_from(a, t2);
    remove_from(b, t1);
    v2t_[c].push_back(t2);
    v2t_[d].push_back(t1);
    std::sort(v2t_[c].begin(), v2t_[c].end());
    std::sort(v2t_[d].begin(), v2t_[d].end());
    return true;
  }

  bool try_move(LO v) {
    const auto& star = v2t_[v];
    if (star.size() < 3) return false;
    auto star_min = [&](const Vec2& uv, const Vec3& p, bool check) {
      double worst = kPi;
      for (LO t : star) {
        const auto& T = m_.triangles[t];
        std::array<Vec2, 3> q{m_.uv[T[0]], m_.uv[T[1]], m_.uv[T[2]]};
        std::array<Vec3, 3> x{m_.points[T[0]], m_.points[T[1]], m_.points[T[2]]};
        for (int k = 0; k < 3; ++k)
          if (T[k] == v) {
            q[k] = uv;
            x[k] = p;
          }
        if (check && !valid(T, q, x)) return -1.0;
        worst = std::min(worst, min_angle(x[0], x[1], x[2]));
      }
      return worst;
    };
    const double before = star_min(m_.uv[v], m_.points[v], false);
    Vec2 uv_centroid{0, 0};
    Vec3 centroid{0, 0, 0};
    int n = 0;
    for (LO t : star)
      for (const LO w : m_.triangles[t])
        if (w != v) {
          uv_centroid += m_.uv[w];
          centroid += m_.points[w];
          ++n;
        }
    uv_centroid = uv_centroid / n;
    centroid = centroid / n;
    std::vector<Vec2> candidates;
    Vec3 foot;
    candidates.push_back(surf_.project(centroid, m_.uv[v], &foot));
    for (const double w : {1.0, 0.5, 0.25})
      candidates.push_back(m_.uv[v] + (uv_centroid - m_.uv[v]) * w);
    double best = before + kGain;
    Vec2 best_uv{};
    bool found = false;
    for (const Vec2& uv : candidates) {
      if (!std::isfinite(uv.u) || !std::isfinite(uv.v)) continue;
      const double q = star_min(uv, surf_.eval(uv).p, true);
      if (q > best) {
        best = q;
        best_uv = uv;
        found = true;
      }
    }
    // Then a compass search in the tangent plane: on a strongly anisotropic parametrisation none of
    // the centroids may be good, while a nearby 3D position is.
    Vec2 at = found ? best_uv : m_.uv[v];
    double step = 0;
    for (LO t : star)
      for (const LO w : m_.triangles[t])
        if (w != v) step += distance(m_.points[w], m_.points[v]);
    step *= 0.25 / n;
    for (int level = 0; opt_.compass_search && level < 6; ++level, step *= 0.5) {
      bool improved = true;
      for (int guard = 0; improved && guard < 8; ++guard) {
        improved = false;
        const cad::SurfaceEval e = surf_.eval(at);
        const Vec3 e1 = normalized(e.du);
        const Vec3 e2 = normalized(cross(surf_.normal(at), e1));
        if (norm(e1) == 0 || norm(e2) == 0) break;
        for (int k = 0; k < 8; ++k) {
          const double a = k * kPi / 4;
          const Vec3 target = e.p + (e1 * std::cos(a) + e2 * std::sin(a)) * step;
          const Vec2 uv = surf_.project(target, at, &foot);
          if (!std::isfinite(uv.u) || !std::isfinite(uv.v)) continue;
          const double q = star_min(uv, surf_.eval(uv).p, true);
          if (q > best) {
            best = q;
            best_uv = uv;
            found = improved = true;
          }
        }
        if (improved) at = best_uv;
      }
    }
    if (!found) return false;
    m_.uv[v] = best_uv;
    m_.points[v] = surf_.eval(best_uv).p;
    m_.vclass[v].param = {best_uv.u, best_uv.v};
    return true;
  }

  FaceMesh m_;
  const cad::FaceGeometry& surf_;
  double sign_;
  ImproveOptions opt_;
  std::vector<std::uint8_t> pole_;
  std::vector<std::vector<LO>> v2t_;
  std::unordered_map<std::uint64_t, std::array<LO, 2>> e2t_;
  std::int64_t flips_ = 0, moves_ = 0;
};

}  // namespace

FaceMesh improve_small_angles(const FaceMesh& mesh, const cad::FaceGeometry& surface,
                              bool face_reversed, const ImproveOptions& options,
                              ImproveStats* stats) {
  if (mesh.triangles.empty()) {
    if (stats != nullptr) *stats = ImproveStats{0, 0, 180.0, 180.0};
    return mesh;
  }
  return Improver(mesh, surface, face_reversed, options).run(stats);
}

}  // namespace qsmesh::mesh
