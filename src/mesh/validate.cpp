#include "qsmesh/mesh/validate.hpp"

#include <algorithm>
#include <map>
#include <memory>
#include <sstream>
#include <vector>

#include "qsmesh/core/error.hpp"

namespace qsmesh::mesh {

std::string ConformityReport::summary() const {
  std::ostringstream os;
  os << edges << " edges; bad interior " << interior_edges_bad << ", bad curve " << curve_edges_bad
     << ", misoriented " << orientation_bad << ", degenerate elements " << degenerate_elements
     << ", faces without elements " << faces_without_elements;
  return os.str();
}

namespace {
// One use of the edge {v, other} by an element, filed under its smaller vertex v.
struct EdgeUse {
  GO other;      ///< the larger vertex id
  LO face;       ///< the element's face's group
  bool forward;  ///< traversed from the smaller to the larger vertex id
};

bool repeats_a_vertex(const GO* v, int n) {
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if (v[i] == v[j]) return true;
  return false;
}
}  // namespace

// The element edges are filed by their smaller vertex (a counting sort, linear in the elements)
// and each vertex's few uses sorted: on Block.stp at 4x its reference count (2.3M quads) this is
// several times faster than a hash map of per-edge lists, the former form. The verdict per edge
// is the same.
ConformityReport check_conformity(const SurfaceMesh& mesh, const cad::CadModel& model,
                                  std::span<const LO> face_group) {
  ConformityReport r;
  // Elements are compared by their face's group (a face alone is its own).
  const auto group = [&](LO f) { return face_group.empty() ? f : face_group[f]; };
  const GO nv = mesh.num_vertices();
  const auto check_ids = [&](const GO* v, int n) {
    for (int i = 0; i < n; ++i)
      QSMESH_CHECK(v[i] >= 0 && v[i] < nv, "check_conformity: vertex id " << v[i] << " of " << nv);
  };
  std::vector<std::int64_t> per_face(static_cast<std::size_t>(model.num_faces()), 0);
  std::vector<GO> start(static_cast<std::size_t>(nv) + 1, 0);
  const auto each_element = [&](const auto& visit) {
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
      visit(mesh.triangles[i].data(), 3, mesh.triangle_face[i]);
    for (std::size_t i = 0; i < mesh.quads.size(); ++i)
      visit(mesh.quads[i].data(), 4, mesh.quad_face[i]);
  };
  each_element([&](const GO* v, int n, LO f) {
    check_ids(v, n);
    ++per_face[group(f)];
    if (repeats_a_vertex(v, n)) {
      ++r.degenerate_elements;
      return;
    }
    for (int i = 0; i < n; ++i) ++start[std::min(v[i], v[(i + 1) % n]) + 1];
  });
  for (GO v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<EdgeUse> uses(static_cast<std::size_t>(start[nv]));
  std::vector<GO> next(start.begin(), start.end() - 1);
  each_element([&](const GO* v, int n, LO f) {
    if (repeats_a_vertex(v, n)) return;
    for (int i = 0; i < n; ++i) {
      const GO a = v[i], b = v[(i + 1) % n];
      uses[next[std::min(a, b)]++] = {std::max(a, b), group(f), a < b};
    }
  });
  // Bars by their smaller vertex too (the last bar of an edge names its curve, as bar_curves).
  std::vector<GO> bar_start(static_cast<std::size_t>(nv) + 1, 0);
  for (const auto& b : mesh.bars) {
    check_ids(b.data(), 2);
    ++bar_start[std::min(b[0], b[1]) + 1];
  }
  for (GO v = 0; v < nv; ++v) bar_start[v + 1] += bar_start[v];
  std::vector<std::size_t> bars(mesh.bars.size());
  {
    std::vector<GO> at(bar_start.begin(), bar_start.end() - 1);
    for (std::size_t i = 0; i < mesh.bars.size(); ++i)
      bars[static_cast<std::size_t>(at[std::min(mesh.bars[i][0], mesh.bars[i][1])]++)] = i;
  }

  // Expected uses of each curve edge: one per use of the curve in a face loop.
  std::vector<int> curve_uses(static_cast<std::size_t>(model.num_curves()), 0);
  for (const auto& f : model.faces())
    for (const auto& l : f.loops)
      for (const auto& u : l.uses) ++curve_uses[u.curve];

  for (GO v = 0; v < nv; ++v) {
    const auto first = uses.begin() + start[v], last = uses.begin() + start[v + 1];
    std::sort(first, last, [](const EdgeUse& x, const EdgeUse& y) {
      return x.other != y.other ? x.other < y.other : x.face < y.face;
    });
    for (auto run = first; run != last;) {
      auto end = run;
      while (end != last && end->other == run->other) ++end;
      ++r.edges;
      const auto count = static_cast<int>(end - run);
      LO curve = kNoIndex;
      for (GO k = bar_start[v]; k < bar_start[v + 1]; ++k) {
        const std::size_t b = bars[static_cast<std::size_t>(k)];
        if (std::max(mesh.bars[b][0], mesh.bars[b][1]) == run->other) curve = mesh.bar_curve[b];
      }
      if (curve != kNoIndex) {
        if (count != curve_uses[curve]) ++r.curve_edges_bad;
        run = end;
        continue;
      }
      // Off the curves, each face that has the edge has it twice, traversed both ways. Two faces
      // may both have an edge between the same two curve vertices (a face given twice in the CAD,
      // or faces sharing two curves), each inside itself; faces meeting at it, once each, do not
      // conform.
      bool bad = false, misoriented = false;
      for (auto i = run; i != end; i += 2) {
        if (i + 1 == end || i->face != (i + 1)->face ||
            (i + 2 != end && (i + 2)->face == i->face)) {
          bad = true;
          break;
        }
        misoriented = misoriented || i->forward == (i + 1)->forward;
      }
      if (bad) {
        ++r.interior_edges_bad;
      } else if (misoriented) {
        ++r.orientation_bad;
      }
      run = end;
    }
  }
  for (LO f = 0; f < model.num_faces(); ++f)
    if (group(f) == f && per_face[f] == 0) ++r.faces_without_elements;
  return r;
}

double max_distance_to_cad(std::span<const Vec3> points, std::span<const VertexClass> vclass,
                           const cad::CadModel& model, int dim) {
  QSMESH_CHECK(
      points.size() == vclass.size(),
      "max_distance_to_cad: " << points.size() << " points, " << vclass.size() << " classes");
  // One evaluator per entity met (a face mesh has one; an assembled mesh many).
  std::map<LO, std::unique_ptr<cad::CurveGeometry>> curves;
  std::map<LO, std::unique_ptr<cad::FaceGeometry>> faces;
  double worst = 0;
  for (std::size_t v = 0; v < vclass.size(); ++v) {
    const VertexClass& c = vclass[v];
    if (c.dim != dim) continue;
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
    worst = std::max(worst, distance(on_cad, points[v]));
  }
  return worst;
}

double max_distance_to_cad(const CurveMesh& curve, const cad::CadModel& model) {
  if (curve.num_edges() < 2) return 0;
  const std::unique_ptr<cad::CurveGeometry> g = model.curve_geometry(curve.curve);
  double worst = 0;
  for (LO i = 1; i < curve.num_edges(); ++i)
    worst = std::max(worst, distance(g->point(curve.t[i]), curve.points[i]));
  return worst;
}

double max_distance_to_cad(const SurfaceMesh& mesh, const cad::CadModel& model) {
  double worst = 0;
  for (int dim = 0; dim <= 2; ++dim)
    worst = std::max(worst, max_distance_to_cad(mesh.points, mesh.vclass, model, dim));
  return worst;
}

}  // namespace qsmesh::mesh
