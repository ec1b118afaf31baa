#include "survey_common.hpp"

#include <cstdlib>
#include <exception>
#include <iostream>

#include "qsmesh/core/log.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/parallel/comm.hpp"

namespace qsmesh::test {

bool parse_survey_args(int argc, char** argv, const std::string& usage, SurveyArgs& args,
                       const std::function<bool(const std::string&, int&)>& extra) {
  bool ok = true;
  for (int i = 1; ok && i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--size-factor" && i + 1 < argc) {
      args.size_factor = std::atof(argv[++i]);
    } else if (a == "--threads" && i + 1 < argc) {
      args.threads = std::atoi(argv[++i]);
    } else if (a == "--faces") {
      args.per_face = true;
    } else if (extra(a, i)) {
    } else if (args.path.empty() && a.rfind("--", 0) != 0) {
      args.path = a;
    } else {
      ok = false;
    }
  }
  if (!ok || args.path.empty() || !(args.size_factor > 0)) {
    std::cerr << usage << "\n";
    return false;
  }
  return true;
}

cad::CadModel load_survey_model(const std::string& path) {
  cad::set_kernel_messages(true);
  return cad::load_cad(path);
}

SurveyRun run_survey_pipeline(const cad::CadModel& model, double size_factor, bool cross_fields,
                              const TaskArena& tasks) {
  SurveyRun run;
  Logger log(std::cerr, LogLevel::Warning);
  run.size = model.diagonal() * size_factor;
  run.options.background.sizes.size = run.size;
  run.options.sizemap.size_max = run.size;
  run.options.size_map = true;
  run.options.cross_fields = cross_fields;
  run.options.until = parallel::Stage::Background;
  // QSMESH_SURVEY_NO_BALANCE=1: the plain quantization of Sec. 4.3, to compare with the balanced
  // one.
  if (const char* nb = std::getenv("QSMESH_SURVEY_NO_BALANCE");
      nb != nullptr && std::string(nb) == "1")
    run.options.balance_counts = false;
  const Stopwatch clock;
  run.result = parallel::run_pipeline(parallel::Comm::self(), model, run.options, tasks, log);
  run.pipeline_seconds = clock.seconds();
  return run;
}

int run_reporting_errors(const std::string& tool, const std::function<void()>& body) {
  try {
    body();
  } catch (const std::exception& e) {
    std::cerr << tool << ": " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace qsmesh::test
