#include "qsmesh/remesh/disk_remesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <utility>

#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/quality.hpp"

namespace qsmesh::remesh {

int irregularity(const Cavity& cavity, std::span<const int> in_valence,
                 std::span<const int> interior_valence) {
  int cost = 0;
  for (std::size_t j = 0; j < in_valence.size(); ++j) {
    const int d = cavity.ideal_valence[j] - cavity.out_valence[j] - in_valence[j];
    cost += d * d;
  }
  for (int v : interior_valence) cost += (4 - v) * (4 - v);
  return cost;
}

bool valence_allowed(VertexKind kind, int ideal, int current, int total,
                     const ChoiceOptions& options) {
  // Keeping a valence is never a new defect; it lets a cavity that touches a defect of lower
  // priority (or one not fixable today) still be remeshed.
  if (total == current) return true;
  const bool enforced = static_cast<int>(kind) <= static_cast<int>(options.enforce_up_to);
  switch (kind) {
    case VertexKind::interior:
      return total >= options.interior_min &&
             total <= (enforced ? options.interior_max : options.relaxed_interior_max);
    case VertexKind::curve:
      return enforced ? total == ideal
                      : total >= options.relaxed_curve_min && total <= options.relaxed_curve_max;
    case VertexKind::corner:
      return enforced ? total == ideal : total >= 1 && total <= ideal + 1;
  }
  return false;
}

Replacement best_replacement(const DiskQuadTable& table, const Cavity& cavity,
                             const ChoiceOptions& options) {
  const int b = static_cast<int>(cavity.kind.size());
  QSMESH_CHECK(cavity.out_valence.size() == cavity.kind.size() &&
                   cavity.ideal_valence.size() == cavity.kind.size() &&
                   cavity.current_valence.size() == cavity.kind.size(),
               "cavity arrays differ in size");
  Replacement best;
  // allowed[j * (max_in + 1) + v]: may cavity vertex j get v quads inside? Precomputed once: the
  // inner loop below runs over every entry, rotation and direction.
  constexpr int kMaxIn = 8;
  std::vector<char> allowed(static_cast<std::size_t>(b) * (kMaxIn + 1), 0);
  for (int j = 0; j < b; ++j)
    for (int v = 1; v <= kMaxIn; ++v)
      allowed[j * (kMaxIn + 1) + v] =
          valence_allowed(cavity.kind[j], cavity.ideal_valence[j], cavity.current_valence[j],
                          cavity.out_valence[j] + v, options);
  for (LO e : table.with_boundary(b)) {
    const auto val = table.valences(e);
    const int n = table.interior_size(e);
    int interior_cost = 0;
    for (int k = 0; k < n; ++k) interior_cost += (4 - val[b + k]) * (4 - val[b + k]);
    for (int dir = 0; dir < 2; ++dir)
      for (int r = 0; r < b; ++r) {
        const Replacement cand{e, r, dir == 1, 0, n};
        int cost = interior_cost;
        bool ok = true;
        for (int k = 0; k < b && ok; ++k) {
          const int j = cavity_vertex(cand, k, b);
          const int in = val[k];
          if (in > kMaxIn || !allowed[j * (kMaxIn + 1) + in]) {
            ok = false;
            break;
          }
          const int d = cavity.ideal_valence[j] - cavity.out_valence[j] - in;
          cost += d * d;
        }
        if (!ok) continue;
        if (best.entry == kNoIndex || cost < best.irregularity ||
            (cost == best.irregularity && n < best.num_interior)) {
          best = cand;
          best.irregularity = cost;
        }
      }
  }
  return best;
}

std::vector<std::array<LO, 4>> place_replacement(const DiskQuadTable& table, const Replacement& r,
                                                 std::span<const LO> cycle, LO first_new) {
  const int b = static_cast<int>(cycle.size());
  QSMESH_CHECK(r.entry != kNoIndex && table.boundary_size(r.entry) == b,
               "replacement does not fit a cavity of " << b << " vertices");
  auto global = [&](int k) {
    return k < b ? cycle[cavity_vertex(r, k, b)] : first_new + static_cast<LO>(k - b);
  };
  std::vector<std::array<LO, 4>> out;
  for (const auto& lq : table.quads(r.entry)) {
    std::array<LO, 4> q{global(lq[0]), global(lq[1]), global(lq[2]), global(lq[3])};
    if (r.reversed) std::swap(q[1], q[3]);  // the same cycle, walked the other way
    out.push_back(q);
  }
  return out;
}

namespace {

std::vector<int> corner_ideal_valences(const mesh::FaceMesh& m, const DiskRemeshOptions& options) {
  if (!options.corner_valence.empty()) {
    QSMESH_CHECK(static_cast<LO>(options.corner_valence.size()) == m.num_vertices(),
                 "face " << m.face << ": corner_valence has " << options.corner_valence.size()
                         << " entries for " << m.num_vertices() << " vertices");
    return options.corner_valence;
  }
  return estimate_corner_valences(m);
}

// Vertices where the surface normal vanishes (poles): their quads fan out of a collapsed curve, so
// the angles there say nothing about the valence they should have. A seam vertex is not one of
// them: each of its two images (same (dim, entity, index), one per side of the seam in uv) is a
// curve vertex of the face on its own side, ideal valence 2, and its curve edges stay in the
// cavity cycle.
std::vector<char> poles(const mesh::FaceMesh& m, const cad::FaceGeometry& surface) {
  const LO nv = m.num_vertices();
  std::vector<char> flag(nv, 0);
  for (LO v = 0; v < nv; ++v)
    if (m.vclass[v].dim != 2 && norm(surface.normal(m.uv[v])) == 0) flag[v] = 1;
  return flag;
}

VertexKind kind_of(const mesh::VertexClass& c) {
  return c.dim == 0 ? VertexKind::corner : c.dim == 1 ? VertexKind::curve : VertexKind::interior;
}

// The face mesh being edited: dead quads and vertices are dropped at the end.
struct Work {
  const cad::FaceGeometry& surface;
  const DiskQuadTable& table;
  const DiskRemeshOptions& options;
  LO face;
  std::vector<Vec3> points;
  std::vector<Vec2> uv;
  std::vector<mesh::VertexClass> vclass;
  std::vector<std::array<LO, 4>> quads;
  std::vector<char> quad_alive, vertex_alive, pole;
  std::vector<int> ideal;
  std::vector<std::vector<LO>> v2q;
  DiskRemeshStats stats;

