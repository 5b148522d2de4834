/* pm_load_relax: dynamic relaxation within a load step, the fallback of
 * load stepping where Newton cannot finish a step: damped pseudo-dynamics
 * on the residual with a mass per unknown from the tangent's row sums. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_interrupt.h"
#include "pm_newton_impl.h"
#include "pm_newton_solver_impl.h"
#include "pm_omp.h"
#include "pm_progress.h"

/* A mass raised this many times over (by inadmissible increments or a
 * stiffer response than the tangent's at the start) ends the relaxation. */
#define RELAX_MAX_SCALE 1e8
/* The largest squared frequency, in units of the pseudo-time step, a mass
 * is allowed: the central difference is stable up to 4. */
#define RELAX_MAX_OMEGA2 1.0

pm_err pm_relax_work_init(pm_relax_work *w, long n) {
  memset(w, 0, sizeof *w);
  pm_err ret = PM_SUCCESS;
  PM_TRY(PM_ALLOC(w->mass, n, "relaxation masses"));
  PM_TRY(PM_ALLOC(w->v, n, "relaxation velocities"));
  PM_TRY(PM_ALLOC(w->r, n, "relaxation residual"));
  PM_TRY(PM_ALLOC(w->rt, n, "relaxation residual"));
  PM_TRY(PM_ALLOC(w->xt, n, "relaxation state"));
  PM_TRY(PM_ALLOC(w->mode, n, "lowest mode"));
done:
  if (ret != PM_SUCCESS) pm_relax_work_free(w);
  return ret;
}

void pm_relax_work_free(pm_relax_work *w) {
  free(w->mass);
  free(w->v);
  free(w->r);
  free(w->rt);
  free(w->xt);
  free(w->mode);
  memset(w, 0, sizeof *w);
}

pm_err pm_relax_masses(pm_newton *s, const double *x, double *m) {
  const long n = s->p.n;
  if (s->p.jacobian_prepare) PM_CALL(s->p.jacobian_prepare(s->p.ctx, x));
  double *vals;
  PM_CALL(pm_newton_jvals(s, &vals));
  PM_CALL(pm_newton_values_at(s, x, vals));
  double top = 0;
  for (long i = 0; i < n; i++) {
    double sum = 0;
    for (long k = s->jpat.ptr[i]; k < s->jpat.ptr[i + 1]; k++)
      sum += fabs(vals[k]);
    m[i] = 0.5 * sum;
    top = fmax(top, m[i]);
  }
  PM_CHECK(top > 0 && isfinite(top), PM_ERR_UNSTABLE,
           "relaxation: the tangent is zero or not finite");
  for (long i = 0; i < n; i++)
    if (!(m[i] > 1e-12 * top)) m[i] = top;
  return PM_SUCCESS;
}

pm_err pm_relax_residual(pm_newton *s, const double *x, double *r,
                         double *norm) {
  pm_err e = pm_newton_residual(s, x, r);
  if (e != PM_SUCCESS) return e;
  *norm = pm_newton_norm(s, r);
  if (!isfinite(*norm)) return PM_ERROR(PM_ERR_UNSTABLE, "residual not finite");
  return PM_SUCCESS;
}

pm_err pm_relax_outcome(pm_err e, const char *what, double rn, double r0,
                        double goal, long it, const char *tail, char *msg,
                        long cap) {
  if (e == PM_SUCCESS || e == PM_ERR_NOT_CONVERGED)
    snprintf(msg, (size_t)cap,
             "%s %s: residual %.2e from %.2e (goal %.2e) in %ld iterations, "
             "%s",
             what,
             e == PM_SUCCESS ? "reached its goal" : "did not reach its goal",
             rn, r0, goal, it, tail);
  else if (!pm_newton_hard_failure(e))
    snprintf(msg, (size_t)cap, "%s failed after %ld iterations: %s", what, it,
             pm_error_message());
  return e == PM_ERR_NOT_CONVERGED ? PM_ERROR(e, "%s", msg) : e;
}

bool pm_load_out_of_time(const pm_newton *s, double cpu0, pm_load_report *rep) {
  if (!(s->o.fallback_seconds > 0 &&
        pm_cputime() - cpu0 > s->o.fallback_seconds))
    return false;
  rep->fallbacks_timed_out++;
  return true;
}

