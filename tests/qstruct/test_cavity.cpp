#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "analytic_surfaces.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/qstruct/cavity.hpp"
#include "qsmesh/smooth/quad_tools.hpp"

namespace qsmesh::qstruct {
namespace {

// The shared plane with its projection in closed form (the orthogonal foot), as these tests
// always had it, rather than Newton steps.
class Plane : public test::Plane {
 public:
  [[nodiscard]] Vec2 project(const Vec3& p, const Vec2&, Vec3* foot) const override {
    if (foot) *foot = {p.x, p.y, 0};
    return {p.x, p.y};
  }
};

// nx x ny grid of unit squares on face 0: boundary vertices first (counter-clockwise from the
// origin, corners dim 0, the rest on curves 0..3), interior vertices after, quads
// counter-clockwise.
mesh::FaceMesh grid(int nx, int ny) {
  mesh::FaceMesh m;
  m.face = 0;
  std::map<std::pair<int, int>, LO> id;
  const auto add = [&](int i, int j, mesh::VertexClass c) {
    id[{i, j}] = m.num_vertices();
    m.points.push_back({double(i), double(j), 0});
    m.uv.push_back({double(i), double(j)});
    m.vclass.push_back(c);
  };
  std::vector<std::pair<int, int>> loop;
  for (int i = 0; i < nx; ++i) loop.emplace_back(i, 0);
  for (int j = 0; j < ny; ++j) loop.emplace_back(nx, j);
  for (int i = nx; i > 0; --i) loop.emplace_back(i, ny);
  for (int j = ny; j > 0; --j) loop.emplace_back(0, j);
  LO corner = 0;
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const auto [i, j] = loop[k];
    const bool is_corner = (i == 0 || i == nx) && (j == 0 || j == ny);
    const int side = j == 0 && i < nx ? 0 : (i == nx && j < ny ? 1 : (j == ny && i > 0 ? 2 : 3));
    add(i, j,
        is_corner ? mesh::VertexClass{0, corner++, kNoIndex, {0, 0}}
                  : mesh::VertexClass{1, side, static_cast<LO>(k), {double(k), 0}});
  }
  for (int j = 1; j < ny; ++j)
    for (int i = 1; i < nx; ++i)
      add(i, j, mesh::VertexClass{2, 0, kNoIndex, {double(i), double(j)}});
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      m.quads.push_back({id[{i, j}], id[{i + 1, j}], id[{i + 1, j + 1}], id[{i, j + 1}]});
  return m;
}

LO vertex_at(const mesh::FaceMesh& m, double x, double y) {
  for (LO v = 0; v < m.num_vertices(); ++v)
    if (m.points[v].x == x && m.points[v].y == y) return v;
  return kNoIndex;
}

// Rotates the edge shared by two quads: the two quads (a b e f), (b c d e) sharing b-e become
// (a b c f), (c d e f). b and e lose a quad (valence 3), c and f gain one (valence 5). Then the
// interior is smoothed so that the input is valid.
void rotate_edge(mesh::FaceMesh& m, LO b, LO e) {
  std::vector<LO> qs;
  for (LO q = 0; q < static_cast<LO>(m.quads.size()); ++q) {
    const auto& qd = m.quads[q];
    for (int k = 0; k < 4; ++k)
      if ((qd[k] == b && qd[(k + 1) % 4] == e) || (qd[k] == e && qd[(k + 1) % 4] == b))
        qs.push_back(q);
  }
  ASSERT_EQ(qs.size(), 2u);
  // Rotate both quads so that quad 0 is (x b e y) ... i.e. find the cycle (a b c d e f) of the
  // hexagon.
  auto at = [&](LO q, LO v) {
    int k = 0;
    while (m.quads[q][k] != v) ++k;
    return k;
  };
  LO q1 = qs[0], q2 = qs[1];
  // q1 holds b -> e? then swap roles so that q1 has e -> b, i.e. q1 = (a b e f) reads b then e
  // backwards.
  int k = at(q1, b);
  if (m.quads[q1][(k + 1) % 4] != e) std::swap(q1, q2);
  // q1 = (b e f a) in cyclic order, q2 = (e b c d).
  k = at(q1, b);
  const LO f = m.quads[q1][(k + 2) % 4], a = m.quads[q1][(k + 3) % 4];
  const int k2 = at(q2, e);
  const LO c = m.quads[q2][(k2 + 2) % 4], d = m.quads[q2][(k2 + 3) % 4];
  // Hexagon b e f a ... cyclic: a b ... going around: (b, c, d, e, f, a) with q1 = b e f a, q2 = e
  // b c d. New diagonal joins c and f: quads (f a b c) and (c d e f), same orientation.
  m.quads[q1] = {f, a, b, c};
  m.quads[q2] = {c, d, e, f};
}

std::map<LO, int> interior_valences(const mesh::FaceMesh& m) {
  std::vector<int> val(m.num_vertices(), 0);
  for (const auto& q : m.quads)
    for (const LO v : q) ++val[v];
  std::map<LO, int> out;
  for (LO v = 0; v < m.num_vertices(); ++v)
    if (m.vclass[v].dim == 2 && val[v] != 0) out[v] = val[v];
  return out;
}

double min_sicn(const mesh::FaceMesh& m) {
  double w = 2;
  for (const auto& q : m.quads)
    w = std::min(w,
                 mesh::quad_sicn({m.points[q[0]], m.points[q[1]], m.points[q[2]], m.points[q[3]]}));
  return w;
}

// m after `iterations` passes of the smoother (test inputs made valid after edge rotations).
mesh::FaceMesh smoothed(const mesh::FaceMesh& m, const Plane& plane, int iterations) {
  smooth::SmoothOptions so;
  so.iterations = iterations;
  return smooth::smooth_face(m, plane, so);
}

// An nx x ny grid with rotated edges (two valence-3 and two valence-5 vertices each), smoothed.
mesh::FaceMesh perturbed(const Plane& plane, int nx = 10, int ny = 8,
                         const std::vector<std::array<double, 4>>& edges = {{4, 4, 5, 4}}) {
  mesh::FaceMesh m = grid(nx, ny);
  for (const auto& e : edges) rotate_edge(m, vertex_at(m, e[0], e[1]), vertex_at(m, e[2], e[3]));
  return smoothed(m, plane, 20);
}

// The CAD-classified vertices are kept, in the same order, with the same points, uv and class.
void expect_boundary_kept(const mesh::FaceMesh& in, const mesh::FaceMesh& out) {
  std::vector<LO> a, b;
  for (LO v = 0; v < in.num_vertices(); ++v)
    if (in.vclass[v].dim < 2) a.push_back(v);
  for (LO v = 0; v < out.num_vertices(); ++v)
    if (out.vclass[v].dim < 2) b.push_back(v);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const LO v = a[i], w = b[i];
    EXPECT_EQ(out.vclass[w].dim, in.vclass[v].dim);
    EXPECT_EQ(out.vclass[w].entity, in.vclass[v].entity);
    EXPECT_EQ(out.vclass[w].index, in.vclass[v].index);
    EXPECT_EQ(out.points[w], in.points[v]);
    EXPECT_TRUE(out.uv[w] == in.uv[v]);
  }
}