  [[nodiscard]] int valence(LO v) const { return static_cast<int>(v2q[v].size()); }
  [[nodiscard]] int ideal_valence(LO v) const {
    return vclass[v].dim == 0 ? ideal[v] : vclass[v].dim == 1 ? 2 : 4;
  }
  [[nodiscard]] bool is_defect(LO v) const {
    if (!vertex_alive[v] || pole[v] || v2q[v].empty()) return false;
    const int val = valence(v);
    switch (kind_of(vclass[v])) {
      case VertexKind::interior:
        return val >= 6;
      case VertexKind::curve:
        return val != 2;
      case VertexKind::corner:
        return val != ideal[v];
    }
    return false;
  }
  [[nodiscard]] static double sicn_of(const std::array<LO, 4>& q, const std::vector<Vec3>& p) {
    return mesh::quad_sicn({p[q[0]], p[q[1]], p[q[2]], p[q[3]]});
  }
  [[nodiscard]] double sicn(const std::array<LO, 4>& q) const { return sicn_of(q, points); }
  // Corners of q turning with (first) and against (second) the surface normal at their vertex; a
  // corner where the surface has no normal (a pole) counts for neither.
  [[nodiscard]] std::pair<int, int> turns(const std::array<LO, 4>& q, const std::vector<Vec3>& p,
                                          const std::vector<Vec2>& u) const {
    std::pair<int, int> n{0, 0};
    for (int k = 0; k < 4; ++k) {
      const double t = corner_turn(q, k, p, u);
      n.first += t > 0 ? 1 : 0;
      n.second += t < 0 ? 1 : 0;
    }
    return n;
  }
  [[nodiscard]] double corner_turn(const std::array<LO, 4>& q, int k, const std::vector<Vec3>& p,
                                   const std::vector<Vec2>& u) const {
    const Vec3 a = p[q[(k + 1) % 4]] - p[q[k]], c = p[q[(k + 3) % 4]] - p[q[k]];
    return dot(cross(a, c), surface.normal(u[q[k]]));
  }

