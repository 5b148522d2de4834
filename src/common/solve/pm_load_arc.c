/* pm_load_arc: arc-length continuation (Riks, the normal plane) within a
 * load step, the fallback of load stepping at a limit point: the load
 * factor becomes an unknown, and the path is followed round the fold to
 * the step's load on its far side. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_interrupt.h"
#include "pm_newton_impl.h"
#include "pm_newton_solver_impl.h"
#include "pm_omp.h"
#include "pm_progress.h"

/* Corrector iterations of one arc step, and arc steps of one fallback (a
 * path that goes back by more than 1.5 loads is abandoned too: the cubic
 * snap-through of unit.test_load_steps goes back 1.18). */
#define ARC_ITERS 12
#define ARC_STEPS 60
/* An arc step converged in at most this many iterations lengthens the
 * next by half; a failed one halves it, down to ARC_MIN_FRACTION of the
 * first. */
#define ARC_EASY 4
#define ARC_MIN_FRACTION 1e-4
/* A corrector whose residual grows past this multiple of the predictor's
 * is abandoned for a shorter arc. */
#define ARC_GROWTH 10.0

pm_err pm_arc_work_init(pm_arc_work *w, long n) {
  memset(w, 0, sizeof *w);
  pm_err ret = PM_SUCCESS;
  double **v[] = {&w->xa, &w->r,   &w->t,   &w->fl,
                  &w->b,  &w->dxr, &w->dxf, &w->ox};
  for (size_t i = 0; i < sizeof v / sizeof *v; i++)
    PM_TRY(PM_ALLOC(*v[i], n, "arc-length work space"));
done:
  if (ret != PM_SUCCESS) pm_arc_work_free(w);
  return ret;
}

void pm_arc_work_free(pm_arc_work *w) {
  double *v[] = {w->xa, w->r, w->t, w->fl, w->b, w->dxr, w->dxf, w->ox};
  for (size_t i = 0; i < sizeof v / sizeof *v; i++) free(v[i]);
  memset(w, 0, sizeof *w);
}

/* fl = dr/dlambda at (x, lambda) by a forward difference (r = r(x) at
 * lambda, given); leaves the load at lambda. */
static pm_err load_derivative(pm_newton *s, const double *x, double lambda,
                              const double *r, double *fl) {
  const pm_newton_problem *p = &s->p;
  const long n = p->n;
  const double h = 1e-7 * fmax(1.0, fabs(lambda));
  pm_newton_note_load(s, lambda + h);
  pm_err e = p->set_load(p->ctx, lambda + h);
  if (e == PM_SUCCESS) e = pm_newton_residual(s, x, fl);
  pm_newton_note_load(s, lambda);
  pm_err e2 = p->set_load(p->ctx, lambda);
  if (e != PM_SUCCESS) return e;
  PM_OMP(parallel for schedule(static))
  for (long i = 0; i < n; i++) fl[i] = (fl[i] - r[i]) / h;
  return e2;
}

/* dx solves K(x) dx = b.  fresh: a new factorisation at x (near a fold a
 * kept one, made at another state, left GMRES hundreds of iterations);
 * the second solve at the same x reuses it. */
static pm_err solve(pm_newton *s, const double *x, const double *b, double *dx,
                    bool fresh, pm_load_report *rep) {
  if (fresh) s->pc_built = false;
  pm_newton_report tr;
  memset(&tr, 0, sizeof tr);
  pm_err e = pm_newton_tangent_solve(s, x, b, dx, &tr);
  pm_load_add_costs(rep, &tr);
  return e;
}

static double dot(long n, const double *a, const double *b) {
  double d = 0;
  PM_OMP(parallel for schedule(static) reduction(+ : d))
  for (long i = 0; i < n; i++) d += a[i] * b[i];
  return d;
}

/* The unit tangent (t, tl) of the path at (x, lambda), r = r(x) there, in
 * the metric |(dx, dl)|^2 = dx.dx + S^2 dl^2, oriented along (ox, ol). */
static pm_err path_tangent(pm_newton *s, const double *x, double lambda,
                           const double *r, double S, const double *ox,
                           double ol, pm_arc_work *w, pm_load_report *rep,
                           double *tl) {
  const long n = s->p.n;
  PM_CALL(load_derivative(s, x, lambda, r, w->fl));
  PM_OMP(parallel for schedule(static))
  for (long i = 0; i < n; i++) w->b[i] = -w->fl[i];
  PM_CALL(solve(s, x, w->b, w->t, true, rep)); /* K dx/dl = -dr/dl */
  const double norm = sqrt(dot(n, w->t, w->t) + S * S);
  double l = 1 / norm;
  for (long i = 0; i < n; i++) w->t[i] /= norm;
  if (dot(n, w->t, ox) + S * S * l * ol < 0) {
    for (long i = 0; i < n; i++) w->t[i] = -w->t[i];
    l = -l;
  }
  *tl = l;
  return PM_SUCCESS;
}

