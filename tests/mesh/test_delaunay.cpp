// Parametric Delaunay kernel on analytic faces: plane, cylinder patch, full cylinder with a seam,
// sphere with two poles, square with a hole, L-shape, graded size, determinism, a large plane.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "analytic_surfaces.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/delaunay.hpp"
#include "qsmesh/mesh/predicates.hpp"

namespace {

using namespace qsmesh;
using namespace qsmesh::mesh;
constexpr double kPi = 3.14159265358979323846;

// The kernel never projects: the surfaces return the guess, as they always did here.
constexpr test::Projection kProjection = test::Projection::kGuess;
using test::Cylinder;
using test::Plane;
using test::Sphere;

// ------------------------------------------------------------------ loops
// Appends the side uv0 -> uv1 (uv-linear, n segments; the end point is left to the next side).
void add_side(BoundaryLoop& loop, const cad::FaceGeometry& s, Vec2 uv0, Vec2 uv1, int n, LO curve,
              bool degenerate = false, Vec3 pole = {}) {
  for (int k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / n;
    BoundaryPoint p;
    p.uv = uv0 * (1 - t) + uv1 * t;
    p.xyz = degenerate ? pole : s.eval(p.uv).p;
    p.vclass.dim = k == 0 ? 0 : 1;
    p.vclass.entity = curve;
    p.vclass.index = k;
    loop.points.push_back(p);
    loop.degenerate.push_back(degenerate ? 1 : 0);
  }
}

int segs(double len, double h) { return std::max(1, static_cast<int>(std::lround(len / h))); }

BoundaryLoop polygon(const cad::FaceGeometry& s, const std::vector<Vec2>& corners, double h) {
  BoundaryLoop loop;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Vec2 a = corners[i], b = corners[(i + 1) % corners.size()];
    add_side(loop, s, a, b, segs(norm(b - a), h), static_cast<LO>(i));
  }
  return loop;
}

// ------------------------------------------------------------------ checks
struct Report {
  double uv_area = 0, area3d = 0;
  double frac_len_ok = 0, frac_angle_ok = 0, min_angle = 180, mean_min_angle = 0;
  std::size_t triangles = 0;
};

double angle_deg(const Vec3& a, const Vec3& b, const Vec3& c) {  // at a
  const Vec3 u = b - a, v = c - a;
  return std::acos(std::clamp(dot(u, v) / (norm(u) * norm(v)), -1.0, 1.0)) * 180 / kPi;
}

