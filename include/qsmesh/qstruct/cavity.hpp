// Quasi-structured topology by cavity remeshing (paper 000 Sec. 6.2): a quad-mesh topology over a
// face mesh, the growth of convex remeshable cavities (Sec. 6.2.1) and the four-step remeshing
// strategy that removes unnecessary irregular vertices while keeping the ones matching cross-field
// singularities (Sec. 6.2.2). Cavities are replaced by refined patterns (Sec. 6.1.1, patterns.hpp).
//
// Terms (paper 000 Sec. 6): for a vertex x on the cavity boundary, n_in / n_out are its quads
// inside / outside the cavity (quads of this face only). x is a convex corner when n_in = 1 and a
// concave corner when x is not on the face boundary and n_out = 1. The sides are the boundary
// split at the convex corners (a convex cavity has no concave corner). Irregularity of a vertex:
// |valence - 4| inside the face, |valence - 2| on the face boundary (CAD curves), 0 on CAD corners
// (their valence is never changed here; Sec. 6.3 handles corners).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/core/adjacency.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/qstruct/patterns.hpp"
#include "qsmesh/smooth/smooth.hpp"

namespace qsmesh::qstruct {

/// Topology of the quads of a FaceMesh (triangles ignored): vertex -> quads (CSR, increasing quad
/// ids), quad -> quad across each edge, mesh-boundary flags. Edge k of quad q joins q[k] and
/// q[(k + 1) % 4]. Throws qsmesh::Error when an edge is used by more than two quads or twice in
/// the same direction (inconsistent orientation).
class QuadTopology {
 public:
  QuadTopology() = default;
  explicit QuadTopology(const mesh::FaceMesh& mesh);

  [[nodiscard]] LO num_vertices() const { return static_cast<LO>(on_boundary_.size()); }
  [[nodiscard]] LO num_quads() const { return static_cast<LO>(q2q_.size()); }
  /// Quads around v (increasing ids); the quadrilateral valence is their number.
  [[nodiscard]] std::span<const LO> quads_of(LO v) const { return v2q_[v]; }
  [[nodiscard]] LO valence(LO v) const { return static_cast<LO>(v2q_[v].size()); }
  /// Quad across edge k of q, kNoIndex on the mesh boundary.
  [[nodiscard]] LO neighbour(LO q, int k) const { return q2q_[q][k]; }
  /// v lies on an edge used by one quad only (the face boundary, or the border of a hole).
  [[nodiscard]] bool on_boundary(LO v) const { return on_boundary_[v] != 0; }

