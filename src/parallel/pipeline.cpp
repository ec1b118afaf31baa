#include "qsmesh/parallel/pipeline.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <set>
#include <span>

#include "exchange.hpp"
#include "field_stage.hpp"
#include "improve.hpp"
#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/background/size.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/assemble.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/mesh/validate.hpp"
#include "qsmesh/parallel/face_task.hpp"
#include "qsmesh/parallel/partition.hpp"
#include "qsmesh/parallel/pattern_helpers.hpp"
#include "qsmesh/parallel/record.hpp"
#include "split_round.hpp"

namespace qsmesh::parallel {

const char* to_string(Stage s) {
  switch (s) {
    case Stage::Background:
      return "background";
    case Stage::Unstructured:
      return "unstructured";
    case Stage::QuasiStructured:
      return "quasi-structured";
  }
  return "?";
}

Stage parse_stage(const std::string& name) {
  if (name == "background") return Stage::Background;
  if (name == "unstructured") return Stage::Unstructured;
  if (name == "quasi-structured") return Stage::QuasiStructured;
  throw InputError("--until: unknown stage '" + name +
                   "' (valid: background, unstructured, quasi-structured)");
}

std::vector<double> estimate_face_costs(const cad::CadModel& model, double size) {
  std::vector<double> cost;
  cost.reserve(static_cast<std::size_t>(model.num_faces()));
  for (const cad::Face& f : model.faces()) cost.push_back(std::max(1.0, f.area / (size * size)));
  return cost;
}

std::vector<double> estimate_field_costs(const cad::CadModel& model, double size,
                                         bool exact_uniform, bool exact_revolution,
                                         double field_divisions) {
  // The background's largest edge on each face, as the background stage caps it.
  background::SizeOptions sizes;
  sizes.size = size;
  sizes.field_divisions = field_divisions;
  std::vector<double> cost(static_cast<std::size_t>(model.num_faces()));
  for (LO f = 0; f < model.num_faces(); ++f) {
    const cad::Face& face = model.faces()[static_cast<std::size_t>(f)];
    const double edge = sizes.field_cap(face.box.diagonal());
    double& c = cost[static_cast<std::size_t>(f)];
    c = std::max(1.0, face.area / (edge * edge));
    if (exact_uniform && cad::planar_with_right_angle_lines(model, f)) {
      c = 0;
    } else if (const auto axis =
                   exact_revolution ? cad::iso_line_revolution_axis(model, f) : std::nullopt) {
      c = axis->cylinder ? 0 : c / 10;
    }
  }
  return cost;
}

std::vector<int> partition_model_faces(const cad::CadModel& model, double size, int nranks,
                                       bool exact_uniform, bool exact_revolution,
                                       double field_divisions) {
  return partition_faces(
      model.face2faces(), estimate_face_costs(model, size),
      estimate_field_costs(model, size, exact_uniform, exact_revolution, field_divisions), nranks);
}

namespace {

// Stage times: each stage ends with the slowest rank's time; the stages split by faces also add
// this rank's own time to busy() (PipelineResult::rank_busy_seconds). The clock is read before
// the reduction, so a rank's time is its work, not its wait for the others.
class StageClock {
 public:
  StageClock(const Comm& comm, StageTimes& times) : comm_(comm), times_(times) {}
  void start() { clock_.reset(); }
  void end(const char* stage, bool by_faces) {
    const double seconds = clock_.seconds();
    if (by_faces) busy_ += seconds;
    times_.add(stage, comm_.allreduce_max(seconds));
  }
  [[nodiscard]] double busy() const { return busy_; }

