#include "qsmesh/qstruct/face_pattern.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/smooth/quad_tools.hpp"
#include "qsmesh/smooth/untangle.hpp"

namespace qsmesh::qstruct {

const char* to_string(Refusal r) {
  switch (r) {
    case Refusal::None:
      return "none";
    case Refusal::Loops:
      return "loops";
    case Refusal::Degenerate:
      return "degenerate";
    case Refusal::NoPattern:
      return "no_pattern";
    case Refusal::Quality:
      return "quality";
    case Refusal::TooManyQuads:
      return "too_many_quads";
    case Refusal::Error:
      return "error";
    case Refusal::UnstructuredBetter:
      return "unstructured_better";
  }
  return "?";
}

bool fill_to_compare(double sicn_avg, std::int64_t quads, std::int64_t irregular_interior,
                     std::int64_t field_singularities, const PatternFaceOptions& options) {
  if (options.compare_avg_margin < 0 || quads <= options.small_fill_quads) return false;
  if (!(sicn_avg > options.compare_below_avg)) return true;
  if (!options.compare_irregular || quads > options.compare_irregular_max_quads ||
      irregular_interior <= 0)
    return false;
  // At the field's count the unstructured mesh can only win on its mean, by more than the margin:
  // impossible above 1 - margin (SICN is at most 1).
  return !options.compare_above_field || irregular_interior > field_singularities ||
         !(sicn_avg > 1.0 - options.compare_avg_margin);
}

bool unstructured_clearly_better(const mesh::FaceQuadStats& fill,
                                 const mesh::FaceQuadStats& unstructured,
                                 const PatternFaceOptions& options) {
  if (options.compare_avg_margin < 0) return false;
  if (unstructured.quads <= 0 || unstructured.triangles > 0) return false;
  return unstructured.sicn_min > options.min_sicn &&
         unstructured.sicn_avg > fill.sicn_avg + options.compare_avg_margin;
}

bool unstructured_fewer_irregular(const mesh::FaceQuadStats& fill,
                                  const mesh::FaceQuadStats& unstructured, double tolerance,
                                  const PatternFaceOptions& options) {
  if (!options.compare_irregular) return false;
  if (unstructured.quads <= 0 || unstructured.triangles > 0 || !(unstructured.sicn_min > 0))
    return false;
  return unstructured.irregular_interior < fill.irregular_interior &&
         unstructured.sicn_min >= fill.sicn_min - tolerance &&
         unstructured.sicn_avg >= fill.sicn_avg - tolerance;
}

bool fill_wins(const mesh::FaceQuadStats& fill, const mesh::FaceQuadStats& unstructured, bool kept,
               double tolerance, const PatternFaceOptions& options) {
  if (kept)
    return !unstructured_clearly_better(fill, unstructured, options) &&
           !unstructured_fewer_irregular(fill, unstructured, tolerance, options);
  return fill.sicn_min >= unstructured.sicn_min - tolerance &&
         fill.sicn_avg >= unstructured.sicn_avg - tolerance &&
         fill.irregular_interior <= unstructured.irregular_interior;
}

namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

Vec3 project_tangent(const Vec3& t, const Vec3& n) { return t - n * dot(t, n); }

// Tangent of a curve use at its start (at_end false) or end, along the traversal direction.
// Where the parametrisation stalls (zero derivative), the first or last mesh edge stands in.
Vec3 use_tangent(const cad::CadModel& model, const cad::CurveUse& use, const mesh::CurveMesh& cm,
                 bool at_end) {
  const cad::Curve& curve = model.curves()[use.curve];
  const bool at_t1 = at_end != use.reversed;
  const auto geo = model.curve_geometry(use.curve);
  Vec3 d = geo->derivative(at_t1 ? curve.t1 : curve.t0);
  const LO n = cm.num_edges();
  const Vec3 edge = at_t1 ? cm.points[n] - cm.points[n - 1] : cm.points[1] - cm.points[0];
  // |dC/dt| (t1 - t0) and the mesh length are both the curve's length scale.
  if (!(norm(d) * (curve.t1 - curve.t0) > 1e-9 * norm(edge) * n)) d = edge;
  return use.reversed ? d * -1.0 : d;
}

// Starts tried for a face without corner (see try_sides); all are laid out, whatever
// PatternFaceOptions::max_candidates.
constexpr LO kCornerlessStarts = 8;

struct Candidate {
  PatternMatch match;
  RefinedPattern refined;
  std::vector<LO> seq;  // face loop point of each refined boundary position
  int score = 0;        // boundary valence mismatch at the corners that do not split sides
  double held = 1;      // lowest boundary_held_sicn at the loop points holding a single quad
};

mesh::FaceMesh build_mesh(LO f, const cad::Face& face, const cad::FaceGeometry& surface,
                          const FaceSides& fs, const Candidate& cand, linalg::SolverCache* cache) {
  const LO nb = static_cast<LO>(fs.points.size());
  const RefinedPattern& r = cand.refined;
  std::vector<LO> r2m(static_cast<std::size_t>(r.num_vertices), kNoIndex);
  for (std::size_t p = 0; p < r.boundary.size(); ++p) r2m[r.boundary[p]] = cand.seq[p];
  LO next = nb;
  for (LO v = 0; v < r.num_vertices; ++v)
    if (r2m[v] == kNoIndex) r2m[v] = next++;
  mesh::FaceMesh m;
  m.face = f;
  m.points.resize(next);
  m.uv.resize(next);
  m.vclass.resize(next);
  for (LO i = 0; i < nb; ++i) {
    m.points[i] = fs.points[i].xyz;
    m.uv[i] = fs.points[i].uv;
    m.vclass[i] = fs.points[i].vclass;
  }
  // The pattern's quads follow its boundary (interior on the left); mapped onto the face loop they
  // follow the loop, or run against it for a mirrored match. Counter-clockwise in (u, v) is along
  // du x dv, which is the face normal unless the face is reversed.
  const bool flip = ((fs.uv_area < 0) != cand.match.reversed) != face.reversed;
  m.quads.reserve(r.quads.size());
  for (const auto& q : r.quads) {
    const std::array<LO, 4> t{r2m[q[0]], r2m[q[1]], r2m[q[2]], r2m[q[3]]};
    m.quads.push_back(flip ? std::array<LO, 4>{t[0], t[3], t[2], t[1]} : t);
  }
  QSMESH_CHECK(smooth::chord_laplace_uv(m.quads, nb, m.uv, cache),
               "the Laplace layout is not finite");
  if (!fs.poles.empty()) {
    // Around a pole the parameter plane stretches without bound, and a (u, v) layout crowds the
    // quads there (cube_filet's corner patches: SICN min 0.52 against 0.86 for the same topology
    // made by the unstructured path). The same Laplace on x, y and z, projected onto the surface
    // from the (u, v) layout, spaces them as the boundary does in 3D.
    std::vector<Vec2> xy(m.uv.size()), z(m.uv.size());
    for (LO i = 0; i < nb; ++i) {
      xy[i] = {m.points[i].x, m.points[i].y};
      z[i] = {m.points[i].z, 0};
    }
    QSMESH_CHECK(
        smooth::laplace_uv(m.quads, nb, xy, cache) && smooth::laplace_uv(m.quads, nb, z, cache),
        "the 3D Laplace layout is not finite");
    for (LO v = nb; v < next; ++v)
      m.uv[v] = surface.project(Vec3{xy[v].u, xy[v].v, z[v].u}, m.uv[v], nullptr);
  }
  for (LO v = nb; v < next; ++v) {
    m.points[v] = surface.eval(m.uv[v]).p;
    m.vclass[v].dim = 2;
    m.vclass[v].entity = f;
    m.vclass[v].index = kNoIndex;
    m.vclass[v].param = {m.uv[v].u, m.uv[v].v};
  }
  return m;
}

// The move search's counts and times of `from` added to `to`: a face's report covers
// every search it ran.
void add_search_counts(PatternFaceReport& to, const PatternFaceReport& from) {
  to.layouts += from.layouts;
  to.batches += from.batches;
  to.search_seconds += from.search_seconds;
  to.layout_seconds += from.layout_seconds;
  to.layout_batches += from.layout_batches;
  to.layout_vectors += from.layout_vectors;
  to.lend_ranks = std::max(to.lend_ranks, from.lend_ranks);
  to.vector_lendable = std::max(to.vector_lendable, from.vector_lendable);
}

// One layout of a candidate: built (Laplace in (u, v)) and smoothed with `smooth`.
mesh::FaceMesh lay_out_candidate(LO f, const cad::Face& face, const cad::FaceGeometry& surface,
                                 const FaceSides& fs, const Candidate& c,
                                 const smooth::SmoothOptions& smooth, linalg::SolverCache* cache) {
  return smooth::smooth_face(build_mesh(f, face, surface, fs, c, cache), surface, smooth, nullptr,
                             cache);
}

// Whether the quads at or below min_sicn are few enough for the untangler to be worth a try
// (PatternFaceOptions::lift_max_poor_fraction).
bool few_poor_quads(const mesh::FaceMesh& m, const PatternFaceOptions& options, double min_sicn) {
  std::int64_t poor = 0;
  for (const auto& q : m.quads)
    if (mesh::quad_sicn({m.points[q[0]], m.points[q[1]], m.points[q[2]], m.points[q[3]]}) <=
        min_sicn)
      ++poor;
  const double bound =
      std::max(static_cast<double>(options.lift_min_poor_quads),
               options.lift_max_poor_fraction * static_cast<double>(m.quads.size()));
  return static_cast<double>(poor) <= bound;
}

// Whether a valid fill of `quads` quads with these SICN is kept: its minimum above min_sicn (the
// face's threshold, see try_sides) and its mean above options.min_sicn_avg, or its minimum above
// options.keep_sicn_min whatever its mean, or a small fill (options.small_fill_quads).
bool passes_sicn(double sicn_min, double sicn_avg, std::int64_t quads, double min_sicn,
                 const PatternFaceOptions& options) {
  return sicn_min > min_sicn &&
         (sicn_avg > options.min_sicn_avg || sicn_min > options.keep_sicn_min ||
          quads <= options.small_fill_quads);
}

// Whether a measured fill is kept: valid and passes_sicn.
bool passes(const smooth::QualityReport& q, double min_sicn, const PatternFaceOptions& options) {
  return q.invalid == 0 && passes_sicn(q.sicn_min, q.sicn_avg, q.quads, min_sicn, options);
}

// The report's pattern and placement from a candidate.
void report_pattern(PatternFaceReport& rep, std::span<const Pattern> patterns, const Candidate& c) {
  rep.pattern = c.match.pattern;
  rep.pattern_name = patterns[c.match.pattern].name;
  rep.start = c.match.start;
  rep.reversed = c.match.reversed;
}

// Paper 000 Sec. 6.1.1 picks the chord subdivisions closest to the balanced guess, blind to
// the geometry: a size transition in a rectangle lands halfway along it even when the face
// widens near one end (mambo's [102, 20, 102, 32] strips: rows of tall quads above the
// transition, SICN avg 0.93). Moves along the kernel of Eq. 14 keep every side's count and shift
// the pattern's irregular vertices; a local search over them keeps the best mean SICN.
//
// The search is serial (each step starts from the best so far), but the layouts a step may ask
// for are known before it: the four coarse points of a vector are offsets from where its search
// started, and a halving step tries +step then -step from the same best. With
// PatternFaceOptions::tasks of more than one thread each such batch is laid out at once, one task
// per layout (each with its own surface evaluator: an evaluator serves one thread), and the
// serial rules then read the layouts in their order: the same tries, counts and winner as the
// serial search, so the same fill; a layout the serial search would not have reached is wasted.
// With one thread the layouts are made when the rules reach them, as before.
mesh::FaceMesh move_irregular_vertices(const cad::CadModel& model, LO f, const cad::Face& face,
                                       const cad::FaceGeometry& surface, const FaceSides& fs,
                                       const Pattern& pattern, const Candidate& start,
                                       mesh::FaceMesh mesh, smooth::QualityReport q,
                                       double min_sicn, const PatternFaceOptions& options,
                                       PatternFaceReport& rep, linalg::SolverCache* cache) {
  const Stopwatch search_clock;
  // Without corner the pattern may also turn along the loop: an empty vector stands for that
  // shift (t loop points), searched last, over a quarter of the loop each way.
  const LO nb = static_cast<LO>(fs.points.size());
  std::vector<std::vector<LO>> moves = chord_moves(pattern);
  if (fs.corners.empty()) moves.emplace_back();
  if (moves.empty()) return mesh;
  Candidate best = start;
  const int moves_before = rep.moves;
  int evaluations = 0;
  // PatternFaceOptions::move_work_ratio: the search's layouts in proportion to the quads the
  // face asks for.
  int max_evaluations = options.move_evaluations;
  const auto start_quads = static_cast<double>(start.refined.quads.size());
  if (options.size_map_quads > 0 && options.move_work_ratio > 0 && start_quads > 0)
    max_evaluations = static_cast<int>(std::min<double>(
        max_evaluations, std::floor(options.move_work_ratio * options.size_map_quads *
                                    options.move_evaluations / start_quads)));
  // A search cut short inside the coarse sweeps of its vectors samples part of one range and
  // leaves the fill as it was, or nearly (PatternFaceOptions::move_min_layouts_per_vector).
  if (max_evaluations <
      options.move_min_layouts_per_vector * static_cast<std::int64_t>(moves.size())) {
    rep.chords = start.match.chords;
    rep.sicn_min = q.sicn_min;
    rep.sicn_avg = q.sicn_avg;
    rep.quads = static_cast<std::int64_t>(mesh.quads.size());
    return mesh;
  }
  // The layouts are compared after a few smoothing passes, the winner smoothed fully at the end;
  // the start is compared as the others are (the caller's mesh of it had every pass).
  smooth::SmoothOptions search = options.smooth;
  const bool light =
      options.move_search_iterations > 0 && options.move_search_iterations < search.iterations;
  if (light) search.iterations = options.move_search_iterations;
  const mesh::FaceMesh given = light ? mesh : mesh::FaceMesh{};
  const smooth::QualityReport given_q = q;
  if (light && q.invalid == 0) {
    mesh = smooth::smooth_face(build_mesh(f, face, surface, fs, start, cache), surface, search,
                               nullptr, cache);
    q = smooth::measure(mesh);
  }
  // The mean, less twice the shortfall of the minimum below its threshold: a refused fill climbs
  // toward the thresholds, a kept one (no shortfall) toward a higher mean.
  const auto score = [&](const smooth::QualityReport& r) {
    return r.sicn_avg + 2 * std::min(0.0, r.sicn_min - min_sicn);
  };
  // Whether fill `a` beats fill `b`: passing the thresholds first, then the score by more than
  // `margin`.
  const auto beats = [&](const smooth::QualityReport& a, const smooth::QualityReport& b,
                         double margin) {
    const bool good_a = passes(a, min_sicn, options), good_b = passes(b, min_sicn, options);
    return good_a != good_b ? good_a : score(a) > score(b) + margin;
  };
  // The candidate `origin` moved by t along v (by t loop points for the empty vector); none when
  // a chord would drop below 1 or the fill exceed max_quads. Moves add up: origin moved by a,
  // then by t - a, is origin moved by t.
  const auto moved = [&](const Candidate& origin, const std::vector<LO>& v,
                         LO t) -> std::optional<Candidate> {
    Candidate c = origin;
    if (v.empty()) {
      for (LO& p : c.seq) p = (((p + t) % nb) + nb) % nb;
    } else {
      for (std::size_t j = 0; j < v.size(); ++j) {
        c.match.chords[j] += t * v[j];
        if (c.match.chords[j] < 1) return std::nullopt;
      }
      c.refined = refine_pattern(pattern, c.match.chords);
    }
    if (options.max_quads > 0 &&
        static_cast<std::int64_t>(c.refined.quads.size()) > options.max_quads)
      return std::nullopt;
    return c;
  };
  struct Layout {
    Candidate c;
    mesh::FaceMesh mesh;
    smooth::QualityReport q;
    /// What laying it out threw, in a batch: thrown when the rules read it, as the serial search
    /// would have thrown there (a layout they never read must not fail the face).
    std::exception_ptr error;
  };
  // `with` is the face's solver cache on the serial path, none in a batch's tasks: the cache is
  // single-thread, and it gives the same bits as a fresh factorization.
  const auto lay_out = [&](Candidate c, const cad::FaceGeometry& on, linalg::SolverCache* with) {
    Layout l;
    l.mesh = lay_out_candidate(f, face, on, fs, c, search, with);
    l.q = smooth::measure(l.mesh);
    l.c = std::move(c);
    return l;
  };
  // The current vector's layouts, by offset from where its search started (`origin`).
  Candidate origin = best;
  std::map<LO, Layout> laid;
  LO at = 0;                // offset of `best` from origin
  bool used_batch = false;  // the rules read a layout of the current batch
  // Lays out at once those of `offsets` not laid out yet that the rules may still read (at most
  // the layouts left to the search), when there are threads for it.
  const auto lay_out_batch = [&](const std::vector<LO>& v, const std::vector<LO>& offsets) {
    used_batch = false;
    if (options.tasks == nullptr || options.tasks->threads() < 2) return;
    std::vector<std::pair<LO, Candidate>> todo;
    for (const LO t : offsets) {
      if (t == at || laid.count(t) != 0 ||
          static_cast<int>(todo.size()) >= max_evaluations - evaluations)
        continue;
      bool again = false;
      for (const auto& d : todo) again = again || d.first == t;
      if (again) continue;
      if (std::optional<Candidate> c = moved(origin, v, t)) todo.emplace_back(t, std::move(*c));
    }
    if (todo.size() < 2) return;  // nothing to gain; the rules lay it out when they get there
    std::vector<Layout> out(todo.size());
    options.tasks->parallel_for(static_cast<std::int64_t>(todo.size()), [&](std::int64_t k) {
      const auto u = static_cast<std::size_t>(k);
      try {
        const std::unique_ptr<cad::FaceGeometry> own = model.face_geometry(f);
        out[u] = lay_out(std::move(todo[u].second), *own, nullptr);
      } catch (...) {
        out[u].error = std::current_exception();
      }
    });
    for (std::size_t u = 0; u < todo.size(); ++u) laid.emplace(todo[u].first, std::move(out[u]));
  };
  // The serial rule: lays out the best candidate moved to offset t along v (from `laid` when the
  // batch made it); true (and best, mesh, q updated) when better.
  const auto try_move = [&](const std::vector<LO>& v, LO t) {
    if (t == at || evaluations >= max_evaluations) return false;
    auto it = laid.find(t);
    if (it == laid.end()) {
      std::optional<Candidate> c = moved(origin, v, t);
      if (!c) return false;
      const Stopwatch layout_clock;
      it = laid.emplace(t, lay_out(std::move(*c), surface, cache)).first;
      rep.layout_seconds += layout_clock.seconds();
    }
    // Counted by the batches the rules read from, whether or not they were laid out at once, so
    // that a run on one thread tells what the batches would be on several.
    if (!used_batch) {
      used_batch = true;
      ++rep.batches;
    }
    ++evaluations;
    ++rep.layouts;
    const Layout& l = it->second;
    if (l.error) std::rethrow_exception(l.error);
    if (l.q.invalid != 0) return false;
    if (!beats(l.q, q, 1e-4)) return false;
    best = l.c;
    mesh = l.mesh;
    q = l.q;
    at = t;
    ++rep.moves;
    return true;
  };
  // Lending (PatternFaceOptions::helpers, move_lend_layouts). A lent batch plans the offsets the
  // rules may read in the next levels of halving steps from where the search stands (a level:
  // every position the previous levels may have moved to, +step and -step each), up to
  // move_lend_layouts of them, and has them laid out over the free helpers and this worker at
  // once. The rules then read them in their order, as they read the threads' batches. Without
  // helpers (options.helpers null: one rank) the batches are only counted, as if move_lend_layouts
  // workers were free: what the scaling simulation replays; with helpers but none free, each
  // batch is the first level, and the rules lay out what they read.
  const bool lending = options.move_lend_layouts > 0;
  // Whether moved(origin, v, t) gives a candidate, without refining it: every chord at least 1
  // and the refined quads (per coarse quad, the product of its two chords) within max_quads.
  const auto feasible = [&](const std::vector<LO>& v, LO t) {
    if (v.empty())
      return options.max_quads <= 0 ||
             static_cast<std::int64_t>(origin.refined.quads.size()) <= options.max_quads;
    std::vector<LO> chords = origin.match.chords;
    for (std::size_t j = 0; j < v.size(); ++j) {
      chords[j] += t * v[j];
      if (chords[j] < 1) return false;
    }
    if (options.max_quads <= 0) return true;
    std::int64_t quads = 0;
    for (const auto& qe : pattern.quad_edges)
      quads += static_cast<std::int64_t>(chords[pattern.edge_chord[qe[0]]]) *
               chords[pattern.edge_chord[qe[1]]];
    return quads <= options.max_quads;
  };
  if (lending) rep.vector_lendable = 1;
  std::set<LO> planned;  // offsets from origin planned by the current vector's batches
  // The levels of halving steps from `step` down (each the new offsets it may read, in the order
  // the rules read them: +step before -step, positions in increasing order), while they add up
  // to at most move_lend_layouts (the first level always). Offsets no move reaches (a chord below
  // 1, a fill above max_quads) are left out, and so are the positions they would lead to.
  const auto halving_levels = [&](const std::vector<LO>& v, LO step) {
    std::vector<std::vector<LO>> levels;
    std::set<LO> positions{at}, seen;
    std::size_t total = 0;
    for (LO s = step; s >= 1; s /= 2) {
      std::vector<LO> level;
      std::set<LO> reached = positions;
      for (const LO p : positions)
        for (const LO t : {p + s, p - s}) {
          if (!feasible(v, t)) continue;
          reached.insert(t);
          if (seen.insert(t).second) level.push_back(t);
        }
      if (!levels.empty() &&
          total + level.size() > static_cast<std::size_t>(options.move_lend_layouts))
        break;
      total += level.size();
      levels.push_back(std::move(level));
      positions = std::move(reached);
    }
    return levels;
  };
  // Plans a lent batch when the first level holds an offset not planned yet: counts it, and lays
  // out as many of its levels as the helpers claimed can take at once (each worker one layout,
  // one level at least) over them and this worker.
  const auto plan_batch = [&](const std::vector<LO>& v, std::vector<std::vector<LO>> levels) {
    if (levels.empty() || evaluations >= max_evaluations) return;  // the rules read no more
    bool fresh = false;
    for (const LO t : levels.front())
      fresh = fresh || (t != at && planned.count(t) == 0 && laid.count(t) == 0 && feasible(v, t));
    if (!fresh) return;
    std::size_t total = 0;
    for (const auto& level : levels) total += level.size();
    int workers = options.move_lend_layouts;  // counted only, no helper free
    if (options.helpers != nullptr) {
      const int want = static_cast<int>(std::min<std::size_t>(
                           total, static_cast<std::size_t>(options.move_lend_layouts))) -
                       1;
      workers = 1 + (want > 0 ? options.helpers->claim(want) : 0);
    }
    // The deepest levels that give each worker one layout, the first level at least.
    std::vector<LO> offsets;
    for (std::size_t l = 0; l < levels.size(); ++l) {
      if (l > 0 && offsets.size() + levels[l].size() > static_cast<std::size_t>(workers)) break;
      for (const LO t : levels[l])
        if ((l > 0 || t != at) && planned.count(t) == 0 && laid.count(t) == 0 &&
            std::find(offsets.begin(), offsets.end(), t) == offsets.end() && feasible(v, t))
          offsets.push_back(t);
    }
    for (const LO t : offsets) planned.insert(t);
    ++rep.layout_batches;
    rep.layout_vectors += static_cast<int>(offsets.size());
    // No helper free: the rules lay out what they read, as the serial search does (laying out
    // -step before knowing whether +step wins would cost this worker a layout).
    if (options.helpers == nullptr || workers < 2) return;
    rep.lend_ranks = std::max(rep.lend_ranks, workers - 1);
    std::vector<MoveLayoutRequest> requests;
    std::vector<Candidate> cands;
    std::vector<LO> at_offset;
    for (const LO t : offsets) {
      std::optional<Candidate> c = moved(origin, v, t);
      if (!c) continue;
      at_offset.push_back(t);
      MoveLayoutRequest r;
      r.face = f;
      r.pattern = c->match.pattern;
      r.reversed = c->match.reversed;
      r.chords = c->match.chords;
      r.seq = c->seq;
      r.smooth_iterations = search.iterations;
      requests.push_back(std::move(r));
      cands.push_back(std::move(*c));
    }
    // Released even when this worker keeps every layout (lay_out hands each claimed one a share).
    std::vector<MoveLayoutResult> results =
        options.helpers->lay_out(requests, [&](const MoveLayoutRequest& r) {
          const Stopwatch layout_clock;
          MoveLayoutResult out;
          const auto u = static_cast<std::size_t>(&r - requests.data());
          try {
            out.mesh = lay_out_candidate(f, face, surface, fs, cands[u], search, cache);
            out.quality = smooth::measure(out.mesh);
          } catch (const Error& e) {
            out.error = e.message();
          } catch (const std::exception& e) {
            out.error = e.what();
          }
          rep.layout_seconds += layout_clock.seconds();
          return out;
        });
    QSMESH_CHECK(results.size() == requests.size(),
                 "move layouts: " << results.size() << " results for " << requests.size());
    for (std::size_t u = 0; u < results.size(); ++u) {
      Layout l;
      l.c = std::move(cands[u]);
      if (!results[u].error.empty()) {
        l.error = std::make_exception_ptr(Error(results[u].error));
      } else {
        l.mesh = std::move(results[u].mesh);
        l.q = results[u].quality;
      }
      laid.emplace(at_offset[u], std::move(l));
    }
  };
  for (const auto& v : moves) {
    // Feasible range [lo, hi] of t (every chord stays >= 1).
    LO lo = std::numeric_limits<LO>::min(), hi = std::numeric_limits<LO>::max();
    if (v.empty()) lo = -nb / 4, hi = nb / 4;
    for (std::size_t j = 0; j < v.size(); ++j) {
      if (v[j] > 0) lo = std::max(lo, -((best.match.chords[j] - 1) / v[j]));
      if (v[j] < 0) hi = std::min(hi, (best.match.chords[j] - 1) / -v[j]);
    }
    // A move that only adds (a closed chord's layers) has no bound from the sides: it may
    // double the chords it adds to.
    if (hi == std::numeric_limits<LO>::max()) {
      hi = 0;
      for (std::size_t j = 0; j < v.size(); ++j)
        if (v[j] > 0) hi = std::max(hi, best.match.chords[j] / v[j]);
    }
    if (lo == std::numeric_limits<LO>::min() || hi - lo < 1) continue;
    origin = best;
    laid.clear();
    planned.clear();
    at = 0;
    // Coarse: four points spread over the range; then halving steps around the best.
    const LO span = std::max<LO>(1, (hi - lo) / 5);
    std::vector<LO> coarse;
    for (int k = 1; k <= 4; ++k) coarse.push_back(lo + k * (hi - lo) / 5);
    used_batch = false;  // a step: the rules' batch (counted whether or not laid out at once)
    if (lending) plan_batch(v, {coarse});
    if (!lending || options.helpers == nullptr) lay_out_batch(v, coarse);
    for (const LO t : coarse) try_move(v, t);
    for (LO step = std::max<LO>(1, span / 2); step >= 1; step /= 2) {
      used_batch = false;
      if (lending) plan_batch(v, halving_levels(v, step));
      if (!lending || options.helpers == nullptr) lay_out_batch(v, {at + step, at - step});
      if (!try_move(v, at + step)) try_move(v, at - step);
    }
  }
  if (light && rep.moves > moves_before) {
    mesh::FaceMesh full = smooth::smooth_face(build_mesh(f, face, surface, fs, best, cache),
                                              surface, options.smooth, nullptr, cache);
    const smooth::QualityReport fq = smooth::measure(full);
    // The given mesh may have been lifted (untangled) where the light start was not: the moved
    // fill wins only when it is also better smoothed fully.
    const bool wins = fq.invalid == 0 && (given_q.invalid != 0 || beats(fq, given_q, 0.0));
    if (wins) {
      mesh = std::move(full);
      q = fq;
    } else {
      best = start;
      mesh = given;
      q = given_q;
      rep.moves = moves_before;
    }
  } else if (light) {
    mesh = given;
    q = given_q;
  }
  rep.chords = best.match.chords;
  rep.sicn_min = q.sicn_min;
  rep.sicn_avg = q.sicn_avg;
  rep.quads = static_cast<std::int64_t>(mesh.quads.size());
  rep.search_seconds += search_clock.seconds();
  return mesh;
}

void set_side_edges(FaceSides& fs) {
  const LO n = static_cast<LO>(fs.points.size());
  const LO m = static_cast<LO>(fs.corners.size());
  fs.side_edges.clear();
  if (m == 0) fs.side_edges.push_back(n);  // one smooth loop: one side closing on itself
  for (LO k = 0; k < m; ++k) {
    const LO a = fs.corners[k], b = k + 1 < m ? fs.corners[k + 1] : fs.corners[0] + n;
    fs.side_edges.push_back(b - a);
  }
}

// A closed chord (the disk pattern's ring) is the layers between the centre quad and the side.
// In a round disk of radius R whose centre quad has sides R the ring is R / 2 = A / P wide (A the
// area, P the perimeter), A N / P^2 layers in edges of the boundary's spacing P / N. On a long
// face this is too many (a 16 x 2 slot: 7 layers where 2 fit), and the move search of each start
// brings it down; scaling it by the roundness 4 pi A / P^2 instead was no better (stadiums 2-16
// long: better on some, worse on others; Block's slots 9 and 220: SICN avg 0.98 -> 0.93). A is
// the loop's vector area (exact on a plane, the projected area on a curved face).
LO ring_layers(const FaceSides& fs) {
  const LO nb = static_cast<LO>(fs.points.size());
  Vec3 twice_area{0, 0, 0};
  double perimeter = 0;
  for (LO i = 0; i < nb; ++i) {
    const Vec3& a = fs.points[i].xyz;
    const Vec3& b = fs.points[(i + 1) % nb].xyz;
    twice_area = twice_area + cross(a - fs.points[0].xyz, b - fs.points[0].xyz);
    perimeter += norm(b - a);
  }
  if (!(perimeter > 0)) return 1;
  return std::max<LO>(
      1, static_cast<LO>(std::lround(0.5 * norm(twice_area) * nb / (perimeter * perimeter))));
}

// Matching, ranking and geometric trials for one split of the boundary into sides. Fills `rep`
// (ok, or the refusal and its reason) and returns the mesh kept, or an empty one.
mesh::FaceMesh try_sides(const cad::CadModel& model, LO f, const cad::Face& face,
                         const cad::FaceGeometry& surface, const FaceSides& fs,
                         std::span<const Pattern> patterns, const PatternFaceOptions& options,
                         PatternFaceReport& rep, linalg::SolverCache* cache) {
  const ErrorContext context{"qstruct", 2, f};
  mesh::FaceMesh empty;
  empty.face = f;
  rep = PatternFaceReport{};
  rep.side_edges = fs.side_edges;
  const auto refuse = [&](Refusal why, const std::string& msg) {
    rep.ok = false;
    rep.refusal = why;
    rep.reason = Error(msg, context).what();
    rep.quads = 0;
    return empty;
  };
  const std::vector<PatternMatch> matches =
      match_patterns(patterns, fs.side_edges, options.match, fs.corners.empty());
  if (matches.empty()) {
    std::ostringstream os;
    os << "no pattern fits the sides [";
    for (std::size_t i = 0; i < fs.side_edges.size(); ++i) os << (i ? "," : "") << fs.side_edges[i];
    os << "]";
    return refuse(Refusal::NoPattern, os.str());
  }

  const LO nb = static_cast<LO>(fs.points.size());
  const LO m = static_cast<LO>(fs.corners.size());
  LO layers = 0;  // ring_layers(fs), computed for the first pattern with a closed chord
  std::vector<char> splits(nb, 0);
  for (const LO c : fs.corners) splits[c] = 1;
  std::vector<Candidate> cands, oversize;
  std::int64_t fewest_quads = -1;
  for (const auto& match : matches) {
    const Pattern& pat = patterns[match.pattern];
    PatternMatch sized = match;
    for (LO j = 0; j < pat.num_chords; ++j)
      if (pat.closed_chord(j)) {
        if (layers == 0) layers = ring_layers(fs);
        sized.chords[j] = layers;
      }
    const RefinedPattern refined = refine_pattern(pat, sized.chords);
    const auto nq = static_cast<std::int64_t>(refined.quads.size());
    if (fewest_quads < 0 || nq < fewest_quads) fewest_quads = nq;
    QSMESH_CHECK(
        static_cast<LO>(refined.boundary.size()) == nb,
        "refined boundary has " << refined.boundary.size() << " vertices, the face " << nb);
    std::vector<int> valence(static_cast<std::size_t>(refined.num_vertices), 0);
    for (const auto& q : refined.quads)
      for (const LO v : q) ++valence[v];
    // Without corner any loop point may start the single side, and where the pattern's corners
    // land matters as soon as the face is not round (an ellipse 3:1 with 32 edges: SICN avg 0.83
    // from one start, 0.66 from another). The disk pattern is the same after a half turn, so
    // starts spread over half the loop are tried, each then moved by the search.
    std::vector<LO> firsts;
    if (m == 0) {
      for (LO k = 0; k < kCornerlessStarts; ++k) firsts.push_back(k * nb / (2 * kCornerlessStarts));
    } else {
      firsts.push_back(match.reversed ? fs.corners[(match.start + 1) % m]
                                      : fs.corners[match.start]);
    }
    for (const LO first : firsts) {
      Candidate c;
      c.match = sized;
      c.refined = refined;
      c.seq.resize(nb);
      for (LO p = 0; p < nb; ++p)
        c.seq[p] = (((match.reversed ? first - p : first + p) % nb) + nb) % nb;
      for (LO p = 0; p < nb; ++p) {
        const LO i = c.seq[p];
        if (splits[i]) continue;
        const int ideal = fs.points[i].vclass.dim == 0
                              ? std::max(2, static_cast<int>(std::lround(fs.angle_deg[i] / 90.0)))
                              : 2;
        c.score += std::abs(valence[refined.boundary[p]] - ideal);
      }
      for (LO p = 0; p < nb; ++p) {
        if (valence[refined.boundary[p]] != 1) continue;
        const LO i = c.seq[p];
        const Vec3& at = fs.points[i].xyz;
        c.held = std::min(c.held, boundary_held_sicn(fs.points[(i + nb - 1) % nb].xyz - at,
                                                     fs.points[(i + 1) % nb].xyz - at));
      }
      (options.max_quads > 0 && nq > options.max_quads ? oversize : cands).push_back(std::move(c));
    }
  }
  // matches come sorted by pattern order and energy; the valence fit goes first.
  const auto by_score = [](const Candidate& a, const Candidate& b) { return a.score < b.score; };
  std::stable_sort(cands.begin(), cands.end(), by_score);
  std::stable_sort(oversize.begin(), oversize.end(), by_score);

  // The quad at a corner of angle a below 90 degrees reaches at best SICN sin(a) (equal edges):
  // a threshold above that would refuse every mesh of the face, the unstructured one included.
  double min_sicn = options.min_sicn;
  for (const LO c : fs.corners) {
    const double reachable = std::sin(fs.angle_deg[c] * std::numbers::pi / 180);
    if (fs.angle_deg[c] < 90 && reachable <= options.min_sicn)
      min_sicn = std::min(min_sicn, options.corner_sicn_factor * reachable);
  }
  rep.min_sicn = min_sicn;
  const auto keep = [&](mesh::FaceMesh kept) {
    rep.ok = true;
    rep.refusal = Refusal::None;
    return kept;
  };
  if (cands.empty()) {
    std::ostringstream os;
    os << "every fitting pattern needs at least " << fewest_quads << " quads, more than the "
       << options.max_quads << " the size map allows";
    if (options.move_evaluations > 0 &&
        !(oversize.front().held < options.held_sicn_ratio * min_sicn)) {
      // The balanced subdivisions put a transition where it costs the most quads; moved, the
      // same pattern may fit the bound (Block's half-disks [60, 78] at size factor 0.0037). The
      // search starts from a worst-possible score and lays out only the moves within the bound.
      const Candidate& c = oversize.front();
      report_pattern(rep, patterns, c);
      smooth::QualityReport none;
      none.invalid = 1;
      none.sicn_min = -1;
      none.sicn_avg = -1;
      mesh::FaceMesh moved =
          move_irregular_vertices(model, f, face, surface, fs, patterns[c.match.pattern], c,
                                  mesh::FaceMesh{}, none, min_sicn, options, rep, cache);
      if (rep.moves > 0) {
        ++rep.candidates;
        // A move is kept only when its fill is valid, so the moved fill is.
        if (passes_sicn(rep.sicn_min, rep.sicn_avg, static_cast<std::int64_t>(moved.quads.size()),
                        min_sicn, options))
          return keep(std::move(moved));
        refuse(Refusal::Quality, os.str() + "; moved, " + rep.pattern_name +
                                     " fits with SICN min " + std::to_string(rep.sicn_min) +
                                     " avg " + std::to_string(rep.sicn_avg));
        rep.quads = static_cast<std::int64_t>(moved.quads.size());
        rep.refused_mesh = std::move(moved);
        return empty;
      }
    }
    return refuse(Refusal::TooManyQuads, os.str());
  }
  mesh::FaceMesh best;
  bool best_valid = false, best_good = false;
  int best_k = 0;
  smooth::QualityReport best_q;
  const int tries = std::min<int>(m == 0 ? kCornerlessStarts : std::max(1, options.max_candidates),
                                  static_cast<int>(cands.size()));
  bool best_held = false;  // the best candidate is held below the threshold (held_sicn_ratio)
  for (int k = 0; k < tries; ++k) {
    const Candidate& c = cands[k];
    // A candidate held below the threshold fails it whatever is done to it: only the first is
    // laid out, for the caller's comparison.
    const bool held = c.held < options.held_sicn_ratio * min_sicn;
    if (held && k > 0) continue;
    mesh::FaceMesh mesh = smooth::smooth_face(build_mesh(f, face, surface, fs, c, cache), surface,
                                              options.smooth, nullptr, cache);
    smooth::QualityReport q = smooth::measure(mesh);
    // A layout good on average but with a few poor quads (usually next to an irregular vertex of
    // the pattern, or a folded corner of a size transition) is worth lifting locally; the
    // smoothing kernels never lower the minimum, so they cannot get out of a fold.
    if (!held && options.lift_poor_quads && (q.invalid > 0 || q.sicn_min <= min_sicn) &&
        q.sicn_avg > options.min_sicn_avg && few_poor_quads(mesh, options, min_sicn)) {
      ++rep.lifts;
      smooth::UntangleOptions uo;
      uo.target = min_sicn + 0.05;
      uo.max_rings = std::max(uo.rings, options.lift_max_rings);
      mesh = smooth::untangle_face(mesh, surface, uo);
      q = smooth::measure(mesh);
    }
    ++rep.candidates;
    // Without corner every valid start is moved and the starts compete after their moves: the
    // best start balanced is often not the best moved (an ellipse 2:1 with 64 edges: SICN avg
    // 0.78 against 0.97).
    std::vector<LO> chords = c.match.chords;
    if (!held && m == 0 && options.move_evaluations > 0 && q.invalid == 0 && q.sicn_min > 0 &&
        q.sicn_avg < options.move_below_avg) {
      PatternFaceReport trial;
      mesh = move_irregular_vertices(model, f, face, surface, fs, patterns[c.match.pattern], c,
                                     std::move(mesh), q, min_sicn, options, trial, cache);
      rep.moves += trial.moves;
      add_search_counts(rep, trial);
      q.sicn_min = trial.sicn_min;
      q.sicn_avg = trial.sicn_avg;
      chords = trial.chords;
    }
    const bool good = passes(q, min_sicn, options);
    // The first good candidate wins, except without corner, where the starts compete on the mean.
    const bool better =
        best_good ? good && q.sicn_avg > rep.sicn_avg : good || k == 0 || q.sicn_min > rep.sicn_min;
    if (better) {
      best_held = held;
      best_good = good;
      best_valid = q.invalid == 0 && q.sicn_min > 0;
      best_k = k;
      best_q = q;
      report_pattern(rep, patterns, c);
      rep.chords = chords;
      rep.sicn_min = q.sicn_min;
      rep.sicn_avg = q.sicn_avg;
      rep.quads = static_cast<std::int64_t>(mesh.quads.size());
      best = std::move(mesh);
    }
    // ... until one needs no moves (its mean at or above move_below_avg).
    if (m == 0 && best_good && (k + 1 == tries || rep.sicn_avg >= options.move_below_avg))
      return keep(std::move(best));
    if (m != 0 && best_good) {
      if (options.move_evaluations > 0 && best_q.sicn_avg < options.move_below_avg)
        best = move_irregular_vertices(model, f, face, surface, fs, patterns[c.match.pattern], c,
                                       std::move(best), best_q, min_sicn, options, rep, cache);
      return keep(std::move(best));
    }
  }
  if (best_valid && !best_held && m != 0 && options.move_evaluations > 0) {
    // The best valid candidate below the thresholds may pass them with its irregular vertices
    // elsewhere (Block's half-disks [60, 78]: SICN avg 0.53 balanced, 0.84 moved). Without
    // corner every start was moved already.
    const Candidate& c = cands[best_k];
    best = move_irregular_vertices(model, f, face, surface, fs, patterns[c.match.pattern], c,
                                   std::move(best), best_q, min_sicn, options, rep, cache);
    if (passes_sicn(rep.sicn_min, rep.sicn_avg, static_cast<std::int64_t>(best.quads.size()),
                    min_sicn, options))
      return keep(std::move(best));
  }
  std::ostringstream os;
  os << rep.candidates << " candidate(s) tried, best " << rep.pattern_name << " with SICN min "
     << rep.sicn_min << " avg " << rep.sicn_avg << " (thresholds " << min_sicn << ", "
     << options.min_sicn_avg << ")";
  refuse(Refusal::Quality, os.str());
  if (best_valid) {
    rep.quads = static_cast<std::int64_t>(best.quads.size());
    rep.refused_mesh = std::move(best);
  }
  return empty;
}

}  // namespace