TEST(Cavity, Topology) {
  const mesh::FaceMesh m = grid(3, 2);
  const QuadTopology t(m);
  EXPECT_EQ(t.num_quads(), 6);
  const LO center = vertex_at(m, 1, 1);
  EXPECT_EQ(t.valence(center), 4);
  EXPECT_FALSE(t.on_boundary(center));
  EXPECT_TRUE(t.on_boundary(vertex_at(m, 0, 0)));
  EXPECT_EQ(t.valence(vertex_at(m, 0, 0)), 1);
  int boundary_edges = 0;
  for (LO q = 0; q < t.num_quads(); ++q)
    for (int k = 0; k < 4; ++k) {
      const LO n = t.neighbour(q, k);
      if (n == kNoIndex) {
        ++boundary_edges;
        continue;
      }
      bool back = false;
      for (int j = 0; j < 4; ++j) back = back || t.neighbour(n, j) == q;
      EXPECT_TRUE(back);
    }
  EXPECT_EQ(boundary_edges, 10);
  mesh::FaceMesh bad = m;
  bad.quads[1] = {bad.quads[1][3], bad.quads[1][2], bad.quads[1][1], bad.quads[1][0]};  // flipped
  EXPECT_THROW({ const QuadTopology bad_topology(bad); }, Error);
}

TEST(Cavity, Step1RemovesUnnecessaryPair) {
  const Plane plane;
  const mesh::FaceMesh in = perturbed(plane);
  ASSERT_GT(min_sicn(in), 0);
  ASSERT_EQ(count_irregular(in), 4);
  CavityReport rep;
  const auto patterns = builtin_patterns();
  const mesh::FaceMesh out = remesh_cavities(in, plane, {}, patterns, CavityOptions{}, &rep);
  EXPECT_TRUE(rep.skipped.empty()) << rep.skipped;
  EXPECT_EQ(rep.irregular_before, 4);
  EXPECT_EQ(rep.irregular_after, 0);
  EXPECT_GE(rep.remeshed[0], 1);
  for (const auto& [v, val] : interior_valences(out)) EXPECT_EQ(val, 4) << "vertex " << v;
  EXPECT_GT(min_sicn(out), 0.5);
  EXPECT_EQ(out.quads.size(), in.quads.size());
  expect_boundary_kept(in, out);
  // Quads keep facing +z (counter-clockwise in the plane).
  for (const auto& q : out.quads) {
    const Vec3 n = cross(out.points[q[1]] - out.points[q[0]], out.points[q[2]] - out.points[q[0]]);
    EXPECT_GT(n.z, 0);
  }
}

TEST(Cavity, Step1IsLocal) {
  const Plane plane;
  const mesh::FaceMesh in = perturbed(plane, 16, 16);
  CavityOptions options;
  options.max_quads_maximal = 30;
  options.max_quads_sparse = 30;  // 4 irregular vertices in 256 quads are sparse: same bound
  CavityReport rep;
  const auto patterns = builtin_patterns();
  const mesh::FaceMesh out = remesh_cavities(in, plane, {}, patterns, options, &rep);
  EXPECT_EQ(rep.irregular_after, 0);
  EXPECT_GE(rep.remeshed[0], 1);
  EXPECT_GT(min_sicn(out), 0.5);
  expect_boundary_kept(in, out);
  // Far from the rotated edge nothing moved (ids shift when vertices are dropped; points do not).
  const Vec3 pair{4.5, 4, 0};
  std::set<std::array<double, 3>> kept;
  for (const auto& p : out.points) kept.insert({p.x, p.y, p.z});
  int far = 0, missing = 0;
  for (LO v = 0; v < in.num_vertices(); ++v) {
    if (distance(in.points[v], pair) < 9) continue;
    ++far;
    missing += kept.count({in.points[v].x, in.points[v].y, in.points[v].z}) ? 0 : 1;
  }
  EXPECT_GT(far, 50);
  EXPECT_EQ(missing, 0);
}

