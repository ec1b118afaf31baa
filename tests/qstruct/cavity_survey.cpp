// cavity_survey MODEL [--size-factor F] [--threads T] [--first N] [--faces] [--quad-change F]
// [--avg-ratio R]
//                      [--candidates N] [--rings N] [--backtracks N] [--minimal-tries N]
//                      [--smooth-iterations N] [--no-step3-transitions]
// Paper 000 Sec. 6.2 on the unstructured quad meshes of a model's faces: the pipeline runs to the
// quantized curves with cross fields (as `qsmesh mesh --until unstructured`), each face (the first
// N, default all) is meshed by quad::mesh_face_unstructured and then given to
// qstruct::remesh_cavities with its cross-field singularities. Prints interior irregular vertices
// and SICN before/after, summed over the faces, and the cavities per step. Serial (MPI_COMM_SELF).
#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/log.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "qsmesh/qstruct/cavity.hpp"
#include "qsmesh/quad/unstructured.hpp"
#include "qsmesh/quantize/quantize.hpp"
#include "survey_common.hpp"

using namespace qsmesh;

int main(int argc, char** argv) {
  parallel::MpiSession mpi(&argc, &argv);
  test::SurveyArgs args;
  LO first = std::numeric_limits<LO>::max();
  qstruct::CavityOptions co;
  const bool ok = test::parse_survey_args(
      argc, argv,
      "usage: cavity_survey MODEL [--size-factor F] [--threads T] [--first N] [--faces] "
      "[--quad-change F] [--avg-ratio R] [--candidates N] [--rings N] [--backtracks N] "
      "[--minimal-tries N] "
      "[--smooth-iterations N] [--no-step3-transitions]",
      args, [&](const std::string& a, int& i) {
        if (a == "--no-step3-transitions") {
          co.step3_transitions = false;
          return true;
        }
        if (i + 1 >= argc) return false;
        if (a == "--first") {
          first = std::atoi(argv[++i]);
        } else if (a == "--quad-change") {
          co.max_quad_change = std::atof(argv[++i]);
        } else if (a == "--avg-ratio") {
          co.keep_avg_ratio = std::atof(argv[++i]);
        } else if (a == "--candidates") {
          co.max_candidates = std::atoi(argv[++i]);
        } else if (a == "--minimal-tries") {
          co.max_minimal_tries = std::atoi(argv[++i]);
        } else if (a == "--backtracks") {
          co.max_backtracks = std::atoi(argv[++i]);
        } else if (a == "--rings") {
          co.smooth_rings = std::atoi(argv[++i]);
        } else if (a == "--smooth-iterations") {
          co.smooth.iterations = std::atoi(argv[++i]);

        } else {
          return false;
        }
        return true;
      });
  if (!ok) return 2;
  const std::string& path = args.path;
  const double size_factor = args.size_factor;
  const bool per_face = args.per_face;
  return test::run_reporting_errors("cavity_survey", [&] {
    const cad::CadModel model = test::load_survey_model(path);
    const TaskArena tasks(args.threads);
    const test::SurveyRun run =
        test::run_survey_pipeline(model, size_factor, /*cross_fields=*/true, tasks);
    const parallel::PipelineResult& result = run.result;
    const double size = run.size;
    quad::UnstructuredOptions qo;
    qo.size = size;

    const auto patterns = qstruct::builtin_patterns();
    std::int64_t broken = 0;
    std::int64_t faces = 0, skipped = 0, irr0 = 0, irr1 = 0, quads0 = 0, quads1 = 0, sings = 0,
                 flagged = 0, kept = 0;
    double min0 = 1, min1 = 1, sum0 = 0, sum1 = 0, seconds = 0;
    std::array<std::int64_t, 4> grown{}, remeshed{}, rejected{};
    std::array<qstruct::CavityStepDiagnostics, 4> diag{};
    const LO nf = std::min(first, model.num_faces());
    for (LO f = 0; f < nf; ++f) {
      quad::UnstructuredReport ur;
      const mesh::FaceMesh in = quad::mesh_face_unstructured(model, f, result.quantized_curves,
                                                             quad::FaceFields{}, qo, &ur);
      if (in.quads.empty()) continue;
      const auto surface = model.face_geometry(f);
      std::vector<crossfield::Singularity> s;
      if (f < static_cast<LO>(result.cross_fields.size()) && result.cross_fields[f].ok)
        s = result.cross_fields[f].singularities;
      qstruct::CavityReport rep;
      Stopwatch clock;
      const mesh::FaceMesh out = qstruct::remesh_cavities(in, *surface, s, patterns, co, &rep);
      const double t = clock.seconds();
      seconds += t;
      ++faces;
      if (!rep.skipped.empty()) {
        ++skipped;
        if (per_face) std::cout << "face " << f << " skipped: " << rep.skipped << "\n";
        continue;
      }
      // What assembly relies on: the CAD-classified vertices unchanged and in order, a manifold
      // consistently oriented quad mesh.
      {
        std::vector<LO> a, b;
        for (LO v = 0; v < in.num_vertices(); ++v)
          if (in.vclass[v].dim < 2) a.push_back(v);
        for (LO v = 0; v < out.num_vertices(); ++v)
          if (out.vclass[v].dim < 2) b.push_back(v);
        bool same = a.size() == b.size();
        for (std::size_t i = 0; same && i < a.size(); ++i)
          same = in.points[a[i]] == out.points[b[i]] && in.uv[a[i]] == out.uv[b[i]] &&
                 in.vclass[a[i]].entity == out.vclass[b[i]].entity &&
                 in.vclass[a[i]].index == out.vclass[b[i]].index;
        try {
          const qstruct::QuadTopology topo(out);
        } catch (const Error&) {
          same = false;
        }
        if (!same || rep.sicn_min_after <= 0) {
          ++broken;
          std::cout << "face " << f << ": output check failed\n";
        }
      }
      irr0 += rep.irregular_before;
      irr1 += rep.irregular_after;
      quads0 += static_cast<std::int64_t>(in.quads.size());
      quads1 += static_cast<std::int64_t>(out.quads.size());
      min0 = std::min(min0, rep.sicn_min_before);
      min1 = std::min(min1, rep.sicn_min_after);
      sum0 += rep.sicn_avg_before * static_cast<double>(in.quads.size());
      sum1 += rep.sicn_avg_after * static_cast<double>(out.quads.size());
      sings += rep.singularities;
      flagged += rep.flagged;
      kept += rep.flagged_kept;
      for (int k = 0; k < 4; ++k) {
        grown[k] += rep.grown[k];
        remeshed[k] += rep.remeshed[k];
        rejected[k] += rep.rejected_quality[k];
        const auto& a = rep.diagnostics[k];
        auto& b = diag[k];
        b.stop_concave += a.stop_concave;
        b.stop_max_quads += a.stop_max_quads;
        b.stop_no_frontier += a.stop_no_frontier;
        b.stop_fan += a.stop_fan;
        b.stop_found += a.stop_found;
        b.checks += a.checks;
        b.no_pattern += a.no_pattern;
        b.no_match += a.no_match;
        b.not_better += a.not_better;
        b.refused_layout += a.refused_layout;
        b.refused_invalid += a.refused_invalid;
        b.refused_min += a.refused_min;
        b.refused_avg += a.refused_avg;
        b.refused_screened += a.refused_screened;
        b.skipped_futile += a.skipped_futile;
      }
      if (per_face)
        std::cout << "face " << f << " quads " << in.quads.size() << " -> " << out.quads.size()
                  << " irregular " << rep.irregular_before << " -> " << rep.irregular_after
                  << " sicn min " << rep.sicn_min_before << " -> " << rep.sicn_min_after << " avg "
                  << rep.sicn_avg_before << " -> " << rep.sicn_avg_after << " remeshed "
                  << rep.remeshed[0] << "/" << rep.remeshed[1] << "/" << rep.remeshed[2] << "/"
                  << rep.remeshed[3] << " flagged " << rep.flagged << "/" << rep.singularities
                  << " (" << t << " s)\n";
    }
    std::cout << path << " (size factor " << size_factor << "): " << faces << " faces, " << skipped
              << " skipped, " << broken << " failed the output checks\n"
              << "  interior irregular vertices " << irr0 << " -> " << irr1 << "\n"
              << "  quads " << quads0 << " -> " << quads1 << ", SICN min " << min0 << " -> " << min1
              << ", avg " << (quads0 ? sum0 / quads0 : 0) << " -> " << (quads1 ? sum1 / quads1 : 0)
              << "\n"
              << "  singularities " << sings << ", flagged " << flagged << ", kept " << kept << "\n"
              << "  cavities grown / remeshed / refused by quality, Steps 1-4:";
    for (int k = 0; k < 4; ++k)
      std::cout << " " << grown[k] << "/" << remeshed[k] << "/" << rejected[k];
    std::cout << "\n";
    for (int k = 0; k < 4; ++k) {
      const auto& b = diag[k];
      std::cout << "  step " << k + 1 << ": growth stops concave/max_quads/no_frontier/fan/found "
                << b.stop_concave << "/" << b.stop_max_quads << "/" << b.stop_no_frontier << "/"
                << b.stop_fan << "/" << b.stop_found << "; checks " << b.checks << " (no pattern "
                << b.no_pattern << ", no match " << b.no_match << ", not better " << b.not_better
                << "); refused layout/screened/invalid/min/avg " << b.refused_layout << "/"
                << b.refused_screened << "/" << b.refused_invalid << "/" << b.refused_min << "/"
                << b.refused_avg << "; skipped (nothing changed) " << b.skipped_futile << "\n";
    }
    std::cout << "  remesh_cavities time " << seconds << " s\n";
  });
}
