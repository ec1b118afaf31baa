// Gmsh MSH 4.1 ASCII. Entity tags are CAD ids + 1 (Gmsh tags are positive); node tags are vertex
// ids + 1 and element tags run 1..n in the order the blocks are written.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "detail.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/atomic_file.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/mesh/high_order_nodes.hpp"

namespace qsmesh::io {

namespace {

void write_box(OutputFile& out, const Box3& box) {
  const Box3 b = box.valid() ? box : Box3{Vec3{0, 0, 0}, Vec3{0, 0, 0}};
  out << b.lo.x << ' ' << b.lo.y << ' ' << b.lo.z << ' ' << b.hi.x << ' ' << b.hi.y << ' '
      << b.hi.z;
}

}  // namespace

void write_msh(const mesh::SurfaceMesh& mesh, const std::string& path,
               const WriteOptions& options) {
  detail::check_output_folder(path);
  check_mesh_for_output(mesh);
  const GO nv = mesh.num_vertices();
  const std::array<LO, 3> num_entities = {mesh.num_cad_corners, mesh.num_cad_curves,
                                          mesh.num_cad_faces};

  // Nodes of each entity, in vertex order; every vertex must be classified.
  std::array<std::vector<std::vector<GO>>, 3> entity2nodes;
  for (int d = 0; d < 3; ++d) entity2nodes[d].resize(static_cast<std::size_t>(num_entities[d]));
  for (GO v = 0; v < nv; ++v) {
    const auto& vc = mesh.vclass[static_cast<std::size_t>(v)];
    QSMESH_CHECK(vc.dim >= 0 && vc.dim <= 2 && vc.entity >= 0 && vc.entity < num_entities[vc.dim],
                 "MSH output " << path << ": vertex " << v << " has classification (dim "
                               << int{vc.dim} << ", entity " << vc.entity << ") out of range");
    entity2nodes[vc.dim][static_cast<std::size_t>(vc.entity)].push_back(v);
  }
  const detail::ElementGroups groups = detail::group_elements(mesh);

  // Bounding boxes: the entity's own vertices and those of its elements (and end corners).
  auto pt = [&](GO v) { return mesh.points[static_cast<std::size_t>(v)]; };
  std::vector<Box3> curve_box(static_cast<std::size_t>(mesh.num_cad_curves));
  for (LO c = 0; c < mesh.num_cad_curves; ++c) {
    Box3& b = curve_box[static_cast<std::size_t>(c)];
    for (GO v : entity2nodes[1][static_cast<std::size_t>(c)]) b.add(pt(v));
    for (GO e : groups.curve2bars[static_cast<std::size_t>(c)]) {
      for (GO v : mesh.bars[static_cast<std::size_t>(e)]) b.add(pt(v));
    }
    if (!mesh.curve_corners.empty()) {
      for (LO k : mesh.curve_corners[static_cast<std::size_t>(c)]) {
        if (k == kNoIndex) continue;
        for (GO v : entity2nodes[0][static_cast<std::size_t>(k)]) b.add(pt(v));
      }
    }
  }
  std::vector<Box3> face_box(static_cast<std::size_t>(mesh.num_cad_faces));
  for (LO f = 0; f < mesh.num_cad_faces; ++f) {
    Box3& b = face_box[static_cast<std::size_t>(f)];
    for (GO v : entity2nodes[2][static_cast<std::size_t>(f)]) b.add(pt(v));
    for (GO e : groups.face2tris[static_cast<std::size_t>(f)]) {
      for (GO v : mesh.triangles[static_cast<std::size_t>(e)]) b.add(pt(v));
    }
    for (GO e : groups.face2quads[static_cast<std::size_t>(f)]) {
      for (GO v : mesh.quads[static_cast<std::size_t>(e)]) b.add(pt(v));
    }
    if (mesh.face2curves.size() > 0) {
      for (LO c : mesh.face2curves[f]) b.add(curve_box[static_cast<std::size_t>(c)]);
    }
  }

  AtomicFile atomic(path);
  OutputFile out(atomic);
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";

  // $Entities: numPoints numCurves numSurfaces numVolumes, then each entity with no physical tag.
  out << "$Entities\n"
      << mesh.num_cad_corners << ' ' << mesh.num_cad_curves << ' ' << mesh.num_cad_faces << " 0\n";
  for (LO k = 0; k < mesh.num_cad_corners; ++k) {
    const auto& nodes = entity2nodes[0][static_cast<std::size_t>(k)];
    const Vec3 p = nodes.empty() ? Vec3{} : pt(nodes.front());
    out << k + 1 << ' ' << p.x << ' ' << p.y << ' ' << p.z << " 0\n";
  }
  for (LO c = 0; c < mesh.num_cad_curves; ++c) {
    out << c + 1 << ' ';
    write_box(out, curve_box[static_cast<std::size_t>(c)]);
    out << " 0 ";
    // Bounding points: start corner positive, end corner negative (its orientation on the curve).
    std::vector<long long> bounds;
    if (!mesh.curve_corners.empty()) {
      const auto& cc = mesh.curve_corners[static_cast<std::size_t>(c)];
      if (cc[0] != kNoIndex) bounds.push_back(cc[0] + 1);
      if (cc[1] != kNoIndex) bounds.push_back(-(cc[1] + 1));
    }
    out << bounds.size();
    for (long long b : bounds) out << ' ' << b;
    out << '\n';
  }
  for (LO f = 0; f < mesh.num_cad_faces; ++f) {
    out << f + 1 << ' ';
    write_box(out, face_box[static_cast<std::size_t>(f)]);
    out << " 0 ";
    // Curve orientations in the face's loops are not in SurfaceMesh: all written positive.
    if (mesh.face2curves.size() > 0) {
      const auto curves = mesh.face2curves[f];
      out << curves.size();
      for (LO c : curves) out << ' ' << c + 1;
    } else {
      out << 0;
    }
    out << '\n';
  }
  out << "$EndEntities\n";

  // $Nodes: numEntityBlocks numNodes minNodeTag maxNodeTag; per block
  // entityDim entityTag parametric(0) numNodesInBlock, the tags, then the coordinates.
  std::size_t node_blocks = 0;
  for (int d = 0; d < 3; ++d) {
    for (const auto& nodes : entity2nodes[d]) node_blocks += nodes.empty() ? 0 : 1;
  }
  out << "$Nodes\n" << node_blocks << ' ' << nv << ' ' << (nv > 0 ? 1 : 0) << ' ' << nv << '\n';
  for (int d = 0; d < 3; ++d) {
    for (std::size_t e = 0; e < entity2nodes[d].size(); ++e) {
      const auto& nodes = entity2nodes[d][e];
      if (nodes.empty()) continue;
      out << d << ' ' << e + 1 << " 0 " << nodes.size() << '\n';
      for (GO v : nodes) out << v + 1 << '\n';
      for (GO v : nodes) {
        const Vec3 p = pt(v);
        out << p.x << ' ' << p.y << ' ' << p.z << '\n';
      }
    }
  }
  out << "$EndNodes\n";

  // $Elements: numEntityBlocks numElements minElementTag maxElementTag; per block
  // entityDim entityTag elementType numElementsInBlock, then "tag node..." lines.
  std::size_t elem_blocks = 0;
  GO num_elems = 0;
  if (options.msh_corner_elements) {
    for (const auto& nodes : entity2nodes[0]) {
      if (!nodes.empty()) {
        ++elem_blocks;
        ++num_elems;
      }
    }
  }
  for (const auto& bars : groups.curve2bars) {
    if (!bars.empty()) {
      ++elem_blocks;
      num_elems += static_cast<GO>(bars.size());
    }
  }
  for (LO f = 0; f < mesh.num_cad_faces; ++f) {
    for (const auto* list : {&groups.face2tris[static_cast<std::size_t>(f)],
                             &groups.face2quads[static_cast<std::size_t>(f)]}) {
      if (!list->empty()) {
        ++elem_blocks;
        num_elems += static_cast<GO>(list->size());
      }
    }
  }
  out << "$Elements\n"
      << elem_blocks << ' ' << num_elems << ' ' << (num_elems > 0 ? 1 : 0) << ' ' << num_elems
      << '\n';
  GO tag = 1;
  // Gmsh's element types of quads and lines of order 1..5, and its node order of quads (the
  // recursive one of CGNS).
  static constexpr std::array<int, 6> kQuadType{0, 3, 10, 36, 37, 38},
      kLineType{0, 1, 8, 26, 27, 28};
  const int order = mesh.order;
  const std::vector<int> perm =
      mesh::quad_permutation(order, mesh::quad_grid_positions_recursive(order));
  if (options.msh_corner_elements) {
    for (std::size_t k = 0; k < entity2nodes[0].size(); ++k) {
      const auto& nodes = entity2nodes[0][k];
      if (nodes.empty()) continue;
      out << "0 " << k + 1 << " 15 1\n" << tag++ << ' ' << nodes.front() + 1 << '\n';
    }
  }
  for (std::size_t c = 0; c < groups.curve2bars.size(); ++c) {
    const auto& bars = groups.curve2bars[c];
    if (bars.empty()) continue;
    out << "1 " << c + 1 << ' ' << kLineType[static_cast<std::size_t>(order)] << ' ' << bars.size()
        << '\n';
    for (GO e : bars) {
      out << tag++;
      for (int k = 0; k <= order; ++k)
        out << ' ' << detail::bar_node(mesh, static_cast<std::size_t>(e), k) + 1;
      out << '\n';
    }
  }
  for (LO f = 0; f < mesh.num_cad_faces; ++f) {
    const auto& tris = groups.face2tris[static_cast<std::size_t>(f)];
    if (!tris.empty()) {
      out << "2 " << f + 1 << " 2 " << tris.size() << '\n';
      for (GO e : tris) {
        const auto& t = mesh.triangles[static_cast<std::size_t>(e)];
        out << tag++ << ' ' << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
      }
    }
    const auto& quads = groups.face2quads[static_cast<std::size_t>(f)];
    if (!quads.empty()) {
      out << "2 " << f + 1 << ' ' << kQuadType[static_cast<std::size_t>(order)] << ' '
          << quads.size() << '\n';
      for (GO e : quads) {
        out << tag++;
        for (int k : perm)
          out << ' ' << detail::quad_node(mesh, static_cast<std::size_t>(e), k) + 1;
        out << '\n';
      }
    }
  }
  QSMESH_CHECK(tag == num_elems + 1, "MSH output " << path << ": element count mismatch");
  out << "$EndElements\n";
  out.close();
  atomic.commit();
}

}  // namespace qsmesh::io
