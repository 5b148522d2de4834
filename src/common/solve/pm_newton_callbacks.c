/* pm_newton_callbacks: what SNES calls of the problem: the residual (with
 * inadmissible states and residuals not finite as domain errors), the Jacobian
 * (assembled or as a shell), the line search's precheck and the linear solver's
 * timing. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <petscsnes.h>

#include "pm_newton_solver_impl.h"
#include "pm_omp.h"
#include "pm_progress.h"

PetscErrorCode pm_newton_snes_residual(SNES snes, Vec X, Vec R, void *ctx) {
  pm_newton *s = ctx;
  const double *x;
  double *r;
  Vec xl, rl;
  PetscFunctionBeginUser;
  double t = pm_wtime(), tc = pm_cputime();
  PetscCall(pm_newton_in_get(s, X, s->Gx, &xl, &x));
  PetscCall(pm_newton_out_get(s, R, s->Gr, &rl, &r));
  pm_err e = s->p.residual(s->p.ctx, x, r);
  /* A residual that is not finite (a stress the model cannot evaluate) is
   * an inadmissible state like an inverted point: the line search
   * shortens the step. */
  const long held = s->dist ? s->nloc : s->p.n;
  for (long i = 0; i < held && e == PM_SUCCESS; i++)
    if (!isfinite(r[i]))
      e = PM_ERROR(PM_ERR_UNSTABLE, "residual not finite at unknown %ld", i);
  e = pm_newton_agreed(s, e);
  PetscCall(pm_newton_out_done(s, R, s->Gr, &rl, &r, e == PM_SUCCESS));
  PetscCall(pm_newton_in_done(s, s->Gx, &xl, &x));
  if (s->rep) {
    s->rep->time_residual += pm_wtime() - t;
    s->rep->cpu_residual += pm_cputime() - tc;
    s->rep->residual_evaluations++;
  }
  s->domain_last = e != PM_SUCCESS;
  if (e == PM_SUCCESS) PetscFunctionReturn(0);
  if (pm_newton_hard_failure(e)) {
    s->hard = e;
    SETERRQ(s->comm, PETSC_ERR_USER, "residual callback failed: %s",
            pm_error_message());
  }
  snprintf(s->domain_msg, sizeof s->domain_msg, "%s",
           pm_error_code() == e ? pm_error_message() : pm_err_string(e));
  pm_error_clear();
  PetscCall(SNESSetFunctionDomainError(snes));
  PetscFunctionReturn(0);
}

/* Pseudo-transient continuation's shift added to the diagonal of the
 * matrix factorised: B's, or the augmented matrix's first n rows. */
static PetscErrorCode add_shift(pm_newton *s, Mat B) {
  PetscFunctionBeginUser;
  if (!pm_newton_aug_on(s)) {
    PetscCall(MatDiagonalSet(B, s->Shift, ADD_VALUES));
    PetscFunctionReturn(0);
  }
  const double *d;
  PetscCall(VecGetArrayRead(s->Shift, &d));
  PetscErrorCode code = pm_newton_aug_shift(s, d);
  PetscCall(VecRestoreArrayRead(s->Shift, &d));
  PetscCall(code);
  PetscFunctionReturn(0);
}

PetscErrorCode pm_newton_snes_jacobian(SNES snes, Vec X, Mat A, Mat B,
                                       void *ctx) {
  pm_newton *s = ctx;
  const double *x;
  Vec xl;
  (void)snes;
  (void)A;
  PetscFunctionBeginUser;
  double t = pm_wtime(), tc = pm_cputime();
  PetscCall(VecCopy(X, s->Xlin));
  PetscCall(pm_newton_in_get(s, X, s->Glin, &xl, &x));
  pm_err e = PM_SUCCESS;
  if (s->p.jacobian_prepare)
    e = pm_newton_agreed(s, s->p.jacobian_prepare(s->p.ctx, x));
  /* A preconditioner matrix left unchanged keeps its factorisation: PETSc
   * sets a PC up again only when the matrix's state has changed. */
  bool rebuild =
      s->o.op == PM_NEWTON_ASSEMBLED || s->jacobians % s->o.pc_lag == 0;
  bool new_pc = rebuild;
  if (s->o.pc_reuse_its > 0) {
    /* a new preconditioner when the kept one has stopped paying; an
     * assembled Jacobian is the operator: its values are always new */
    new_pc = !s->pc_built || s->lin_failed || s->lin_its > s->o.pc_reuse_its ||
             s->pc_stale;
    rebuild = new_pc || s->o.op == PM_NEWTON_ASSEMBLED;
    if (new_pc) {
      s->pc_pending = true;
      s->pc_stale = false;
      s->pc_built = true;
      s->pc_load = s->load;
      PetscCall(VecCopy(X, s->Xpc));
    }
    PetscCall(
        KSPSetReusePreconditioner(s->ksp, new_pc ? PETSC_FALSE : PETSC_TRUE));
    PetscCall(SNESSetLagPreconditioner(s->snes, new_pc ? 1 : -1));
  }
  s->jacobians++;
  if (new_pc && s->rep) s->rep->pc_setups++;
  if (e == PM_SUCCESS && rebuild) {
    if (pm_newton_aug_on(s)) {
      e = pm_newton_agreed(s, pm_newton_aug_values(s, x));
    } else if (s->o.op == PM_NEWTON_MATRIX_FREE_CHEAP_PC) {
      e = pm_newton_fill(s, B, &s->ppat, s->pcols, s->pvals,
                         pm_newton_precond_values, x);
    } else if (s->dist) {
      e = pm_newton_agreed(s, pm_newton_values_at(s, x, s->jvals));
      if (e == PM_SUCCESS)
        e = pm_newton_insert_values(s, B, &s->jpat, s->jcols, s->jvals);
    } else {
      e = pm_newton_fill(s, B, &s->jpat, s->jcols, s->jvals,
                         pm_newton_values_at, x);
    }
    /* pseudo-transient continuation: the shift in the matrix factorised
     * (and, assembled, multiplied by) */
    if (e == PM_SUCCESS && s->shifted) PetscCall(add_shift(s, B));
    s->fine_stale = true; /* the finest level's copy (pm_newton_fine.c) */
  }
  e = pm_newton_agreed(s, e);
  PetscCall(pm_newton_in_done(s, s->Glin, &xl, &x));
  if (s->rep) {
    s->rep->time_assembly += pm_wtime() - t;
    s->rep->cpu_assembly += pm_cputime() - tc;
    s->rep->jacobians++;
  }
  if (e != PM_SUCCESS) {
    s->hard = e;
    SETERRQ(s->comm, PETSC_ERR_USER, "Jacobian callback failed: %s",
            pm_error_message());
  }
  PetscFunctionReturn(0);
}

