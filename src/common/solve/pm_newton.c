/* pm_newton: the Newton solve behind PETSc's SNES (its start, its end and
 * the report of how it ended), the tangent solve of a load step's
 * predictor, and the solver's options and accessors. */
#include "pm_newton.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <petscsnes.h>

#include "pm_newton_impl.h"
#include "pm_newton_solver_impl.h"
#include "pm_omp.h"
#include "pm_petsc.h"
#include "pm_progress.h"

pm_newton_options pm_newton_options_default(void) {
  return (pm_newton_options){.rtol = 1e-8,
                             .max_iter = 25,
                             .linear = PM_NEWTON_DIRECT,
                             .linear_rtol = 1e-10,
                             .linear_ew_max = 1e-2,
                             .linear_max_iter = 1000,
                             .op = PM_NEWTON_ASSEMBLED,
                             .pc_lag = 1,
                             .pc_reuse_cost = 4,
                             .coloring = PM_COLORING_LARGEST_FIRST,
                             .line_search = PM_LINE_SEARCH_BT,
                             .load_steps = 10,
                             .max_cuts = 10,
                             .grow_after = 2,
                             .relax_max_iter = 20000,
                             .relax_rtol = 1e-3};
}

const char *pm_newton_reason_name(pm_newton_reason r) {
  switch (r) {
  case PM_NEWTON_NOT_RUN: return "not run";
  case PM_NEWTON_CONVERGED_RESIDUAL: return "converged (residual)";
  case PM_NEWTON_CONVERGED_ABSOLUTE: return "converged (absolute residual)";
  case PM_NEWTON_CONVERGED_DISPLACEMENT: return "converged (displacement)";
  case PM_NEWTON_CONVERGED_ENERGY: return "converged (energy)";
  case PM_NEWTON_CONVERGED_ALL: return "converged (all criteria)";
  case PM_NEWTON_DIVERGED_MAX_ITER: return "diverged (max iterations)";
  case PM_NEWTON_DIVERGED_STALLED: return "diverged (stalled)";
  case PM_NEWTON_DIVERGED_LINE_SEARCH: return "diverged (line search)";
  case PM_NEWTON_DIVERGED_NAN: return "diverged (not a number)";
  case PM_NEWTON_DIVERGED_DOMAIN: return "diverged (inadmissible state)";
  case PM_NEWTON_DIVERGED_LINEAR: return "diverged (linear solver)";
  }
  return "unknown";
}

const pm_newton_problem *pm_newton_problem_of(const pm_newton *s) {
  return &s->p;
}
const pm_newton_options *pm_newton_options_of(const pm_newton *s) {
  return &s->o;
}
int pm_newton_colors(const pm_newton *s) { return s ? s->jcol.ncolors : 0; }
int pm_newton_pc_colors(const pm_newton *s) { return s ? s->pcol.ncolors : 0; }

