#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepTools.hxx>
#include <TopoDS_Face.hxx>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <gp_Ax3.hxx>
#include <gp_Cylinder.hxx>
#include <gp_Pln.hxx>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <string>

#include "face_case.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/smooth/quad_tools.hpp"
#include "qsmesh/smooth/smooth.hpp"
#include "shapes.hpp"

namespace qsmesh::smooth {
namespace {

using test::load_face;
using test::tmp_path;
using test::write_face;
using Case = test::FaceCase;

// mesh::quad_corners computes each corner's terms once for the SICN and the area vector; the
// smoother, the untangler and oriented_sicn take both from it. The values must be those of the
// formula evaluated term by term as before (Eq. 12 per corner, the area vector from the edge
// cross products), bit for bit, or the meshes would change: quads of every shape, folded and
// degenerate ones included.
double reference_sicn(const std::array<Vec3, 4>& q) {
  std::array<Vec3, 4> n{};
  Vec3 sum{};
  for (int i = 0; i < 4; ++i) {
    n[i] = cross(q[(i + 1) % 4] - q[i], q[(i + 3) % 4] - q[i]);
    sum += n[i];
  }
  const double ns = norm(sum);
  if (!(ns > 0)) return -1.0;
  const Vec3 normal = sum / ns;
  double worst = std::numeric_limits<double>::max();
  for (int i = 0; i < 4; ++i) {
    const Vec3 prev = q[(i + 3) % 4] - q[i];
    const Vec3 next = q[(i + 1) % 4] - q[i];
    const double denom = norm2(prev) + norm2(next);
    worst = std::min(worst, denom > 0 ? 2.0 * dot(n[i], normal) / denom : -1.0);
  }
  return worst;
}
double reference_oriented_sicn(const std::array<Vec3, 4>& x, const Vec3& normal, double sign) {
  Vec3 sum{};
  for (int k = 0; k < 4; ++k) sum += cross(x[k] - x[(k + 3) % 4], x[(k + 1) % 4] - x[k]);
  if (norm2(normal) > 0 && sign * dot(sum, normal) <= 0) return -1.0;
  return reference_sicn(x);
}
std::uint64_t bits(double d) { return std::bit_cast<std::uint64_t>(d); }

TEST(Smooth, OrientedSicnIsQuadSicnBitForBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-1.0, 1.0);
  const Vec3 up{0, 0, 1}, tilted = normalized(Vec3{0.3, -0.2, 1});
  int flipped = 0, valid = 0;
  for (int t = 0; t < 20000; ++t) {
    std::array<Vec3, 4> q;
    // A unit square jittered by up to `jitter`: near-squares, skewed, folded and twisted quads.
    const double jitter = t % 4 == 0 ? 1e-3 : (t % 4 == 1 ? 0.3 : 1.5);
    const std::array<Vec3, 4> square{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{1, 1, 0}, Vec3{0, 1, 0}};
    for (int k = 0; k < 4; ++k)
      q[k] = square[k] * 1e3 + Vec3{coord(rng), coord(rng), 0.2 * coord(rng)} * (1e3 * jitter);
    if (t % 97 == 0) q[2] = q[1];  // a degenerate edge
    if (t % 89 == 0) q = {q[0], q[0], q[0], q[0]};
    const double s = mesh::quad_sicn(q);
    ASSERT_EQ(bits(s), bits(reference_sicn(q))) << t;
    ASSERT_EQ(bits(mesh::quad_sicn_from(mesh::quad_corners(q))), bits(s)) << t;
    for (const Vec3& n : {up, tilted, Vec3{0, 0, 0}})
      for (const double sign : {1.0, -1.0}) {
        const double o = oriented_sicn(q, n, sign);
        ASSERT_EQ(bits(o), bits(reference_oriented_sicn(q, n, sign))) << t;
        flipped += o == -1.0 && s != -1.0 ? 1 : 0;
      }
    valid += s > 0 ? 1 : 0;
  }
  EXPECT_GT(flipped, 1000);
  EXPECT_GT(valid, 5000);
}

// 10 x 6 plate in the z = 0 plane, u = x, v = y.
std::string write_plate() {
  return write_face(
      BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 0.0, 10.0, 0.0, 6.0).Face(),
      "smooth_plate.brep");
}
// Quarter of a cylinder side of radius 2, height 3: no seam inside.
std::string write_cylinder_patch() {
  return write_face(
      BRepBuilderAPI_MakeFace(gp_Cylinder(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2.0), 0.0,
                              std::numbers::pi / 2, 0.0, 3.0)
          .Face(),
      "smooth_cyl_patch.brep");
}

