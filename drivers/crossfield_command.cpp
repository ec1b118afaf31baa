// `qsmesh crossfield`: the cross field stage on its own, for people to look at (paper 000 Sec. 3).
#include <cmath>
#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "json.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/parallel/pipeline.hpp"

namespace qsmesh::cli {

namespace {

/// The VTU of the background mesh with the cross-field data as cell fields and the singularities
/// as markers (see `qsmesh crossfield --help`).
io::WriteOptions cross_field_fields(const mesh::SurfaceMesh& mesh,
                                    const std::vector<parallel::CrossFieldOutput>& fields) {
  io::WriteOptions opt;
  for (LO f = 0; f < static_cast<LO>(fields.size()); ++f)
    for (const auto& s : fields[f].singularities) opt.vtu_markers.push_back({s.position, f});
  const std::size_t nt = mesh.triangles.size(), nm = opt.vtu_markers.size();
  io::Field cu{"cross_u", 3, std::vector<double>(3 * (nt + nm), 0.0)};
  io::Field cv{"cross_v", 3, std::vector<double>(3 * (nt + nm), 0.0)};
  io::Field un{"u_norm", 1, std::vector<double>(nt + nm, 0.0)};
  io::Field H{"H", 1, std::vector<double>(nt + nm, 0.0)};
  io::Field h{"h", 1, std::vector<double>(nt + nm, 0.0)};
  io::Field index{"singularity_index", 1, std::vector<double>(nt + nm, 0.0)};
  // Triangles are grouped by face in face order, each face's in its background order.
  std::size_t t = 0;
  for (LO f = 0; f < static_cast<LO>(fields.size()); ++f) {
    const auto& cf = fields[f];
    std::size_t k = 0;
    for (; t < nt && mesh.triangle_face[t] == f; ++t, ++k) {
      if (!cf.ok || k >= cf.directions.size()) continue;  // no field on this face
      for (int c = 0; c < 3; ++c) {
        cu.values[3 * t + c] = cf.directions[k][0][c];
        cv.values[3 * t + c] = cf.directions[k][1][c];
      }
      un.values[t] = cf.u_norm[k];
      H.values[t] = cf.H[k];
      h.values[t] = std::exp(cf.H[k]);
    }
  }
  std::size_t m = nt;
  for (const auto& cf : fields)
    for (const auto& s : cf.singularities) index.values[m++] = s.index;
  opt.cell_fields = {cu, cv, un, H, h, index};
  return opt;
}

}  // namespace

int run_crossfield(const Arguments& args) {
  if (!args.output.empty()) {
    io::check_output_path(args.output);
    if (!io::is_supported_output(args.output) || args.output.size() < 4 ||
        args.output.substr(args.output.size() - 4) != ".vtu")
      throw InputError("-o: '" + args.output + "': the cross field is written as VTU (.vtu)");
  }
  check_output_files(args);

  Session s(args, "crossfield");
  check_request(args, s);
  s.announce(args, "crossfield");
  linalg::SolverLane lane;
  parallel::PipelineOptions options = field_options(args, s);
  options.cross_fields = true;
  const parallel::PipelineResult result =
      parallel::run_pipeline(s.comm, s.model, options, *s.tasks, s.log, &lane);
  for (const auto& [stage, sec] : result.times.entries()) s.times.add(stage, sec);
  if (s.rank != 0) return 0;

  const LO nfaces = s.model.num_faces();
  int consistent = 0, with_field = 0, plus = 0, minus = 0, levels = 0, factorizations = 0,
      solves = 0, stalled_levels = 0;
  for (const auto& cf : result.cross_fields) {
    if (!cf.ok) continue;
    ++with_field;
    consistent += cf.euler.consistent ? 1 : 0;
    for (const auto& sg : cf.singularities) (sg.index > 0 ? plus : minus) += 1;
    levels += cf.levels;
    factorizations += cf.factorizations;
    solves += cf.solves;
    stalled_levels += cf.stalled_levels;
  }
  if (!args.output.empty()) {
    Stopwatch clock;
    io::write_vtu(result.mesh, args.output, cross_field_fields(result.mesh, result.cross_fields));
    s.times.add("write", clock.seconds());
    s.log.info(cat("wrote ", args.output));
  }

  if (!args.quiet && !args.check) {
    std::cout << "\nper face: singularities (+1 / -1), Euler relation (found / expected), levels, "
                 "solves, seconds\n";
    for (LO f = 0; f < nfaces; ++f) {
      const auto& cf = result.cross_fields[f];
      if (!cf.ok) {
        std::cout << "  face " << f << ": no cross field: " << cf.error << "\n";
        continue;
      }
      int p = 0, n = 0;
      for (const auto& sg : cf.singularities) (sg.index > 0 ? p : n) += 1;
      std::cout << "  face " << std::setw(4) << f << ": " << p << " / " << n << ", euler "
                << (cf.euler.consistent ? "ok" : "NOT ok") << " (" << cf.euler.found << " / "
                << cf.euler.expected << "), " << cf.levels << " levels, " << cf.solves
                << " solves, " << std::setprecision(3) << cf.seconds << " s\n";
    }
    std::cout << "\nsummary\n  faces: " << nfaces << " (" << nfaces - with_field
              << " without cross field)\n"
              << "  singularities: " << plus << " of index +1, " << minus << " of index -1\n"
              << "  factorizations: " << factorizations << ", solves: " << solves
              << "\n  time (s):" << times_line(s.times) << "\n";
  }
  if (args.check) {
    for (LO f = 0; f < nfaces; ++f) {
      const auto& cf = result.cross_fields[f];
      if (!cf.ok)
        std::cout << "face " << f << ": no cross field: " << cf.error << "\n";
      else if (!cf.euler.consistent)
        std::cout << "face " << f << ": singularities sum to " << cf.euler.found
                  << ", Euler relation asks " << cf.euler.expected << " (chi " << cf.euler.chi
                  << ", corner term " << cf.euler.corner_term << ")\n";
    }
  }
  std::cout << "euler-consistent: " << consistent << "/" << nfaces << "\n";

  if (!args.stats.empty()) {
    JsonWriter j;
    j.begin_object();
    write_run_header(j, args, s);
    j.value("faces", static_cast<std::int64_t>(nfaces));
    j.value("faces_with_cross_field", with_field);
    j.value("euler_consistent", consistent);
    j.value("singularities_plus", plus);
    j.value("singularities_minus", minus);
    j.value("levels", levels);
    j.value("factorizations", factorizations);
    j.value("solves", solves);
    j.value("stalled_levels", stalled_levels);  // --field-stall, --field-stall-revolution
    write_times(j, s.times);
    j.begin_array("face_list");
    for (LO f = 0; f < nfaces; ++f) {
      const auto& cf = result.cross_fields[f];
      int p = 0, n = 0;
      for (const auto& sg : cf.singularities) (sg.index > 0 ? p : n) += 1;
      j.begin_object()
          .value("face", static_cast<std::int64_t>(f))
          .value("ok", cf.ok)
          .value("plus", p)
          .value("minus", n)
          .value("euler_found", cf.euler.found)
          .value("euler_expected", cf.euler.expected)
          .value("euler_consistent", cf.euler.consistent)
          .value("levels", cf.levels)
          .value("factorizations", cf.factorizations)
          .value("solves", cf.solves)
          .value("stalled_levels", cf.stalled_levels)
          .value("iterations_per_level", std::vector<double>(cf.iterations_per_level.begin(),
                                                             cf.iterations_per_level.end()))
          .value("seconds", cf.seconds)
          .value("solver", cf.solver)
          .value("solver_ranks", cf.solver_ranks)  // split over ranks: --distributed-threshold
          .value("rows_per_rank",
                 std::vector<double>(cf.rows_per_rank.begin(), cf.rows_per_rank.end()))
          .end_object();
    }
    j.end_array();
    j.end_object();
    write_text_file_atomically(args.stats, j.str());
  }
  return 0;
}

}  // namespace qsmesh::cli
