// Local remeshing of quad meshes with disk quadrangulations (paper 000 Sec. 6.3.2): the choice of
// the replacement of a cavity by Eq. 15 under the allowed valence ranges, and the removal of the
// defects (interior valence >= 6, curve vertices of valence != 2, corners away from their ideal
// valence) of the quad mesh of one CAD face. Runs after the unstructured quad stage and its
// smoothing, before the larger cavity remeshing (Sec. 6.2).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/remesh/disk_table.hpp"
#include "qsmesh/smooth/smooth.hpp"

namespace qsmesh::remesh {

/// Where a cavity boundary vertex sits on the CAD model; also the priority order of Sec. 6.3.2
/// (corners first, then curves, then the interior of faces).
enum class VertexKind : std::uint8_t { corner = 0, curve = 1, interior = 2 };

/// A cavity: a topological disk of quads, described by its boundary cycle x_1..x_b
/// (counter-clockwise seen from the face normal). All vectors have b entries.
struct Cavity {
  std::vector<VertexKind> kind;
  std::vector<int> out_valence;    ///< n_out: quads at x_j outside the cavity
  std::vector<int> ideal_valence;  ///< n-bar: 4 inside a face, 2 on a curve, the corner's own
  /// Total valence today (n_out + today's n_in): keeping it is always allowed. Negative: the
  /// vertex must end in its allowed range (the defect being fixed).
  std::vector<int> current_valence;
};

/// Which vertex kinds must end in their allowed range (Sec. 6.3.2, priorities): fixing a corner
/// enforces corners only, fixing a curve vertex enforces corners and curves, fixing an interior
/// vertex enforces all three.
struct ChoiceOptions {
  VertexKind enforce_up_to = VertexKind::interior;
  /// Allowed total valence n_in + n_out of face-interior boundary vertices when enforced
  /// (Sec. 6.3.2: 3..5) and when relaxed (never below 3: a doublet is not a defect we may create).
  int interior_min = 3, interior_max = 5, relaxed_interior_max = 6;
  /// Curve vertices: exactly 2 when enforced; 1..3 when relaxed. Corners: exactly n-bar when
  /// enforced; 1..n-bar+1 when relaxed.
  int relaxed_curve_min = 1, relaxed_curve_max = 3;
};

/// A replacement: table entry `entry` placed on the cavity with boundary vertex k of the entry on
/// cavity vertex (rotation + k) mod b, or (rotation - k) mod b when `reversed` (the entry mirrored;
/// its quads are then reversed to stay counter-clockwise).
struct Replacement {
  LO entry = kNoIndex;  ///< kNoIndex: no allowed replacement
  int rotation = 0;
  bool reversed = false;
  int irregularity = 0;  ///< Eq. 15
  int num_interior = 0;
};

/// Cavity vertex index of the entry's boundary vertex k under `r`.
[[nodiscard]] inline int cavity_vertex(const Replacement& r, int k, int b) {
  return r.reversed ? ((r.rotation - k) % b + b) % b : (r.rotation + k) % b;
}

/// Eq. 15 for given valences inside the cavity: sum_j (n-bar_j - n_out_j - n_in_j)^2 over the
/// boundary plus sum_k (4 - n_k)^2 over the interior vertices.
[[nodiscard]] int irregularity(const Cavity& cavity, std::span<const int> in_valence,
                               std::span<const int> interior_valence);

/// True when a total valence `total` of a boundary vertex of kind `kind` (ideal `ideal`,
/// `current` today) is allowed: in the range of its kind (enforced or relaxed), or unchanged
/// (a defect already there is not made worse by being kept).
[[nodiscard]] bool valence_allowed(VertexKind kind, int ideal, int current, int total,
                                   const ChoiceOptions& options);

/// Paper 000 Sec. 6.3.2: the replacement minimising Eq. 15 among all entries of `table` with b
/// boundary vertices, all b rotations and both directions, whose totals are allowed
/// (valence_allowed). Ties: fewer interior vertices, then table order, rotation, direction.
/// Returns entry kNoIndex when b is not in the table or nothing is allowed.
[[nodiscard]] Replacement best_replacement(const DiskQuadTable& table, const Cavity& cavity,
                                           const ChoiceOptions& options);

/// The quads of replacement `r` on a cavity whose boundary vertices are `cycle`
/// (counter-clockwise), its interior vertices numbered first_new, first_new + 1, ...:
/// counter-clockwise like the cavity in both directions (a mirrored entry has its quads reversed),
/// so that the boundary edges of the result are exactly cycle[j] -> cycle[j+1].
[[nodiscard]] std::vector<std::array<LO, 4>> place_replacement(const DiskQuadTable& table,
                                                               const Replacement& r,
                                                               std::span<const LO> cycle,
                                                               LO first_new);

struct DiskRemeshOptions {
  /// Ideal valence of each dim-0 vertex of the face mesh, indexed by face-mesh vertex (empty: all
  /// estimated as max(1, round(angle / 90 deg)) from the angles of its quads in 3D, the corner's
  /// angle in this face). Entries of other vertices are ignored.
  std::vector<int> corner_valence;
  int max_passes = 4;  ///< sweeps corners -> curves -> interior, until one changes nothing
  /// When the cavity of a defect's own quads has no allowed replacement or fails the geometry
  /// check, try once more with the quads around their face-interior vertices added (Gmsh's
  /// implementation tries that larger patch first). A curve vertex with a single quad, e.g. on a
  /// seam, has no replacement of that quad alone that gives it valence 2.
  bool larger_cavity = true;
  /// A corner or curve defect for which no replacement lowers Eq. 15, with fewer quads than its
  /// ideal valence (they span too wide an angle) and one of them of SICN below this, is fixed by
  /// priority alone (Sec. 6.3.2: corners first, then curves, then the interior): it must reach its
  /// ideal valence, vertices of its kind and above end ideal or unchanged, and face-interior
  /// vertices may get worse within ChoiceOptions' relaxed range (0: never). A curve vertex with
  /// one quad spans 180 degrees. Measured at the reference sizes (docs/benchmarks.md): SICN min of
  /// the built-in example 0.036 -> 0.140 and of mambo_s34 0.294 -> 0.468, for 10 and 5 more
  /// interior irregular vertices.
  double force_below_sicn = 0.3;
  /// Geometry acceptance: every quad of the enlarged cavity must have SICN > 0, the region may not
  /// have more corners turning against the surface normal at their vertex than before (on a
  /// strongly curved surface valid quads can have some: coarse quads around a leading edge), and
  /// its minimum SICN must reach min_sicn or, when accept_if_not_worse, the minimum of the same
  /// region before the change.
  double min_sicn = 0.3;
  bool accept_if_not_worse = true;
  smooth::SmoothOptions smoothing{};  ///< on the enlarged cavity, its boundary locked
};

struct DiskRemeshStats {
  LO defects_before = 0, defects_after = 0;
  LO replaced = 0;           ///< cavities replaced
  LO no_candidate = 0;       ///< tries without an allowed replacement better than today
  LO rejected_geometry = 0;  ///< replacements rolled back by the geometry check
  LO skipped = 0;            ///< cavities tried that are not a simple disk or beyond the table
  // no_candidate, rejected_geometry and skipped count tries: a defect may try up to four cavities.
};

/// The ideal valence of each dim-0 vertex estimated from its angle in the face: max(1, round(angle
/// / 90 deg)), the angle summed over its quads' corners in 3D (0 for other vertices). What
/// DiskRemeshOptions::corner_valence defaults to.
[[nodiscard]] std::vector<int> estimate_corner_valences(const mesh::FaceMesh& mesh);

/// Defects of a quad face mesh (Sec. 6.3): dim-2 vertices of valence >= 6, dim-1 vertices of
/// valence != 2, dim-0 vertices of valence != ideal (options.corner_valence or the estimate).
/// Each image of a seam vertex (its (dim, entity, index) twice in the mesh, one per side) counts as
/// a curve vertex; a dim-0 vertex seen twice (a seam end, a pole) is not counted.
[[nodiscard]] LO count_defects(const mesh::FaceMesh& mesh, const DiskRemeshOptions& options);

/// Paper 000 Sec. 6.3.2 on one face.
///
/// Takes an all-quad FaceMesh (no triangle; quads counter-clockwise about the face normal; uv
/// consistent with points) and the face's geometry. For each defect vertex, corners first, then
/// curves, then the interior (vertex order inside each kind), the cavity of its quads (a simple
/// disk, b <= table.max_boundary()) is replaced by best_replacement (priorities of ChoiceOptions by
/// the defect's kind) when that lowers Eq. 15; failing that, the larger cavity and the priority
/// rule of DiskRemeshOptions::larger_cavity and force_below_sicn. A pole (no surface normal) is
/// never a defect; on a cavity's boundary it keeps its valence. New interior vertices start at the
/// harmonic (uniform Tutte) position in uv; the enlarged cavity (the new quads and every quad
/// touching them) is smoothed with smooth::smooth_face with its boundary locked, then checked
/// (DiskRemeshOptions::min_sicn and the acceptance there): a transaction, the whole replacement
/// is kept or nothing changes.
/// dim-0 and dim-1 vertices never move. Deterministic (fixed order, no threads).
/// Returns the new mesh: surviving vertices in their order then the new ones; quads likewise.
[[nodiscard]] mesh::FaceMesh remesh_disk_defects(const mesh::FaceMesh& mesh,
                                                 const cad::FaceGeometry& surface,
                                                 const DiskQuadTable& table,
                                                 const DiskRemeshOptions& options,
                                                 DiskRemeshStats* stats = nullptr);

}  // namespace qsmesh::remesh
