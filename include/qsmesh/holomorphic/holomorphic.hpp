// Quad meshes with the fewest singularities on topological poly-annuli from holomorphic 1-forms
// (paper 004): a basis of the holomorphic 1-forms whose real part is tangent to every boundary
// (Sec. 4, "Exact / Non-exact / Conjugate Harmonic Forms"), the area-distortion energy over their
// real combinations and its minimisation (Eqs. 4.9-4.11), the zeros of the chosen form (the
// singularities of the quad mesh, Eq. 4.12 and the winding rule after it), and the quad mesh of a
// topological annulus (b = 2: no zero, the form integrates to a regular grid).
//
// Everything works on one face's background triangulation (mesh::FaceMesh) with its 3D points:
// cotangent weights are intrinsic, so planar and curved faces are treated alike.
#pragma once

#include <array>
#include <complex>
#include <span>
#include <string>
#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/mesh/delaunay.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/smooth/smooth.hpp"

namespace qsmesh::holomorphic {

/// A face's triangulation as a topological surface: the copies of a vertex on a seam (same corner,
/// or same vertex of the same curve mesh) merged into one, edges numbered, boundary loops found.
struct PolyAnnulus {
  bool ok = false;     ///< genus 0 with at least 2 boundary loops (else `reason` says why not)
  std::string reason;  ///< why the surface is not a poly-annulus
  std::vector<Vec3> points;                  ///< merged vertices
  std::vector<LO> face2merged;               ///< FaceMesh vertex -> merged vertex
  std::vector<std::array<LO, 3>> triangles;  ///< merged corners, FaceMesh order and orientation
  std::vector<std::array<LO, 2>> edges;      ///< (a, b) with a < b: the orientation of 1-forms
  std::vector<std::array<LO, 3>> tri_edges;  ///< edge k of a triangle joins corners k and k + 1
  std::vector<std::array<LO, 2>>
      edge_tris;  ///< the triangles of an edge (second kNoIndex: boundary)
  /// Boundary loops as closed vertex cycles, each traversed with the surface on its left (the
  /// direction of its edges in their triangles); loops[0] is the longest (the exterior boundary
  /// gamma_0 of the paper), the others are the interior boundaries gamma_1 .. gamma_n.
  std::vector<std::vector<LO>> loops;
  std::vector<double> loop_length;
  std::vector<LO> edge_loop;  ///< loop of a boundary edge, kNoIndex for interior edges
  int euler = 0;              ///< V - E + F (2 - b for a poly-annulus)
  [[nodiscard]] LO num_vertices() const { return static_cast<LO>(points.size()); }
  [[nodiscard]] LO num_edges() const { return static_cast<LO>(edges.size()); }
  [[nodiscard]] LO num_interior_loops() const { return static_cast<LO>(loops.size()) - 1; }
};

/// Builds the PolyAnnulus of `mesh` (its triangles; quads are ignored). Precondition: triangles
/// oriented consistently (as mesh_face_background makes them). Never throws for a surface of
/// another topology: ok is false and reason says why (not a manifold, several components, genus
/// > 0, fewer than 2 boundary loops).
[[nodiscard]] PolyAnnulus poly_annulus(const mesh::FaceMesh& mesh);

struct BasisOptions {
  linalg::SolverOptions solver;  ///< the cotangent Laplacians' solver
};

/// The holomorphic 1-form basis of a poly-annulus with n = b - 1 interior boundaries (Sec. 4):
///  - f[j]: harmonic with f = 1 on gamma_{j+1}, 0 on the other loops (Eq. 4.3); exact[j] = df[j];
///  - omega[k]: harmonic (Neumann: tangent to every boundary), omega = eta + dh (Eq. 4.5), with eta
///    the Poincare dual of a shortest path in the dual graph from gamma_{k+1} to gamma_0 (the cut;
///    the paper's Eq. 4.4 builds the same cohomology class from a primal cut); scaled so that its
///    period on gamma_{k+1} is 1 and 0 on the other interior loops;
///  - conj[k][j]: *omega[k] = sum_j conj[k][j] df[j] (Theorem 1.2, Eq. 4.7);
///  - phi_k = omega[k] + i *omega[k] (Eq. 4.8), one value per edge (edges[e] oriented a -> b).
/// Both Laplacians (Dirichlet on the loops, and Neumann with one vertex pinned) are factorized
/// once and serve all their right-hand sides.
struct HolomorphicBasis {
  LO n = 0;
  std::vector<double> weights;  ///< cotangent weight of each edge (half the sum of cotangents)
  std::vector<std::vector<double>> f, exact, omega, star_omega;
  std::vector<std::vector<double>> conj;
  std::vector<std::vector<std::complex<double>>> phi;
  /// A[m][j] = integral of omega_m ^ df_j (Eq. 4.1): Stokes makes it +-identity; its distance to
  /// that is a check of the discretisation.
  std::vector<std::vector<double>> wedge;
  int factorizations = 0, solves = 0;
  double seconds = 0;  ///< wall time of the basis (cuts, weights, solves, conjugates)
};

/// The basis of a poly-annulus (ok). Throws qsmesh::Error when a Laplacian cannot be factorized
/// or the conjugate system is singular (a degenerate triangulation). `lane` may be null (Eigen).
[[nodiscard]] HolomorphicBasis holomorphic_basis(const PolyAnnulus& surface,
                                                 const BasisOptions& options,
                                                 linalg::SolverLane* lane);

/// The real combination sum_k lambda[k] phi_k, per edge.
[[nodiscard]] std::vector<std::complex<double>> combine(const HolomorphicBasis& basis,
                                                        std::span<const double> lambda);

/// Area of each triangle under the metric |phi|^2 (Sec. 4, "Optimization"): 1/2 Im(conj(phi(e1))
/// phi(e2)) with e1, e2 the triangle's first two edges directed counter-clockwise.
[[nodiscard]] std::vector<double> phi_areas(const PolyAnnulus& surface,
                                            std::span<const std::complex<double>> phi);

struct EnergyOptions {
  int max_iterations = 200;
  /// Stops when an iteration lowers the energy by less than this fraction of it, or when the
  /// gradient norm falls below gradient_tolerance * (energy + total area^2) / |lambda|.
  double relative_decrease = 1e-12;
  double gradient_tolerance = 1e-10;
};

struct EnergyResult {
  std::vector<double> lambda;  ///< the minimiser's coefficients
  std::vector<double> energy;  ///< energy before the first iteration, then after each
  int iterations = 0;
  bool converged = false;  ///< a stopping rule held (else max_iterations)
  double seconds = 0;
};

/// E(lambda) = sum over triangles of (area_lambda - area)^2 (Eq. 4.9), with the 3D areas.
[[nodiscard]] double area_energy(const PolyAnnulus& surface, const HolomorphicBasis& basis,
                                 std::span<const double> lambda);

/// Minimises E over real lambda (Eq. 4.10): Newton steps on the n x n system (gradient Eq. 4.11),
/// a gradient step when the Hessian is not positive definite, each with a backtracking line search
/// that accepts only a decrease, so the logged energy decreases monotonically. Starts from all
/// lambda equal, scaled so the total areas agree.
[[nodiscard]] EnergyResult minimize_area_distortion(const PolyAnnulus& surface,
                                                    const HolomorphicBasis& basis,
                                                    const EnergyOptions& options);

/// A zero of a 1-form: an interior vertex around which phi turns (order + 1) times (the winding of
/// the immersed one-ring, Sec. 4 "Quad-mesh generation"), or a triangle that phi flips: phi is
/// linear on a triangle, so a zero that falls inside one (not on a vertex) shows as that triangle's
/// image turned over, and counts as a simple zero there.
struct Zero {
  LO vertex = kNoIndex;    ///< merged vertex (kNoIndex: a flipped triangle)
  LO triangle = kNoIndex;  ///< the flipped triangle (kNoIndex: a vertex)
  int order = 0;
};

struct ZeroReport {
  /// Interior vertices with winding != 1 (order may be < 0), then flipped triangles (order 1).
  std::vector<Zero> interior;
  /// Boundary vertices whose immersed half ring turns by more than 1.5 pi (a zero on the
  /// boundary: the horizontal boundary would bend there).
  std::vector<LO> boundary;
  /// Sum of the interior orders (flipped triangles included) + sum over boundary vertices of
  /// (turn - pi) / (2 pi): b - 2 by the Poincare-Hopf theorem for a form whose boundary is
  /// horizontal; the discrete sum is exactly that (each triangle's image angles sum to pi, or -pi
  /// when flipped), so a deviation means a form that is not horizontal on the boundary.
  double index_sum = 0;
  LO flipped = 0;  ///< triangles of negative phi-area (images of zero area at corners excluded)
};

/// The zeros of phi (per-edge values) on `surface`.
[[nodiscard]] ZeroReport find_zeros(const PolyAnnulus& surface,
                                    std::span<const std::complex<double>> phi);

/// The grid of mesh_annulus: u of its interior points is discrete-harmonic over the grid (SOR).
struct GridOptions {
  int max_sweeps = 20000;   ///< 0: columns straight between the two loops' points
  double relaxation = 1.9;  ///< SOR factor in (0, 2)
  double tolerance = 1e-6;  ///< stop when no point moves by more than this fraction of a column
};

/// A critical trajectory (paper 004 Sec. 4, "Quad-mesh generation"): a prong of the horizontal
/// (Im of the integral of phi constant) or vertical (Re constant) trajectory through a zero,
/// traced triangle by triangle in the flat charts of phi.
struct Trajectory {
  std::size_t zero = 0;  ///< index in ZeroReport::interior of the zero it leaves
  bool horizontal = true;
  std::vector<Vec3> points;  ///< polyline on the triangulation, from the zero's neighbourhood
  enum class End { Boundary, Zero, Limit };
  End end = End::Limit;      ///< a boundary loop, a zero's neighbourhood, or max_steps reached
  LO end_loop = kNoIndex;    ///< the loop hit (End::Boundary)
  std::size_t end_zero = 0;  ///< the zero reached (End::Zero)
};

struct TraceOptions {
  int max_steps = 100000;  ///< triangles crossed by one trajectory at most
};

/// The critical trajectories of phi from each zero of `zeros` (ZeroReport::interior with order
/// >= 1). Around a zero, the boundary of the triangles touching it (its vertex, or the flipped
/// triangle's three) is immersed by integrating phi from the zero: the polygon winds order + 1
/// times, and each crossing of the real (imaginary) axis starts a horizontal (vertical) prong,
/// 2 (order + 1) of each, traced outwards until it meets a boundary loop or the neighbourhood of
/// a zero.
[[nodiscard]] std::vector<Trajectory> critical_trajectories(
    const PolyAnnulus& surface, std::span<const std::complex<double>> phi, const ZeroReport& zeros,
    const TraceOptions& options);

struct HolomorphicOptions {
  BasisOptions basis;
  EnergyOptions energy;
  GridOptions grid;
  /// mesh_annulus refuses a loop that turns by more than this at a CAD corner (3D angle between
  /// its edges there, degrees).
  double max_corner_turn_deg = 30;
  /// mesh_poly_annulus (b >= 3) refuses a loop that turns by more than this at a CAD corner. A
  /// 90-degree corner of a plate becomes a boundary vertex with two quads of the patch's grid
  /// (about 45 degrees each, SICN about 0.7 there; a rounded plate's tangent corners are not
  /// corners); the face's SICN check (keep_holomorphic) still rejects a folded result.
  double max_patch_corner_turn_deg = 100;
  /// mesh_poly_annulus (b >= 3) smooths its patches' grids (smooth::smooth_face, boundary locked;
  /// rolled back when the minimum SICN would drop): next to a zero the form's grid has quads that
  /// are thin in 3D (a critical curve close to a loop on one side), which the smoothing widens.
  bool smooth_patches = true;
  smooth::SmoothOptions smoothing;
  /// mesh_group (group.hpp): Laplacian sweeps over the group mesh's interior vertices when
  /// smooth_patches (smooth_face works in one parameter plane, a group spans several).
  int group_sweeps = 10;
};

/// What the holomorphic path did on one face.
struct HolomorphicReport {
  bool ok = false;             ///< a mesh was made
  std::string reason;          ///< why not (the default path then meshes the face)
  LO boundaries = 0;           ///< boundary loops of the background triangulation
  LO zeros = 0;                ///< interior zeros of the optimised form
  int rows = 0, columns = 0;   ///< b >= 3: rows summed over the patches, most columns of one
  int patches = 0;             ///< b >= 3: flat cylinders between critical levels (0 for b = 2)
  std::vector<double> energy;  ///< per iteration
  double basis_seconds = 0, energy_seconds = 0, seconds = 0;
};

/// The quad mesh of a topological annulus (b = 2) from its holomorphic 1-form: the form is
/// integrated over the background triangulation (a multi-valued u, a single-valued v constant on
/// each boundary), the N points of each final boundary loop are placed on it, and the grid has N
/// columns and M = round(height / (period / N)) rows (at least 1), so its quads are as square as
/// the counts allow; a seam curve crossing the face becomes one column and sets M to its count.
/// Rows are levels of v; along them u is discrete-harmonic over the grid (GridOptions), so that a
/// difference between the two loops' spacings spreads over the rows. Interior grid points are
/// mapped back through the background triangle that contains them and
/// projected on `surface`.
///  - `background`: the face's background triangulation; `loops`: the face's final boundary
///    (background::face_boundary on the final curve meshes).
/// Returns an all-quad FaceMesh oriented like the background (seam vertices in two copies), or an
/// empty mesh with report->reason when the face is not an annulus, its two loops have different
/// counts or a sharp corner (HolomorphicOptions::max_corner_turn_deg), a seam's count cannot match,
/// or a point cannot be located. Never throws for a face-level failure.
[[nodiscard]] mesh::FaceMesh mesh_annulus(const mesh::FaceMesh& background,
                                          std::span<const mesh::BoundaryLoop> loops,
                                          const cad::FaceGeometry& surface,
                                          const HolomorphicOptions& options,
                                          HolomorphicReport* report);

/// The quad mesh of a poly-annulus (paper 004 Sec. 4, "Quad-mesh generation"); b = 2 is
/// mesh_annulus. For b >= 3: v = Im of the integral of the optimised form is single valued
/// (the conjugates are exact), harmonic, constant on each loop; its saddles are the zeros of the
/// form. The levels of the saddles and of the loops cut the surface into flat cylinders (the
/// critical horizontal trajectories bound them), each meshed as a grid: its side on a loop takes
/// that loop's final points; a side on a cut takes points at equal steps of u, shared with the
/// cylinders across the cut, a saddle being a point of all three; rows at equal steps of v
/// (round(height * columns / period) of them), u harmonic over the grid (GridOptions), each
/// point placed on its row's level curve and projected on `surface`. A simple zero becomes a
/// valence-8 vertex (two quads in each of the two lobes' grids, four in the grid that passes it
/// twice), so the mesh has exactly b - 2 of them and no other irregular vertex.
/// Conformity across a cut needs the counts on each side to sum to the same: the loops' counts
/// must add up as the form's periods do (for a plate with holes on which v is lowest on the outer
/// loop: outer count = the holes' counts summed). Returns an empty mesh with report->reason when
/// they do not, when a loop turns by more than max_patch_corner_turn_deg at a corner, has a zero of
/// the form (v crossing its level next to it), when a zero is not simple, two zeros share a
/// critical curve, the face has a seam, or a level curve is not one closed curve. Never throws for
/// a face-level failure.
[[nodiscard]] mesh::FaceMesh mesh_poly_annulus(const mesh::FaceMesh& background,
                                               std::span<const mesh::BoundaryLoop> loops,
                                               const cad::FaceGeometry& surface,
                                               const HolomorphicOptions& options,
                                               HolomorphicReport* report);

struct AnnulusCountOptions {
  /// A curve's count may move by even steps up to this fraction of its ideal value
  /// (Quantization::ideal) away from it, and always by 2 (qstruct::BalanceOptions::max_change).
  double max_change = 0.35;
  /// Faces whose loops turn by more than this at a corner are left alone: mesh_annulus refuses
  /// them (HolomorphicOptions::max_corner_turn_deg).
  double max_corner_turn_deg = 30;
  /// Loops whose counts differ by more than this fraction of the larger are left apart: the
  /// moves reach other faces through the chords (t20_data's annulus, 224 against 312 edges, made
  /// equal cost its chamfer faces 4 to 10 irregular vertices each, docs/benchmarks.md).
  double max_loop_difference = 0.2;
};

struct AnnulusCountReport {
  LO annuli = 0;          ///< faces that are annuli (two loops, seams merged) without sharp corner
  LO equal_before = 0;    ///< of those, with equal loop counts from the quantization
  LO equal_after = 0;     ///< and after balancing
  LO curves_changed = 0;  ///< curves whose count changed
};

/// The two boundary chains of face f when its topology is an annulus: two loops and no seam, or
/// one loop with one seam curve used twice (a cylinder's side), the seam's uses removed; no
/// degenerate curve. Each chain lists the curve uses in loop order. Empty otherwise.
[[nodiscard]] std::vector<std::vector<cad::CurveUse>> annulus_chains(const cad::CadModel& model,
                                                                     LO f);

/// Loop counts a grid can join (mesh_annulus needs equal counts on the two loops; the
/// quantization, which does not know the method, leaves them apart): for `--method holomorphic`
/// and `auto`, every face that is an annulus (annulus_chains) without a corner sharper than
/// options.max_corner_turn_deg (measured on the background curve meshes `curves`) and whose two
/// loops' counts differ gets them equal, in face id order: the short loop's free curves raised
/// by even steps, then, where their room (options.max_change) does not suffice, the long loop's
/// lowered. A step moves one variable by 2 edges on each of its curves: a chord (curve2chord:
/// the curves of a chord move together, so that the four-sided faces across it keep their equal
/// opposite counts) or a curve in no chord, the one of fewest curves, then least count / ideal
/// (up; most, down), then first found; never past what the loops still differ by. Loops further
/// apart than options.max_loop_difference are left alone. A variable moves only when none of its
/// curves is in `fixed` (user prescriptions), degenerate, on the other loop, or on a loop of an
/// annulus done before (so that it stays balanced). A face that cannot be balanced keeps its
/// counts. Parities and loop parities are kept (even steps). Deterministic; returns the new
/// counts (`edges` otherwise).
[[nodiscard]] std::vector<int> balance_annulus_counts(
    const cad::CadModel& model, std::span<const mesh::CurveMesh> curves, std::span<const int> edges,
    std::span<const double> ideal, std::span<const LO> curve2chord, std::span<const LO> fixed,
    const AnnulusCountOptions& options, AnnulusCountReport* report = nullptr);

/// The per-face method of the quad stage.
enum class Method { Default, Holomorphic, Auto };

/// Parses "default", "holomorphic", "auto"; throws qsmesh::InputError otherwise.
[[nodiscard]] Method parse_method(const std::string& text);

/// Whether a face keeps its holomorphic mesh: Holomorphic keeps any valid one (report ok, all
/// quads, SICN min > 0); Auto keeps it only with fewer interior irregular vertices than the default
/// mesh and SICN min and avg each no lower than the default's minus `sicn_tolerance`; Default
/// never.
[[nodiscard]] bool keep_holomorphic(Method method, const HolomorphicReport& report,
                                    const mesh::FaceQuadStats& holomorphic,
                                    const mesh::FaceQuadStats& by_default, double sicn_tolerance);

}  // namespace qsmesh::holomorphic