// What every remeshable cavity must be: free of the flagged vertex `flagged`, lowering the
// irregularity, and convex (every boundary vertex inside the face has n_out != 1).
void expect_remeshable_without(const QuadTopology& t, const Cavity& c, LO flagged) {
  EXPECT_EQ(std::count(c.interior.begin(), c.interior.end(), flagged), 0);
  EXPECT_LT(c.irregularity_after, c.irregularity_before);
  for (std::size_t i = 0; i < c.boundary.size(); ++i)
    if (!t.on_boundary(c.boundary[i])) {
      EXPECT_NE(t.valence(c.boundary[i]) - c.n_in[i], 1);
    }
}

TEST(Cavity, SingularityIsNeverInside) {
  const Plane plane;
  const mesh::FaceMesh m = perturbed(plane);
  const QuadTopology t(m);
  // Flag one of the valence-3 vertices; grow from the other irregular ones.
  std::vector<char> singular(m.num_vertices(), 0);
  LO s = kNoIndex;
  std::vector<LO> others;
  for (const auto& [v, val] : interior_valences(m)) {
    if (val == 3 && s == kNoIndex) {
      s = v;
    } else if (val != 4) {
      others.push_back(v);
    }
  }
  ASSERT_NE(s, kNoIndex);
  ASSERT_EQ(others.size(), 3u);
  singular[s] = 1;
  const auto patterns = builtin_patterns();
  std::vector<Pattern> four;
  for (const auto& p : patterns)
    if (p.num_sides() == 4) four.push_back(p);
  for (const bool maximal : {false, true}) {
    GrowOptions go;
    go.maximal = maximal;
    go.patterns = four;
    for (const LO seed : others) {
      const GrowResult g = grow_cavity(m, t, seed, singular, go);
      for (const auto& c : g.remeshable) {
        expect_remeshable_without(t, c, s);
        EXPECT_FALSE(c.matches.empty());
        LO sum = 0;
        for (const LO e : c.side_edges) sum += e;
        EXPECT_EQ(sum, static_cast<LO>(c.boundary.size()));
      }
    }
  }
  // Without the flag, a maximal growth from a valence-5 vertex finds a grid cavity holding all
  // four.
  std::vector<char> none(m.num_vertices(), 0);
  std::vector<Pattern> grid_only{patterns[0]};
  GrowOptions go;
  go.maximal = true;
  go.patterns = grid_only;
  const GrowResult g = grow_cavity(m, t, others.back(), none, go);
  ASSERT_FALSE(g.remeshable.empty());
  EXPECT_EQ(std::count(g.remeshable.back().interior.begin(), g.remeshable.back().interior.end(), s),
            1);
}

// A flagged vertex next to a +1/-1 pair blocks the isotropic growth (it would become an
// unabsorbable concave vertex); backtracking grows around it instead, to larger grid cavities.
TEST(Cavity, BacktrackingGrowsAroundABlockedConcaveVertex) {
  const Plane plane;
  const mesh::FaceMesh m = perturbed(plane, 16, 16);
  const QuadTopology t(m);
  const auto valences = interior_valences(m);
  std::vector<LO> irregular;
  for (const auto& [v, val] : valences)
    if (val != 4) irregular.push_back(v);
  ASSERT_EQ(irregular.size(), 4u);
  const std::vector<Pattern> grid_only{builtin_patterns()[0]};
  const auto holds_all = [&](const Cavity& c) {
    for (const LO v : irregular)
      if (std::count(c.interior.begin(), c.interior.end(), v) == 0) return false;
    return true;
  };
  int unlocked = 0, candidates = 0;
  for (const auto& [f, val] : valences) {
    if (val != 4 || distance(m.points[f], Vec3{4.5, 4, 0}) > 3.5) continue;
    ++candidates;
    std::vector<char> singular(m.num_vertices(), 0);
    singular[f] = 1;
    // Largest remeshable cavity met holding the four irregular vertices, without and with.
    std::size_t before = 0, after = 0;
    for (const int backtracks : {0, 8}) {
      GrowOptions go;
      go.maximal = true;
      go.patterns = grid_only;
      go.max_backtracks = backtracks;
      for (const LO seed : irregular) {
        const GrowResult g = grow_cavity(m, t, seed, singular, go);
        for (const auto& c : g.remeshable) {
          expect_remeshable_without(t, c, f);
          // The cavity is a disk of distinct quads.
          std::set<LO> distinct(c.quads.begin(), c.quads.end());
          EXPECT_EQ(distinct.size(), c.quads.size());
          if (holds_all(c)) {
            std::size_t& best = backtracks == 0 ? before : after;
            best = std::max(best, c.quads.size());
          }
        }
      }
    }
    // The growths agree up to the first blocked concave vertex, where the plain one stops.
    EXPECT_GE(after, before);
    unlocked += after > before ? 1 : 0;
  }
  EXPECT_GT(candidates, 10);
  EXPECT_GE(unlocked, 1);
}

// Minimal growth asked for several remeshable cavities: the first is the minimal one, the next
// ones are larger.
TEST(Cavity, MinimalGrowthFallbacks) {
  const Plane plane;
  const mesh::FaceMesh m = perturbed(plane, 16, 16);
  const QuadTopology t(m);
  std::vector<char> none(m.num_vertices(), 0);
  std::vector<Pattern> four;
  for (const auto& p : builtin_patterns())
    if (p.num_sides() == 4) four.push_back(p);
  int seeds_with_fallbacks = 0;
  for (const auto& [seed, val] : interior_valences(m)) {
    if (val == 4) continue;
    GrowOptions go;
    go.patterns = four;
    const GrowResult one = grow_cavity(m, t, seed, none, go);
    go.max_remeshable = 3;
    const GrowResult three = grow_cavity(m, t, seed, none, go);
    ASSERT_FALSE(one.remeshable.empty());
    ASSERT_LE(one.remeshable.size(), 1u);
    ASSERT_FALSE(three.remeshable.empty());
    EXPECT_LE(three.remeshable.size(), 3u);
    EXPECT_EQ(three.remeshable[0].quads, one.remeshable[0].quads);
    for (std::size_t k = 1; k < three.remeshable.size(); ++k)
      EXPECT_GT(three.remeshable[k].quads.size(), three.remeshable[k - 1].quads.size());
    seeds_with_fallbacks += three.remeshable.size() > 1 ? 1 : 0;
  }
  EXPECT_GE(seeds_with_fallbacks, 1);
}

