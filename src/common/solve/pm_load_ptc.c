/* pm_load_ptc: pseudo-transient continuation within a load step, the
 * fallback of load stepping where Newton cannot finish a step: Newton on
 * the tangent shifted by the relaxation's masses over a pseudo time step
 * that grows as the residual falls (switched evolution relaxation). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pm_interrupt.h"
#include "pm_newton_impl.h"
#include "pm_newton_solver_impl.h"
#include "pm_omp.h"
#include "pm_petsc.h"
#include "pm_progress.h"

/* The first shift 1 / dtau is PM_PTC_SHIFT0 (pm_newton_impl.h), in units
 * of the masses (whose Gershgorin bound puts every frequency of M^-1 K at
 * most 2): small enough that the stiff modes settle in a few iterations,
 * large enough to dominate a tangent's small negative eigenvalues; a
 * caller that knows the lowest eigenvalue passes one above it. */
/* The factorisation kept while the shift stays within this factor of the
 * one it was made at (beyond, GMRES on it takes hundreds of iterations). */
#define PTC_REFACTOR 2.0
/* A trial that multiplies the residual by more than this is not taken. */
#define PTC_GROWTH 10.0
/* A shift raised past this (by rejected trials) ends the continuation. */
#define PTC_SHIFT_MAX 1e6

/* The linear solve (J(x) + diag(shift m)) dx = -r. */
/* A new factorisation when shift is not within PTC_REFACTOR of *made, the
 * shift the kept one was made at (0: none kept), which it then updates. */
static pm_err shifted_solve(pm_newton *s, const double *x, const double *r,
                            const double *m, double shift, double *made,
                            double *b, double *dx, pm_load_report *rep) {
  const long n = s->p.n;
  if (!(*made > 0 && shift <= PTC_REFACTOR * *made &&
        shift * PTC_REFACTOR >= *made) ||
      !s->pc_built) {
    s->pc_built = false;
    *made = shift;
  }
  double *d;
  PM_PETSC_CALL(VecGetArray(s->Shift, &d));
  for (long i = 0; i < n; i++) d[i] = shift * m[i];
  PM_PETSC_CALL(VecRestoreArray(s->Shift, &d));
  for (long i = 0; i < n; i++) b[i] = -r[i];
  pm_newton_report tr;
  memset(&tr, 0, sizeof tr);
  s->shifted = true;
  pm_err e = pm_newton_tangent_solve(s, x, b, dx, &tr);
  s->shifted = false;
  pm_load_add_costs(rep, &tr);
  return e;
}

pm_err pm_load_ptc(pm_newton *s, double *x, double goal, double shift0,
                   pm_relax_work *w, pm_load_report *rep, double *r_start,
                   double *curvature, char *msg, long cap) {
  const long n = s->p.n;
  const long max_iter = s->o.ptc_max_iter;
  const double t0 = pm_wtime(), cpu0 = pm_cputime();
  /* (the relaxation's work space: its velocities hold the increment) */
  double *m = w->mass, *dx = w->v, *r = w->r, *rt = w->rt, *xt = w->xt;
  double rn = 0, r0 = 0, qmin = INFINITY, made = 0;
  double shift = shift0 > 0 ? shift0 : PM_PTC_SHIFT0;
  long it = 0, rejected = 0;
  bool timed = false;
  pm_err e;
  msg[0] = '\0';
  PM_CHECK(!s->dist && s->Shift, PM_ERR_UNSUPPORTED,
           "continuation: one process's problems only");
  rep->ptc_runs++;
  if ((e = pm_relax_residual(s, x, r, &r0)) != PM_SUCCESS) goto out;
  if ((e = pm_relax_masses(s, x, m)) != PM_SUCCESS) goto out;
  *r_start = r0;
  rn = r0;
  while (rn > goal && it < max_iter) {
    it++;
    if ((e = pm_interrupt_check("in the continuation of a load step")) !=
        PM_SUCCESS)
      goto out;
    if (pm_load_out_of_time(s, cpu0, rep)) {
      timed = true;
      it--;
      break;
    }
    e = shifted_solve(s, x, r, m, shift, &made, rt, dx, rep);
    double rtn = 0;
    if (e == PM_SUCCESS) {
      /* dx.J dx = -dx.r - shift dx.M dx: the curvature along dx */
      double dr = 0, dm = 0;
      PM_OMP(parallel for schedule(static) reduction(+ : dr, dm))
      for (long i = 0; i < n; i++) {
        dr += dx[i] * r[i];
        dm += m[i] * dx[i] * dx[i];
      }
      if (dm > 0) qmin = fmin(qmin, (-dr - shift * dm) / dm);
      PM_OMP(parallel for schedule(static))
      for (long i = 0; i < n; i++) xt[i] = x[i] + dx[i];
      e = pm_relax_residual(s, xt, rt, &rtn);
      if (e == PM_SUCCESS && rtn > PTC_GROWTH * rn)
        e = PM_ERROR(PM_ERR_NOT_CONVERGED, "residual grew %.3g times",
                     rtn / rn);
    }
    if (e != PM_SUCCESS) {
      if (pm_newton_hard_failure(e)) goto out;
      /* Inadmissible, diverging or not solved: not taken; a shorter
       * pseudo time step. */
      pm_error_clear();
      rejected++;
      shift *= 4;
      if (shift > PTC_SHIFT_MAX) {
        e = PM_ERROR(PM_ERR_UNSTABLE,
                     "continuation: no acceptable increment after %ld "
                     "iterations (shift raised to %.1e)",
                     it, shift);
        goto out;
      }
      continue;
    }
    /* switched evolution relaxation: dtau grows as |r| falls */
    shift *= rtn / rn;
    memcpy(x, xt, (size_t)n * sizeof *x);
    memcpy(r, rt, (size_t)n * sizeof *r);
    rn = rtn;
  }
  e = rn <= goal ? PM_SUCCESS : PM_ERR_NOT_CONVERGED;
out:;
  /* the kept factorisation is of a shifted matrix: Newton makes its own */
  s->pc_built = false;
  char tail[128];
  snprintf(tail, sizeof tail, "%ld not taken, smallest curvature %.2e%s",
           rejected, isfinite(qmin) ? qmin : 0.0,
           timed ? "; stopped at its fallback_seconds" : "");
  e = pm_relax_outcome(e, "continuation", rn, r0, goal, it, tail, msg, cap);
  *curvature = isfinite(qmin) ? qmin : 0;
  rep->ptc_iterations += it;
  rep->time_ptc += pm_wtime() - t0;
  return e;
}
