#include "qsmesh/background/face_mesh.hpp"

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

mesh::FaceMesh mesh_face_background(const cad::CadModel& model, LO f,
                                    std::span<const mesh::CurveMesh> curves,
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
    const auto loops = face_boundary(model, f, *surface, curves);
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

}  // namespace qsmesh::background