// Growths that found nothing are not repeated while nothing changed within their reach: the
// result is the same as with every growth repeated.
TEST(Cavity, SkippingFutileGrowthsKeepsTheResult) {
  const Plane plane;
  // Two pairs far apart and one +1 singularity between them (Step 2 commits), a 3-pair cluster.
  const mesh::FaceMesh in =
      perturbed(plane, 24, 12, {{4, 4, 5, 4}, {18, 6, 18, 7}, {11, 8, 12, 8}, {11, 3, 11, 4}});
  std::vector<crossfield::Singularity> sings(1);
  sings[0].position = {11.5, 8, 0};
  sings[0].index = 1;
  const auto patterns = builtin_patterns();
  CavityOptions with, without;
  without.skip_futile = false;
  with.max_quads_maximal = without.max_quads_maximal = 80;
  CavityReport a, b;
  const mesh::FaceMesh out_a = remesh_cavities(in, plane, sings, patterns, with, &a);
  const mesh::FaceMesh out_b = remesh_cavities(in, plane, sings, patterns, without, &b);
  ASSERT_TRUE(a.skipped.empty()) << a.skipped;
  EXPECT_LT(a.irregular_after, a.irregular_before);
  EXPECT_EQ(out_a.quads, out_b.quads);
  EXPECT_EQ(out_a.points.size(), out_b.points.size());
  for (std::size_t i = 0; i < std::min(out_a.points.size(), out_b.points.size()); ++i)
    EXPECT_EQ(out_a.points[i], out_b.points[i]) << "vertex " << i;
  std::int64_t skipped = 0, skipped_without = 0;
  for (int k = 0; k < 4; ++k) {
    skipped += a.diagnostics[k].skipped_futile;
    skipped_without += b.diagnostics[k].skipped_futile;
    EXPECT_EQ(a.remeshed[k], b.remeshed[k]);
    EXPECT_LE(a.grown[k], b.grown[k]);
  }
  EXPECT_EQ(skipped_without, 0);
  EXPECT_GT(skipped, 0);
}

TEST(Cavity, FlaggedSingularityIsPreserved) {
  const Plane plane;
  const mesh::FaceMesh in = perturbed(plane);
  LO s = kNoIndex;
  for (const auto& [v, val] : interior_valences(in))
    if (val == 3) {
      s = v;
      break;
    }
  ASSERT_NE(s, kNoIndex);
  crossfield::Singularity sing;
  sing.position = in.points[s];
  sing.index = 1;
  CavityReport rep;
  const auto patterns = builtin_patterns();
  const std::vector<crossfield::Singularity> sings{sing};
  const mesh::FaceMesh out = remesh_cavities(in, plane, sings, patterns, CavityOptions{}, &rep);
  EXPECT_TRUE(rep.skipped.empty()) << rep.skipped;
  EXPECT_EQ(rep.flagged, 1);
  EXPECT_EQ(rep.flagged_kept, 1);
  // A valence-3 vertex remains near the singularity, and the mesh is valid.
  bool found = false;
  for (const auto& [v, val] : interior_valences(out))
    if (val == 3 && distance(out.points[v], sing.position) < 3.0) found = true;
  EXPECT_TRUE(found);
  EXPECT_LE(rep.irregular_after, rep.irregular_before);
  EXPECT_GE(rep.irregular_after, 1);
  EXPECT_GT(min_sicn(out), 0);
  expect_boundary_kept(in, out);
}

// A pattern with one interior vertex (triangle: valence 3, pentagon: valence 5) refined with n
// edges per chord, laid out on a regular polygon of side 2n (the boundary on the polygon, the
// interior by smoothing).
mesh::FaceMesh polygon_face(const Plane& plane, const std::string& name, LO n, LO* centre) {
  const auto patterns = builtin_patterns();
  const Pattern* pat = nullptr;
  for (const auto& p : patterns)
    if (p.name == name) pat = &p;
  EXPECT_NE(pat, nullptr);
  const std::vector<LO> chords(static_cast<std::size_t>(pat->num_chords), n);
  const RefinedPattern r = refine_pattern(*pat, chords);
  const int sides = pat->num_sides();
  const double radius = n / std::sin(std::numbers::pi / sides);
  std::vector<Vec2> corner;
  for (int k = 0; k < sides; ++k) {
    const double a = 2 * std::numbers::pi * k / sides;
    corner.push_back({radius * std::cos(a), radius * std::sin(a)});
  }
  mesh::FaceMesh m;
  m.face = 0;
  m.points.resize(r.num_vertices);
  m.uv.assign(r.num_vertices, Vec2{0, 0});
  m.vclass.assign(r.num_vertices, mesh::VertexClass{2, 0, kNoIndex, {0, 0}});
  const LO nb = static_cast<LO>(r.boundary.size());
  for (int side = 0; side < sides; ++side) {
    const LO b0 = r.side_start[side], b1 = side + 1 < sides ? r.side_start[side + 1] : nb;
    for (LO p = b0; p < b1; ++p) {
      const double t = double(p - b0) / double(b1 - b0);
      const LO v = r.boundary[p];
      m.uv[v] = corner[side] * (1 - t) + corner[(side + 1) % sides] * t;
      m.vclass[v] = p == b0 ? mesh::VertexClass{0, side, kNoIndex, {0, 0}}
                            : mesh::VertexClass{1, side, p, {t, 0}};
    }
  }
  for (LO v = 0; v < r.num_vertices; ++v) m.points[v] = plane.eval(m.uv[v]).p;
  m.quads = r.quads;
  *centre = kNoIndex;
  for (LO v = 0; v < pat->num_vertices(); ++v)
    if (std::count(pat->boundary.begin(), pat->boundary.end(), v) == 0)
      *centre = r.coarse_vertex[v];
  return m;
}