// Deterministic pseudo-random numbers in [-1, 1] (no library distribution: portable).
struct Lcg {
  std::uint64_t s;
  double next() {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(s >> 11) / static_cast<double>(1ULL << 53) * 2.0 - 1.0;
  }
};

// Structured nu x nv grid of quads over the uv box; interior uv perturbed by `amp` cell sizes.
// seam_u: the sides u = lo and u = hi are the two images of one seam curve.
mesh::FaceMesh grid(const cad::FaceGeometry& g, Box2 box, int nu, int nv, double amp,
                    std::uint64_t seed, bool seam_u = false) {
  mesh::FaceMesh m;
  m.face = 0;
  Lcg rng{seed};
  const double hu = (box.hi.u - box.lo.u) / nu, hv = (box.hi.v - box.lo.v) / nv;
  auto id = [&](int i, int j) { return static_cast<LO>(j * (nu + 1) + i); };
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      Vec2 uv{box.lo.u + i * hu, box.lo.v + j * hv};
      mesh::VertexClass c;
      const bool bi = i == 0 || i == nu, bj = j == 0 || j == nv;
      if (bi && bj) {
        c.dim = 0;
        c.entity =
            (seam_u && i == nu) ? LO(j == 0 ? 0 : 2) : LO((j == 0 ? 0 : 2) + (i == 0 ? 0 : 1));
      } else if (bi || bj) {
        c.dim = 1;
        if (bj) {
          c.entity = j == 0 ? 0 : 2;
          c.index = i;
        } else {
          c.entity = (seam_u || i == 0) ? 3 : 1;
          c.index = j;
        }
      } else {
        uv.u += amp * hu * rng.next();
        uv.v += amp * hv * rng.next();
        c.param = {uv.u, uv.v};
      }
      m.uv.push_back(uv);
      m.points.push_back(g.eval(uv).p);
      m.vclass.push_back(c);
    }
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i)
      m.quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  return m;
}

// Each grid cell split into two triangles, each triangle into three quads (centroid + edge
// midpoints): interior vertices of valence 3, 4 and 6. Interior uv perturbed by `amp` cell sizes.
mesh::FaceMesh split_triangles(const cad::FaceGeometry& g, Box2 box, int nu, int nv, double amp,
                               std::uint64_t seed) {
  mesh::FaceMesh m;
  Lcg rng{seed};
  const double hu = (box.hi.u - box.lo.u) / nu, hv = (box.hi.v - box.lo.v) / nv;
  auto on_boundary = [&](const Vec2& uv) {
    const double e = 1e-9 * (hu + hv);
    return std::abs(uv.u - box.lo.u) < e || std::abs(uv.u - box.hi.u) < e ||
           std::abs(uv.v - box.lo.v) < e || std::abs(uv.v - box.hi.v) < e;
  };
  std::map<std::pair<long, long>, LO> index;  // key: uv in half-steps
  auto vertex = [&](long a, long b) {         // at uv = lo + (a hu, b hv) / 6
    const auto [it, inserted] = index.emplace(std::make_pair(a, b), static_cast<LO>(m.uv.size()));
    if (inserted) {
      const Vec2 uv{box.lo.u + a * hu / 6.0, box.lo.v + b * hv / 6.0};
      mesh::VertexClass c;
      if (on_boundary(uv)) {
        c.dim = 1;
        c.entity = 0;
        c.index = static_cast<LO>(m.uv.size());
      }
      m.uv.push_back(uv);
      m.vclass.push_back(c);
    }
    return it->second;
  };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const std::array<std::pair<long, long>, 4> c{
          {{6L * i, 6L * j}, {6L * i + 6, 6L * j}, {6L * i + 6, 6L * j + 6}, {6L * i, 6L * j + 6}}};
      for (const auto& t : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
        const auto& a = c[t[0]];
        const auto& b = c[t[1]];
        const auto& d = c[t[2]];
        const LO va = vertex(a.first, a.second), vb = vertex(b.first, b.second),
                 vd = vertex(d.first, d.second);
        const LO mab = vertex((a.first + b.first) / 2, (a.second + b.second) / 2);
        const LO mbd = vertex((b.first + d.first) / 2, (b.second + d.second) / 2);
        const LO mda = vertex((d.first + a.first) / 2, (d.second + a.second) / 2);
        const LO g0 =
            vertex((a.first + b.first + d.first) / 3, (a.second + b.second + d.second) / 3);
        m.quads.push_back({va, mab, g0, mda});
        m.quads.push_back({vb, mbd, g0, mab});
        m.quads.push_back({vd, mda, g0, mbd});
      }
    }
  for (std::size_t v = 0; v < m.uv.size(); ++v) {
    if (m.vclass[v].dim == 2) {
      m.uv[v].u += amp * hu / 6.0 * rng.next();
      m.uv[v].v += amp * hv / 6.0 * rng.next();
      m.vclass[v].param = {m.uv[v].u, m.uv[v].v};
    }
    m.points.push_back(g.eval(m.uv[v]).p);
  }
  return m;
}

