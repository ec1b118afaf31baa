#include "qsmesh/mesh/validate.hpp"

#include <algorithm>
#include <map>
#include <memory>
#include <sstream>
#include <unordered_map>

#include "qsmesh/mesh/edges.hpp"

namespace qsmesh::mesh {

std::string ConformityReport::summary() const {
  std::ostringstream os;
  os << edges << " edges; bad interior " << interior_edges_bad << ", bad curve " << curve_edges_bad
     << ", misoriented " << orientation_bad << ", degenerate elements " << degenerate_elements
     << ", faces without elements " << faces_without_elements;
  return os.str();
}

namespace {
struct EdgeUse {
  LO face;
  bool forward;  ///< traversed from the smaller to the larger vertex id
};
}  // namespace

ConformityReport check_conformity(const SurfaceMesh& mesh, const cad::CadModel& model,
                                  std::span<const LO> face_group) {
  ConformityReport r;
  // Elements are compared by their face's group (a face alone is its own).
  const auto group = [&](LO f) { return face_group.empty() ? f : face_group[f]; };
  std::unordered_map<std::uint64_t, std::vector<EdgeUse>> uses;
  std::vector<std::int64_t> per_face(static_cast<std::size_t>(model.num_faces()), 0);
  auto add = [&](const GO* v, int n, LO f) {
    const LO face = group(f);
    ++per_face[face];
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j)
        if (v[i] == v[j]) {
          ++r.degenerate_elements;
          return;
        }
    for (int i = 0; i < n; ++i) {
      const GO a = v[i], b = v[(i + 1) % n];
      uses[edge_key(a, b)].push_back({face, a < b});
    }
  };
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    add(mesh.triangles[i].data(), 3, mesh.triangle_face[i]);
  for (std::size_t i = 0; i < mesh.quads.size(); ++i)
    add(mesh.quads[i].data(), 4, mesh.quad_face[i]);

  // Expected uses of each curve edge: one per use of the curve in a face loop.
  std::vector<int> curve_uses(static_cast<std::size_t>(model.num_curves()), 0);
  for (const auto& f : model.faces())
    for (const auto& l : f.loops)
      for (const auto& u : l.uses) ++curve_uses[u.curve];
  const std::unordered_map<std::uint64_t, LO> bar_curve = bar_curves(mesh);

  r.edges = static_cast<std::int64_t>(uses.size());
  for (const auto& [k, list] : uses) {
    const auto bar = bar_curve.find(k);
    if (bar != bar_curve.end()) {
      if (static_cast<int>(list.size()) != curve_uses[bar->second]) ++r.curve_edges_bad;
      continue;
    }
    // Off the curves, each face that has the edge has it twice, traversed both ways. Two faces may
    // both have an edge between the same two curve vertices (a face given twice in the CAD, or
    // faces sharing two curves), each inside itself; faces meeting at it, once each, do not
    // conform.
    std::vector<EdgeUse> sorted = list;
    std::sort(sorted.begin(), sorted.end(),
              [](const EdgeUse& x, const EdgeUse& y) { return x.face < y.face; });
    bool bad = false, misoriented = false;
    for (std::size_t i = 0; i < sorted.size(); i += 2) {
      if (i + 1 >= sorted.size() || sorted[i].face != sorted[i + 1].face ||
          (i + 2 < sorted.size() && sorted[i + 2].face == sorted[i].face)) {
        bad = true;
        break;
      }
      misoriented = misoriented || sorted[i].forward == sorted[i + 1].forward;
    }
    if (bad) {
      ++r.interior_edges_bad;
    } else if (misoriented) {
      ++r.orientation_bad;
    }
  }
  for (LO f = 0; f < model.num_faces(); ++f)
    if (group(f) == f && per_face[f] == 0) ++r.faces_without_elements;
  return r;
}

double max_distance_to_cad(const SurfaceMesh& mesh, const cad::CadModel& model) {
  std::map<LO, std::unique_ptr<cad::CurveGeometry>> curves;
  std::map<LO, std::unique_ptr<cad::FaceGeometry>> faces;
  double worst = 0;
  for (GO v = 0; v < mesh.num_vertices(); ++v) {
    const VertexClass& c = mesh.vclass[v];
    Vec3 on_cad;
    if (c.dim == 0) {
      on_cad = model.corners()[c.entity].point;
    } else if (c.dim == 1) {
      auto& g = curves[c.entity];
      if (!g) g = model.curve_geometry(c.entity);
      on_cad = g->point(c.param[0]);
    } else {
      auto& g = faces[c.entity];
      if (!g) g = model.face_geometry(c.entity);
      on_cad = g->eval({c.param[0], c.param[1]}).p;
    }
    worst = std::max(worst, distance(on_cad, mesh.points[v]));
  }
  return worst;
}

}  // namespace qsmesh::mesh
