/* pm_newton_linear: the linear solver of each Newton step, configured from
 * the options and then PETSc's, and what it multiplies by. */
#include <petscsnes.h>

#include "pm_newton_solver_impl.h"
#include "pm_petsc.h"

/* The linear solver, configured from the options and then PETSc's. */
static pm_err create_linear(pm_newton *s, KSP *out) {
  pm_err ret = PM_SUCCESS;
  const pm_newton_options *o = &s->o;
  bool matrix_free = o->op != PM_NEWTON_ASSEMBLED;
  KSP ksp = NULL;
  PC pc;
  PM_PETSC(KSPCreate(s->comm, &ksp));
  PM_PETSC(PetscObjectSetOptions((PetscObject)ksp, s->opts));
  PM_PETSC(KSPSetOptionsPrefix(ksp, "pm_"));
  PM_PETSC(KSPGetPC(ksp, &pc));
  PM_PETSC(PetscObjectSetOptions((PetscObject)pc, s->opts));
  switch (o->linear) {
  case PM_NEWTON_DIRECT:
    /* With a matrix-free operator the factorisation preconditions GMRES
     * (exactly, for a current J: one iteration). */
    PM_PETSC(KSPSetType(ksp, matrix_free ? KSPGMRES : KSPPREONLY));
    PM_PETSC(PCSetType(pc, PCLU));
#ifdef PETSC_HAVE_MUMPS
    PM_PETSC(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
#endif
    break;
  case PM_NEWTON_GMRES_GAMG:
    PM_PETSC(KSPSetType(ksp, KSPGMRES));
    PM_PETSC(PCSetType(pc, PCGAMG));
    break;
  case PM_NEWTON_CG_JACOBI:
    PM_PETSC(KSPSetType(ksp, KSPCG));
    PM_PETSC(PCSetType(pc, PCJACOBI));
    break;
  case PM_NEWTON_GMRES_ILU:
    /* Across ranks ILU(0) in each rank's block (block Jacobi's default). */
    PM_PETSC(KSPSetType(ksp, KSPGMRES));
    PM_PETSC(PCSetType(pc, s->dist ? PCBJACOBI : PCILU));
    break;
  case PM_NEWTON_CG_GAMG:
    PM_PETSC(KSPSetType(ksp, KSPCG));
    PM_PETSC(PCSetType(pc, PCGAMG));
    break;
  }
  PM_PETSC(KSPSetTolerances(ksp, o->linear_rtol, PETSC_DEFAULT, PETSC_DEFAULT,
                            o->linear_max_iter));
  PM_PETSC(KSPSetPreSolve(ksp, pm_newton_linear_presolve, s));
  PM_PETSC(KSPSetPostSolve(ksp, pm_newton_linear_postsolve, s));
  PM_PETSC(PetscOptionsPush(s->opts));
  PetscErrorCode code = KSPSetFromOptions(ksp);
  PetscOptionsPop();
  PM_PETSC(code);
  *out = ksp;
  ksp = NULL;
done:
  KSPDestroy(&ksp);
  return ret;
}

/* Gives SNES a new linear solver (in place of one left inconsistent by a
 * failure inside it). */
pm_err pm_newton_replace_linear(pm_newton *s) {
  KSP ksp, held;
  PM_CALL(create_linear(s, &ksp));
  held = ksp;
  PetscErrorCode code = SNESSetKSP(s->snes, ksp);
  KSPDestroy(&ksp); /* SNES holds it */
  PM_PETSC_CALL(code);
  s->ksp = held;
  return PM_SUCCESS;
}

/* What the linear solver multiplies by (A) and builds its preconditioner
 * from (B). */
void pm_newton_operators(const pm_newton *s, Mat *A, Mat *B) {
  *A = s->o.op == PM_NEWTON_ASSEMBLED ? s->J : s->Shell;
  *B = s->o.op == PM_NEWTON_MATRIX_FREE_CHEAP_PC ? s->P : s->J;
}

pm_newton_linear pm_newton_linear_of(pm_linear_solver l) {
  switch (l) {
  case PM_LINEAR_GMRES_GAMG: return PM_NEWTON_GMRES_GAMG;
  case PM_LINEAR_CG_JACOBI: return PM_NEWTON_CG_JACOBI;
  case PM_LINEAR_GMRES_ILU: return PM_NEWTON_GMRES_ILU;
  case PM_LINEAR_CG_GAMG: return PM_NEWTON_CG_GAMG;
  case PM_LINEAR_DIRECT: break;
  }
  return PM_NEWTON_DIRECT;
}
