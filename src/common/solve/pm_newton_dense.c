/* pm_newton_dense: the direct solver's LU taken dense where the matrix is
 * small and full enough (a tangent of three rings is a third to two
 * thirds full at the sizes the direct solver serves): LAPACK's dgetrf on
 * every OpenMP thread, then a triangular solve a linear iteration.  Here
 * a dense LU of 1217 unknowns takes 20 ms and its solve 0.75 ms, where
 * MUMPS took 50-65 ms and 1.5 ms on the same matrix (docs/validation.md,
 * "The coupled LU dense when it is small").  The matrix is held
 * row-major in Sd, which LAPACK reads as its transpose: the solve is the
 * transposed one. */
#include <math.h>
#include <string.h>

#include <lapacke.h>
#include <petscksp.h>

#include "pm_newton_solver_impl.h"
#include "pm_omp.h"
#include "pm_petsc.h"

bool pm_newton_dense_within(const pm_newton *s) {
  PetscInt v = (PetscInt)PM_NEWTON_AUG_DENSE_MAX;
  PetscBool set = PETSC_FALSE;
  if (PetscOptionsGetInt(s->opts, NULL, "-pm_aug_dense_max", &v, &set) || !set)
    v = (PetscInt)PM_NEWTON_AUG_DENSE_MAX;
  const double n = (double)s->p.n;
  return !s->dist && s->p.n <= (long)v && n * n <= 2147483647.0;
}

pm_err pm_newton_dense_storage(pm_newton *s) {
  const long n = s->p.n;
  if (s->Sd) return PM_SUCCESS;
  PM_CALL(PM_ALLOC(s->Sd, n * n, "dense LU"));
  PM_CALL(PM_ALLOC(s->ipiv, n, "dense LU pivots"));
  return PM_SUCCESS;
}

void pm_newton_dense_factor(pm_newton *s) {
  const lapack_int n = (lapack_int)s->p.n;
  s->dense_failed =
      LAPACKE_dgetrf_work(LAPACK_COL_MAJOR, n, n, s->Sd, n, s->ipiv) != 0;
}

PetscErrorCode pm_newton_dense_solve(pm_newton *s, PC pc, Vec x, Vec y) {
  const long n = s->p.n;
  const double *a;
  double *b;
  PetscFunctionBeginUser;
  PetscCall(VecGetArrayRead(x, &a));
  PetscCall(VecGetArray(y, &b));
  if (s->dense_failed) {
    for (long i = 0; i < n; i++) b[i] = INFINITY;
  } else {
    memcpy(b, a, (size_t)n * sizeof *b);
    LAPACKE_dgetrs_work(LAPACK_COL_MAJOR, 'T', (lapack_int)n, 1, s->Sd,
                        (lapack_int)n, s->ipiv, b, (lapack_int)n);
  }
  PetscCall(VecRestoreArray(y, &b));
  PetscCall(VecRestoreArrayRead(x, &a));
  if (s->dense_failed)
    PetscCall(PCSetFailedReason(pc, PC_FACTOR_NUMERIC_ZEROPIVOT));
  PetscFunctionReturn(0);
}

bool pm_newton_dense_direct_fits(const pm_newton *s) {
  const double n = (double)s->p.n;
  return !s->aug && pm_newton_dense_within(s) &&
         (double)s->jpat.ptr[s->p.n] >= 0.1 * n * n;
}

/* The preconditioner's matrix into Sd, row by row on every thread; then
 * its LU. */
static PetscErrorCode dense_setup(PC pc) {
  pm_newton *s;
  Mat A, B;
  const PetscInt *ia, *ja;
  const PetscScalar *v;
  PetscInt rows;
  PetscBool done;
  PetscFunctionBeginUser;
  PetscCall(PCShellGetContext(pc, &s));
  pm_newton_operators(s, &A, &B);
  PetscCall(
      MatGetRowIJ(B, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ia, &ja, &done));
  PetscCheck(done && rows == (PetscInt)s->p.n, PETSC_COMM_SELF, PETSC_ERR_PLIB,
             "dense LU: the matrix's rows are not at hand");
  PetscCall(MatSeqAIJGetArrayRead(B, &v));
  const long n = s->p.n;
  double *S = s->Sd;
  PM_OMP(parallel for schedule(static) default(none) shared(n, ia, ja, v, S))
  for (long i = 0; i < n; i++) {
    double *Si = S + i * n;
    memset(Si, 0, (size_t)n * sizeof *Si);
    for (PetscInt k = ia[i]; k < ia[i + 1]; k++) Si[ja[k]] += v[k];
  }
  PetscCall(MatSeqAIJRestoreArrayRead(B, &v));
  PetscCall(
      MatRestoreRowIJ(B, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ia, &ja, &done));
  pm_newton_dense_factor(s);
  PetscFunctionReturn(0);
}

static PetscErrorCode dense_apply(PC pc, Vec x, Vec y) {
  pm_newton *s;
  PetscFunctionBeginUser;
  PetscCall(PCShellGetContext(pc, &s));
  PetscCall(pm_newton_dense_solve(s, pc, x, y));
  PetscFunctionReturn(0);
}

PetscErrorCode pm_newton_shell_pc(pm_newton *s, PC pc,
                                  PetscErrorCode (*setup)(PC),
                                  PetscErrorCode (*apply)(PC, Vec, Vec),
                                  const char *name) {
  PetscFunctionBeginUser;
  PetscCall(PCSetType(pc, PCSHELL));
  PetscCall(PCShellSetContext(pc, s));
  if (setup) PetscCall(PCShellSetSetUp(pc, setup));
  PetscCall(PCShellSetApply(pc, apply));
  PetscCall(PCShellSetName(pc, name));
  PetscFunctionReturn(0);
}

PetscErrorCode pm_newton_dense_set_pc(pm_newton *s, PC pc) {
  return pm_newton_shell_pc(s, pc, dense_setup, dense_apply, "dense LU");
}
