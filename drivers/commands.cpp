#include "commands.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <string_view>
#include <thread>

#include "json.hpp"
#include "limits.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/log.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/highorder/block_patches.hpp"
#include "qsmesh/highorder/high_order.hpp"
#include "qsmesh/holomorphic/holomorphic.hpp"
#include "qsmesh/io/atomic_file.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/layout/coarse_layout.hpp"
#include "qsmesh/layout/quad_layout.hpp"
#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/mesh/validate.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/partition.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "qsmesh/quantize/quantize.hpp"
#include "qsmesh/sizemap/size_map.hpp"
#include "report_totals.hpp"

namespace qsmesh::cli {

namespace fs = std::filesystem;

namespace {

// The name a path resolves to (symbolic links and '..' resolved as far as it exists), for telling
// whether two names are one file.
fs::path resolved(const std::string& path) {
  std::error_code ec;
  fs::path r = fs::weakly_canonical(fs::absolute(fs::path(path), ec), ec);
  return ec ? fs::absolute(fs::path(path), ec).lexically_normal() : r;
}

bool same_file(const std::string& a, const std::string& b) {
  if (resolved(a) == resolved(b)) return true;
  std::error_code ec;
  return fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec) && !ec;  // hard links
}

}  // namespace

std::vector<RunOutput> run_outputs(const Arguments& args) {
  std::vector<RunOutput> outputs;
  if (!args.output.empty()) {
    outputs.push_back({"-o", args.output, ""});
    if (args.command != Command::Example && io::output_format(args.output) == io::Format::kHdf5)
      outputs.push_back({"the .xdmf file", io::xdmf_path_for(args.output), " written beside -o"});
    if (args.command == Command::Mesh && io::output_format(args.output) == io::Format::kPlot3d)
      outputs.push_back(
          {"the .json file", io::plot3d_connections_path(args.output), " written beside -o"});
  }
  if (!args.stats.empty()) outputs.push_back({"--stats", args.stats, ""});
  return outputs;
}

void check_output_files(const Arguments& args) {
  const std::vector<RunOutput> outputs = run_outputs(args);
  std::vector<RunOutput> inputs;
  if (!args.model.empty()) inputs.push_back({"the model", args.model, ""});
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    for (const RunOutput& in : inputs)
      if (same_file(outputs[i].path, in.path))
        throw InputError(outputs[i].text() + " names the same file as " + in.text() +
                         ", which it would overwrite; give another name");
    for (std::size_t j = 0; j < i; ++j)
      if (same_file(outputs[i].path, outputs[j].path))
        throw InputError(outputs[i].text() + " names the same file as " + outputs[j].text() +
                         "; give another name");
  }
  // The mesh commands' -o and its .xdmf are checked with their format (io::check_output_path).
  for (const RunOutput& out : outputs)
    if (out.what == "--stats" || args.command == Command::Example)
      io::check_output_file(out.what, out.path);
}

void write_text_file_atomically(const std::string& path, const std::string& text) {
  io::AtomicFile file(path);
  io::OutputFile out(file);
  out << std::string_view(text);
  out.close();
  file.commit();
}

namespace {
// Curves that collapse to a point (poles).
std::int64_t degenerate_curves(const cad::CadModel& model) {
  std::int64_t n = 0;
  for (const auto& c : model.curves()) n += c.degenerate ? 1 : 0;
  return n;
}

// Curves whose range the loader trimmed where they run past a corner (cad::Curve::t0).
std::int64_t trimmed_curves(const cad::CadModel& model) {
  std::int64_t n = 0;
  for (const auto& c : model.curves()) n += c.trimmed[0] || c.trimmed[1] ? 1 : 0;
  return n;
}
}  // namespace

int run_info(const Arguments& args) {
  const cad::CadModel model = cad::load_cad(args.model, cad::LoadOptions{args.sew, 0, {}});
  // --partition: the faces over P ranks as run_pipeline partitions them (same weights, same METIS
  // call), at the size a mesh run with the same --size / --size-factor has.
  const double size =
      args.size ? *args.size : model.diagonal() * args.size_factor.value_or(kDefaultSizeFactor);
  std::vector<std::vector<int>> parts;
  std::vector<double> costs, field_costs;
  if (!args.partition.empty()) {
    if (!(size > 0))
      throw InputError("size: the model '" + args.model + "' has an empty bounding box");
    costs = parallel::estimate_face_costs(model, size);
    // The run's estimates: its field divisions (the shortcuts on, their default).
    const double divisions = field_divisions(args);
    field_costs = parallel::estimate_field_costs(model, size, true, true, divisions);
    // METIS prints its complaints (more parts than a graph bisects well) on stdout, which holds
    // the JSON: they go to stderr instead.
    std::cout.flush();
    std::fflush(stdout);
    const int saved = ::dup(STDOUT_FILENO);
    if (saved >= 0) ::dup2(STDERR_FILENO, STDOUT_FILENO);
    for (const int p : args.partition)
      parts.push_back(parallel::partition_model_faces(model, size, p, true, true, divisions));
    std::fflush(stdout);
    if (saved >= 0) {
      ::dup2(saved, STDOUT_FILENO);
      ::close(saved);
    }
  }
  // Per part: faces and the two estimated costs; returns "faces min-max, cost max / mean, field
  // cost max / mean".
  const auto balance = [&](int p, const std::vector<int>& part) {
    std::vector<std::int64_t> n(static_cast<std::size_t>(p), 0);
    std::vector<double> w(static_cast<std::size_t>(p), 0.0), wf(w);
    for (std::size_t f = 0; f < part.size(); ++f) {
      ++n[static_cast<std::size_t>(part[f])];
      w[static_cast<std::size_t>(part[f])] += costs[f];
      wf[static_cast<std::size_t>(part[f])] += field_costs[f];
    }
    const auto max_over_mean = [p](const std::vector<double>& x) {
      double total = 0;
      for (const double v : x) total += v;
      return total > 0 ? *std::max_element(x.begin(), x.end()) * p / total : 1.0;
    };
    std::ostringstream os;
    os << *std::min_element(n.begin(), n.end()) << "-" << *std::max_element(n.begin(), n.end())
       << " faces per rank, estimated cost max / mean " << max_over_mean(w)
       << ", estimated cross-field cost max / mean " << max_over_mean(wf);
    return os.str();
  };
  if (args.json) {
    JsonWriter j;
    j.begin_object();
    j.value("file", args.model);
    j.value("corners", static_cast<std::int64_t>(model.num_corners()));
    j.value("curves", static_cast<std::int64_t>(model.num_curves()));
    j.value("faces", static_cast<std::int64_t>(model.num_faces()));
    j.value("degenerate_curves", degenerate_curves(model));
    j.value("curves_trimmed_at_corners", trimmed_curves(model));
    j.value("diagonal", model.diagonal());
    j.begin_array("box")
        .begin_object()
        .value("x", model.box().lo.x)
        .value("y", model.box().lo.y)
        .value("z", model.box().lo.z)
        .end_object();
    j.begin_object()
        .value("x", model.box().hi.x)
        .value("y", model.box().hi.y)
        .value("z", model.box().hi.z)
        .end_object()
        .end_array();
    j.begin_array("face_list");
    for (LO f = 0; f < model.num_faces(); ++f) {
      const cad::Face& face = model.faces()[f];
      std::int64_t uses = 0;
      for (const auto& l : face.loops) uses += static_cast<std::int64_t>(l.uses.size());
      j.begin_object()
          .value("id", static_cast<std::int64_t>(f))
          .value("type", cad::to_string(face.type))
          .value("loops", static_cast<std::int64_t>(face.loops.size()))
          .value("curve_uses", uses)
          .value("seams", static_cast<std::int64_t>(face.seams.size()))
          .value("area", face.area)
          .value("reversed", face.reversed)
          .value("uniform_field", cad::planar_with_right_angle_lines(model, f));
      if (!parts.empty())  // the partition's two weights
        j.value("estimated_cost", costs[static_cast<std::size_t>(f)])
            .value("estimated_field_cost", field_costs[static_cast<std::size_t>(f)]);
      j.end_object();
    }
    j.end_array();
    if (!parts.empty()) {
      j.value("partition_size", size);
      j.begin_object("partitions");
      for (std::size_t k = 0; k < parts.size(); ++k) {
        j.begin_array(std::to_string(args.partition[k]));
        for (const int r : parts[k]) j.value("", r);
        j.end_array();
      }
      j.end_object();
    }
    j.end_object();
    std::cout << j.str();
    return 0;
  }
  std::cout << "model:     " << args.model << "\n"
            << "corners:   " << model.num_corners() << "\n"
            << "curves:    " << model.num_curves() << "\n"
            << "faces:     " << model.num_faces() << "\n";
  std::cout << "degenerate curves: " << degenerate_curves(model) << "\n"
            << "curves trimmed at corners (running past them): " << trimmed_curves(model) << "\n"
            << "bounding box: (" << model.box().lo.x << ", " << model.box().lo.y << ", "
            << model.box().lo.z << ") - (" << model.box().hi.x << ", " << model.box().hi.y << ", "
            << model.box().hi.z << "), diagonal " << model.diagonal() << "\n\n";
  std::cout << std::setw(6) << "face" << std::setw(12) << "surface" << std::setw(7) << "loops"
            << std::setw(7) << "uses" << std::setw(7) << "seams" << std::setw(15) << "area"
            << "\n";
  for (LO f = 0; f < model.num_faces(); ++f) {
    const cad::Face& face = model.faces()[f];
    std::size_t uses = 0;
    for (const auto& l : face.loops) uses += l.uses.size();
    std::cout << std::setw(6) << f << std::setw(12) << cad::to_string(face.type) << std::setw(7)
              << face.loops.size() << std::setw(7) << uses << std::setw(7) << face.seams.size()
              << std::setw(15) << std::setprecision(6) << face.area
              << (face.reversed ? "  reversed" : "") << "\n";
  }
  if (!parts.empty()) {
    std::cout << "\nMETIS partition at size " << size
              << " (weights area / size^2; cross field: 0 on\n"
              << "faces of the exact shortcuts, planar with lines at right angles or cylinders\n"
              << "cut along their circles and lines, a tenth on other faces of revolution that\n"
              << "take theirs; the area over the square of the face's background edge,\n"
              << "its bounding box diagonal / --field-divisions where that is larger):\n";
    for (std::size_t k = 0; k < parts.size(); ++k)
      std::cout << "  " << args.partition[k] << " ranks: " << balance(args.partition[k], parts[k])
                << "\n";
  }
  return 0;
}