 private:
  const Comm& comm_;
  StageTimes& times_;
  Stopwatch clock_;
  double busy_ = 0;
};

// What the stages share: the communicator, the model, the options, the threads and the log.
struct Context {
  const Comm& comm;
  const cad::CadModel& model;
  const PipelineOptions& options;
  const TaskArena& tasks;
  Logger& log;
};

// body(task) on every face of this rank, one TBB task per face. With a stage name, progress is
// counted on this rank and rank 0's logger prints it at every tenth of the faces (the other
// ranks' loggers are quiet by default).
template <class Body>
void each_face(const Context& cx, std::vector<FaceTask>& faces, const char* stage,
               const Body& body) {
  const auto total = static_cast<std::int64_t>(faces.size());
  std::atomic<std::int64_t> done{0};
  cx.tasks.parallel_for(total, [&](std::int64_t i) {
    body(faces[static_cast<std::size_t>(i)]);
    if (stage == nullptr) return;
    const std::int64_t n = ++done;
    if (n * 10 / total != (n - 1) * 10 / total)
      cx.log.info(cat(stage, ": ", n, "/", total, " faces on rank ", cx.comm.rank()));
  });
}

// An upper bound of the unknowns of a face's largest field system: two per edge of its background
// triangulation (the cross field's heat systems; gluing seams only removes edges, and the
// conformal scaling has one unknown per vertex). Below `threshold` the cruder bound of two per
// triangle side answers without counting the edges, which is every face but a giant one.
std::int64_t field_unknowns_bound(const mesh::FaceMesh& m, std::int64_t threshold) {
  const auto sides = 6 * static_cast<std::int64_t>(m.triangles.size());
  if (sides < threshold) return sides;
  std::vector<std::uint64_t> keys;
  keys.reserve(3 * m.triangles.size());
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::uint32_t>(std::min(t[k], t[(k + 1) % 3]));
      const auto b = static_cast<std::uint32_t>(std::max(t[k], t[(k + 1) % 3]));
      keys.push_back(std::uint64_t{a} << 32 | b);
    }
  std::sort(keys.begin(), keys.end());
  return 2 * static_cast<std::int64_t>(std::unique(keys.begin(), keys.end()) - keys.begin());
}

// The faces whose field systems may reach SolverOptions::distributed_threshold (every rank, in
// face order): their fields are computed by all ranks together (shared_cross_fields). Collective.
std::vector<LO> shared_field_faces(const Context& cx, const std::vector<FaceTask>& faces) {
  std::vector<std::int64_t> bound(static_cast<std::size_t>(cx.model.num_faces()), 0);
  for (const FaceTask& t : faces)
    bound[t.face] =
        field_unknowns_bound(t.background, cx.options.crossfield.solver.distributed_threshold);
  cx.comm.allreduce_sum(bound);
  std::vector<LO> shared;
  for (LO f = 0; f < cx.model.num_faces(); ++f)
    if (bound[f] >= cx.options.crossfield.solver.distributed_threshold) shared.push_back(f);
  return shared;
}

// The cross fields of the shared faces, one face after the other, each by every rank of the
// communicator: a rank that does not own the face triangulates its background again (the
// background is deterministic), every rank builds the face's systems, and those above the
// distributed threshold are solved by the ranks together through a group lane (linalg splits
// the rows and gives every rank the whole, correctly rounded, solution), so every rank ends with
// the same field; the owner keeps it. Collective, on the calling thread.
void shared_cross_fields(const Context& cx, std::span<const mesh::CurveMesh> curves,
                         std::vector<FaceTask>& faces, const std::vector<LO>& shared, bool keep,
                         linalg::SolverLane& lane) {
  const std::unique_ptr<linalg::SolverGroup> group = cx.comm.solver_group();
  for (const LO f : shared) {
    const Stopwatch face_clock;
    FaceTask other;
    auto mine =
        std::find_if(faces.begin(), faces.end(), [f](const FaceTask& t) { return t.face == f; });
    FaceTask& t = mine != faces.end() ? *mine : other;
    if (mine == faces.end()) {
      other.face = f;
      mesh_background(other, cx.model, curves, cx.options.background);
    }
    linalg::SolverLane group_lane(lane, *group);
    compute_cross_field(t, cx.options.crossfield, cx.options.cross_fields, keep, &group_lane);
    const linalg::DistributedReport& report = group_lane.report();
    if (cx.options.cross_fields) {
      t.field_summary.solver_ranks = report.ranks;
      t.field_summary.rows_per_rank = report.rows_per_rank;
    }
    t.times.crossfield = face_clock.seconds();
    std::string rows;
    for (const LO r : report.rows_per_rank) rows += cat(" ", r);
    cx.log.info(cat("crossfield: face ", f, ": ", report.systems, " systems split over ",
                    report.ranks, " ranks (largest ", report.unknowns, " unknowns, rows per rank",
                    rows, "), ", report.solves, " solves + ", report.refinement_steps,
                    " refinement solves, ", face_clock.seconds(), " s"));
  }
}

// Size map (paper 000 Sec. 4.1-4.2): curve sizes known to every rank, face fields on the faces'
// ranks, their union on shared curves by an MPI min-reduction, then the faces again. Returns the
// united curve sizes (every rank); fills each task's sizes.
sizemap::CurveSizes size_map_stage(const Context& cx, std::span<const mesh::CurveMesh> curves,
                                   std::vector<FaceTask>& faces, bool cf_sizes) {
  const sizemap::SizeMapOptions& so = cx.options.sizemap;
  const sizemap::CurveSizes initial = sizemap::initial_curve_sizes(cx.model, curves, so, cx.tasks);
  const std::vector<double> targets = sizemap::face_quad_targets(cx.model, so);
  const auto face_pass = [&](const sizemap::CurveSizes& on_curves) {
    each_face(cx, faces, nullptr, [&](FaceTask& t) {
      const Stopwatch face_clock;
      t.sizes = sizemap::face_sizes(t.background, cf_sizes ? t.cross_field.get() : nullptr, curves,
                                    on_curves, targets[t.face], so);
      t.times.sizemap += face_clock.seconds();
    });
  };
  face_pass(initial);
  // The union on shared curves and corners starts from the initial sizes on every rank (the
  // minimum is idempotent), so curves that no face of this rank touches keep their values.
  sizemap::CurveSizes united = initial;
  for (const FaceTask& t : faces) sizemap::fold_boundary_min(t.background, t.sizes.s, united);
  std::vector<double> flat = united.pack();
  cx.comm.allreduce_min(flat);
  united.unpack(flat);
  sizemap::grade_curves(cx.model, curves, so.gradation, united);
  face_pass(united);  // faces now agree on their shared curves
  // The frontal insertion reads only the crosses of each field; the rest was for the size map.
  if (!cx.options.cross_fields)
    each_face(cx, faces, nullptr, [&](FaceTask& t) {
      const Stopwatch face_clock;
      if (t.cross_field != nullptr)
        crossfield::shrink_cross_field(*t.cross_field, crossfield::CrossFieldUse::Guide);
      t.times.sizemap += face_clock.seconds();
    });
  return united;
}

// --- Smooth groups (PipelineOptions::smooth_groups) ----------------------------------------------

// The groups of two faces or more (holomorphic::smooth_face_groups), and each face's group's first
// face (itself when alone). Every rank computes the same, from the model only.
struct SmoothGroups {
  std::vector<std::vector<LO>> groups;
  std::vector<LO> face_group;
};

SmoothGroups find_smooth_groups(const cad::CadModel& model,
                                const holomorphic::GroupOptions& options) {
  SmoothGroups out;
  out.face_group.resize(static_cast<std::size_t>(model.num_faces()));
  for (auto& g : holomorphic::smooth_face_groups(model, options)) {
    for (const LO f : g) out.face_group[static_cast<std::size_t>(f)] = g.front();
    if (g.size() > 1) out.groups.push_back(std::move(g));
  }
  return out;
}

// The index in `faces` (this rank's tasks) of each face it holds.
std::map<LO, std::size_t> local_index(const std::vector<FaceTask>& faces) {
  std::map<LO, std::size_t> local_of;
  for (std::size_t i = 0; i < faces.size(); ++i) local_of[faces[i].face] = i;
  return local_of;
}

// A group glued from this rank's tasks (the partition keeps a group on one rank), each face's
// loops on `curves`; the surfaces of its faces go to `owned`. Never throws for the group.
holomorphic::GluedGroup glue_local(const cad::CadModel& model, std::span<const LO> group,
                                   const std::vector<FaceTask>& faces,
                                   const std::map<LO, std::size_t>& local_of,
                                   std::span<const mesh::CurveMesh> curves,
                                   std::vector<std::unique_ptr<cad::FaceGeometry>>& owned) {
  holomorphic::GluedGroup failed;
  std::vector<mesh::FaceMesh> backgrounds;
  std::vector<std::vector<mesh::BoundaryLoop>> loops;
  owned.clear();
  try {
    for (const LO f : group) {
      const FaceTask& t = faces[local_of.at(f)];
      if (!t.background_report.ok || t.background.triangles.empty()) {
        failed.reason = "face " + std::to_string(f) + " has no background mesh";
        return failed;
      }
      backgrounds.push_back(t.background);
      owned.push_back(model.face_geometry(f));
      loops.push_back(background::face_boundary(model, f, *owned.back(), curves));
    }
  } catch (const std::exception& e) {
    failed.reason = std::string("boundary: ") + e.what();
    return failed;
  }
  return holomorphic::glue_group(group, backgrounds, loops);
}

// The group's mesh on `curves` (holomorphic::mesh_group on glue_local's triangulation); empty,
// with the reason in `reason`, when gluing or meshing fails or gives no quad. Never throws for
// the group.
holomorphic::GroupMesh mesh_local_group(const cad::CadModel& model, std::span<const LO> group,
                                        const std::vector<FaceTask>& faces,
                                        const std::map<LO, std::size_t>& local_of,
                                        std::span<const mesh::CurveMesh> curves,
                                        const holomorphic::HolomorphicOptions& options,
                                        std::string& reason) {
  std::vector<std::unique_ptr<cad::FaceGeometry>> owned;
  const holomorphic::GluedGroup glued = glue_local(model, group, faces, local_of, curves, owned);
  if (!glued.ok) {
    reason = glued.reason;
    return {};
  }
  std::vector<const cad::FaceGeometry*> surfaces;
  surfaces.reserve(owned.size());
  for (const auto& o : owned) surfaces.push_back(o.get());
  holomorphic::HolomorphicReport report;
  holomorphic::GroupMesh mesh;
  try {
    mesh = holomorphic::mesh_group(glued, surfaces, options, &report);
  } catch (const std::exception& e) {
    report.ok = false;
    report.reason = e.what();
  }
  if (!report.ok || mesh.mesh.quads.empty()) {
    reason = report.reason.empty() ? "no quads" : report.reason;
    return {};
  }
  reason.clear();
  return mesh;
}

// The counts of the groups' outer loops from their optimised forms (paper 004 Sec. 4: the loops'
// periods add up, and so must the counts of a conforming mesh; holomorphic::loop_periods,
// balanced_loop_counts), as prescriptions (curve, count) for the quantization. The target edge
// length is the one at which the loops' summed ideal counts (the size map's) are kept. A loop of
// several curves shares its count by their ideal counts. Each group is computed by the rank
// holding it; a max-reduction gives every rank the same lists (one per group of sg.groups). Curves
// the user prescribed keep their counts (a group then meshes only if they add up).
std::vector<std::vector<std::pair<LO, int>>> group_loop_counts(
    const Context& cx, const SmoothGroups& sg, std::span<const mesh::CurveMesh> curves,
    const std::vector<FaceTask>& faces, const PipelineResult& result) {
  const cad::CadModel& model = cx.model;
  const std::vector<double> ideal = quantize::ideal_edge_counts(curves, result.curve_sizes.at);
  std::set<LO> user;
  for (const auto& [c, n] : cx.options.quantize.prescribed) user.insert(c);
  const std::map<LO, std::size_t> local_of = local_index(faces);
  // Minus each curve's count (0: none), so that the minimum over ranks is the largest count.
  std::vector<double> count(static_cast<std::size_t>(model.num_curves()), 0.0);
  for (const auto& group : sg.groups) {
    if (local_of.count(group.front()) == 0) continue;
    std::vector<std::unique_ptr<cad::FaceGeometry>> owned;
    const holomorphic::GluedGroup glued = glue_local(model, group, faces, local_of, curves, owned);
    const auto skip = [&](const std::string& why) {
      cx.log.info(cat("smooth group of face ", group.front(), ": no loop counts (", why, ")"));
    };
    if (!glued.ok) {
      skip(glued.reason);
      continue;
    }
    try {
      const holomorphic::PolyAnnulus s = holomorphic::poly_annulus(glued.background);
      if (!s.ok) {
        skip(s.reason);
        continue;
      }
      const auto& ho = cx.options.holomorphic;
      const holomorphic::HolomorphicBasis B = holomorphic::holomorphic_basis(s, ho.basis, nullptr);
      const holomorphic::EnergyResult E = holomorphic::minimize_area_distortion(s, B, ho.energy);
      const std::vector<double> periods = holomorphic::loop_periods(s, combine(B, E.lambda));
      // The curves of each loop, read from the classification of its merged vertices.
      std::map<LO, LO> merged_curve;
      for (std::size_t v = 0; v < glued.background.vclass.size(); ++v)
        if (glued.background.vclass[v].dim == 1)
          merged_curve[s.face2merged[v]] = glued.background.vclass[v].entity;
      std::vector<std::vector<LO>> loop_curves(s.loops.size());
      double period_sum = 0, ideal_sum = 0;
      for (std::size_t l = 0; l < s.loops.size(); ++l) {
        std::set<LO> on;
        for (const LO x : s.loops[l])
          if (const auto it = merged_curve.find(x); it != merged_curve.end()) on.insert(it->second);
        loop_curves[l].assign(on.begin(), on.end());
        for (const LO c : on) ideal_sum += ideal[static_cast<std::size_t>(c)];
        period_sum += std::abs(periods[l]);
      }
      if (ideal_sum <= 0 || period_sum <= 0) {
        skip("no loop length");
        continue;
      }
      const std::vector<LO> counts =
          holomorphic::balanced_loop_counts(periods, period_sum / ideal_sum);
      std::string line = cat("smooth group of face ", group.front(), ": loop periods / counts");
      for (std::size_t l = 0; l < s.loops.size(); ++l)
        line += cat(" ", periods[l], " / ", counts[l]);
      cx.log.info(line);
      for (std::size_t l = 0; l < s.loops.size(); ++l) {
        const auto& cs = loop_curves[l];
        if (cs.empty()) continue;
        // Largest remainders of the loop's count split by the curves' ideal counts, one edge at
        // least each.
        double loop_ideal = 0;
        for (const LO c : cs) loop_ideal += ideal[static_cast<std::size_t>(c)];
        std::vector<std::int64_t> n(cs.size(), 1);
        std::vector<std::pair<double, std::size_t>> rest;
        std::int64_t given = 0;
        for (std::size_t k = 0; k < cs.size(); ++k) {
          const double share =
              double(counts[l]) * ideal[static_cast<std::size_t>(cs[k])] / loop_ideal;
          n[k] = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::floor(share)));
          rest.emplace_back(-(share - std::floor(share)), k);
          given += n[k];
        }
        std::sort(rest.begin(), rest.end());
        for (std::size_t k = 0; given < counts[l] && k < rest.size(); ++k, ++given)
          ++n[rest[k].second];
        for (std::size_t k = 0; k < cs.size(); ++k)
          if (user.count(cs[k]) == 0) {
            double& at = count[static_cast<std::size_t>(cs[k])];
            at = std::min(at, -double(n[k]));
          }
      }
    } catch (const std::exception& e) {
      skip(e.what());
    }
  }
  cx.comm.allreduce_min(count);
  // Each curve's count to the first group with a face on it (groups in sg.groups order).
  std::vector<LO> group_of_face(static_cast<std::size_t>(model.num_faces()), kNoIndex);
  for (std::size_t g = sg.groups.size(); g-- > 0;)
    for (const LO f : sg.groups[g]) group_of_face[static_cast<std::size_t>(f)] = static_cast<LO>(g);
  std::vector<std::vector<std::pair<LO, int>>> out(sg.groups.size());
  for (LO c = 0; c < model.num_curves(); ++c) {
    if (count[static_cast<std::size_t>(c)] >= 0) continue;
    LO g = kNoIndex;
    for (const LO f : model.curve2faces()[c]) {
      const LO gf = group_of_face[static_cast<std::size_t>(f)];
      if (gf != kNoIndex && (g == kNoIndex || gf < g)) g = gf;
    }
    if (g != kNoIndex)
      out[static_cast<std::size_t>(g)].emplace_back(
          c, static_cast<int>(-count[static_cast<std::size_t>(c)]));
  }
  return out;
}

