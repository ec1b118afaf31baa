// Cross field of one CAD face (paper 000 Sec. 3): boundary-aligned cross field by multilevel heat
// diffusion on Crouzeix-Raviart edges (Sec. 3.1, Algorithm 1, boundary-condition extension), its
// singularities and the check against the Euler relation (Sec. 3.2, Sec. 1.3 Eq. 2), and its
// conformal scaling (Sec. 3.3, Eq. 8-9).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/types.hpp"
#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::crossfield {

/// How a diffusion level measures the change of the field between two of its iterations (the
/// level ends when the change is below CrossFieldOptions::tolerance).
enum class LevelChange {
  /// The largest change of any edge's (cos 4θ, sin 4θ): ||U(i+1) - U(i)||_inf of Algorithm 1.
  Max,
  /// The root mean square of the edges' changes, each edge weighted by its mass (a third of the
  /// area of its triangles). Near a singularity the cross turns by a right angle across a few
  /// edges of small area; as the finest levels move it by a cell at a time, the largest change
  /// stays of order 1 for tens of iterations while the rest of the face has long converged, and
  /// the level runs to max_iterations_per_level (mambo_s34's largest faces: 50 at every level).
  Rms,
};

/// The change between two iterates of the diffusion as `how` measures it. `before` and `after`
/// hold one pair (cos 4θ, sin 4θ) per edge, `mass` one weight (> 0) per pair.
[[nodiscard]] double level_change(std::span<const double> before, std::span<const double> after,
                                  std::span<const double> mass, LevelChange how);

/// True when a diffusion level has stalled: its area-weighted RMS change (level_change with
/// LevelChange::Rms) of the last iteration, rms.back(), is above `ratio` times the one `window`
/// iterations earlier. `rms` holds the level's changes, one per iteration so far. Converging
/// levels shrink their change by a factor of 3 or more per iteration and never stall; on the
/// finest levels, where singularities creep a cell at a time, the change decays by a few percent
/// per iteration or grows again (the perforated plate's last level: 0.127, 0.042, 0.021, 0.011,
/// 0.012 every 5 iterations, down to 1.1e-3 only at iteration 50). False when window <= 0 or
/// fewer than window + 1 changes are known.
[[nodiscard]] bool level_stalled(std::span<const double> rms, int window, double ratio);

