/* pm_petsc: lazy PETSc start, finalisation at exit, errors as pm_err. */
#include "pm_petsc.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_newton.h"
#include "pm_par.h"
#include "pm_par_mpi.h"

static bool started;  /* this module called PetscInitialize */
static bool finished; /* PETSc was finalised: it cannot start again */
/* The first message of the last PETSc error (its innermost frame). */
static char petsc_message[512];
static PetscErrorCode petsc_code; /* its code */

static PetscErrorCode record_error(MPI_Comm comm, int line, const char *func,
                                   const char *file, PetscErrorCode code,
                                   PetscErrorType type, const char *mess,
                                   void *ctx) {
  (void)comm;
  (void)ctx;
  if (type == PETSC_ERROR_INITIAL) {
    const char *text = NULL;
    petsc_code = code;
    PetscErrorMessage(code, &text, NULL);
    snprintf(petsc_message, sizeof petsc_message, "%s%s%s (%s in %s:%d)",
             text ? text : "PETSc error", mess && *mess ? ": " : "",
             mess ? mess : "", func ? func : "?", file ? file : "?", line);
  }
  return code;
}

void pm_petsc_preload(void) {
  if (pm_petsc_api_load("a static solve (time.quasi_static.method: static, "
                        "implicit MPM)") != PM_SUCCESS)
    pm_error_clear();
}

pm_err pm_petsc_init(void) {
  PetscBool ready = PETSC_FALSE;
  PM_CHECK(!finished, PM_ERR_LINALG,
           "PETSc was finalised (pm_solve_finalize) and cannot start again");
  /* The library is opened here, by its first user: a run that does not
   * solve never maps it (the ranks' exchanges are MPI alone). */
  PM_CALL(pm_petsc_api_load(
      "a static solve (time.quasi_static.method: static, implicit MPM)"));
  PM_PETSC_CALL(PetscInitialized(&ready));
  if (ready) return PM_SUCCESS;
  /* PETSc's objects live on the run's ranks (PETSc's own world where the
   * program attached none: it starts MPI itself then). */
  if (pm_par_comm() != MPI_COMM_NULL) PETSC_COMM_WORLD = pm_par_comm();
  int mpi_ready = 0;
  MPI_Initialized(&mpi_ready);
  if (!mpi_ready) pm_par_singleton_quiet();
  PetscErrorCode code = PetscInitializeNoArguments();
  PM_CHECK(code == 0, PM_ERR_LINALG, "PetscInitializeNoArguments failed (%d)",
           (int)code);
  started = true;
  atexit(pm_solve_finalize);
  PM_PETSC_CALL(PetscPopSignalHandler());
  PM_PETSC_CALL(PetscPushErrorHandler(record_error, NULL));
  return PM_SUCCESS;
}

pm_err pm_petsc_error(PetscErrorCode code, const char *file, int line,
                      const char *func, const char *call) {
  const char *text = NULL;
  if (!petsc_message[0]) PetscErrorMessage(code, &text, NULL);
  pm_err ret = pm_error_set(
      PM_ERR_LINALG, file, line, func, "%s failed: %s", call,
      petsc_message[0] ? petsc_message : (text ? text : "PETSc error"));
  petsc_message[0] = '\0';
  return ret;
}

const char *pm_petsc_last_message(PetscErrorCode *code) {
  static char copy[sizeof petsc_message];
  memcpy(copy, petsc_message, sizeof copy);
  if (code) *code = petsc_message[0] ? petsc_code : 0;
  petsc_message[0] = '\0';
  return copy;
}

void pm_solve_finalize(void) {
  if (!started || finished) return;
  finished = true;
  PetscFinalize();
}
