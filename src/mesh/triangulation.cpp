#include "triangulation.hpp"

#include "qsmesh/core/error.hpp"

namespace qsmesh::mesh::detail {

LO Triangulation::add_vertex(const Vec2& p) {
  pts.push_back(p);
  v2t.push_back(kNoIndex);
  return static_cast<LO>(pts.size()) - 1;
}

LO Triangulation::new_tri(LO a, LO b, LO c) {
  LO t;
  if (!free_.empty()) {
    t = free_.back();
    free_.pop_back();
  } else {
    t = static_cast<LO>(tris.size());
    tris.emplace_back();
  }
  Tri& T = tris[t];
  T.v = {a, b, c};
  T.n = {kNoIndex, kNoIndex, kNoIndex};
  T.locked = 0;
  T.alive = 1;
  T.state = 0;
  T.stamp = next_stamp_++;
  return t;
}

void Triangulation::kill_tri(LO t) {
  tris[t].alive = 0;
  tris[t].stamp = next_stamp_++;
  free_.push_back(t);
}

int Triangulation::slot_of(LO t, LO v) const {
  const Tri& T = tris[t];
  return T.v[0] == v ? 0 : T.v[1] == v ? 1 : T.v[2] == v ? 2 : -1;
}

int Triangulation::edge_to(LO t, LO nb) const {
  const Tri& T = tris[t];
  return T.n[0] == nb ? 0 : T.n[1] == nb ? 1 : T.n[2] == nb ? 2 : -1;
}

std::int64_t Triangulation::num_live() const {
  std::int64_t n = 0;
  for (const Tri& t : tris) n += t.alive;
  return n;
}

void Triangulation::grow_marks() {
  if (in_cav_.size() < tris.size() + 64) {
    const std::size_t n = tris.size() * 2 + 64;
    in_cav_.resize(n, 0U);
    tested_.resize(n, 0U);
    conn_.resize(n, 0U);
  }
}

Location Triangulation::locate(const Vec2& p, LO start, bool stop_at_locked) const {
  LO t = start;
  LO prev = kNoIndex;
  // A visibility walk can cycle in a non-Delaunay triangulation; a randomised choice of the
  // first edge tested (fixed-seed generator, so deterministic) makes it terminate.
  const std::int64_t max_steps = 4 * static_cast<std::int64_t>(tris.size()) + 1000;
  for (std::int64_t step = 0; step < max_steps; ++step) {
    const Tri& T = tris[t];
    rng_ = rng_ * 1664525U + 1013904223U;
    const int r = static_cast<int>((rng_ >> 16) % 3U);
    double o[3];
    bool moved = false;
    for (int k = 0; k < 3; ++k) {
      const int i = (r + k) % 3;
      if (T.n[i] == prev && prev != kNoIndex) {
        o[i] = 1;  // came from there: p is on this side
        continue;
      }
      o[i] = orient2d(pts[T.v[next3(i)]], pts[T.v[prev3(i)]], p);
      if (o[i] < 0) {
        if (T.n[i] == kNoIndex || (stop_at_locked && T.is_locked(i)))
          return {LocKind::kBlocked, t, i};
        prev = t;
        t = T.n[i];
        moved = true;
        break;
      }
    }
    if (moved) continue;
    // The edge we came through was skipped; it can only be zero if p lies on it.
    if (prev != kNoIndex) {
      const int i = edge_to(t, prev);
      o[i] = orient2d(pts[T.v[next3(i)]], pts[T.v[prev3(i)]], p);
    }
    int zeros = 0, zi = -1, zj = -1;
    for (int i = 0; i < 3; ++i)
      if (o[i] == 0) {
        (zeros == 0 ? zi : zj) = i;
        ++zeros;
      }
    if (zeros == 0) return {LocKind::kInside, t, -1};
    if (zeros == 1) return {LocKind::kOnEdge, t, zi};
    return {LocKind::kOnVertex, t, 3 - zi - zj};
  }
  return {LocKind::kFailed, t, -1};
}

void Triangulation::fill_cavity(LO vid, const Cavity& cav, std::vector<LO>* created) {
  if (vlink_.size() < pts.size()) vlink_.resize(pts.size() * 2, kNoIndex);
  for (LO t : cav.tris) kill_tri(t);
  const std::size_t first = created ? created->size() : 0;
  std::vector<LO> local;
  std::vector<LO>& out = created ? *created : local;
  for (const Cavity::Edge& e : cav.boundary) {
    const LO t = new_tri(vid, e.a, e.b);
    Tri& T = tris[t];
    T.n[0] = e.outside;
    if (e.locked) T.locked = 1;
    if (e.outside != kNoIndex) tris[e.outside].n[e.outside_edge] = t;
    vlink_[e.a] = t;
    v2t[e.a] = t;
    out.push_back(t);
  }
  for (std::size_t k = first; k < out.size(); ++k) {
    const LO t = out[k];
    const LO u = vlink_[tris[t].v[2]];  // the new triangle whose edge starts at our b
    QSMESH_ASSERT(u != kNoIndex, "cavity boundary is not a closed loop");
    tris[t].n[1] = u;
    tris[u].n[2] = t;
  }
  for (std::size_t k = first; k < out.size(); ++k) vlink_[tris[out[k]].v[1]] = kNoIndex;
  if (out.size() > first) v2t[vid] = out[first];
}

bool Triangulation::flip(LO t, int i) {
  Tri& T = tris[t];
  if (T.is_locked(i)) return false;
  const LO u = T.n[i];
  if (u == kNoIndex) return false;
  const int j = edge_to(u, t);
  const LO a = T.v[i], b = T.v[next3(i)], c = T.v[prev3(i)];
  const LO d = tris[u].v[j];
  if (orient2d(pts[a], pts[b], pts[d]) <= 0 || orient2d(pts[a], pts[d], pts[c]) <= 0) return false;
  const LO tB = T.n[next3(i)], tC = T.n[prev3(i)];
  const bool lB = T.is_locked(next3(i)), lC = T.is_locked(prev3(i));
  Tri& U = tris[u];
  const LO uC = U.n[next3(j)], uB = U.n[prev3(j)];
  const bool luC = U.is_locked(next3(j)), luB = U.is_locked(prev3(j));
  // t' = (a, b, d), u' = (d, c, a)
  T.v = {a, b, d};
  T.n = {uC, u, tC};
  T.locked = static_cast<std::uint8_t>((luC ? 1 : 0) | (lC ? 4 : 0));
  U.v = {d, c, a};
  U.n = {tB, t, uB};
  U.locked = static_cast<std::uint8_t>((lB ? 1 : 0) | (luB ? 4 : 0));
  if (uC != kNoIndex) tris[uC].n[edge_to(uC, u)] = t;
  if (tB != kNoIndex) tris[tB].n[edge_to(tB, t)] = u;
  T.stamp = next_stamp_++;
  U.stamp = next_stamp_++;
  v2t[a] = t;
  v2t[b] = t;
  v2t[d] = t;
  v2t[c] = u;
  return true;
}

void Triangulation::star(LO v, std::vector<LO>& out) const {
  out.clear();
  const LO t0 = v2t[v];
  if (t0 == kNoIndex) return;
  // Rewind clockwise to the hull (or all the way round).
  LO t = t0;
  for (;;) {
    const int k = slot_of(t, v);
    const LO prev = tris[t].n[prev3(k)];  // across edge (v, v[k+1]) going clockwise
    if (prev == kNoIndex || prev == t0) break;
    t = prev;
  }
  const LO start = t;
  for (;;) {
    out.push_back(t);
    const int k = slot_of(t, v);
    const LO nx = tris[t].n[next3(k)];  // across edge (v[k+2], v): counterclockwise
    if (nx == kNoIndex || nx == start) break;
    t = nx;
  }
}

std::pair<LO, int> Triangulation::find_edge(LO a, LO b) const {
  std::vector<LO> s;
  star(a, s);
  for (LO t : s) {
    const int k = slot_of(t, a);
    if (tris[t].v[next3(k)] == b) return {t, prev3(k)};
  }
  return {kNoIndex, -1};
}

}  // namespace qsmesh::mesh::detail
