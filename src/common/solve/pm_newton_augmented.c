/* pm_newton_augmented: a preconditioner factorised from a larger matrix
 * (pm_newton_problem.aux_n): M = [J0 G; C D], D diagonal, applied to
 * [r; 0], whose first n values are (J0 - G D^-1 C)^-1 r.  Up to
 * PM_NEWTON_AUG_DENSE_MAX unknowns that Schur complement is formed dense,
 * straight from the caller's rows on every OpenMP thread, and factorised
 * dense (pm_newton_dense.c); above, or where M's last rows are not so,
 * MUMPS factorises M. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <petscsnes.h>

#include "pm_newton_solver_impl.h"
#include "pm_omp.h"
#include "pm_petsc.h"

pm_err pm_newton_aug_init(pm_newton *s, const pm_newton_problem *p) {
  if (p->aux_n <= 0) return PM_SUCCESS;
  PM_CHECK(p->aux_ptr && p->aux_idx && p->aux_values, PM_ERR_ARG,
           "Newton problem: aux_n needs aux_ptr, aux_idx and aux_values");
  PM_CHECK(!s->dist && s->o.op == PM_NEWTON_MATRIX_FREE, PM_ERR_UNSUPPORTED,
           "Newton problem: the augmented preconditioner (aux_n) needs a "
           "matrix-free operator and one process");
  const long N = p->n + p->aux_n;
  PM_CALL(pm_pattern_check(N, p->aux_ptr, p->aux_idx));
  s->aux_N = N;
  s->aux_ptr = p->aux_ptr;
  s->aux_idx = p->aux_idx;
  s->aug = true;
  return PM_SUCCESS;
}

/* Whether the dense path serves: n within its bound, and M's rows past n
 * holding no column past n but their own (D diagonal). */
static bool dense_fits(const pm_newton *s) {
  const long n = s->p.n, N = s->aux_N, *ptr = s->aux_ptr, *idx = s->aux_idx;
  if (!pm_newton_dense_within(s)) return false;
  for (long i = n; i < N; i++)
    for (long k = ptr[i]; k < ptr[i + 1]; k++)
      if (idx[k] >= n && idx[k] != i) return false;
  return true;
}