/* The reason, status and message of a finished SNESSolve. */
static pm_err classify(pm_newton *s, pm_newton_report *rep) {
  SNESConvergedReason sr;
  PM_PETSC_CALL(SNESGetConvergedReason(s->snes, &sr));
  int it = rep->iterations;
  double r = it <= PM_NEWTON_MAX_ITER ? rep->residual_norm[it] : NAN;
  char figures[160];
  snprintf(figures, sizeof figures,
           "residual %.2e from %.2e; smallest cosine of dx and J dx "
           "%.2f",
           r, s->r0, rep->min_curvature);
  size_t cap = sizeof rep->message;
  if (sr > 0) {
    rep->reason = s->reason;
    rep->status = PM_SUCCESS;
    return PM_SUCCESS;
  }
  rep->status = PM_ERR_NOT_CONVERGED;
  switch (sr) {
  case SNES_DIVERGED_MAX_IT:
    if (s->reason == PM_NEWTON_DIVERGED_STALLED) {
      rep->reason = PM_NEWTON_DIVERGED_STALLED;
      snprintf(rep->message, cap,
               "Newton stalled: the residual was not halved over iterations "
               "%d and %d (%s)",
               it - 1, it, figures);
      break;
    }
    rep->reason = PM_NEWTON_DIVERGED_MAX_ITER;
    snprintf(rep->message, cap, "Newton did not converge in %d iterations (%s)",
             it, figures);
    break;
  case SNES_DIVERGED_FNORM_NAN:
    rep->reason = PM_NEWTON_DIVERGED_NAN;
    rep->status = PM_ERR_UNSTABLE;
    snprintf(rep->message, cap,
             "Newton: residual not finite after %d "
             "iterations",
             it);
    break;
  case SNES_DIVERGED_FUNCTION_DOMAIN:
    rep->reason = PM_NEWTON_DIVERGED_DOMAIN;
    rep->status = PM_ERR_UNSTABLE;
    if (!s->started)
      snprintf(rep->message, cap,
               "Newton: the initial state is inadmissible: %s", s->domain_msg);
    else
      snprintf(rep->message, cap,
               "Newton: no admissible step in iteration %d (%s): %s", it + 1,
               figures, s->domain_msg);
    break;
  case SNES_DIVERGED_LINEAR_SOLVE: {
    KSPConvergedReason kr;
    PetscInt kits;
    PM_PETSC_CALL(KSPGetConvergedReason(s->ksp, &kr));
    PM_PETSC_CALL(KSPGetIterationNumber(s->ksp, &kits));
    rep->reason = PM_NEWTON_DIVERGED_LINEAR;
    snprintf(rep->message, cap,
             "Newton: the linear solver failed in iteration %d: %s (%s) "
             "after %d linear iterations, linear residual %.2e from %.2e; %s",
             it + 1, pm_newton_linear_reason_words(kr), KSPConvergedReasons[kr],
             (int)kits, s->lin_r, s->lin_r0, figures);
    /* A failed factorisation is not redone by PETSc 3.18 (MUMPS keeps its
     * error): the next solve gets a new linear solver. */
    if (kr == KSP_DIVERGED_PC_FAILED) PM_CALL(pm_newton_replace_linear(s));
    break;
  }
  default:
    if (s->domain_last) {
      rep->reason = PM_NEWTON_DIVERGED_DOMAIN;
      rep->status = PM_ERR_UNSTABLE;
      snprintf(rep->message, cap,
               "Newton: no admissible step in iteration %d (%s): %s", it + 1,
               figures, s->domain_msg);
    } else {
      rep->reason = PM_NEWTON_DIVERGED_LINE_SEARCH;
      snprintf(rep->message, cap,
               "Newton: the line search found no step that decreases the "
               "residual in iteration %d (%s; SNES %s)",
               it + 1, figures, SNESConvergedReasons[sr]);
    }
  }
  return PM_SUCCESS;
}

