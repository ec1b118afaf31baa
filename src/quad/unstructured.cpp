#include "qsmesh/quad/unstructured.hpp"

#include <algorithm>
#include <limits>

#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/quad/subdivide.hpp"
#include "qsmesh/smooth/smooth.hpp"
#include "qsmesh/smooth/untangle.hpp"

namespace qsmesh::quad {

namespace {

double min_sicn(const mesh::FaceMesh& m) {
  double worst = std::numeric_limits<double>::max();
  for (const auto& q : m.quads)
    worst = std::min(worst, mesh::quad_sicn({m.points[q[0]], m.points[q[1]], m.points[q[2]], m.points[q[3]]}));
  return m.quads.empty() ? -1.0 : worst;
}

}  // namespace

mesh::FaceMesh mesh_face_unstructured(const cad::CadModel& model, LO f, std::span<const mesh::CurveMesh> halved,
                                      std::span<const mesh::CurveMesh> full, const UnstructuredOptions& options,
                                      UnstructuredReport* report) {
  UnstructuredReport local;
  UnstructuredReport& rep = report != nullptr ? *report : local;
  rep = UnstructuredReport{};
  const ErrorContext context{"unstructured", 2, f};
  // The triangles become quads of half their size by subdivision: mesh at twice the size, with
  // half the edges per turn on curved geometry.
  background::BackgroundOptions tri_options;
  tri_options.sizes.size = 2 * options.size;
  tri_options.sizes.edges_per_turn = 8;
  background::FaceReport tri_report;
  const mesh::FaceMesh tri = background::mesh_face_background(model, f, halved, tri_options, &tri_report);
  if (!tri_report.ok) {
    rep.error = tri_report.error;
    mesh::FaceMesh empty;
    empty.face = f;
    return empty;
  }
  try {
    const auto surface = model.face_geometry(f);
    // Geometry optimisation (Sec. 5.3), each step measured and rolled back if it hurts; the
    // untangler only where a quad is still invalid.
    const auto optimise = [&](mesh::FaceMesh m) {
      m = smooth::smooth_face(m, *surface, smooth::SmoothOptions{});
      if (min_sicn(m) <= 0) m = smooth::untangle_face(m, *surface, smooth::UntangleOptions{});
      return m;
    };
    mesh::FaceMesh out;
    try {
      out = optimise(subdivide(recombine(tri, {}, options.recombine), *surface, full));
    } catch (const Error& e) {
      rep.error = e.with_context(context).what();
    }
    if (out.quads.empty() || min_sicn(out) <= 0) {
      // Subdividing the triangles alone always gives quads; recombination is what may fold one.
      // The better of the two meshes is kept.
      rep.fell_back = true;
      mesh::FaceMesh alt = optimise(subdivide(tri, *surface, full));
      if (out.quads.empty() || min_sicn(alt) > min_sicn(out)) out = std::move(alt);
    }
    out.face = f;
    rep.quads = static_cast<std::int64_t>(out.quads.size());
    rep.sicn_min = min_sicn(out);
    rep.ok = rep.sicn_min > 0;
    if (!rep.ok && rep.error.empty()) rep.error = Error("a quad is folded (SICN <= 0)", context).what();
    return out;
  } catch (const std::exception& e) {
    rep.error = Error(e.what(), context).what();
    mesh::FaceMesh empty;
    empty.face = f;
    return empty;
  }
}

}  // namespace qsmesh::quad