struct CrossFieldOptions {
  int levels = 4;           ///< N diffusion levels (Algorithm 1), >= 1
  double tolerance = 1e-3;  ///< a level ends when its change (level_change) < tolerance
  LevelChange level_change = LevelChange::Max;
  int max_iterations_per_level = 50;
  /// A level also ends when it has stalled (level_stalled over its RMS changes, whatever
  /// level_change measures): after stall_window iterations whose RMS change fell by less than
  /// the factor stall_ratio. 0: never (the level runs until the tolerance or
  /// max_iterations_per_level).
  int stall_window = 0;
  double stall_ratio = 0.5;
  /// The stall rule's window on a solved face of revolution (compute_face_cross_field's `axis`
  /// given, its shortcut not taken), where stall_window is 0. Turning the field's singularities
  /// together about the axis changes its energy only through boundary features far away, so the
  /// levels drift and run to max_iterations_per_level, with an end point set by the cap, not by
  /// convergence (docs/benchmarks.md, "field6"). 0: such faces run as any other.
  int revolution_stall_window = 4;
  /// A level before the second-to-last that converges (change below tolerance) within this many
  /// iterations skips the intermediate levels: the next level solved is the last one, at α_final.
  /// Such a level shows a field that no longer moves as α shrinks, so the intermediate α, whose
  /// role is to let singularities settle progressively (Algorithm 1), would each cost a
  /// factorization for iterations that change nothing; the last level is kept because its α,
  /// (3 h_min)^2, is orders of magnitude below the others. A field still moving at a level (the
  /// wing-body example's leading-edge skin: 11, 5, 6, 22 iterations) runs every level.
  /// 0: every level is solved.
  int settled_level_iterations = 2;
  /// A level that settles (settled_level_iterations) on a field with no singularity inside the
  /// face ends the diffusion: the last level is not solved either. Such a field is set by its
  /// boundary, and the later levels would move it by far less than the tolerance, for a
  /// factorization each. A level that needs more iterations, even to a regular field, still goes
  /// through every level: the continuation through the intermediate α shapes the field
  /// (docs/benchmarks.md, "Settled regular fields end the diffusion").
  /// false: a settled level skips to the last one, which is always solved.
  bool settled_regular_ends = true;
  bool extend_boundary = true;   ///< Sec. 3.1 boundary-condition extension
  double acute_corner_deg = 45;  ///< artificial +1 singularity at CAD corners sharper than this
  /// Sec. 3.3 scaling, outliers clamped: H is clamped to its area-weighted quantiles q and 1 - q
  /// over the face (0: no clamping). H has logarithmic singularities at cusps and sharp corners;
  /// left as they are, exp(H) shrinks to the size floor there and the faces around fill with
  /// slivers (docs/architecture.md, "Decisions worth knowing").
  double scaling_quantile = 0.05;
  /// A face with a CAD corner sharper than this (degrees; a cusp, where two curves leave the
  /// corner tangentially) gets a uniform scaling, H = 0: at a cusp H has a singularity the
  /// quantile clamp does not tame. 0: never.
  double cusp_angle_deg = 2;
  /// A planar face whose boundary edges all lie along one cross (a rectilinear polygon in any
  /// rotation, holes and slits included: box walls, machined pockets and steps) has the constant
  /// cross as the exact solution of the boundary extension and of every diffusion level, no
  /// singularity, and H = 0 exactly (its rotation vanishes). Such a face gets that field without a
  /// solve (stats.solver "exact uniform", no level); the solved field differs from it by rounding
  /// only (test CrossField.UniformShortcutEqualsTheSolvedField). false: always solve.
  bool exact_uniform = true;
  /// A face on a surface of revolution (compute_face_cross_field's `axis`) whose sampled boundary
  /// edges all lie along the parallels or the meridians (a cylinder, cone, torus or sphere patch
  /// cut along them, a hole's wall, a fillet) takes the cross of the parallels and meridians
  /// without a diffusion solve (stats.solver "exact revolution"). Among the boundary-aligned
  /// fields without singularities it is the exact continuous minimiser of the smoothness energy:
  /// it is harmonic (the connection form of the orthogonal frame of a surface of revolution is
  /// divergence-free), and on a cylinder it is parallel, so H = 0 there without a solve; elsewhere
  /// the scaling is solved as usual. The face falls back to the diffusion when the field has a
  /// singularity (a pole inside) or breaks the Euler relation. On cylinders and cones the solved
  /// field differs from it by the discretisation only; on a torus tube the diffusion may add
  /// +- pairs where it gets no structured grid (test
  /// CrossField.RevolutionShortcutMatchesTheSolvedField). false: always solve.
  bool exact_revolution = true;
  linalg::SolverOptions solver;
};

struct Singularity {
  Vec3 position;
  int index = 0;  ///< +1 (valence 3) or -1 (valence 5)
  enum class Where { Vertex, Edge, Triangle, AcuteCorner } where = Where::Vertex;
  LO element =
      kNoIndex;  ///< glued vertex (Vertex, AcuteCorner), edge (Edge) or triangle (Triangle)
};

/// Whether an interior vertex of the quad mesh is to carry the singularity: every kind but the
/// artificial +1 at an acute CAD corner, which a corner quad holds.
[[nodiscard]] inline bool is_interior(const Singularity& s) {
  return s.where != Singularity::Where::AcuteCorner;
}

/// Eq. 2 of paper 000 with the corner contributions.
struct EulerCheck {
  int chi = 0;  ///< V - E + F of the glued triangulation
  int corner_term =
      0;  ///< sum over boundary CAD corners of k_c = 2 - round(angle / 90 deg) (acute: 1)
  int expected =
      0;          ///< 4 chi - corner_term: the sum of interior singularity indices Eq. 2 asks for
  int found = 0;  ///< sum of the indices in the singularity list (acute-corner ones included)
  bool consistent = false;  ///< found == expected
  /// Diagnostic: the boundary indices the computed field really has (sum over every boundary vertex
  /// of 2 + (rotation of the cross around it - 4 * angle) / 2 pi). The discrete index theorem makes
  /// (sum of interior cell indices) + field_boundary_term == 4 chi exactly; a mismatch between
  /// field_boundary_term and corner_term shows where the field disagrees with the CAD corners.
  int field_boundary_term = 0;
};

struct CrossFieldStats {
  int levels = 0;          ///< diffusion levels run
  int factorizations = 0;  ///< heat-system factorizations (one per level)
  int solves = 0;          ///< heat-system solves
  std::vector<int> iterations_per_level;
  int stalled_levels = 0;    ///< levels ended by the stall rule (CrossFieldOptions::stall_window)
  double seconds = 0;        ///< wall time of compute_face_cross_field
  int extension_solves = 0;  ///< Laplace solves of the boundary-condition extension (0 or 1)
  int dropped_pairs = 0;     ///< clusters of singular cells whose indices cancel (not listed)
  int high_index_cells = 0;  ///< cells of |index| >= 2 (listed as |index| singularities of +-1)
  std::string solver;        ///< name of the linear solver backend used
};