pm_err pm_newton_solve_from(pm_newton *s, double *x, const double *x_start,
                            double r_ref, pm_newton_report *rep) {
  pm_err ret = PM_SUCCESS;
  long n = s->p.n;
  double t0 = pm_wtime();
  memset(rep, 0, sizeof *rep);
  s->rep = rep;
  s->reason = PM_NEWTON_NOT_RUN;
  s->hard = PM_SUCCESS;
  s->domain_last = false;
  s->domain_msg[0] = '\0';
  s->r0 = s->e0 = s->incr = s->energy = 0;
  s->ew_rprev = s->ew_eta = 0;
  s->r_ref = r_ref;
  s->jacobians = 0;
  s->in_linear = false;
  s->started = false;
  s->pc_stale = false;
  s->it_base = s->lin_base = 0;
  PM_TRY(pm_newton_copy_in(s->X, x, n));
  PM_TRY(pm_newton_copy_in(s->Xstart, x_start, n));
  PM_PETSC(VecCopy(s->X, s->Xacc));
  PetscErrorCode code;
  PetscInt its = 0, lits = 0;
  for (;;) {
    /* Objects PETSc creates inside the solve (the factor matrix, multigrid
     * levels) read the default options database: this solver's, for now. */
    PM_PETSC(PetscOptionsPush(s->opts));
    code = SNESSolve(s->snes, NULL, s->X);
    PetscOptionsPop();
    SNESGetIterationNumber(s->snes, &its);
    SNESGetLinearSolveIterations(s->snes, &lits);
    if (code || !s->pc_stale || s->hard != PM_SUCCESS) break;
    /* A linear solve stopped because the kept preconditioner cost more
     * than a new one: Newton goes on from its last iterate (the residual
     * reference kept) with a new one, the iterations counted on. */
    s->it_base += (int)its;
    s->lin_base += (int)lits + s->lin_its;
    s->r_ref = s->r0;
    PM_PETSC(VecCopy(s->Xacc, s->X));
  }
  rep->iterations = s->it_base + (int)its;
  rep->linear_iterations = s->lin_base + (int)lits;
  if (s->hard != PM_SUCCESS) {
    ret = pm_error_trace(s->hard, __FILE__, __LINE__, __func__,
                         "a callback of the Newton solve");
    rep->status = ret;
    snprintf(rep->message, sizeof rep->message, "%s", pm_error_message());
    goto done;
  }
  if (code && s->in_linear) {
    /* A numerical failure inside the linear solver that PETSc raises as an
     * error (an external solver's, a zero pivot) is a linear solver failure
     * like any other: the caller may cut the step, and the solver it left
     * half-way is replaced.  Other errors (bad options) are PETSc's. */
    PetscErrorCode cause;
    const char *what = pm_petsc_last_message(&cause);
    s->in_linear = false;
    rep->time_linear += pm_wtime() - s->linear_started;
    rep->cpu_linear += pm_cputime() - s->linear_started_cpu;
    if (cause != PETSC_ERR_LIB && cause != PETSC_ERR_MAT_LU_ZRPVT &&
        cause != PETSC_ERR_MAT_CH_ZRPVT && cause != PETSC_ERR_FP &&
        cause != PETSC_ERR_NOT_CONVERGED) {
      ret = PM_ERROR(PM_ERR_LINALG, "SNESSolve failed: %s", what);
      (void)pm_newton_replace_linear(s);
      goto done;
    }
    rep->reason = PM_NEWTON_DIVERGED_LINEAR;
    rep->status = PM_ERR_NOT_CONVERGED;
    snprintf(rep->message, sizeof rep->message,
             "Newton: the linear solver failed in iteration %d (%s)",
             rep->iterations + 1, what);
    PM_TRY(pm_newton_replace_linear(s));
    ret = PM_ERROR(rep->status, "%s", rep->message);
    goto done;
  }
  PM_PETSC(code);
  PM_TRY(classify(s, rep));
  if (rep->status != PM_SUCCESS)
    ret = PM_ERROR(rep->status, "%s", rep->message);
done:
  if (pm_newton_copy_out(s->Xacc, x, n) != PM_SUCCESS && ret == PM_SUCCESS)
    ret = pm_error_code();
  rep->time_total = pm_wtime() - t0;
  s->rep = NULL;
  return ret;
}

/* What a solve's Jacobian callback does, outside a solve: the Jacobian
 * at x (into s->X) made and given to the linear solver, with this
 * solver's PETSc options pushed (the caller pops them); PETSc's failure
 * into *code, a callback's into s->hard. */
static pm_err linearise_at(pm_newton *s, const double *x,
                           PetscErrorCode *code) {
  Mat A, B;
  pm_newton_operators(s, &A, &B);
  s->hard = PM_SUCCESS;
  s->jacobians = 0;
  PM_CALL(pm_newton_copy_in(s->X, x, s->p.n));
  PM_PETSC_CALL(PetscOptionsPush(s->opts));
  *code = pm_newton_snes_jacobian(s->snes, s->X, A, B, s);
  if (!*code) *code = KSPSetOperators(s->ksp, A, B);
  return PM_SUCCESS;
}

