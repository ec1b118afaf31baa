// Separatrices, four-sided regions, their quantization on the fixed curve meshes, transfinite
// filling and smoothing (paper 003 Sec. 2, the partition of Fig. 1).
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <sstream>

#include "internal.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/smooth/quad_tools.hpp"
#include "qsmesh/smooth/smooth.hpp"

namespace qsmesh::fieldmesh {

using detail::kPi;
using detail::wrap;

namespace {

/// A face-level failure with its stage (caught in mesh_face_from_field).
struct Failure {
  std::string stage, reason;
};

[[noreturn]] void fail(const std::string& stage, const std::string& reason) {
  throw Failure{stage, reason};
}

struct Node {
  enum Kind { Singular, Corner, Hit, Crossing } kind = Singular;
  Vec2 uv;
  Vec3 xyz;
  int d = 0;           ///< singular: index d / 4
  LO loop = kNoIndex;  ///< corner, hit
  double pos = 0;      ///< corner, hit: position along the loop (point index, fractional for hits)
  LO ipos = kNoIndex;  ///< corner, hit: loop point after quantization
  int quads = 0;       ///< corner: quads its angle asks for
};

struct Polyline {
  LO from = kNoIndex, to = kNoIndex;
  std::vector<Vec2> uv;
};

struct Edge {
  LO a = kNoIndex, b = kNoIndex;
  std::vector<Vec2> uv;
  bool boundary = false;
};

struct Context {
  const cad::CadModel& model;
  LO f;
  const cad::FaceGeometry& surface;
  const mesh::FaceMesh& tri;
  const Frame& frame;
  std::span<const double> theta;
  const detail::Loops& loops;
  const detail::Locator& locator;
  const FieldMeshOptions& options;
  double h = 0;     ///< mean boundary edge length (3D)
  double step = 0;  ///< separatrix step (3D)
  double rho = 0;   ///< radius around singular points (3D)
};

Vec3 at(const Context& c, const Vec2& uv) { return c.surface.eval(uv).p; }

// Unit branch of the cross at uv nearest to `prev`, and its parameter-plane step per unit length.
bool branch(const Context& c, const Vec2& uv, const Vec3& prev, Vec3& w, Vec2& duv) {
  const detail::FieldSample s = detail::sample_field(c.locator, c.tri, c.frame, c.theta, uv);
  if (!s.inside) return false;
  const Vec3 t = cross(s.normal, s.ref);
  double best = -2;
  for (int k = 0; k < 4; ++k) {
    const double a = s.theta + k * kPi / 2;
    const Vec3 cand = s.ref * std::cos(a) + t * std::sin(a);
    if (dot(cand, prev) > best) {
      best = dot(cand, prev);
      w = cand;
    }
  }
  duv = detail::uv_direction(c.surface, uv, w);
  return norm(duv) > 0;
}

// First crossing of segment [p, q] with a boundary loop: loop, fractional position, point.
bool boundary_crossing(const Context& c, const Vec2& p, const Vec2& q, LO& loop, double& pos,
                       Vec2& x) {
  double best = 2;
  for (LO l = 0; l < static_cast<LO>(c.loops.loops.size()); ++l) {
    const auto& pts = c.loops.loops[l].points;
    const std::size_t n = pts.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2 a = pts[i].uv, b = pts[(i + 1) % n].uv;
      const Vec2 r = q - p, s = b - a;
      const double den = cross(r, s);
      if (std::abs(den) < 1e-300) continue;
      const double t = cross(a - p, s) / den, u = cross(a - p, r) / den;
      if (t < 0 || t > 1 || u < 0 || u > 1) continue;
      if (t < best) {
        best = t;
        loop = l;
        pos = static_cast<double>(i) + u;
        x = p + r * t;
      }
    }
  }
  return best <= 1;
}

// Traces one separatrix from node `origin`, leaving through `seed` along `w0`. Ends at a
// boundary (a new Hit node) or within rho of a singular point or a concave corner.
Polyline trace(const Context& c, std::vector<Node>& nodes, LO origin, const Vec2& seed,
               const Vec3& w0) {
  Polyline out;
  out.from = origin;
  out.uv = {nodes[origin].uv, seed};
  // The separatrix ends at x on loop `loop` (position pos along it): a new Hit node.
  const auto end_on_boundary = [&](const Vec2& x, LO loop, double pos) {
    Node hit;
    hit.kind = Node::Hit;
    hit.uv = x;
    hit.xyz = at(c, x);
    hit.loop = loop;
    hit.pos = pos;
    out.to = static_cast<LO>(nodes.size());
    nodes.push_back(hit);
  };
  Vec2 p = seed;
  Vec3 prev = w0;
  double length = c.rho;
  double perimeter = 0;
  for (const auto& loop : c.loops.loops)
    for (std::size_t i = 0; i < loop.points.size(); ++i)
      perimeter += distance(loop.points[i].xyz, loop.points[(i + 1) % loop.points.size()].xyz);
  const LO num_attractors = static_cast<LO>(nodes.size());
  while (true) {
    Vec3 w1, w2;
    Vec2 d1, d2;
    if (!branch(c, p, prev, w1, d1)) {
      // Outside by round-off, past the last boundary test: the end is the nearest boundary point.
      LO loop = kNoIndex;
      double pos = 0, best = 1e300;
      Vec2 x;
      for (LO l = 0; l < static_cast<LO>(c.loops.loops.size()); ++l) {
        const auto& pts = c.loops.loops[l].points;
        for (std::size_t i = 0; i < pts.size(); ++i) {
          const Vec2 a = pts[i].uv, e = pts[(i + 1) % pts.size()].uv - a;
          const double t = std::clamp(dot(p - a, e) / std::max(dot(e, e), 1e-300), 0.0, 1.0);
          const double d = norm(a + e * t - p);
          if (d < best) {
            best = d;
            loop = l;
            pos = static_cast<double>(i) + t;
            x = a + e * t;
          }
        }
      }
      if (loop == kNoIndex || best > 2 * norm(out.uv.back() - out.uv[out.uv.size() - 2]) + 1e-12)
        fail("separatrices", "a separatrix left the triangulation");
      end_on_boundary(x, loop, pos);
      out.uv.back() = x;
      return out;
    }
    const Vec2 p1 = p + d1 * c.step;
    if (!branch(c, p1, w1, w2, d2)) {
      w2 = w1;
      d2 = d1;
    }
    const Vec2 q = p + (d1 + d2) * (0.5 * c.step);
    LO loop = kNoIndex;
    double pos = 0;
    Vec2 x;
    if (boundary_crossing(c, p, q, loop, pos, x)) {
      end_on_boundary(x, loop, pos);
      out.uv.push_back(x);
      return out;
    }
    const Vec3 xq = at(c, q);
    for (LO k = 0; k < num_attractors; ++k) {
      const Node& nd = nodes[k];
      const bool attracts = nd.kind == Node::Singular || (nd.kind == Node::Corner && nd.quads >= 3);
      if (!attracts || (k == origin && length < 4 * c.rho)) continue;
      if (distance(xq, nd.xyz) < c.rho) {
        out.to = k;
        out.uv.push_back(nd.uv);
        return out;
      }
    }
    out.uv.push_back(q);
    prev = normalized(w1 + w2);
    p = q;
    length += c.step;
    if (length > c.options.max_length_factor * perimeter)
      fail("separatrices", "a separatrix did not close (longer than " +
                               std::to_string(c.options.max_length_factor) + " perimeters)");
  }
}

// Directions (3D, unit) of the separatrices leaving singular node s: where the cross on a circle
// of radius r contains the radial direction (Sec. 2.2: V = 4 - d of them).
std::vector<Vec3> singular_directions(const Context& c, const Node& s, double r) {
  const detail::FieldSample f0 = detail::sample_field(c.locator, c.tri, c.frame, c.theta, s.uv);
  if (!f0.inside) return {};
  const Vec3 t = cross(f0.normal, f0.ref);
  const int samples = 720;
  std::vector<double> g(samples), alpha(samples);
  for (int i = 0; i < samples; ++i) {
    alpha[i] = 2 * kPi * i / samples;
    const Vec3 w = f0.ref * std::cos(alpha[i]) + t * std::sin(alpha[i]);
    const Vec2 duv = detail::uv_direction(c.surface, s.uv, w);
    const detail::FieldSample fs =
        detail::sample_field(c.locator, c.tri, c.frame, c.theta, s.uv + duv * r);
    if (!fs.inside) return {};
    // The radial direction's angle in the sample's own frame.
    const double a = detail::frame_angle(w, fs.ref, fs.normal);
    g[i] = wrap(fs.theta - a, kPi / 2);
  }
  std::vector<Vec3> out;
  for (int i = 0; i < samples; ++i) {
    const int j = (i + 1) % samples;
    const bool down = g[i] > 0 && g[j] <= 0, up = g[i] < 0 && g[j] >= 0;
    if ((down || up) && std::abs(g[i] - g[j]) < kPi / 4) {
      const double s01 = g[i] / (g[i] - g[j]);
      const double a = alpha[i] + s01 * (2 * kPi / samples);
      out.push_back(f0.ref * std::cos(a) + t * std::sin(a));
    }
  }
  return out;
}

// Splits the separatrices at their crossings (new Crossing nodes) into edges.
std::vector<Edge> separatrix_edges(const Context& c, std::vector<Node>& nodes,
                                   const std::vector<Polyline>& seps) {
  struct Cut {
    double param;
    LO node;
    Vec2 uv;
  };
  std::vector<std::vector<Cut>> cuts(seps.size());
  auto near_shared_end = [&](const Polyline& a, const Polyline& b, const Vec2& x) {
    for (LO n : {a.from, a.to})
      if (n == b.from || n == b.to)
        if (distance(at(c, x), nodes[n].xyz) < 0.5 * c.rho) return true;
    return false;
  };
  // Segments binned on a grid of the parameter plane; a crossing counts in the cell holding it.
  std::vector<double> lengths;
  for (const auto& sp : seps)
    for (std::size_t k = 0; k + 1 < sp.uv.size(); ++k)
      lengths.push_back(norm(sp.uv[k + 1] - sp.uv[k]));
  if (lengths.empty()) return {};
  std::nth_element(lengths.begin(),
                   lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2),
                   lengths.end());
  const double cell = std::max(4 * lengths[lengths.size() / 2], 1e-300);
  auto cell_of = [&](double x) { return static_cast<long long>(std::floor(x / cell)); };
  std::map<std::pair<long long, long long>, std::vector<std::pair<std::size_t, std::size_t>>> grid;
  for (std::size_t i = 0; i < seps.size(); ++i)
    for (std::size_t k = 0; k + 1 < seps[i].uv.size(); ++k) {
      const Vec2 p = seps[i].uv[k], q = seps[i].uv[k + 1];
      for (long long x = cell_of(std::min(p.u, q.u)); x <= cell_of(std::max(p.u, q.u)); ++x)
        for (long long y = cell_of(std::min(p.v, q.v)); y <= cell_of(std::max(p.v, q.v)); ++y)
          grid[{x, y}].emplace_back(i, k);
    }
  for (const auto& [key, segs] : grid)
    for (std::size_t m = 0; m < segs.size(); ++m)
      for (std::size_t n = m + 1; n < segs.size(); ++n) {
        auto [i, s] = segs[m];
        auto [j, t] = segs[n];
        if (i == j) continue;
        if (i > j) {
          std::swap(i, j);
          std::swap(s, t);
        }
        const Vec2 p = seps[i].uv[s], r = seps[i].uv[s + 1] - p;
        const Vec2 q = seps[j].uv[t], sv = seps[j].uv[t + 1] - q;
        const double den = cross(r, sv);
        if (std::abs(den) < 1e-300) continue;
        const double a = cross(q - p, sv) / den, b = cross(q - p, r) / den;
        if (a < 0 || a >= 1 || b < 0 || b >= 1) continue;
        const Vec2 x = p + r * a;
        if (std::pair(cell_of(x.u), cell_of(x.v)) != key) continue;
        if (near_shared_end(seps[i], seps[j], x)) continue;
        Node nd;
        nd.kind = Node::Crossing;
        nd.uv = x;
        nd.xyz = at(c, x);
        const LO id = static_cast<LO>(nodes.size());
        nodes.push_back(nd);
        cuts[i].push_back({static_cast<double>(s) + a, id, x});
        cuts[j].push_back({static_cast<double>(t) + b, id, x});
      }
  std::vector<Edge> edges;
  for (std::size_t i = 0; i < seps.size(); ++i) {
    auto& cs = cuts[i];
    std::sort(cs.begin(), cs.end(), [](const Cut& x, const Cut& y) { return x.param < y.param; });
    const auto& P = seps[i].uv;
    Edge e;
    e.a = seps[i].from;
    e.uv = {P[0]};
    std::size_t k = 0;
    for (std::size_t s = 0; s + 1 < P.size(); ++s) {
      for (; k < cs.size() && cs[k].param < static_cast<double>(s + 1); ++k) {
        e.uv.push_back(cs[k].uv);
        e.b = cs[k].node;
        edges.push_back(e);
        e = Edge{};
        e.a = cs[k].node;
        e.uv = {cs[k].uv};
      }
      e.uv.push_back(P[s + 1]);
    }
    e.b = seps[i].to;
    edges.push_back(e);
  }
  return edges;
}

