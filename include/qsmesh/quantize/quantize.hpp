// Global curve quantization (paper 000 Sec. 4.3): how many edges each CAD curve gets, consistently
// for the whole model, and where the curve vertices go (Eq. 11).
//
// Every function here depends only on the model, the background curve meshes and the sizes along
// them, which are identical on every rank: every rank computes the same quantization and the same
// curve meshes, whatever the partition and the thread count.
#pragma once

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/core/types.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::quantize {

struct QuantizeOptions {
  /// User edge counts (curve id, count > 0), kept exactly. A prescribed curve fixes the count of
  /// its whole chord. Several entries for one curve must agree.
  std::vector<std::pair<LO, int>> prescribed;
  /// Opposite sides of a four-sided face are forced equal (joined in one chord) unless their ideal
  /// counts differ by more than this ratio (max / min > chord_ratio_limit). Must be >= 1.
  double chord_ratio_limit = 2.0;
  /// ... nor when their lengths differ by more than this ratio (max / min). A grid across a face
  /// whose ends differ more than that in length has cells that much wider at one end, whatever
  /// the size map asks (mambo_s34's fillets [62, 6, 62, 6]: arcs 1.51 long, ideal 4.0 edges, got
  /// 6 through a tapered face from arcs 3.14 long, ideal 6.3, and cells 0.5 x 0.25). Must be >= 1.
  double chord_length_ratio_limit = 2.0;
  /// Counts for all-quad meshing by midpoint subdivision (paper 000 Sec. 5.2), which halves each
  /// face loop before the quad mesher and subdivides afterwards: every loop even (and every
  /// stretch of a loop between two poles), not every curve. Curves are rounded to even counts,
  /// then as few as possible move to the nearest odd count where prescriptions (or slivers)
  /// make a loop odd. false: each curve the nearest integer, no parity.
  bool even = true;
  /// With `even`: a free curve (or chord) whose ideal count is below sqrt 2 (nearer 1 edge than
  /// 2 in ratio) takes 1 edge, and the loops it makes odd get a neighbouring curve odd too. A
  /// strip between two such curves is then one quad across (a grid fill).
  bool odd_slivers = false;
  /// With `even`: a free curve (or chord, every member) shorter than this (CAD length, model
  /// units; 0: off) takes 1 edge, like odd_slivers, whatever its ideal count. Set from
  /// sizemap::sliver_length, whose rule (i') grades the sizes toward that one edge.
  double sliver_length = 0;
  /// When `even`, also make the halved meshes (place_vertices with halved = true) valid boundaries:
  /// closed curves at least 6 (3 before subdivision) and curves joining the same two corners at
  /// least 4 (2 before subdivision, so the two halved curves never coincide). Off by default: the
  /// minimums then apply to the final counts only (closed 4, parallel 2).
  bool halved_minimums = false;
};

struct Quantization {
  /// Per curve: the floating number of edges, integral of dl / s (from ideal_edge_counts).
  std::vector<double> ideal;
  /// Per curve: the final number of edges. When options.even: even and >= 2 (>= 4 on closed
  /// curves) but for prescriptions and the curves that parity (or odd_slivers) makes odd, and
  /// every face loop's sum even; >= 1 otherwise (>= 3 closed, >= 2 when another curve joins the
  /// same two corners).
  /// Degenerate curves (poles): 0; place_vertices keeps their single background edge.
  std::vector<int> edges;
  /// Chord id per curve (0 .. num_chords-1, numbered by increasing smallest curve id), kNoIndex
  /// when the curve is in no chord. A chord is a set of topologically parallel curves: opposite
  /// sides of four-sided faces, propagated through shared curves.
  std::vector<LO> curve2chord;
  LO num_chords = 0;
  /// Sum of `edges` over all curves.
  std::int64_t total_edges = 0;
};

/// Paper 000 Sec. 4.3, size map integration: for each curve c, the integral of dl / s along the
/// background polyline curves[c].points, with s linear along each polyline segment between
/// sizes[c][i] and sizes[c][i+1] (integrated exactly: len * ln(s1/s0) / (s1 - s0)).
/// Preconditions: sizes.size() == curves.size(), sizes[c].size() == curves[c].points.size(),
/// every size finite and > 0 (model units). Returns one value per curve (0 for a degenerate curve,
/// whose polyline has zero length). Throws qsmesh::Error when a precondition fails.
[[nodiscard]] std::vector<double> ideal_edge_counts(std::span<const mesh::CurveMesh> curves,
                                                    std::span<const std::vector<double>> sizes);

/// Paper 000 Sec. 4.3, topological constraints on quadrilateral patches, and Sec. 5.2 (even
/// loops).
///  - Chords: for every face with one loop of exactly four curve uses (a conformal four-sided
///  face),
///    uses 0-2 and 1-3 are opposite; each opposite pair of non-degenerate curves is joined
///    (union-find over curves) unless max/min of their ideal values > chord_ratio_limit or of
///    their lengths > chord_length_ratio_limit. A curve
///    is in a chord when it is a side of at least one joined pair (a seam opposite itself, as on a
///    cylinder, makes a chord of one curve). All curves of a chord get the average of the chord's
///    ideal values (each curve counted once), then rounded.
///  - Rounding: to the nearest even number when options.even (at least 2), else to the nearest
///    integer (at least 1); closed curves at least 4 (even) / 3; curves joining the same two
///    corners at least 2 each. A chord takes the largest minimum of its curves so it stays equal.
///  - Prescriptions are kept exactly, odd ones too, and fix their whole chord.
///  - Parity (options.even): every face loop must have an even count, and where a loop has two
///    or more poles (degenerate curves), each stretch between two of them (background::
///    halved_face_boundary keeps poles on halved vertices). Free chords and curves (and slivers
///    with options.odd_slivers) change parity where a loop needs it: for each odd loop, the
///    cheapest chain of curves shared with the next odd loop (or reaching an open boundary) in
///    relative change of count, each moved to the nearest count of the other parity (a Gaussian
///    elimination over GF(2) where no chain exists, through curves of three or more faces).
///    Where the chords make that impossible, the chords without a prescription, then all
///    chords, are given up (curve2chord says which are kept).
///  - InputError for: an unknown or degenerate curve, a count <= 0, two different counts in one
///    chord (naming both curves), a count below what a closed curve (3) or a pair of curves joining
///    the same corners (2) needs, and prescriptions that leave a loop odd whatever the other
///    curves take (the message names the loop, or the loops, and the prescribed curves in them;
///    check_prescription_parity says the same before any work).
/// `ideal` has one value per curve (model.num_curves()), finite and >= 0.
/// Sequential and deterministic: the result depends only on the model, `ideal` and `options`.
[[nodiscard]] Quantization quantize_curves(const cad::CadModel& model,
                                           std::span<const double> ideal,
                                           const QuantizeOptions& options);

/// The parity check of quantize_curves for user prescriptions alone, before any sizes exist:
/// throws InputError (the message quantize_curves would give) when the prescribed counts
/// (curve id, count) leave some face loop, or stretch of a loop between two poles, odd whatever
/// counts the other curves take. Unknown ids and counts <= 0 are skipped (quantize_curves
/// refuses them). Whatever passes here, quantize_curves can meet.
void check_prescription_parity(const cad::CadModel& model,
                               std::span<const std::pair<LO, int>> prescribed);

struct PlaceOptions {
  /// Opposite curves of the four-sided faces whose two pairs of opposite sides are joined in
  /// chords (the faces a grid or transition pattern fills) share one vertex distribution, so the
  /// pattern's rows do not shear: the curves connected by such faces (oriented through them) are
  /// placed by the mean of their normalised profiles (∫ dl / s over the curve, as a function of
  /// the arc-length fraction) instead of each by its own. Measured at the reference vertex
  /// counts (docs/benchmarks.md, with align_length_ratio 1.5): interior irregular vertices
  /// Block.stp 3158 -> 3083, mambo 321 -> 318, t20 109 -> 103, but A319 1146 -> 1166 and
  /// wing_fuselage 873 -> 882 (unstructured neighbours of the aligned faces); four 44 x 4 grids of
  /// Block at size factor 0.0037 from SICN avg 0.62 (refused) to 0.93.
  bool align_chords = true;
  /// ... through the faces whose opposite sides differ in length by at most this ratio (>= 1).
  /// Measured at the reference counts, against no bound: the built-in example SICN avg 0.878 ->
  /// 0.895 (its wing root and tip, 2.35:1, no longer blended), the six shared models within 3%
  /// in interior irregular vertices either way.
  double align_length_ratio = 1.5;
  /// Arc-length samples of the shared profile (>= 2).
  int profile_samples = 256;
  /// Two curves of one face closer than this fraction of the edge length are the sides of a thin
  /// face, and their vertices are aligned across it (align_thin_sides); 0: off.
  double thin_side_ratio = 0.5;
};

/// Paper 000 Eq. 11: the final curve meshes, one per curve, indexed by curve id. Curve c gets
/// n = q.edges[c] edges (n = q.edges[c] / 2 when `halved`: the meshes the quad mesher uses before
/// midpoint subdivision when every count is even; q.edges[c] must then be even: the quad stage
/// builds them per face from the full meshes with background::halved_face_boundary, which gives
/// the same vertices for even counts and also handles odd ones). Vertex i sits where the integral
/// of dl / s (s linear along the background polyline curves[c], as in ideal_edge_counts) reaches
/// i/n of the total; its parameter is interpolated linearly between the two background vertices
/// around it and its point is evaluated on the CAD curve (model.curve_geometry(c)). With
/// options.align_chords, the curves of a set of aligned opposite sides (see PlaceOptions) use the
/// set's mean profile instead of their own, sampled at options.profile_samples + 1 arc-length
/// fractions and interpolated linearly; their vertex i sits where that profile reaches i/n, at
/// that fraction of the background polyline's length. The end vertices are the
/// curve's corners exactly (t = the background's end parameters). Degenerate curves keep their
/// background mesh (one edge). One task per curve on `tasks`; the result does not depend on the
/// thread count. Throws qsmesh::Error on size mismatches or non-positive sizes.
[[nodiscard]] std::vector<mesh::CurveMesh> place_vertices(
    const cad::CadModel& model, std::span<const mesh::CurveMesh> curves,
    std::span<const std::vector<double>> sizes, const Quantization& q, bool halved,
    const TaskArena& tasks, const PlaceOptions& options = {});

/// Aligned vertices on the two sides of thin faces (issue 29): where two curves of a face that
/// share no corner (a neck's two sides, a slot's arc and the circle around it) lie closer than
/// `width_ratio` x the local edge length, the quads across are two rows of slivers, and they shear
/// when the vertices of the two sides do not face each other (Block.stp's face 520 at size factor
/// 0.02: 12 and 6 edges, 20 quads below SICN 0.1). A vertex of one curve faces the other when its
/// nearest point there is inside that curve, closer than `width_ratio` x the mean length of its
/// edges, and not along its own tangent (within 60 degrees of normal to it). Of two curves facing
/// each other, the one with the larger fraction of facing vertices is the master (its vertices
/// stay); the other (the slave) gets a vertex at the foot of each of them, with the master's
/// parity of index, so that the halved meshes (every even vertex while every count of the face is
/// even) are aligned too; between and beyond those, its vertices are spread as before over the
/// pieces with the rounded counts (every piece within 2:1 of its former spacing, else up to three
/// feet at each end are dropped, else the slave keeps its vertices). Its count stays. A curve that
/// is master anywhere is never a slave; opposite sides of a four-sided face in one chord are
/// aligned already (PlaceOptions::align_chords) and skipped, as are faces with an odd curve,
/// curves used twice by the face (seams) and closed curves. Works on the full curve meshes
/// `full` (indexed by curve id) in place; `background` gives the curves' polylines. Returns the
/// curves moved, increasing. The same on every rank, whatever the thread count of `tasks`.
[[nodiscard]] std::vector<LO> align_thin_sides(const cad::CadModel& model,
                                               std::span<const mesh::CurveMesh> background,
                                               const Quantization& q,
                                               std::vector<mesh::CurveMesh>& full,
                                               const TaskArena& tasks, double width_ratio);

/// The curves whose meshes make the boundary of face f cross itself in the face's parameter
/// plane: two segments of its loops (background::face_boundary on `curves`) that cross properly
/// (exact orientation tests, segments sharing a loop vertex excepted) or lie on one line over a
/// common length (the boundary runs back over itself), and the curves of a loop of fewer than
/// three segments (two curves joining the same corners with one edge each). The Delaunay kernel
/// cannot triangulate such a boundary, so the face could not be meshed at all: a tight curve (a
/// small fillet, a slot's end) with too few edges cuts a corner across a neighbouring curve.
/// Sorted, each curve once; empty when the boundary is simple. Throws what face_geometry /
/// face_boundary throw.
[[nodiscard]] std::vector<LO> crossing_curves(const cad::CadModel& model, LO f,
                                              std::span<const mesh::CurveMesh> curves);

/// crossing_curves on the halved boundary of face f (background::halved_face_boundary of the
/// final curve meshes `full`): a halved segment across a corner names both curves beside it.
[[nodiscard]] std::vector<LO> crossing_curves_halved(const cad::CadModel& model, LO f,
                                                     std::span<const mesh::CurveMesh> full);

/// Doubles the count of each curve in `curves` (2n + 1 when n is odd, so that every loop keeps
/// its parity) and gives every curve of its chord at least that count (so chords stay equal);
/// updates total_edges. Curves without edges
/// (degenerate), unknown ids and the chords of the curves in `fixed` (user prescriptions, kept
/// exactly) are left alone.
void refine_curves(Quantization& q, std::span<const LO> curves, std::span<const LO> fixed = {});

}  // namespace qsmesh::quantize