void expect_boundary_locked_and_on_surface(const mesh::FaceMesh& in, const mesh::FaceMesh& out,
                                           const cad::FaceGeometry& g, double size) {
  test::expect_locked_and_on_surface(in, out, g, size, /*check_params=*/false);
}

TEST(Smooth, MeasureOfSquaresIsOne) {
  const Case c = load_face(write_plate(), cad::SurfaceType::Plane);
  const auto m = grid(*c.geometry, c.model.faces()[c.face].uv_box, 10, 6, 0.0, 1);
  const QualityReport r = measure(m);
  EXPECT_NEAR(r.sicn_min, 1.0, 1e-12);
  EXPECT_NEAR(r.sicn_avg, 1.0, 1e-12);
  EXPECT_EQ(r.invalid, 0);
}

TEST(Smooth, PerturbedPlateGridBecomesRegular) {
  const Case c = load_face(write_plate(), cad::SurfaceType::Plane);
  const auto in = grid(*c.geometry, c.model.faces()[c.face].uv_box, 20, 12, 0.35, 7);
  SmoothStats st;
  const auto out = smooth_face(in, *c.geometry, SmoothOptions{}, &st);
  std::printf("plate: before min %.4f avg %.4f, after min %.4f avg %.4f, %s, %d it\n",
              st.before.sicn_min, st.before.sicn_avg, st.after.sicn_min, st.after.sicn_avg,
              st.method.c_str(), st.iterations);
  EXPECT_LT(st.before.sicn_avg, 0.9);
  EXPECT_GE(st.after.sicn_avg, 0.95);
  EXPECT_GT(st.after.sicn_min, st.before.sicn_min);
  EXPECT_FALSE(st.rolled_back);
  EXPECT_EQ(st.method.rfind("uv_laplacian+", 0), 0u) << st.method;
  expect_boundary_locked_and_on_surface(in, out, *c.geometry, c.model.diagonal());
  const auto r = measure(out);
  EXPECT_EQ(r.sicn_min, st.after.sicn_min);
}

TEST(Smooth, KernelsAloneImprovePlateGrid) {
  const Case c = load_face(write_plate(), cad::SurfaceType::Plane);
  const auto in = grid(*c.geometry, c.model.faces()[c.face].uv_box, 20, 12, 0.35, 11);
  SmoothOptions o;
  o.laplacian_uv = false;
  o.iterations = 30;
  SmoothStats st;
  const auto out = smooth_face(in, *c.geometry, o, &st);
  std::printf("plate kernels only: before min %.4f avg %.4f, after min %.4f avg %.4f, %d it\n",
              st.before.sicn_min, st.before.sicn_avg, st.after.sicn_min, st.after.sicn_avg,
              st.iterations);
  EXPECT_EQ(st.method, "kernels");
  EXPECT_GE(st.after.sicn_avg, 0.95);
  EXPECT_GT(st.after.sicn_min, st.before.sicn_min);
  expect_boundary_locked_and_on_surface(in, out, *c.geometry, c.model.diagonal());
}