MoveLayoutResult lay_out_move(const cad::CadModel& model, const FaceSides& fs,
                              std::span<const Pattern> patterns,
                              const smooth::SmoothOptions& smooth,
                              const MoveLayoutRequest& request) {
  MoveLayoutResult out;
  try {
    QSMESH_CHECK(request.face >= 0 && request.face < model.num_faces() && request.pattern >= 0 &&
                     request.pattern < static_cast<LO>(patterns.size()) &&
                     request.seq.size() == fs.points.size(),
                 "move layout request of face " << request.face << " does not fit its sides");
    Candidate c;
    c.match.pattern = request.pattern;
    c.match.reversed = request.reversed;
    c.match.chords = request.chords;
    c.refined = refine_pattern(patterns[request.pattern], request.chords);
    c.seq = request.seq;
    smooth::SmoothOptions so = smooth;
    so.iterations = request.smooth_iterations;
    const auto surface = model.face_geometry(request.face);
    out.mesh =
        lay_out_candidate(request.face, model.faces()[request.face], *surface, fs, c, so, nullptr);
    out.quality = smooth::measure(out.mesh);
  } catch (const Error& e) {
    out = MoveLayoutResult{};
    out.error = e.message();
  } catch (const std::exception& e) {
    out = MoveLayoutResult{};
    out.error = e.what();
  }
  return out;
}

