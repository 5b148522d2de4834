/* pm_petsc: PETSc started once on first use and stopped at exit, and its
 * failures turned into pm_err with PETSc's own message. */
#ifndef PM_PETSC_H
#define PM_PETSC_H

#include "pm_petsc_api.h" /* petscsys.h and the rest, through the table */

#include "pm_error.h"

/* Initialises PETSc (and MPI, as one process, unless the program did) if
 * that has not been done; registers pm_solve_finalize at exit.  PETSc's
 * signal handler is removed (the program's, or a sanitizer's, stays), and
 * PETSc errors are recorded instead of printed.  PM_ERR_LINALG if PETSc
 * cannot start or was finalised. */
pm_err pm_petsc_init(void);
/* Opens libpetsc (its table filled) ahead of pm_petsc_init, for a run that
 * will solve: a failure is left for pm_petsc_init to report.  A
 * pm_isolate_meanwhile task (about 0.08 s here: the loader's relocations
 * of libpetsc and the fifty libraries it brings, while gmsh meshes). */
void pm_petsc_preload(void);

/* Records a failed PETSc call (code != 0) as PM_ERR_LINALG with the call's
 * text and PETSc's message; returns PM_ERR_LINALG. */
pm_err pm_petsc_error(PetscErrorCode code, const char *file, int line,
                      const char *func, const char *call);

/* The message of the last PETSc error, which it then forgets ("" if
 * none); *code (may be NULL) receives its code (0 if none). */
const char *pm_petsc_last_message(PetscErrorCode *code);

/* PETSc call in a function with `pm_err ret` and a `done` label. */
#define PM_PETSC(call)                                                         \
  do {                                                                         \
    PetscErrorCode pm_petsc_code_ = (call);                                    \
    if (pm_petsc_code_) {                                                      \
      ret =                                                                    \
          pm_petsc_error(pm_petsc_code_, __FILE__, __LINE__, __func__, #call); \
      goto done;                                                               \
    }                                                                          \
  } while (0)

/* PETSc call in a function without resources to release. */
#define PM_PETSC_CALL(call)                                                    \
  do {                                                                         \
    PetscErrorCode pm_petsc_code_ = (call);                                    \
    if (pm_petsc_code_)                                                        \
      return pm_petsc_error(pm_petsc_code_, __FILE__, __LINE__, __func__,      \
                            #call);                                            \
  } while (0)

#endif
