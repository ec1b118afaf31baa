// Set-up shared by the qstruct survey tools (qstruct_survey, cavity_survey): command line, model
// loading and the serial pipeline run to the quantized curves.
#pragma once

#include <functional>
#include <string>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/parallel/pipeline.hpp"

namespace qsmesh::test {

/// Options every survey takes.
struct SurveyArgs {
  std::string path;           ///< the model (first argument that is not an option)
  double size_factor = 0.02;  ///< --size-factor: target size as a fraction of the model diagonal
  int threads = 1;            ///< --threads
  bool per_face = false;      ///< --faces: one line per face
};

/// Reads MODEL, --size-factor F, --threads T and --faces into `args`; any other argument argv[i]
/// goes to `extra(arg, i)`, which returns true when it is one of the tool's own options (it may
/// advance i past a value). Prints `usage` to stderr and returns false on an unknown argument, a
/// missing model or a size factor <= 0.
[[nodiscard]] bool parse_survey_args(int argc, char** argv, const std::string& usage,
                                     SurveyArgs& args,
                                     const std::function<bool(const std::string&, int&)>& extra);

/// The serial pipeline run of a survey.
struct SurveyRun {
  parallel::PipelineOptions options;  ///< what it ran with
  parallel::PipelineResult result;
  double size = 0;              ///< target size, model diagonal * size factor (model units)
  double pipeline_seconds = 0;  ///< wall time of run_pipeline
};

/// Runs the pipeline on MPI_COMM_SELF up to parallel::Stage::Background with the size map on
/// (as `qsmesh sizemap`), cross fields when `cross_fields`, warnings to stderr.
[[nodiscard]] SurveyRun run_survey_pipeline(const cad::CadModel& model, double size_factor,
                                            bool cross_fields, const TaskArena& tasks);

/// Loads the model at `path` with the CAD kernel's messages on.
[[nodiscard]] cad::CadModel load_survey_model(const std::string& path);

/// Runs `body`; an exception is printed as "tool: what" to stderr and gives 1, else 0.
int run_reporting_errors(const std::string& tool, const std::function<void()>& body);

}  // namespace qsmesh::test
