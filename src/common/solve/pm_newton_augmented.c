/* pm_newton_augmented: a preconditioner factorised from a larger matrix
 * (pm_newton_problem.aux_n): the LU of [J0 G; C I] applied to [r; 0],
 * whose first n values are (J0 - G C)^-1 r. */
#include <stdlib.h>
#include <string.h>

#include <petscsnes.h>

#include "pm_newton_solver_impl.h"
#include "pm_petsc.h"

pm_err pm_newton_aug_init(pm_newton *s, const pm_newton_problem *p) {
  if (p->aux_n <= 0) return PM_SUCCESS;
  PM_CHECK(p->aux_ptr && p->aux_idx && p->aux_values, PM_ERR_ARG,
           "Newton problem: aux_n needs aux_ptr, aux_idx and aux_values");
  PM_CHECK(!s->dist && s->o.op == PM_NEWTON_MATRIX_FREE, PM_ERR_UNSUPPORTED,
           "Newton problem: the augmented preconditioner (aux_n) needs a "
           "matrix-free operator and one process");
  const long N = p->n + p->aux_n;
  PM_CALL(pm_pattern_build(N, p->aux_ptr, p->aux_idx, true, &s->apat));
  PM_CALL(PM_ALLOC(s->asrc, s->apat.nsrc > 0 ? s->apat.nsrc : 1,
                   "augmented matrix values"));
  s->aug = true;
  return PM_SUCCESS;
}

pm_err pm_newton_aug_objects(pm_newton *s) {
  if (!s->aug) return PM_SUCCESS;
  PC pc;
  const PetscInt N = (PetscInt)s->apat.n;
  PetscInt *cols; /* (one process: none kept) */
  PM_CALL(pm_newton_create_matrix(s, &s->apat, false, &cols, NULL, &s->Ma));
  PM_PETSC_CALL(VecCreateSeq(PETSC_COMM_SELF, N, &s->Ab));
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
  PM_CALL(pm_newton_scatter_into(s->Ma, &s->apat, s->asrc));
  s->aug_dirty = true;
  return PM_SUCCESS;
}

PetscErrorCode pm_newton_aug_factor(pm_newton *s) {
  PetscFunctionBeginUser;
  if (!pm_newton_aug_on(s) || !s->aug_dirty) PetscFunctionReturn(0);
  PetscCall(KSPSetOperators(s->ka, s->Ma, s->Ma));
  PetscCall(KSPSetUp(s->ka));
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
  const long n = s->p.n, N = s->apat.n;
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
  PetscFunctionBeginUser;
  PetscCall(PCSetType(pc, PCSHELL));
  PetscCall(PCShellSetContext(pc, s));
  PetscCall(PCShellSetApply(pc, aug_apply));
  PetscCall(PCShellSetName(pc, "augmented LU"));
  PetscFunctionReturn(0);
}

void pm_newton_aug_free(pm_newton *s) {
  KSPDestroy(&s->ka);
  MatDestroy(&s->Ma);
  VecDestroy(&s->Ab);
  VecDestroy(&s->Ay);
  pm_pattern_free(&s->apat);
  free(s->asrc);
}
