#include "qsmesh/mesh/assemble.hpp"

#include <algorithm>

#include "qsmesh/core/error.hpp"

namespace qsmesh::mesh {

SurfaceMesh assemble(const cad::CadModel& model, std::span<const CurveMesh> curves,
                     std::span<const FaceMesh> faces) {
  const LO nc = model.num_corners();
  const LO ncurves = model.num_curves();
  const LO nfaces = model.num_faces();
  QSMESH_CHECK(static_cast<LO>(curves.size()) == ncurves, "one curve mesh per curve expected");
  QSMESH_CHECK(static_cast<LO>(faces.size()) == nfaces, "one face mesh slot per face expected");

  SurfaceMesh out;
  out.num_cad_corners = nc;
  out.num_cad_curves = ncurves;
  out.num_cad_faces = nfaces;

  std::vector<GO> curve_offset(static_cast<std::size_t>(ncurves) + 1, nc);
  for (LO c = 0; c < ncurves; ++c)
    curve_offset[c + 1] = curve_offset[c] + std::max<LO>(0, curves[c].num_edges() - 1);
  std::vector<GO> face_offset(static_cast<std::size_t>(nfaces) + 1, curve_offset[ncurves]);
  for (LO f = 0; f < nfaces; ++f) {
    GO interior = 0;
    for (const VertexClass& vc : faces[f].vclass) interior += vc.dim == 2 ? 1 : 0;
    face_offset[f + 1] = face_offset[f] + interior;
  }

  const GO nv = face_offset[nfaces];
  out.points.resize(static_cast<std::size_t>(nv));
  out.vclass.resize(static_cast<std::size_t>(nv));
  for (LO i = 0; i < nc; ++i) {
    out.points[i] = model.corners()[i].point;
    out.vclass[i] = VertexClass{0, i, kNoIndex, {0, 0}};
  }
  for (LO c = 0; c < ncurves; ++c) {
    const CurveMesh& cm = curves[c];
    for (LO i = 1; i < cm.num_edges(); ++i) {
      const GO g = curve_offset[c] + i - 1;
      out.points[g] = cm.points[i];
      out.vclass[g] = VertexClass{1, c, i, {cm.t[i], 0}};
    }
  }

  // Curve edges, grouped by curve.
  for (LO c = 0; c < ncurves; ++c) {
    const CurveMesh& cm = curves[c];
    const auto& cc = model.curves()[c];
    if (cc.degenerate) continue;
    auto id = [&](LO i) -> GO {
      if (i == 0) return cc.corners[0];
      if (i == cm.num_edges()) return cc.corners[1];
      return curve_offset[c] + i - 1;
    };
    for (LO i = 0; i < cm.num_edges(); ++i) {
      out.bars.push_back({id(i), id(i + 1)});
      out.bar_curve.push_back(c);
    }
  }

  // Faces in increasing id; local -> global through the classification.
  std::vector<GO> local2global;
  for (LO f = 0; f < nfaces; ++f) {
    const FaceMesh& fm = faces[f];
    local2global.assign(fm.vclass.size(), -1);
    GO next_interior = face_offset[f];
    for (std::size_t i = 0; i < fm.vclass.size(); ++i) {
      const VertexClass& vc = fm.vclass[i];
      GO g = -1;
      if (vc.dim == 0) {
        QSMESH_CHECK(vc.entity >= 0 && vc.entity < nc, "face " << f << ": bad corner id " << vc.entity);
        g = vc.entity;
      } else if (vc.dim == 1) {
        QSMESH_CHECK(vc.entity >= 0 && vc.entity < ncurves, "face " << f << ": bad curve id " << vc.entity);
        const CurveMesh& cm = curves[vc.entity];
        QSMESH_CHECK(vc.index >= 1 && vc.index < cm.num_edges(),
                     "face " << f << ": vertex index " << vc.index << " outside curve " << vc.entity);
        g = curve_offset[vc.entity] + vc.index - 1;
      } else {
        g = next_interior++;
        out.points[g] = fm.points[i];
        out.vclass[g] = vc;
        out.vclass[g].entity = f;
        out.vclass[g].index = kNoIndex;
      }
      local2global[i] = g;
    }
    for (const auto& t : fm.triangles) {
      const std::array<GO, 3> gt{local2global[t[0]], local2global[t[1]], local2global[t[2]]};
      // Two uv images of one vertex (pole) collapse a triangle: it carries no area, drop it.
      if (gt[0] == gt[1] || gt[1] == gt[2] || gt[0] == gt[2]) continue;
      out.triangles.push_back(gt);
      out.triangle_face.push_back(f);
    }
    for (const auto& q : fm.quads) {
      out.quads.push_back({local2global[q[0]], local2global[q[1]], local2global[q[2]], local2global[q[3]]});
      out.quad_face.push_back(f);
    }
  }

  // Topology for the writers.
  out.curve_corners.resize(static_cast<std::size_t>(ncurves));
  for (LO c = 0; c < ncurves; ++c) out.curve_corners[c] = model.curves()[c].corners;
  std::vector<std::pair<LO, LO>> pairs;
  for (LO f = 0; f < nfaces; ++f) {
    std::vector<LO> cs;
    for (const auto& loop : model.faces()[f].loops)
      for (const auto& use : loop.uses) cs.push_back(use.curve);
    std::sort(cs.begin(), cs.end());
    cs.erase(std::unique(cs.begin(), cs.end()), cs.end());
    for (LO c : cs) pairs.emplace_back(f, c);
  }
  out.face2curves = Adjacency::from_pairs(nfaces, std::move(pairs));
  return out;
}

}  // namespace qsmesh::mesh