struct FaceCrossField {
  LO face = kNoIndex;
  // Glued triangulation: FaceMesh vertices with the same corner (dim 0) or the same curve vertex
  // (dim 1: curve id and index) are one vertex, so seams of periodic surfaces are interior.
  std::vector<Vec3> points;
  std::vector<std::array<LO, 3>> triangles;  ///< oriented along the face normal
  std::vector<LO> input2glued;               ///< FaceMesh vertex -> glued vertex
  std::vector<std::int8_t> vertex_dim;       ///< CAD dimension of each glued vertex (0, 1, 2)
  std::vector<std::array<LO, 2>> edges;      ///< (a, b) with a < b
  /// tri2edges[t][k]: edge joining triangles[t][k] and triangles[t][(k+1)%3].
  std::vector<std::array<LO, 3>> tri2edges;
  std::vector<std::uint8_t> boundary_edge;  ///< 1 when the edge has one triangle after gluing
  std::vector<std::uint8_t> fixed_edge;     ///< 1 when Dirichlet in the heat solves
  /// Per edge: (cos 4θ, sin 4θ) after projection, θ measured from the edge direction
  /// edges[e][0] -> edges[e][1], positive around the face normal.
  std::vector<Vec2> u;
  std::vector<double> u_norm;                   ///< per edge: |U| of the last unprojected solve
  std::vector<std::array<Vec3, 2>> directions;  ///< per triangle: two orthogonal unit branches
  std::vector<double> H, h;                     ///< per glued vertex: conformal scaling, h = exp(H)
  std::vector<Singularity> singularities;
  EulerCheck euler;
  CrossFieldStats stats;
};

/// Whole step 1 for one face: glue, Algorithm 1 (+BC extension), singularities (+acute corners),
/// Euler check, scaling. `background` is the face's background triangulation (FaceMesh of
/// background::mesh_face_background, triangles oriented along the face normal); `lane` may be null
/// (Eigen). A face without boundary (closed surface, e.g. a full sphere) has no Dirichlet data and
/// starts from a fixed direction projected on the surface. Throws qsmesh::Error on an empty mesh
/// or a solver failure; the caller logs the face and falls back. `axis`: the face's axis when it
/// lies on a surface of revolution (cad::revolution_axis), for CrossFieldOptions::exact_revolution
/// and revolution_stall_window.
[[nodiscard]] FaceCrossField compute_face_cross_field(
    const mesh::FaceMesh& background, const CrossFieldOptions& options, linalg::SolverLane* lane,
    const std::optional<cad::RevolutionAxis>& axis = std::nullopt);

/// The constant C of Sec. 3.3 giving about n_quads quads: C = -1/2 ln(N / ∫ e^{-2H}), the integral
/// over the glued triangulation (per triangle, the mean of e^{-2H} at its vertices times its area).
/// The size map is then h(x) = exp(H(x) + C) (model units).
[[nodiscard]] double scaling_constant(const FaceCrossField& cf, double n_quads);

/// What a caller still reads of a FaceCrossField (shrink_cross_field).
enum class CrossFieldUse {
  /// sizemap::face_sizes, scaling_constant and the guide below: glued points, triangles,
  /// input2glued, edges, H, h, directions, singularities.
  SizeMapAndGuide,
  /// The frontal point insertion (quad::FaceGuide: triangles, input2glued, directions) and the
  /// cavity remeshing (singularities).
  Guide,
};

/// Frees (capacity included) the arrays of `cf` that `use` does not read; euler and stats stay.
/// For a pipeline that holds every face's field from the cross-field stage to its unstructured
/// mesh: the edge unknowns (u, u_norm, tri2edges, flags) go once the field is made, the glued
/// geometry and the scaling once the size map is built. Block.stp at its reference count, one
/// rank: peak heap 101 -> 74 MB (docs/benchmarks.md).
void shrink_cross_field(FaceCrossField& cf, CrossFieldUse use);

// Stages of compute_face_cross_field, exposed for tests and tools.

/// Fills points, triangles, input2glued, vertex_dim, edges, tri2edges, boundary_edge of `cf`.
void glue_triangulation(const mesh::FaceMesh& background, FaceCrossField& cf);

}  // namespace qsmesh::crossfield
