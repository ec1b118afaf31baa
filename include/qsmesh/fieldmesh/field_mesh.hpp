// Quad meshing of one CAD face from a cross field given by the user (paper 003): the field of
// Eq. 2 from singular points or per-vertex crosses, the compatibility checks (Eqs. 11, 16, 17,
// boundary indices from the corner angles of Table 1), the hole correction (Eqs. 18-20), the
// alignment by a harmonic rotation angle (Eq. 14), the heat-method reference frame on curved faces
// (Sec. 4), separatrices from the singularities and the concave corners, the partition into
// four-sided regions, their quantization on the face's fixed curve meshes, transfinite filling and
// smoothing.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/types.hpp"
#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::fieldmesh {

/// A singular point of a user field (paper 003 Eq. 2): position (model units, on or near the face)
/// and d, the index being d / 4 (d = 1: valence 3, d = -1: valence 5). A point on the face's
/// boundary (nearer to a boundary edge of the face's triangulation than a quarter of its length)
/// is a boundary singular point (Sec. 2.5) at the nearer curve vertex: it replaces the Table 1
/// index of that point (0 on a smooth curve), so the point gets 2 - d quads (d <= 1); it is a
/// corner of the partition when d = 1 and sends 1 - d separatrices when d < 0.
struct SingularPoint {
  Vec3 position;
  int d = 0;
};

/// Reference frame of a face's triangulation: per vertex the unit normal (oriented as the face)
/// and a unit tangent `ref` from which cross angles are measured.
struct Frame {
  std::vector<Vec3> normal, ref;
};

/// Frame of `tri` (a FaceMesh with triangles oriented along the face normal). Planar faces (every
/// normal within 1e-6 of the first): ref is the projection of the surface's du direction at the
/// first vertex, the same everywhere. Otherwise paper 003 Sec. 4, heat method: a tangent vector
/// put at vertex 0 is diffused by one implicit step of the vector heat equation (Eq. 21) with the
/// connection Laplacian (cotangent weights, the rotation between per-vertex bases on each edge),
/// t = (bounding-box diagonal)^2, and normalised at every vertex. Solved through linalg (`lane`
/// may be null). Throws qsmesh::Error at a pole or where the diffused vector vanishes.
[[nodiscard]] Frame face_frame(const mesh::FaceMesh& tri, const cad::FaceGeometry& surface,
                               linalg::SolverLane* lane);

/// Angle (radians, modulo pi/2) of the cross of Eq. 2 at every vertex of `tri`, measured from
/// frame.ref: sum_i d_i / 4 arg(z - a_i), z and a_i the parameter-plane images (a_i projected on
/// the surface). On a planar face with an isometric parametrization this is Eq. 2 itself; on a
/// curved one it is a smooth field with the same singular points and indices. Boundary singular
/// points (see SingularPoint) are left out of the product: the alignment turns the field there.
[[nodiscard]] std::vector<double> field_from_points(const mesh::FaceMesh& tri,
                                                    const cad::FaceGeometry& surface,
                                                    std::span<const SingularPoint> points);

/// Angle of a 3D direction at every vertex (one branch of the cross per vertex, projected on the
/// tangent plane; a zero vector gives angle 0), modulo pi/2, from frame.ref.
[[nodiscard]] std::vector<double> field_from_directions(const Frame& frame,
                                                        std::span<const Vec3> directions);

/// Compatibility of a field with one boundary loop (paper 003 Sec. 2.3 and 3).
struct LoopDegree {
  double field = 0;    ///< deg(u, Gamma) (Eq. 6), in turns, along the loop's traversal
  double aligned = 0;  ///< the degree a boundary-aligned field has there, corner indices included
  double corner_indices = 0;  ///< sum of the corner indices I(b) of Table 1 on the loop
};

struct Compatibility {
  std::vector<LoopDegree> loops;       ///< loops[0] is the outer loop
  bool ok = false;                     ///< Eq. 11 (one loop) / Eq. 16 (several) holds
  bool needs_hole_correction = false;  ///< Eq. 16 holds but Eq. 17 does not on some loop
  std::string reason;                  ///< when !ok: what fails, naming the equation
};

