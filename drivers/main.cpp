// qsmesh: the command-line driver.
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "commands.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/parallel/comm.hpp"

int main(int argc, char** argv) {
  using namespace qsmesh;
  io::prepare_output_libraries();
  std::vector<std::string> args(argv + 1, argv + argc);
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

  // Only the mesh and crossfield commands run distributed; the others need no MPI.
  const bool distributed = parsed.command == cli::Command::Mesh || parsed.command == cli::Command::CrossField ||
                           parsed.command == cli::Command::SizeMap;
  if (!distributed) {
    try {
      return parsed.command == cli::Command::Info ? cli::run_info(parsed) : cli::run_example(parsed);
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
  try {
    switch (parsed.command) {
      case cli::Command::Mesh: return cli::run_mesh(parsed);
      case cli::Command::CrossField: return cli::run_crossfield(parsed);
      default: return cli::run_sizemap(parsed);
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
