#include "backends.hpp"

namespace qsmesh::linalg {

std::unique_ptr<LinearSolver> make_solver(LO n, const SolverOptions& options, SolverLane* lane) {
  QSMESH_CHECK(n >= 0, "make_solver: negative system size " << n);
  // A group lane splits its large systems over the group's ranks (every rank makes this call).
  const bool distributed =
      lane != nullptr && lane->group() != nullptr && n >= options.distributed_threshold;
  QSMESH_CHECK(!options.complex_pairs || n % 2 == 0,
               "make_solver: complex_pairs needs an even system size, not " << n);
  const auto eigen = [&] {
    return options.complex_pairs ? detail::make_eigen_complex_solver()
                                 : detail::make_eigen_solver();
  };
  switch (options.backend) {
    case Backend::Eigen:
      return eigen();
    case Backend::Petsc:
      QSMESH_CHECK(lane != nullptr,
                   "make_solver: Backend::Petsc needs a SolverLane, and none was given");
      if (distributed) return detail::make_petsc_distributed_solver(*lane);
      return detail::make_petsc_solver(*lane);
    case Backend::PetscMultigrid:
      QSMESH_CHECK(lane != nullptr,
                   "make_solver: Backend::PetscMultigrid needs a SolverLane, and none was given");
      return detail::make_petsc_multigrid_solver(*lane, options.multigrid_rtol, options.block_size);
    case Backend::Automatic:
      if (distributed) return detail::make_petsc_distributed_solver(*lane);
      if (lane != nullptr &&
          n >= (options.complex_pairs ? options.petsc_threshold_complex : options.petsc_threshold))
        return detail::make_petsc_solver(*lane);
      return eigen();
  }
  QSMESH_CHECK(false, "make_solver: unknown backend " << static_cast<int>(options.backend));
  return nullptr;
}

}  // namespace qsmesh::linalg
