// `qsmesh sizemap`: the size map (paper 000 Sec. 4.1-4.2) and the curve quantization (Sec. 4.3)
// on their own, for people to look at.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>

#include "commands.hpp"
#include "json.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/parallel/pipeline.hpp"

namespace qsmesh::cli {

namespace {

/// Point fields s, s_min, s_cf on the assembled background mesh (global numbering: corners, curve
/// vertices, then the faces' interior vertices in face order), and the quantized curve vertices as
/// markers with their curve id.
io::WriteOptions size_fields(const cad::CadModel& model, const parallel::PipelineResult& r) {
  const auto& mesh = r.mesh;
  const std::size_t nv = mesh.points.size();
  constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> s(nv, kUnset), s_min(nv, kUnset), s_cf(nv, kUnset);
  GO next = 0;
  std::vector<GO> curve_first(static_cast<std::size_t>(model.num_curves()), -1);
  for (GO v = 0; v < static_cast<GO>(nv); ++v) {
    const auto& vc = mesh.vclass[v];
    if (vc.dim < 2) ++next;  // face-interior vertices come after every corner and curve vertex
    if (vc.dim == 1 && curve_first[vc.entity] < 0) curve_first[vc.entity] = v - (vc.index - 1);
  }
  // s_min and s_cf differ between the faces sharing a curve: the first face in id order is shown.
  for (LO f = 0; f < model.num_faces(); ++f) {
    const auto& bg = r.background[f];
    const auto& fs = r.face_sizes[f];
    for (std::size_t v = 0; v < bg.vclass.size(); ++v) {
      const auto& vc = bg.vclass[v];
      const GO g = vc.dim == 2   ? next++
                   : vc.dim == 0 ? vc.entity
                                 : curve_first[vc.entity] + vc.index - 1;
      if (fs.s.empty() || !std::isnan(s[g])) continue;
      s[g] = fs.s[v];
      s_min[g] = fs.s_min[v];
      if (!fs.s_cf.empty()) s_cf[g] = fs.s_cf[v];
    }
  }
  // Boundary vertices carry the union of the faces' sizes (the curve sizes).
  for (GO v = 0; v < static_cast<GO>(nv); ++v) {
    const auto& vc = mesh.vclass[v];
    if (vc.dim == 1) s[v] = r.curve_sizes.at[vc.entity][vc.index];
    if (vc.dim == 0) s[v] = r.curve_sizes.corner[vc.entity];
  }
  io::WriteOptions opt;
  opt.vtu_include_bars = true;
  for (LO c = 0; c < static_cast<LO>(r.quantized_curves.size()); ++c) {
    const auto& cm = r.quantized_curves[c];
    for (std::size_t i = 0; i < cm.points.size(); ++i)
      opt.vtu_markers.push_back({cm.points[i], kNoIndex});
  }
  const std::size_t nm = opt.vtu_markers.size();
  for (auto* f : {&s, &s_min, &s_cf}) f->resize(nv + nm, kUnset);
  opt.point_fields = {{"s", 1, s}, {"s_min", 1, s_min}, {"s_cf", 1, s_cf}};
  const std::size_t ncells = mesh.triangles.size() + mesh.quads.size() + mesh.bars.size() + nm;
  std::vector<double> qcurve(ncells, -1.0);
  std::size_t m = ncells - nm;
  for (LO c = 0; c < static_cast<LO>(r.quantized_curves.size()); ++c)
    for (std::size_t i = 0; i < r.quantized_curves[c].points.size(); ++i) qcurve[m++] = c;
  opt.cell_fields = {{"quantized_curve", 1, qcurve}};
  return opt;
}

}  // namespace

int run_sizemap(const Arguments& args) {
  io::check_output_path(args.output);
  if (args.output.size() < 4 || args.output.substr(args.output.size() - 4) != ".vtu")
    throw InputError("-o: '" + args.output + "': the size map is written as VTU (.vtu)");
  check_output_files(args);

  Session s(args, "sizemap");
  linalg::SolverLane lane;
  parallel::PipelineOptions options = field_options(args, s);
  options.size_map = true;
  check_request(args, s);
  apply_size_options(args, s, options);
  s.announce(args, "sizemap");
  const parallel::PipelineResult result =
      parallel::run_pipeline(s.comm, s.model, options, *s.tasks, s.log, &lane);
  for (const auto& [stage, sec] : result.times.entries()) s.times.add(stage, sec);
  if (s.rank != 0) return 0;

  Stopwatch clock;
  io::write_vtu(result.mesh, args.output, size_fields(s.model, result));
  s.times.add("write", clock.seconds());
  s.log.info(cat("wrote ", args.output));

  const auto& q = result.quantization;
  double smin = std::numeric_limits<double>::max(), smax = 0;
  for (const auto& v : result.curve_sizes.at)
    for (double x : v) {
      smin = std::min(smin, x);
      smax = std::max(smax, x);
    }
  if (!args.quiet) {
    std::cout << "\nsummary\n  size map method: " << args.sizemap
              << "\n  curves: " << s.model.num_curves() << ", chords: " << q.num_chords
              << ", edges: " << q.total_edges << "\n  size on curves: " << smin << " to " << smax
              << "\n  time (s):" << times_line(s.times) << "\n";
  }
  if (!args.stats.empty()) {
    JsonWriter j;
    j.begin_object();
    write_run_header(j, args, s);
    j.value("method", args.sizemap);
    j.value("curvature_edges", curvature_edges(args));
    j.value("face_curvature", args.face_curvature);
    j.value("feature_ratio", feature_ratio(args));
    j.value("thin_aspect", thin_aspect(args));
    j.value("size_min", given_size_min(args, s.size));
    j.value("curves", static_cast<std::int64_t>(s.model.num_curves()));
    j.value("chords", static_cast<std::int64_t>(q.num_chords));
    j.value("edges", q.total_edges);
    j.value("curve_size_min", smin);
    j.value("curve_size_max", smax);
    j.begin_array("curve_edges");
    for (int e : q.edges) j.value("", static_cast<std::int64_t>(e));
    j.end_array();
    write_times(j, s.times);
    j.end_object();
    write_text_file_atomically(args.stats, j.str());
  }
  return 0;
}

}  // namespace qsmesh::cli
