// The driver's commands. Each returns the process exit code.
#pragma once

#include <memory>

#include "cli.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/log.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "qsmesh/parallel/split.hpp"

namespace qsmesh::cli {

/// What the distributed commands (mesh, crossfield) share: the communicator, a logger that prints
/// on rank 0, the model read by every rank, the size, the thread arena and the stage times.
/// Collective: MPI must be initialised. Throws InputError for a bad model file.
struct Session {
  Session(const Arguments& args, const char* command);
  /// The run's first line (model, size, ranks and threads): printed once the request is checked,
  /// so that a refused run prints only its error.
  void announce(const Arguments& args, const char* command);
  parallel::Comm comm;
  int rank = 0, ranks = 1;
  Logger log;
  cad::CadModel model;
  double size = 0;
  int threads = 1;
  std::unique_ptr<TaskArena> tasks;
  StageTimes times;
  /// The load's face measurements, split over the ranks and threads (cad::LoadOptions).
  parallel::SplitRound load_round;
};

class JsonWriter;
/// The fields every distributed command's --stats starts with: model, ranks, threads, size.
void write_run_header(JsonWriter& j, const Arguments& args, const Session& s);
/// "seconds": {stage: seconds, ..., "total": seconds}.
void write_times(JsonWriter& j, const StageTimes& times);
/// " stage seconds; ... total seconds" for the printed summaries.
std::string times_line(const StageTimes& times);

int run_info(const Arguments& args);
int run_example(const Arguments& args);
/// Collective over MPI_COMM_WORLD; MPI must be initialised.
int run_mesh(const Arguments& args);
/// `qsmesh crossfield`: background meshes and cross fields of every face (paper 000 Sec. 3),
/// written as VTU with the fields, and the Euler check per face. Collective.
int run_crossfield(const Arguments& args);
/// `qsmesh sizemap`: size map and curve quantization (paper 000 Sec. 4), written as VTU.
/// Collective.
int run_sizemap(const Arguments& args);

/// The size-map options of the command line (--sizemap, --quads, --curvature-edges, --curve-edges,
/// --face-quads, --corner-size, --curve-size, --face-size), checked against the model (InputError
/// naming an id that does not exist), set in options.sizemap and options.quantize.prescribed;
/// options.sizemap.size_max is the session's size.
void apply_size_options(const Arguments& args, const Session& s,
                        parallel::PipelineOptions& options);
/// The background's field divisions a run uses: --field-divisions, or kDefaultFieldDivisions.
double field_divisions(const Arguments& args);
/// The pipeline options every field-computing command shares: the session's size, the field
/// divisions, and the cross-field options (--distributed-threshold, --field-change,
/// --field-iterations, --field-stall); the rest at their defaults.
parallel::PipelineOptions field_options(const Arguments& args, const Session& s);
/// The curvature edges per turn a run uses: --curvature-edges, or the size map's default.
double curvature_edges(const Arguments& args);
/// The feature ratio a run uses: --feature-ratio, or the size map's default.
double feature_ratio(const Arguments& args);
/// The thin-face aspect ratio a run uses: --thin-aspect, or kDefaultThinAspect.
double thin_aspect(const Arguments& args);
/// The floor of the automatic sizes the user gave, in model units: --size-min, or --size-min-ratio
/// times `size` (the size cap); 0 when neither is given (the size map's default floor).
double given_size_min(const Arguments& args, double size);

/// Throws InputError when the size options ask for more quads than --max-quads allows or more
/// memory than this machine has (lower estimates, limits.hpp), naming the request and the estimate.
void check_request(const Arguments& args, const Session& s);

/// Checks the files a run writes before any work: every output (-o, the .xdmf beside an .h5,
/// --stats) names a file distinct from the model and from the others (symbolic links, '..' and
/// hard links resolved), and each can be created where it will be written. Throws InputError.
/// The -o of mesh, crossfield and sizemap is checked by io::check_output_path as well.
void check_output_files(const Arguments& args);

/// Writes `text` to `path` through a temporary file renamed at the end.
void write_text_file_atomically(const std::string& path, const std::string& text);
/// One file a run writes, named for messages: `what` ("-o", "--stats", "the .xdmf file") and
/// `after` (" written beside -o").
struct RunOutput {
  std::string what, path, after;
  [[nodiscard]] std::string text() const { return what + " '" + path + "'" + after; }
};
/// Every file the command of `args` may write: -o (for .h5 also its XDMF description) and --stats.
[[nodiscard]] std::vector<RunOutput> run_outputs(const Arguments& args);

}  // namespace qsmesh::cli