// The polygon face of `name` with one edge rotated two steps from the centre (one more +1/-1
// pair on each side of it), smoothed, the centre flagged by a singularity of `index`: the
// remeshing ends with the centre's irregular vertex only.
void absorb_pair(const std::string& name, int index, const CavityOptions& options, int by_step) {
  const Plane plane;
  LO centre = kNoIndex;
  mesh::FaceMesh m = polygon_face(plane, name, 6, &centre);
  const LO valence = index == 1 ? 3 : 5;
  {
    const QuadTopology t(m);
    ASSERT_EQ(t.valence(centre), valence);
    // An edge two steps away from the centre, between valence-4 interior vertices.
    LO b = kNoIndex, e = kNoIndex;
    for (const LO q : t.quads_of(centre)) {
      const auto& qd = m.quads[q];
      int k = 0;
      while (qd[k] != centre) ++k;
      const LO n1 = qd[(k + 1) % 4], n2 = qd[(k + 2) % 4];
      if (t.valence(n1) == 4 && t.valence(n2) == 4 && !t.on_boundary(n1) && !t.on_boundary(n2)) {
        b = n1;
        // From n1, a neighbour outside the quads around the centre.
        for (const LO q2 : t.quads_of(n1)) {
          const auto& d = m.quads[q2];
          if (std::count(d.begin(), d.end(), centre)) continue;
          int j = 0;
          while (d[j] != n1) ++j;
          for (const LO x : {d[(j + 1) % 4], d[(j + 3) % 4]}) {
            bool touches_centre_quad = false;
            for (const LO q3 : t.quads_of(centre))
              touches_centre_quad =
                  touches_centre_quad || std::count(m.quads[q3].begin(), m.quads[q3].end(), x);
            if (!touches_centre_quad && !t.on_boundary(x) && e == kNoIndex) e = x;
          }
        }
        break;
      }
    }
    ASSERT_NE(e, kNoIndex);
    rotate_edge(m, b, e);
  }
  m = smoothed(m, plane, 30);
  ASSERT_GT(min_sicn(m), 0);
  ASSERT_EQ(count_irregular(m), 5);
  crossfield::Singularity sing;
  sing.position = m.points[centre];
  sing.index = index;
  const std::vector<crossfield::Singularity> sings{sing};
  CavityReport rep;
  const auto patterns = builtin_patterns();
  const mesh::FaceMesh out = remesh_cavities(m, plane, sings, patterns, options, &rep);
  EXPECT_EQ(rep.flagged, 1);
  EXPECT_EQ(rep.flagged_kept, 1);
  EXPECT_EQ(rep.irregular_after, 1);
  std::map<int, int> hist;
  for (const auto& [v, val] : interior_valences(out)) ++hist[val];
  EXPECT_EQ(hist[valence], 1);
  EXPECT_GT(min_sicn(out), 0.3);
  EXPECT_GE(rep.remeshed[by_step - 1], 1);
  expect_boundary_kept(m, out);
}

// Step 2: the singularity absorbs the pair (a triangular cavity around the valence-3 centre).
TEST(Cavity, PlusOneSingularityAbsorbsAPair) { absorb_pair("triangle", 1, CavityOptions{}, 2); }

TEST(Cavity, MinusOneSingularityAbsorbsAPair) {
  // All steps: Step 1 finds a grid cavity beside the centre.
  absorb_pair("pentagon", -1, CavityOptions{}, 1);
  // Step 2 alone: a pentagonal cavity around the valence-5 centre.
  CavityOptions only2;
  only2.steps = {false, true, false, false};
  absorb_pair("pentagon", -1, only2, 2);
}