// Quantization (paper 000 Sec. 4.3), balanced against the patterns and repaired where a face
// boundary crosses itself, computed identically on every rank: fills result.quantization,
// balance, curves_refined_for_crossings and quantized_curves (the final curve meshes; each face
// halves its own loops from them, background::halved_face_boundary).
void quantize_stage(const Context& cx, std::span<const mesh::CurveMesh> curves,
                    const std::vector<FaceTask>& faces, const SmoothGroups& sg,
                    std::span<const std::vector<std::pair<LO, int>>> group_counts,
                    PipelineResult& result) {
  const PipelineOptions& options = cx.options;
  const cad::CadModel& model = cx.model;
  const std::vector<double> ideal = quantize::ideal_edge_counts(curves, result.curve_sizes.at);
  // The smooth groups' outer counts (group_counts, one list per group) are prescribed as the
  // user's are, group by group where the quantization can meet them: a group's counts may clash
  // with a chord of four-sided faces outside it (cube_filet), and the group then keeps the
  // quantization's counts (its mesh falls back unless they add up). Same on every rank.
  quantize::QuantizeOptions qo = options.quantize;
  std::vector<char> accepted(group_counts.size(), 0);
  for (std::size_t g = 0; g < group_counts.size(); ++g) {
    const auto& list = group_counts[g];
    if (list.empty()) continue;
    quantize::QuantizeOptions trial = qo;
    trial.prescribed.insert(trial.prescribed.end(), list.begin(), list.end());
    try {
      (void)quantize::quantize_curves(model, ideal, trial);
      qo = std::move(trial);
      accepted[g] = 1;
    } catch (const InputError& e) {
      cx.log.info(cat("quantize: loop counts of the smooth group with curve ", list.front().first,
                      " not prescribed (", e.what(), ")"));
    }
  }
  if (std::find(accepted.begin(), accepted.end(), 1) != accepted.end()) {
    // A group whose mesh fails for reasons other than its counts (zeros of the form on a loop,
    // sharp corners) would leave its faces' own meshes on counts chosen for the group, worse
    // than the quantization's (Block: interior irregular vertices of those faces 660 -> 890).
    // So each group is meshed once on curve meshes with the counts prescribed (its own curves'
    // counts are then final), and only the groups that mesh keep their prescriptions.
    const quantize::Quantization q = quantize::quantize_curves(model, ideal, qo);
    const std::vector<mesh::CurveMesh> placed = quantize::place_vertices(
        model, curves, result.curve_sizes.at, q, /*halved=*/false, cx.tasks, options.place);
    const std::map<LO, std::size_t> local_of = local_index(faces);
    std::vector<std::int64_t> failed(group_counts.size(), 0);
    for (std::size_t g = 0; g < group_counts.size(); ++g) {
      if (accepted[g] == 0 || local_of.count(sg.groups[g].front()) == 0) continue;
      std::string why;
      (void)mesh_local_group(model, sg.groups[g], faces, local_of, placed, options.holomorphic,
                             why);
      if (!why.empty()) {
        failed[g] = 1;
        cx.log.info(cat("quantize: loop counts of the smooth group of face ", sg.groups[g].front(),
                        " not prescribed (its mesh fails: ", why, ")"));
      }
    }
    cx.comm.allreduce_sum(failed);
    qo = options.quantize;
    for (std::size_t g = 0; g < group_counts.size(); ++g)
      if (accepted[g] != 0 && failed[g] == 0)
        qo.prescribed.insert(qo.prescribed.end(), group_counts[g].begin(), group_counts[g].end());
  }
  std::vector<LO> fixed;  // user prescriptions: never changed
  for (const auto& [c, n] : qo.prescribed) fixed.push_back(c);
  result.quantization = quantize::quantize_curves(model, ideal, qo);
  if (options.balance_counts) {
    // Every rank balances the whole model the same way (deterministic, model-wide data only).
    const auto patterns = qstruct::builtin_patterns();
    std::vector<int> edges = qstruct::balance_curve_counts(
        model, curves, result.quantization, patterns, fixed, options.balance, &result.balance);
    result.quantization.total_edges = 0;
    for (const int e : edges) result.quantization.total_edges += e;
    result.quantization.edges = std::move(edges);
    cx.log.info(cat("quantize: faces fitting a pattern ", result.balance.fitting_before, " -> ",
                    result.balance.fitting_after, " of ", result.balance.faces_considered,
                    ", grids ", result.balance.grids_before, " -> ", result.balance.grids_after,
                    " (", result.balance.curves_changed, " curves changed)"));
  }
  if (options.face_method != holomorphic::Method::Default) {
    // The holomorphic grid of an annulus needs equal counts on its two loops (after the pattern
    // balancing, which does not look at faces with two loops).
    holomorphic::AnnulusCountReport annuli;
    std::vector<int> edges = holomorphic::balance_annulus_counts(
        model, curves, result.quantization.edges, result.quantization.ideal,
        result.quantization.curve2chord, fixed, {}, &annuli);
    result.quantization.total_edges = 0;
    for (const int e : edges) result.quantization.total_edges += e;
    result.quantization.edges = std::move(edges);
    cx.log.info(cat("quantize: annuli with equal loop counts ", annuli.equal_before, " -> ",
                    annuli.equal_after, " of ", annuli.annuli, " (", annuli.curves_changed,
                    " curves changed)"));
  }
  // Boundary repair: a face whose boundary crosses itself in its parameter plane cannot be
  // triangulated. Each rank checks its own faces; the flags are summed, so every rank refines
  // the same curves and keeps the same quantization.
  bool placed_final = false;  // result.quantized_curves holds the final quantization's meshes
  for (int round = 0; round < options.boundary_repair_rounds; ++round) {
    std::vector<std::int64_t> flags(static_cast<std::size_t>(model.num_curves()), 0);
    std::vector<std::vector<LO>> found(faces.size());
    // The final curve meshes, and the halved boundaries made from them (paper 000 Sec. 5.2).
    result.quantized_curves =
        quantize::place_vertices(model, curves, result.curve_sizes.at, result.quantization,
                                 /*halved=*/false, cx.tasks, options.place);
    for (const bool halved : {true, false}) {
      cx.tasks.parallel_for(static_cast<std::int64_t>(faces.size()), [&](std::int64_t i) {
        const LO f = faces[static_cast<std::size_t>(i)].face;
        try {
          const auto c = halved
                             ? quantize::crossing_curves_halved(model, f, result.quantized_curves)
                             : quantize::crossing_curves(model, f, result.quantized_curves);
          found[i].insert(found[i].end(), c.begin(), c.end());
        } catch (const std::exception& e) {
          // The face's own stages report its geometry errors; this check only looks for
          // crossings.
          cx.log.debug(Error(e.what(), ErrorContext{"quantize", 2, f}).what());
        }
      });
    }
    placed_final = true;
    for (const auto& list : found)
      for (const LO c : list) flags[c] = 1;
    cx.comm.allreduce_sum(flags);
    std::vector<LO> flagged;
    for (LO c = 0; c < model.num_curves(); ++c)
      if (flags[c] > 0) flagged.push_back(c);
    if (flagged.empty()) break;
    const std::int64_t before = result.quantization.total_edges;
    quantize::refine_curves(result.quantization, flagged, fixed);
    if (result.quantization.total_edges == before) break;  // only fixed curves are involved
    placed_final = false;
    result.curves_refined_for_crossings.push_back(static_cast<LO>(flagged.size()));
    cx.log.info(
        cat("quantize: ", flagged.size(),
            " curves refined where face boundaries crossed themselves in the parameter plane"));
  }
  if (!placed_final)
    result.quantized_curves =
        quantize::place_vertices(model, curves, result.curve_sizes.at, result.quantization,
                                 /*halved=*/false, cx.tasks, options.place);
  cx.log.info(cat("quantize: ", model.num_curves(), " curves, ", result.quantization.num_chords,
                  " chords, ", result.quantization.total_edges, " edges"));
}