double length3d(const Context& c, const std::vector<Vec2>& uv) {
  double l = 0;
  Vec3 prev = at(c, uv[0]);
  for (std::size_t i = 1; i < uv.size(); ++i) {
    const Vec3 x = at(c, uv[i]);
    l += distance(prev, x);
    prev = x;
  }
  return l;
}

// n + 1 points along the polyline at equal 3D arc-length steps (ends included).
std::vector<Vec2> resample(const Context& c, const std::vector<Vec2>& uv, int n) {
  std::vector<double> s{0};
  Vec3 prev = at(c, uv[0]);
  for (std::size_t i = 1; i < uv.size(); ++i) {
    const Vec3 x = at(c, uv[i]);
    s.push_back(s.back() + distance(prev, x));
    prev = x;
  }
  std::vector<Vec2> out{uv.front()};
  std::size_t j = 0;
  for (int k = 1; k < n; ++k) {
    const double target = s.back() * k / n;
    while (j + 2 < s.size() && s[j + 1] < target) ++j;
    const double len = s[j + 1] - s[j];
    const double a = len > 0 ? std::clamp((target - s[j]) / len, 0.0, 1.0) : 0.0;
    out.push_back(uv[j] * (1 - a) + uv[j + 1] * a);
  }
  out.push_back(uv.back());
  return out;
}