PetscErrorCode pm_newton_shell_mult(Mat A, Vec in, Vec out) {
  pm_newton *s;
  const double *x, *dx;
  double *dr;
  Vec xl, dxl, drl;
  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &s));
  const double t = pm_wtime(), tc = pm_cputime();
  /* The linearisation point's held values are Glin's since the Jacobian
   * was made there. */
  xl = s->Xlin;
  if (s->dist) PetscCall(VecGhostGetLocalForm(s->Glin, &xl));
  PetscCall(VecGetArrayRead(xl, &x));
  PetscCall(pm_newton_in_get(s, in, s->Gdx, &dxl, &dx));
  PetscCall(pm_newton_out_get(s, out, s->Gdr, &drl, &dr));
  pm_err e = pm_newton_agreed(s, s->p.jacobian_apply(s->p.ctx, x, dx, dr));
  PetscCall(pm_newton_out_done(s, out, s->Gdr, &drl, &dr, e == PM_SUCCESS));
  PetscCall(pm_newton_in_done(s, s->Gdx, &dxl, &dx));
  if (s->shifted && e == PM_SUCCESS) { /* pseudo-transient continuation */
    PetscCall(VecPointwiseMult(s->ShiftWork, s->Shift, in));
    PetscCall(VecAXPY(out, 1.0, s->ShiftWork));
  }
  PetscCall(VecRestoreArrayRead(xl, &x));
  if (s->dist) PetscCall(VecGhostRestoreLocalForm(s->Glin, &xl));
  if (s->rep) {
    s->rep->jacobian_applications++;
    s->rep->time_apply += pm_wtime() - t;
    s->rep->cpu_apply += pm_cputime() - tc;
  }
  if (e != PM_SUCCESS) {
    s->hard = e;
    SETERRQ(s->comm, PETSC_ERR_USER, "jacobian_apply failed: %s",
            pm_error_message());
  }
  PetscFunctionReturn(0);
}

/* The Newton direction before the line search scales it: SNES's Y solves
 * J Y = r, so dx = -Y. */
PetscErrorCode pm_newton_precheck(SNESLineSearch ls, Vec X, Vec Y,
                                  PetscBool *changed, void *ctx) {
  pm_newton *s = ctx;
  Vec F;
  PetscReal dot;
  (void)ls;
  (void)X;
  PetscFunctionBeginUser;
  *changed = PETSC_FALSE;
  PetscCall(SNESGetFunction(s->snes, &F, NULL, NULL));
  PetscCall(VecNorm(Y, NORM_2, &s->incr));
  PetscCall(VecDot(Y, F, &dot));
  s->energy = fabs(dot);
  /* dx = -Y, J dx = -r: dx.J dx / (|dx| |J dx|) = Y.r / (|Y| |r|) */
  PetscReal rn;
  PetscCall(VecNorm(F, NORM_2, &rn));
  if (s->rep && s->incr > 0 && rn > 0) {
    const double q = dot / (s->incr * rn);
    if (s->rep->min_curvature == 0 || q < s->rep->min_curvature)
      s->rep->min_curvature = q;
  }
  PetscFunctionReturn(0);
}

/* linear_ew: the forcing term of the linear solve whose right-hand side
 * has norm rk (pm_newton.h, linear_ew). */