// A face's pattern time and its move search's counts (the scaling simulation's batches).
void set_pattern_times(FaceTimes& times, const PatternFill& fill) {
  times.patterns = fill.seconds;
  times.pattern_layouts = fill.report.layouts;
  times.pattern_batches = fill.report.batches;
  times.pattern_search = fill.report.search_seconds;
  times.pattern_layout_seconds = fill.report.layout_seconds;
  times.pattern_layout_batches = fill.report.layout_batches;
  times.pattern_layout_vectors = fill.report.layout_vectors;
  times.pattern_layout_lend_ranks = fill.report.lend_ranks;
  times.pattern_vector_lendable = fill.report.vector_lendable;
}

// Simple CAD faces meshed directly by a pattern (paper 000 Sec. 6.1.2, pipeline step 4); the
// others go through the unstructured path. A fill needs only the model, the curve meshes (every
// rank has them) and the face's quad bound (if any), which its owner computes from its size map
// and shares with the quads the size map asks for; the faces are then dealt out over all ranks
// (deal_out), those asking for the most quads first: a few faces whose fills are refused and
// searched take most of the stage. Each fill goes to its owner (take_fill). Returns the quad
// bound of each face's fills (0: none), by face id, on every rank.
std::vector<std::int64_t> pattern_stage(const Context& cx, std::vector<FaceTask>& faces,
                                        std::span<const qstruct::Pattern> patterns,
                                        const PipelineResult& result) {
  const PipelineOptions& options = cx.options;
  const LO nfaces = cx.model.num_faces();
  std::vector<double> expected(static_cast<std::size_t>(nfaces), 0.0);
  each_face(cx, faces, nullptr, [&](FaceTask& t) {
    expected[static_cast<std::size_t>(t.face)] = sizemap::expected_quads(t.background, t.sizes.s);
    t.times.expected_quads = expected[static_cast<std::size_t>(t.face)];
  });
  cx.comm.allreduce_sum(expected);  // each face's entry is set by its owner alone
  std::vector<std::int64_t> fill_bound(static_cast<std::size_t>(nfaces), 0);
  if (options.pattern_max_quad_ratio > 0)
    for (LO f = 0; f < nfaces; ++f)
      fill_bound[f] = std::max<std::int64_t>(
          options.pattern_min_quad_bound,
          static_cast<std::int64_t>(std::ceil(options.pattern_max_quad_ratio * expected[f])));
  std::vector<LO> order(static_cast<std::size_t>(nfaces));
  std::iota(order.begin(), order.end(), LO{0});
  std::sort(order.begin(), order.end(), [&](LO a, LO b) {
    return expected[a] != expected[b] ? expected[a] > expected[b] : a < b;
  });
  std::vector<PatternFill> fills(static_cast<std::size_t>(nfaces));
  std::vector<char> filled(static_cast<std::size_t>(nfaces), 0);  // by this rank
  DealProgress progress("patterns", nfaces, cx.comm, cx.log);
  // Ranks done with their faces lay out the move searches of the others
  // (PipelineOptions::move_layouts_over_ranks): with one thread per rank only, since RankHelpers
  // is used by one thread (with more, the rank's threads split its own searches).
  const bool lend = cx.comm.size() > 1 && cx.comm.allreduce_and(options.move_layouts_over_ranks &&
                                                                cx.tasks.threads() == 1);
  std::optional<RankHelpers> ranks;
  std::optional<RankLayoutHelpers> helpers;
  if (lend) {
    ranks.emplace(cx.comm);
    helpers.emplace(*ranks, cx.model, result.quantized_curves, patterns, options.patterns);
  }
  deal_out(
      cx.comm, nfaces, cx.tasks,
      [&](std::int64_t k) {
        const auto f = static_cast<std::size_t>(order[static_cast<std::size_t>(k)]);
        qstruct::PatternFaceOptions po = options.patterns;
        po.size_map_quads = expected[f];
        po.tasks = &cx.tasks;  // one face's move search split over this rank's threads
        if (lend) po.helpers = &*helpers;
        if (!options.move_layouts_over_ranks) po.move_lend_layouts = 0;
        fills[f] = mesh_face_fill(cx.model, static_cast<LO>(f), result.quantized_curves, patterns,
                                  po, fill_bound[f], options.pattern_compare_tolerance >= 0);
        filled[f] = 1;
        progress.done();
      },
      [&] {
        if (!lend) return;
        helpers->serve_until_all_done();
        cx.log.debug(cat("patterns: rank ", cx.comm.rank(), " laid out ", helpers->served(),
                         " move layouts for other ranks"));
      });
  // Fills to their owners.
  std::vector<std::int64_t> local_of(static_cast<std::size_t>(nfaces), -1);
  for (std::size_t i = 0; i < faces.size(); ++i)
    local_of[static_cast<std::size_t>(faces[i].face)] = static_cast<std::int64_t>(i);
  ToOwners<PatternFill> to_owners(cx.comm.size());
  for (LO f = 0; f < nfaces; ++f) {
    if (filled[static_cast<std::size_t>(f)] == 0) continue;
    PatternFill& fill = fills[static_cast<std::size_t>(f)];
    const std::int64_t i = local_of[static_cast<std::size_t>(f)];
    if (i >= 0) {
      set_pattern_times(faces[static_cast<std::size_t>(i)].times, fill);
      take_fill(faces[static_cast<std::size_t>(i)], std::move(fill), options.patterns);
    } else
      to_owners.add(result.face_rank[f], f, fill);
    fill = PatternFill{};
  }
  to_owners.deliver(cx.comm, [&](LO f, PatternFill&& fill) {
    QSMESH_CHECK(f >= 0 && f < nfaces && local_of[static_cast<std::size_t>(f)] >= 0,
                 "pattern fill of face " << f << " sent to rank " << cx.comm.rank()
                                         << ", which does not own it");
    FaceTask& t = faces[static_cast<std::size_t>(local_of[static_cast<std::size_t>(f)])];
    set_pattern_times(t.times, fill);
    take_fill(t, std::move(fill), options.patterns);
  });
  return fill_bound;
}

