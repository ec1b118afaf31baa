// Private to src/linalg: what the PETSc backends share (error checking, index conversion).
#pragma once

#include <petscmat.h>
#include <petscsys.h>

#include <cstdint>
#include <string>

#include "qsmesh/linalg/solver.hpp"

namespace qsmesh::linalg::detail {

/// Throws qsmesh::Error with PETSc's message recorded under `lane`.
[[noreturn]] void petsc_failed(SolverLane& lane, PetscErrorCode code, const char* call,
                               const char* file, int line);

/// `value` as a PETSc index; throws when it does not fit.
PetscInt to_petsc_int(std::int64_t value, const char* what);

/// Marks `matrix` symmetric positive definite for good (the field systems are), so that the
/// factorizations take their SPD paths. Under the lane's lock.
void set_spd_options(SolverLane& lane, Mat matrix);

/// Throws unless `factor`'s numeric factorization succeeded: PETSc reports a failure through the
/// factor, not the return code (MatSetErrorIfFailure is off), and MUMPS's SPD path accepts
/// negative pivots, so a Cholesky factor with any is refused too. `mumps`: the factor is MUMPS's
/// (its INFOG(1) and INFOG(12) are read); `who` and `name` open and name the messages; `n` is the
/// system's size. Under the lane's lock.
void check_factorization(SolverLane& lane, Mat factor, bool mumps, MatFactorType type,
                         const std::string& name, LO n, const char* who);

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