mesh::FaceMesh partition_and_fill(Context& c, std::span<const SingularPoint> singular,
                                  FieldMeshReport& rep, std::vector<LO>& singular_vertices) {
  const auto& L = c.loops;
  std::vector<Node> nodes;
  for (const auto& s : singular) {
    Node n;
    n.kind = Node::Singular;
    n.uv = c.surface.project(s.position, c.tri.uv[0], nullptr);
    n.xyz = at(c, n.uv);
    n.d = s.d;
    nodes.push_back(n);
  }
  const LO num_singular = static_cast<LO>(nodes.size());
  for (LO l = 0; l < static_cast<LO>(L.loops.size()); ++l)
    for (std::size_t i = 0; i < L.loops[l].points.size(); ++i)
      if (L.quads[l][i] > 0) {  // CAD vertices and the given boundary singular points
        Node n;
        n.kind = Node::Corner;
        n.uv = L.loops[l].points[i].uv;
        n.xyz = L.loops[l].points[i].xyz;
        n.loop = l;
        n.pos = static_cast<double>(i);
        n.ipos = static_cast<LO>(i);
        n.quads = L.quads[l][i];
        nodes.push_back(n);
      }
  const LO num_fixed = static_cast<LO>(nodes.size());

  // Separatrices: V = 4 - d from each singular point (Eq. 7), q - 1 from each concave corner.
  std::vector<Polyline> seps;
  for (LO s = 0; s < num_singular; ++s) {
    const int valence = 4 - nodes[s].d;
    std::vector<Vec3> dirs;
    for (double r : {c.rho, 2 * c.rho, 0.5 * c.rho, 3 * c.rho}) {
      dirs = singular_directions(c, nodes[s], r);
      if (static_cast<int>(dirs.size()) == valence) break;
    }
    if (static_cast<int>(dirs.size()) != valence)
      fail("separatrices", "singular point " + std::to_string(s) + " of index " +
                               std::to_string(nodes[s].d) + "/4 shows " +
                               std::to_string(dirs.size()) + " separatrix directions, " +
                               std::to_string(valence) + " expected");
    for (const Vec3& w : dirs) {
      const Vec2 duv = detail::uv_direction(c.surface, nodes[s].uv, w);
      seps.push_back(trace(c, nodes, s, nodes[s].uv + duv * c.rho, w));
    }
  }
  for (LO k = num_singular; k < num_fixed; ++k) {
    const Node& n = nodes[k];
    if (n.quads < 3) continue;
    const auto& pts = L.loops[n.loop].points;
    const std::size_t i = static_cast<std::size_t>(n.ipos), m = pts.size();
    const LO v = L.tri[n.loop][i];
    const Vec3 nv = c.frame.normal[v];
    const Vec3 eout = normalized(pts[(i + 1) % m].xyz - pts[i].xyz);
    const double angle = L.angle[n.loop][i];
    for (int q = 1; q < n.quads; ++q) {
      const double b = angle * q / n.quads;
      const Vec3 w = eout * std::cos(b) + cross(nv, eout) * std::sin(b);
      const Vec2 duv = detail::uv_direction(c.surface, n.uv, w);
      seps.push_back(trace(c, nodes, k, n.uv + duv * c.rho, w));
    }
  }
  // A separatrix joining two singular points is traced from both: keep one (Sec. 2.2, merging).
  {
    std::vector<Polyline> kept;
    for (const auto& s : seps) {
      bool dup = false;
      for (const auto& k : kept)
        if (k.from == s.to && k.to == s.from) {
          const Vec3 mid = at(c, s.uv[s.uv.size() / 2]);
          double dmin = 1e300;
          for (const auto& p : k.uv) dmin = std::min(dmin, distance(at(c, p), mid));
          dup = dup || dmin < 2 * c.rho;
        }
      if (!dup) kept.push_back(s);
    }
    seps = std::move(kept);
  }
  rep.separatrices = static_cast<int>(seps.size());

  std::vector<Edge> edges = separatrix_edges(c, nodes, seps);
  const std::size_t num_sep_edges = edges.size();
  // Boundary edges between consecutive nodes of each loop.
  std::vector<std::vector<LO>> on_loop(L.loops.size());
  for (LO k = 0; k < static_cast<LO>(nodes.size()); ++k)
    if (nodes[k].kind == Node::Corner || nodes[k].kind == Node::Hit)
      on_loop[nodes[k].loop].push_back(k);
  for (auto& ids : on_loop)
    std::sort(ids.begin(), ids.end(), [&](LO a, LO b) { return nodes[a].pos < nodes[b].pos; });
  auto boundary_polyline = [&](LO l, LO a, LO b) {
    const auto& pts = L.loops[l].points;
    const double m = static_cast<double>(pts.size());
    std::vector<Vec2> uv{nodes[a].uv};
    double end = nodes[b].pos;
    if (end <= nodes[a].pos) end += m;
    for (double i = std::floor(nodes[a].pos) + 1; i < end; i += 1)
      uv.push_back(pts[static_cast<std::size_t>(std::fmod(i, m))].uv);
    uv.push_back(nodes[b].uv);
    return uv;
  };
  for (LO l = 0; l < static_cast<LO>(L.loops.size()); ++l) {
    const auto& ids = on_loop[l];
    if (ids.empty()) fail("regions", "boundary loop " + std::to_string(l) + " without a corner");
    for (std::size_t k = 0; k < ids.size(); ++k) {
      Edge e;
      e.a = ids[k];
      e.b = ids[(k + 1) % ids.size()];
      e.boundary = true;
      e.uv = boundary_polyline(l, e.a, e.b);
      edges.push_back(e);
    }
  }

  // Half-edges 2e (a -> b) and 2e + 1 (b -> a); faces on their left.
  const LO nh = static_cast<LO>(2 * edges.size());
  auto tail = [&](LO h) { return (h & 1) ? edges[h / 2].b : edges[h / 2].a; };
  auto head = [&](LO h) { return (h & 1) ? edges[h / 2].a : edges[h / 2].b; };
  auto first_dir = [&](LO h) {
    const auto& uv = edges[h / 2].uv;
    const std::size_t n = uv.size();
    for (std::size_t k = 1; k < n; ++k) {
      const Vec2 d = (h & 1) ? uv[n - 1 - k] - uv[n - 1] : uv[k] - uv[0];
      if (norm(d) > 0) return std::atan2(d.v, d.u);
    }
    return 0.0;
  };
  std::vector<std::vector<LO>> out(nodes.size());
  for (LO h = 0; h < nh; ++h) out[tail(h)].push_back(h);
  for (auto& o : out)
    std::sort(o.begin(), o.end(), [&](LO a, LO b) { return first_dir(a) < first_dir(b); });
  auto next = [&](LO h) {
    const auto& o = out[head(h)];
    const auto it = std::find(o.begin(), o.end(), h ^ 1);
    const std::size_t idx = static_cast<std::size_t>(it - o.begin());
    return o[(idx + o.size() - 1) % o.size()];
  };
  std::vector<char> seen(nh, 0);
  std::vector<std::vector<LO>> regions;
  for (LO h0 = 0; h0 < nh; ++h0) {
    if (seen[h0]) continue;
    std::vector<LO> cyc;
    bool outside = false;
    for (LO h = h0; !seen[h]; h = next(h)) {
      seen[h] = 1;
      cyc.push_back(h);
      outside = outside || (edges[h / 2].boundary && (h & 1));
      if (cyc.size() > static_cast<std::size_t>(nh)) fail("regions", "a region does not close");
    }
    if (!outside) regions.push_back(cyc);
  }
  // Region corners: nodes where three or more edges meet, and CAD corners of one quad (Table 1).
  auto is_corner = [&](LO n) {
    return out[n].size() >= 3 || (nodes[n].kind == Node::Corner && nodes[n].quads == 1);
  };
  struct Side {
    std::vector<LO> half_edges;
    bool boundary = false;
  };
  std::vector<std::array<Side, 4>> sides;
  for (std::size_t r = 0; r < regions.size(); ++r) {
    auto& cyc = regions[r];
    std::vector<std::size_t> at_corner;
    for (std::size_t k = 0; k < cyc.size(); ++k)
      if (is_corner(tail(cyc[k]))) at_corner.push_back(k);
    if (at_corner.size() != 4)
      fail("regions",
           "region " + std::to_string(r) + " has " + std::to_string(at_corner.size()) +
               " corners, 4 expected (the field is not aligned or a separatrix was missed)");
    std::rotate(cyc.begin(), cyc.begin() + static_cast<std::ptrdiff_t>(at_corner[0]), cyc.end());
    std::array<Side, 4> s;
    int side = -1;
    for (LO h : cyc) {
      if (is_corner(tail(h))) ++side;
      s[side].half_edges.push_back(h);
    }
    for (auto& sd : s) {
      const std::size_t nb = static_cast<std::size_t>(std::count_if(
          sd.half_edges.begin(), sd.half_edges.end(), [&](LO h) { return edges[h / 2].boundary; }));
      if (nb != 0 && nb != sd.half_edges.size())
        fail("regions", "a region side mixes boundary and separatrix");
      sd.boundary = nb != 0;
      if (!sd.boundary && sd.half_edges.size() != 1)
        fail("regions", "a region side holds several separatrix arcs");
    }
    sides.push_back(s);
  }
  rep.regions = static_cast<int>(regions.size());

  // Quantization: opposite sides of every region get equal counts; curve meshes are fixed, so
  // boundary counts depend only on where the separatrices' ends land (integer loop positions).
  std::vector<LO> uf(num_sep_edges);
  std::iota(uf.begin(), uf.end(), 0);
  std::function<LO(LO)> find = [&](LO x) { return uf[x] == x ? x : uf[x] = find(uf[x]); };
  struct Equation {
    const Side* a;
    const Side* b;
    std::size_t region;
  };
  std::vector<Equation> eqs;
  for (std::size_t r = 0; r < sides.size(); ++r)
    for (int k = 0; k < 2; ++k) {
      const Side &a = sides[r][k], &b = sides[r][k + 2];
      if (!a.boundary && !b.boundary)
        uf[find(a.half_edges[0] / 2)] = find(b.half_edges[0] / 2);
      else
        eqs.push_back({&a, &b, r});
    }
  std::vector<LO> hits;
  for (LO k = 0; k < static_cast<LO>(nodes.size()); ++k)
    if (nodes[k].kind == Node::Hit) hits.push_back(k);
  std::sort(hits.begin(), hits.end(), [&](LO a, LO b) {
    return std::pair(nodes[a].loop, nodes[a].pos) < std::pair(nodes[b].loop, nodes[b].pos);
  });
  auto loop_size = [&](LO l) { return static_cast<LO>(L.loops[l].points.size()); };
  // Count of a boundary side, or -1 while one of its ends is unplaced.
  auto boundary_count = [&](const Side& s) -> LO {
    const LO a = tail(s.half_edges.front()), b = head(s.half_edges.back());
    if (nodes[a].ipos == kNoIndex || nodes[b].ipos == kNoIndex) return -1;
    const LO m = loop_size(nodes[a].loop);
    const LO d = ((nodes[b].ipos - nodes[a].ipos) % m + m) % m;
    return d == 0 ? m : d;
  };
  std::vector<LO> value(num_sep_edges);
  std::vector<std::size_t> value_region(num_sep_edges);
  // Whether the placed ends give equal counts on opposite sides; `why`, when given, says where
  // they do not (only asked once the search failed: the search calls this many times).
  auto consistent = [&](std::string* why = nullptr) {
    std::fill(value.begin(), value.end(), -1);
    for (const auto& e : eqs) {
      LO va = -1, vb = -1;
      if (e.a->boundary) va = boundary_count(*e.a);
      if (e.b->boundary) vb = boundary_count(*e.b);
      if ((e.a->boundary && va == 0) || (e.b->boundary && vb == 0)) {
        if (why != nullptr)
          *why = "a side of region " + std::to_string(e.region) + " holds no curve edge";
        return false;
      }
      if (e.a->boundary && e.b->boundary) {
        if (va >= 0 && vb >= 0 && va != vb) {
          if (why != nullptr)
            *why = "the opposite boundary sides of region " + std::to_string(e.region) + " hold " +
                   std::to_string(va) + " and " + std::to_string(vb) + " curve edges";
          return false;
        }
        continue;
      }
      const Side& sep = e.a->boundary ? *e.b : *e.a;
      const LO known = e.a->boundary ? va : vb;
      if (known < 0) continue;
      const LO cls = find(sep.half_edges[0] / 2);
      LO& v = value[cls];
      if (v >= 0 && v != known) {
        if (why != nullptr)
          *why = "regions " + std::to_string(value_region[cls]) + " and " +
                 std::to_string(e.region) +
                 ", joined by a chain of separatrix arcs of equal counts, ask for " +
                 std::to_string(v) + " and " + std::to_string(known) + " curve edges";
        return false;
      }
      v = known;
      value_region[cls] = e.region;
    }
    return true;
  };
  // Structural: with no separatrix end placed, the sides between CAD corners (and given boundary
  // points) already disagree; no move of the ends can help, only other curve counts.
  if (std::string why; !consistent(&why))
    fail("quantization", "the face's curve counts cannot fit the partition (" +
                             std::to_string(hits.size()) +
                             " separatrix ends, none can change this): " + why);
  auto order_ok = [&]() {
    for (LO l = 0; l < static_cast<LO>(L.loops.size()); ++l) {
      const auto& ids = on_loop[l];
      if (ids.size() < 2) continue;
      LO total = 0;
      const LO m = loop_size(l);
      for (std::size_t k = 0; k < ids.size(); ++k) {
        const LO d = ((nodes[ids[(k + 1) % ids.size()]].ipos - nodes[ids[k]].ipos) % m + m) % m;
        if (d == 0) return false;
        total += d;
      }
      if (total != m) return false;
    }
    return true;
  };
  double best_cost = 1e300;
  std::vector<LO> best;
  bool found = false;
  long budget = 400000;
  std::function<void(std::size_t, double)> search = [&](std::size_t k, double cost) {
    if (cost >= best_cost || --budget < 0) return;
    if (k == hits.size()) {
      if (!order_ok() || !consistent()) return;
      best_cost = cost;
      found = true;
      best.clear();
      for (LO hh : hits) best.push_back(nodes[hh].ipos);
      return;
    }
    Node& n = nodes[hits[k]];
    const LO m = loop_size(n.loop), base = static_cast<LO>(std::lround(n.pos));
    std::vector<LO> cand;
    for (int dlt = -c.options.snap_range; dlt <= c.options.snap_range; ++dlt)
      cand.push_back(base + dlt);
    std::sort(cand.begin(), cand.end(),
              [&](LO a, LO b) { return std::abs(a - n.pos) < std::abs(b - n.pos); });
    for (LO p : cand) {
      n.ipos = ((p % m) + m) % m;
      if (consistent()) search(k + 1, cost + std::abs(p - n.pos));
    }
    n.ipos = kNoIndex;
  };
  search(0, 0.0);
  if (!found && budget < 0)
    fail("quantization", "the search for the places of " + std::to_string(hits.size()) +
                             " separatrix ends ran out of steps before finding equal counts on "
                             "opposite region sides");
  if (!found)
    fail("quantization", "no placement of the separatrix ends within " +
                             std::to_string(c.options.snap_range) +
                             " curve vertices gives equal counts on opposite region sides");
  for (std::size_t k = 0; k < hits.size(); ++k) nodes[hits[k]].ipos = best[k];
  consistent();
  // Classes no boundary side reaches: counts from their length.
  std::map<LO, std::pair<double, int>> free_len;
  for (std::size_t e = 0; e < num_sep_edges; ++e)
    if (value[find(static_cast<LO>(e))] < 0) {
      auto& [len, cnt] = free_len[find(static_cast<LO>(e))];
      len += length3d(c, edges[e].uv);
      ++cnt;
    }
  for (const auto& [cls, lc] : free_len)
    value[cls] = std::max<LO>(1, static_cast<LO>(std::lround(lc.first / lc.second / c.h)));

  // Separatrix ends move to their curve vertices; the displacement fades along the arc.
  for (std::size_t e = 0; e < num_sep_edges; ++e) {
    auto& uv = edges[e].uv;
    for (int end = 0; end < 2; ++end) {
      const Node& n = nodes[end == 0 ? edges[e].a : edges[e].b];
      if (n.kind != Node::Hit) continue;
      const Vec2 target = L.loops[n.loop].points[static_cast<std::size_t>(n.ipos)].uv;
      const Vec2 delta = target - (end == 0 ? uv.front() : uv.back());
      const std::size_t m = uv.size();
      for (std::size_t i = 0; i < m; ++i) {
        const double w =
            m > 1 ? static_cast<double>(end == 0 ? m - 1 - i : i) / static_cast<double>(m - 1)
                  : 1.0;
        uv[i] += delta * w;
      }
    }
  }

  // Vertices: loop points, interior nodes, separatrix samples, region interiors.
  mesh::FaceMesh out_mesh;
  out_mesh.face = c.f;
  auto add_vertex = [&](const Vec2& uv, const Vec3& xyz, const mesh::VertexClass& vc) {
    out_mesh.uv.push_back(uv);
    out_mesh.points.push_back(xyz);
    out_mesh.vclass.push_back(vc);
    return static_cast<LO>(out_mesh.points.size() - 1);
  };
  auto interior_class = [&](const Vec2& uv) {
    mesh::VertexClass vc;
    vc.dim = 2;
    vc.entity = c.f;
    vc.param = {uv.u, uv.v};
    return vc;
  };
  std::vector<std::vector<LO>> loop_vertex(L.loops.size());
  for (std::size_t l = 0; l < L.loops.size(); ++l)
    for (const auto& p : L.loops[l].points)
      loop_vertex[l].push_back(add_vertex(p.uv, p.xyz, p.vclass));
  std::vector<LO> node_vertex(nodes.size(), kNoIndex);
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const Node& n = nodes[k];
    if (n.kind == Node::Corner || n.kind == Node::Hit)
      node_vertex[k] = loop_vertex[n.loop][static_cast<std::size_t>(n.ipos)];
    else
      node_vertex[k] = add_vertex(n.uv, at(c, n.uv), interior_class(n.uv));
    if (n.kind == Node::Singular) singular_vertices.push_back(node_vertex[k]);
  }
  std::vector<std::vector<LO>> edge_vertices(num_sep_edges);
  for (std::size_t e = 0; e < num_sep_edges; ++e) {
    const LO n = value[find(static_cast<LO>(e))];
    const std::vector<Vec2> s = resample(c, edges[e].uv, n);
    edge_vertices[e].push_back(node_vertex[edges[e].a]);
    for (int k = 1; k < n; ++k)
      edge_vertices[e].push_back(add_vertex(s[k], at(c, s[k]), interior_class(s[k])));
    edge_vertices[e].push_back(node_vertex[edges[e].b]);
  }
  auto side_vertices = [&](const Side& s) {
    std::vector<LO> v;
    if (s.boundary) {
      const Node& a = nodes[tail(s.half_edges.front())];
      const LO m = loop_size(a.loop), cnt = boundary_count(s);
      for (LO k = 0; k <= cnt; ++k)
        v.push_back(loop_vertex[a.loop][static_cast<std::size_t>((a.ipos + k) % m)]);
    } else {
      const LO h = s.half_edges[0];
      v = edge_vertices[h / 2];
      if (h & 1) std::reverse(v.begin(), v.end());
    }
    return v;
  };
  const bool flip = c.model.faces()[c.f].reversed;
  for (const auto& s : sides) {
    const std::vector<LO> b = side_vertices(s[0]), r = side_vertices(s[1]);
    std::vector<LO> t = side_vertices(s[2]), lft = side_vertices(s[3]);
    std::reverse(t.begin(), t.end());
    std::reverse(lft.begin(), lft.end());
    const std::size_t n = b.size() - 1, m = r.size() - 1;
    if (t.size() != n + 1 || lft.size() != m + 1)
      fail("quantization", "opposite region sides differ");
    std::vector<LO> grid((n + 1) * (m + 1));
    auto id = [&](std::size_t i, std::size_t j) -> LO& { return grid[j * (n + 1) + i]; };
    for (std::size_t i = 0; i <= n; ++i) {
      id(i, 0) = b[i];
      id(i, m) = t[i];
    }
    for (std::size_t j = 0; j <= m; ++j) {
      id(0, j) = lft[j];
      id(n, j) = r[j];
    }
    const auto& U = out_mesh.uv;
    for (std::size_t j = 1; j < m; ++j)
      for (std::size_t i = 1; i < n; ++i) {
        const double x = static_cast<double>(i) / n, y = static_cast<double>(j) / m;
        // Transfinite (Coons) interpolation of the four sides in the parameter plane.
        const Vec2 p = U[b[i]] * (1 - y) + U[t[i]] * y + U[lft[j]] * (1 - x) + U[r[j]] * x -
                       (U[b[0]] * ((1 - x) * (1 - y)) + U[b[n]] * (x * (1 - y)) +
                        U[t[0]] * ((1 - x) * y) + U[t[n]] * (x * y));
        id(i, j) = add_vertex(p, at(c, p), interior_class(p));
      }
    for (std::size_t j = 0; j < m; ++j)
      for (std::size_t i = 0; i < n; ++i) {
        std::array<LO, 4> q{id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)};
        if (flip) std::swap(q[1], q[3]);
        out_mesh.quads.push_back(q);
      }
    // The region as a block: (i, j) runs counter-clockwise in uv, which is along the face normal
    // unless the face is reversed; then the quads were flipped and the block is the transposed
    // grid (j, i).
    RegionGrid g;
    g.ni = static_cast<LO>(flip ? m : n);
    g.nj = static_cast<LO>(flip ? n : m);
    g.vertices.resize(grid.size());
    for (std::size_t j = 0; j <= m; ++j)
      for (std::size_t i = 0; i <= n; ++i)
        g.vertices[flip ? i * (m + 1) + j : j * (n + 1) + i] = id(i, j);
    rep.grids.push_back(std::move(g));
  }
  return out_mesh;
}

}  // namespace