// Unstructured all-quad meshes (paper 000 Sec. 5) of the faces without a pattern mesh, on the
// quantized curve meshes: frontal points guided by the face's cross field and size map (read on
// its background mesh) on the halved curves, recombined, subdivided onto the full ones,
// smoothed. Of a face's cross field, the later steps need only its singularities; the field, the
// background mesh and the size map (the largest per-face data) go as soon as the face's
// unstructured mesh is made, so that they are not held through the improvement and the output
// (Block.stp at its reference count, one rank: peak heap 131 -> 101 MB, and 74 MB with
// crossfield::shrink_cross_field; docs/benchmarks.md).
void unstructured_stage(const Context& cx, std::vector<FaceTask>& faces,
                        std::span<const mesh::CurveMesh> full, bool keep_singularities) {
  quad::UnstructuredOptions qo;
  qo.size = cx.options.background.sizes.size;
  each_face(cx, faces, "unstructured", [&](FaceTask& t) {
    if (wants_unstructured(t)) {
      const Stopwatch face_clock;
      quad::FaceFields face_fields;
      if (t.background_report.ok && t.cross_field != nullptr) {
        face_fields.background = &t.background;
        face_fields.cross_field = t.cross_field.get();
        face_fields.sizes = t.sizes.s;
      }
      t.quad_mesh =
          quad::mesh_face_unstructured(cx.model, t.face, full, face_fields, qo, &t.unstructured);
      t.times.unstructured = face_clock.seconds();
      t.seconds += t.times.unstructured;
    }
    if (t.cross_field != nullptr && keep_singularities)
      t.singularities = std::move(t.cross_field->singularities);
    t.cross_field.reset();
    t.background = mesh::FaceMesh{};
    if (!cx.options.size_map) t.sizes = sizemap::FaceSizes{};
  });
}

// Topological improvement of the faces the unstructured path meshed with quads only (Sec.
// 6.2-6.3, then the final smoothing), dealt out over ranks and threads as faces finish. Returns
// the time of its three steps summed over the faces of all ranks.
std::array<double, 3> improvement_stage(const Context& cx, std::vector<FaceTask>& faces,
                                        std::span<const qstruct::Pattern> patterns) {
  std::vector<ImproveFace> to_improve;
  // The face's time in the stage is what improve_faces adds to its seconds.
  std::vector<double> before(faces.size());
  for (std::size_t i = 0; i < faces.size(); ++i) before[i] = faces[i].seconds;
  for (FaceTask& t : faces) {
    if (!wants_improvement(t)) continue;
    t.times.improvement_quads = static_cast<std::int64_t>(t.quad_mesh.quads.size());
    ImproveFace f;
    f.face = t.face;
    f.mesh = &t.quad_mesh;
    f.singularities = t.singularities;
    f.report = &t.quasi.improvement;
    f.seconds = &t.seconds;
    f.task_seconds = &t.times.improvement_tasks;
    f.pass_seconds = &t.times.improvement_passes;
    to_improve.push_back(f);
  }
  const remesh::DiskQuadTable table = remesh::DiskQuadTable::builtin();
  ImproveSettings settings;
  settings.patterns = patterns;
  settings.table = &table;
  settings.cavities = cx.options.cavities;
  settings.disk = cx.options.disk;
  settings.final_smoothing = cx.options.final_smoothing;
  settings.final_smooth = cx.options.final_smooth;
  settings.lift = cx.options.lift;
  settings.task_quads = cx.options.task_quads;
  settings.whole_pass_after_cuts = cx.options.whole_pass_after_cuts;
  settings.second_pass_cavities = cx.options.second_pass_cavities;
  settings.second_pass_sicn_per_irregular = cx.options.second_pass_sicn_per_irregular;
  settings.second_pass_sicn_sum_per_irregular = cx.options.second_pass_sicn_sum_per_irregular;
  settings.second_pass_min_unnecessary = cx.options.second_pass_min_unnecessary;
  settings.second_pass_max_quads = cx.options.second_pass_max_quads;
  settings.second_pass_task_irregular = cx.options.second_pass_task_irregular;
  const std::array<double, 3> steps =
      improve_faces(cx.comm, cx.model, to_improve, settings, cx.tasks, cx.log);
  for (std::size_t i = 0; i < faces.size(); ++i)
    faces[i].times.improvement = faces[i].seconds - before[i];
  return steps;
}

// The fills that wait for the face's final mesh (compare_refused_fill), after a second chance for
// those the size map's quad bound refused (second_fill_bound: wing_fuselage's blunt trailing
// edges at size factor 0.02, strips [2, 48, 2, 48] sized for one quad, 101 unstructured quads
// with 3 irregular vertices inside a strip two quads wide; t20's chamfer slivers with a 0-degree
// cusp at size factor 0.01, where the fallback folded a quad too). Where the unstructured path
// did no better, the pattern's fewer irregular vertices win (a small triangle face is often the
// same three quads either way).
void compare_stage(const Context& cx, std::vector<FaceTask>& faces,
                   std::span<const qstruct::Pattern> patterns,
                   std::span<const std::int64_t> fill_bound,
                   std::span<const mesh::CurveMesh> curves) {
  const PipelineOptions& options = cx.options;
  if (options.pattern_compare_tolerance >= 0)
    each_face(cx, faces, nullptr, [&](FaceTask& t) {
      const Stopwatch face_clock;
      const std::optional<std::int64_t> max_quads =
          second_fill_bound(t, fill_bound[static_cast<std::size_t>(t.face)]);
      if (max_quads)
        take_second_fill(t, mesh_face_fill(cx.model, t.face, curves, patterns, options.patterns,
                                           *max_quads, true));
      t.times.compare += face_clock.seconds();
    });
  each_face(cx, faces, nullptr, [&](FaceTask& t) {
    const Stopwatch face_clock;
    const FillComparison c =
        compare_refused_fill(t, options.pattern_compare_tolerance, options.patterns);
    if (c.kept && c.against_unstructured)
      cx.log.debug(cat("face ", t.face, ": kept fill (", c.pattern, ", ", c.fill.quads,
                       " quads, SICN ", c.fill.sicn_min, " / ", c.fill.sicn_avg,
                       ") against unstructured (", c.unstructured.quads, " quads, SICN ",
                       c.unstructured.sicn_min, " / ", c.unstructured.sicn_avg,
                       "): ", c.fill_taken ? "fill" : "unstructured"));
    t.times.compare += face_clock.seconds();
  });
}

