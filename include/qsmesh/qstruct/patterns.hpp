// Pattern-based quad meshing (paper 000 Sec. 6.1.1, Fig. 4): coarse quad patterns, their sides,
// topological chords and the integer system of Eq. 14, the matching of a cavity's side counts
// with the patterns, and the refined quad mesh of a matched pattern.
//
// The built-in patterns come from data/patterns.txt, compiled in at build time:
//  - 2 sides: half_disk (two valence-3 vertices; each side holds a chord that turns inside, w = 2);
//  - 3 sides: triangle (three quads around a valence-3 vertex);
//  - 4 sides: grid (one quad), transition_1 (one valence-3 / valence-5 pair: the paper's third
//    pattern, a + b + c = N1, d + e = N2, a + c = N3, b + d + e = N4), transition_2 (two pairs:
//    two chords leave one side and turn to its two neighbours, so N1 - N3 and N4 - N2 may differ),
//    transition_2_joined (the same without the chord between the turning ones: they meet at a
//    valence-6 vertex, for opposite sides too short for transition_2);
//  - 5 sides: pentagon (five quads around a valence-5 vertex), l_shape (three quads, the concave
//    corner a valence-3 boundary vertex inside a side, for L-shaped faces);
//  - 6 sides: hexagon (six quads around a valence-6 vertex).
// Within one number of sides, the file order is the order of preference.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "qsmesh/core/types.hpp"

namespace qsmesh::qstruct {

/// A coarse quad pattern (a small quad mesh of a disk) and what is derived from it.
///
/// Terms (paper 000 Sec. 6): a corner is a boundary vertex with one quad (valence 1); the sides
/// are the boundary split at the corners (a pattern without corner has one side, closing on
/// itself); a topological chord is a class of edges linked through opposite edges of quads (a
/// dual chord); Eq. 14: sum_j w[i][j] s_j = N_i, where w[i][j] is the number of edges of side i
/// in chord j (0, 1 or 2). A closed chord (a ring reaching no side) has a zero column: Eq. 14
/// leaves its subdivision free.
struct Pattern {
  std::string name;
  std::vector<Vec2> xy;                       ///< drawing coordinates from the data file
  std::vector<std::array<LO, 4>> quads;       ///< counter-clockwise
  std::vector<LO> valence;                    ///< quads per vertex
  std::vector<std::array<LO, 2>> edges;       ///< unique edges (lower id first)
  std::vector<std::array<LO, 4>> quad_edges;  ///< edge k of a quad joins its vertices k and k+1
  std::vector<LO> edge_chord;                 ///< chord of each edge
  LO num_chords = 0;
  /// Boundary vertices counter-clockwise (interior on the left), starting at the corner with the
  /// smallest id (without corner: the boundary vertex with the smallest id); boundary edge k
  /// joins boundary[k] and boundary[k + 1] (cyclic).
  std::vector<LO> boundary;
  std::vector<LO> boundary_edge;  ///< edge id of boundary edge k
  std::vector<LO> side_start;     ///< position in `boundary` where each side starts
  /// Eq. 14 matrix, num_sides() x num_chords, row-major: w[i * num_chords + j].
  std::vector<int> w;
  /// Interior vertices whose valence is not 4 plus boundary non-corners whose valence is not 2.
  int irregular = 0;

