/* pm_newton_convergence: the convergence test SNES calls after each
 * iteration: the residual, displacement and energy criteria, stalling and
 * the iteration limit. */
#include <math.h>

#include <petscsnes.h>

#include "pm_newton_solver_impl.h"

/* The linear iterations of this solve so far (a solve made again from its
 * last iterate counts on). */
static long linear_so_far(const pm_newton *s, SNES snes) {
  PetscInt lits = 0;
  if (SNESGetLinearSolveIterations(snes, &lits)) return 0;
  return (long)s->lin_base + (long)lits;
}

/* Called with the state after `it` iterations (accepted by the line
 * search). */
PetscErrorCode pm_newton_converged_test(SNES snes, PetscInt it, PetscReal xnorm,
                                        PetscReal snorm, PetscReal fnorm,
                                        SNESConvergedReason *reason,
                                        void *ctx) {
  pm_newton *s = ctx;
  pm_newton_report *rep = s->rep;
  const pm_newton_options *o = &s->o;
  Vec X;
  (void)xnorm;
  (void)snorm;
  PetscFunctionBeginUser;
  *reason = SNES_CONVERGED_ITERATING;
  const PetscInt it_snes = it;
  /* (a solve made again from its last iterate counts on) */
  it += s->it_base;
  if (it <= PM_NEWTON_MAX_ITER) rep->residual_norm[it] = fnorm;
  if (!isfinite(fnorm)) {
    s->reason = PM_NEWTON_DIVERGED_NAN;
    *reason = SNES_DIVERGED_FNORM_NAN;
    PetscFunctionReturn(0);
  }
  PetscCall(SNESGetSolution(snes, &X));
  PetscCall(VecCopy(X, s->Xacc));
  if (it_snes == 0) {
    s->started = true;
    s->r0 = fmax(fnorm, s->r_ref);
    if (fnorm <= o->atol || fnorm == 0) {
      s->reason = PM_NEWTON_CONVERGED_ABSOLUTE;
      *reason = SNES_CONVERGED_FNORM_ABS;
    }
    PetscFunctionReturn(0);
  }
  PetscReal alpha = 0;
  PetscCall(SNESLineSearchGetLambda(s->ls, &alpha));
  if (it <= PM_NEWTON_MAX_ITER) {
    rep->increment_norm[it] = s->incr;
    rep->energy[it] = s->energy;
    rep->step_length[it] = alpha;
  }
  if (it == 1) s->e0 = s->energy;

  bool on[3] = {o->rtol > 0, o->dtol > 0, o->etol > 0};
  bool met[3] = {false, false, false};
  met[0] = on[0] && fnorm <= o->rtol * s->r0;
  if (on[1]) {
    PetscReal travel;
    PetscCall(VecWAXPY(s->Work, -1.0, s->Xstart, X));
    PetscCall(VecNorm(s->Work, NORM_2, &travel));
    met[1] = s->incr <= o->dtol * travel;
  }
  met[2] = on[2] && s->energy <= o->etol * s->e0;
  static const pm_newton_reason which[3] = {PM_NEWTON_CONVERGED_RESIDUAL,
                                            PM_NEWTON_CONVERGED_DISPLACEMENT,
                                            PM_NEWTON_CONVERGED_ENERGY};
  int count_on = 0, count_met = 0, first = -1;
  for (int c = 0; c < 3; c++) {
    count_on += on[c];
    count_met += met[c];
    if (met[c] && first < 0) first = c;
  }
  if (fnorm <= o->atol) {
    s->reason = PM_NEWTON_CONVERGED_ABSOLUTE;
  } else if (o->all_criteria ? count_on > 0 && count_met == count_on
                             : count_met > 0) {
    s->reason = o->all_criteria && count_on > 1 ? PM_NEWTON_CONVERGED_ALL
                                                : which[first];
  } else if (it >= o->max_iter) {
    s->reason = PM_NEWTON_DIVERGED_MAX_ITER;
    *reason = SNES_DIVERGED_MAX_IT;
    PetscFunctionReturn(0);
  } else if (it >= 2 && it <= PM_NEWTON_MAX_ITER &&
             fnorm > 0.5 * rep->residual_norm[it - 2] &&
             ((o->stall_after > 0 && it >= o->stall_after) ||
              (o->stall_linear > 0 &&
               linear_so_far(s, snes) > o->stall_linear))) {
    s->reason = PM_NEWTON_DIVERGED_STALLED;
    *reason = SNES_DIVERGED_MAX_IT;
    PetscFunctionReturn(0);
  } else {
    PetscFunctionReturn(0);
  }
  *reason = s->reason == PM_NEWTON_CONVERGED_ABSOLUTE
                ? SNES_CONVERGED_FNORM_ABS
                : SNES_CONVERGED_FNORM_RELATIVE;
  PetscFunctionReturn(0);
}
