#include "qsmesh/quad/unstructured.hpp"

#include <algorithm>
#include <limits>

#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/delaunay.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/quad/subdivide.hpp"
#include "qsmesh/smooth/smooth.hpp"
#include "qsmesh/smooth/untangle.hpp"

namespace qsmesh::quad {

namespace {

double min_sicn(const mesh::FaceMesh& m) {
  double worst = std::numeric_limits<double>::max();
  for (const auto& q : m.quads)
    worst = std::min(
        worst, mesh::quad_sicn({m.points[q[0]], m.points[q[1]], m.points[q[2]], m.points[q[3]]}));
  return m.quads.empty() ? -1.0 : worst;
}

bool valid(const mesh::FaceMesh& m) { return !m.quads.empty() && min_sicn(m) > 0; }

// Geometry optimisation (Sec. 5.3) of one candidate mesh, each step measured and rolled back if it
// hurts; the untangler only where a quad is still invalid.
mesh::FaceMesh optimise(mesh::FaceMesh m, const cad::FaceGeometry& surface) {
  if (m.quads.empty()) return m;
  m = smooth::smooth_face(m, surface, smooth::SmoothOptions{});
  if (min_sicn(m) <= 0) m = smooth::untangle_face(m, surface, smooth::UntangleOptions{});
  return m;
}

// Sec. 5.2-5.3 on a triangulation of the face: recombined (weighted by the cross `directions`, or
// not when empty), subdivided and optimised. When a quad stays invalid, every triangle is
// subdivided instead (that always gives quads; recombination is what may fold one) and the better
// of the two meshes is returned, with `fell_back` set.
mesh::FaceMesh quads_from(const mesh::FaceMesh& tri,
                          std::span<const std::array<Vec3, 2>> directions,
                          const cad::FaceGeometry& surface, std::span<const mesh::CurveMesh> full,
                          const background::HalvedBoundary& halved,
                          const UnstructuredOptions& options, bool& fell_back) {
  const std::map<std::pair<LO, LO>, Vec3> corner_mids = corner_midpoints(tri, halved);
  mesh::FaceMesh out =
      optimise(subdivide(recombine(tri, directions, options.recombine, nullptr, &corner_mids),
                         surface, full, halved),
               surface);
  if (valid(out)) return out;
  fell_back = true;
  mesh::FaceMesh alt = optimise(subdivide(tri, surface, full, halved), surface);
  return out.quads.empty() || min_sicn(alt) > min_sicn(out) ? alt : out;
}

// An edge of the triangulation longer than `ratio` times the spacing at its midpoint (3D).
bool has_long_edge(const mesh::FaceMesh& tri, const mesh::SizeFunction& size, double ratio) {
  for (const auto& t : tri.triangles)
    for (int k = 0; k < 3; ++k) {
      const LO a = t[k], b = t[(k + 1) % 3];
      const Vec3 mid = 0.5 * (tri.points[a] + tri.points[b]);
      if (distance(tri.points[a], tri.points[b]) > ratio * size(0.5 * (tri.uv[a] + tri.uv[b]), mid))
        return true;
    }
  return false;
}

// Sec. 5.1-5.2: frontal points, their triangulation, recombination along the cross, subdivision.
// Returns an empty mesh when neither the recombined nor the plain subdivided triangles are valid.
mesh::FaceMesh frontal_quads(const cad::CadModel& model, LO f, const cad::FaceGeometry& surface,
                             const background::HalvedBoundary& halved,
                             std::span<const mesh::CurveMesh> full, const FaceFields& fields,
                             const UnstructuredOptions& options, UnstructuredReport& rep) {
  const FaceGuide guide(*fields.background, *fields.cross_field, fields.sizes);
  const std::vector<mesh::BoundaryLoop>& loops = halved.loops;
  const std::vector<Vec2> points = frontal_points(surface, loops, guide, options.frontal);
  rep.frontal_points = static_cast<std::int64_t>(points.size());
  const double factor = options.frontal.spacing_factor;
  const mesh::SizeFunction size = [&](const Vec2& uv, const Vec3&) {
    return factor * guide.at(uv).size;
  };
  mesh::TriangulateOptions to;
  to.interior_points = points;
  to.refine = false;
  mesh::FaceMesh tri = mesh::triangulate_face(surface, model.faces()[f].reversed, loops, size, to);
  // Where the frontal points leave room that the kernel spans with long thin triangles (seen on a
  // surface of revolution whose parametrisation is stretched 40 times along its axis: edges of 100
  // across rows spaced 6), those recombine and subdivide into folded quads. The kernel's own size
  // refinement fills such room; not used everywhere because it also adds points between
  // well-placed frontal ones (Block.stp: 6% more vertices and more irregular ones).
  if (options.refill_edge_ratio > 0 && has_long_edge(tri, size, options.refill_edge_ratio)) {
    to.refine = true;
    tri = mesh::triangulate_face(surface, model.faces()[f].reversed, loops, size, to);
  }
  // The kernel's Delaunay steps work in (u, v). Where the parametrisation is much finer one way
  // than the other, a strip narrower than the spacing (which holds no frontal point) looks wide
  // there and gets flat triangles along its curves, whose subdivision folds quads on the curve:
  // Block.stp at size factor 0.008, a torus fillet 0.78 wide and 24 times finer across than
  // along in (u, v) (face 82), fell back to the uniform path with 133 irregular vertices. Such a
  // face is triangulated again in parameters scaled to its 3D proportions, kept when that is
  // free of them; the other faces keep their triangulation (and mesh) as it was.
  if (mesh::has_flat_boundary_triangle(tri)) {
    mesh::FaceMesh again =
        mesh::triangulate_face_scaled(surface, model.faces()[f].reversed, loops, size, to,
                                      mesh::mean_boundary_speeds(surface, loops));
    if (!mesh::has_flat_boundary_triangle(again)) tri = std::move(again);
  }
  const auto to_quads = [&](mesh::FaceMesh& t, bool& fell_back) {
    t.face = f;
    for (auto& vc : t.vclass)
      if (vc.dim == 2) vc.entity = f;
    // Moving badly placed points (where fronts met) before pairing: thin triangles there have no
    // good partner and become lone triangles, each a valence-3 vertex after subdivision. Measured
    // on Block.stp at 258k vertices: interior irregular vertices 6.01% -> 5.62%.
    const mesh::FaceMesh moved = mesh::improve_small_angles(t, surface, model.faces()[f].reversed,
                                                            options.improve_triangles);
    std::vector<std::array<Vec3, 2>> directions;
    directions.reserve(moved.triangles.size());
    for (const auto& tr : moved.triangles)
      directions.push_back(
          guide.at((moved.uv[tr[0]] + moved.uv[tr[1]] + moved.uv[tr[2]]) / 3.0).cross);
    return quads_from(moved, directions, surface, full, halved, options, fell_back);
  };
  bool fell_back = false;
  mesh::FaceMesh out = to_quads(tri, fell_back);
  // Long edges left after the refill are fans across strips too narrow for points
  // (UnstructuredOptions::retry_shorten_ratio); looked for only where they may have folded a quad.
  if ((fell_back || !valid(out)) && options.retry_shorten_ratio > 0 &&
      options.refill_edge_ratio > 0 && has_long_edge(tri, size, options.refill_edge_ratio)) {
    to.shorten_ratio = options.retry_shorten_ratio;
    bool again_fell_back = false;
    mesh::FaceMesh retry =
        mesh::triangulate_face(surface, model.faces()[f].reversed, loops, size, to);
    mesh::FaceMesh again = to_quads(retry, again_fell_back);
    if (valid(again) && (!valid(out) || min_sicn(again) > min_sicn(out))) {
      out = std::move(again);
      fell_back = again_fell_back;
    }
  }
  rep.fell_back = rep.fell_back || fell_back;
  return valid(out) ? out : mesh::FaceMesh{};
}

}  // namespace

mesh::FaceMesh mesh_face_unstructured(const cad::CadModel& model, LO f,
                                      std::span<const mesh::CurveMesh> full,
                                      const FaceFields& fields, const UnstructuredOptions& options,
                                      UnstructuredReport* report) {
  UnstructuredReport local;
  UnstructuredReport& rep = report != nullptr ? *report : local;
  rep = UnstructuredReport{};
  const ErrorContext context{"unstructured", 2, f};
  try {
    const auto surface = model.face_geometry(f);
    const background::HalvedBoundary halved =
        background::halved_face_boundary(model, f, *surface, full);
    mesh::FaceMesh out;
    const bool want_frontal = options.use_frontal;
    if (want_frontal && fields.background != nullptr && fields.cross_field != nullptr &&
        !fields.sizes.empty()) {
      try {
        out = frontal_quads(model, f, *surface, halved, full, fields, options, rep);
        rep.frontal = !out.quads.empty();
      } catch (const Error& e) {
        rep.error = e.with_context(context).what();
      }
    }
    if (!rep.frontal) {
      // Fallback path: the kernel's own refinement at a uniform size. The triangles become quads
      // of half their size by subdivision: mesh at twice the size, with half the edges per turn
      // on curved geometry.
      // A face that should have had the frontal path counts as fallen back whatever follows.
      rep.fell_back = want_frontal;
      background::BackgroundOptions tri_options;
      tri_options.sizes.size = 2 * options.size;
      tri_options.sizes.edges_per_turn = 8;
      background::FaceReport tri_report;
      const mesh::FaceMesh tri = background::mesh_face_background(
          model, f, std::span<const mesh::BoundaryLoop>(halved.loops), tri_options, &tri_report);
      if (!tri_report.ok) {
        rep.error = tri_report.error;
        mesh::FaceMesh empty;
        empty.face = f;
        return empty;
      }
      try {
        out = quads_from(tri, {}, *surface, full, halved, options, rep.fell_back);
      } catch (const Error& e) {
        rep.error = e.with_context(context).what();
        rep.fell_back = true;
        out = optimise(subdivide(tri, *surface, full, halved), *surface);
      }
    }
    out.face = f;
    rep.quads = static_cast<std::int64_t>(out.quads.size());
    rep.sicn_min = min_sicn(out);
    rep.ok = rep.sicn_min > 0;
    if (!rep.ok && rep.error.empty())
      rep.error = Error("a quad is folded (SICN <= 0)", context).what();
    return out;
  } catch (const std::exception& e) {
    rep.error = Error(e.what(), context).what();
    mesh::FaceMesh empty;
    empty.face = f;
    return empty;
  }
}

}  // namespace qsmesh::quad