struct FieldMeshOptions {
  double step_factor = 0.2;      ///< separatrix step, times the mean boundary edge length
  double max_length_factor = 6;  ///< a separatrix longer than this times the perimeter fails
  int snap_range = 4;            ///< boundary ends move at most this many curve vertices
  /// Smoothing: the chord-weighted Laplace layout in the parameter plane with the boundary and the
  /// singular vertices fixed (they stay where the field puts them); with move_singular_points,
  /// also smooth::smooth_face (Winslow / angle-based kernels) that moves them too.
  bool move_singular_points = false;
  /// A result whose SICN min is below this is refused (stage "filling"): the face keeps its
  /// default mesh. On the shared models with --method separatrix, the faces below 0.2 were long
  /// regions bent by separatrices that pass close to a corner or to each other (mambo_s34:
  /// SICN min 0.005 of the model with them, docs/benchmarks.md).
  double min_sicn = 0.2;
  int smooth_iterations = 10;
  linalg::SolverOptions solver;
};

/// One four-sided region of the partition as the structured grid of its quads: ni x nj quads whose
/// (ni + 1) x (nj + 1) vertices are vertices[j * (ni + 1) + i] (ids of the face mesh's vertices, i
/// fastest), oriented as layout::Block: the quad at (i, j) is (i, j), (i + 1, j), (i + 1, j + 1),
/// (i, j + 1), counter-clockwise about the face normal. These are the blocks of the face for
/// block-structured output, so that no layout has to be extracted from its mesh.
struct RegionGrid {
  LO ni = 0, nj = 0;
  std::vector<GO> vertices;
  /// Every field, once (visit(name, member)): what the ranks exchange (parallel/record.hpp).
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("ni", self.ni);
    visit("nj", self.nj);
    visit("vertices", self.vertices);
  }
};

/// What happened on one face.
struct FieldMeshReport {
  LO face = kNoIndex;
  bool ok = false;
  std::string stage;   ///< the stage that failed (compatibility, separatrices, regions,
                       ///< quantization, filling), empty when ok
  std::string reason;  ///< why, one line
  Compatibility compatibility;
  int singularities = 0;  ///< interior singular points of the aligned field
  int separatrices = 0;   ///< traced (after merging)
  int regions = 0;        ///< four-sided regions
  mesh::FaceQuadStats stats;
  /// When ok: the regions as grids of the returned mesh's vertices, which they cover once (in the
  /// order of the mesh's quads, which are emitted region by region).
  std::vector<RegionGrid> grids;
};

/// The singular points of a discrete field (angles per vertex of `tri`): triangles around which the
/// field turns by a nonzero multiple of pi/2, with d = that turn / (pi/2), at their centroids
/// (positions), clusters of adjacent triangles merged.
[[nodiscard]] std::vector<SingularPoint> detect_singularities(const mesh::FaceMesh& tri,
                                                              std::span<const double> theta);

/// Paper 003 on face f with its final curve meshes `curves` (kept as they are: the result
/// conforms to the faces around) and a field given on a triangulation `tri` of the face whose
/// boundary vertices are those curve meshes' (mesh_face_background on `curves`): `theta` per
/// vertex of `tri` (field_from_points / field_from_directions, measured from frame.ref), `given`
/// the singular points the field was built from (empty: taken from the discrete field); those on
/// the boundary are boundary singular points (see SingularPoint), whose indices enter Eq. 11 and
/// the alignment's corner jumps (Eq. 15).
/// Returns the all-quad FaceMesh (boundary vertices classified as the curve meshes, interior ones
/// dim 2 on f); on failure an empty mesh and report->ok false with the stage and the reason. An
/// incompatible field (Eq. 11 or 16) fails at stage "compatibility"; never throws for a face-level
/// failure.
[[nodiscard]] mesh::FaceMesh mesh_face_from_field(
    const cad::CadModel& model, LO f, std::span<const mesh::CurveMesh> curves,
    const mesh::FaceMesh& tri, const Frame& frame, std::span<const double> theta,
    std::span<const SingularPoint> given, const FieldMeshOptions& options, linalg::SolverLane* lane,
    FieldMeshReport* report);

/// Compatibility of `theta` with face f (the loops of `tri`'s boundary, corner indices from the
/// corner angles by Table 1: I = (2 - round(angle / 90 deg)) / 4, or d / 4 at the boundary points
/// of `given`).
[[nodiscard]] Compatibility check_compatibility(const cad::CadModel& model, LO f,
                                                std::span<const mesh::CurveMesh> curves,
                                                const mesh::FaceMesh& tri, const Frame& frame,
                                                std::span<const double> theta,
                                                std::span<const SingularPoint> given = {});

}  // namespace qsmesh::fieldmesh
