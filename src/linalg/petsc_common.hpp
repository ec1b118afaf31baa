// Private to src/linalg: what the PETSc backends share (error checking, index conversion).
#pragma once

#include <petscsys.h>

#include <cstdint>

#include "qsmesh/linalg/solver.hpp"

namespace qsmesh::linalg::detail {

/// Throws qsmesh::Error with PETSc's message recorded under `lane`.
[[noreturn]] void petsc_failed(SolverLane& lane, PetscErrorCode code, const char* call,
                               const char* file, int line);

/// `value` as a PETSc index; throws when it does not fit.
PetscInt to_petsc_int(std::int64_t value, const char* what);

}  // namespace qsmesh::linalg::detail

// Checks the return code of a PETSc call; used inside a class with a member `lane_` (a
// SolverLane*) while holding lane_->mutex().
#define QSMESH_PETSC_CALL(call)                                                           \
  do {                                                                                    \
    const PetscErrorCode qsmesh_petsc_code_ = (call);                                     \
    if (qsmesh_petsc_code_ != 0) [[unlikely]]                                             \
      ::qsmesh::linalg::detail::petsc_failed(*lane_, qsmesh_petsc_code_, #call, __FILE__, \
                                             __LINE__);                                   \
  } while (false)
