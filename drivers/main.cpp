// qsmesh: the command-line driver.
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "commands.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/log.hpp"
#include "qsmesh/io/atomic_file.hpp"
#include "qsmesh/io/signal_cleanup.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/parallel/comm.hpp"

namespace {

using namespace qsmesh;

// What a run killed outright (SIGKILL: no handler runs) left beside these outputs, before any
// work: its temporaries would otherwise stay forever, hidden and megabytes large.
void clean_leftovers_of(const std::vector<std::string>& outputs, const cli::Arguments& a,
                        std::string prefix) {
  Logger log(std::cerr, a.quiet ? LogLevel::Warning : LogLevel::Info, std::move(prefix));
  for (const std::string& out : outputs)
    for (const std::string& line :
         io::clean_leftovers(out, io::find_leftovers(out, io::process_exists)))
      log.info(line);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace qsmesh;
  io::prepare_output_libraries();
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    // Nothing asked: a usage error, not a successful run (scripts calling it with an empty
    // variable must notice).
    std::cerr << cli::help("");
    return 2;
  }
  cli::Arguments parsed;
  try {
    parsed = cli::parse(args);
  } catch (const InputError& e) {
    std::cerr << "qsmesh: " << e.what() << "\n";
    return 2;
  }
  if (parsed.command == cli::Command::Help) {
    std::cout << cli::help(parsed.help_topic);
    return 0;
  }
  if (parsed.command == cli::Command::Version) {
    std::cout << "qsmesh 0.1.0\n";
    return 0;
  }

  cad::set_kernel_messages(!parsed.verbose);
  // Known right after parsing, so that a signal at any later point finds their temporaries' names.
  std::vector<std::string> outputs;
  for (const cli::RunOutput& out : cli::run_outputs(parsed)) outputs.push_back(out.path);

  // Only the mesh and crossfield commands run distributed; the others need no MPI.
  const bool distributed = parsed.command == cli::Command::Mesh ||
                           parsed.command == cli::Command::CrossField ||
                           parsed.command == cli::Command::SizeMap;
  if (!distributed) {
    const io::SignalCleanup on_signal(outputs);
    clean_leftovers_of(outputs, parsed, "");
    try {
      return parsed.command == cli::Command::Info ? cli::run_info(parsed)
                                                  : cli::run_example(parsed);
    } catch (const InputError& e) {
      std::cerr << "qsmesh: " << e.what() << "\n";
      return 2;
    } catch (const OutputError& e) {
      std::cerr << "qsmesh: " << e.what() << "\n";
      return 1;
    } catch (const std::exception& e) {
      std::cerr << "qsmesh: internal error: " << e.what() << "\n";
      return 1;
    }
  }

  parallel::MpiSession mpi(&argc, &argv);
  const bool root = parallel::Comm::world().rank() == 0;
  // Every rank: mpirun forwards SIGINT and SIGTERM to all of them. After MPI_Init, so that the
  // handler is the one that stays.
  const io::SignalCleanup on_signal(outputs);
  // Only rank 0 writes, so only rank 0 looks for what an earlier run left (its lines prefixed as
  // the run's own are).
  if (root)
    clean_leftovers_of(outputs, parsed,
                       parallel::Comm::world().size() > 1 ? "[rank 0] " : std::string());
  try {
    switch (parsed.command) {
      case cli::Command::Mesh:
        return cli::run_mesh(parsed);
      case cli::Command::CrossField:
        return cli::run_crossfield(parsed);
      default:
        return cli::run_sizemap(parsed);
    }
  } catch (const InputError& e) {
    // Every rank reads the same input and fails the same way: one line, from rank 0.
    if (root) std::cerr << "qsmesh: " << e.what() << "\n";
    return 2;
  } catch (const OutputError& e) {
    // Only rank 0 writes: the disk, not the mesh, failed.
    std::cerr << "qsmesh: " << e.what() << "\n";
    if (parallel::Comm::world().size() > 1) parallel::MpiSession::abort(1);
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "qsmesh: internal error: " << e.what() << "\n";
    if (parallel::Comm::world().size() > 1) parallel::MpiSession::abort(1);
    return 1;
  }
}