// CavityOptions::screen_passes: candidates stopped after a few smoothing passes are ones the
// acceptance would refuse after all of them, and the passes of the others are unchanged, so the
// result is the unscreened one, bit for bit.
TEST(Cavity, ScreenedCandidatesLeaveTheResultUnchanged) {
  const Plane plane;
  // Graded along x (cells 0.2 to 3.8 wide): the grid replacements of the pairs' cavities are
  // laid out evenly, and many are refused.
  mesh::FaceMesh in =
      perturbed(plane, 24, 12, {{4, 4, 5, 4}, {18, 6, 18, 7}, {11, 8, 12, 8}, {11, 3, 11, 4}});
  for (LO v = 0; v < in.num_vertices(); ++v) {
    const double x = in.uv[v].u / 24;
    in.uv[v].u = 24 * x * (0.1 + 0.9 * x);
    in.points[v] = {in.uv[v].u, in.uv[v].v, 0};
    if (in.vclass[v].dim == 2) in.vclass[v].param = {in.uv[v].u, in.uv[v].v};
  }
  const auto patterns = builtin_patterns();
  CavityOptions screened, unscreened;
  unscreened.screen_passes = 0;
  screened.max_quads_maximal = unscreened.max_quads_maximal = 80;
  // A stricter mean than the default's: some candidates are refused (54), some kept.
  screened.keep_avg_ratio = unscreened.keep_avg_ratio = 1.1;
  CavityReport a, b;
  const mesh::FaceMesh out_a = remesh_cavities(in, plane, {}, patterns, screened, &a);
  const mesh::FaceMesh out_b = remesh_cavities(in, plane, {}, patterns, unscreened, &b);
  ASSERT_TRUE(a.skipped.empty()) << a.skipped;
  EXPECT_LT(a.irregular_after, a.irregular_before);
  EXPECT_EQ(out_a.quads, out_b.quads);
  ASSERT_EQ(out_a.points.size(), out_b.points.size());
  for (std::size_t i = 0; i < out_a.points.size(); ++i)
    EXPECT_EQ(out_a.points[i], out_b.points[i]) << "vertex " << i;
  std::int64_t stopped = 0, stopped_without = 0, refused = 0, refused_without = 0;
  for (int k = 0; k < 4; ++k) {
    const auto& x = a.diagnostics[k];
    const auto& y = b.diagnostics[k];
    stopped += x.refused_screened;
    stopped_without += y.refused_screened;
    refused += x.refused_screened + x.refused_invalid + x.refused_min + x.refused_avg;
    refused_without += y.refused_invalid + y.refused_min + y.refused_avg;
    EXPECT_EQ(a.remeshed[k], b.remeshed[k]);
  }
  EXPECT_EQ(stopped_without, 0);
  EXPECT_GT(stopped, 0);
  EXPECT_EQ(refused, refused_without);
}

// The graded grid of the screen's test, whose candidates are refused in numbers.
mesh::FaceMesh graded_grid(const Plane& plane) {
  mesh::FaceMesh in =
      perturbed(plane, 24, 12, {{4, 4, 5, 4}, {18, 6, 18, 7}, {11, 8, 12, 8}, {11, 3, 11, 4}});
  for (LO v = 0; v < in.num_vertices(); ++v) {
    const double x = in.uv[v].u / 24;
    in.uv[v].u = 24 * x * (0.1 + 0.9 * x);
    in.points[v] = {in.uv[v].u, in.uv[v].v, 0};
    if (in.vclass[v].dim == 2) in.vclass[v].param = {in.uv[v].u, in.uv[v].v};
  }
  return in;
}

void expect_same_mesh(const mesh::FaceMesh& a, const mesh::FaceMesh& b) {
  EXPECT_EQ(a.quads, b.quads);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_EQ(a.points[i], b.points[i]) << "vertex " << i;
    EXPECT_EQ(a.uv[i], b.uv[i]) << "vertex " << i;
  }
}

// CavityMemo: candidates refused before with the same local problem are refused from the record,
// and the result is bit for bit the one without a memo, refusals counted alike.
TEST(Cavity, MemoLeavesTheResultUnchanged) {
  const Plane plane;
  const mesh::FaceMesh in = graded_grid(plane);
  const auto patterns = builtin_patterns();
  CavityOptions options;
  options.max_quads_maximal = 80;
  options.keep_avg_ratio = 1.1;
  CavityReport a, b;
  CavityMemo memo;
  const mesh::FaceMesh with = remesh_cavities(in, plane, {}, patterns, options, &a, &memo);
  const mesh::FaceMesh without = remesh_cavities(in, plane, {}, patterns, options, &b);
  ASSERT_TRUE(a.skipped.empty()) << a.skipped;
  EXPECT_LT(a.irregular_after, a.irregular_before);
  expect_same_mesh(with, without);
  for (int k = 0; k < 4; ++k) {
    const auto& x = a.diagnostics[k];
    const auto& y = b.diagnostics[k];
    EXPECT_EQ(a.remeshed[k], b.remeshed[k]);
    EXPECT_EQ(x.refused_layout, y.refused_layout);
    EXPECT_EQ(x.refused_screened, y.refused_screened);
    EXPECT_EQ(x.refused_invalid, y.refused_invalid);
    EXPECT_EQ(x.refused_min, y.refused_min);
    EXPECT_EQ(x.refused_avg, y.refused_avg);
  }
  EXPECT_GT(memo.records(), 0);
  EXPECT_GT(memo.hits(), 0);  // the rounds meet refused candidates again
}

// A memo handed on to a second call on the same mesh: under the same bounds every candidate the
// first refused is refused from its record; under looser bounds (the second pass's) some are laid
// out again, and the result is the one of a fresh call either way.
TEST(Cavity, MemoIsHandedOnToALaterCall) {
  const Plane plane;
  const mesh::FaceMesh in = graded_grid(plane);
  const auto patterns = builtin_patterns();
  CavityOptions strict;
  strict.max_quads_maximal = 80;
  strict.keep_avg_ratio = 1.1;
  CavityOptions loose = strict;
  loose.keep_avg_ratio = 1.08;
  loose.max_backtracks = 16;
  CavityMemo memo;
  (void)remesh_cavities(in, plane, {}, patterns, strict, nullptr, &memo);
  const std::int64_t hits = memo.hits();
  CavityReport again;
  const mesh::FaceMesh same = remesh_cavities(in, plane, {}, patterns, strict, &again, &memo);
  std::int64_t refused = 0;
  for (const auto& d : again.diagnostics)
    refused +=
        d.refused_layout + d.refused_screened + d.refused_invalid + d.refused_min + d.refused_avg;
  EXPECT_EQ(memo.hits() - hits, refused);  // nothing refused was laid out again
  expect_same_mesh(same, remesh_cavities(in, plane, {}, patterns, strict));

  const std::int64_t before_loose = memo.hits();
  const mesh::FaceMesh looser = remesh_cavities(in, plane, {}, patterns, loose, nullptr, &memo);
  EXPECT_GT(memo.hits(), before_loose);
  expect_same_mesh(looser, remesh_cavities(in, plane, {}, patterns, loose));
  // Other smoothing options: the records are forgotten, the result still the fresh one.
  CavityOptions other = strict;
  other.smooth.iterations = 6;
  const mesh::FaceMesh o = remesh_cavities(in, plane, {}, patterns, other, nullptr, &memo);
  expect_same_mesh(o, remesh_cavities(in, plane, {}, patterns, other));
}