Report check_mesh(const std::string& name, const FaceMesh& fm, std::span<const BoundaryLoop> loops,
                  bool reversed, const SizeFunction& size, const std::set<LO>& poles = {}) {
  Report r;
  r.triangles = fm.triangles.size();
  const LO nv = fm.num_vertices();
  EXPECT_EQ(fm.uv.size(), fm.points.size());
  EXPECT_EQ(fm.vclass.size(), fm.points.size());
  std::set<std::pair<LO, LO>> edges;
  std::vector<int> used(nv, 0);
  for (const auto& t : fm.triangles) {
    for (int i = 0; i < 3; ++i) {
      EXPECT_GE(t[i], 0);
      EXPECT_LT(t[i], nv);
      used[t[i]] = 1;
      const LO a = t[i], b = t[(i + 1) % 3];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
    EXPECT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
    const double o = orient2d(fm.uv[t[0]], fm.uv[t[1]], fm.uv[t[2]]);
    const bool at_pole = std::any_of(t.begin(), t.end(), [&](LO v) { return poles.count(v) > 0; });
    if (!at_pole) {
      if (reversed)
        EXPECT_LT(o, 0) << name;
      else
        EXPECT_GT(o, 0) << name;
    }
    r.uv_area += std::fabs(0.5 * o);
    r.area3d +=
        0.5 * norm(cross(fm.points[t[1]] - fm.points[t[0]], fm.points[t[2]] - fm.points[t[0]]));
    EXPECT_GT(norm(cross(fm.points[t[1]] - fm.points[t[0]], fm.points[t[2]] - fm.points[t[0]])), 0)
        << name << ": zero-area triangle";
  }
  for (LO v = 0; v < nv; ++v) EXPECT_TRUE(used[v]) << name << ": unreferenced vertex " << v;
  // Every non-degenerate boundary segment is an edge; find boundary vertices by uv, else xyz.
  auto find_vertex = [&](const BoundaryPoint& p) {
    for (LO v = 0; v < nv; ++v)
      if (fm.uv[v] == p.uv && fm.vclass[v].dim < 2) return v;
    for (LO v = 0; v < nv; ++v)
      if (fm.points[v] == p.xyz && fm.vclass[v].dim < 2) return v;
    return kNoIndex;
  };
  int missing = 0;
  for (const BoundaryLoop& L : loops) {
    const std::size_t n = L.points.size();
    for (std::size_t i = 0; i < n; ++i) {
      if (L.degenerate[i]) continue;
      const LO a = find_vertex(L.points[i]), b = find_vertex(L.points[(i + 1) % n]);
      EXPECT_NE(a, kNoIndex);
      EXPECT_NE(b, kNoIndex);
      missing += edges.count({std::min(a, b), std::max(a, b)}) == 0;
    }
  }
  EXPECT_EQ(missing, 0) << name << ": boundary segments missing";
  // Edge lengths relative to the size, and minimum angles.
  std::size_t ok = 0;
  std::array<int, 8> lhist{};
  for (const auto& [a, b] : edges) {
    const double l = distance(fm.points[a], fm.points[b]);
    const double h = 0.5 * (size(fm.uv[a], fm.points[a]) + size(fm.uv[b], fm.points[b]));
    ok += l >= 0.3 * h && l <= 2.0 * h;
    lhist[std::min(7, static_cast<int>(l / h / 0.25))]++;
  }
  r.frac_len_ok = static_cast<double>(ok) / edges.size();
  std::array<int, 7> ahist{};
  std::size_t aok = 0;
  double sum = 0;
  for (const auto& t : fm.triangles) {
    const Vec3 &a = fm.points[t[0]], &b = fm.points[t[1]], &c = fm.points[t[2]];
    const double m = std::min({angle_deg(a, b, c), angle_deg(b, c, a), angle_deg(c, a, b)});
    r.min_angle = std::min(r.min_angle, m);
    sum += m;
    aok += m >= 20;
    ahist[std::min(6, static_cast<int>(m / 10))]++;
  }
  r.mean_min_angle = sum / fm.triangles.size();
  r.frac_angle_ok = static_cast<double>(aok) / fm.triangles.size();
  std::printf(
      "[%s] %zu triangles, %d vertices; min angle %.1f deg, mean min angle %.1f; "
      "edges in [0.3,2]h: %.2f%%; min angle >= 20: %.2f%%\n",
      name.c_str(), fm.triangles.size(), nv, r.min_angle, r.mean_min_angle, 100 * r.frac_len_ok,
      100 * r.frac_angle_ok);
  std::printf("   min-angle histogram (10 deg bins): ");
  for (int k = 0; k < 7; ++k) std::printf("[%d,%d):%d ", 10 * k, 10 * k + 10, ahist[k]);
  std::printf("\n   edge/h histogram (0.25 bins): ");
  for (int k = 0; k < 8; ++k) std::printf("%.2f:%d ", 0.25 * k, lhist[k]);
  std::printf("\n");
  return r;
}

void expect_quality(const Report& r, double len_ok = 0.97, double angle_ok = 0.97) {
  EXPECT_GE(r.frac_len_ok, len_ok);
  EXPECT_GE(r.frac_angle_ok, angle_ok);
}

// ------------------------------------------------------------------ tests
TEST(Delaunay, PlaneSquare) {
  const Plane plane(kProjection);
  const double h = 0.5;
  std::vector<BoundaryLoop> loops{polygon(plane, {{0, 0}, {10, 0}, {10, 10}, {0, 10}}, h)};
  SizeFunction size = [&](const Vec2&, const Vec3&) { return h; };
  TriangulateStats stats;
  const FaceMesh fm = triangulate_face(plane, false, loops, size, {}, &stats);
  const Report r = check_mesh("plane", fm, loops, false, size);
  EXPECT_NEAR(r.uv_area, 100, 1e-9);
  expect_quality(r);
  EXPECT_GT(r.min_angle, 25);
  // Boundary points first, in input order, with their classification.
  for (std::size_t i = 0; i < loops[0].points.size(); ++i) {
    EXPECT_EQ(fm.uv[i], loops[0].points[i].uv);
    EXPECT_EQ(fm.vclass[i].entity, loops[0].points[i].vclass.entity);
  }
  for (std::size_t i = loops[0].points.size(); i < fm.uv.size(); ++i) {
    EXPECT_EQ(fm.vclass[i].dim, 2);
    EXPECT_EQ(fm.vclass[i].entity, kNoIndex);
    EXPECT_EQ(fm.vclass[i].param[0], fm.uv[i].u);
  }
  std::printf("   stats: inserted %lld rejected %lld flips %lld\n",
              static_cast<long long>(stats.inserted), static_cast<long long>(stats.rejected),
              static_cast<long long>(stats.boundary_flips));
}

TEST(Delaunay, ReversedAndClockwiseLoop) {
  const Plane plane(kProjection);
  const double h = 0.7;
  // Clockwise outer loop, reversed face.
  std::vector<BoundaryLoop> loops{polygon(plane, {{0, 0}, {0, 5}, {8, 5}, {8, 0}}, h)};
  SizeFunction size = [&](const Vec2&, const Vec3&) { return h; };
  const FaceMesh fm = triangulate_face(plane, true, loops, size);
  const Report r = check_mesh("plane-reversed-cw", fm, loops, true, size);
  EXPECT_NEAR(r.uv_area, 40, 1e-9);
  expect_quality(r);
}

TEST(Delaunay, SquareWithHole) {
  const Plane plane(kProjection);
  const double h = 0.4;
  std::vector<BoundaryLoop> loops{polygon(plane, {{0, 0}, {10, 0}, {10, 10}, {0, 10}}, h),
                                  polygon(plane, {{3, 3}, {7, 3}, {7, 7}, {3, 7}}, h)};
  SizeFunction size = [&](const Vec2&, const Vec3&) { return h; };
  const FaceMesh fm = triangulate_face(plane, false, loops, size);
  const Report r = check_mesh("square-hole", fm, loops, false, size);
  EXPECT_NEAR(r.uv_area, 84, 1e-9);
  expect_quality(r);
  for (const auto& t : fm.triangles) {  // nothing inside the hole
    const Vec2 c = (fm.uv[t[0]] + fm.uv[t[1]] + fm.uv[t[2]]) / 3.0;
    EXPECT_FALSE(c.u > 3 && c.u < 7 && c.v > 3 && c.v < 7);
  }
}

TEST(Delaunay, LShape) {
  const Plane plane(kProjection);
  const double h = 0.3;
  std::vector<BoundaryLoop> loops{
      polygon(plane, {{0, 0}, {6, 0}, {6, 3}, {3, 3}, {3, 6}, {0, 6}}, h)};
  SizeFunction size = [&](const Vec2&, const Vec3&) { return h; };
  const FaceMesh fm = triangulate_face(plane, false, loops, size);
  const Report r = check_mesh("L-shape", fm, loops, false, size);
  EXPECT_NEAR(r.uv_area, 27, 1e-9);
  expect_quality(r);
}

// A patch of a cylinder of radius 10: u in [0, 1.2] rad (12 mm of arc), v in [0, 6] mm; sides of
// about h.
BoundaryLoop cylinder_patch(const Cylinder& cyl, double h) {
  BoundaryLoop loop;
  add_side(loop, cyl, {0, 0}, {1.2, 0}, segs(12, h), 0);
  add_side(loop, cyl, {1.2, 0}, {1.2, 6}, segs(6, h), 1);
  add_side(loop, cyl, {1.2, 6}, {0, 6}, segs(12, h), 2);
  add_side(loop, cyl, {0, 6}, {0, 0}, segs(6, h), 3);
  return loop;
}

TEST(Delaunay, CylinderPatchAnisotropicUV) {
  const Cylinder cyl(10, kProjection);
  const double h = 0.8;
  std::vector<BoundaryLoop> loops{cylinder_patch(cyl, h)};
  SizeFunction size = [&](const Vec2&, const Vec3&) { return h; };
  const FaceMesh fm = triangulate_face(cyl, false, loops, size);
  const Report r = check_mesh("cylinder-patch", fm, loops, false, size);
  EXPECT_NEAR(r.uv_area, 7.2, 1e-9);
  EXPECT_NEAR(r.area3d, 72, 72 * 0.01);
  expect_quality(r);
}

TEST(Delaunay, FullCylinderWithSeam) {
  const Cylinder cyl(10, kProjection);
  const double h = 1.0, H = 12;
  BoundaryLoop loop;
  const int nc = segs(2 * kPi * 10, h), ns = segs(H, h);
  add_side(loop, cyl, {0, 0}, {2 * kPi, 0}, nc, 0);        // bottom circle
  add_side(loop, cyl, {2 * kPi, 0}, {2 * kPi, H}, ns, 1);  // seam up at u = 2 pi
  add_side(loop, cyl, {2 * kPi, H}, {0, H}, nc, 2);        // top circle, reversed
  add_side(loop, cyl, {0, H}, {0, 0}, ns, 1);              // seam down at u = 0
  std::vector<BoundaryLoop> loops{loop};
  SizeFunction size = [&](const Vec2&, const Vec3&) { return h; };
  const FaceMesh fm = triangulate_face(cyl, false, loops, size);
  const Report r = check_mesh("full-cylinder", fm, loops, false, size);
  EXPECT_NEAR(r.uv_area, 2 * kPi * H, 1e-9);
  EXPECT_NEAR(r.area3d, 2 * kPi * 10 * H, 2 * kPi * 10 * H * 0.02);
  expect_quality(r);
}

TEST(Delaunay, SphereWithPoles) {
  const double R = 5, h = 0.6;
  const Sphere sph(R, kProjection);
  const Vec3 south{0, 0, -R}, north{0, 0, R};
  BoundaryLoop loop;
  const int nm = segs(kPi * R, h);
  add_side(loop, sph, {0, -kPi / 2}, {2 * kPi, -kPi / 2}, 1, 0, true, south);  // south pole
  add_side(loop, sph, {2 * kPi, -kPi / 2}, {2 * kPi, kPi / 2}, nm, 1);         // seam up
  add_side(loop, sph, {2 * kPi, kPi / 2}, {0, kPi / 2}, 1, 2, true, north);    // north pole
  add_side(loop, sph, {0, kPi / 2}, {0, -kPi / 2}, nm, 1);                     // seam down
  loop.points[nm + 2].xyz = north;  // the degenerate segments' ends are the poles exactly
  loop.points[1].xyz = south;
  std::vector<BoundaryLoop> loops{loop};
  SizeFunction size = [&](const Vec2&, const Vec3&) { return h; };
  TriangulateStats stats;
  const FaceMesh fm = triangulate_face(sph, false, loops, size, {}, &stats);
  // Triangles at a merged pole carry the corner's (u, v) and may be inverted in (u, v); they are
  // checked in 3D below.
  std::set<LO> poles;
  for (LO v = 0; v < fm.num_vertices(); ++v)
    if (distance(fm.points[v], south) < 1e-12 || distance(fm.points[v], north) < 1e-12)
      poles.insert(v);
  const Report r = check_mesh("sphere", fm, loops, false, size, poles);
  EXPECT_NEAR(r.area3d, 4 * kPi * R * R, 4 * kPi * R * R * 0.02);
  expect_quality(r, 0.97, 0.95);
  // One vertex at each pole; fans around them.
  for (const Vec3& pole : {south, north}) {
    int at_pole = 0;
    LO pv = kNoIndex;
    for (LO v = 0; v < fm.num_vertices(); ++v)
      if (distance(fm.points[v], pole) < 1e-12) {
        ++at_pole;
        pv = v;
      }
    EXPECT_EQ(at_pole, 1);
    int fan = 0;
    for (const auto& t : fm.triangles) fan += (t[0] == pv || t[1] == pv || t[2] == pv);
    EXPECT_GE(fan, 3);
    std::printf("   pole fan: %d triangles\n", fan);
  }
  // 3D orientation: outward normals.
  int inward = 0;
  for (const auto& t : fm.triangles) {
    const Vec3 n = cross(fm.points[t[1]] - fm.points[t[0]], fm.points[t[2]] - fm.points[t[0]]);
    inward += dot(n, fm.points[t[0]] + fm.points[t[1]] + fm.points[t[2]]) <= 0;
  }
  EXPECT_EQ(inward, 0);
}

TEST(Delaunay, GradedSize) {
  const Plane plane(kProjection);
  SizeFunction size = [](const Vec2& uv, const Vec3&) { return 0.1 + 0.08 * uv.u; };
  // Boundary sampled with the same size (graded along the bottom/top sides).
  BoundaryLoop loop;
  auto graded = [&](Vec2 a, Vec2 b, LO curve) {
    std::vector<Vec2> pts{a};
    const Vec2 d = b - a;
    const double len = norm(d);
    double s = 0;
    while (true) {
      const Vec2 p = a + d * (s / len);
      s += size(p, {});
      if (s > len - 0.5 * size(b, {})) break;
      pts.push_back(a + d * (s / len));
    }
    for (std::size_t k = 0; k < pts.size(); ++k) {
      BoundaryPoint bp;
      bp.uv = pts[k];
      bp.xyz = {pts[k].u, pts[k].v, 0};
      bp.vclass.dim = k == 0 ? 0 : 1;
      bp.vclass.entity = curve;
      loop.points.push_back(bp);
      loop.degenerate.push_back(0);
    }
  };
  graded({0, 0}, {10, 0}, 0);
  graded({10, 0}, {10, 4}, 1);
  graded({10, 4}, {0, 4}, 2);
  graded({0, 4}, {0, 0}, 3);
  std::vector<BoundaryLoop> loops{loop};
  const FaceMesh fm = triangulate_face(plane, false, loops, size);
  const Report r = check_mesh("graded", fm, loops, false, size);
  EXPECT_NEAR(r.uv_area, 40, 1e-9);
  expect_quality(r);
  // Triangles near u = 0 are much smaller than near u = 10.
  double small = 0, large = 0;
  int ns = 0, nl = 0;
  for (const auto& t : fm.triangles) {
    const Vec2 c = (fm.uv[t[0]] + fm.uv[t[1]] + fm.uv[t[2]]) / 3.0;
    const double a = 0.5 * std::fabs(orient2d(fm.uv[t[0]], fm.uv[t[1]], fm.uv[t[2]]));
    if (c.u < 1) {
      small += a;
      ++ns;
    }
    if (c.u > 9) {
      large += a;
      ++nl;
    }
  }
  ASSERT_GT(ns, 0);
  ASSERT_GT(nl, 0);
  EXPECT_GT((large / nl) / (small / ns), 20.0);
}

TEST(Delaunay, Deterministic) {
  const Cylinder cyl(10, kProjection);
  const double h = 0.9;
  // Sides sampled by their 3D length (u is an angle on a radius-10 cylinder).
  auto loop_of = [&](const std::vector<Vec2>& corners) {
    BoundaryLoop loop;
    for (std::size_t i = 0; i < corners.size(); ++i) {
      const Vec2 a = corners[i], b = corners[(i + 1) % corners.size()];
      const double len = std::hypot(10 * (b.u - a.u), b.v - a.v);
      add_side(loop, cyl, a, b, segs(len, h), static_cast<LO>(i));
    }
    return loop;
  };
  std::vector<BoundaryLoop> loops{loop_of({{0, 0}, {1.5, 0}, {1.5, 8}, {0, 8}}),
                                  loop_of({{0.5, 3}, {0.7, 5}, {0.9, 3}})};
  SizeFunction size = [&](const Vec2& uv, const Vec3&) { return h * (1 + 0.3 * std::sin(uv.v)); };
  const FaceMesh a = triangulate_face(cyl, false, loops, size);
  const FaceMesh b = triangulate_face(cyl, false, loops, size);
  ASSERT_EQ(a.points.size(), b.points.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  EXPECT_TRUE(a.uv == b.uv);
  EXPECT_TRUE(a.triangles == b.triangles);
  check_mesh("deterministic-cyl-hole", a, loops, false, size);
}

TEST(Delaunay, RejectsSelfIntersectingLoop) {
  const Plane plane(kProjection);
  std::vector<BoundaryLoop> loops{polygon(plane, {{0, 0}, {4, 4}, {4, 0}, {0, 4}}, 0.5)};
  SizeFunction size = [](const Vec2&, const Vec3&) { return 0.5; };
  EXPECT_THROW((void)triangulate_face(plane, false, loops, size), Error);
}

TEST(Delaunay, MaxPointsGuard) {
  const Plane plane(kProjection);
  std::vector<BoundaryLoop> loops{polygon(plane, {{0, 0}, {10, 0}, {10, 10}, {0, 10}}, 1.0)};
  SizeFunction size = [](const Vec2&, const Vec3&) { return 0.05; };
  TriangulateOptions opt;
  opt.max_points = 100;
  TriangulateStats stats;
  const FaceMesh fm = triangulate_face(plane, false, loops, size, opt, &stats);
  EXPECT_LE(stats.inserted, 100);
  EXPECT_EQ(fm.num_vertices(), static_cast<LO>(loops[0].points.size() + stats.inserted));
}

TEST(Delaunay, LargePlanePerformance) {
  const Plane plane(kProjection);
  const double h = 0.0465;
  std::vector<BoundaryLoop> loops{polygon(plane, {{0, 0}, {10, 0}, {10, 10}, {0, 10}}, h)};
  SizeFunction size = [&](const Vec2&, const Vec3&) { return h; };
  const auto t0 = std::chrono::steady_clock::now();
  const FaceMesh fm = triangulate_face(plane, false, loops, size);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("   large plane: %zu triangles in %.3f s = %.0f triangles/s\n", fm.triangles.size(),
              s, fm.triangles.size() / s);
  EXPECT_GT(fm.triangles.size(), 90000U);
  const Report r = check_mesh("large-plane", fm, loops, false, size);
  EXPECT_NEAR(r.uv_area, 100, 1e-8);
  expect_quality(r);
}

}  // namespace

namespace {
using namespace qsmesh;
using namespace qsmesh::mesh;

// Very anisotropic parametrisation (u in radians on a 1000 mm radius) and a boundary sampled
// much finer, or much coarser, than the size: valid output, no runaway refinement.
TEST(Delaunay, AnisotropicAndMismatchedBoundary) {
  const Cylinder cyl(1000, kProjection);
  for (const double bh : {0.1, 3.0}) {
    const double h = 1.0;
    BoundaryLoop loop;
    add_side(loop, cyl, {0, 0}, {0.02, 0}, segs(20, bh), 0);
    add_side(loop, cyl, {0.02, 0}, {0.02, 10}, segs(10, bh), 1);
    add_side(loop, cyl, {0.02, 10}, {0, 10}, segs(20, bh), 2);
    add_side(loop, cyl, {0, 10}, {0, 0}, segs(10, bh), 3);
    std::vector<BoundaryLoop> loops{loop};
    SizeFunction size = [&](const Vec2&, const Vec3&) { return h; };
    TriangulateStats stats;
    const FaceMesh fm = triangulate_face(cyl, false, loops, size, {}, &stats);
    const Report r = check_mesh(bh < 1 ? "aniso-fine-boundary" : "aniso-coarse-boundary", fm, loops,
                                false, size);
    EXPECT_NEAR(r.uv_area, 0.2, 1e-12);
    EXPECT_NEAR(r.area3d, 200, 2);
    EXPECT_LT(stats.inserted, 2000);
    std::printf("   inserted %lld rejected %lld\n", static_cast<long long>(stats.inserted),
                static_cast<long long>(stats.rejected));
  }
}
}  // namespace

// Flat boundary triangles: three boundary vertices (corner or curve) and a (u, v) area below
// the ratio times the squared longest edge; a triangle with an interior vertex never counts.
TEST(Delaunay, FlatBoundaryTriangleIsDetected) {
  FaceMesh m;
  const auto add = [&](Vec2 uv, int dim) {
    m.uv.push_back(uv);
    m.points.push_back({uv.u, uv.v, 0});
    VertexClass c;
    c.dim = static_cast<std::uint8_t>(dim);
    m.vclass.push_back(c);
  };
  add({0, 0}, 0);      // 0: corner
  add({1, 0.001}, 1);  // 1: curve vertex, 0.001 off the chord 0-2
  add({2, 0}, 1);      // 2: curve vertex
  add({1, 1}, 2);      // 3: interior
  add({1, 0.5}, 1);    // 4: curve vertex of another curve, well off the chord
  m.triangles = {{0, 2, 3}};
  EXPECT_FALSE(has_flat_boundary_triangle(m));
  m.triangles.push_back({0, 2, 4});  // boundary-only but not flat (area 0.5, longest 2)
  EXPECT_FALSE(has_flat_boundary_triangle(m));
  m.triangles.push_back({0, 2, 1});  // flat: area 0.001 < 1e-3 * 4
  EXPECT_TRUE(has_flat_boundary_triangle(m));
  EXPECT_FALSE(has_flat_boundary_triangle(m, 1e-4));
  m.triangles = {{0, 1, 3}};  // flat enough but with an interior vertex
  m.uv[3] = {0.5, 0.0005};
  EXPECT_FALSE(has_flat_boundary_triangle(m));
}

// A strip of a cylinder of radius 10, 30 long around it and 0.8 wide along its axis: (u, v) =
// (angle, axial position) make it 6 spacings wide in the parameter plane against 0.6 in 3D.
// Triangulated in parameters scaled by the boundary's mean speeds (10 and 1), it is valid and
// maps back to the face's own (u, v), with the boundary points first and in order.
TEST(Delaunay, ScaledParametersMapBack) {
  const Cylinder cyl(10, kProjection);
  BoundaryLoop loop;
  add_side(loop, cyl, {0, 0}, {3, 0}, 23, 0);
  add_side(loop, cyl, {3, 0}, {3, 0.8}, 1, 1);
  add_side(loop, cyl, {3, 0.8}, {0, 0.8}, 23, 2);
  add_side(loop, cyl, {0, 0.8}, {0, 0}, 1, 3);
  const std::vector<BoundaryLoop> loops{loop};
  const SizeFunction size = [](const Vec2&, const Vec3&) { return 1.3; };
  const Vec2 speeds = mean_boundary_speeds(cyl, loops);
  EXPECT_NEAR(speeds.u, 10.0, 1e-9);
  EXPECT_NEAR(speeds.v, 1.0, 1e-9);
  const FaceMesh fm = triangulate_face_scaled(cyl, false, loops, size, {}, speeds);
  const Report r = check_mesh("cylinder-strip-scaled", fm, loops, false, size);
  EXPECT_NEAR(r.uv_area, 2.4, 1e-9);
  EXPECT_FALSE(has_flat_boundary_triangle(fm));
  for (std::size_t i = 0; i < loop.points.size(); ++i)
    EXPECT_LT(norm(fm.uv[i] - loop.points[i].uv), 1e-12);
  for (std::size_t v = 0; v < fm.points.size(); ++v) {
    EXPECT_LT(distance(fm.points[v], cyl.eval(fm.uv[v]).p), 1e-9);
    if (fm.vclass[v].dim == 2) {
      EXPECT_EQ(fm.vclass[v].param[0], fm.uv[v].u);
    }
  }
}

TEST(Delaunay, UnitScaleIsTheSameTriangulation) {
  const Cylinder cyl(10, kProjection);
  const double h = 0.8;
  const std::vector<BoundaryLoop> loops{cylinder_patch(cyl, h)};
  const SizeFunction size = [&](const Vec2&, const Vec3&) { return h; };
  const FaceMesh a = triangulate_face(cyl, false, loops, size);
  const FaceMesh b = triangulate_face_scaled(cyl, false, loops, size, {}, {1, 1});
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.uv, b.uv);
  EXPECT_THROW((void)triangulate_face_scaled(cyl, false, loops, size, {}, {0, 1}), Error);
}