double boundary_held_sicn(const Vec3& a, const Vec3& b) {
  const double denom = norm2(a) + norm2(b);
  return denom > 0 ? 2.0 * norm(cross(a, b)) / denom : 0.0;
}

FaceSides face_sides(const cad::CadModel& model, LO f, const cad::FaceGeometry& surface,
                     std::span<const mesh::CurveMesh> curves, const PatternFaceOptions& options) {
  const cad::Face& face = model.faces()[f];
  QSMESH_CHECK(face.loops.size() == 1, "the face has " << face.loops.size() << " boundary loops");
  QSMESH_CHECK(face.loops_closed, "the boundary loop is not closed");
  const auto& uses = face.loops[0].uses;
  const LO nu = static_cast<LO>(uses.size());
  const auto degenerate = [&](LO u) { return model.curves()[uses[u].curve].degenerate; };
  QSMESH_CHECK(
      std::any_of(uses.begin(), uses.end(),
                  [&](const cad::CurveUse& x) { return !model.curves()[x.curve].degenerate; }),
      "the boundary loop has only degenerate curves");
  const auto next_regular = [&](LO u) {
    do u = (u + 1) % nu;
    while (degenerate(u));
    return u;
  };
  FaceSides fs;
  const auto loops = background::face_boundary(model, f, surface, curves);
  const auto& raw = loops[0].points;
  // A degenerate curve (a pole: a cone's apex, the nose of a fuselage) is one point in 3D but a
  // segment of the parameter plane. Its use gives no edge: its copies of the pole merge into the
  // first point of the next use, at their mean (u, v), so the pole is one corner where the curves
  // on either side meet and a cone sector is a triangle. The mean keeps the (u, v) loop simple for
  // the Laplace layout; the smoothing works on the surface and leaves boundary points in place.
  // pole_copies[u], pole_uv[u]: the copies merged into regular use u's first point, their sum.
  std::vector<LO> pole_copies(static_cast<std::size_t>(nu), 0);
  std::vector<Vec2> pole_uv(static_cast<std::size_t>(nu), Vec2{0, 0});
  LO rpos = 0;
  for (LO u = 0; u < nu; ++u) {
    const LO ne = curves[uses[u].curve].num_edges();
    fs.use_start.push_back(static_cast<LO>(fs.points.size()));
    if (degenerate(u)) {
      const LO to = next_regular(u);
      for (LO i = 0; i < ne; ++i)
        pole_uv[to] = pole_uv[to] + raw[static_cast<std::size_t>(rpos + i)].uv;
      pole_copies[to] += ne;
    } else {
      for (LO i = 0; i < ne; ++i) fs.points.push_back(raw[static_cast<std::size_t>(rpos + i)]);
    }
    rpos += ne;
  }
  QSMESH_CHECK(rpos == static_cast<LO>(raw.size()),
               "the boundary loop does not match the curve meshes");
  const LO n = static_cast<LO>(fs.points.size());
  for (LO& s : fs.use_start) s %= n;  // trailing degenerate uses end where the loop starts
  for (LO u = 0; u < nu; ++u)
    if (pole_copies[u] > 0) {
      auto& p = fs.points[static_cast<std::size_t>(fs.use_start[u])];
      p.uv = (p.uv + pole_uv[u]) * (1.0 / static_cast<double>(pole_copies[u] + 1));
    }
  for (LO i = 0; i < n; ++i) fs.uv_area += 0.5 * cross(fs.points[i].uv, fs.points[(i + 1) % n].uv);
  QSMESH_CHECK(fs.uv_area != 0, "the boundary loop has no area in the parameter plane");

  fs.angle_deg.assign(n, 180.0);
  const double orient = fs.uv_area > 0 ? 1.0 : -1.0;
  const auto point_uv = [&](LO i) {
    return fs.points[static_cast<std::size_t>((i % n + n) % n)].uv;
  };
  const auto unit_normal_at = [&](const Vec2& uv) {
    const auto ev = surface.eval(uv);
    const Vec3 c = cross(ev.du, ev.dv);
    return norm(c) > 0 ? normalized(c) : c;
  };
  const auto unit_normal = [&](LO i) { return unit_normal_at(point_uv(i)); };
  // Just off a pole towards loop point i: the normal there tends to the pole's own on a smooth
  // surface (a fuselage nose), to the side's at a cone's apex; the loop point itself if singular.
  const auto normal_off_pole = [&](LO pole, LO i) {
    const Vec3 near = unit_normal_at(point_uv(pole) + (point_uv(i) - point_uv(pole)) * 1e-3);
    return norm(near) > 0 ? near : unit_normal(i);
  };
  LO prev = nu - 1;  // the last regular use before u
  while (degenerate(prev)) --prev;
  for (LO u = 0; u < nu; ++u) {
    if (degenerate(u)) continue;
    const LO pos = fs.use_start[u];
    // A pole between the two uses of a seam (a sphere's, a whole cone's) lies inside the face,
    // not on a boundary made of the other curves.
    QSMESH_CHECK(pole_copies[u] == 0 || uses[prev].curve != uses[u].curve,
                 "pole between the two uses of seam curve " << uses[u].curve);
    const Vec3 t_in = use_tangent(model, uses[prev], curves[uses[prev].curve], true);
    const Vec3 t_out = use_tangent(model, uses[u], curves[uses[u].curve], false);
    // At a pole du x dv vanishes: the mean of the normals just off it towards its two neighbours.
    Vec3 normal = pole_copies[u] > 0 ? normal_off_pole(pos, pos - 1) + normal_off_pole(pos, pos + 1)
                                     : unit_normal(pos);
    QSMESH_CHECK(norm(normal) > 0 && norm(t_in) > 0 && norm(t_out) > 0,
                 "singular surface or curve at the corner of curve " << uses[u].curve);
    // With the normal du x dv flipped for a clockwise (u, v) loop, the interior lies on the left.
    normal = normalized(normal) * orient;
    const Vec3 a = normalized(project_tangent(t_in, normal)),
               b = normalized(project_tangent(t_out, normal));
    const double turn = std::atan2(dot(cross(a, b), normal), dot(a, b)) * kDeg;
    fs.angle_deg[pos] = 180.0 - turn;
    if (fs.angle_deg[pos] < options.corner_angle_deg) fs.corners.push_back(pos);
    if (pole_copies[u] > 0) fs.poles.push_back(pos);
    prev = u;
  }
  set_side_edges(fs);
  return fs;
}