TEST(Smooth, PerturbedCylinderPatchBecomesRegular) {
  const Case c = load_face(write_cylinder_patch(), cad::SurfaceType::Cylinder);
  const auto in = grid(*c.geometry, c.model.faces()[c.face].uv_box, 12, 12, 0.35, 3);
  SmoothStats st;
  const auto out = smooth_face(in, *c.geometry, SmoothOptions{}, &st);
  std::printf("cylinder patch: before min %.4f avg %.4f, after min %.4f avg %.4f, %s\n",
              st.before.sicn_min, st.before.sicn_avg, st.after.sicn_min, st.after.sicn_avg,
              st.method.c_str());
  EXPECT_LT(st.before.sicn_avg, 0.9);
  EXPECT_GE(st.after.sicn_avg, 0.95);
  EXPECT_GT(st.after.sicn_min, st.before.sicn_min);
  EXPECT_EQ(st.method.rfind("uv_laplacian+", 0), 0u) << st.method;
  expect_boundary_locked_and_on_surface(in, out, *c.geometry, c.model.diagonal());
  for (const auto& p : out.points) EXPECT_NEAR(std::hypot(p.x, p.y), 2.0, 1e-9);
}

TEST(Smooth, SeamSkipsUvLaplacianButKernelsImprove) {
  const Case c =
      load_face(test::write_cylinder(tmp_path("smooth_cyl.brep")), cad::SurfaceType::Cylinder);
  Box2 box = c.model.faces()[c.face].uv_box;
  ASSERT_TRUE(c.model.faces()[c.face].u_periodic);
  const auto in = grid(*c.geometry, box, 24, 10, 0.35, 5, /*seam_u=*/true);
  SmoothOptions o;
  o.iterations = 30;
  SmoothStats st;
  const auto out = smooth_face(in, *c.geometry, o, &st);
  std::printf("cylinder with seam: before min %.4f avg %.4f, after min %.4f avg %.4f, %s, %d it\n",
              st.before.sicn_min, st.before.sicn_avg, st.after.sicn_min, st.after.sicn_avg,
              st.method.c_str(), st.iterations);
  EXPECT_EQ(st.method, "uv_laplacian(skipped:seam)+kernels");
  EXPECT_GT(st.after.sicn_avg, st.before.sicn_avg + 0.05);
  EXPECT_GT(st.after.sicn_min, st.before.sicn_min);
  EXPECT_GE(st.after.sicn_avg, 0.9);
  expect_boundary_locked_and_on_surface(in, out, *c.geometry, c.model.diagonal());
}

TEST(Smooth, IrregularVerticesUseAngleKernel) {
  const Case c = load_face(write_plate(), cad::SurfaceType::Plane);
  const auto in = split_triangles(*c.geometry, c.model.faces()[c.face].uv_box, 6, 4, 0.8, 13);
  for (const bool lap : {false, true}) {
    SmoothOptions o;
    o.laplacian_uv = lap;
    o.iterations = 20;
    SmoothStats st;
    const auto out = smooth_face(in, *c.geometry, o, &st);
    std::printf("split triangles (%s): before min %.4f avg %.4f, after min %.4f avg %.4f, %d it\n",
                st.method.c_str(), st.before.sicn_min, st.before.sicn_avg, st.after.sicn_min,
                st.after.sicn_avg, st.iterations);
    EXPECT_GT(st.after.sicn_min, st.before.sicn_min);
    EXPECT_GT(st.after.sicn_avg, st.before.sicn_avg);
    EXPECT_EQ(st.after.invalid, 0);
    expect_boundary_locked_and_on_surface(in, out, *c.geometry, c.model.diagonal());
  }
}

