// Pattern-aware curve quantization (paper 000 Sec. 4.3 and 6.1.2): the edge counts of the curves
// nudged so that more CAD faces have sides that a coarse pattern fits.
//
// The quantization of Sec. 4.3 rounds each curve (or chord of four-sided faces) on its own; a
// face whose sides are made of several curves, or a three-sided face, then often gets counts that
// no pattern matches (e.g. [26, 10, 16] breaks the triangle inequality, [4, 40, 4, 30] needs a
// size transition across a strip 4 edges wide) and falls back to the unstructured path with its
// irregular vertices. The paper names "quantization aware of the patterns" as the fix; this is a
// greedy, deterministic form of it.
#pragma once

#include <span>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/qstruct/face_pattern.hpp"
#include "qsmesh/qstruct/patterns.hpp"
#include "qsmesh/quantize/quantize.hpp"

namespace qsmesh::qstruct {

struct BalanceOptions {
  /// A curve's count may move away from its ideal value (Quantization::ideal) by at most this
  /// fraction of the ideal value (and always by 2 edges); a count already further away may only
  /// come closer.
  double max_change = 0.35;
  /// Greedy passes over the faces (each stops early when nothing changed).
  int max_passes = 6;
  /// Four-sided faces whose opposite sides have lengths within this ratio (both pairs) are
  /// rectangles in all but their counts: after the passes above, such a face that a pattern fits
  /// only with a size transition is steered to the grid (opposite counts made equal), when no face
  /// loses its fit or its grid. Below 1: off.
  double grid_length_ratio = 1.1;
  /// Corner detection as for the pattern meshing (corner_angle_deg) and the matching.
  PatternFaceOptions faces;
};

struct BalanceReport {
  LO faces_considered = 0;  ///< faces with one loop, no pole and 2 to 6 sides
  LO fitting_before = 0;    ///< of those, faces some pattern fits before balancing
  LO fitting_after = 0;     ///< and after
  LO grids_before = 0;      ///< four-sided faces with equal opposite counts, before balancing
  LO grids_after = 0;       ///< and after
  LO curves_changed = 0;    ///< curves whose count changed
  int passes = 0;
};

/// Takes the quantization q of the model (even loops, chords of Sec. 4.3) and returns new edge
/// counts, one per curve, such that
///  - every count moves by even steps (every loop stays even; an odd count stays odd), at least
///    2 (4 on a closed curve; one less for an odd count), and the curves of one chord of q
///    stay equal (a chord moves as one variable); curves in `fixed` (user prescriptions) and
///    degenerate curves keep their count;
///  - faces with one closed loop, no degenerate curve and 2..6 sides (split at the corners below
///    options.faces.corner_angle_deg, found on `curves`, the background curve meshes by curve id)
///    are the targets: a face "fits" when match_patterns(patterns, side counts) is not empty;
///  - greedy passes over the faces in id order: for a four-sided face that does not fit, moves
///    of one variable on a side that cancel (or halve) the difference with the opposite side; for
///    a three-sided face, moves that restore the triangle inequality. A move is applied when it
///    keeps the count bounds above, does not lower the number of fitting faces, and lowers the
///    total misfit of the faces it touches (four sides: |N1 - N3| + |N2 - N4|; three sides: by how
///    much the longest side fails the triangle inequality); the best move of a face by (fitting
///    faces gained, misfit, relative change) is taken.
/// Deterministic: the result depends only on the model, the curve meshes, q and the options.
/// Fills `report` when not null.
[[nodiscard]] std::vector<int> balance_curve_counts(
    const cad::CadModel& model, std::span<const mesh::CurveMesh> curves,
    const quantize::Quantization& q, std::span<const Pattern> patterns, std::span<const LO> fixed,
    const BalanceOptions& options, BalanceReport* report = nullptr);

}  // namespace qsmesh::qstruct
