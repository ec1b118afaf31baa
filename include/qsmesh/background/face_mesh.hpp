// Background triangulation of one CAD face (paper 000 Sec. 3.1: the triangulation on which the
// cross field is computed), conforming to the locked curve meshes.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "qsmesh/background/size.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/delaunay.hpp"
#include "qsmesh/mesh/improve.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::background {

struct BackgroundOptions {
  SizeOptions sizes;
  mesh::TriangulateOptions triangulate;
  mesh::ImproveOptions improve;  ///< 3D clean-up of small angles after the kernel
};

/// What happened on one face.
struct FaceReport {
  LO face = kNoIndex;
  bool ok = false;         ///< false: the face could not be meshed and is absent from the output
  bool fell_back = false;  ///< true: refinement failed and the boundary-only triangulation was kept
  std::string error;       ///< the error met, if any (with stage and face id)
  double seconds = 0;
  /// Every field, once (visit(name, member)): what the ranks exchange (parallel/record.hpp).
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("face", self.face);
    visit("ok", self.ok);
    visit("fell_back", self.fell_back);
    visit("error", self.error);
    visit("seconds", self.seconds);
  }
};

/// The boundary loops of face f in its parameter plane, built from the curve meshes: each curve
/// use contributes its vertices in traversal order (the last one is the first of the next use),
/// with uv from the face's pcurve of that use, xyz and classification from the curve mesh.
[[nodiscard]] std::vector<mesh::BoundaryLoop> face_boundary(
    const cad::CadModel& model, LO f, const cad::FaceGeometry& surface,
    std::span<const mesh::CurveMesh> curves);

/// One segment of a halved boundary loop (see halved_face_boundary): the full boundary vertex
/// that midpoint subdivision puts at its middle.
struct HalvedSegment {
  /// The full loop's vertex between the segment's ends: a curve vertex (vclass.dim 1, its index
  /// in the full curve mesh), or a corner (dim 0) where a loop takes an odd count up to it, or
  /// another copy of a pole on a degenerate curve's segment (uv halfway along the segment).
  mesh::BoundaryPoint mid;
  /// For a curve vertex: whether the segment runs along the curve mesh (its first end is full
  /// vertex mid.vclass.index - 1); false when it runs backwards.
  bool forward = true;
  /// The curves of the two full edges the segment spans (equal unless mid is a corner).
  LO curve_before = kNoIndex, curve_after = kNoIndex;
};

/// The boundary of face f before midpoint subdivision (paper 000 Sec. 5.2), for any counts that
/// make every loop even (quantize::quantize_curves).
struct HalvedBoundary {
  /// Every other vertex of each loop of face_boundary(model, f, surface, full): curve vertices
  /// keep the index of their full curve mesh (so consecutive vertices of one curve differ by 2).
  std::vector<mesh::BoundaryLoop> loops;
  /// segments[l][k]: what lies between loops[l].points[k] and points[k + 1].
  std::vector<std::vector<HalvedSegment>> segments;
  /// Per loop: 0 when the loop's first corner is a halved vertex, 1 when it is a midpoint.
  std::vector<int> offsets;
};

/// The halved boundary of face f from its final curve meshes `full`. Each loop of
/// face_boundary(full), with a degenerate curve counted as 2 edges (its two pole images and a
/// third copy between them), has an even number N of edges; the halved loop keeps the vertices
/// at even positions from one of two starts: the loop's first vertex (offset 0) or the next one
/// (offset 1). With every count of the loop even, offset 0 puts every corner on a halved vertex:
/// the halved meshes of the curves, as quantize::place_vertices(halved = true) makes them. A
/// curve with an odd count shifts the corners after it to odd positions: such a corner lies at
/// the middle of a halved segment joining the curve vertices beside it, where subdivision puts
/// it back, and it gets two sub-quads. The offset is chosen per loop so that the corners left at
/// midpoints are as flat as can be (cost |angle / 90 degrees - 2| per corner, the 3D angle
/// between its two full edges; offset 0 on ties), and a pole is never one (a pole at a midpoint
/// would make collapsed quads). Throws qsmesh::Error when a loop has an odd number of edges or
/// both offsets put a pole at a midpoint (quantize_curves prevents both), and what face_boundary
/// throws.
[[nodiscard]] HalvedBoundary halved_face_boundary(const cad::CadModel& model, LO f,
                                                  const cad::FaceGeometry& surface,
                                                  std::span<const mesh::CurveMesh> full);

/// Triangulates face f with sizes adapted to its curvature (SizeOptions), the boundary locked to
/// `curves`. Never throws for a face-level failure: when refinement fails the boundary-only
/// triangulation is returned (report->fell_back), when that fails too an empty mesh
/// (report->ok false); `report` receives the details. Interior vertices are classified on face f.
[[nodiscard]] mesh::FaceMesh mesh_face_background(const cad::CadModel& model, LO f,
                                                  std::span<const mesh::CurveMesh> curves,
                                                  const BackgroundOptions& options,
                                                  FaceReport* report);

/// The same on given boundary loops of face f (face_boundary, or the loops of a HalvedBoundary).
[[nodiscard]] mesh::FaceMesh mesh_face_background(const cad::CadModel& model, LO f,
                                                  std::span<const mesh::BoundaryLoop> loops,
                                                  const BackgroundOptions& options,
                                                  FaceReport* report);

}  // namespace qsmesh::background