mesh::FaceMesh mesh_face_from_field(const cad::CadModel& model, LO f,
                                    std::span<const mesh::CurveMesh> curves,
                                    const mesh::FaceMesh& tri, const Frame& frame,
                                    std::span<const double> theta,
                                    std::span<const SingularPoint> given,
                                    const FieldMeshOptions& options, linalg::SolverLane* lane,
                                    FieldMeshReport* report) {
  FieldMeshReport local;
  FieldMeshReport& rep = report != nullptr ? *report : local;
  rep = FieldMeshReport{};
  rep.face = f;
  try {
    QSMESH_CHECK(theta.size() == tri.points.size(), "one angle per vertex expected");
    const auto surface = model.face_geometry(f);
    const detail::SplitPoints split = detail::split_points(tri, *surface, given);
    for (const auto& b : split.boundary)
      if (b.d > 1)
        fail("compatibility", "a boundary singular point of index " + std::to_string(b.d) +
                                  "/4: Eq. 15 leaves 2 - 4 I quads there, at least one (I <= 1/4)");
    const detail::Loops loops = detail::face_loops(model, f, curves, tri, frame, split.boundary);
    rep.compatibility = detail::compatibility(loops, theta);
    if (!rep.compatibility.ok) fail("compatibility", rep.compatibility.reason);
    const std::vector<double> aligned =
        detail::align_field(tri, loops, theta, rep.compatibility, options.solver, lane);
    std::vector<SingularPoint> singular = split.interior;
    if (given.empty()) singular = detect_singularities(tri, aligned);
    // Points of index 0 are regular; they emit four separatrices that only cut regions further.
    std::erase_if(singular, [](const SingularPoint& s) { return s.d == 0; });
    rep.singularities = static_cast<int>(singular.size());
    const detail::Locator locator(tri);
    Context c{model, f, *surface, tri, frame, aligned, loops, locator, options};
    double len = 0;
    int cnt = 0;
    for (const auto& loop : loops.loops)
      for (std::size_t i = 0; i < loop.points.size(); ++i, ++cnt)
        len += distance(loop.points[i].xyz, loop.points[(i + 1) % loop.points.size()].xyz);
    c.h = len / std::max(1, cnt);
    double tri_len = 0;
    for (const auto& t : tri.triangles) tri_len += distance(tri.points[t[0]], tri.points[t[1]]);
    tri_len /= std::max<std::size_t>(1, tri.triangles.size());
    c.step = options.step_factor * std::min(c.h, tri_len);
    c.rho = 1.5 * tri_len;
    std::vector<LO> singular_vertices;
    mesh::FaceMesh quads = partition_and_fill(c, singular, rep, singular_vertices);
    auto worst_sicn = [&](const mesh::FaceMesh& m) {
      double worst = 1;
      for (const auto& q : m.quads)
        worst = std::min(worst, smooth::oriented_sicn({m.points[q[0]], m.points[q[1]],
                                                       m.points[q[2]], m.points[q[3]]},
                                                      surface->normal(m.uv[q[0]]), 1.0));
      return worst;
    };
    // Smoothing that keeps the singular points where the user put them: the chord-weighted
    // Laplace layout with the boundary and the singular vertices fixed, kept when it is better.
    {
      const LO nv = quads.num_vertices();
      std::vector<LO> order, rank(nv, kNoIndex);
      std::vector<char> fixed(nv, 0);
      for (LO v = 0; v < nv; ++v) fixed[v] = quads.vclass[v].dim != 2;
      for (LO v : singular_vertices) fixed[v] = 1;
      for (int pass = 1; pass >= 0; --pass)
        for (LO v = 0; v < nv; ++v)
          if (fixed[v] == pass) {
            rank[v] = static_cast<LO>(order.size());
            order.push_back(v);
          }
      const LO num_fixed = static_cast<LO>(std::count(fixed.begin(), fixed.end(), 1));
      std::vector<std::array<LO, 4>> q2 = quads.quads;
      for (auto& q : q2)
        for (LO& v : q) v = rank[v];
      std::vector<Vec2> uv(nv);
      for (LO v = 0; v < nv; ++v) uv[rank[v]] = quads.uv[v];
      if (smooth::chord_laplace_uv(q2, num_fixed, uv)) {
        mesh::FaceMesh laid = quads;
        for (LO v = 0; v < nv; ++v)
          if (!fixed[v]) {
            laid.uv[v] = uv[rank[v]];
            laid.points[v] = surface->eval(laid.uv[v]).p;
            laid.vclass[v].param = {laid.uv[v].u, laid.uv[v].v};
          }
        if (worst_sicn(laid) > worst_sicn(quads)) quads = std::move(laid);
      }
    }
    {
      // smooth_face keeps vertices of triangles where they are: the singular vertices are given
      // such a (degenerate) triangle for the call unless they may move.
      mesh::FaceMesh locked = quads;
      if (!options.move_singular_points)
        for (LO v : singular_vertices) locked.triangles.push_back({v, v, v});
      smooth::SmoothOptions so;
      so.iterations = options.smooth_iterations;
      mesh::FaceMesh smoothed = smooth::smooth_face(locked, *surface, so);
      smoothed.triangles.clear();
      if (worst_sicn(smoothed) >= worst_sicn(quads)) quads = std::move(smoothed);
    }
    rep.stats = mesh::face_quad_stats(quads);
    const double worst = worst_sicn(quads);
    if (worst <= 0)
      fail("filling",
           "the filled regions hold invalid quads (SICN min " + std::to_string(worst) + ")");
    if (worst < options.min_sicn)
      fail("filling",
           "SICN min " + std::to_string(worst) + " below " + std::to_string(options.min_sicn));
    rep.ok = true;
    return quads;
  } catch (const Failure& e) {
    rep.stage = e.stage;
    rep.reason = e.reason;
  } catch (const std::exception& e) {
    rep.stage = rep.stage.empty() ? "field" : rep.stage;
    rep.reason = e.what();
  }
  rep.ok = false;
  rep.grids.clear();
  return {};
}

}  // namespace qsmesh::fieldmesh