static double forcing_term(pm_newton *s, double rk) {
  const pm_newton_options *o = &s->o;
  double eta = o->linear_ew_max;
  if (s->ew_rprev > 0) {
    const double q = rk / s->ew_rprev, safe = 0.9 * s->ew_eta * s->ew_eta;
    eta = 0.9 * q * q;
    if (safe > 0.1 && safe > eta) eta = safe;
    if (eta > o->linear_ew_max) eta = o->linear_ew_max;
  }
  /* no tighter than the last Newton iteration needs */
  const double target = fmax(o->rtol * s->r0, o->atol);
  if (rk > 0 && eta < 0.5 * target / rk) eta = 0.5 * target / rk;
  if (eta > o->linear_ew_max) eta = o->linear_ew_max;
  if (eta < o->linear_rtol) eta = o->linear_rtol;
  s->ew_rprev = rk;
  s->ew_eta = eta;
  return eta;
}

PetscErrorCode pm_newton_linear_presolve(KSP ksp, Vec b, Vec x, void *ctx) {
  pm_newton *s = ctx;
  (void)x;
  const bool capped = s->lin_cap > 0 && s->lin_cap < s->o.linear_max_iter;
  const PetscInt max_it = capped ? s->lin_cap : s->o.linear_max_iter;
  if (s->o.linear_ew) {
    PetscReal rk;
    PetscCall(VecNorm(b, NORM_2, &rk));
    PetscCall(KSPSetTolerances(ksp, forcing_term(s, rk), PETSC_DEFAULT,
                               PETSC_DEFAULT, max_it));
  } else if (capped || s->lin_capped) {
    /* the cap set or lifted, the tolerances kept */
    PetscReal rtol, abstol, dtol;
    PetscInt was;
    PetscCall(KSPGetTolerances(ksp, &rtol, &abstol, &dtol, &was));
    PetscCall(KSPSetTolerances(ksp, rtol, abstol, dtol, max_it));
  }
  s->lin_capped = capped;
  s->linear_started = pm_wtime();
  s->linear_started_cpu = pm_cputime();
  s->in_linear = true;
  /* The preconditioner's set-up (a factorisation, a multigrid hierarchy)
   * now, to time it apart; KSPSolve's own set-up then finds it done. */
  const int blas = pm_blas_widen(); /* the factorisation on every core */
  PetscErrorCode code = KSPSetUp(ksp);
  if (!code) code = KSPSetUpOnBlocks(ksp);
  if (!code) code = pm_newton_fine_attach(s, ksp);
  if (!code) code = pm_newton_aug_factor(s);
  pm_blas_restore(blas);
  PetscCall(code);
  if (s->rep) {
    s->rep->time_setup += pm_wtime() - s->linear_started;
    s->rep->cpu_setup += pm_cputime() - s->linear_started_cpu;
  }
  s->pc_fresh = s->pc_pending;
  if (s->pc_pending) {
    s->pc_pending = false;
    s->pc_first_its = -1;
    s->pc_budget = pm_newton_pc_budget(s);
  }
  return 0;
}

int pm_newton_pc_budget(const pm_newton *s) {
  /* An iteration count, the same on every rank and in every run (a timed
   * cost would let two runs of one scene decide differently). */
  if (s->o.pc_reuse_its <= 0 || s->o.pc_reuse_cost <= 0) return 0;
  return (int)fmin(ceil(s->o.pc_reuse_cost * s->o.pc_reuse_its),
                   s->o.linear_max_iter);
}

/* pc_reuse_cost: the iterations of the first linear solve on a new
 * preconditioner. */
static void note_reuse(pm_newton *s, int its) {
  if (s->pc_fresh) s->pc_first_its = its;
}

bool pm_newton_pc_spent(const pm_newton *s, int it) {
  return s->o.pc_reuse_its > 0 && s->o.pc_reuse_cost > 0 && !s->pc_fresh &&
         s->pc_budget > 0 && s->pc_first_its >= 0 &&
         it - s->pc_first_its > s->pc_budget;
}

PetscErrorCode pm_newton_linear_postsolve(KSP ksp, Vec b, Vec x, void *ctx) {
  pm_newton *s = ctx;
  (void)ksp;
  (void)b;
  (void)x;
  if (s->rep) {
    s->rep->time_linear += pm_wtime() - s->linear_started;
    s->rep->cpu_linear += pm_cputime() - s->linear_started_cpu;
  }
  s->in_linear = false;
  PetscInt its;
  KSPConvergedReason why;
  PetscCall(KSPGetIterationNumber(ksp, &its));
  PetscCall(KSPGetConvergedReason(ksp, &why));
  s->lin_its = (int)its;
  s->lin_failed = why < 0;
  /* A kept preconditioner the solve failed on (its iteration limit, a
   * breakdown) is spent too: the solve is made again on a new one rather
   * than failing Newton (and cutting a load step) for a stale one. */
  if (why < 0 && why != KSP_DIVERGED_PC_FAILED && !s->pc_fresh &&
      s->o.pc_reuse_its > 0 && s->o.pc_reuse_cost > 0 &&
      !pm_newton_stop_signal(s))
    s->pc_stale = true;
  if (!s->pc_stale) note_reuse(s, (int)its);
  return 0;
}