// The largest distance between the final mesh's vertices and the CAD (mesh::max_distance_to_cad of
// the mesh the gather assembles), split as the mesh is held: each face's interior vertices on its
// rank, one task per face (face_stats' `distance`); the curve meshes' interior vertices (every
// rank has them) by curve id over the ranks, a task per curve; max-reduced over the ranks. The
// corners are the CAD's corner points (distance 0). A maximum, so the same at any numbers of ranks
// and threads.
double distance_stage(const Context& cx, std::vector<FaceTask>& faces,
                      std::span<const mesh::CurveMesh> curves, bool quads) {
  std::vector<double> worst(faces.size() + curves.size() + 1, 0.0);  // + 1: never empty
  cx.tasks.parallel_for(static_cast<std::int64_t>(faces.size()), [&](std::int64_t i) {
    FaceTask& t = faces[static_cast<std::size_t>(i)];
    const Stopwatch face_clock;
    const mesh::FaceMesh& m = quads ? t.quad_mesh : t.background;
    worst[static_cast<std::size_t>(i)] = mesh::max_distance_to_cad(m.points, m.vclass, cx.model, 2);
    t.times.distance = face_clock.seconds();
  });
  const int rank = cx.comm.rank(), nranks = cx.comm.size();
  const auto mine = static_cast<std::int64_t>(
      (static_cast<int>(curves.size()) + nranks - 1 - rank) / nranks);  // c = rank + k * nranks
  cx.tasks.parallel_for(mine, [&](std::int64_t k) {
    const std::size_t c = static_cast<std::size_t>(rank + k * nranks);
    worst[faces.size() + c] = mesh::max_distance_to_cad(curves[c], cx.model);
  });
  return cx.comm.allreduce_max(*std::max_element(worst.begin(), worst.end()));
}

// What the assembly needs of the groups meshed on this rank (PipelineOptions::smooth_groups;
// empty on every rank otherwise).
struct GroupsForOutput {
  std::map<LO, mesh::FaceQuadStats> stats;  ///< by face of a group meshed
  /// By curve: 1 when used twice by the faces of a group meshed (inside it: a curve between two
  /// of its faces, or a seam of one), so that its quads cross it and it gets no bars.
  std::vector<std::int64_t> inner_curves;
};

// Gathers every face on rank 0 and assembles them (collective; faces is emptied). The assembled
// mesh is sized first from every face's counts; the faces then arrive one rank at a time and
// each is written in place and dropped, so that rank 0 holds the assembled mesh and one rank's
// faces, not every face twice over. Fills result's per-face vectors and mesh on rank 0.
void gather_stage(const Context& cx, std::vector<FaceTask>& faces,
                  std::span<const mesh::CurveMesh> final_curves, bool quads, bool quasi,
                  GroupsForOutput& groups, StageClock& clock, PipelineResult& result) {
  clock.start();
  const PipelineOptions& options = cx.options;
  const LO nfaces = cx.model.num_faces();
  std::vector<std::int64_t> counts(3 * static_cast<std::size_t>(nfaces), 0);
  for (const FaceTask& t : faces) {
    const mesh::FaceMesh& m = quads ? t.quad_mesh : t.background;
    if (!t.group_quad_face.empty()) {
      // A smooth group's mesh, held by its first face, counts on the faces it gives its quads
      // and interior vertices to (mesh::MeshAssembler::add_group); the other faces bring none.
      for (const mesh::VertexClass& vc : m.vclass)
        if (vc.dim == 2) ++counts[3 * static_cast<std::size_t>(vc.entity)];
      for (const LO f : t.group_quad_face) ++counts[3 * static_cast<std::size_t>(f) + 2];
      continue;
    }
    const mesh::FaceContribution c = mesh::face_contribution(m);
    const auto at = 3 * static_cast<std::size_t>(t.face);
    counts[at] += c.interior_vertices;
    counts[at + 1] += c.triangles;
    counts[at + 2] += c.quads;
  }
  cx.comm.allreduce_sum(counts);  // each face's entries are set by its owner alone
  // Packing: each face's output and statistics, then its record, one task per face on this rank
  // (per-face work: it runs where the face is, not on rank 0); the records are then joined in
  // face order, so the gathered bytes are those of a serial loop.
  std::vector<std::vector<char>> records(faces.size());
  cx.tasks.parallel_for(static_cast<std::int64_t>(faces.size()), [&](std::int64_t i) {
    const Stopwatch face_clock;
    FaceOutput out = take_output(std::move(faces[static_cast<std::size_t>(i)]), quads);
    // A smooth group's faces: their own parts of the group's mesh (group_face_stats).
    if (const auto it = groups.stats.find(out.report.face); quads && it != groups.stats.end())
      out.stats = it->second;
    out.times.pack = face_clock.seconds();
    write_record(records[static_cast<std::size_t>(i)], out);
  });
  faces.clear();
  std::size_t total_bytes = 0;
  for (const auto& r : records) total_bytes += r.size();
  std::vector<char> buffer;
  buffer.reserve(total_bytes);
  for (auto& r : records) {
    buffer.insert(buffer.end(), r.begin(), r.end());
    std::vector<char>().swap(r);
  }
  // Per face, but left out of the ranks' busy time (load_imbalance), which covers the meshing
  // stages.
  clock.end("pack", false);
  clock.start();
  std::optional<mesh::MeshAssembler> assembler;
  // The curves inside the groups meshed get no bars (every rank takes part in the sum when any
  // group was formed; the flags are empty otherwise).
  std::vector<char> inner;
  if (!groups.inner_curves.empty()) {
    cx.comm.allreduce_sum(groups.inner_curves);
    for (const std::int64_t x : groups.inner_curves) inner.push_back(x > 0 ? 1 : 0);
  }
  const bool size_map = options.size_map || quads;
  const bool keep_background = size_map && !quads;  // the size map's output draws them
  if (cx.comm.rank() == 0) {
    std::vector<mesh::FaceContribution> contributions(static_cast<std::size_t>(nfaces));
    for (LO f = 0; f < nfaces; ++f) {
      const auto at = 3 * static_cast<std::size_t>(f);
      contributions[f] = {counts[at], counts[at + 1], counts[at + 2]};
    }
    assembler.emplace(cx.model, final_curves, contributions, inner);
    const auto n = static_cast<std::size_t>(nfaces);
    result.reports.resize(n);
    if (options.cross_fields) result.cross_fields.resize(n);
    if (options.size_map) result.face_sizes.resize(n);
    if (quads) result.quad_reports.resize(n);
    if (quasi) result.quasi_reports.resize(n);
    if (quads) {
      result.face_stats.resize(n);
      result.face_seconds.resize(n);
      result.face_times.resize(n);
      result.field_grids.resize(n);
    }
    if (keep_background) result.background.resize(n);
  }
  cx.comm.gather_bytes_each(std::move(buffer), 0, [&](int, std::vector<char>& bytes) {
    std::size_t pos = 0;
    while (pos < bytes.size()) {
      FaceOutput out;
      const std::size_t at = pos;
      read_record(bytes, pos, out);
      out.times.bytes = static_cast<std::int64_t>(pos - at);
      const LO f = out.report.face;
      QSMESH_CHECK(f >= 0 && f < nfaces, "gathered report for unknown face " << f);
      result.reports[f] = std::move(out.report);
      out.mesh.face = f;
      if (out.group_first != kNoIndex && out.group_quad_face.empty()) {
        // A face of a smooth group: its quads came with the group's first face.
      } else if (!out.group_quad_face.empty()) {
        (void)assembler->add_group(out.mesh, out.group_quad_face);
      } else {
        const std::vector<GO> global = assembler->add_face(f, out.mesh);
        if (quads) {
          for (fieldmesh::RegionGrid& g : out.field_grids)
            for (GO& v : g.vertices) v = global[static_cast<std::size_t>(v)];
        }
      }
      if (quads) result.field_grids[f] = std::move(out.field_grids);
      if (keep_background) result.background[f] = std::move(out.mesh);
      if (options.cross_fields) result.cross_fields[f] = std::move(out.cross_field);
      if (options.size_map) result.face_sizes[f] = std::move(out.sizes);
      if (quads) result.quad_reports[f] = std::move(out.unstructured);
      if (quasi) result.quasi_reports[f] = std::move(out.quasi);
      if (quads) {
        result.face_stats[f] = out.stats;
        result.face_seconds[f] = out.seconds;
        result.face_times[f] = out.times;
      }
    }
    std::vector<char>().swap(bytes);
  });
  if (cx.comm.rank() == 0) result.mesh = assembler->finish();
}

