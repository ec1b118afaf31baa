// Paper 004 on groups of CAD faces joined across smooth curves (group.hpp).
#include "qsmesh/holomorphic/group.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <set>

#include "detail.hpp"
#include "qsmesh/cad/smooth.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/smooth/approx_surface.hpp"

namespace qsmesh::holomorphic {

bool smooth_across(const cad::CadModel& model, LO c, const GroupOptions& options) {
  return cad::smooth_across(model, c, options.max_normal_angle_deg, options.samples);
}

std::vector<std::vector<LO>> smooth_face_groups(const cad::CadModel& model,
                                                const GroupOptions& options) {
  const LO nf = model.num_faces();
  std::vector<LO> parent(static_cast<std::size_t>(nf));
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](LO x) {
    while (parent[static_cast<std::size_t>(x)] != x)
      x = parent[static_cast<std::size_t>(x)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
    return x;
  };
  for (LO c = 0; c < model.num_curves(); ++c) {
    if (!smooth_across(model, c, options)) continue;
    const auto faces = model.curve2faces()[c];
    const LO a = find(faces[0]), b = find(faces[1]);
    if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }
  std::map<LO, std::size_t> group_of_root;
  std::vector<std::vector<LO>> groups;
  for (LO f = 0; f < nf; ++f) {
    const auto [it, added] = group_of_root.try_emplace(find(f), groups.size());
    if (added) groups.emplace_back();
    groups[it->second].push_back(f);
  }
  return groups;
}

GluedGroup glue_group(std::span<const LO> faces, std::span<const mesh::FaceMesh> backgrounds,
                      std::span<const std::vector<mesh::BoundaryLoop>> loops) {
  GluedGroup g;
  g.faces.assign(faces.begin(), faces.end());
  const std::size_t n = faces.size();
  if (n == 0 || backgrounds.size() != n || loops.size() != n) {
    g.reason = "a group needs one background mesh and one set of loops per face";
    return g;
  }
  for (std::size_t p = 0; p < n; ++p)
    if (backgrounds[p].triangles.empty()) {
      g.reason = "face " + std::to_string(faces[p]) + " has no background triangle";
      return g;
    }
  // Each face's boundary edges (used by one of its triangles, not back), keyed by the curve
  // classification of their ends, with +1 when traversed from the smaller key to the larger.
  using EdgeKey = std::pair<detail::Key, detail::Key>;
  std::vector<std::map<EdgeKey, int>> boundary(n);
  for (std::size_t p = 0; p < n; ++p) {
    const auto& m = backgrounds[p];
    std::map<std::pair<LO, LO>, int> directed;
    for (const auto& t : m.triangles)
      for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
    for (const auto& [e, count] : directed) {
      if (count != 1 || directed.count({e.second, e.first}) != 0) continue;
      const auto& ca = m.vclass[static_cast<std::size_t>(e.first)];
      const auto& cb = m.vclass[static_cast<std::size_t>(e.second)];
      if (ca.dim > 1 || cb.dim > 1) continue;
      const detail::Key ka = detail::point_key(ca), kb = detail::point_key(cb);
      if (ka == kb) continue;
      const bool up = ka < kb;
      auto& dir = boundary[p][up ? EdgeKey{ka, kb} : EdgeKey{kb, ka}];
      // A seam's two banks traverse its edges both ways: not an edge shared with another face.
      dir = dir == 0 ? (up ? 1 : -1) : 2;
    }
  }
  // Orientation by a breadth-first walk over the faces sharing boundary edges.
  std::vector<int> flip(n, -1);
  flip[0] = 0;
  std::vector<std::size_t> queue{0};
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t p = queue[head];
    for (std::size_t q = 0; q < n; ++q) {
      if (q == p) continue;
      for (const auto& [e, dp] : boundary[p]) {
        if (dp == 2) continue;
        const auto it = boundary[q].find(e);
        if (it == boundary[q].end() || it->second == 2) continue;
        // Consistent when the two effective directions are opposite.
        const int want = flip[p] ^ (it->second == dp ? 1 : 0);
        if (flip[q] == -1) {
          flip[q] = want;
          queue.push_back(q);
        } else if (flip[q] != want) {
          g.reason = "faces " + std::to_string(faces[p]) + " and " + std::to_string(faces[q]) +
                     " cannot be oriented alike (a non-orientable group)";
          return g;
        }
      }
    }
  }
  for (std::size_t p = 0; p < n; ++p)
    if (flip[p] == -1) {
      g.reason = "face " + std::to_string(faces[p]) + " shares no curve with the rest of the group";
      return g;
    }
  g.background.face = faces[0];
  g.reversed.resize(n);
  for (std::size_t p = 0; p < n; ++p) {
    const auto& m = backgrounds[p];
    const auto offset = static_cast<LO>(g.background.points.size());
    g.background.points.insert(g.background.points.end(), m.points.begin(), m.points.end());
    g.background.uv.insert(g.background.uv.end(), m.uv.begin(), m.uv.end());
    g.background.vclass.insert(g.background.vclass.end(), m.vclass.begin(), m.vclass.end());
    g.point_part.insert(g.point_part.end(), m.points.size(), static_cast<LO>(p));
    g.reversed[p] = static_cast<char>(flip[p]);
    for (auto t : m.triangles) {
      for (LO& x : t) x += offset;
      if (flip[p] != 0) std::swap(t[1], t[2]);
      g.background.triangles.push_back(t);
      g.triangle_part.push_back(static_cast<LO>(p));
    }
    for (auto loop : loops[p]) {
      // A loop runs as the glued triangles' boundary edges do (the surface on its left). The
      // loops of a face are not always in its triangles' direction (a reversed face's), so the
      // direction is read off the first segment that is a boundary edge of the face's triangles.
      bool against = false;
      for (std::size_t i = 0; i < loop.points.size(); ++i) {
        const detail::Key ka = detail::point_key(loop.points[i].vclass);
        const detail::Key kb = detail::point_key(loop.points[(i + 1) % loop.points.size()].vclass);
        if (ka == kb) continue;
        const bool up = ka < kb;
        const auto it = boundary[p].find(up ? EdgeKey{ka, kb} : EdgeKey{kb, ka});
        if (it == boundary[p].end() || it->second == 2) continue;
        const int along = (up ? 1 : -1) * it->second * (flip[p] != 0 ? -1 : 1);
        against = along < 0;
        break;
      }
      if (against) {
        // Segment i joins points i and i + 1: reversed, old segment i joins new n-2-i and n-1-i.
        std::reverse(loop.points.begin(), loop.points.end());
        if (loop.degenerate.size() == loop.points.size() && !loop.degenerate.empty()) {
          std::vector<std::uint8_t> d(loop.degenerate.size());
          const std::size_t m2 = d.size();
          for (std::size_t i = 0; i < m2; ++i) d[(2 * m2 - 2 - i) % m2] = loop.degenerate[i];
          loop.degenerate = std::move(d);
        }
      }
      g.loops.push_back(std::move(loop));
      g.loop_part.push_back(static_cast<LO>(p));
    }
  }
  g.ok = true;
  return g;
}