 private:
  Adjacency v2q_;
  std::vector<std::array<LO, 4>> q2q_;
  std::vector<char> on_boundary_;
};

/// Which cavities the growth accepts as remeshable.
struct GrowOptions {
  /// Minimal: stop at the first remeshable cavity; maximal: grow on and keep the last one.
  bool maximal = false;
  /// Replacement patterns (a subset of builtin_patterns(); only patterns whose boundary vertices
  /// are corners or valence 2, i.e. convex ones, make sense for convex cavities).
  std::span<const Pattern> patterns;
  /// Step 2 of Sec. 6.2.2: the seed is a singularity allowed inside the cavity; a remeshable
  /// cavity then also holds at least one other irregular vertex, and its replacement has exactly
  /// one irregular interior vertex, of the seed's valence.
  bool seed_is_singularity = false;
  /// The paper matches the cavity each time it is convex and has absorbed new irregular
  /// vertices; with this set, at every convex state once it holds one (two for Step 2). The
  /// boundary changes at each step, and the isotropic growth often passes through the 3- or
  /// 5-sided shapes between two absorptions.
  bool check_every_step = true;
  LO max_quads = 400;  ///< growth stops at this many quads
  /// A match is kept only when its refined pattern has between (1 - f) and (1 + f) times the
  /// cavity's quads (the mesh size is the size map's business, not the pattern's); < 0: any.
  double max_quad_change = 0.25;
  int max_candidates = 2;  ///< matches kept per remeshable cavity (best first)
  /// When a concave vertex cannot be absorbed, the growth goes back to its last convex state,
  /// never adds the quad that left it again, and grows on elsewhere, at most this many times
  /// (0: the growth stops there, as in the paper).
  int max_backtracks = 0;
  /// Minimal growth: stop at the k-th remeshable cavity met (0 or 1: the first, the paper's
  /// minimal cavity; more give larger fallbacks when the smallest is refused geometrically).
  int max_remeshable = 1;
  MatchOptions match;
  /// Optional: match_patterns' results kept across growths (same matches, less work). The
  /// caller's, for one thread; `patterns` must stay alive while it is used.
  MatchCache* match_cache = nullptr;
};

/// A remeshable cavity and how to remesh it.
struct Cavity {
  std::vector<LO> quads;  ///< the cavity, in order of growth (a topological disk)
  /// Boundary vertices in order, along the quads' orientation (the cavity on the left when quads
  /// turn counter-clockwise), starting at a convex corner.
  std::vector<LO> boundary;
  std::vector<LO> n_in;               ///< n_in of each boundary vertex
  std::vector<LO> corners;            ///< positions in `boundary` of the convex corners (n_in = 1)
  std::vector<LO> side_edges;         ///< side k runs from corners[k] to corners[k + 1] (cyclic)
  std::vector<LO> interior;           ///< vertices inside (all their quads in the cavity)
  std::vector<PatternMatch> matches;  ///< at most GrowOptions::max_candidates, best first
  /// Irregularity of the cavity's vertices (interior and boundary) now, and after the best match.
  int irregularity_before = 0, irregularity_after = 0;
};

/// Result of one growth: the remeshable cavities met, in order of growth (minimal: at most one).
struct GrowResult {
  std::vector<Cavity> remeshable;
  LO grown_quads = 0;  ///< size of the cavity when the growth stopped
  int checks = 0;      ///< pattern matchings done
  /// Why the growth stopped: a concave vertex could not be absorbed, GrowOptions::max_quads, no
  /// outside quad could be added, the seed fan is not a disk, or (minimal) a remeshable cavity.
  enum class Stop { Concave, MaxQuads, NoFrontier, Fan, Found } stop = Stop::NoFrontier;
  /// Of the checks: no pattern with that many sides (told from the number of vertices in one
  /// cavity quad, before the boundary is walked), no match (Eq. 14 unsolvable within the
  /// attempts), matches none of which is remeshable (irregularity not lowered, quad change,
  /// a flagged vertex or a CAD corner would change valence, Step 2's single irregular vertex).
  int no_pattern = 0, no_match = 0, not_better = 0;
  /// Largest distance from the seed's point to a vertex of a quad the growth looked at (added,
  /// undone or next to the cavity): the growth depends on nothing farther.
  double reach = 0;
};

/// Paper 000 Sec. 6.2.1: grows a cavity from the quads around `seed` (an interior vertex).
///  - Concave boundary vertices (not on the mesh boundary, n_out = 1) are absorbed first; when one
///    cannot be absorbed the growth stops. Otherwise the outside quad next to the cavity whose
///    centroid is nearest to the seed (3D; ties: lowest id) is added.
///  - A quad is added only when the cavity stays a topological disk (the quad shares one chain of
///    1 to 3 consecutive edges with it and touches it nowhere else), no flagged vertex
///    (singular[v] != 0, the seed excepted when seed_is_singularity) and no vertex on a CAD
///    curve or corner (vclass.dim < 2) not on the mesh boundary becomes interior, and no CAD
///    corner of valence >= 3 (a concave corner) gets n_out = 0.
///  - Each time the cavity is convex and has absorbed new irregular interior vertices (or at every
///    convex state, GrowOptions::check_every_step), its sides
///    are matched with options.patterns (match_patterns); it is remeshable when a match's
///    refined pattern leaves every flagged boundary vertex and every CAD corner with its valence,
///    strictly lowers the irregularity of the cavity's vertices and keeps the number of quads
///    within GrowOptions::max_quad_change.
/// `singular` has one flag per vertex. Deterministic.
[[nodiscard]] GrowResult grow_cavity(const mesh::FaceMesh& mesh, const QuadTopology& topo, LO seed,
                                     std::span<const char> singular, const GrowOptions& options);

/// Options of the remeshing strategy.
struct CavityOptions {
  /// A singularity flags the nearest interior vertex of valence 3 (index +1) or 5 (index -1)
  /// within this many local edge lengths (the mean length of the vertex's edges).
  double singularity_distance = 3.0;
  /// Size bounds of the growth (GrowOptions::max_quads) for the maximal grid cavities (Steps 1
  /// and 3) and the minimal ones (Steps 2 and 4).
  LO max_quads_maximal = 600;
  LO max_quads_minimal = 150;
  /// From the round where at most sparse_irregular_ratio unnecessary irregular vertices per quad
  /// are left, the maximal growths (Steps 1 and 3) may take max_quads_sparse quads
  /// (CavityReport::escalated). Sparse pairs are far apart, and few seeds keep the larger bound
  /// cheap. Measured end to end (2 threads, docs/benchmarks.md), interior irregular vertices:
  /// mambo_s34 at size factor 0.00504703 610 -> 409, Block at 0.0043 3282 -> 3193, t20 307 ->
  /// 290; A319, wing_fuselage and cube_filet unchanged.
  /// Raising max_quads_maximal to 3000 everywhere gave mambo 396 but cost wing_fuselage 2.3x the
  /// time for nothing (its faces keep 6% irregular vertices: size transitions).
  LO max_quads_sparse = 3000;
  double sparse_irregular_ratio = 0.05;
  /// Remeshable cavities of a maximal growth tried geometrically, largest first.
  int max_geometric_tries = 3;
  /// Remeshable cavities of a minimal growth (Steps 2 and 4) tried geometrically, smallest first
  /// (GrowOptions::max_remeshable): when the minimal one is refused, the next larger ones.
  int max_minimal_tries = 3;
  /// Skip a growth (Steps 1, 3, 4) that found nothing from the same seed before while no commit
  /// has changed the mesh within its reach (CavityStepDiagnostics::skipped_futile). Same result,
  /// less time (Block.stp, survey at 0.02: Step 3 starts 3.7k growths instead of 16.5k).
  bool skip_futile = true;
  int max_candidates = 2;  ///< matches tried per cavity (GrowOptions::max_candidates)
  /// GrowOptions::max_backtracks. With 8 and max_minimal_tries 3 on Block.stp (cavity_survey,
  /// size factor 0.02): interior irregular vertices 10494 -> 4978 instead of 5345, SICN avg
  /// 0.8676 instead of 0.8705, 2% fewer quads, remesh time 16.8 s instead of 12.2 s.
  int max_backtracks = 8;
  /// Vertex rings around the cavity smoothed with it (0: only the new interior vertices; 1: the
  /// cavity boundary too, CAD vertices always stay).
  int smooth_rings = 1;
  /// Acceptance after smoothing, over the touched quads (the new quads and the quads around the
  /// smoothed vertices): every quad valid, facing like the face, with SICN (Eq. 12) above
  /// min_sicn, and the minimum SICN at least min(good_sicn, keep_ratio x the minimum before).
  /// The mean SICN of the new quads must also be at least keep_avg_ratio x the mean SICN of the
  /// cavity's quads before. 0.97 trades irregular vertices for quality: at the reference vertex
  /// counts (docs/benchmarks.md, eleventh session), 0.95 -> 0.97 takes mambo_s34's SICN avg from
  /// 0.9807 to 0.9837 (interior irregular 0.23% -> 0.25%), t20 0.9831 -> 0.9837 (82 -> 79),
  /// Block 0.923 -> 0.927 (0.96% -> 1.00%); 0.98 and 1.0 leave more irregular vertices than the
  /// reference's on t20 (112, 142 against 95) and Block (1.25% at 1.0 against 1.16%).
  double min_sicn = 0.1;
  double keep_ratio = 0.8;
  double good_sicn = 0.6;
  double keep_avg_ratio = 0.97;
  /// A candidate is screened after this many of its smoothing passes (smooth.iterations in all;
  /// 0, 1 or at least smooth.iterations: off): it is refused there when, with each pass left
  /// gaining what the last one did, its minimum would stay below the acceptance bound less
  /// screen_min_margin, or its mean below the mean bound less screen_avg_margin
  /// (CavityStepDiagnostics::refused_screened). Smoothing gains less with each pass, so this
  /// overestimates what a candidate can reach; the passes of a candidate let through are the
  /// same as unscreened, so its mesh is too. Measured (docs/benchmarks.md, issue 27, branch
  /// `speed`) on the six shared models at their reference counts: 92% of the candidates that
  /// the acceptance refused stop after 3 passes instead of 10 (Block: 5829 of 6338), none of
  /// those it accepted (their projected minimum came at worst 0.003 below its bound, their
  /// projected mean at worst 0.0001 above its bound), and the meshes are byte-identical.
  int screen_passes = 3;
  double screen_min_margin = 0.05;
  double screen_avg_margin = 0.01;
  /// GrowOptions::max_quad_change. 0.3 measured against 0.15 on Block.stp (all faces, size factor
  /// 0.02, tests/qstruct/cavity_survey): interior irregular vertices 10475 -> 5346 instead of
  /// 6669 at the same SICN average (0.870), for 8% fewer quads (the filled patterns are coarser).
  double max_quad_change = 0.3;
  /// Step 3 matches its maximal cavities with every four-sided convex pattern (the size
  /// transitions too), not only the grid as Step 1 (the paper's Step 3 repeats Step 1). Once
  /// Steps 1-2 have removed what grids can, many of the remaining irregular pairs are transitions
  /// that only a large cavity can spread with good quads (Step 4's minimal ones are refused by
  /// quality). These growths check a match only when new irregular vertices came in (the paper's
  /// rule; GrowOptions::check_every_step is for the grid), and their futile seeds are kept apart
  /// from the grid's. Measured end to end at the reference vertex counts (2 threads), interior
  /// irregular vertices: mambo_s34 0.92% -> 0.53%, t20 2.16% -> 1.78%, Block 2.93% -> 2.75%, A319
  /// 5.16% -> 5.16%, wing_fuselage 6.43% -> 6.19%; SICN avg within 0.008 (t20 0.947 -> 0.939);
  /// 7% (mambo) and 10% (t20) fewer vertices (the transitions are coarser); cavity remeshing
  /// takes up to 2.4x as long (Block 8.5 -> 16.9 s, A319 3.4 -> 8.1 s; docs/benchmarks.md).
  bool step3_transitions = true;
  int max_rounds = 10;  ///< passes of Steps 1-4 (the loop stops earlier when nothing changes)
  std::array<bool, 4> steps{true, true, true, true};  ///< which of Steps 1-4 run (experiments)
  /// Deterministic work bound: growths started, all steps together (0: none).
  std::int64_t max_cavities = 0;
  /// Wall-clock bound in seconds (0: none). When it stops the run the result depends on timing:
  /// not reproducible, leave 0 where that matters.
  double time_budget_s = 0;
  MatchOptions match;
  smooth::SmoothOptions smooth;
};

/// Diagnostics of one step of Sec. 6.2.2 (why growths and replacements fail), summed over growths.
struct CavityStepDiagnostics {
  /// GrowResult::stop of the growths.
  std::int64_t stop_concave = 0, stop_max_quads = 0, stop_no_frontier = 0, stop_fan = 0,
               stop_found = 0;
  /// GrowResult::checks and their failures.
  std::int64_t checks = 0, no_pattern = 0, no_match = 0, not_better = 0;
  /// Geometric trials (Remesher) refused: Laplace layout failed, a touched quad invalid or
  /// flipped (SICN <= min_sicn), minimum SICN below the keep_ratio bound, mean SICN below the
  /// keep_avg_ratio bound.
  std::int64_t refused_layout = 0, refused_invalid = 0, refused_min = 0, refused_avg = 0;
  /// Geometric trials stopped by the screen after CavityOptions::screen_passes smoothing passes.
  std::int64_t refused_screened = 0;
  /// Growths not started again: the same growth from that seed found no remeshable cavity and
  /// no commit since changed anything within its reach (the result would be the same).
  std::int64_t skipped_futile = 0;
};

struct CavityReport {
  /// Per step of Sec. 6.2.2 (index 0..3 = Steps 1..4): growths started, cavities remeshed.
  std::array<std::int64_t, 4> grown{}, remeshed{};
  std::array<std::int64_t, 4> rejected_quality{};  ///< remeshable cavities refused after smoothing
  std::array<CavityStepDiagnostics, 4> diagnostics{};
  int rounds = 0;
  int escalated = 0;  ///< 1 when the maximal growths got max_quads_sparse (from some round on)
  std::int64_t irregular_before = 0, irregular_after = 0;  ///< interior vertices of valence != 4
  std::int64_t singularities = 0;  ///< singularities given (acute-corner ones excluded)
  std::int64_t flagged = 0;        ///< flagged vertices at the start
  std::int64_t flagged_kept = 0;   ///< flagged vertices at the end (with their valence)
  double sicn_min_before = 0, sicn_avg_before = 0, sicn_min_after = 0, sicn_avg_after = 0;
  bool work_bound_hit = false, time_budget_hit = false;
  std::string skipped;  ///< why the face was left as it is (empty when processed)
};

/// The candidates of remesh_cavities that were laid out, smoothed and refused, each under the
/// exact local problem it was (the touched quads' vertices with their points, uv and
/// classification, the new quads, the quality before), with what its smoothing reached: the
/// minimum and mean after the screen's passes and, when it ran to the end, after the last one.
/// The rounds and steps grow the same cavities again from the same seeds while their surroundings
/// do not change, and a growth whose candidates were all refused is grown again (only growths
/// that found nothing are skipped, CavityOptions::skip_futile). A candidate met again with the
/// same local problem is decided from what was recorded, under the acceptance bounds of the run
/// that meets it: refused there without its layout and smoothing, or laid out and smoothed again
/// when the record cannot tell (it would pass now, or was screened and would not be now). The
/// layout and smoothing depend on the local problem alone, so the mesh is bit for bit the one
/// without a memo. A memo can be handed on to a later call on the same face and surface (the
/// second pass starts from the same mesh with looser bounds: PipelineOptions::
/// second_pass_cavities); it forgets its records when that call's smoothing options differ.
/// It also keeps, for the calls it is handed to, what depends on their arguments alone: the
/// pattern lists of the steps, match_patterns' results (MatchCache) and the analyses of the
/// layouts' and smoothings' linear systems (linalg::SolverCache); the second pass grows the same
/// cavities as the first (Block.stp: a third of the first pass's matches came again). A call with
/// another pattern list selects its lists again and forgets the match results.
///
/// One thread at a time; a memo belongs to the task that improves one face (or piece).
class CavityMemo {
 public:
  /// Records of at most `max_bytes` bytes in all (keys and records); later candidates are not
  /// recorded once it is full.
  explicit CavityMemo(std::int64_t max_bytes = std::int64_t{64} << 20);
  ~CavityMemo();
  CavityMemo(CavityMemo&&) noexcept;
  CavityMemo& operator=(CavityMemo&&) noexcept;
  CavityMemo(const CavityMemo&) = delete;
  CavityMemo& operator=(const CavityMemo&) = delete;
  /// Candidates decided from a record (refused without layout and smoothing).
  [[nodiscard]] std::int64_t hits() const;
  /// Candidates recorded.
  [[nodiscard]] std::int64_t records() const;

