/* pm_newton_line_search: a line search that takes Newton's full step where
 * it lowers the residual's norm enough (the sufficient decrease of
 * backtracking's first trial) and otherwise the secant on the residual's
 * norm along the step (PETSc's l2): the secant's better steps where the
 * full one overshoots, and Newton's own steps, with their quadratic order,
 * near the root. */
#include <math.h>

#include <petscsnes.h>

#include "pm_newton_solver_impl.h"
#include "pm_petsc.h"

/* The sufficient decrease of the squared norm, as PETSc's bt by default:
 * |F(x - y)|^2 <= (1 - 2 alpha) |F(x)|^2. */
#define PM_FULL_STEP_ALPHA 1e-4

static PetscErrorCode full_then_secant(SNESLineSearch ls, void *ctx) {
  pm_newton *s = ctx;
  Vec X, F, Y, W, G;
  PetscReal xnorm, fnorm, ynorm, gnorm;
  PetscBool changed;
  SNES snes;
  PetscFunctionBeginUser;
  PetscCall(SNESLineSearchGetVecs(ls, &X, &F, &Y, &W, &G));
  PetscCall(SNESLineSearchGetNorms(ls, &xnorm, &fnorm, &ynorm));
  PetscCall(SNESLineSearchGetSNES(ls, &snes));
  PetscCall(SNESLineSearchSetReason(ls, SNES_LINESEARCH_SUCCEEDED));
  PetscCall(SNESLineSearchPreCheck(ls, X, Y, &changed));
  PetscCall(VecWAXPY(W, -1.0, Y, X));
  PetscCall(SNESComputeFunction(snes, W, G));
  if (!s->domain_last) {
    PetscCall(VecNorm(G, NORM_2, &gnorm));
    if (isfinite(gnorm) &&
        gnorm * gnorm <= (1 - 2 * PM_FULL_STEP_ALPHA) * fnorm * fnorm) {
      PetscCall(VecCopy(W, X));
      PetscCall(VecCopy(G, F));
      PetscCall(VecNorm(Y, NORM_2, &ynorm));
      PetscCall(VecNorm(X, NORM_2, &xnorm));
      PetscCall(SNESLineSearchSetLambda(ls, 1.0));
      PetscCall(SNESLineSearchSetNorms(ls, xnorm, gnorm, ynorm));
      PetscFunctionReturn(0);
    }
  }
  /* the secant from x along the same step */
  SNESLineSearchReason why;
  PetscReal lambda;
  PetscCall(SNESLineSearchApply(s->ls2, X, F, &fnorm, Y));
  PetscCall(SNESLineSearchGetReason(s->ls2, &why));
  PetscCall(SNESLineSearchGetLambda(s->ls2, &lambda));
  PetscCall(SNESLineSearchGetNorms(s->ls2, &xnorm, &fnorm, &ynorm));
  PetscCall(SNESLineSearchSetReason(ls, why));
  PetscCall(SNESLineSearchSetLambda(ls, lambda));
  PetscCall(SNESLineSearchSetNorms(ls, xnorm, fnorm, ynorm));
  PetscFunctionReturn(0);
}

pm_err pm_newton_full_l2_create(pm_newton *s) {
  PM_PETSC_CALL(SNESLineSearchShellSetUserFunc(s->ls, full_then_secant, s));
  PM_PETSC_CALL(SNESLineSearchCreate(s->comm, &s->ls2));
  PM_PETSC_CALL(PetscObjectSetOptions((PetscObject)s->ls2, s->opts));
  PM_PETSC_CALL(SNESLineSearchSetSNES(s->ls2, s->snes));
  PM_PETSC_CALL(SNESLineSearchSetFunction(s->ls2, SNESComputeFunction));
  PM_PETSC_CALL(SNESLineSearchSetType(s->ls2, SNESLINESEARCHL2));
  PM_PETSC_CALL(SNESLineSearchSetTolerances(s->ls2, PETSC_DEFAULT, 1e300,
                                            PETSC_DEFAULT, PETSC_DEFAULT,
                                            PETSC_DEFAULT, PETSC_DEFAULT));
  return PM_SUCCESS;
}