// A 5-degree wedge on the plate, tip at (1, 3), axis along +x: one quad holds the tip (c, a1, x,
// b1), rungs across the wedge at r = 0.4, 0.5, 0.62, 0.77 from the tip, their middles inner
// vertices (the last one locked). The tip quad's inner vertex x starts at r = 0.55, ahead of the
// second rung's middle: the quads behind the first rung get a sharp angle there. The tip quad's
// minimum is its 5-degree corner whatever x does, so only the cusp rule moves x back: just past
// the first rung, where the quads behind it are near rectangles.
TEST(Smooth, CuspQuadInnerVertexSitsJustPastTheFirstRung) {
  const Case c = load_face(write_plate(), cad::SurfaceType::Plane);
  const double t = std::tan(2.5 * std::numbers::pi / 180);
  const std::array<double, 4> r{0.4, 0.5, 0.62, 0.77};
  mesh::FaceMesh m;
  m.face = 0;
  auto add = [&](double x, double y, int dim, LO entity, LO index) {
    mesh::VertexClass vc;
    vc.dim = dim;
    vc.entity = entity;
    vc.index = index;
    if (dim == 2) vc.param = {x, y};
    m.uv.push_back({x, y});
    m.points.push_back(c.geometry->eval({x, y}).p);
    m.vclass.push_back(vc);
    return static_cast<LO>(m.uv.size()) - 1;
  };
  const LO tip = add(1, 3, 0, 0, 0);
  std::array<LO, 4> a{}, b{}, mid{};
  for (int i = 0; i < 4; ++i) {
    a[i] = add(1 + r[i], 3 - r[i] * t, 1, 0, i + 1);
    b[i] = add(1 + r[i], 3 + r[i] * t, 1, 1, i + 1);
    if (i > 0) mid[i] = i == 3 ? add(1 + r[i], 3, 1, 2, 1) : add(1 + r[i], 3, 2, 0, 0);
  }
  const LO x = add(1.55, 3, 2, 0, 0);
  m.quads.push_back({tip, a[0], x, b[0]});
  m.quads.push_back({a[0], a[1], mid[1], x});
  m.quads.push_back({x, mid[1], b[1], b[0]});
  for (int i = 1; i < 3; ++i) {
    m.quads.push_back({a[i], a[i + 1], mid[i + 1], mid[i]});
    m.quads.push_back({mid[i], mid[i + 1], b[i + 1], b[i]});
  }
  const auto out = smooth_face(m, *c.geometry, SmoothOptions{});
  double away = 1;
  for (std::size_t q = 1; q < out.quads.size(); ++q) {
    const auto& v = out.quads[q];
    away = std::min(away, mesh::quad_sicn({out.points[v[0]], out.points[v[1]], out.points[v[2]],
                                           out.points[v[3]]}));
  }
  std::printf("cusp quad: inner vertex at r = %.4f (first rung 0.4), SICN min of the others %.4f\n",
              out.uv[x].u - 1, away);
  EXPECT_GE(out.uv[x].u, 1 + r[0]);
  EXPECT_LE(out.uv[x].u, 1 + r[0] + r[0] * t);  // within half the rung past it
  EXPECT_NEAR(out.uv[x].v, 3, 1e-9);
  EXPECT_GE(away, 0.3);
  expect_boundary_locked_and_on_surface(m, out, *c.geometry, c.model.diagonal());
}

TEST(Smooth, OptimalGridIsNotMadeWorse) {
  const Case c = load_face(write_plate(), cad::SurfaceType::Plane);
  const auto in = grid(*c.geometry, c.model.faces()[c.face].uv_box, 10, 6, 0.0, 1);
  SmoothStats st;
  const auto out = smooth_face(in, *c.geometry, SmoothOptions{}, &st);
  std::printf("optimal grid: before min %.17g, after min %.17g, %s, rolled back %d\n",
              st.before.sicn_min, st.after.sicn_min, st.method.c_str(), int(st.rolled_back));
  EXPECT_GE(st.after.sicn_min, st.before.sicn_min);
  EXPECT_GE(measure(out).sicn_min, measure(in).sicn_min);
  for (std::size_t v = 0; v < in.points.size(); ++v)
    EXPECT_LT(distance(in.points[v], out.points[v]), 1e-12);
  if (st.rolled_back) {
    for (std::size_t v = 0; v < in.points.size(); ++v) EXPECT_TRUE(in.points[v] == out.points[v]);
  }
}