// A group's mesh on the final curve meshes (holomorphic::mesh_group), made while its faces'
// background meshes are still there; empty with the reason when it fails.
struct GroupResult {
  std::vector<LO> faces;
  holomorphic::GroupMesh mesh;
  std::string reason;
};

std::vector<GroupResult> mesh_smooth_groups(const Context& cx, const SmoothGroups& sg,
                                            const std::vector<FaceTask>& faces,
                                            const PipelineResult& result) {
  const std::map<LO, std::size_t> local_of = local_index(faces);
  std::vector<GroupResult> out;
  for (const auto& group : sg.groups) {
    if (local_of.count(group.front()) == 0) continue;
    GroupResult& r = out.emplace_back();
    r.faces = group;
    r.mesh = mesh_local_group(cx.model, group, faces, local_of, result.quantized_curves,
                              cx.options.holomorphic, r.reason);
    cx.log.info(cat("smooth group of face ", group.front(), " (", group.size(), " faces): ",
                    r.reason.empty() ? cat(r.mesh.mesh.quads.size(), " quads") : r.reason));
  }
  return out;
}

// The statistics of each face of a group meshed (for --stats' face_stats): its quads and their
// SICN, its interior vertices (those on the face) with their valence among all the group's
// quads; the group's irregular boundary vertices are counted on its first face.
void group_face_stats(const GroupResult& r, std::map<LO, mesh::FaceQuadStats>& stats) {
  const mesh::FaceMesh& m = r.mesh.mesh;
  const mesh::FaceQuadStats whole = mesh::face_quad_stats(m);
  std::vector<int> valence(m.points.size(), 0);
  for (const auto& q : m.quads)
    for (const LO v : q) ++valence[static_cast<std::size_t>(v)];
  for (const LO f : r.faces) {
    mesh::FaceQuadStats s;
    std::vector<char> used(m.points.size(), 0);
    double sum = 0;
    s.sicn_min = 0;
    for (std::size_t k = 0; k < m.quads.size(); ++k) {
      if (r.mesh.quad_face[k] != f) continue;
      std::array<Vec3, 4> x{};
      for (std::size_t i = 0; i < 4; ++i) {
        const auto v = static_cast<std::size_t>(m.quads[k][i]);
        used[v] = 1;
        x[i] = m.points[v];
      }
      const double q = mesh::quad_sicn(x);
      s.sicn_min = s.quads == 0 ? q : std::min(s.sicn_min, q);
      sum += q;
      ++s.quads;
    }
    if (s.quads > 0) s.sicn_avg = sum / double(s.quads);
    for (std::size_t v = 0; v < m.points.size(); ++v) {
      s.vertices += used[v];
      if (m.vclass[v].dim == 2 && m.vclass[v].entity == f && valence[v] != 4)
        ++s.irregular_interior;
    }
    if (f == r.faces.front()) s.irregular_boundary = whole.irregular_boundary;
    stats[f] = s;
  }
}

// Each group meshed replaces its faces' own meshes where the face policy keeps it (under auto:
// when it is better than they are): the first face's task holds the group's mesh
// and the face of each quad, the others are left empty and point to it. A group that failed
// keeps its faces' meshes, the reason in each face's QuasiReport::holomorphic.
GroupsForOutput apply_smooth_groups(const cad::CadModel& model, std::vector<GroupResult>& groups,
                                    std::vector<FaceTask>& faces, holomorphic::Method method,
                                    double sicn_tolerance) {
  GroupsForOutput out;
  out.inner_curves.assign(static_cast<std::size_t>(model.num_curves()), 0);
  auto& stats = out.stats;
  const std::map<LO, std::size_t> local_of = local_index(faces);
  for (GroupResult& r : groups) {
    if (r.reason.empty()) {
      // The policy of a face (holomorphic::keep_holomorphic) on the group against its faces' own
      // meshes taken together: under auto, fewer interior irregular vertices at SICN min and avg
      // within the tolerance; either way no quad with SICN <= 0.
      mesh::FaceQuadStats theirs;
      double weighted = 0;
      theirs.sicn_min = 1;
      for (const LO f : r.faces) {
        const mesh::FaceQuadStats s = mesh::face_quad_stats(faces[local_of.at(f)].quad_mesh);
        theirs.quads += s.quads;
        theirs.triangles += s.triangles;
        theirs.irregular_interior += s.irregular_interior;
        if (s.quads > 0) theirs.sicn_min = std::min(theirs.sicn_min, s.sicn_min);
        weighted += s.sicn_avg * double(s.quads);
      }
      if (theirs.quads > 0) theirs.sicn_avg = weighted / double(theirs.quads);
      const mesh::FaceQuadStats mine = mesh::face_quad_stats(r.mesh.mesh);
      holomorphic::HolomorphicReport ok;
      ok.ok = true;
      if (!holomorphic::keep_holomorphic(method, ok, mine, theirs, sicn_tolerance))
        r.reason =
            cat("the faces' own meshes kept: group ", mine.irregular_interior,
                " interior irregular, SICN ", mine.sicn_min, " / ", mine.sicn_avg, "; faces ",
                theirs.irregular_interior, ", ", theirs.sicn_min, " / ", theirs.sicn_avg);
    }
    if (r.reason.empty()) {
      group_face_stats(r, stats);
      std::map<LO, int> uses;
      for (const LO f : r.faces)
        for (const auto& loop : model.faces()[static_cast<std::size_t>(f)].loops)
          for (const auto& use : loop.uses) ++uses[use.curve];
      for (const auto& [c, n] : uses)
        if (n >= 2) out.inner_curves[static_cast<std::size_t>(c)] = 1;
    }
    std::string name = "group of faces";
    for (const LO f : r.faces) name += cat(" ", f);
    for (const LO f : r.faces) {
      FaceTask& t = faces[local_of.at(f)];
      if (!r.reason.empty()) {
        t.quasi.holomorphic = name + " not meshed (" + r.reason + "); face: " + t.quasi.holomorphic;
        continue;
      }
      t.quasi.by_holomorphic = true;
      t.quasi.holomorphic = "kept: " + name;
      t.group_first = r.faces.front();
      t.field_grids.clear();
      t.quad_mesh = mesh::FaceMesh{};
      if (f == r.faces.front()) {
        t.quad_mesh = std::move(r.mesh.mesh);
        t.quad_mesh.face = f;
        t.group_quad_face = std::move(r.mesh.quad_face);
      }
    }
  }
  return out;
}

// The curves stage (background::CurveMeshing), its first two steps split by curve over the ranks
// in two rounds (curve_round): the sampling, then the feature and wedge sizes, which need every
// curve's samples. The last step (gradation from the corners and the vertices) needs every
// curve's sizes and is cheap: every rank does it on every curve. The meshes are those of
// background::mesh_curves, at any rank count. Collective.
std::vector<mesh::CurveMesh> curves_stage(const Context& cx, std::vector<SplitRound>& rounds) {
  const background::CurveMeshing meshing(cx.model, cx.options.background.sizes);
  const LO n = meshing.num_curves();
  std::vector<background::CurveSamples> samples(static_cast<std::size_t>(n));
  std::vector<double> weights(static_cast<std::size_t>(n));
  for (LO c = 0; c < n; ++c) weights[c] = meshing.sampling_cost(c);
  rounds.push_back(split_round(
      cx.comm, cx.tasks, std::move(weights), [&](LO c) { samples[c] = meshing.sample(c); },
      [&](LO c) { return record_bytes(samples[c]); },
      [&](LO c, std::vector<char>& out) { write_record(out, samples[c]); },
      [&](LO c, const std::vector<char>& in, std::size_t& pos) {
        read_record(in, pos, samples[c]);
      }));
  if (meshing.limits_sizes()) {
    const Stopwatch clock;
    const background::CurveFeatureSearch search = meshing.feature_search(samples);
    // A curve's search costs about one query per sample.
    weights.assign(static_cast<std::size_t>(n), 0.0);
    for (LO c = 0; c < n; ++c) weights[c] = static_cast<double>(samples[c].p.size());
    SplitRound round = split_round(
        cx.comm, cx.tasks, std::move(weights),
        [&](LO c) { meshing.limit_sizes(search, samples[c]); },
        [&](LO c) { return record_bytes(samples[c].h); },
        [&](LO c, std::vector<char>& out) { write_record(out, samples[c].h); },
        [&](LO c, const std::vector<char>& in, std::size_t& pos) {
          read_record(in, pos, samples[c].h);
        });
    round.seconds = clock.seconds();  // with the search, built by every rank
    rounds.push_back(std::move(round));
  }
  return meshing.place(std::move(samples), cx.tasks);
}

}  // namespace