pm_err pm_load_arc(pm_newton *s, double *x, const double *xc,
                   const double *xprev, double lambda, double lambda_prev,
                   double target, double goal, pm_arc_work *w,
                   pm_load_report *rep, double *limit, char *msg, long cap) {
  const pm_newton_problem *p = &s->p;
  const long n = p->n;
  const double t0 = pm_wtime(), cpu0 = pm_cputime();
  double *xa = w->xa, *r = w->r, *t = w->t;
  double la = lambda, tl = 0, rn = 0, peak = lambda;
  long its = 0;
  int steps = 0, back = 0;
  bool timed = false;
  pm_err e = PM_SUCCESS;
  msg[0] = '\0';
  *limit = NAN;
  PM_CHECK(!s->dist, PM_ERR_UNSUPPORTED, "arc length: one process only");
  rep->arc_runs++;
  memcpy(xa, xc, (size_t)n * sizeof *xa);
  /* the metric's scale: the mean |dx| / lambda of the path so far, so that
   * x and lambda weigh alike along it */
  double S = lambda > 0 ? sqrt(dot(n, xc, xc)) / lambda : 1;
  if (!(S > 0 && isfinite(S))) S = 1;
  pm_newton_note_load(s, la);
  if ((e = p->set_load(p->ctx, la)) != PM_SUCCESS) goto out;
  if ((e = pm_newton_residual(s, xa, r)) != PM_SUCCESS) goto out;
  /* the orientation: along the last converged step */
  for (long i = 0; i < n; i++) w->ox[i] = xc[i] - xprev[i];
  double ol = lambda - lambda_prev;
  if (!(ol > 0)) ol = 1;
  if ((e = path_tangent(s, xa, la, r, S, w->ox, ol, w, rep, &tl)) != PM_SUCCESS)
    goto out;
  /* the first arc: the last converged step's length (Crisfield), at
   * most that of a quarter of the nominal step along the tangent */
  const double nominal = 1.0 / s->o.load_steps;
  double last2 = S * S * ol * ol;
  for (long i = 0; i < n; i++) last2 += w->ox[i] * w->ox[i];
  const double ds0 =
      fmin(sqrt(last2), S * sqrt(2.0) * fmax(0.25 * nominal, target - lambda));
  double ds = ds0;
  while (steps < ARC_STEPS) {
    PM_CALL(pm_interrupt_check("in the arc-length continuation"));
    if (pm_load_out_of_time(s, cpu0, rep)) {
      timed = true;
      e = PM_ERR_NOT_CONVERGED;
      goto out;
    }
    /* predictor along the tangent, corrector in its normal plane */
    double l = la + ds * tl;
    PM_OMP(parallel for schedule(static))
    for (long i = 0; i < n; i++) x[i] = xa[i] + ds * t[i];
    bool ok = false;
    int k = 0;
    double r_pred = 0;
    for (; k < ARC_ITERS; k++) {
      its++;
      pm_newton_note_load(s, l);
      e = p->set_load(p->ctx, l);
      if (e == PM_SUCCESS) e = pm_relax_residual(s, x, r, &rn);
      if (e != PM_SUCCESS) break;
      if (rn <= goal) {
        ok = true;
        break;
      }
      if (k == 0) r_pred = rn;
      if (rn > ARC_GROWTH * r_pred) break; /* diverging: a shorter arc */
      e = load_derivative(s, x, l, r, w->fl);
      for (long i = 0; i < n; i++) w->b[i] = -r[i];
      if (e == PM_SUCCESS) e = solve(s, x, w->b, w->dxr, true, rep);
      for (long i = 0; i < n; i++) w->b[i] = -w->fl[i];
      if (e == PM_SUCCESS) e = solve(s, x, w->b, w->dxf, false, rep);
      if (e != PM_SUCCESS) break;
      /* t.dx + S^2 tl dl = 0 with dx = dxr + dl dxf */
      const double den = dot(n, t, w->dxf) + S * S * tl;
      if (!(fabs(den) > 0)) {
        e = PM_ERROR(PM_ERR_NOT_CONVERGED, "arc length: the bordered "
                                           "system is singular");
        break;
      }
      const double dl = -dot(n, t, w->dxr) / den;
      PM_OMP(parallel for schedule(static))
      for (long i = 0; i < n; i++) x[i] += w->dxr[i] + dl * w->dxf[i];
      l += dl;
    }
    if (e != PM_SUCCESS && pm_newton_hard_failure(e)) goto out;
    pm_error_clear();
    e = PM_SUCCESS;
    if (!ok) {
      ds /= 2;
      if (ds < ARC_MIN_FRACTION * ds0) {
        e = PM_ERROR(PM_ERR_NOT_CONVERGED,
                     "arc length: an arc of %.2e did not converge", ds);
        goto out;
      }
      continue;
    }
    steps++;
    if (l < la) back++;
    if (l < la && !s->o.follow_fold) {
      /* The load turned back: a limit point at the highest load reached.
       * Past it the structure snaps; the caller carries the step to the
       * branch it jumps to (the unstable path beyond is not followed). */
      fprintf(stderr, "pointmech: arc %d: lambda %.8g, %d iterations\n", steps,
              l, k);
      *limit = peak;
      e = PM_ERR_NOT_CONVERGED;
      goto out;
    }
    peak = fmax(peak, l);
    if (l < lambda - 1.5) {
      e = PM_ERROR(PM_ERR_NOT_CONVERGED,
                   "arc length: the path went back 1.5 loads (to lambda "
                   "%.4g) without passing the step's load",
                   l);
      goto out;
    }
    fprintf(stderr, "pointmech: arc %d: lambda %.8g, %d iterations\n", steps, l,
            k);
    if (l >= target) {
      /* past the step's load: Newton there, from the point of the chord
       * at the step's load */
      const double f = (target - la) / (l - la);
      PM_OMP(parallel for schedule(static))
      for (long i = 0; i < n; i++) x[i] = xa[i] + f * (x[i] - xa[i]);
      pm_newton_note_load(s, target);
      if ((e = p->set_load(p->ctx, target)) != PM_SUCCESS) goto out;
      e = pm_newton_solve_from(s, x, xc, goal / fmax(s->o.rtol, 1e-300),
                               &rep->last);
      rep->newton_iterations += rep->last.iterations;
      rep->linear_iterations += rep->last.linear_iterations;
      la = target;
      goto out;
    }
    /* the next tangent, oriented along this arc */
    for (long i = 0; i < n; i++) w->ox[i] = x[i] - xa[i];
    ol = l - la;
    memcpy(xa, x, (size_t)n * sizeof *xa);
    la = l;
    if ((e = path_tangent(s, xa, la, r, S, w->ox, ol, w, rep, &tl)) !=
        PM_SUCCESS)
      goto out;
    if (k <= ARC_EASY) ds *= 1.5;
  }
  e = PM_ERROR(PM_ERR_NOT_CONVERGED,
               "arc length: %d arcs did not reach the step's load (at "
               "lambda %.6g)",
               steps, la);
out:;
  if (e != PM_SUCCESS && !pm_newton_hard_failure(e)) {
    /* the load and the state of the last converged step */
    pm_error_clear();
    memcpy(x, xc, (size_t)n * sizeof *x);
    e = PM_ERR_NOT_CONVERGED;
  }
  pm_newton_note_load(s, target);
  pm_err e2 = p->set_load(p->ctx, target);
  if (e == PM_SUCCESS) e = e2;
  const int used = snprintf(
      msg, (size_t)cap,
      "arc length %s: %d arcs (%d with the load falling), %ld iterations, "
      "reached lambda %.6g",
      e == PM_SUCCESS    ? "passed the fold"
      : isfinite(*limit) ? "found a limit point (the load turned back)"
                         : "did not reach the step's load",
      steps, back, its, isfinite(*limit) ? *limit : la);
  if (timed && used >= 0 && used < cap)
    snprintf(msg + used, (size_t)(cap - used),
             "; stopped at its fallback_seconds");
  if (e == PM_SUCCESS) rep->arc_passes++;
  rep->arc_steps += steps;
  rep->arc_iterations += its;
  rep->time_arc += pm_wtime() - t0;
  s->pc_built = false; /* Newton's next solve factorises at its own state */
  if (e == PM_ERR_NOT_CONVERGED) e = PM_ERROR(PM_ERR_NOT_CONVERGED, "%s", msg);
  return e;
}