  [[nodiscard]] LO num_vertices() const { return static_cast<LO>(xy.size()); }
  [[nodiscard]] int num_sides() const { return static_cast<int>(side_start.size()); }
  [[nodiscard]] int weight(int side, LO chord) const { return w[side * num_chords + chord]; }
  /// No corner: the pattern fills a cavity bounded by one smooth loop (match_patterns).
  [[nodiscard]] bool cornerless() const { return valence[boundary[side_start[0]]] != 1; }
  /// Whether chord j reaches no side (a ring): Eq. 14 does not constrain it.
  [[nodiscard]] bool closed_chord(LO chord) const {
    for (int i = 0; i < num_sides(); ++i)
      if (weight(i, chord) != 0) return false;
    return true;
  }
};

/// Derives boundary, sides, chords and w from a coarse quad mesh. Throws qsmesh::Error when the
/// mesh is not a valid pattern: an index out of range, a repeated vertex in a quad, an edge used
/// by more than two quads or twice in one direction (inconsistent orientation), a boundary that
/// is not one closed loop (not a disk).
[[nodiscard]] Pattern make_pattern(std::string name, std::vector<Vec2> xy,
                                   std::vector<std::array<LO, 4>> quads);

/// The built-in patterns (data/patterns.txt), in file order. Built anew by each call (cheap);
/// callers keep the vector and pass it down.
[[nodiscard]] std::vector<Pattern> builtin_patterns();

struct MatchOptions {
  /// The depth-first search gives up after this many trial values (paper: a few hundred).
  int max_attempts = 500;
};

/// A strictly positive integer solution of Eq. 14.
struct ChordSolution {
  bool found = false;
  std::vector<LO> s;          ///< chord subdivisions (when found)
  std::vector<double> ideal;  ///< the balanced ideal x_j
  double energy = 0;          ///< E = sum_j (s_j - x_j)^2 of s
  int attempts = 0;           ///< trial values used by the search
};

/// Paper 000 Sec. 6.1.1: solves sum_j w[i][j] s_j = N_i (w: num_sides x num_chords, row-major)
/// for integers s_j >= 1. The ideal guess x_j balances each side: every edge slot of side i gets
/// N_i / (sum_j w[i][j]), and x_j is the mean of its slots. Integer (fraction-free) row echelon
/// form, then a depth-first search from the bottom row up: free variables take values in order of
/// distance to round(x_j), within bounds implied by the rows, pivots follow by back substitution
/// (must be exact and >= 1). Among the solutions met within options.max_attempts trial values the
/// one with the smallest E is kept (ties: the first met). A chord on no side (a zero column: a
/// closed chord) is not constrained and gets 1; the caller sizes it from the geometry.
/// Deterministic.
[[nodiscard]] ChordSolution solve_chords(std::span<const int> w, int num_sides, LO num_chords,
                                         std::span<const LO> side_edges,
                                         const MatchOptions& options = {});

/// One way a pattern fits a cavity with side counts N. Pattern side i lies on cavity side
/// (reversed ? (start - i) : (start + i)) mod m; `reversed` means the pattern is used mirrored
/// (its boundary runs against the cavity's).
struct PatternMatch {
  LO pattern = kNoIndex;  ///< index in the pattern list
  int start = 0;          ///< cavity side holding pattern side 0
  bool reversed = false;
  std::vector<LO> chords;  ///< subdivision of each chord of the pattern
  double energy = 0;       ///< E of the solution
};

/// Every pattern with N.size() sides, every rotation in both directions (paper 000 Sec. 6.1.1),
/// solved with solve_chords. Matches giving the same subdivisions on every cavity side (symmetric
/// duplicates, e.g. the 8 placements of the grid) are kept once. Sorted by pattern index, then
/// energy, then (reversed, start). Empty when no pattern fits. `cornerless`: the cavity is
/// bounded by one smooth loop (side_edges holds its one count); only the patterns without corner
/// (Pattern::cornerless) fit it, and they fit nothing else.
[[nodiscard]] std::vector<PatternMatch> match_patterns(std::span<const Pattern> patterns,
                                                       std::span<const LO> side_edges,
                                                       const MatchOptions& options = {},
                                                       bool cornerless = false);

/// match_patterns' results kept per (pattern list, side counts, options): a cavity growth matches
/// every convex state it passes through, and the same side counts come back across the growths
/// of a face (Block.stp at its reference count: most matches of remesh_cavities were repeats).
/// match_patterns is a function of its arguments, so a kept result is the one it would give.
/// A pattern list is identified by its address and size: it must stay alive and unchanged while
/// the cache is used (remesh_cavities keeps its lists for the whole call). One thread at a time.
class MatchCache {
 public:
  /// At most `max_entries` results are kept; when full, the cache starts over.
  explicit MatchCache(std::size_t max_entries = 1 << 15) : max_entries_(max_entries) {}
  /// match_patterns(patterns, side_edges, options, cornerless); the reference is valid until
  /// the next call.
  [[nodiscard]] const std::vector<PatternMatch>& matches(std::span<const Pattern> patterns,
                                                         std::span<const LO> side_edges,
                                                         const MatchOptions& options = {},
                                                         bool cornerless = false);
  [[nodiscard]] std::int64_t hits() const { return hits_; }
  [[nodiscard]] std::int64_t misses() const { return misses_; }

 private:
  struct Key {
    const Pattern* list;
    std::size_t size;
    int max_attempts;
    bool cornerless;
    std::vector<LO> sides;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const;
  };
  std::size_t max_entries_;
  std::int64_t hits_ = 0, misses_ = 0;
  std::unordered_map<Key, std::vector<PatternMatch>, KeyHash> results_;
};

/// Integer vectors spanning the kernel of the pattern's Eq. 14 matrix w: adding a multiple of one
/// to a solution changes no side's count, only where the pattern's irregular vertices sit (e.g.
/// how far up a rectangle's size transition is). One vector per free chord of the reduced row
/// echelon form, scaled to the smallest integers; empty when the sides fix every chord (the grid).
[[nodiscard]] std::vector<std::vector<LO>> chord_moves(const Pattern& pattern);

/// The refined quad mesh of a pattern: each coarse quad becomes an s_i x s_j grid, s from its two
/// chords (paper 000 Fig. 4, bottom).
struct RefinedPattern {
  LO num_vertices = 0;
  std::vector<std::array<LO, 4>> quads;  ///< counter-clockwise like the pattern
  /// Boundary vertices in the pattern's boundary order (starting at pattern side 0's first
  /// corner); boundary[side_start[i]] is the first vertex of side i, side i has sum_j w[i][j] s_j
  /// edges.
  std::vector<LO> boundary;
  std::vector<LO> side_start;
  std::vector<LO> coarse_vertex;  ///< refined id of each coarse vertex
};

/// Builds the refined mesh; chords[j] >= 1 for every chord. Refined ids: the coarse vertices
/// first (same ids), then edge interiors by edge, then quad interiors by quad. Throws
/// qsmesh::Error on a wrong number of chords or a non-positive subdivision.
[[nodiscard]] RefinedPattern refine_pattern(const Pattern& pattern, std::span<const LO> chords);

}  // namespace qsmesh::qstruct