int run_example(const Arguments& args) {
  check_output_files(args);
  const auto format = example_format(args.output);
  QSMESH_CHECK(format, "example: no CAD format for " << args.output << " (parse refuses it)");
  io::AtomicFile file(args.output);
  cad::write_example(args.example_name, file.temp_path(), *format);
  file.commit();
  std::cout << "wrote " << args.output << " (example " << args.example_name << ")\n";
  return 0;
}

namespace {

/// Self-checks of the written mesh against the CAD model.
struct Checks {
  mesh::ConformityReport conformity;
  double max_distance_to_cad = 0;  ///< relative to the model diagonal
  /// Peak resident memory of each rank (MB): the others' at the end of the pipeline, rank 0's
  /// after writing the output.
  std::vector<double> rank_peak_mb;
  /// With --block-structured: the quad layout written.
  struct Blocks {
    std::int64_t blocks = 0, quads = 0, largest = 0;
    LO unblocked_faces = 0, extended_faces = 0;
    /// Faces whose blocks are the regions of their cross-field partition (paper 003), as given.
    LO partition_faces = 0;
    /// PLOT3D output: what it could not hold (the unblocked faces with elements).
    std::optional<io::Plot3dReport> plot3d;
    /// --block-patches: the patches' report and their largest distance to the fine mesh over
    /// the model's diagonal.
    std::optional<highorder::BlockPatchReport> patches;
    double patch_deviation = 0;
    /// --layout coarse: its statistics; fallback: it failed and the dense layout was written.
    std::optional<layout::CoarseStats> coarse;
    bool fallback = false;
    [[nodiscard]] double mean_quads() const {
      return blocks > 0 ? static_cast<double>(quads) / static_cast<double>(blocks) : 0.0;
    }
  };
  std::optional<Blocks> blocks;
  std::optional<highorder::HighOrderReport> high_order;  ///< with --order 2..5
  /// With --order 2..5: highorder::max_element_distance_to_cad / the model's diagonal.
  double high_order_distance = 0;
};

/// How one face ended at the last stage run.
struct FaceOutcome {
  LO face;
  bool ok, fell_back;
  std::string error;
};

/// Per face: the quad stage's report when it ran, the background stage's otherwise.
std::vector<FaceOutcome> outcomes(const parallel::PipelineResult& r) {
  std::vector<FaceOutcome> out;
  if (!r.quad_reports.empty()) {
    for (std::size_t f = 0; f < r.quad_reports.size(); ++f) {
      const auto& q = r.quad_reports[f];
      out.push_back({static_cast<LO>(f), q.ok, q.fell_back, q.error});
    }
  } else {
    for (const auto& rep : r.reports) out.push_back({rep.face, rep.ok, rep.fell_back, rep.error});
  }
  return out;
}

/// Faces without a valid mesh at the stage reached, and faces that fell back to a simpler method.
std::pair<std::int64_t, std::int64_t> count_failures(const parallel::PipelineResult& r) {
  std::int64_t failed = 0, fell_back = 0;
  for (const auto& o : outcomes(r)) {
    failed += o.ok ? 0 : 1;
    fell_back += o.fell_back ? 1 : 0;
  }
  return {failed, fell_back};
}

/// How face f got its quad mesh: "pattern:<name>", "frontal" or "fallback".
std::string quad_method(const parallel::PipelineResult& r, std::size_t f) {
  if (f < r.quasi_reports.size() && r.quasi_reports[f].by_field)
    return "field:" + r.quasi_reports[f].field_method;
  if (f < r.quasi_reports.size()) {
    if (r.quasi_reports[f].by_holomorphic) return "holomorphic";
    std::string pattern = r.quasi_reports[f].pattern_method();
    if (!pattern.empty()) return pattern;
  }
  return f < r.quad_reports.size() && r.quad_reports[f].frontal ? "frontal" : "fallback";
}

/// Why face f was not meshed by a pattern (qstruct::Refusal as text); empty when it was, or when
/// the run stopped before the quasi-structured stage.
std::string pattern_refusal(const parallel::PipelineResult& r, std::size_t f) {
  return f < r.quasi_reports.size() ? r.quasi_reports[f].pattern_refusal() : std::string();
}

/// Whether face f's cavity remeshing stopped on --face-time-budget.
bool time_budget_hit(const parallel::PipelineResult& r, std::size_t f) {
  return f < r.quasi_reports.size() && r.quasi_reports[f].improvement.time_budget_hit;
}

// Largest over mean of the ranks' busy times (1 when balanced or on one rank).
// One round split over the ranks: its seconds, bytes, and by item its weight and seconds.
void write_split_round(JsonWriter& j, const parallel::SplitRound& round) {
  j.begin_object()
      .value("seconds", round.seconds)
      .value("bytes", round.bytes)
      .value("weights", round.weights)
      .value("item_seconds", round.item_seconds)
      .end_object();
}

double load_imbalance(const std::vector<double>& busy) {
  if (busy.empty()) return 1.0;
  double sum = 0, most = 0;
  for (double b : busy) {
    sum += b;
    most = std::max(most, b);
  }
  return sum > 0 ? most * static_cast<double>(busy.size()) / sum : 1.0;
}

std::int64_t total_irregular_boundary(const parallel::PipelineResult& r) {
  std::int64_t n = 0;
  for (const auto& st : r.face_stats) n += st.irregular_boundary;
  return n;
}

/// Totals of the quasi-structured stage over the faces, by their --stats names
/// (parallel::QuasiReport::fields).
ReportTotals quasi_totals(const parallel::PipelineResult& r) {
  return ReportTotals::sum(std::span<const parallel::QuasiReport>(r.quasi_reports));
}

std::string stats_json(const Arguments& args, const Session& session,
                       const parallel::PipelineResult& r, const mesh::MeshStats& s,
                       const Checks& checks) {
  const cad::CadModel& model = session.model;
  JsonWriter j;
  j.begin_object();
  write_run_header(j, args, session);
  j.value("output", args.output);
  j.value("stage", args.until);
  j.value("sizing", args.sizing);  // clamped or paper (--sizing); the options below are its result
  j.value("curvature_edges", curvature_edges(args));  // edges per full turn (0: none)
  j.value("face_curvature", args.face_curvature);
  j.value("feature_ratio", feature_ratio(args));
  j.value("thin_aspect", thin_aspect(args));
  j.value("size_min", given_size_min(args, session.size));  // model units (0: the size cap / 100)
  j.value("corners", static_cast<std::int64_t>(model.num_corners()));
  j.value("curves", static_cast<std::int64_t>(model.num_curves()));
  j.value("faces", static_cast<std::int64_t>(model.num_faces()));
  const auto [failed, fell_back] = count_failures(r);
  j.value("faces_failed", failed);
  j.value("faces_fell_back", fell_back);
  std::int64_t refined = 0;  // curves refined because a face boundary crossed itself (all rounds)
  for (const LO n : r.curves_refined_for_crossings) refined += n;
  j.value("curves_refined_for_crossings", refined);
  if (!r.quad_reports.empty()) {
    std::int64_t frontal = 0;
    for (const auto& q : r.quad_reports) frontal += q.frontal ? 1 : 0;
    j.value("faces_frontal", frontal);  // faces meshed by the frontal path (Sec. 5.1)
  }
  // Sec. 6.1.2-6.3: what the quasi-structured stage did, summed over the faces (the fields of
  // parallel::QuasiReport and ImprovementReport, documented there).
  if (!r.quasi_reports.empty()) quasi_totals(r).write(j);
  j.value("vertices", s.vertices);
  j.value("triangles", s.triangles);
  j.value("quads", s.quads);
  j.value("curve_edges", s.bars);
  j.value("interior_vertices", s.interior_vertices);
  j.value("irregular_interior", s.irregular_interior);
  if (!r.face_stats.empty()) j.value("irregular_boundary", total_irregular_boundary(r));
  j.value("sicn_min", s.sicn_min);
  j.value("sicn_avg", s.sicn_avg);
  // Quads with SICN < 0.1, and of them those at a CAD corner sharper than 8 degrees in their face
  // (no quad there does better); the rest by face in face_stats.
  j.value("quads_sicn_below_0_1", s.quads_sicn_below_0_1);
  j.value("quads_sicn_below_0_1_forced_by_corner", s.quads_sicn_below_0_1_forced_by_corner);
  j.value("quads_sicn_below_0_1_other",
          s.quads_sicn_below_0_1 - s.quads_sicn_below_0_1_forced_by_corner);
  j.value("triangle_quality_min", s.tri_quality_min);
  j.value("triangle_quality_avg", s.tri_quality_avg);
  j.value("min_angle_deg", s.min_angle_deg);
  j.begin_object("min_angle_histogram");
  static const char* kBins[] = {"0-5", "5-10", "10-20", "20-30", "30-60"};
  for (int b = 0; b < 5; ++b) j.value(kBins[b], s.min_angle_histogram[b]);
  j.end_object();
  j.value("small_angle_at_sharp_corner", s.small_angle_at_sharp_corner);
  j.value("conforming", checks.conformity.ok());
  j.value("max_distance_to_cad", checks.max_distance_to_cad);
  write_times(j, session.times);
  if (!r.rank_busy_seconds.empty()) {
    j.begin_array("rank_busy_seconds");
    for (double b : r.rank_busy_seconds) j.value("", b);
    j.end_array();
    j.value("load_imbalance", load_imbalance(r.rank_busy_seconds));
  }
  if (checks.high_order) {
    j.value("order", checks.high_order->order);
    j.value("high_order_curve_nodes", checks.high_order->curve_nodes);
    j.value("high_order_face_nodes", checks.high_order->face_nodes);
    j.value("high_order_unprojected_nodes", checks.high_order->unprojected);
    j.value("high_order_reshaped_quads", checks.high_order->reshaped);
    j.value("high_order_untangled_quads", checks.high_order->untangled);
    j.value("high_order_straightened_quads", checks.high_order->straightened);
    j.value("high_order_curve_straightened_quads", checks.high_order->curve_straightened);
    j.value("high_order_invalid_quads", checks.high_order->invalid);
    j.value("high_order_min_scaled_jacobian", checks.high_order->min_scaled_jacobian);
    j.value("high_order_untangled_min_scaled_jacobian",
            checks.high_order->untangled_min_scaled_jacobian);
    j.value("high_order_max_element_distance_to_cad", checks.high_order_distance);
  }
  if (checks.blocks) {
    j.value("blocks", checks.blocks->blocks);
    j.value("block_quads_mean", checks.blocks->mean_quads());
    j.value("block_quads_largest", checks.blocks->largest);
    j.value("faces_not_in_blocks", static_cast<std::int64_t>(checks.blocks->unblocked_faces));
    j.value("faces_with_extended_traces", static_cast<std::int64_t>(checks.blocks->extended_faces));
    j.value("faces_with_partition_blocks",
            static_cast<std::int64_t>(checks.blocks->partition_faces));
    j.value("block_layout",
            std::string(checks.blocks->coarse
                            ? (checks.blocks->fallback ? "dense (coarse failed)" : "coarse")
                            : "dense"));
    if (const auto& c = checks.blocks->coarse) {
      // The new mesh's numbers only when it was written.
      const bool kept = !checks.blocks->fallback;
      j.value("ilp_variables", c->ilp_variables);
      j.value("ilp_constraints", c->ilp_constraints);
      j.value("ilp_seconds", c->ilp_seconds);
      j.value("ilp_rounds", static_cast<std::int64_t>(c->ilp_rounds));
      j.value("tmesh_patches", c->tmesh_patches);
      j.value("coarse_layout_repairs", static_cast<std::int64_t>(c->repairs));
      j.value("coarse_layout_repairs_grown", static_cast<std::int64_t>(c->repairs_grown));
      j.value("coarse_layout_repairs_restored", static_cast<std::int64_t>(c->repairs_restored));
      j.value("smooth_curves_crossed", c->smooth_curves);
      j.value("traces_across_curves", c->traces_across_curves);
      j.value("blocks_across_curves", kept ? c->blocks_across_curves : std::int64_t{0});
      j.value("smooth_curve_vertices_not_four",
              kept ? c->smooth_curve_vertices_not_four : std::int64_t{0});
      j.value("coarse_cells", kept ? c->cells : std::int64_t{0});
      j.value("irregular_coarse_vertices", kept ? c->irregular_coarse_vertices : std::int64_t{0});
      j.value("chords_removed", kept ? c->chords_removed : std::int64_t{0});
      j.value("chords_closed_kept", kept ? c->chords_closed_kept : std::int64_t{0});
      j.value("chords_open_at_irregular", kept ? c->chords_open_at_irregular : std::int64_t{0});
      j.value("chords_open_elsewhere", kept ? c->chords_open_elsewhere : std::int64_t{0});
      j.value("coarse_layout_seconds", c->seconds);
      j.value("block_mesh_quads", kept ? c->fine_quads : std::int64_t{0});
      j.value("block_mesh_sicn_min", kept ? c->sicn_min : 0.0);
      j.value("block_mesh_sicn_avg", kept ? c->sicn_avg : 0.0);
      j.value("sides_input_spacing", kept ? c->sides_input_spacing : std::int64_t{0});
      j.value("sides_uniform_spacing", kept ? c->sides_uniform_spacing : std::int64_t{0});
      j.value("spacing_fallbacks", static_cast<std::int64_t>(c->spacing_fallbacks));
    }
    if (const auto& p = checks.blocks->patches) {
      j.value("block_patch_order", p->order);
      j.value("block_patches", p->patches);
      j.value("block_patch_curve_bars", p->curve_bars);
      j.value("block_patch_nodes", p->nodes);
      j.value("block_patch_nodes_off_cad", p->unprojected);
      j.value("block_patches_invalid", p->invalid);
      j.value("block_patch_max_deviation", checks.blocks->patch_deviation);
    }
    if (checks.blocks->plot3d) {
      const io::Plot3dReport& p = *checks.blocks->plot3d;
      j.value("plot3d_left_out_faces", static_cast<std::int64_t>(p.skipped_faces.size()));
      j.value("plot3d_left_out_triangles", static_cast<std::int64_t>(p.skipped_triangles));
      j.value("plot3d_left_out_quads", static_cast<std::int64_t>(p.skipped_quads));
    }
  }
  if (!checks.rank_peak_mb.empty()) {
    j.begin_array("rank_peak_memory_mb");
    for (double m : checks.rank_peak_mb) j.value("", m);
    j.end_array();
  }
  // The rounds split over the ranks (parallel::SplitRound, documented there;
  // scripts/simulate_scaling.py deals and replays them): the curves stage's, by curve, and the
  // load's face measurements, by face.
  j.begin_array("curve_rounds");
  for (const parallel::SplitRound& round : r.curve_rounds) write_split_round(j, round);
  j.end_array();
  j.begin_array("load_rounds");
  if (!session.load_round.weights.empty()) write_split_round(j, session.load_round);
  j.end_array();
  if (!r.quasi_reports.empty()) {
    // The improvement stage runs its three steps face by face; their time summed over the faces.
    j.begin_object("improvement_face_seconds")
        .value("cavities", r.improvement_seconds[0])
        .value("disk_remesh", r.improvement_seconds[1])
        .value("final_smoothing", r.improvement_seconds[2])
        .end_object();
  }
  j.begin_array("face_reports");
  for (const auto& o : outcomes(r)) {
    if (o.ok && !o.fell_back) continue;
    j.begin_object()
        .value("face", static_cast<std::int64_t>(o.face))
        .value("ok", o.ok)
        .value("fell_back", o.fell_back)
        .value("error", o.error)
        .end_object();
  }
  j.end_array();
  if (!r.face_stats.empty()) {
    // Per face (quad stages): how it was meshed, its statistics and the time spent on it.
    j.begin_array("face_stats");
    for (std::size_t f = 0; f < r.face_stats.size(); ++f) {
      j.begin_object()
          .value("face", static_cast<std::int64_t>(f))
          .value("rank", f < r.face_rank.size() ? r.face_rank[f] : 0)
          .value("method", quad_method(r, f))
          .value("pattern_refusal", pattern_refusal(r, f))
          .value("holomorphic",
                 f < r.quasi_reports.size() ? r.quasi_reports[f].holomorphic : std::string())
          .value("field_refusal",
                 f < r.quasi_reports.size() ? r.quasi_reports[f].field_refusal : std::string());
      // The face's statistics (mesh::FaceQuadStats::fields, documented there).
      mesh::FaceQuadStats::fields(r.face_stats[f],
                                  [&](const char* name, const auto& v) { j.value(name, v); });
      j.value("quads_sicn_below_0_1",  // not forced by a sharp CAD corner
              f < s.face_quads_sicn_below_0_1.size() ? s.face_quads_sicn_below_0_1[f] : 0)
          .value("seconds", r.face_seconds[f])
          .value("time_budget_hit", time_budget_hit(r, f));
      // Per stage, and the dealt stages' order keys (parallel::FaceTimes, documented there;
      // scripts/simulate_scaling.py replays them).
      if (f < r.face_times.size()) {
        j.begin_object("stage_seconds");
        parallel::FaceTimes::fields(r.face_times[f],
                                    [&](const char* name, const auto& v) { j.value(name, v); });
        j.end_object();
      }
      // The face's topological improvement (parallel::ImprovementReport::fields, documented
      // there): what its cost follows (the unstructured mesh's irregular vertices) and did.
      if (f < r.quasi_reports.size() && r.face_times.size() > f &&
          r.face_times[f].improvement_quads > 0) {
        j.begin_object("improvement");
        parallel::ImprovementReport::fields(
            r.quasi_reports[f].improvement, [&](const char* name, const auto& v) {
              if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::array<std::int64_t, 4>>)
                j.value(name, std::vector<double>(v.begin(), v.end()));
              else
                j.value(name, v);
            });
        j.end_object();
      }
      j.end_object();
    }
    j.end_array();
  }
  j.end_object();
  return j.str();
}

