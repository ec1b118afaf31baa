#include "qsmesh/background/face_mesh.hpp"

#include <array>
#include <cmath>
#include <numbers>

#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"

namespace qsmesh::background {

std::vector<mesh::BoundaryLoop> face_boundary(const cad::CadModel& model, LO f,
                                              const cad::FaceGeometry& surface,
                                              std::span<const mesh::CurveMesh> curves) {
  const cad::Face& face = model.faces()[f];
  std::vector<mesh::BoundaryLoop> loops;
  loops.reserve(face.loops.size());
  for (LO l = 0; l < static_cast<LO>(face.loops.size()); ++l) {
    mesh::BoundaryLoop loop;
    const auto& uses = face.loops[l].uses;
    for (LO u = 0; u < static_cast<LO>(uses.size()); ++u) {
      const cad::CurveUse& use = uses[u];
      const cad::Curve& curve = model.curves()[use.curve];
      const mesh::CurveMesh& cm = curves[use.curve];
      const LO n = cm.num_edges();
      QSMESH_CHECK(n >= 1, "curve " << use.curve << " has no mesh");
      for (LO k = 0; k < n; ++k) {  // the end vertex belongs to the next use
        const LO i = use.reversed ? n - k : k;
        mesh::BoundaryPoint p;
        p.uv = surface.boundary_uv(l, u, cm.t[i]);
        p.xyz = cm.points[i];
        if (i == 0 || i == n) {
          p.vclass.dim = 0;
          p.vclass.entity = curve.corners[i == 0 ? 0 : 1];
          p.vclass.index = kNoIndex;
          p.vclass.param = {0, 0};
        } else {
          p.vclass.dim = 1;
          p.vclass.entity = use.curve;
          p.vclass.index = i;
          p.vclass.param = {cm.t[i], 0};
        }
        loop.points.push_back(p);
        loop.degenerate.push_back(curve.degenerate ? 1 : 0);
      }
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

HalvedBoundary halved_face_boundary(const cad::CadModel& model, LO f,
                                    const cad::FaceGeometry& surface,
                                    std::span<const mesh::CurveMesh> full) {
  const cad::Face& face = model.faces()[f];
  const std::vector<mesh::BoundaryLoop> loops = face_boundary(model, f, surface, full);
  HalvedBoundary out;
  for (LO l = 0; l < static_cast<LO>(loops.size()); ++l) {
    // The full loop with a third copy of each pole on its degenerate curve, as subdivision makes
    // it: one entry per full vertex, with the curve use of the edge leaving it.
    struct Full {
      mesh::BoundaryPoint p;
      LO use = kNoIndex;
      bool degenerate = false;  // the edge leaving this vertex lies on a degenerate curve
      bool pole = false;        // the first image of a pole (a degenerate curve starts here)
    };
    std::vector<Full> F;
    const auto& uses = face.loops[l].uses;
    const auto& pts = loops[l].points;
    std::size_t k = 0;
    for (LO u = 0; u < static_cast<LO>(uses.size()); ++u) {
      const LO n = full[uses[u].curve].num_edges();
      const bool deg = model.curves()[uses[u].curve].degenerate;
      for (LO e = 0; e < n && k < pts.size(); ++e, ++k) {
        F.push_back({pts[k], u, deg, deg && e == 0});
        if (deg) {
          // The copy between the two images; its uv is set once the next image is known.
          F.push_back({pts[k], u, true, false});
          F.back().p.uv = Vec2{std::nan(""), std::nan("")};
        }
      }
    }
    const auto N = static_cast<LO>(F.size());
    for (LO i = 0; i < N; ++i)
      if (std::isnan(F[i].p.uv.u)) F[i].p.uv = 0.5 * (F[i - 1].p.uv + F[(i + 1) % N].p.uv);
    QSMESH_CHECK(N % 2 == 0, "face " << f << ", loop " << l << ": " << N
                                     << " boundary edges; midpoint subdivision needs an even loop");
    // Cost of leaving a corner at a midpoint, for each offset.
    std::array<double, 2> cost{0, 0};
    std::array<bool, 2> allowed{true, true};
    for (LO i = 0; i < N; ++i) {
      if (F[i].p.vclass.dim != 0) continue;
      const int odd_offset = (i % 2 == 0) ? 1 : 0;  // the offset that leaves vertex i a midpoint
      if (F[i].pole || (i > 0 && F[i - 1].degenerate) || (i == 0 && F[N - 1].degenerate)) {
        // A pole image (or the copy between them): its degenerate curve must be one segment.
        if (F[i].pole) allowed[odd_offset] = false;
        continue;
      }
      const Vec3 a = F[(i + N - 1) % N].p.xyz - F[i].p.xyz;
      const Vec3 b = F[(i + 1) % N].p.xyz - F[i].p.xyz;
      const double angle = std::atan2(norm(cross(a, b)), dot(a, b));
      cost[odd_offset] += std::abs(angle / (0.5 * std::numbers::pi) - 2.0);
    }
    QSMESH_CHECK(allowed[0] || allowed[1],
                 "face " << f << ", loop " << l
                         << ": its poles are an odd number of edges apart; midpoint subdivision "
                            "cannot keep every pole on a vertex");
    const int offset = !allowed[0] ? 1 : !allowed[1] ? 0 : (cost[1] < cost[0] ? 1 : 0);
    mesh::BoundaryLoop halved;
    std::vector<HalvedSegment> segments;
    for (LO h = 0; h < N / 2; ++h) {
      const LO i = offset + 2 * h;
      const Full& a = F[i];
      const Full& m = F[(i + 1) % N];
      halved.points.push_back(a.p);
      halved.degenerate.push_back(a.degenerate && m.degenerate ? 1 : 0);
      HalvedSegment s;
      s.mid = m.p;
      s.forward = !uses[m.use].reversed;
      s.curve_before = uses[a.use].curve;
      s.curve_after = uses[m.use].curve;
      segments.push_back(s);
    }
    out.loops.push_back(std::move(halved));
    out.segments.push_back(std::move(segments));
    out.offsets.push_back(offset);
  }
  return out;
}

namespace {

mesh::FaceMesh mesh_face_background_impl(const cad::CadModel& model, LO f,
                                         std::span<const mesh::CurveMesh> curves,
                                         const std::span<const mesh::BoundaryLoop>* given,
                                         const BackgroundOptions& options, FaceReport* report) {
  const Stopwatch clock;
  FaceReport local;
  FaceReport& rep = report != nullptr ? *report : local;
  rep = FaceReport{};
  rep.face = f;
  const ErrorContext context{"background", 2, f};
  mesh::FaceMesh out;
  out.face = f;
  try {
    const auto surface = model.face_geometry(f);
    const std::vector<mesh::BoundaryLoop> loops =
        given != nullptr ? std::vector<mesh::BoundaryLoop>(given->begin(), given->end())
                         : face_boundary(model, f, *surface, curves);
    std::vector<Vec3> bpoints;
    std::vector<double> bsizes;
    for (const auto& loop : loops) {
      const std::size_t n = loop.points.size();
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3& p = loop.points[i].xyz;
        const double prev = distance(loop.points[(i + n - 1) % n].xyz, p);
        const double next = distance(p, loop.points[(i + 1) % n].xyz);
        // Pole points (degenerate curves) have zero-length edges and tell nothing about sizes.
        if (prev <= 0 && next <= 0) continue;
        bpoints.push_back(p);
        bsizes.push_back(prev <= 0 ? next : next <= 0 ? prev : 0.5 * (prev + next));
      }
    }
    const SizeOptions sizes =
        options.sizes.capped(options.sizes.field_cap(model.faces()[f].box.diagonal()));
    const FaceSizeField field(*surface, sizes, std::move(bpoints), std::move(bsizes));
    const mesh::SizeFunction size = [&](const Vec2& uv, const Vec3& xyz) { return field(uv, xyz); };
    const bool reversed = model.faces()[f].reversed;
    try {
      out = mesh::triangulate_face(*surface, reversed, loops, size, options.triangulate);
      // The kernel's flips and moves work in (u, v); around poles and on strongly anisotropic
      // parametrisations some thin triangles are only visible, and fixable, in 3D.
      out = mesh::improve_small_angles(out, *surface, reversed, options.improve);
    } catch (const Error& e) {
      // Refinement is what usually fails on bad geometry; the boundary-only triangulation is still
      // a conforming mesh of the face and keeps the model watertight.
      rep.error = e.with_context(context).what();
      rep.fell_back = true;
      mesh::TriangulateOptions coarse = options.triangulate;
      coarse.max_points = 0;
      out = mesh::triangulate_face(*surface, reversed, loops, size, coarse);
    }
    out.face = f;
    for (auto& vc : out.vclass)
      if (vc.dim == 2) vc.entity = f;
    rep.ok = true;
  } catch (const Error& e) {
    rep.error = e.with_context(context).what();
    rep.ok = false;
    out = mesh::FaceMesh{};
    out.face = f;
  } catch (const std::exception& e) {
    rep.error = Error(e.what(), context).what();
    rep.ok = false;
    out = mesh::FaceMesh{};
    out.face = f;
  }
  rep.seconds = clock.seconds();
  return out;
}

}  // namespace

mesh::FaceMesh mesh_face_background(const cad::CadModel& model, LO f,
                                    std::span<const mesh::CurveMesh> curves,
                                    const BackgroundOptions& options, FaceReport* report) {
  return mesh_face_background_impl(model, f, curves, nullptr, options, report);
}

mesh::FaceMesh mesh_face_background(const cad::CadModel& model, LO f,
                                    std::span<const mesh::BoundaryLoop> loops,
                                    const BackgroundOptions& options, FaceReport* report) {
  return mesh_face_background_impl(model, f, {}, &loops, options, report);
}

}  // namespace qsmesh::background