TEST(Smooth, InvertedInputIsUntangledOrRolledBack) {
  // One interior vertex thrown outside its cell: quads around it are folded. The result is never
  // worse than the input, and here it is valid.
  const Case c = load_face(write_plate(), cad::SurfaceType::Plane);
  auto in = grid(*c.geometry, c.model.faces()[c.face].uv_box, 10, 6, 0.0, 1);
  const LO v = 3 * 11 + 5;
  in.uv[v] = in.uv[v] + Vec2{2.5, 0.3};
  in.points[v] = c.geometry->eval(in.uv[v]).p;
  SmoothOptions o;
  o.laplacian_uv = false;
  SmoothStats st;
  const auto out = smooth_face(in, *c.geometry, o, &st);
  EXPECT_GT(st.before.invalid, 0);
  EXPECT_GE(st.after.sicn_min, st.before.sicn_min);
  EXPECT_LE(st.after.invalid, st.before.invalid);
  o.laplacian_uv = true;
  const auto out2 = smooth_face(in, *c.geometry, o, &st);
  EXPECT_EQ(st.after.invalid, 0);
  EXPECT_GT(st.after.sicn_min, 0.99);
}

// SmoothOptions::after_pass sees every pass and can stop them; a hook that lets every pass run
// leaves the result bit for bit as without it.
TEST(Smooth, AfterPassSeesEachPassAndCanStopThem) {
  const Case c = load_face(write_cylinder_patch(), cad::SurfaceType::Cylinder);
  const auto in = split_triangles(*c.geometry, c.model.faces()[c.face].uv_box, 5, 5, 0.8, 17);
  SmoothOptions plain;
  plain.laplacian_uv = false;  // the kernels alone: several passes before they settle
  plain.iterations = 6;
  SmoothStats sp;
  const auto a = smooth_face(in, *c.geometry, plain, &sp);
  ASSERT_GE(sp.iterations, 3);
  std::vector<int> seen;
  SmoothOptions watched = plain;
  watched.after_pass = [&](int pass, const mesh::FaceMesh&) {
    seen.push_back(pass);
    return true;
  };
  SmoothStats sw;
  const auto b = smooth_face(in, *c.geometry, watched, &sw);
  EXPECT_FALSE(sw.stopped_early);
  ASSERT_EQ(static_cast<int>(seen.size()), sp.iterations);
  for (std::size_t k = 0; k < seen.size(); ++k) EXPECT_EQ(seen[k], static_cast<int>(k) + 1);
  for (std::size_t v = 0; v < a.points.size(); ++v) {
    EXPECT_TRUE(a.points[v] == b.points[v]);
    EXPECT_TRUE(a.uv[v] == b.uv[v]);
  }
  // Stopped after pass 2: two passes, and what the mesh was then.
  SmoothOptions stopped = plain;
  std::vector<Vec3> at_two;
  stopped.after_pass = [&](int pass, const mesh::FaceMesh& m) {
    if (pass == 2) at_two = m.points;
    return pass < 2;
  };
  SmoothStats ss;
  const auto d = smooth_face(in, *c.geometry, stopped, &ss);
  EXPECT_TRUE(ss.stopped_early);
  EXPECT_EQ(ss.iterations, 2);
  EXPECT_EQ(d.points, at_two);
  EXPECT_FALSE(d.points == a.points);
}

TEST(Smooth, Deterministic) {
  const Case c = load_face(write_cylinder_patch(), cad::SurfaceType::Cylinder);
  const auto in = split_triangles(*c.geometry, c.model.faces()[c.face].uv_box, 5, 5, 0.8, 17);
  for (const bool lap : {false, true}) {
    SmoothOptions o;
    o.laplacian_uv = lap;
    const auto a = smooth_face(in, *c.geometry, o);
    const auto b = smooth_face(in, *c.geometry, o);
    for (std::size_t v = 0; v < a.points.size(); ++v) {
      EXPECT_TRUE(a.points[v] == b.points[v]);
      EXPECT_TRUE(a.uv[v] == b.uv[v]);
    }
  }
}

}  // namespace
}  // namespace qsmesh::smooth