void print_summary(std::ostream& os, const cad::CadModel& model, const parallel::PipelineResult& r,
                   const mesh::MeshStats& s, const Checks& checks, const StageTimes& times,
                   bool per_face) {
  const auto [failed, fell_back] = count_failures(r);
  os << "\nsummary\n"
     << "  faces:      " << model.num_faces() << " (" << failed << " failed, " << fell_back
     << " fell back to a simpler method)\n"
     << "  vertices:   " << s.vertices << "\n"
     << "  triangles:  " << s.triangles << "\n"
     << "  quads:      " << s.quads << "\n"
     << "  irregular interior vertices: " << s.irregular_interior << " of " << s.interior_vertices
     << "\n";
  if (!r.face_stats.empty())
    os << "  boundary vertices away from their ideal valence (per face): "
       << total_irregular_boundary(r) << "\n";
  if (s.quads > 0)
    os << "  SICN min/avg: " << s.sicn_min << " / " << s.sicn_avg << "\n"
       << "  quads with SICN < 0.1: " << s.quads_sicn_below_0_1 << " ("
       << s.quads_sicn_below_0_1_forced_by_corner
       << " at CAD corners sharper than 8 deg, where no quad does better)\n";
  if (!r.curves_refined_for_crossings.empty()) {
    LO refined = 0;
    for (const LO n : r.curves_refined_for_crossings) refined += n;
    os << "  curves refined because a face boundary crossed itself: " << refined << "\n";
  }
  if (!r.quasi_reports.empty()) {
    // By their --stats names (parallel::QuasiReport::fields).
    const ReportTotals t = quasi_totals(r);
    const auto steps = "cavities_remeshed_per_step";
    os << "  faces meshed by patterns: " << t("faces_meshed_by_pattern") << " of "
       << model.num_faces();
    if (const std::int64_t n = t("faces_meshed_by_pattern_after_comparison"); n > 0)
      os << " (" << n
         << " of them as good as their unstructured mesh, below the pattern thresholds)";
    if (const std::int64_t n = t("faces_fill_gave_way_to_unstructured"); n > 0)
      os << "; " << n
         << " fill(s) gave way to the face's unstructured mesh (a clearly better mean, or fewer "
            "irregular vertices at no worse SICN)";
    os << "\n"
       << "  cavity remeshing (other faces): irregular interior vertices "
       << t("irregular_unstructured_before") << " -> " << t("irregular_unstructured_after_cavities")
       << "; cavities remeshed by step " << t(steps, 0) << ", " << t(steps, 1) << ", "
       << t(steps, 2) << ", " << t(steps, 3) << "\n"
       << "  disk remeshing: defects " << t("disk_defects_before") << " -> "
       << t("disk_defects_after") << " (" << t("disk_cavities_replaced") << " cavities replaced)\n";
    if (const std::int64_t n = t("faces_second_pass_kept"); n > 0)
      os << "  second improvement pass (looser cavity acceptance) kept on " << n
         << " face(s): fewer irregular vertices at a bounded cost in SICN\n";
    if (const std::int64_t n = t("faces_time_budget_hit"); n > 0)
      os << "  faces stopped by --face-time-budget: " << n
         << " (kept the valid mesh reached; list with -v)\n";
  }
  if (s.triangles > 0) {
    os << "  triangle quality min/avg: " << s.tri_quality_min << " / " << s.tri_quality_avg << "\n"
       << "  smallest angle: " << s.min_angle_deg << " deg; triangles by smallest angle: "
       << "<5: " << s.min_angle_histogram[0] << ", 5-10: " << s.min_angle_histogram[1]
       << ", 10-20: " << s.min_angle_histogram[2] << ", 20-30: " << s.min_angle_histogram[3]
       << ", >=30: " << s.min_angle_histogram[4] << " (" << s.small_angle_at_sharp_corner
       << " below 10 at CAD corners sharper than 10)\n";
  }
  os << "  conforming: "
     << (checks.conformity.ok() ? "yes" : "NO (" + checks.conformity.summary() + ")")
     << "; largest vertex distance to its CAD entity: " << checks.max_distance_to_cad
     << " of the diagonal\n";
  os << "  time (s):" << times_line(times) << "\n";
  if (r.rank_busy_seconds.size() > 1) {
    const auto [lo, hi] =
        std::minmax_element(r.rank_busy_seconds.begin(), r.rank_busy_seconds.end());
    os << "  ranks' time in the per-face stages (s): min " << *lo << ", max " << *hi
       << "; load imbalance (max / mean) " << load_imbalance(r.rank_busy_seconds) << "\n";
  }
  if (checks.high_order) {
    const highorder::HighOrderReport& q = *checks.high_order;
    os << "  high-order nodes (order " << q.order << "): " << q.curve_nodes << " on curves, "
       << q.face_nodes << " in faces (" << q.unprojected
       << " off the CAD: no CAD point near, or put back straight); quads whose face nodes went "
          "along the face's parameter lines to stay valid "
       << q.reshaped << ", untangled along the curves and in (u, v) " << q.untangled
       << ", went back straight " << q.straightened << ", made entirely straight "
       << q.curve_straightened << ", still invalid " << q.invalid << "; smallest scaled Jacobian "
       << q.min_scaled_jacobian << "; curved elements' largest distance to the CAD / diagonal "
       << checks.high_order_distance << "\n";
  }
  if (checks.blocks) {
    const Checks::Blocks& b = *checks.blocks;
    os << "  blocks (structured zones): " << b.blocks << ", " << b.mean_quads()
       << " quads each on average, largest " << b.largest << "; faces not in blocks "
       << b.unblocked_faces << "; faces traced again with extended traces " << b.extended_faces
       << "; faces whose blocks are their cross-field partition " << b.partition_faces << "\n";
    if (b.plot3d && !b.plot3d->skipped_faces.empty())
      os << "  left out of the PLOT3D file (not blocks): " << b.plot3d->skipped_faces.size()
         << " faces, " << b.plot3d->skipped_triangles << " triangles, " << b.plot3d->skipped_quads
         << " quads\n";
    if (b.coarse && !b.fallback)
      os << "  coarse layout: ILP " << b.coarse->ilp_variables << " variables, "
         << b.coarse->ilp_constraints << " constraints, " << b.coarse->ilp_seconds << " s; layout "
         << b.coarse->seconds << " s; " << b.coarse->fine_quads << " quads, SICN min "
         << b.coarse->sicn_min << " avg " << b.coarse->sicn_avg << "\n";
    if (b.fallback) os << "  coarse layout failed: the dense layout was written\n";
    if (b.patches)
      os << "  block patches (order " << b.patches->order << "): " << b.patches->patches
         << " Lagrange quads, " << b.patches->curve_bars << " bars on CAD curves, "
         << b.patches->nodes << " nodes (" << b.patches->unprojected << " off the CAD), "
         << b.patches->invalid << " folded; largest distance to the fine mesh / diagonal "
         << b.patch_deviation << "\n";
  }
  if (!checks.rank_peak_mb.empty()) {
    const std::vector<double>& mb = checks.rank_peak_mb;
    os << "  peak memory (MB): " << std::lround(mb.front()) << " on rank 0";
    if (mb.size() == 2) {
      os << ", " << std::lround(mb[1]) << " on rank 1";
    } else if (mb.size() > 2) {
      const auto [lo, hi] = std::minmax_element(mb.begin() + 1, mb.end());
      os << ", " << std::lround(*lo) << " to " << std::lround(*hi) << " on the other ranks";
    }
    os << "\n";
  }
  for (const auto& o : outcomes(r))
    if (!o.ok || (o.fell_back && !o.error.empty()))
      os << "  face " << o.face << ": " << o.error << "\n";
  if (per_face && !r.face_stats.empty()) {
    os << "  per face: method (and why no pattern was kept), vertices, quads, triangles, irregular "
          "interior / boundary, SICN min / avg, seconds\n";
    for (std::size_t f = 0; f < r.face_stats.size(); ++f) {
      const auto& st = r.face_stats[f];
      const std::string refusal = pattern_refusal(r, f);
      os << "    face " << f << ": " << quad_method(r, f)
         << (refusal.empty() ? "" : " (no pattern: " + refusal + ")") << ", " << st.vertices << ", "
         << st.quads << ", " << st.triangles << ", " << st.irregular_interior << " / "
         << st.irregular_boundary << ", " << st.sicn_min << " / " << st.sicn_avg << ", "
         << r.face_seconds[f] << (time_budget_hit(r, f) ? " (stopped by --face-time-budget)" : "")
         << "\n";
    }
  }
}

}  // namespace

