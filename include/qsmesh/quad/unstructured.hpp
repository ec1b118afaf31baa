// The unstructured all-quad mesh of one CAD face (paper 000 Sec. 5): cross-field-guided frontal
// point insertion on the halved quantized curve meshes (Sec. 5.1) and their Delaunay
// triangulation, triangle recombination weighted by the cross-field alignment (Sec. 5.2), midpoint
// subdivision onto the full curve meshes, smoothing (Sec. 5.3). Faces without a cross field (or
// where that path fails or folds a quad) take the Delaunay kernel's own refinement at a uniform
// size instead.
#pragma once

#include <span>
#include <string>

#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/mesh/improve.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/quad/frontal.hpp"
#include "qsmesh/quad/recombine.hpp"

namespace qsmesh::quad {

struct UnstructuredOptions {
  /// Largest final edge length (model units, > 0): the uniform size of the fallback path, whose
  /// triangulation uses twice it.
  double size = 0;
  /// Frontal insertion (Sec. 5.1); its spacing_factor (2) turns the size map into the spacing of
  /// the halved triangulation.
  FrontalOptions frontal;
  bool use_frontal = true;  ///< false: always the fallback path
  /// When an edge of the frontal triangulation is longer than this times the spacing at its
  /// midpoint (the frontal points left room the kernel spanned with thin triangles), the
  /// triangulation is redone with the frontal points and the kernel's size refinement (0: never).
  /// wing_fuselage.step, size factor 0.08: the fuselage face got folded quads from such thin
  /// triangles and fell back (4 s of the 4.3 s unstructured stage). 2.5 rather than 3 (twelfth
  /// session, default size 0.02): the built-in wing-body example 104 -> 85 interior irregular
  /// vertices, SICN 0.195 / 0.892 -> 0.214 / 0.909 (2262 -> 2416 vertices); wing_fuselage 197 ->
  /// 191, SICN min 0.021 -> 0.033 (a fan of long triangles at the fuselage's tail tip); the other
  /// shared models, and all six at their reference vertex counts, give byte-identical meshes.
  /// 2.0 changes wing_fuselage at its reference count (179 -> 176, SICN avg 0.8801 -> 0.8798).
  double refill_edge_ratio = 2.5;
  /// When the recombined frontal mesh still folds a quad (it then falls back to subdividing every
  /// triangle) and the triangulation still has such long edges, the face is triangulated once
  /// more with mesh::TriangulateOptions::shorten_ratio set to this, and the better valid mesh (the
  /// higher minimum SICN) is kept (0: never). wing_fuselage.step at size factor 0.005: a fairing
  /// sliver (face 12), whose parametrisation is 50 times stretched unevenly toward its tip, got a
  /// fan of triangles 60 long across a strip 8 wide; it fell back with 42 interior irregular
  /// vertices, SICN 0.084 / 0.721, and now keeps the frontal path (14, 0.157 / 0.80). Faces whose
  /// frontal mesh is valid are not touched.
  double retry_shorten_ratio = 0.7;
  /// Recombination (Sec. 5.2): greedy, then augmenting paths pair the triangles left alone.
  RecombineOptions recombine{.augment_depth = 30, .augment_min_sicn = 0.1};
  /// 3D clean-up of the frontal triangulation before recombination: interior vertices of triangles
  /// with an angle below 40 degrees moved to their centroids when that helps (no tangent-plane
  /// search: measured slower and no better here).
  mesh::ImproveOptions improve_triangles{
      .target_angle_deg = 40, .rounds = 4, .move_vertices = true, .compass_search = false};
};

/// What the frontal path reads for one face, from the earlier stages (all from the same face).
struct FaceFields {
  const mesh::FaceMesh* background = nullptr;               ///< background triangulation
  const crossfield::FaceCrossField* cross_field = nullptr;  ///< its cross field (null: none)
  std::span<const double> sizes;                            ///< size map per background vertex
};

/// What happened on one face.
struct UnstructuredReport {
  bool ok = false;  ///< an all-quad mesh with every quad valid (SICN > 0)
  /// The face did not get the intended method: the frontal path was wanted (options.use_frontal)
  /// but the face has no fields or the path failed, or recombination failed or folded a quad and
  /// every triangle was subdivided instead.
  bool fell_back = false;
  bool frontal = false;  ///< the mesh comes from the frontal triangulation (else the fallback path)
  std::int64_t frontal_points = 0;  ///< interior points the frontal insertion placed
  std::string error;                ///< the error met, with stage and face id
  double sicn_min = 0;              ///< of the face's quads
  std::int64_t quads = 0;
  /// Every field, once (visit(name, member)): what the ranks exchange (parallel/record.hpp).
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("ok", self.ok);
    visit("fell_back", self.fell_back);
    visit("frontal", self.frontal);
    visit("frontal_points", self.frontal_points);
    visit("error", self.error);
    visit("sicn_min", self.sicn_min);
    visit("quads", self.quads);
  }
};

/// All-quad mesh of face f on `full`, the final curve meshes (every loop of the face even: see
/// quantize::quantize_curves). The triangulation is made on the face's halved boundary
/// (background::halved_face_boundary: every other full boundary vertex) and subdivided back onto
/// the full one. `fields`: the face's background mesh, cross field and size
/// map; with all three (and options.use_frontal) the triangulation is the frontal one (Sec. 5.1,
/// spacing options.frontal.spacing_factor x size map) and the recombination is weighted by the
/// cross at each triangle. If that path throws, or neither its recombined nor its subdivided
/// triangles give valid quads, the face falls back to the Delaunay refinement at uniform size 2 x
/// options.size. Never throws for a face-level failure: the report says what happened and an
/// empty mesh is returned when nothing valid could be made.
[[nodiscard]] mesh::FaceMesh mesh_face_unstructured(const cad::CadModel& model, LO f,
                                                    std::span<const mesh::CurveMesh> full,
                                                    const FaceFields& fields,
                                                    const UnstructuredOptions& options,
                                                    UnstructuredReport* report);

}  // namespace qsmesh::quad