std::vector<double> loop_periods(const PolyAnnulus& surface,
                                 std::span<const std::complex<double>> phi) {
  std::map<std::pair<LO, LO>, LO> edge_of;
  for (std::size_t e = 0; e < surface.edges.size(); ++e)
    edge_of[{surface.edges[e][0], surface.edges[e][1]}] = static_cast<LO>(e);
  std::vector<double> out;
  for (const auto& loop : surface.loops) {
    double sum = 0;
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const LO a = loop[i], b = loop[(i + 1) % loop.size()];
      const auto e = static_cast<std::size_t>(edge_of.at(std::minmax(a, b)));
      sum += surface.edges[e][0] == a ? phi[e].real() : -phi[e].real();
    }
    out.push_back(sum);
  }
  return out;
}

std::vector<LO> balanced_loop_counts(std::span<const double> periods, double size) {
  QSMESH_CHECK(size > 0, "balanced_loop_counts: size " << size);
  std::vector<LO> counts(periods.size());
  LO plus = 0, minus = 0;
  for (std::size_t l = 0; l < periods.size(); ++l) {
    counts[l] = std::max<LO>(4, 2 * static_cast<LO>(std::lround(std::abs(periods[l]) / size / 2)));
    (periods[l] >= 0 ? plus : minus) += counts[l];
  }
  if (plus == minus) return counts;
  // The short side's longest loop takes the difference (even, since all counts are).
  const bool raise_plus = plus < minus;
  std::size_t best = periods.size();
  for (std::size_t l = 0; l < periods.size(); ++l)
    if ((periods[l] >= 0) == raise_plus &&
        (best == periods.size() || std::abs(periods[l]) > std::abs(periods[best])))
      best = l;
  if (best == periods.size()) return counts;  // one side empty: no form has such periods
  counts[best] += raise_plus ? minus - plus : plus - minus;
  return counts;
}