void write_run_header(JsonWriter& j, const Arguments& args, const Session& s) {
  j.value("model", args.model);
  j.value("ranks", s.ranks);
  j.value("threads", s.threads);
  j.value("size", s.size);
  j.value("field_divisions", field_divisions(args));
}

void write_times(JsonWriter& j, const StageTimes& times) {
  j.begin_object("seconds");
  for (const auto& [stage, sec] : times.entries()) j.value(stage, sec);
  j.value("total", times.total());
  j.end_object();
}

std::string times_line(const StageTimes& times) {
  std::ostringstream os;
  os << std::setprecision(3);
  for (const auto& [stage, sec] : times.entries()) os << " " << stage << " " << sec << ";";
  os << " total " << times.total();
  return os.str();
}

Session::Session(const Arguments& args, const char* command)
    : comm(parallel::Comm::world()),
      rank(comm.rank()),
      ranks(comm.size()),
      log(std::cerr,
          rank == 0
              ? (args.quiet ? LogLevel::Warning : (args.verbose ? LogLevel::Debug : LogLevel::Info))
              : LogLevel::Warning,
          ranks > 1 ? cat("[rank ", rank, "] ") : "") {
  threads = args.threads;
  if (threads <= 0)
    threads =
        std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / comm.local_size());
  tasks = std::make_unique<TaskArena>(threads);
  if (tasks->threads() < threads && args.threads > 0)
    log.warn(cat("--threads ", args.threads, ": this process may run on ", tasks->threads(),
                 " core(s); using ", tasks->threads(), " thread(s)"));
  threads = tasks->threads();
  Stopwatch clock;
  cad::LoadOptions load{args.sew, 0, {}};
  // Every rank reads the file (the topology's ids must be the same everywhere), but the faces'
  // area integrals, most of the rest on B-spline models, are split over the ranks and threads.
  load.measure_faces = [this](LO n, const std::function<double(LO)>& area) {
    return parallel::measure_split(comm, *tasks, n, area, &load_round);
  };
  model = cad::load_cad(args.model, load);
  times.add("load", comm.allreduce_max(clock.seconds()));
  size = args.size ? *args.size : model.diagonal() * args.size_factor.value_or(kDefaultSizeFactor);
  if (!(size > 0))
    throw InputError("size: the model '" + args.model + "' has an empty bounding box");
}

