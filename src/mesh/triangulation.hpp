// Internal triangulation kernel of the mesh module: a 2D triangulation of the parameter plane with
// neighbour links and locked (constrained) edges, point location by a visibility walk, and point
// insertion into a cavity chosen by a caller-given criterion (isotropic Delaunay for the boundary
// points, metric Delaunay for refinement, and later the frontal quad-dominant insertion of paper
// 000 Sec. 5.1). Every decision that affects topology uses the exact predicates.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "qsmesh/core/types.hpp"
#include "qsmesh/mesh/predicates.hpp"

namespace qsmesh::mesh::detail {

constexpr int next3(int i) { return i == 2 ? 0 : i + 1; }
constexpr int prev3(int i) { return i == 0 ? 2 : i - 1; }

/// Triangle: vertices counterclockwise in (u, v); edge i is opposite v[i], i.e. joins
/// v[i + 1] -> v[i + 2]; n[i] is the triangle across edge i (kNoIndex on the hull / outside).
struct Tri {
  std::array<LO, 3> v{kNoIndex, kNoIndex, kNoIndex};
  std::array<LO, 3> n{kNoIndex, kNoIndex, kNoIndex};
  std::uint8_t locked = 0;  ///< bit i: edge i is a locked boundary edge
  std::uint8_t alive = 0;
  std::uint8_t state = 0;   ///< free for the algorithm that drives the kernel
  std::uint32_t stamp = 0;  ///< changes whenever the slot is reused (lazy priority queues)
  [[nodiscard]] bool is_locked(int i) const { return ((locked >> i) & 1U) != 0; }
};

enum class LocKind : std::uint8_t { kInside, kOnEdge, kOnVertex, kBlocked, kFailed };

struct Location {
  LocKind kind = LocKind::kFailed;
  LO tri = kNoIndex;
  int index = -1;  ///< edge (kOnEdge, kBlocked) or vertex slot (kOnVertex) in tri
};

/// Cavity of a pending insertion: triangles to remove, and the boundary edges (a, b) seen
/// counterclockwise from the new point, with the triangle outside each one.
struct Cavity {
  std::vector<LO> tris;
  struct Edge {
    LO a, b, outside;
    int outside_edge;  ///< index of the edge in `outside` (when outside != kNoIndex)
    bool locked;
  };
  std::vector<Edge> boundary;
};

class Triangulation {
 public:
  std::vector<Vec2> pts;
  std::vector<Tri> tris;
  std::vector<LO> v2t;  ///< one live triangle incident to each vertex (kNoIndex if none)

  LO add_vertex(const Vec2& p);
  LO new_tri(LO a, LO b, LO c);
  void kill_tri(LO t);
  [[nodiscard]] int slot_of(LO t, LO v) const;          ///< index of vertex v in t, or -1
  [[nodiscard]] int edge_to(LO t, LO neighbour) const;  ///< i with n[i] == neighbour, or -1
  [[nodiscard]] std::int64_t num_live() const;

  /// Visibility walk from `start` towards p. Stops (kBlocked) at a locked edge or the hull when
  /// stop_at_locked; with a deterministic pseudo-random edge order so that it cannot cycle.
  [[nodiscard]] Location locate(const Vec2& p, LO start, bool stop_at_locked = true) const;

  /// Builds the cavity of point p located at loc: starts from the located triangle(s), grows
  /// across unlocked edges into triangles t for which in_cavity(t) is true, then shrinks it until
  /// every boundary edge sees p strictly counterclockwise (exact orient2d), so that it is a
  /// star-shaped disk. Returns false when no valid cavity exists (p on a locked edge or vertex).
  template <class Criterion>
  bool build_cavity(const Vec2& p, const Location& loc, Criterion&& in_cavity, Cavity& cav);

  /// Replaces the cavity by the fan of triangles joining vertex vid to its boundary edges.
  /// created receives the new triangles (in boundary order).
  void fill_cavity(LO vid, const Cavity& cav, std::vector<LO>* created);

  /// Flips edge i of t when the quadrilateral is strictly convex; false otherwise (or locked).
  bool flip(LO t, int i);

  /// Live triangles around vertex v, counterclockwise, starting from v2t[v] rewound to the hull
  /// when v is on it.
  void star(LO v, std::vector<LO>& out) const;

  /// Triangle and edge index holding the directed edge a -> b, or {kNoIndex, -1}.
  [[nodiscard]] std::pair<LO, int> find_edge(LO a, LO b) const;