  bool try_fix(LO x);
  bool try_cavity(LO x, std::vector<LO> cav, bool force);
};

// Two rules, each on two cavities.
//  - Rules: first the replacement minimising Eq. 15, kept only when it lowers Eq. 15 over the
//    cavity. For a corner or curve defect that finds nothing, has fewer quads than its ideal
//    valence and a poor one (DiskRemeshOptions::force_below_sicn), then the priorities of
//    Sec. 6.3.2 alone: the defect must reach its ideal valence, corners (and curves when fixing a
//    curve) must end ideal or unchanged, and face-interior vertices may get worse within the
//    relaxed range. A curve vertex with one quad spans 180 degrees (SICN near 0) and an interior
//    vertex of valence 3 or 5 costs the same in Eq. 15, yet only the first is a bad quad.
//  - Cavities: the quads of x; then those with every quad around their face-interior vertices
//    added (Gmsh's implementation tries that larger patch first). A curve vertex with one quad has
//    no replacement of that quad alone that gives it two.
bool Work::try_fix(LO x) {
  const std::vector<LO> small = v2q[x];
  std::set<LO> grown(small.begin(), small.end());
  if (options.larger_cavity)
    for (LO q : small)
      for (LO v : quads[q])
        if (vclass[v].dim == 2) grown.insert(v2q[v].begin(), v2q[v].end());
  std::vector<std::vector<LO>> cavities{small};
  if (grown.size() > small.size()) cavities.emplace_back(grown.begin(), grown.end());
  bool may_force = kind_of(vclass[x]) != VertexKind::interior && valence(x) < ideal_valence(x);
  if (may_force) {
    double worst = 1;
    for (LO q : small) worst = std::min(worst, sicn(quads[q]));
    may_force = worst < options.force_below_sicn;
  }
  for (int rule = 0; rule < (may_force ? 2 : 1); ++rule)
    for (const auto& cav : cavities)
      if (try_cavity(x, cav, rule == 1)) return true;
  return false;
}

bool Work::try_cavity(LO x, std::vector<LO> cav, bool force) {  // cav by value: commit edits v2q
  const auto refuse = [&](LO& counter) {
    ++counter;
    return false;
  };
  std::set<LO> in_cavity(cav.begin(), cav.end());
  // Boundary of the union of the cavity's quads: directed edges whose reverse is not in it.
  std::set<std::pair<LO, LO>> directed;
  for (LO q : cav)
    for (int k = 0; k < 4; ++k) directed.emplace(quads[q][k], quads[q][(k + 1) % 4]);
  std::map<LO, LO> next;
  for (const auto& [a, c] : directed)
    if (directed.count({c, a}) == 0 && !next.emplace(a, c).second)
      return refuse(stats.skipped);  // the boundary touches itself: not a simple disk
  if (next.empty()) return refuse(stats.skipped);
  std::vector<LO> cycle{next.begin()->first};
  while (true) {
    const LO c = next.at(cycle.back());
    if (c == cycle.front()) break;
    cycle.push_back(c);
    if (cycle.size() > next.size()) break;
  }
  const int b = static_cast<int>(cycle.size());
  if (b != static_cast<int>(next.size()) || b > table.max_boundary()) return refuse(stats.skipped);
  std::set<LO> on_cycle(cycle.begin(), cycle.end());
  std::vector<LO> inner;
  for (LO q : cav)
    for (LO v : quads[q])
      if (!on_cycle.count(v) && std::find(inner.begin(), inner.end(), v) == inner.end())
        inner.push_back(v);
  for (LO v : inner) {
    bool inside = vclass[v].dim == 2;
    for (LO q : v2q[v]) inside = inside && in_cavity.count(q) > 0;
    if (!inside) return refuse(stats.skipped);
  }

  Cavity cavity;
  std::vector<int> in_now(b), inner_now;
  for (int j = 0; j < b; ++j) {
    const LO v = cycle[j];
    int in = 0;
    for (LO q : v2q[v]) in += in_cavity.count(q) ? 1 : 0;
    in_now[j] = in;
    // A pole on the cycle keeps its valence: its angles say nothing about the valence it needs.
    cavity.kind.push_back(pole[v] ? VertexKind::corner : kind_of(vclass[v]));
    cavity.out_valence.push_back(valence(v) - in);
    cavity.ideal_valence.push_back(pole[v] ? valence(v) : ideal_valence(v));
    // force: x has no valence to keep (Cavity::current_valence < 0), it must reach its range.
    cavity.current_valence.push_back(force && v == x ? -1 : valence(v));
  }
  for (LO v : inner) inner_now.push_back(valence(v));
  const int cost_now = irregularity(cavity, in_now, inner_now);
  ChoiceOptions choice;
  choice.enforce_up_to = kind_of(vclass[x]);
  const Replacement best = best_replacement(table, cavity, choice);
  if (best.entry == kNoIndex || (!force && best.irregularity >= cost_now))
    return refuse(stats.no_candidate);

  // The replacement's quads in mesh ids; new interior vertices numbered after the current ones.
  const LO first_new = static_cast<LO>(points.size());
  const int n = best.num_interior;
  const std::vector<std::array<LO, 4>> new_quads = place_replacement(table, best, cycle, first_new);

  // Tentative positions of the new vertices only: the face's arrays change at commit.
  Vec2 centre{0, 0};
  for (LO v : cycle) centre += uv[v];
  centre = centre / b;
  std::vector<Vec2> new_uv(n, centre);
  auto uv_of = [&](LO v) { return v >= first_new ? new_uv[v - first_new] : uv[v]; };
  // Uniform harmonic (Tutte) placement of the new vertices in uv: a few hundred Gauss-Seidel sweeps
  // on at most four unknowns, enough to converge; smoothing below does the real work.
  std::vector<std::set<LO>> nbr(n);
  for (const auto& q : new_quads)
    for (int k = 0; k < 4; ++k)
      if (q[k] >= first_new) {
        nbr[q[k] - first_new].insert(q[(k + 1) % 4]);
        nbr[q[k] - first_new].insert(q[(k + 3) % 4]);
      }
  for (int it = 0; it < 200 && n > 0; ++it)
    for (int k = 0; k < n; ++k) {
      Vec2 s{0, 0};
      for (LO w : nbr[k]) s += uv_of(w);
      new_uv[k] = s / static_cast<double>(nbr[k].size());
    }

  // The enlarged cavity: the new quads and every other live quad touching the cavity boundary.
  std::set<LO> ring;
  for (LO v : cycle)
    for (LO q : v2q[v])
      if (!in_cavity.count(q)) ring.insert(q);
  std::vector<std::array<LO, 4>> region(new_quads);
  for (LO q : ring) region.push_back(quads[q]);
  // Before: the old cavity and the same ring. The orientation is the old cavity's majority (the
  // mesh's own convention, counter-clockwise about the normal, normally). Corners turning against
  // it: on a strongly curved surface a valid quad (SICN > 0 about its own normal) may have some,
  // e.g. quads wrapping a wing's leading edge, so the region may not end with more of them than it
  // had, instead of none.
  double min_before = 1.0;
  int orient = 0;
  std::pair<int, int> turns_before{0, 0};
  const auto count_before = [&](LO q) {
    min_before = std::min(min_before, sicn(quads[q]));
    const auto [with, against] = turns(quads[q], points, uv);
    turns_before.first += with;
    turns_before.second += against;
    return with - against;
  };
  for (LO q : cav) orient += count_before(q);
  for (LO q : ring) count_before(q);
  const bool ccw = orient >= 0;
  const int backward_before = ccw ? turns_before.second : turns_before.first;

  // The region as a face mesh of its own. Free: new vertices, and dim-2 vertices whose quads after
  // the change all lie in the region; the others are locked for smooth_face by classifying them as
  // corners of their own (unique entities below kNoIndex).
  std::map<LO, LO> local;  // mesh id -> submesh id
  mesh::FaceMesh sub;
  sub.face = face;
  for (const auto& q : region)
    for (LO v : q)
      if (local.emplace(v, static_cast<LO>(sub.points.size())).second) {
        const Vec2 w = uv_of(v);
        sub.points.push_back(v >= first_new ? surface.eval(w).p : points[v]);
        sub.uv.push_back(w);
        sub.vclass.push_back(v >= first_new ? mesh::VertexClass{2, face, kNoIndex, {w.u, w.v}}
                                            : vclass[v]);
      }
  for (const auto& [v, lv] : local) {
    bool free_vertex = v >= first_new;
    if (!free_vertex && vclass[v].dim == 2) {
      free_vertex = true;
      for (LO q : v2q[v])
        if (!in_cavity.count(q) && !ring.count(q)) free_vertex = false;
    }
    if (!free_vertex) sub.vclass[lv] = mesh::VertexClass{0, -2 - lv, kNoIndex, {0, 0}};
  }
  for (const auto& q : region)
    sub.quads.push_back({local[q[0]], local[q[1]], local[q[2]], local[q[3]]});
  const mesh::FaceMesh smoothed = smooth::smooth_face(sub, surface, options.smoothing);

  double min_after = 1.0;
  int backward_after = 0;
  for (const auto& q : smoothed.quads) {
    min_after = std::min(min_after, sicn_of(q, smoothed.points));
    const auto [with, against] = turns(q, smoothed.points, smoothed.uv);
    backward_after += ccw ? against : with;
  }
  if (backward_after > backward_before) min_after = -1.0;
  const bool good =
      min_after >= options.min_sicn || (options.accept_if_not_worse && min_after >= min_before);
  if (!(min_after > 0 && good)) {
    return refuse(stats.rejected_geometry);
  }

  // Commit.
  for (const auto& [v, lv] : local)
    if (v < first_new && sub.vclass[lv].dim == 2) {
      points[v] = smoothed.points[lv];
      uv[v] = smoothed.uv[lv];
      vclass[v].param = {uv[v].u, uv[v].v};
    }
  for (int k = 0; k < n; ++k) {
    const LO lv = local.at(first_new + k);
    points.push_back(smoothed.points[lv]);
    uv.push_back(smoothed.uv[lv]);
    vclass.push_back(mesh::VertexClass{2, face, kNoIndex, {uv.back().u, uv.back().v}});
    vertex_alive.push_back(1);
    pole.push_back(0);
    ideal.push_back(0);
    v2q.emplace_back();
  }
  for (LO q : cav) {
    quad_alive[q] = 0;
    for (LO v : quads[q]) std::erase(v2q[v], q);
  }
  for (LO v : inner) vertex_alive[v] = 0;
  for (const auto& q : new_quads) {
    const LO id = static_cast<LO>(quads.size());
    quads.push_back(q);
    quad_alive.push_back(1);
    for (LO v : q) v2q[v].push_back(id);
  }
  ++stats.replaced;
  return true;
}

}  // namespace

std::vector<int> estimate_corner_valences(const mesh::FaceMesh& m) {
  const LO nv = m.num_vertices();
  std::vector<double> angle(nv, 0.0);
  for (const auto& q : m.quads)
    for (int k = 0; k < 4; ++k) {
      const LO v = q[k];
      if (m.vclass[v].dim != 0) continue;
      const Vec3 a = m.points[q[(k + 1) % 4]] - m.points[v];
      const Vec3 c = m.points[q[(k + 3) % 4]] - m.points[v];
      const double na = norm(a), nc = norm(c);
      if (na > 0 && nc > 0) angle[v] += std::acos(std::clamp(dot(a, c) / (na * nc), -1.0, 1.0));
    }
  std::vector<int> ideal(nv, 0);
  for (LO v = 0; v < nv; ++v)
    if (m.vclass[v].dim == 0)
      ideal[v] = std::max(1, static_cast<int>(std::lround(angle[v] / (std::numbers::pi / 2))));
  return ideal;
}

LO count_defects(const mesh::FaceMesh& m, const DiskRemeshOptions& options) {
  const std::vector<int> ideal = corner_ideal_valences(m, options);
  std::map<LO, int> corner_uses;  // images of each CAD corner in the mesh
  for (const auto& c : m.vclass)
    if (c.dim == 0) ++corner_uses[c.entity];
  std::vector<int> val(m.num_vertices(), 0);
  for (const auto& q : m.quads)
    for (LO v : q) ++val[v];
  LO defects = 0;
  for (LO v = 0; v < m.num_vertices(); ++v) {
    const auto& c = m.vclass[v];
    if (val[v] == 0) continue;
    if (c.dim == 2) {
      defects += val[v] >= 6 ? 1 : 0;
    } else if (c.dim == 1 || corner_uses[c.entity] == 1) {
      // A seam image is a curve vertex of its side; a corner seen twice (a seam end, a pole) has
      // no ideal valence known here.
      defects += val[v] != (c.dim == 1 ? 2 : ideal[v]) ? 1 : 0;
    }
  }
  return defects;
}

mesh::FaceMesh remesh_disk_defects(const mesh::FaceMesh& mesh, const cad::FaceGeometry& surface,
                                   const DiskQuadTable& table, const DiskRemeshOptions& options,
                                   DiskRemeshStats* stats) {
  QSMESH_CHECK(mesh.triangles.empty(),
               "face " << mesh.face << ": disk remeshing needs an all-quad mesh");
  const LO nv = mesh.num_vertices();
  QSMESH_CHECK(static_cast<LO>(mesh.uv.size()) == nv && static_cast<LO>(mesh.vclass.size()) == nv,
               "face " << mesh.face << ": points, uv and vclass sizes differ");
  Work w{surface,
         table,
         options,
         mesh.face,
         mesh.points,
         mesh.uv,
         mesh.vclass,
         mesh.quads,
         std::vector<char>(mesh.quads.size(), 1),
         std::vector<char>(nv, 1),
         poles(mesh, surface),
         corner_ideal_valences(mesh, options),
         std::vector<std::vector<LO>>(nv),
         {}};
  for (LO q = 0; q < static_cast<LO>(mesh.quads.size()); ++q)
    for (LO v : mesh.quads[q]) w.v2q[v].push_back(q);
  w.stats.defects_before = count_defects(mesh, options);

  for (int pass = 0; pass < options.max_passes; ++pass) {
    bool changed = false;
    for (VertexKind kind : {VertexKind::corner, VertexKind::curve, VertexKind::interior})
      for (LO v = 0; v < static_cast<LO>(w.points.size()); ++v)
        if (kind_of(w.vclass[v]) == kind && w.is_defect(v) && w.try_fix(v)) changed = true;
    if (!changed) break;
  }

  mesh::FaceMesh out;
  out.face = mesh.face;
  std::vector<LO> renumber(w.points.size(), kNoIndex);
  for (LO v = 0; v < static_cast<LO>(w.points.size()); ++v)
    if (w.vertex_alive[v]) {
      renumber[v] = out.num_vertices();
      out.points.push_back(w.points[v]);
      out.uv.push_back(w.uv[v]);
      out.vclass.push_back(w.vclass[v]);
    }
  for (LO q = 0; q < static_cast<LO>(w.quads.size()); ++q)
    if (w.quad_alive[q]) {
      std::array<LO, 4> r{};
      for (int k = 0; k < 4; ++k) r[k] = renumber[w.quads[q][k]];
      out.quads.push_back(r);
    }
  if (stats) {
    *stats = w.stats;
    DiskRemeshOptions after = options;
    if (!after.corner_valence.empty()) {
      // Corner ids move with the renumbering.
      after.corner_valence.assign(out.num_vertices(), 0);
      for (LO v = 0; v < static_cast<LO>(w.points.size()); ++v)
        if (renumber[v] != kNoIndex && v < nv)
          after.corner_valence[renumber[v]] = options.corner_valence[v];
    }
    stats->defects_after = count_defects(out, after);
  }
  return out;
}

}  // namespace qsmesh::remesh