void Session::announce(const Arguments& args, const char* command) {
  log.info(cat("qsmesh ", command, " ", args.model, ": ", model.num_corners(), " corners, ",
               model.num_curves(), " curves, ", model.num_faces(), " faces; size ", size,
               args.sizing == "clamped" ? "" : " (" + args.sizing + " sizing rules)", "; ", ranks,
               " rank(s) x ", threads, " thread(s)"));
}

void check_request(const Arguments& args, const Session& s) {
  ModelMeasures m;
  for (const cad::Face& f : s.model.faces()) {
    m.face_area.push_back(f.area);
    std::vector<int> curves;
    for (const cad::Loop& l : f.loops)
      for (const cad::CurveUse& u : l.uses) curves.push_back(u.curve);
    m.face_curves.push_back(std::move(curves));
  }
  for (const cad::Curve& c : s.model.curves()) m.curve_length.push_back(c.length);
  const double max_quads = args.max_quads < 0 ? kDefaultMaxQuads : args.max_quads;
  if (const auto refusal =
          refuse_request(estimate_request(m, size_request(args, s.size)), max_quads, s.ranks,
                         s.comm.local_size(), machine_memory(), size_option_text(args)))
    throw InputError(*refusal);
}

namespace {

/// Throws InputError unless every id of an ID:VALUE option names an entity of the model.
template <class T>
void check_ids(const char* option, const char* what, const std::vector<std::pair<int, T>>& items,
               LO count) {
  for (const auto& [id, value] : items)
    if (id >= count)
      throw InputError(cat(option, ": ", what, " ", id, " does not exist (the model has ", count,
                           " ", what, "s)"));
}

}  // namespace