pm_err pm_newton_tangent_solve(pm_newton *s, const double *x, const double *b,
                               double *dx, pm_newton_report *rep) {
  pm_err ret = PM_SUCCESS;
  long n = s->p.n;
  KSPConvergedReason kr;
  PetscErrorCode code;
  s->rep = rep;
  PM_TRY(pm_newton_copy_in(s->Work, b, n));
  s->pc_stale = false;
  for (int pass = 0; pass < 2; pass++) {
    /* (a second pass on a new preconditioner when the kept one was
     * spent) */
    PM_TRY(linearise_at(s, x, &code));
    if (!code) {
      code = KSPSolve(s->ksp, s->Work, s->R); /* (its presolve times it) */
      if (s->in_linear) pm_newton_linear_postsolve(s->ksp, s->Work, s->R, s);
    }
    PetscOptionsPop();
    if (code || !s->pc_stale || s->hard != PM_SUCCESS) break;
  }
  if (s->hard != PM_SUCCESS) {
    ret = pm_error_trace(s->hard, __FILE__, __LINE__, __func__,
                         "the tangent of a load step's predictor");
    goto done;
  }
  if (code) {
    /* A failed factorisation leaves the solver unusable: replace it. */
    PetscErrorCode cause;
    const char *what = pm_petsc_last_message(&cause);
    ret = PM_ERROR(PM_ERR_NOT_CONVERGED, "the predictor's linear solve: %s",
                   what);
    (void)pm_newton_replace_linear(s);
    goto done;
  }
  PM_PETSC(KSPGetConvergedReason(s->ksp, &kr));
  if (kr < 0) {
    ret = PM_ERROR(PM_ERR_NOT_CONVERGED, "the predictor's linear solve: %s",
                   KSPConvergedReasons[kr]);
    if (kr == KSP_DIVERGED_PC_FAILED) (void)pm_newton_replace_linear(s);
    goto done;
  }
  PM_TRY(pm_newton_copy_out(s->R, dx, n));
done:
  s->rep = NULL;
  return ret;
}

pm_err pm_newton_solve(pm_newton *s, double *x, pm_newton_report *report) {
  pm_newton_report local;
  PM_CHECK(s && x, PM_ERR_ARG, "pm_newton_solve: solver and x are required");
  return pm_newton_solve_from(s, x, x, 0, report ? report : &local);
}

pm_err pm_newton_pc_rebuild(pm_newton *s, const pm_load_state *st) {
  pm_err ret = PM_SUCCESS;
  PetscErrorCode code;
  s->rep = NULL;
  s->pc_built = false; /* the Jacobian below builds a new one */
  /* as in a solve: the Jacobian's values at x, then the linear solver's
   * set-up (the factorisation of B, or of the augmented matrix) */
  PM_TRY(linearise_at(s, st->pc_x, &code));
  const int blas = pm_blas_widen();
  if (!code) code = KSPSetUp(s->ksp);
  if (!code) code = KSPSetUpOnBlocks(s->ksp);
  if (!code) code = pm_newton_aug_factor(s);
  pm_blas_restore(blas);
  PetscOptionsPop();
  if (s->hard != PM_SUCCESS) {
    ret = pm_error_trace(s->hard, __FILE__, __LINE__, __func__,
                         "the kept factorisation of a resumed run");
    goto done;
  }
  if (code) {
    PetscErrorCode cause;
    ret = PM_ERROR(PM_ERR_LINALG,
                   "the kept factorisation of a resumed run, made again: %s",
                   pm_petsc_last_message(&cause));
    goto done;
  }
  s->lin_its = (int)st->pc_its;
  s->lin_failed = st->pc_failed != 0;
  s->pc_pending = false; /* set up above; the next solve is not its first */
  s->pc_budget = pm_newton_pc_budget(s);
  s->pc_first_its = (int)st->pc_first_its;
done:
  return ret;
}
