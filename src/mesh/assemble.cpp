#include "qsmesh/mesh/assemble.hpp"

#include <algorithm>
#include <sstream>

#include "qsmesh/core/error.hpp"

namespace qsmesh::mesh {

namespace {

// Two vertices of one face mesh are one vertex of the assembled mesh when they are the same
// corner or the same vertex of the same curve (several uv images: seams, poles); interior
// vertices are always distinct.
bool same_vertex(const VertexClass& a, const VertexClass& b) {
  if (a.dim != b.dim || a.dim == 2) return false;
  return a.entity == b.entity && (a.dim == 0 || a.index == b.index);
}

bool collapsed(const FaceMesh& fm, const std::array<LO, 3>& t) {
  return same_vertex(fm.vclass[t[0]], fm.vclass[t[1]]) ||
         same_vertex(fm.vclass[t[1]], fm.vclass[t[2]]) ||
         same_vertex(fm.vclass[t[0]], fm.vclass[t[2]]);
}

}  // namespace

FaceContribution face_contribution(const FaceMesh& face) {
  FaceContribution c;
  for (const VertexClass& vc : face.vclass) c.interior_vertices += vc.dim == 2 ? 1 : 0;
  for (const auto& t : face.triangles) c.triangles += collapsed(face, t) ? 0 : 1;
  c.quads = static_cast<GO>(face.quads.size());
  return c;
}

MeshAssembler::MeshAssembler(const cad::CadModel& model, std::span<const CurveMesh> curves,
                             std::span<const FaceContribution> contributions,
                             std::span<const char> inner_curves)
    : model_(model), curves_(curves) {
  const LO nc = model.num_corners();
  const LO ncurves = model.num_curves();
  const LO nfaces = model.num_faces();
  QSMESH_CHECK(static_cast<LO>(curves.size()) == ncurves, "one curve mesh per curve expected");
  QSMESH_CHECK(static_cast<LO>(contributions.size()) == nfaces,
               "one face contribution per face expected");
  numbering_.num_corners = nc;
  out_.num_cad_corners = nc;
  out_.num_cad_curves = ncurves;
  out_.num_cad_faces = nfaces;

  numbering_.curve_offset.assign(static_cast<std::size_t>(ncurves) + 1, nc);
  for (LO c = 0; c < ncurves; ++c)
    numbering_.curve_offset[c + 1] =
        numbering_.curve_offset[c] + std::max<LO>(0, curves[c].num_edges() - 1);
  numbering_.face_offset.assign(static_cast<std::size_t>(nfaces) + 1,
                                numbering_.curve_offset[ncurves]);
  triangle_offset_.assign(static_cast<std::size_t>(nfaces) + 1, 0);
  quad_offset_.assign(static_cast<std::size_t>(nfaces) + 1, 0);
  for (LO f = 0; f < nfaces; ++f) {
    const FaceContribution& c = contributions[f];
    QSMESH_CHECK(c.interior_vertices >= 0 && c.triangles >= 0 && c.quads >= 0,
                 "face " << f << ": negative contribution");
    numbering_.face_offset[f + 1] = numbering_.face_offset[f] + c.interior_vertices;
    triangle_offset_[f + 1] = triangle_offset_[f] + c.triangles;
    quad_offset_[f + 1] = quad_offset_[f] + c.quads;
  }
  added_.assign(static_cast<std::size_t>(nfaces), 0);

  const GO nv = numbering_.face_offset[nfaces];
  out_.points.resize(static_cast<std::size_t>(nv));
  out_.vclass.resize(static_cast<std::size_t>(nv));
  out_.triangles.resize(static_cast<std::size_t>(triangle_offset_[nfaces]));
  out_.triangle_face.resize(out_.triangles.size());
  out_.quads.resize(static_cast<std::size_t>(quad_offset_[nfaces]));
  out_.quad_face.resize(out_.quads.size());
  for (LO i = 0; i < nc; ++i) {
    out_.points[i] = model.corners()[i].point;
    out_.vclass[i] = VertexClass{0, i, kNoIndex, {0, 0}};
  }
  for (LO c = 0; c < ncurves; ++c) {
    const CurveMesh& cm = curves[c];
    for (LO i = 1; i < cm.num_edges(); ++i) {
      const GO g = numbering_.curve_offset[c] + i - 1;
      out_.points[g] = cm.points[i];
      out_.vclass[g] = VertexClass{1, c, i, {cm.t[i], 0}};
    }
  }

  // Curve edges, grouped by curve.
  for (LO c = 0; c < ncurves; ++c) {
    const CurveMesh& cm = curves[c];
    const auto& cc = model.curves()[c];
    if (cc.degenerate || (!inner_curves.empty() && inner_curves[c] != 0)) continue;
    auto id = [&](LO i) -> GO {
      if (i == 0) return cc.corners[0];
      if (i == cm.num_edges()) return cc.corners[1];
      return numbering_.curve_offset[c] + i - 1;
    };
    for (LO i = 0; i < cm.num_edges(); ++i) {
      out_.bars.push_back({id(i), id(i + 1)});
      out_.bar_curve.push_back(c);
    }
  }
}

std::vector<GO> MeshAssembler::add_face(LO f, const FaceMesh& fm) {
  const LO nc = model_.num_corners();
  const LO ncurves = model_.num_curves();
  QSMESH_CHECK(f >= 0 && f < model_.num_faces(), "assembly: no face " << f);
  QSMESH_CHECK(!added_[f], "assembly: face " << f << " added twice");
  added_[f] = 1;
  // The face must bring what was announced for it: its slots are checked while it is written.
  const auto mismatch = [&](const char* what) {
    std::ostringstream os;
    os << "assembly: face " << f << " has other " << what << " counts than announced";
    return os.str();
  };
  const GO quads_announced = quad_offset_[f + 1] - quad_offset_[f];
  QSMESH_CHECK(static_cast<GO>(fm.quads.size()) == quads_announced, mismatch("quad"));
  std::vector<GO> local2global(fm.vclass.size(), -1);
  GO next_interior = numbering_.face_offset[f];
  for (std::size_t i = 0; i < fm.vclass.size(); ++i) {
    const VertexClass& vc = fm.vclass[i];
    GO g = -1;
    if (vc.dim == 0) {
      QSMESH_CHECK(vc.entity >= 0 && vc.entity < nc,
                   "face " << f << ": bad corner id " << vc.entity);
      g = vc.entity;
    } else if (vc.dim == 1) {
      QSMESH_CHECK(vc.entity >= 0 && vc.entity < ncurves,
                   "face " << f << ": bad curve id " << vc.entity);
      const CurveMesh& cm = curves_[vc.entity];
      QSMESH_CHECK(vc.index >= 1 && vc.index < cm.num_edges(),
                   "face " << f << ": vertex index " << vc.index << " outside curve " << vc.entity);
      g = numbering_.curve_offset[vc.entity] + vc.index - 1;
    } else {
      QSMESH_CHECK(next_interior < numbering_.face_offset[f + 1], mismatch("interior vertex"));
      g = next_interior++;
      out_.points[g] = fm.points[i];
      out_.vclass[g] = vc;
      out_.vclass[g].entity = f;
      out_.vclass[g].index = kNoIndex;
    }
    local2global[i] = g;
  }
  QSMESH_CHECK(next_interior == numbering_.face_offset[f + 1], mismatch("interior vertex"));
  GO t_out = triangle_offset_[f];
  for (const auto& t : fm.triangles) {
    // Two uv images of one vertex (pole) collapse a triangle: it carries no area, drop it.
    if (collapsed(fm, t)) continue;
    QSMESH_CHECK(t_out < triangle_offset_[f + 1], mismatch("triangle"));
    out_.triangles[t_out] = {local2global[t[0]], local2global[t[1]], local2global[t[2]]};
    out_.triangle_face[t_out++] = f;
  }
  QSMESH_CHECK(t_out == triangle_offset_[f + 1], mismatch("triangle"));
  GO q_out = quad_offset_[f];
  for (const auto& q : fm.quads) {
    out_.quads[q_out] = {local2global[q[0]], local2global[q[1]], local2global[q[2]],
                         local2global[q[3]]};
    out_.quad_face[q_out++] = f;
  }
  return local2global;
}

std::vector<GO> MeshAssembler::add_group(const FaceMesh& fm, std::span<const LO> quad_face) {
  const LO nc = model_.num_corners();
  const LO ncurves = model_.num_curves();
  const LO nfaces = model_.num_faces();
  QSMESH_CHECK(quad_face.size() == fm.quads.size(), "assembly: one face per quad of a group");
  QSMESH_CHECK(fm.triangles.empty(), "assembly: a group mesh has quads only");
  std::vector<char> in_group(static_cast<std::size_t>(nfaces), 0);
  const auto take = [&](LO f) {
    QSMESH_CHECK(f >= 0 && f < nfaces, "assembly: group face " << f << " out of range");
    if (in_group[f] != 0) return;
    QSMESH_CHECK(!added_[f], "assembly: face " << f << " added twice");
    in_group[f] = 1;
  };
  for (const LO f : quad_face) take(f);
  for (const VertexClass& vc : fm.vclass)
    if (vc.dim == 2) take(vc.entity);
  std::vector<GO> next_interior(numbering_.face_offset.begin(), numbering_.face_offset.end() - 1);
  std::vector<GO> next_quad(quad_offset_.begin(), quad_offset_.end() - 1);
  std::vector<GO> local2global(fm.vclass.size(), -1);
  for (std::size_t i = 0; i < fm.vclass.size(); ++i) {
    const VertexClass& vc = fm.vclass[i];
    GO g = -1;
    if (vc.dim == 0) {
      QSMESH_CHECK(vc.entity >= 0 && vc.entity < nc, "group: bad corner id " << vc.entity);
      g = vc.entity;
    } else if (vc.dim == 1) {
      QSMESH_CHECK(vc.entity >= 0 && vc.entity < ncurves, "group: bad curve id " << vc.entity);
      const CurveMesh& cm = curves_[vc.entity];
      QSMESH_CHECK(vc.index >= 1 && vc.index < cm.num_edges(),
                   "group: vertex index " << vc.index << " outside curve " << vc.entity);
      g = numbering_.curve_offset[vc.entity] + vc.index - 1;
    } else {
      const LO f = vc.entity;
      QSMESH_CHECK(next_interior[f] < numbering_.face_offset[f + 1],
                   "assembly: group face " << f << " has more interior vertices than announced");
      g = next_interior[f]++;
      out_.points[g] = fm.points[i];
      out_.vclass[g] = vc;
      out_.vclass[g].index = kNoIndex;
    }
    local2global[i] = g;
  }
  for (std::size_t q = 0; q < fm.quads.size(); ++q) {
    const LO f = quad_face[q];
    QSMESH_CHECK(next_quad[f] < quad_offset_[f + 1],
                 "assembly: group face " << f << " has more quads than announced");
    const auto& quad = fm.quads[q];
    out_.quads[next_quad[f]] = {local2global[quad[0]], local2global[quad[1]], local2global[quad[2]],
                                local2global[quad[3]]};
    out_.quad_face[next_quad[f]++] = f;
  }
  for (LO f = 0; f < nfaces; ++f) {
    if (in_group[f] == 0) continue;
    QSMESH_CHECK(next_interior[f] == numbering_.face_offset[f + 1] &&
                     next_quad[f] == quad_offset_[f + 1] &&
                     triangle_offset_[f] == triangle_offset_[f + 1],
                 "assembly: group face " << f << " has other counts than announced");
    added_[f] = 1;
  }
  return local2global;
}

SurfaceMesh MeshAssembler::finish() {
  const LO nfaces = model_.num_faces();
  for (LO f = 0; f < nfaces; ++f)
    QSMESH_CHECK(added_[f] || (numbering_.face_offset[f + 1] == numbering_.face_offset[f] &&
                               triangle_offset_[f + 1] == triangle_offset_[f] &&
                               quad_offset_[f + 1] == quad_offset_[f]),
                 "assembly: face " << f << " announced but never added");
  // Topology for the writers.
  const LO ncurves = model_.num_curves();
  out_.curve_corners.resize(static_cast<std::size_t>(ncurves));
  for (LO c = 0; c < ncurves; ++c) out_.curve_corners[c] = model_.curves()[c].corners;
  std::vector<std::pair<LO, LO>> pairs;
  for (LO f = 0; f < nfaces; ++f) {
    std::vector<LO> cs;
    for (const auto& loop : model_.faces()[f].loops)
      for (const auto& use : loop.uses) cs.push_back(use.curve);
    std::sort(cs.begin(), cs.end());
    cs.erase(std::unique(cs.begin(), cs.end()), cs.end());
    for (LO c : cs) pairs.emplace_back(f, c);
  }
  out_.face2curves = Adjacency::from_pairs(nfaces, std::move(pairs));
  return std::move(out_);
}

SurfaceMesh assemble(const cad::CadModel& model, std::span<const CurveMesh> curves,
                     std::span<const FaceMesh> faces) {
  QSMESH_CHECK(static_cast<LO>(faces.size()) == model.num_faces(),
               "one face mesh slot per face expected");
  std::vector<FaceContribution> counts(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) counts[f] = face_contribution(faces[f]);
  MeshAssembler assembler(model, curves, counts);
  for (LO f = 0; f < model.num_faces(); ++f) assembler.add_face(f, faces[f]);
  return assembler.finish();
}

}  // namespace qsmesh::mesh