double field_divisions(const Arguments& args) {
  return args.field_divisions.value_or(kDefaultFieldDivisions);
}

parallel::PipelineOptions field_options(const Arguments& args, const Session& s) {
  parallel::PipelineOptions options;
  options.background.sizes.size = s.size;
  options.background.sizes.field_divisions = field_divisions(args);
  if (args.distributed_threshold)
    options.crossfield.solver.distributed_threshold = *args.distributed_threshold;
  if (!args.field_change.empty())
    options.crossfield.level_change =
        args.field_change == "rms" ? crossfield::LevelChange::Rms : crossfield::LevelChange::Max;
  if (args.field_iterations) options.crossfield.max_iterations_per_level = *args.field_iterations;
  if (args.field_stall) options.crossfield.stall_window = *args.field_stall;
  if (args.field_stall_ratio) options.crossfield.stall_ratio = *args.field_stall_ratio;
  if (args.field_stall_revolution)
    options.crossfield.revolution_stall_window = *args.field_stall_revolution;
  if (args.field_settled) options.crossfield.settled_level_iterations = *args.field_settled;
  if (args.field_regular) options.crossfield.settled_regular_ends = *args.field_regular;
  if (!args.field_shortcuts.empty()) {
    options.crossfield.exact_uniform = args.field_shortcuts != "none";
    options.crossfield.exact_revolution = args.field_shortcuts == "all";
  }
  return options;
}

double curvature_edges(const Arguments& args) {
  return args.curvature_edges.value_or(sizemap::SizeMapOptions{}.edges_per_turn);
}

double feature_ratio(const Arguments& args) {
  return args.feature_ratio.value_or(sizemap::SizeMapOptions{}.feature_ratio);
}