// The memo keeps the pattern lists and match results across calls: a call with another pattern
// list must select its lists again and forget the matches made with the old ones.
TEST(Cavity, MemoFollowsThePatternList) {
  const Plane plane;
  const mesh::FaceMesh in = graded_grid(plane);
  const auto patterns = builtin_patterns();
  std::vector<Pattern> no_grid;  // no regular four-sided pattern: Steps 1 and 3 find nothing
  for (const auto& p : patterns)
    if (p.num_sides() != 4 || p.irregular != 0) no_grid.push_back(p);
  ASSERT_LT(no_grid.size(), patterns.size());
  CavityOptions options;
  options.max_quads_maximal = 80;
  const mesh::FaceMesh all = remesh_cavities(in, plane, {}, patterns, options);
  const mesh::FaceMesh fewer = remesh_cavities(in, plane, {}, no_grid, options);
  ASSERT_NE(all.quads, fewer.quads);  // the lists make a difference on this mesh
  CavityMemo memo;
  expect_same_mesh(remesh_cavities(in, plane, {}, patterns, options, nullptr, &memo), all);
  expect_same_mesh(remesh_cavities(in, plane, {}, no_grid, options, nullptr, &memo), fewer);
  expect_same_mesh(remesh_cavities(in, plane, {}, patterns, options, nullptr, &memo), all);
}

TEST(Cavity, Deterministic) {
  const Plane plane;
  const mesh::FaceMesh in = perturbed(plane, 12, 10, {{4, 4, 5, 4}, {9, 2, 9, 3}});
  ASSERT_EQ(count_irregular(in), 8);
  ASSERT_GT(min_sicn(in), 0);
  const auto patterns = builtin_patterns();
  // Small cavities: several growths and replacements.
  CavityOptions options;
  options.max_quads_maximal = 30;
  CavityReport r1, r2;
  const mesh::FaceMesh a = remesh_cavities(in, plane, {}, patterns, options, &r1);
  const mesh::FaceMesh b = remesh_cavities(in, plane, {}, patterns, options, &r2);
  ASSERT_EQ(a.num_vertices(), b.num_vertices());
  ASSERT_EQ(a.quads, b.quads);
  for (LO v = 0; v < a.num_vertices(); ++v) EXPECT_EQ(a.points[v], b.points[v]);
  EXPECT_EQ(r1.remeshed, r2.remeshed);
  EXPECT_LT(r1.irregular_after, r1.irregular_before);
  // The work bound stops early and says so.
  CavityOptions bounded = options;
  bounded.max_cavities = 1;
  CavityReport r3;
  const mesh::FaceMesh c = remesh_cavities(in, plane, {}, patterns, bounded, &r3);
  EXPECT_TRUE(r3.work_bound_hit);
  EXPECT_EQ(r3.grown[0] + r3.grown[1] + r3.grown[2] + r3.grown[3], 1);
  EXPECT_GT(min_sicn(c), 0);
  // So does the time budget (here spent before the first growth).
  CavityOptions timed = options;
  timed.time_budget_s = 1e-12;
  CavityReport r4;
  const mesh::FaceMesh d = remesh_cavities(in, plane, {}, patterns, timed, &r4);
  EXPECT_TRUE(r4.time_budget_hit);
  EXPECT_EQ(d.quads, in.quads);
}

// The refined pattern `name` fitting the sides `sides` (pattern side 0 along y = 0, counter-
// clockwise on the w x h rectangle, each side uniformly spaced), its interior laid out by
// chord_laplace_uv: face 0, corners dim 0, sides on curves 0..3, the interior after the boundary.
mesh::FaceMesh pattern_mesh(const std::string& name, const std::vector<LO>& sides, double w,
                            double h) {
  const auto patterns = builtin_patterns();
  LO pi = kNoIndex;
  for (LO i = 0; i < static_cast<LO>(patterns.size()); ++i)
    if (patterns[i].name == name) pi = i;
  EXPECT_NE(pi, kNoIndex);
  const auto matches = match_patterns(patterns, sides);
  const auto it = std::find_if(matches.begin(), matches.end(), [&](const PatternMatch& m) {
    return m.pattern == pi && m.start == 0 && !m.reversed;
  });
  EXPECT_NE(it, matches.end());
  const RefinedPattern r = refine_pattern(patterns[pi], it->chords);
  const LO nb = static_cast<LO>(r.boundary.size());
  std::vector<LO> r2m(static_cast<std::size_t>(r.num_vertices), kNoIndex);
  mesh::FaceMesh m;
  m.face = 0;
  const std::array<Vec2, 5> corner{Vec2{0, 0}, Vec2{w, 0}, Vec2{w, h}, Vec2{0, h}, Vec2{0, 0}};
  for (int k = 0; k < 4; ++k) {
    const LO a = r.side_start[k], b = k + 1 < 4 ? r.side_start[k + 1] : nb;
    for (LO p = a; p < b; ++p) {
      const double t = static_cast<double>(p - a) / static_cast<double>(b - a);
      const Vec2 uv = corner[k] * (1 - t) + corner[k + 1] * t;
      r2m[r.boundary[p]] = m.num_vertices();
      m.uv.push_back(uv);
      m.points.push_back({uv.u, uv.v, 0});
      m.vclass.push_back(p == a ? mesh::VertexClass{0, k, kNoIndex, {0, 0}}
                                : mesh::VertexClass{1, k, p, {t, 0}});
    }
  }
  for (LO v = 0; v < r.num_vertices; ++v)
    if (r2m[v] == kNoIndex) {
      r2m[v] = m.num_vertices();
      m.uv.push_back({0, 0});
      m.points.push_back({0, 0, 0});
      m.vclass.push_back(mesh::VertexClass{2, 0, kNoIndex, {0, 0}});
    }
  for (const auto& q : r.quads) m.quads.push_back({r2m[q[0]], r2m[q[1]], r2m[q[2]], r2m[q[3]]});
  EXPECT_TRUE(smooth::chord_laplace_uv(m.quads, nb, m.uv));
  for (LO v = nb; v < m.num_vertices(); ++v) {
    m.points[v] = {m.uv[v].u, m.uv[v].v, 0};
    m.vclass[v].param = {m.uv[v].u, m.uv[v].v};
  }
  return m;
}

