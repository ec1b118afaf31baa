#include "qsmesh/parallel/face_task.hpp"

#include <algorithm>
#include <exception>
#include <string>
#include <utility>

#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"

namespace qsmesh::parallel {

CrossFieldOutput summarize(const crossfield::FaceCrossField& cf) {
  CrossFieldOutput out;
  out.ok = true;
  const std::size_t nt = cf.triangles.size();
  out.directions = cf.directions;
  out.u_norm.resize(nt);
  out.H.resize(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    double un = 0, h = 0;
    for (int k = 0; k < 3; ++k) {
      un += cf.u_norm[cf.tri2edges[t][k]];
      h += cf.H[cf.triangles[t][k]];
    }
    out.u_norm[t] = un / 3;
    out.H[t] = h / 3;
  }
  out.singularities = cf.singularities;
  out.euler = cf.euler;
  out.levels = cf.stats.levels;
  out.factorizations = cf.stats.factorizations;
  out.solves = cf.stats.solves;
  out.stalled_levels = cf.stats.stalled_levels;
  out.iterations_per_level.assign(cf.stats.iterations_per_level.begin(),
                                  cf.stats.iterations_per_level.end());
  out.seconds = cf.stats.seconds;
  out.solver = cf.stats.solver;
  return out;
}

void mesh_background(FaceTask& task, const cad::CadModel& model,
                     std::span<const mesh::CurveMesh> curves,
                     const background::BackgroundOptions& options) {
  task.background =
      background::mesh_face_background(model, task.face, curves, options, &task.background_report);
  task.axis = cad::revolution_axis(model, task.face);
}

void compute_cross_field(FaceTask& task, const crossfield::CrossFieldOptions& options,
                         bool summarize_field, bool keep, linalg::SolverLane* lane) {
  try {
    auto cf = std::make_unique<crossfield::FaceCrossField>(
        crossfield::compute_face_cross_field(task.background, options, lane, task.axis));
    if (summarize_field)
      task.field_summary = summarize(*cf);
    else
      crossfield::shrink_cross_field(*cf, crossfield::CrossFieldUse::SizeMapAndGuide);
    if (keep) task.cross_field = std::move(cf);
  } catch (const std::exception& e) {
    // A face without a cross field keeps its background mesh; later stages fall back to methods
    // that need no field.
    task.field_summary = CrossFieldOutput{};
    task.field_summary.error = Error(e.what(), ErrorContext{"crossfield", 2, task.face}).what();
  }
}

FaceOutput take_output(FaceTask&& task, bool quads) {
  FaceOutput out;
  out.mesh = std::move(quads ? task.quad_mesh : task.background);
  if (quads) out.stats = mesh::face_quad_stats(out.mesh);
  out.report = std::move(task.background_report);
  out.cross_field = std::move(task.field_summary);
  out.sizes = std::move(task.sizes);
  out.unstructured = std::move(task.unstructured);
  out.quasi = std::move(task.quasi);
  out.seconds = task.seconds;
  out.times = task.times;
  if (quads) out.field_grids = std::move(task.field_grids);
  out.group_quad_face = std::move(task.group_quad_face);
  out.group_first = task.group_first;
  task = FaceTask{};
  return out;
}

PatternFill mesh_face_fill(const cad::CadModel& model, LO f,
                           std::span<const mesh::CurveMesh> curves,
                           std::span<const qstruct::Pattern> patterns,
                           const qstruct::PatternFaceOptions& options, std::int64_t max_quads,
                           bool keep_refused) {
  const Stopwatch clock;
  PatternFill fill;
  qstruct::PatternFaceOptions po = options;
  po.max_quads = max_quads;
  fill.mesh = qstruct::mesh_face_pattern(model, f, curves, patterns, po, &fill.report);
  // The refused candidate travels and waits only for a comparison.
  if (fill.report.ok || !keep_refused) fill.report.refused_mesh = mesh::FaceMesh{};
  fill.seconds = clock.seconds();
  return fill;
}

std::int64_t interior_singularities(const FaceTask& task) {
  if (task.cross_field == nullptr) return 0;
  return std::count_if(task.cross_field->singularities.begin(),
                       task.cross_field->singularities.end(), crossfield::is_interior);
}

void take_fill(FaceTask& task, PatternFill&& fill, const qstruct::PatternFaceOptions& options) {
  qstruct::PatternFaceReport& pr = fill.report;
  if (pr.ok && qstruct::fill_to_compare(pr.sicn_avg, pr.quads,
                                        mesh::face_quad_stats(fill.mesh).irregular_interior,
                                        interior_singularities(task), options)) {
    task.refused = {std::move(fill.mesh), pr.pattern_name, true};
  } else if (pr.ok) {
    task.quasi.by_pattern = true;
    task.quasi.pattern = pr.pattern_name;
    task.unstructured.ok = true;
    task.unstructured.sicn_min = pr.sicn_min;
    task.unstructured.quads = pr.quads;
    task.quad_mesh = std::move(fill.mesh);
  } else {
    task.quasi.refusal = qstruct::to_string(pr.refusal);
    if (!pr.refused_mesh.quads.empty())
      task.refused = {std::move(pr.refused_mesh), pr.pattern_name, false};
  }
  task.seconds += fill.seconds;
}

bool no_valid_quads(const FaceTask& task) {
  return !task.unstructured.ok || !task.quad_mesh.triangles.empty() || task.quad_mesh.quads.empty();
}

std::optional<std::int64_t> second_fill_bound(const FaceTask& task, std::int64_t bound) {
  // Other refusals would give the same answer again.
  if (task.quasi.by_pattern || !task.refused.mesh.quads.empty() ||
      task.quasi.refusal != qstruct::to_string(qstruct::Refusal::TooManyQuads))
    return std::nullopt;
  if (no_valid_quads(task)) return 0;
  const auto unstructured_quads = static_cast<std::int64_t>(task.quad_mesh.quads.size());
  // The bound keeps fills from carrying a size transition across a whole face; here the curve
  // counts forced the unstructured mesh to that size already.
  if (bound <= 0 || unstructured_quads <= bound) return std::nullopt;
  return unstructured_quads;
}

void take_second_fill(FaceTask& task, PatternFill&& fill) {
  qstruct::PatternFaceReport& pr = fill.report;
  if (pr.ok)
    task.refused = {std::move(fill.mesh), pr.pattern_name, false};
  else if (!pr.refused_mesh.quads.empty())
    task.refused = {std::move(pr.refused_mesh), pr.pattern_name, false};
  task.seconds += fill.seconds;
}

FillComparison compare_refused_fill(FaceTask& task, double tolerance,
                                    const qstruct::PatternFaceOptions& options) {
  FillComparison c;
  RefusedFill& r = task.refused;
  if (r.mesh.quads.empty()) return c;
  c.compared = true;
  c.kept = r.kept;
  c.pattern = r.pattern;
  c.fill = mesh::face_quad_stats(r.mesh);
  // Where the unstructured path left nothing valid, any valid fill is better.
  c.fill_taken = no_valid_quads(task);
  if (!c.fill_taken) {
    c.against_unstructured = true;
    c.unstructured = mesh::face_quad_stats(task.quad_mesh);
    c.fill_taken = qstruct::fill_wins(c.fill, c.unstructured, c.kept, tolerance, options);
    if (c.kept && !c.fill_taken) {
      task.quasi.refusal = qstruct::to_string(qstruct::Refusal::UnstructuredBetter);
      task.quasi.gave_way = true;
    }
  }
  if (c.fill_taken) {
    task.quad_mesh = std::move(r.mesh);
    task.unstructured = quad::UnstructuredReport{};
    task.unstructured.ok = true;
    task.unstructured.sicn_min = c.fill.sicn_min;
    task.unstructured.quads = c.fill.quads;
    task.quasi.by_pattern = true;
    task.quasi.by_comparison = !c.kept;  // a kept fill passed the thresholds
    task.quasi.pattern = r.pattern;
    if (c.kept) task.quasi.refusal.clear();
  }
  r = RefusedFill{};
  return c;
}

bool second_pass_wins(const mesh::FaceQuadStats& first, const mesh::FaceQuadStats& second,
                      double avg_per_irregular, double sum_per_irregular, double good_sicn,
                      double keep_ratio) {
  if (avg_per_irregular <= 0 || second.triangles > first.triangles) return false;
  const std::int64_t removed = first.irregular_interior - second.irregular_interior;
  if (removed <= 0) return false;
  // The second pass trades mean quality for irregular vertices; it must not make a poor quad.
  if (second.sicn_min < std::min(good_sicn, keep_ratio * first.sicn_min)) return false;
  const double loss = first.sicn_avg - second.sicn_avg;
  return loss <= avg_per_irregular * static_cast<double>(removed) &&
         loss * static_cast<double>(first.quads) <=
             sum_per_irregular * static_cast<double>(removed);
}

bool second_pass_applies(const mesh::FaceQuadStats& first, std::int64_t flagged_kept,
                         bool time_budget_hit, std::int64_t min_unnecessary,
                         std::int64_t max_quads) {
  if (time_budget_hit || first.irregular_interior - flagged_kept < min_unnecessary) return false;
  return max_quads <= 0 || first.quads <= max_quads;
}

bool wants_unstructured(const FaceTask& task) { return !task.quasi.by_pattern; }

bool wants_improvement(const FaceTask& task) {
  return !task.quasi.by_pattern && task.unstructured.ok && task.quad_mesh.triangles.empty();
}

void make_holomorphic_candidate(FaceTask& task, const cad::CadModel& model,
                                std::span<const mesh::CurveMesh> full,
                                const holomorphic::HolomorphicOptions& options) {
  task.holomorphic_mesh = mesh::FaceMesh{};
  if (!task.background_report.ok || task.background.triangles.empty()) {
    task.quasi.holomorphic = "no background mesh";
    return;
  }
  try {
    const auto surface = model.face_geometry(task.face);
    const auto loops = background::face_boundary(model, task.face, *surface, full);
    task.holomorphic_mesh = holomorphic::mesh_poly_annulus(task.background, loops, *surface,
                                                           options, &task.holomorphic);
  } catch (const std::exception& e) {
    task.holomorphic.ok = false;
    task.holomorphic.reason = std::string("boundary: ") + e.what();
  }
  if (!task.holomorphic.ok) task.quasi.holomorphic = task.holomorphic.reason;
}

bool choose_face_method(FaceTask& task, holomorphic::Method method, double sicn_tolerance) {
  mesh::FaceMesh candidate = std::move(task.holomorphic_mesh);
  task.holomorphic_mesh = mesh::FaceMesh{};
  if (candidate.quads.empty()) return false;  // the reason is recorded already
  const mesh::FaceQuadStats mine = mesh::face_quad_stats(candidate);
  // A face the default path left without a valid all-quad mesh has nothing to compare with.
  const bool no_default = no_valid_quads(task);
  const mesh::FaceQuadStats theirs =
      no_default ? mesh::FaceQuadStats{} : mesh::face_quad_stats(task.quad_mesh);
  const bool keep =
      no_default
          ? holomorphic::keep_holomorphic(holomorphic::Method::Holomorphic, task.holomorphic, mine,
                                          theirs, sicn_tolerance) &&
                method != holomorphic::Method::Default
          : holomorphic::keep_holomorphic(method, task.holomorphic, mine, theirs, sicn_tolerance);
  if (!keep) {
    task.quasi.holomorphic =
        "default mesh kept (" + std::to_string(theirs.irregular_interior) + " irregular, SICN " +
        std::to_string(theirs.sicn_min) + " / " + std::to_string(theirs.sicn_avg) +
        "; holomorphic " + std::to_string(mine.irregular_interior) + ", " +
        std::to_string(mine.sicn_min) + " / " + std::to_string(mine.sicn_avg) + ")";
    return false;
  }
  task.quad_mesh = std::move(candidate);
  task.unstructured.ok = true;
  // The face counts as meshed by its form, not by the pattern it may have had.
  task.quasi.by_pattern = false;
  task.quasi.by_comparison = false;
  task.quasi.pattern.clear();
  task.quasi.by_holomorphic = true;
  task.quasi.holomorphic = "kept";
  return true;
}

}  // namespace qsmesh::parallel