pm_err pm_newton_aug_objects(pm_newton *s) {
  if (!s->aug) return PM_SUCCESS;
  const long n = s->p.n, N = s->aux_N, nsrc = s->aux_ptr[N];
  PM_CALL(PM_ALLOC(s->asrc, nsrc > 0 ? nsrc : 1, "augmented matrix values"));
  if (dense_fits(s)) {
    PM_CALL(PM_ALLOC(s->ashift, n, "augmented matrix shift"));
    PM_CALL(PM_ALLOC(s->adiag, N - n, "augmented matrix diagonal"));
    PM_CALL(pm_newton_dense_storage(s));
    s->aug_dense = true;
    return PM_SUCCESS;
  }
  PC pc;
  PetscInt *cols; /* (one process: none kept) */
  PM_CALL(pm_pattern_build(N, s->aux_ptr, s->aux_idx, true, &s->apat));
  PM_CALL(pm_newton_create_matrix(s, &s->apat, false, &cols, NULL, &s->Ma));
  PM_PETSC_CALL(VecCreateSeq(PETSC_COMM_SELF, (PetscInt)N, &s->Ab));
  PM_PETSC_CALL(VecDuplicate(s->Ab, &s->Ay));
  PM_PETSC_CALL(KSPCreate(PETSC_COMM_SELF, &s->ka));
  PM_PETSC_CALL(PetscObjectSetOptions((PetscObject)s->ka, s->opts));
  PM_PETSC_CALL(KSPSetOptionsPrefix(s->ka, "pm_aug_"));
  PM_PETSC_CALL(KSPSetType(s->ka, KSPPREONLY));
  PM_PETSC_CALL(KSPGetPC(s->ka, &pc));
  PM_PETSC_CALL(PetscObjectSetOptions((PetscObject)pc, s->opts));
  PM_PETSC_CALL(PCSetType(pc, PCLU));
#ifdef PETSC_HAVE_MUMPS
  PM_PETSC_CALL(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
#endif
  PM_PETSC_CALL(PetscOptionsPush(s->opts));
  PetscErrorCode code = KSPSetFromOptions(s->ka);
  PetscOptionsPop();
  PM_PETSC_CALL(code);
  return PM_SUCCESS;
}

pm_err pm_newton_aug_values(pm_newton *s, const double *x) {
  PM_CALL(s->p.aux_values(s->p.ctx, x, s->asrc));
  if (s->aug_dense)
    memset(s->ashift, 0, (size_t)s->p.n * sizeof *s->ashift);
  else
    PM_CALL(pm_newton_scatter_into(s->Ma, &s->apat, s->asrc));
  s->aug_dirty = true;
  return PM_SUCCESS;
}

PetscErrorCode pm_newton_aug_shift(pm_newton *s, const double *d) {
  PetscFunctionBeginUser;
  if (s->aug_dense) {
    for (long i = 0; i < s->p.n; i++) s->ashift[i] += d[i];
    PetscFunctionReturn(0);
  }
  for (PetscInt i = 0; i < (PetscInt)s->p.n; i++)
    PetscCall(MatSetValue(s->Ma, i, i, d[i], ADD_VALUES));
  PetscCall(MatAssemblyBegin(s->Ma, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(s->Ma, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}

/* S = J0 + shift - G D^-1 C into Sd from M's rows as the caller gives
 * them (repeated entries add up), row i of S in Sd's row i, each thread
 * its rows; then the LU of the buffer (S^T to LAPACK).  An exact zero in
 * D or a zero pivot marks the factorisation failed. */
static void dense_factor(pm_newton *s) {
  const long n = s->p.n, N = s->aux_N, *ptr = s->aux_ptr, *idx = s->aux_idx;
  const double *v = s->asrc, *shift = s->ashift;
  double *S = s->Sd, *D = s->adiag;
  bool zero = false;
  for (long a = n; a < N; a++) {
    D[a - n] = 0;
    for (long k = ptr[a]; k < ptr[a + 1]; k++)
      if (idx[k] == a) D[a - n] += v[k];
    zero = zero || D[a - n] == 0;
  }
  s->dense_failed = zero;
  if (zero) return;
  PM_OMP(parallel for schedule(static) default(none)
         shared(n, ptr, idx, v, shift, S, D))
  for (long i = 0; i < n; i++) {
    double *Si = S + i * n;
    memset(Si, 0, (size_t)n * sizeof *Si);
    Si[i] = shift[i];
    for (long k = ptr[i]; k < ptr[i + 1]; k++) {
      const long c = idx[k];
      if (c < n) {
        Si[c] += v[k];
        continue;
      }
      const double g = v[k] / D[c - n];
      for (long q = ptr[c]; q < ptr[c + 1]; q++)
        if (idx[q] < n) Si[idx[q]] -= g * v[q];
    }
  }
  pm_newton_dense_factor(s);
}

PetscErrorCode pm_newton_aug_factor(pm_newton *s) {
  PetscFunctionBeginUser;
  if (!pm_newton_aug_on(s) || !s->aug_dirty) PetscFunctionReturn(0);
  if (s->aug_dense) {
    dense_factor(s);
  } else {
    PetscCall(KSPSetOperators(s->ka, s->Ma, s->Ma));
    PetscCall(KSPSetUp(s->ka));
  }
  s->aug_dirty = false;
  PetscFunctionReturn(0);
}

/* y = the first n values of M^-1 [x; 0]. */
static PetscErrorCode aug_apply(PC pc, Vec x, Vec y) {
  pm_newton *s;
  const double *a;
  double *b;
  PetscFunctionBeginUser;
  PetscCall(PCShellGetContext(pc, &s));
  if (s->aug_dense) {
    PetscCall(pm_newton_dense_solve(s, pc, x, y));
    PetscFunctionReturn(0);
  }
  const long n = s->p.n, N = s->aux_N;
  PetscCall(VecGetArrayRead(x, &a));
  PetscCall(VecGetArray(s->Ab, &b));
  memcpy(b, a, (size_t)n * sizeof *b);
  memset(b + n, 0, (size_t)(N - n) * sizeof *b);
  PetscCall(VecRestoreArray(s->Ab, &b));
  PetscCall(VecRestoreArrayRead(x, &a));
  PetscCall(KSPSolve(s->ka, s->Ab, s->Ay));
  PetscCall(VecGetArrayRead(s->Ay, &a));
  PetscCall(VecGetArray(y, &b));
  memcpy(b, a, (size_t)n * sizeof *b);
  PetscCall(VecRestoreArray(y, &b));
  PetscCall(VecRestoreArrayRead(s->Ay, &a));
  PetscFunctionReturn(0);
}

PetscErrorCode pm_newton_aug_set_pc(pm_newton *s, PC pc) {
  return pm_newton_shell_pc(s, pc, NULL, aug_apply, "augmented LU");
}

void pm_newton_aug_free(pm_newton *s) {
  KSPDestroy(&s->ka);
  MatDestroy(&s->Ma);
  VecDestroy(&s->Ab);
  VecDestroy(&s->Ay);
  pm_pattern_free(&s->apat);
  free(s->asrc);
  free(s->ashift);
  free(s->adiag);
  free(s->Sd);
  free(s->ipiv);
}