namespace {

// The minimum SICN of the quads `around` (3D).
double min_sicn(const mesh::FaceMesh& m, std::span<const LO> around) {
  double worst = 1;
  for (const LO q : around) {
    const auto& quad = m.quads[static_cast<std::size_t>(q)];
    std::array<Vec3, 4> x{};
    for (std::size_t k = 0; k < 4; ++k) x[k] = m.points[static_cast<std::size_t>(quad[k])];
    worst = std::min(worst, mesh::quad_sicn(x));
  }
  return worst;
}

// Laplacian smoothing of a group mesh's interior vertices, each moved to the mean of its edge
// neighbours and projected on the face of the background triangle nearest that point (so a
// vertex may move across an inner curve onto the next face); a move is kept only when the
// minimum SICN of its quads does not drop. Gauss-Seidel in vertex order: deterministic.
void smooth_group(GroupMesh& g, const GluedGroup& group,
                  std::span<const cad::FaceGeometry* const> surfaces,
                  const smooth::ApproxSurface& locator, int sweeps) {
  mesh::FaceMesh& m = g.mesh;
  const std::size_t nv = m.points.size();
  std::vector<std::vector<LO>> quads_of(nv), nbrs(nv);
  for (std::size_t q = 0; q < m.quads.size(); ++q)
    for (std::size_t k = 0; k < 4; ++k) {
      const auto v = static_cast<std::size_t>(m.quads[q][k]);
      quads_of[v].push_back(static_cast<LO>(q));
      for (const std::size_t d : {std::size_t{1}, std::size_t{3}}) {
        const LO w = m.quads[q][(k + d) % 4];
        if (std::find(nbrs[v].begin(), nbrs[v].end(), w) == nbrs[v].end()) nbrs[v].push_back(w);
      }
    }
  std::vector<LO> hint(nv, kNoIndex);
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    int moved = 0;
    for (std::size_t v = 0; v < nv; ++v) {
      if (m.vclass[v].dim != 2 || nbrs[v].empty()) continue;
      Vec3 target{0, 0, 0};
      for (const LO w : nbrs[v]) target = target + m.points[static_cast<std::size_t>(w)];
      target = target * (1.0 / double(nbrs[v].size()));
      const auto hit = locator.closest(target, hint[v]);
      if (hit.triangle == kNoIndex) continue;
      const auto part =
          static_cast<std::size_t>(group.triangle_part[static_cast<std::size_t>(hit.triangle)]);
      Vec3 foot;
      const Vec2 uv = surfaces[part]->project(target, hit.uv, &foot);
      const double before = min_sicn(m, quads_of[v]);
      const Vec3 old = m.points[v];
      m.points[v] = foot;
      if (min_sicn(m, quads_of[v]) < before) {
        m.points[v] = old;
        continue;
      }
      hint[v] = hit.triangle;
      m.uv[v] = uv;
      m.vclass[v].entity = group.faces[part];
      m.vclass[v].param = {uv.u, uv.v};
      g.vertex_face[v] = group.faces[part];
      ++moved;
    }
    if (moved == 0) break;
  }
}

}  // namespace

GroupMesh mesh_group(const GluedGroup& group, std::span<const cad::FaceGeometry* const> surfaces,
                     const HolomorphicOptions& options, HolomorphicReport* report) {
  HolomorphicReport local;
  HolomorphicReport& R = report != nullptr ? *report : local;
  GroupMesh out;
  if (!group.ok || surfaces.size() != group.faces.size()) {
    R = HolomorphicReport{};
    R.reason = group.ok ? "one surface per face of the group is needed" : group.reason;
    return out;
  }
  const detail::Placement placement{surfaces, group.faces, group.triangle_part};
  out.mesh = detail::mesh_poly_annulus_of(group.background, group.loops, placement, options, &R);
  if (!R.ok || out.mesh.quads.empty()) return GroupMesh{};
  // Boundary points carry the uv of the first loop that has them (merge_final keeps that copy).
  std::map<detail::Key, LO> first_face;
  for (std::size_t l = 0; l < group.loops.size(); ++l)
    for (const auto& p : group.loops[l].points)
      first_face.try_emplace(detail::point_key(p.vclass),
                             group.faces[static_cast<std::size_t>(group.loop_part[l])]);
  out.vertex_face.resize(out.mesh.points.size());
  for (std::size_t v = 0; v < out.mesh.points.size(); ++v) {
    const auto& vc = out.mesh.vclass[v];
    out.vertex_face[v] = vc.dim == 2 ? vc.entity : first_face.at(detail::point_key(vc));
  }
  const auto locator = smooth::ApproxSurface(group.background.points, group.background.uv,
                                             group.background.triangles);
  if (options.smooth_patches) smooth_group(out, group, surfaces, locator, options.group_sweeps);
  // Each quad to the face of the background triangle nearest its centre.
  out.quad_face.reserve(out.mesh.quads.size());
  LO hint = kNoIndex;
  for (const auto& q : out.mesh.quads) {
    Vec3 c{0, 0, 0};
    for (const LO x : q) c = c + out.mesh.points[static_cast<std::size_t>(x)] * 0.25;
    const auto hit = locator.closest(c, hint);
    hint = hit.triangle;
    out.quad_face.push_back(group.faces[static_cast<std::size_t>(
        group.triangle_part[static_cast<std::size_t>(hit.triangle)])]);
  }
  return out;
}

}  // namespace qsmesh::holomorphic