bool pm_load_relax_available(const pm_newton *s) {
  return s->o.relax_after > 0 && !s->dist;
}

pm_err pm_load_relax(pm_newton *s, double *x, double rel, double goal,
                     pm_relax_work *w, pm_load_report *rep, double *r_start,
                     char *msg, long cap) {
  const long n = s->p.n;
  const long max_iter = s->o.relax_max_iter;
  const double t0 = pm_wtime(), cpu0 = pm_cputime();
  double *m = w->mass, *v = w->v, *r = w->r, *rt = w->rt, *xt = w->xt;
  double rn = 0, r0 = 0, c = 0, scale = 1;
  long it = 0, rejected = 0;
  bool timed = false;
  pm_err e;
  msg[0] = '\0';
  PM_CHECK(!s->dist, PM_ERR_UNSUPPORTED,
           "relaxation: one process's problems only");
  rep->relaxations++;
  if ((e = pm_relax_residual(s, x, r, &r0)) != PM_SUCCESS) goto out;
  if ((e = pm_relax_masses(s, x, m)) != PM_SUCCESS) goto out;
  *r_start = r0;
  goal = fmax(goal, rel * r0);
  rn = r0;
  memset(v, 0, (size_t)n * sizeof *v);
  while (rn > goal && it < max_iter) {
    it++;
    if ((e = pm_interrupt_check("in the relaxation of a load step")) !=
        PM_SUCCESS)
      goto out;
    if (pm_load_out_of_time(s, cpu0, rep)) {
      timed = true;
      it--;
      break;
    }
    /* v at the half step, damped by c (central difference, unit step) */
    const double keep = (1 - 0.5 * c) / (1 + 0.5 * c), push = 1 / (1 + 0.5 * c);
    PM_OMP(parallel for schedule(static))
    for (long i = 0; i < n; i++) {
      v[i] = keep * v[i] - push * r[i] / (scale * m[i]);
      xt[i] = x[i] + v[i];
    }
    double rtn = 0;
    e = pm_relax_residual(s, xt, rt, &rtn);
    if (e != PM_SUCCESS) {
      if (pm_newton_hard_failure(e)) goto out;
      /* Inadmissible: the increment is not taken; heavier masses, at rest. */
      pm_error_clear();
      rejected++;
      scale *= 4;
      memset(v, 0, (size_t)n * sizeof *v);
      if (scale > RELAX_MAX_SCALE) {
        e = PM_ERROR(PM_ERR_UNSTABLE,
                     "relaxation: no admissible increment after %ld "
                     "iterations (masses raised %.0e times)",
                     it, scale);
        goto out;
      }
      continue;
    }
    /* The Rayleigh quotient of the increment, v.(K v) / v.(M v) with K v ~
     * r(x + v) - r(x): the lowest mode's damping, and a mass raised where
     * the response is stiffer than the masses allow. */
    double num = 0, den = 0;
    PM_OMP(parallel for schedule(static) reduction(+ : num, den))
    for (long i = 0; i < n; i++) {
      num += v[i] * (rt[i] - r[i]);
      den += scale * m[i] * v[i] * v[i];
    }
    const double w2 = den > 0 ? num / den : 0;
    if (w2 > RELAX_MAX_OMEGA2 && isfinite(w2)) {
      scale *= w2 / RELAX_MAX_OMEGA2;
      for (long i = 0; i < n; i++) v[i] /= w2 / RELAX_MAX_OMEGA2;
    }
    if (w2 > 0 && isfinite(w2)) c = fmin(2 * sqrt(fmin(w2, 1.0)), 1.9);
    memcpy(x, xt, (size_t)n * sizeof *x);
    memcpy(r, rt, (size_t)n * sizeof *r);
    rn = rtn;
  }
  e = rn <= goal ? PM_SUCCESS : PM_ERR_NOT_CONVERGED;
out:;
  char tail[128];
  snprintf(tail, sizeof tail, "%ld increments inadmissible%s", rejected,
           timed ? "; stopped at its fallback_seconds" : "");
  e = pm_relax_outcome(e, "relaxation", rn, r0, goal, it, tail, msg, cap);
  rep->relax_iterations += it;
  rep->time_relax += pm_wtime() - t0;
  return e;
}