PipelineResult run_pipeline(const Comm& comm, const cad::CadModel& model,
                            const PipelineOptions& options, const TaskArena& tasks, Logger& log,
                            linalg::SolverLane* lane) {
  PipelineResult result;
  const Context cx{comm, model, options, tasks, log};
  const int rank = comm.rank();
  const int nranks = comm.size();
  const LO nfaces = model.num_faces();
  StageClock clock(comm, result.times);
  const bool quads = options.until >= Stage::Unstructured;
  const bool quasi = options.until >= Stage::QuasiStructured;
  const bool size_map = options.size_map || quads;
  const bool cf_sizes = size_map && options.sizemap.method == sizemap::Method::CrossField;
  // The size map (it needs H at every vertex) and the frontal insertion (the crosses) keep the
  // whole fields; the drivers that asked for them (options.cross_fields) get summaries.
  const bool keep_fields = cf_sizes || quads;

  // Curves: sampled and sized split by curve over the ranks, meshed by every rank.
  clock.start();
  const std::vector<mesh::CurveMesh> curves = curves_stage(cx, result.curve_rounds);
  std::int64_t curve_edges = 0;
  for (const auto& c : curves) curve_edges += c.num_edges();
  clock.end("curves", false);
  std::string rounds;
  for (const SplitRound& r : result.curve_rounds)
    rounds += cat(rounds.empty() ? "" : ", ", r.seconds);
  log.info(cat("curves: ", model.num_curves(), " curves meshed, ", curve_edges, " edges (",
               result.times.get("curves"), " s; rounds split by curve ", rounds, " s)"));

  // Faces: METIS partition balancing the estimated cost and the estimated cross-field cost. Each
  // face of this rank is one record (FaceTask) that the stages below fill in turn.
  clock.start();
  result.face_rank = partition_model_faces(
      model, options.background.sizes.size, nranks, options.crossfield.exact_uniform,
      options.crossfield.exact_revolution, options.background.sizes.field_divisions);
  // A smooth group is meshed as one surface: its faces go to the rank of its first face (the
  // partition is the same on every rank, so is this).
  const bool by_groups =
      options.smooth_groups && quads && options.face_method != holomorphic::Method::Default;
  SmoothGroups smooth_groups;
  if (by_groups) {
    smooth_groups = find_smooth_groups(model, options.groups);
    for (LO f = 0; f < nfaces; ++f)
      result.face_rank[f] = result.face_rank[smooth_groups.face_group[static_cast<std::size_t>(f)]];
    result.face_group = smooth_groups.face_group;
    log.info(cat("smooth groups: ", smooth_groups.groups.size(), " of two faces or more"));
  }
  std::vector<FaceTask> faces;
  for (LO f = 0; f < nfaces; ++f)
    if (result.face_rank[f] == rank) faces.emplace_back().face = f;
  clock.end("partition", false);
  if (nranks > 1) {
    std::vector<std::int64_t> per_rank(static_cast<std::size_t>(nranks), 0);
    per_rank[rank] = static_cast<std::int64_t>(faces.size());
    comm.allreduce_sum(per_rank);
    std::string line = "partition: faces per rank";
    for (auto n : per_rank) line += cat(" ", n);
    log.info(line);
  }

  clock.start();
  each_face(cx, faces, "background", [&](FaceTask& t) {
    const Stopwatch face_clock;
    mesh_background(t, model, curves, options.background);
    t.times.background = face_clock.seconds();
  });
  clock.end("background", true);

  if (options.cross_fields || keep_fields) {
    clock.start();
    // Faces too large for one rank: computed below by all ranks together.
    const std::vector<LO> shared =
        lane != nullptr ? shared_field_faces(cx, faces) : std::vector<LO>{};
    each_face(cx, faces, "crossfield", [&](FaceTask& t) {
      if (std::binary_search(shared.begin(), shared.end(), t.face)) return;
      const Stopwatch face_clock;
      compute_cross_field(t, options.crossfield, options.cross_fields, keep_fields, lane);
      t.times.crossfield = face_clock.seconds();
    });
    if (!shared.empty()) shared_cross_fields(cx, curves, faces, shared, keep_fields, *lane);
    clock.end("crossfield", true);
  }

  if (size_map) {
    clock.start();
    result.curve_sizes = size_map_stage(cx, curves, faces, cf_sizes);
    clock.end("sizemap", true);
    clock.start();
    const std::vector<std::vector<std::pair<LO, int>>> group_counts =
        by_groups ? group_loop_counts(cx, smooth_groups, curves, faces, result)
                  : std::vector<std::vector<std::pair<LO, int>>>{};
    quantize_stage(cx, curves, faces, smooth_groups, group_counts, result);
    clock.end("quantize", false);
  }

  // Paper 003: faces meshed from a cross field, kept aside until the default stages are done.
  std::vector<FieldFace> by_field(faces.size());
  if (quads && (options.given_fields != nullptr || options.separatrix_method)) {
    clock.start();
    cx.tasks.parallel_for(static_cast<std::int64_t>(faces.size()), [&](std::int64_t i) {
      by_field[i] = mesh_task_by_field(faces[i], model, result.quantized_curves, options, lane);
    });
    clock.end("fieldmesh", true);
  }

  // The coarse patterns serve both whole faces (Sec. 6.1.2) and cavities (Sec. 6.2).
  const std::vector<qstruct::Pattern> patterns =
      quasi ? qstruct::builtin_patterns() : std::vector<qstruct::Pattern>{};
  std::vector<std::int64_t> fill_bound;
  if (quasi) {
    clock.start();
    fill_bound = pattern_stage(cx, faces, patterns, result);
    clock.end("patterns", true);
  }
  const bool by_holomorphic = quads && options.face_method != holomorphic::Method::Default;
  if (by_holomorphic)  // before the unstructured stage releases the background meshes
    each_face(cx, faces, "holomorphic", [&](FaceTask& t) {
      make_holomorphic_candidate(t, model, result.quantized_curves, options.holomorphic);
    });
  std::vector<GroupResult> group_meshes;
  if (by_groups) {
    clock.start();
    group_meshes = mesh_smooth_groups(cx, smooth_groups, faces, result);
    clock.end("groups", true);
  }
  if (quads) {
    clock.start();
    unstructured_stage(cx, faces, result.quantized_curves, quasi);
    clock.end("unstructured", true);
  }
  if (quasi) {
    clock.start();
    result.improvement_seconds = improvement_stage(cx, faces, patterns);
    clock.end("improvement", true);
    clock.start();
    compare_stage(cx, faces, patterns, fill_bound, result.quantized_curves);
    clock.end("pattern_compare", true);
  }

  if (by_holomorphic)
    each_face(cx, faces, nullptr, [&](FaceTask& t) {
      choose_face_method(t, options.face_method, options.holomorphic_sicn_tolerance);
    });
  for (std::size_t i = 0; i < faces.size(); ++i) take_field_mesh(faces[i], std::move(by_field[i]));
  GroupsForOutput groups_out =
      by_groups ? apply_smooth_groups(model, group_meshes, faces, options.face_method,
                                      options.holomorphic_sicn_tolerance)
                : GroupsForOutput{};

  const std::span<const mesh::CurveMesh> final_curves =
      quads ? std::span<const mesh::CurveMesh>(result.quantized_curves)
            : std::span<const mesh::CurveMesh>(curves);
  if (options.distance_to_cad) {
    clock.start();
    result.max_distance_to_cad = distance_stage(cx, faces, final_curves, quads);
    clock.end("distance", true);
  }
  // Timed in two: "pack" (per face, on the faces' ranks) and "assemble" (rank 0).
  gather_stage(cx, faces, final_curves, quads, quasi, groups_out, clock, result);
  clock.end("assemble", false);
  result.rank_busy_seconds.assign(static_cast<std::size_t>(nranks), 0.0);
  result.rank_busy_seconds[static_cast<std::size_t>(rank)] = clock.busy();
  comm.allreduce_sum(result.rank_busy_seconds);
  return result;
}

}  // namespace qsmesh::parallel
