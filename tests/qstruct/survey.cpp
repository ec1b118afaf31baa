// qstruct_survey MODEL [--size-factor F] [--threads T] [--faces] [--face F [--dump OBJ]]
// [--min-sicn A] [--min-sicn-avg B] [--smooth-iterations N]
// How many faces of MODEL the pattern path (paper 000 Sec. 6.1.2) meshes on the curve meshes the
// pipeline quantizes (size map, crossfield method, as `qsmesh sizemap`), and why the others are
// refused. Serial (MPI_COMM_SELF); --faces prints one line per face (with its pattern time);
// --dump writes face F's mesh (kept, or the best valid fill refused) as a Wavefront OBJ.
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/log.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "qsmesh/qstruct/face_pattern.hpp"
#include "survey_common.hpp"

using namespace qsmesh;

int main(int argc, char** argv) {
  parallel::MpiSession mpi(&argc, &argv);
  test::SurveyArgs args;
  LO detail = kNoIndex;
  std::string dump;  // --dump: OBJ file of the detail face's mesh (kept, or the refused fill)
  qstruct::PatternFaceOptions fo;
  const bool ok = test::parse_survey_args(
      argc, argv,
      "usage: qstruct_survey MODEL [--size-factor F] [--threads T] [--faces] [--face F [--dump "
      "OBJ]] [--min-sicn A] [--min-sicn-avg B] [--smooth-iterations N]",
      args, [&](const std::string& a, int& i) {
        if (i + 1 >= argc) return false;
        if (a == "--face")
          detail = std::atoi(argv[++i]);
        else if (a == "--dump")
          dump = argv[++i];
        else if (a == "--min-sicn")
          fo.min_sicn = std::atof(argv[++i]);
        else if (a == "--min-sicn-avg")
          fo.min_sicn_avg = std::atof(argv[++i]);
        else if (a == "--smooth-iterations")
          fo.smooth.iterations = std::atoi(argv[++i]);
        else
          return false;
        return true;
      });
  if (!ok) return 2;
  if (!dump.empty() && detail == kNoIndex) {
    std::cerr << "qstruct_survey: --dump needs --face F\n";
    return 2;
  }
  const std::string& path = args.path;
  const double size_factor = args.size_factor;
  const bool per_face = args.per_face;
  return test::run_reporting_errors("qstruct_survey", [&] {
    const cad::CadModel model = test::load_survey_model(path);
    const TaskArena tasks(args.threads);
    const test::SurveyRun run =
        test::run_survey_pipeline(model, size_factor, /*cross_fields=*/false, tasks);
    const parallel::PipelineResult& result = run.result;
    const double pipeline_s = run.pipeline_seconds;

    const auto patterns = qstruct::builtin_patterns();
    Stopwatch clock;
    std::map<std::string, int> refusals, used, no_pattern_sides, quality_patterns;
    std::int64_t quads = 0;
    double worst = 1, sum_avg = 0;
    int meshed = 0;
    for (LO f = 0; f < model.num_faces(); ++f) {
      qstruct::PatternFaceReport rep;
      const Stopwatch face_clock;
      const auto m =
          qstruct::mesh_face_pattern(model, f, result.quantized_curves, patterns, fo, &rep);
      const double face_seconds = face_clock.seconds();
      if (f == detail && !dump.empty()) {
        const mesh::FaceMesh& out = rep.ok ? m : rep.refused_mesh;
        std::ofstream obj(dump);
        if (!obj) throw std::runtime_error("cannot write " + dump);
        obj << std::setprecision(17);
        for (const auto& p : out.points) obj << "v " << p.x << " " << p.y << " " << p.z << "\n";
        for (const auto& q : out.quads)
          obj << "f " << q[0] + 1 << " " << q[1] + 1 << " " << q[2] + 1 << " " << q[3] + 1 << "\n";
        std::cout << "face " << f << ": " << out.quads.size() << " quads written to " << dump
                  << "\n";
      }
      std::string sides = std::to_string(rep.side_edges.size());
      if (rep.ok) {
        ++meshed;
        ++used[rep.pattern_name];
        quads += static_cast<std::int64_t>(m.quads.size());
        worst = std::min(worst, rep.sicn_min);
        sum_avg += rep.sicn_avg;
      } else {
        ++refusals[qstruct::to_string(rep.refusal)];
        if (rep.refusal == qstruct::Refusal::NoPattern) ++no_pattern_sides[sides + " sides"];
        if (rep.refusal == qstruct::Refusal::Quality) ++quality_patterns[rep.pattern_name];
      }
      if (per_face) {
        std::cout << "face " << f << " " << cad::to_string(model.faces()[f].type) << " sides [";
        for (std::size_t i = 0; i < rep.side_edges.size(); ++i)
          std::cout << (i ? "," : "") << rep.side_edges[i];
        std::cout << "] (" << face_seconds << " s) ";
        if (model.faces()[f].loops.size() == 1) {
          try {
            const auto surf = model.face_geometry(f);
            const auto fs = qstruct::face_sides(model, f, *surf, result.quantized_curves, fo);
            int concave = 0;
            double sharpest = 180;
            for (std::size_t i = 0; i < fs.points.size(); ++i)
              if (fs.points[i].vclass.dim == 0) {
                if (fs.angle_deg[i] > 225) ++concave;
                sharpest = std::min(sharpest, fs.angle_deg[i]);
              }
            std::cout << "concave " << concave << " sharpest " << sharpest << " ";
          } catch (const std::exception&) {
          }
        }
        if (rep.ok)
          std::cout << "ok " << rep.pattern_name << " quads " << rep.quads << " sicn "
                    << rep.sicn_min << "/" << rep.sicn_avg;
        else
          std::cout << qstruct::to_string(rep.refusal) << ": " << rep.reason;
        // How far the geometric stage went: untangler calls, moves kept, and for a refused valid
        // fill its quads at or below the min threshold.
        if (rep.candidates > 0) {
          std::cout << " [lifts " << rep.lifts << ", moves " << rep.moves;
          if (!rep.refused_mesh.quads.empty()) {
            int poor = 0;
            const auto& rm = rep.refused_mesh;
            for (const auto& q : rm.quads)
              if (mesh::quad_sicn({rm.points[q[0]], rm.points[q[1]], rm.points[q[2]],
                                   rm.points[q[3]]}) <= rep.min_sicn)
                ++poor;
            std::cout << ", poor " << poor << " of " << rm.quads.size();
          }
          std::cout << "]";
        }
        std::cout << "\n";
      }
    }
    const double faces_s = clock.seconds();
    if (detail != kNoIndex) {
      // One face in detail: the corners, their angles and sides, for looking into a refusal.
      const auto surface = model.face_geometry(detail);
      const auto fs = qstruct::face_sides(model, detail, *surface, result.quantized_curves, fo);
      std::cout << "face " << detail << ": " << fs.points.size() << " boundary points, uv area "
                << fs.uv_area << "\n";
      for (std::size_t i = 0; i < fs.points.size(); ++i)
        if (fs.points[i].vclass.dim == 0)
          std::cout << "  point " << i << " corner " << fs.points[i].vclass.entity << " angle "
                    << fs.angle_deg[i] << " uv (" << fs.points[i].uv.u << ", " << fs.points[i].uv.v
                    << ") xyz (" << fs.points[i].xyz.x << ", " << fs.points[i].xyz.y << ", "
                    << fs.points[i].xyz.z << ")\n";
      for (const auto& use : model.faces()[detail].loops[0].uses)
        std::cout << "  curve " << use.curve << (use.reversed ? " (rev) " : " ")
                  << cad::to_string(model.curves()[use.curve].type) << " edges "
                  << result.quantized_curves[use.curve].num_edges() << " length "
                  << model.curves()[use.curve].length << "\n";
      if (args.per_face)
        for (const auto& use : model.faces()[detail].loops[0].uses) {
          std::cout << "  curve " << use.curve << " vertices:";
          for (const auto& p : result.quantized_curves[use.curve].points)
            std::cout << " (" << p.x << "," << p.y << "," << p.z << ")";
          std::cout << "\n";
        }
    }
    std::cout << path << ": " << meshed << "/" << model.num_faces()
              << " faces meshed by patterns (size factor " << size_factor << ", " << quads
              << " quads";
    if (meshed > 0)
      std::cout << ", SICN min " << worst << ", mean of face averages " << sum_avg / meshed;
    std::cout << ")\n  patterns:";
    for (const auto& [k, n] : used) std::cout << " " << k << " " << n << ";";
    std::cout << "\n  refused:";
    for (const auto& [k, n] : refusals) std::cout << " " << k << " " << n << ";";
    std::cout << "\n  no_pattern by sides:";
    for (const auto& [k, n] : no_pattern_sides) std::cout << " " << k << ": " << n << ";";
    std::cout << "\n  quality refusals by best pattern:";
    for (const auto& [k, n] : quality_patterns) std::cout << " " << k << " " << n << ";";
    std::cout << "\n  time (s): pipeline to quantization " << pipeline_s << ", pattern meshing "
              << faces_s << "\n";
  });
}