int side_of(const FaceSides& fs, LO pos) {
  const auto after = std::upper_bound(fs.corners.begin(), fs.corners.end(), pos);
  return after == fs.corners.begin() ? static_cast<int>(fs.corners.size()) - 1
                                     : static_cast<int>(after - fs.corners.begin()) - 1;
}

mesh::FaceMesh mesh_face_pattern(const cad::CadModel& model, LO f,
                                 std::span<const mesh::CurveMesh> full_curves,
                                 std::span<const Pattern> patterns,
                                 const PatternFaceOptions& options, PatternFaceReport* report) {
  PatternFaceReport local;
  PatternFaceReport& rep = report != nullptr ? *report : local;
  rep = PatternFaceReport{};
  const ErrorContext context{"qstruct", 2, f};
  mesh::FaceMesh empty;
  empty.face = f;
  const auto refuse = [&](Refusal why, const std::string& msg) {
    rep.ok = false;
    rep.refusal = why;
    rep.reason = Error(msg, context).what();
    return empty;
  };
  const cad::Face& face = model.faces()[f];
  if (face.loops.size() != 1)
    return refuse(Refusal::Loops,
                  "the face has " + std::to_string(face.loops.size()) + " boundary loops");
  if (!face.loops_closed) return refuse(Refusal::Loops, "the boundary loop is not closed");
  try {
    const auto surface = model.face_geometry(f);
    FaceSides fs;
    try {
      fs = face_sides(model, f, *surface, full_curves, options);
    } catch (const Error& e) {
      return refuse(Refusal::Degenerate, e.message());
    }
    // One cache for the face's layouts: the move search lays out the same quads again and again.
    linalg::SolverCache cache;
    mesh::FaceMesh out = try_sides(model, f, face, *surface, fs, patterns, options, rep, &cache);
    if (rep.ok) return out;
    // Convex but blunt corners may be better taken as flat: one more try without them.
    FaceSides soft = fs;
    soft.corners.clear();
    for (const LO c : fs.corners)
      if (fs.angle_deg[c] < options.soft_corner_angle_deg) soft.corners.push_back(c);
    if (soft.corners.size() == fs.corners.size()) return out;
    set_side_edges(soft);
    PatternFaceReport second;
    out = try_sides(model, f, face, *surface, soft, patterns, options, second, &cache);
    // Report the attempt that got further (a quality refusal says more than no pattern).
    // Between two quality refusals, the one whose valid candidate has the higher minimum.
    const bool second_better =
        second.ok || (rep.refusal != Refusal::Quality && second.refusal == Refusal::Quality) ||
        (rep.refusal == Refusal::Quality && second.refusal == Refusal::Quality &&
         !second.refused_mesh.quads.empty() &&
         (rep.refused_mesh.quads.empty() || second.sicn_min > rep.sicn_min));
    // The search's counts and time cover both attempts (the pattern stage's batched schedule):
    // the kept report takes the other's (sums and maxima, so the order does not matter).
    if (second_better) {
      add_search_counts(second, rep);
      rep = std::move(second);
    } else {
      add_search_counts(rep, second);
    }
    return out;
  } catch (const Error& e) {
    rep.quads = 0;
    rep.ok = false;
    rep.refusal = Refusal::Error;
    rep.reason = e.with_context(context).what();
    return empty;
  } catch (const std::exception& e) {
    return refuse(Refusal::Error, e.what());
  }
}

}  // namespace qsmesh::qstruct