 private:
  std::vector<LO> free_;
  std::uint32_t next_stamp_ = 1;
  mutable std::uint32_t rng_ = 12345U;
  std::vector<std::uint32_t> in_cav_;  // == cav_id_: in the current cavity
  std::vector<std::uint32_t> tested_;  // == cav_id_: criterion evaluated
  std::uint32_t cav_id_ = 0;
  std::vector<std::uint32_t> conn_;  // == conn_id_: reached while reconnecting
  std::uint32_t conn_id_ = 0;
  std::vector<LO> next_;
  std::vector<LO> stack_;
  std::vector<LO> vlink_;  // per vertex scratch for fill_cavity
  void grow_marks();
};

template <class Criterion>
bool Triangulation::build_cavity(const Vec2& p, const Location& loc, Criterion&& in_cavity,
                                 Cavity& cav) {
  cav.tris.clear();
  cav.boundary.clear();
  if (loc.kind != LocKind::kInside && loc.kind != LocKind::kOnEdge) return false;
  grow_marks();
  if (++cav_id_ == 0) {  // wrapped: reset the marks
    std::fill(in_cav_.begin(), in_cav_.end(), 0U);
    std::fill(tested_.begin(), tested_.end(), 0U);
    cav_id_ = 1;
  }
  const std::uint32_t id = cav_id_;
  LO seed2 = kNoIndex;
  const LO seed = loc.tri;
  if (loc.kind == LocKind::kOnEdge) {
    if (tris[seed].is_locked(loc.index)) return false;
    seed2 = tris[seed].n[loc.index];
    if (seed2 == kNoIndex) return false;
  }
  cav.tris.push_back(seed);
  in_cav_[seed] = tested_[seed] = id;
  if (seed2 != kNoIndex) {
    cav.tris.push_back(seed2);
    in_cav_[seed2] = tested_[seed2] = id;
  }
  for (std::size_t k = 0; k < cav.tris.size(); ++k) {
    const Tri& t = tris[cav.tris[k]];
    for (int i = 0; i < 3; ++i) {
      const LO nb = t.n[i];
      if (nb == kNoIndex || t.is_locked(i) || tested_[nb] == id) continue;
      tested_[nb] = id;
      if (in_cavity(nb)) {
        in_cav_[nb] = id;
        cav.tris.push_back(nb);
      }
    }
  }
  // Shrink to a star-shaped region: drop every triangle owning a boundary edge that does not see
  // p strictly counterclockwise, then keep what stays connected to the seed(s).
  const std::uint32_t out_mark = 0;
  for (;;) {
    bool changed = false;
    for (LO tid : cav.tris) {
      const Tri& t = tris[tid];
      for (int i = 0; i < 3; ++i) {
        const LO nb = t.n[i];
        if (nb != kNoIndex && in_cav_[nb] == id) continue;
        if (orient2d(pts[t.v[next3(i)]], pts[t.v[prev3(i)]], p) <= 0) {
          if (tid == seed || tid == seed2) return false;
          in_cav_[tid] = out_mark;
          changed = true;
          break;
        }
      }
    }
    if (!changed) break;
    // Reconnect from the seeds.
    if (++conn_id_ == 0) {
      std::fill(conn_.begin(), conn_.end(), 0U);
      conn_id_ = 1;
    }
    stack_.clear();
    auto visit = [&](LO tid) {
      if (in_cav_[tid] == id && conn_[tid] != conn_id_) {
        conn_[tid] = conn_id_;
        stack_.push_back(tid);
      }
    };
    visit(seed);
    if (seed2 != kNoIndex) visit(seed2);
    while (!stack_.empty()) {
      const LO tid = stack_.back();
      stack_.pop_back();
      const Tri& t = tris[tid];
      for (int i = 0; i < 3; ++i)
        if (t.n[i] != kNoIndex && !t.is_locked(i)) visit(t.n[i]);
    }
    next_.clear();
    for (LO tid : cav.tris) {
      if (in_cav_[tid] == id && conn_[tid] == conn_id_)
        next_.push_back(tid);
      else
        in_cav_[tid] = out_mark;
    }
    cav.tris.swap(next_);
  }
  for (LO tid : cav.tris) {
    const Tri& t = tris[tid];
    for (int i = 0; i < 3; ++i) {
      const LO nb = t.n[i];
      if (nb != kNoIndex && in_cav_[nb] == id) continue;
      cav.boundary.push_back({t.v[next3(i)], t.v[prev3(i)], nb,
                              nb == kNoIndex ? -1 : edge_to(nb, tid), t.is_locked(i)});
    }
  }
  return true;
}

}  // namespace qsmesh::mesh::detail