double thin_aspect(const Arguments& args) { return args.thin_aspect.value_or(kDefaultThinAspect); }

double given_size_min(const Arguments& args, double size) {
  if (args.size_min_ratio) return *args.size_min_ratio * size;
  return args.size_min.value_or(0.0);
}

void apply_size_options(const Arguments& args, const Session& s,
                        parallel::PipelineOptions& options) {
  check_ids("--curve-edges", "curve", args.curve_edges, s.model.num_curves());
  check_ids("--curve-size", "curve", args.curve_sizes, s.model.num_curves());
  check_ids("--corner-size", "corner", args.corner_sizes, s.model.num_corners());
  check_ids("--face-quads", "face", args.face_quads, s.model.num_faces());
  check_ids("--face-size", "face", args.face_sizes, s.model.num_faces());
  sizemap::SizeMapOptions& so = options.sizemap;
  so.method = args.sizemap == "features" ? sizemap::Method::Features : sizemap::Method::CrossField;
  so.size_max = s.size;
  so.target_quads = args.quads;
  so.edges_per_turn = curvature_edges(args);
  so.face_curvature = args.face_curvature;
  so.feature_ratio = feature_ratio(args);
  so.thin_aspect = thin_aspect(args);
  if (args.size_min && *args.size_min > s.size) {
    std::ostringstream os;
    os << "--size-min " << *args.size_min << " is larger than the size cap " << s.size
       << " (--size / --size-factor)";
    throw InputError(os.str());
  }
  so.size_min = given_size_min(args, s.size);
  for (const auto& [id, v] : args.face_quads) so.face_quads.emplace_back(id, v);
  for (const auto& [id, v] : args.corner_sizes) so.corner_sizes.emplace_back(id, v);
  for (const auto& [id, v] : args.curve_sizes) so.curve_sizes.emplace_back(id, v);
  for (const auto& [id, v] : args.face_sizes) so.face_sizes.emplace_back(id, v);
  for (const auto& [id, n] : args.curve_edges) options.quantize.prescribed.emplace_back(id, n);
  options.quantize.odd_slivers = args.odd_slivers;
  so.one_edge_slivers = args.one_edge_slivers;
  options.quantize.sliver_length = sizemap::sliver_length(so);
  // Odd counts are fine as long as every face loop can stay even (midpoint subdivision): what
  // no choice of the other curves allows is refused now, naming the loop, not after the sizes.
  quantize::check_prescription_parity(s.model, options.quantize.prescribed);
}

namespace {
// Rule (i) of Sec. 4.1 sizes a curve by its length even below the size floor, and the faces around
// grade out from there: worth a line, since it explains irregular vertices the user did not ask
// for and has a remedy.
void note_sliver_curves(Session& s, const sizemap::SizeMapOptions& so) {
  if (so.size_min > 0) return;
  const double floor = sizemap::effective_size_min(so);
  LO count = 0, shortest = kNoIndex;
  for (LO c = 0; c < s.model.num_curves(); ++c) {
    const cad::Curve& curve = s.model.curves()[c];
    if (curve.degenerate || !(curve.length < floor)) continue;
    ++count;
    if (shortest == kNoIndex || curve.length < s.model.curves()[shortest].length) shortest = c;
  }
  if (count == 0) return;
  s.log.info(cat("size map: ", count, " curve", count == 1 ? " is" : "s are",
                 " shorter than the size floor ", floor, " (shortest: curve ", shortest, ", ",
                 s.model.curves()[shortest].length,
                 "); the sizes around them grade down to their length (paper 000 Sec. 4.1), with "
                 "irregular vertices in the transition; --size-min H, --size-min-ratio R or the "
                 "default --sizing clamped stops that"));
}
}  // namespace

namespace {
// A prescription the mesh could not follow (a face's quads decided by its curves' counts) is a
// warning, not a silent difference.
void warn_unmet_prescriptions(const Arguments& args, const parallel::PipelineResult& r,
                              Logger& log) {
  const mesh::SurfaceMesh& m = r.mesh;
  if (r.face_stats.empty()) return;  // no quad stage ran
  for (const auto& [f, asked] : args.face_quads) {
    const double got = static_cast<double>(r.face_stats[static_cast<std::size_t>(f)].quads);
    if (got > 2 * asked || 2 * got < asked)
      log.warn(cat("--face-quads ", f, ":", asked, ": face ", f, " got ", got,
                   " quads; its curves' edge counts and the sizes of its neighbours decide"));
  }
  std::vector<std::int64_t> curve_bars(static_cast<std::size_t>(m.num_cad_curves), 0);
  for (const LO c : m.bar_curve) curve_bars[static_cast<std::size_t>(c)] += 1;
  for (const auto& [c, asked] : args.curve_edges)
    if (curve_bars[static_cast<std::size_t>(c)] != asked)
      log.warn(cat("--curve-edges ", c, ":", asked, ": curve ", c, " got ",
                   curve_bars[static_cast<std::size_t>(c)], " edges"));
}
}  // namespace

