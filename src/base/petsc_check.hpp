#pragma once
// The check of a PETSc call's error code: a non-zero code throws std::runtime_error naming the
// call ("PETSc error in VecDuplicate (code 55)"). Header-only; the one part of base that needs
// PETSc's headers (for PetscErrorCode).
#include <petscsys.h>

#include <stdexcept>
#include <string>

namespace fdem {

inline void petsc_check(PetscErrorCode ierr, const char* what) {
  if (ierr) throw std::runtime_error(std::string("PETSc error in ") + what + " (code " + std::to_string(ierr) + ")");
}

}  // namespace fdem