// Step 3 with the transitions (CavityOptions::step3_transitions): a size transition (one 3-5
// pair) with an edge rotated at its valence-5 vertex. No grid fits a cavity holding the pair, so
// Step 3 with the grid alone (the paper's Step 1 repeated) leaves the rotated edge's irregular
// vertices; with the transitions the whole region becomes one transition pattern again.
TEST(Cavity, Step3TransitionsRemoveAPairNextToATransition) {
  const Plane plane;
  mesh::FaceMesh m = pattern_mesh("transition_1", {8, 6, 6, 8}, 8, 8);
  ASSERT_EQ(count_irregular(m), 2);
  const auto val = interior_valences(m);
  LO five = kNoIndex;
  for (const auto& [v, k] : val)
    if (k == 5) five = v;
  ASSERT_NE(five, kNoIndex);
  // An interior neighbour of the valence-5 vertex whose edge with it can turn.
  LO other = kNoIndex;
  for (const auto& q : m.quads)
    for (int k = 0; k < 4 && other == kNoIndex; ++k)
      if (q[k] == five && m.vclass[q[(k + 1) % 4]].dim == 2 && val.at(q[(k + 1) % 4]) == 4)
        other = q[(k + 1) % 4];
  ASSERT_NE(other, kNoIndex);
  rotate_edge(m, five, other);
  m = smoothed(m, plane, 20);
  ASSERT_GT(min_sicn(m), 0);
  const std::int64_t before = count_irregular(m);
  ASSERT_GT(before, 2);
  const auto patterns = builtin_patterns();
  CavityOptions only3;
  only3.steps = {false, false, true, false};
  only3.step3_transitions = false;
  CavityReport grid_only, with_transitions;
  const mesh::FaceMesh a = remesh_cavities(m, plane, {}, patterns, only3, &grid_only);
  only3.step3_transitions = true;
  const mesh::FaceMesh b = remesh_cavities(m, plane, {}, patterns, only3, &with_transitions);
  EXPECT_EQ(grid_only.irregular_after, before);
  EXPECT_EQ(with_transitions.irregular_after, 2);
  EXPECT_GT(min_sicn(b), 0.3);
  expect_boundary_kept(m, b);
}

// CavityOptions::max_quads_sparse: a rotated edge in a 20 x 20 grid (4 unnecessary irregular
// vertices for 400 quads, 1%) needs a grid cavity of more quads than a tiny maximal bound allows.
// Step 1 alone leaves it with that bound; the sparse bound takes over from the first round.
TEST(Cavity, SparseIrregularVerticesGetLargerMaximalCavities) {
  const Plane plane;
  const mesh::FaceMesh m = perturbed(plane, 20, 20, {{10, 10, 11, 10}});
  ASSERT_EQ(count_irregular(m), 4);
  const auto patterns = builtin_patterns();
  CavityOptions o;
  o.steps = {true, false, false, false};
  o.max_quads_maximal = 1;
  o.max_quads_sparse = 1;  // no larger bound
  CavityReport fixed_bound, raised, dense;
  const mesh::FaceMesh a = remesh_cavities(m, plane, {}, patterns, o, &fixed_bound);
  EXPECT_EQ(fixed_bound.irregular_after, 4);
  EXPECT_EQ(fixed_bound.escalated, 0);
  o.max_quads_sparse = 600;
  o.sparse_irregular_ratio = 0.005;  // 1% is not sparse for this ratio
  (void)remesh_cavities(m, plane, {}, patterns, o, &dense);
  EXPECT_EQ(dense.irregular_after, 4);
  EXPECT_EQ(dense.escalated, 0);
  o.sparse_irregular_ratio = 0.05;
  const mesh::FaceMesh b = remesh_cavities(m, plane, {}, patterns, o, &raised);
  EXPECT_EQ(raised.escalated, 1);
  EXPECT_EQ(raised.irregular_after, 0);
  EXPECT_GT(min_sicn(b), 0.9);
  expect_boundary_kept(m, b);
}

TEST(Cavity, TrianglesLeaveTheMeshAlone) {
  const Plane plane;
  mesh::FaceMesh m = grid(2, 2);
  m.triangles.push_back({0, 1, 2});
  CavityReport rep;
  const auto patterns = builtin_patterns();
  const mesh::FaceMesh out = remesh_cavities(m, plane, {}, patterns, CavityOptions{}, &rep);
  EXPECT_FALSE(rep.skipped.empty());
  EXPECT_EQ(out.quads, m.quads);
}

}  // namespace
}  // namespace qsmesh::qstruct