int run_mesh(const Arguments& args) {
  // Everything the user could get wrong is checked before any work.
  const parallel::Stage until = parallel::parse_stage(args.until);
  io::check_output_path(args.output);
  check_output_files(args);

  Session s(args, "mesh");
  parallel::PipelineOptions options = field_options(args, s);
  check_request(args, s);
  if (until >= parallel::Stage::Unstructured) apply_size_options(args, s, options);
  s.announce(args, "mesh");
  options.until = until;
  options.face_method = args.separatrix_method ? holomorphic::Method::Default
                                               : holomorphic::parse_method(args.method);
  if (until >= parallel::Stage::Unstructured) note_sliver_curves(s, options.sizemap);
  options.cavities.time_budget_s = args.face_time_budget;
  if (args.task_quads >= 0) options.task_quads = args.task_quads;
  if (args.pass_after_cuts) options.whole_pass_after_cuts = *args.pass_after_cuts;
  if (args.second_pass_task >= 0) options.second_pass_task_irregular = args.second_pass_task;
  if (args.second_pass_quads == 0) options.second_pass_sicn_per_irregular = 0;  // off
  if (args.second_pass_quads > 0) options.second_pass_max_quads = args.second_pass_quads;
  // Under a coarse block layout the fills' aligned transitions give fewer blocks than the
  // unstructured meshes that would replace them (A319 at 0.0048-0.0052: 4.9% fewer blocks,
  // mambo_s34 2-44%; docs/benchmarks.md, stop 52), so there only poor means are compared.
  options.patterns.compare_irregular =
      args.fill_comparison.empty() ? !args.coarse_layout : args.fill_comparison != "mean";
  options.patterns.compare_above_field = args.fill_comparison != "all";
  // Paper 003: read before any work, so that a bad file is one InputError line up front.
  fieldmesh::GivenFields given_fields;
  if (!args.cross_field.empty()) {
    given_fields = fieldmesh::read_cross_field_file(args.cross_field, s.model.num_faces());
    options.given_fields = &given_fields;
  }
  options.separatrix_method = args.separatrix_method;
  options.smooth_groups = args.smooth_groups;
  options.distance_to_cad = true;
  // A face whose field system is above SolverOptions::petsc_threshold (petsc_threshold_complex for
  // the cross field's heat systems, factorized as complex by Eigen) is solved by PETSc; with the
  // background at the geometry's resolution that takes a face far larger than its neighbours, or
  // --field-divisions 0 on a large one. Above SolverOptions::distributed_threshold
  // (--distributed-threshold) all ranks solve the face's systems together.
  linalg::SolverLane lane;
  parallel::PipelineResult result =
      parallel::run_pipeline(s.comm, s.model, options, *s.tasks, s.log, &lane);
  for (const auto& [stage, sec] : result.times.entries()) s.times.add(stage, sec);
  // Before rank 0 works alone: a collective after its writing would hang the others if it failed.
  std::vector<double> peak_mb(static_cast<std::size_t>(s.ranks), 0.0);
  peak_mb[static_cast<std::size_t>(s.rank)] = peak_resident_mb();
  s.comm.allreduce_sum(peak_mb);

  if (s.rank == 0) {
    Stopwatch clock;
    const mesh::MeshStats stats = mesh::compute_stats(result.mesh);
    Checks checks;
    checks.conformity = mesh::check_conformity(result.mesh, s.model, result.face_group);
    // The pipeline's distance stage measured it where the faces were (PipelineOptions).
    checks.max_distance_to_cad = result.max_distance_to_cad / s.model.diagonal();
    s.times.add("statistics", clock.seconds());
    clock.reset();
    if (args.order > 1 && !args.block_patches) {
      checks.high_order = highorder::make_high_order(result.mesh, s.model, args.order, *s.tasks);
      s.times.add("high_order", clock.seconds());
      clock.reset();
      checks.high_order_distance =
          highorder::max_element_distance_to_cad(result.mesh, s.model, *s.tasks) /
          s.model.diagonal();
      s.times.add("high_order_check", clock.seconds());
      clock.reset();
    }
    if (args.block_structured || args.block_patches) {
      Checks::Blocks b;
      std::optional<layout::CoarseResult> coarse;
      if (args.coarse_layout) {
        layout::CoarseOptions co;
        co.loop_balance = args.loop_balance;
        co.fit_loop_widths = args.fit_loop_widths;
        co.repairs = args.repairs;
        co.laplacian_uv = args.fine_laplacian;
        co.input_spacing_on_curves = args.fine_input_spacing;
        co.patch_placement = args.fine_patch;
        if (args.cone_angle_deg > 0) co.alpha = args.cone_angle_deg * 3.14159265358979323846 / 180;
        co.cross_smooth_curves = !args.sharp_and_smooth_walls;
        co.traces_across_smooth_curves = args.traces_cross_curves;
        coarse = layout::build_coarse_layout(result.mesh, s.model, co);
        b.coarse = coarse->stats;
        if (!coarse->ok) {
          b.fallback = true;
          s.log.warn(cat("coarse layout failed (", coarse->failure,
                         "): writing the dense layout instead"));
          coarse.reset();
        }
      }
      const mesh::SurfaceMesh& written = coarse ? coarse->mesh : result.mesh;
      // The faces meshed from a cross field bring their blocks: the partition's regions.
      std::vector<layout::GivenBlock> given;
      for (std::size_t f = 0; f < result.field_grids.size(); ++f)
        for (fieldmesh::RegionGrid& g : result.field_grids[f])
          given.push_back({static_cast<LO>(f), g.ni, g.nj, std::move(g.vertices)});
      const layout::QuadLayout lay =
          coarse ? std::move(coarse->layout)
                 : layout::extract_quad_layout(result.mesh, layout::LayoutOptions{}, given);
      b.blocks = static_cast<std::int64_t>(lay.blocks.size());
      for (const layout::Block& k : lay.blocks) {
        const std::int64_t n = static_cast<std::int64_t>(k.ni) * k.nj;
        b.quads += n;
        b.largest = std::max(b.largest, n);
      }
      b.unblocked_faces = static_cast<LO>(lay.unblocked_faces.size());
      b.extended_faces = lay.faces_with_extended_traces;
      b.partition_faces = lay.faces_with_given_blocks;
      s.times.add("layout", clock.seconds());
      clock.reset();
      if (args.block_patches) {
        mesh::SurfaceMesh patches;
        b.patches = highorder::make_block_patches(written, lay, s.model, args.order, patches);
        b.patch_deviation = b.patches->max_deviation / s.model.diagonal();
        s.times.add("patches", clock.seconds());
        clock.reset();
        if (b.unblocked_faces > 0)
          s.log.warn(cat(b.unblocked_faces, " faces do not split into blocks and are not in ",
                         args.output, " (--layout coarse covers every face where it succeeds)"));
        if (b.patches->invalid > 0)
          s.log.warn(cat(b.patches->invalid, " of ", b.patches->patches,
                         " block patches fold at order ", args.order,
                         " (a block bends too much for one polynomial): a lower --order, or "
                         "--block-structured for the blocks' grids"));
        io::write_mesh(patches, args.output);
      } else if (io::output_format(args.output) == io::Format::kPlot3d) {
        io::WriteOptions wo;
        wo.plot3d_fortran_records = !args.plot3d_stream;
        wo.plot3d_single_precision = args.plot3d_single;
        b.plot3d = io::write_plot3d(written, lay, args.output, wo);
        const io::Plot3dReport& p = *b.plot3d;
        if (!p.skipped_faces.empty()) {
          std::string faces;
          for (std::size_t i = 0; i < p.skipped_faces.size() && i < 10; ++i) {
            if (i > 0) faces += ' ';
            faces += std::to_string(p.skipped_faces[i]);
          }
          if (p.skipped_faces.size() > 10) faces += " ...";
          s.log.warn(cat("PLOT3D holds structured blocks only: ", p.skipped_faces.size(),
                         " faces that do not split into blocks (", p.skipped_triangles,
                         " triangles, ", p.skipped_quads, " quads; faces ", faces, ") are not in ",
                         args.output,
                         "; the sidecar lists them and the block sides along them (-o FILE.cgns "
                         "--block-structured writes them as an unstructured zone)"));
        }
      } else {
        io::write_cgns_blocks(written, lay, args.output);
      }
      checks.blocks = b;
    } else {
      io::write_mesh(result.mesh, args.output);
    }
    s.times.add("write", clock.seconds());
    const io::Format format = io::output_format(args.output);
    s.log.info(format == io::Format::kHdf5
                   ? cat("wrote ", args.output, " and ", io::xdmf_path_for(args.output),
                         " (open it in ParaView)")
               : format == io::Format::kPlot3d
                   ? cat("wrote ", args.output, " and ", io::plot3d_connections_path(args.output),
                         " (the blocks' connections)")
                   : cat("wrote ", args.output));
    peak_mb.front() = peak_resident_mb();
    checks.rank_peak_mb = std::move(peak_mb);
    if (!args.quiet)
      print_summary(std::cout, s.model, result, stats, checks, s.times, args.verbose);
    if (!args.stats.empty())
      write_text_file_atomically(args.stats, stats_json(args, s, result, stats, checks));
    for (const auto& o : outcomes(result))
      if (!o.ok) s.log.warn(o.error);
    warn_unmet_prescriptions(args, result, s.log);
  }
  return 0;
}

}  // namespace qsmesh::cli