  struct Impl;
  [[nodiscard]] Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

/// Paper 000 Sec. 6.2.2 on the all-quad mesh of one face.
///  - Input: an all-quad FaceMesh oriented along the face (consistent uv; triangles: the mesh is
///    returned unchanged), its surface, the face's cross-field singularities (3D points, index
///    +1/-1; AcuteCorner ones are ignored: corners are never remeshed here), the pattern list
///    (builtin_patterns()) and options.
///  - Singularities flag vertices (CavityOptions::singularity_distance). Then, while a round
///    changes something: Step 1 maximal cavities matching the 4-sided regular patterns (grid)
///    from each unnecessary irregular vertex; Step 2 minimal 3-sided (+1) / 5-sided (-1) convex
///    cavities around each flagged vertex (the pattern's irregular vertex becomes the flagged
///    one); Step 3 = Step 1, with the transitions too (CavityOptions::step3_transitions); Step 4
///    minimal cavities matching the 4-sided convex patterns
///    (transitions) from each unnecessary irregular vertex. A round that starts with few
///    unnecessary irregular vertices left (CavityOptions::sparse_irregular_ratio) and every round
///    after it bound the maximal cavities by max_quads_sparse instead of max_quads_maximal.
///  - Each replacement is a transaction: the refined pattern is glued to the cavity boundary (same
///    vertex ids), new vertices placed by a uniform Laplace solve in (u, v), the cavity and
///    CavityOptions::smooth_rings rings smoothed (smooth::smooth_face on that region, the rest
///    locked), and rolled back unless the acceptance of CavityOptions holds. Every accepted
///    replacement strictly lowers the total irregularity, so the loop ends.
///  - Output: the mesh compacted: vertices no longer used dropped (only face-interior ones can
///    be), survivors in their input order (CAD-classified vertices keep ids, points, uv and
///    vclass), new vertices after them, classified on the face; quads keep the orientation.
/// Never throws for a face-level failure (report->skipped says why; the input is returned).
/// Deterministic unless time_budget_s is set. `memo` (optional; CavityMemo) spares the candidates
/// refused before, the result unchanged; it is not used when a time budget is set.
[[nodiscard]] mesh::FaceMesh remesh_cavities(
    const mesh::FaceMesh& quads, const cad::FaceGeometry& surface,
    std::span<const crossfield::Singularity> singularities, std::span<const Pattern> patterns,
    const CavityOptions& options, CavityReport* report = nullptr, CavityMemo* memo = nullptr);

/// Interior vertices (vclass.dim 2, not on the mesh boundary, used by a quad) whose quad valence
/// is not 4.
[[nodiscard]] std::int64_t count_irregular(const mesh::FaceMesh& mesh);

}  // namespace qsmesh::qstruct
