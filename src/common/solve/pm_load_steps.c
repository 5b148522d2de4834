/* pm_load_steps: the load factor from 0 to 1 in steps, each solved by
 * Newton from the last converged state; a failed step is relaxed
 * (pm_load_relax.c) or halved, and steps grow after easy ones. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_newton.h"
#include "pm_newton_impl.h"
#include "pm_progress.h"

/* Load factors this close to 1 are 1 (steps of 1/load_steps do not add up
 * to 1 exactly). */
#define PM_LOAD_END_SLACK 1e-12
/* The linear iterations a solve of the Newton that finishes a relaxation
 * may take (relax_step): near a fold an iterative solve on a kept or
 * approximate preconditioner crawls (hundreds of GMRES iterations, each
 * dearer than tens of relaxation iterations), and relaxation on to
 * Newton's tolerance is the cheaper way there. */
#define PM_RELAX_NEWTON_LINEAR 100

void pm_load_add_costs(pm_load_report *rep, const pm_newton_report *nr) {
  rep->time_residual += nr->time_residual;
  rep->time_assembly += nr->time_assembly;
  rep->time_linear += nr->time_linear;
  rep->time_setup += nr->time_setup;
  rep->pc_setups += nr->pc_setups;
  rep->time_apply += nr->time_apply;
  rep->cpu_residual += nr->cpu_residual;
  rep->cpu_assembly += nr->cpu_assembly;
  rep->cpu_linear += nr->cpu_linear;
  rep->cpu_setup += nr->cpu_setup;
  rep->cpu_apply += nr->cpu_apply;
  rep->residual_evaluations += nr->residual_evaluations;
  rep->jacobians += nr->jacobians;
  rep->jacobian_applications += nr->jacobian_applications;
}

static void add_solve(pm_load_report *rep, const pm_newton_report *nr) {
  rep->newton_iterations += nr->iterations;
  rep->linear_iterations += nr->linear_iterations;
  pm_load_add_costs(rep, nr);
}

/* The problem's load set to lambda, and the solver told (a factorisation
 * it keeps remembers the load it was made under). */
static pm_err set_load(pm_newton *s, double lambda) {
  const pm_newton_problem *p = pm_newton_problem_of(s);
  pm_newton_note_load(s, lambda);
  return p->set_load(p->ctx, lambda);
}

static bool recoverable(pm_err e) {
  return e == PM_ERR_NOT_CONVERGED || e == PM_ERR_UNSTABLE;
}

/* The tangent (Euler) predictor of a step from lambda to target at the
 * converged state xc: x = xc + dx with J(xc) dx = -(r(xc) + dr), dr the
 * change of r(xc) over the step, linearised in the load (a forward
 * difference over a millionth of the step).  Unlike the start at xc with
 * the new load, whose prescribed values jump in a boundary layer, this is
 * the linear response to the load increment.  Leaves the load at target.
 * A failure is recoverable: the step then starts from xc. */
static pm_err tangent_predictor(pm_newton *s, double lambda, double target,
                                const double *xc, double *r, double *rh,
                                double *x, pm_load_report *rep) {
  const pm_newton_problem *p = pm_newton_problem_of(s);
  const long n = p->n;
  const double h = 1e-6 * (target - lambda);
  pm_err e = set_load(s, lambda + h);
  if (e == PM_SUCCESS) e = pm_newton_residual(s, xc, rh);
  if (e == PM_SUCCESS) e = set_load(s, lambda);
  if (e == PM_SUCCESS) e = pm_newton_residual(s, xc, r);
  if (e == PM_SUCCESS) {
    const double f = (target - lambda) / h;
    for (long i = 0; i < n; i++) rh[i] = -(r[i] + f * (rh[i] - r[i]));
    pm_newton_report tr;
    memset(&tr, 0, sizeof tr);
    e = pm_newton_tangent_solve(s, xc, rh, x, &tr);
    pm_load_add_costs(rep, &tr);
  }
  if (e == PM_SUCCESS)
    for (long i = 0; i < n; i++) x[i] += xc[i];
  pm_err e2 = set_load(s, target);
  return e != PM_SUCCESS ? e : e2;
}

/* The fallback of a step Newton could not finish, at the step's load (set):
 * relaxation from the last converged state xc (or, with x_start, from the
 * state x holds) to relax_rtol of its imbalance, Newton from there (each
 * linear solve held to PM_RELAX_NEWTON_LINEAR iterations), and if Newton
 * fails again relaxation on from its last iterate to Newton's own
 * tolerance.  x receives the state (converged on success, else the last
 * admissible one); what happened goes to msg (cap bytes). */
static pm_err relax_from(pm_newton *s, double *x, bool x_start,
                         const double *xc, pm_relax_work *w,
                         pm_load_report *rep, char *msg, size_t cap) {
  const pm_newton_options *o = pm_newton_options_of(s);
  const long n = pm_newton_problem_of(s)->n;
  char part[256];
  double r0 = 0, r1 = 0;
  if (!x_start) memcpy(x, xc, (size_t)n * sizeof *x);
  pm_err e = pm_load_relax(s, x, o->relax_rtol, o->atol, w, rep, &r0, part,
                           sizeof part);
  snprintf(msg, cap, "%s", part);
  if (e != PM_SUCCESS && e != PM_ERR_NOT_CONVERGED) return e;
  pm_error_clear();
  pm_newton_cap_linear(s, PM_RELAX_NEWTON_LINEAR);
  e = pm_newton_solve_from(s, x, xc, r0, &rep->last);
  pm_newton_cap_linear(s, 0);
  add_solve(rep, &rep->last);
  if (e == PM_SUCCESS || !recoverable(e)) return e;
  pm_error_clear();
  pm_msg_appendf(msg, cap, "; then %s", rep->last.message);
  e = pm_load_relax(s, x, 0, fmax(o->rtol * r0, o->atol), w, rep, &r1, part,
                    sizeof part);
  pm_msg_appendf(msg, cap, "; on from there: %s", part);
  if (e == PM_SUCCESS) {
    /* Converged by the residual criterion, by relaxation alone. */
    rep->last.reason = PM_NEWTON_CONVERGED_RESIDUAL;
    rep->last.status = PM_SUCCESS;
    rep->last.message[0] = '\0';
  }
  return e;
}

static pm_err relax_step(pm_newton *s, double *x, const double *xc,
                         pm_relax_work *w, pm_load_report *rep, char *msg,
                         size_t cap) {
  return relax_from(s, x, false, xc, w, rep, msg, cap);
}

/* The step carried past a limit point at lambda limit (the highest load
 * the arc reached; eig the lowest eigenvalue at xc) by relaxation at the
 * step's load from xc: the stable state the structure snaps to.  Noted in
 * rep (snap_*) and on stderr when it converges; x, msg and cap as
 * relax_step's. */
static pm_err snap_step(pm_newton *s, double *x, const double *xc,
                        double lambda, double target, double limit, double eig,
                        pm_relax_work *w, pm_load_report *rep, char *msg,
                        size_t cap) {
  const size_t used =
      pm_msg_appendf(msg, cap, "; relaxation past the limit point: ");
  if (used + 2 >= cap) return PM_ERR_NOT_CONVERGED;
  pm_err e = relax_step(s, x, xc, w, rep, msg + used, cap - used);
  if (e != PM_SUCCESS) return e;
  rep->snap_steps++;
  rep->snap_lambda = limit;
  rep->snap_eigenvalue = eig;
  char line[256];
  snprintf(line, sizeof line,
           "load step %d (lambda %.6g -> %.6g) carried by relaxation past a "
           "limit point at lambda %.7g (lowest eigenvalue %.3e at lambda "
           "%.6g)",
           rep->steps + 1, lambda, target, limit, eig, lambda);
  fprintf(stderr, "pointmech: %s\n", line);
  /* every such step's line, while they fit */
  pm_msg_appendf(rep->snap_note, sizeof rep->snap_note, "%s%s",
                 rep->snap_note[0] ? "; " : "", line);
  return e;
}

/* The fallback of a step Newton could not finish, at the step's load
 * (target, set; the last converged state xc at load lambda, the one before
 * xprev at lambda_prev), with options.ptc_max_iter > 0: the tangent's
 * lowest mode at xc (pm_load_mode_at), then where its eigenvalue is
 * negative (xc is unstable: past a bifurcation) the continuation started
 * off xc along the mode (pm_load_branch_switch), else arc length round a
 * limit point (pm_load_arc); where the arc finds the load turning back
 * (options.follow_fold false), relaxation from xc at the step's load
 * (snap_step); where that fails the continuation from xc, shifted above a
 * negative eigenvalue; where that fails the relaxation of relax_step, if
 * not tried.  With ahead (relaxation has carried a step of this run,
 * options.relax_first) relax_step is tried first, and the rest only where
 * it fails, without a relaxation of their own.  x, msg and cap as
 * relax_step's. */
static pm_err fallback_step(pm_newton *s, double *x, const double *xc,
                            const double *xprev, double lambda,
                            double lambda_prev, double target, double r_ref,
                            bool ahead, pm_relax_work *w, pm_arc_work *aw,
                            pm_load_report *rep, char *msg, size_t cap) {
  const pm_newton_options *o = pm_newton_options_of(s);
  const long n = pm_newton_problem_of(s)->n;
  if (o->ptc_max_iter <= 0) return relax_step(s, x, xc, w, rep, msg, cap);
  if (ahead) {
    const size_t used0 = pm_msg_appendf(msg, cap, "relaxation first: ");
    pm_err e = relax_step(s, x, xc, w, rep, msg + used0, cap - used0);
    if (e == PM_SUCCESS || !recoverable(e)) return e;
    pm_error_clear();
    fprintf(stderr, "pointmech: load step %d (lambda %.6g -> %.6g): %s\n",
            rep->steps + 1, lambda, target, msg);
  }
  /* the goal: Newton's, relative to the step's imbalance at xc */
  double r0 = 0, eig = NAN;
  if (pm_newton_residual(s, xc, w->r) == PM_SUCCESS)
    r0 = pm_newton_norm(s, w->r);
  pm_error_clear();
  const double goal = fmax(o->rtol * fmax(r0, r_ref), o->atol);
  pm_err e = pm_load_mode_at(s, lambda, target, xc, w, rep, &eig,
                             rep->mode_note, sizeof rep->mode_note);
  if (e != PM_SUCCESS && !recoverable(e)) return e;
  pm_error_clear();
  if (!ahead) msg[0] = '\0';
  if (rep->mode_note[0]) {
    fprintf(stderr, "pointmech: load step %d (lambda %.6g -> %.6g): %s\n",
            rep->steps + 1, lambda, target, rep->mode_note);
    pm_msg_appendf(msg, cap, "%s%s", msg[0] ? "; " : "", rep->mode_note);
  }
  /* a shift above the negative eigenvalue: the shifted tangent definite */
  const double shift0 =
      isfinite(eig) && eig < 0 ? fmax(PM_PTC_SHIFT0, -4 * eig) : 0;
  bool relaxed = ahead;
  e = PM_ERR_NOT_CONVERGED;
  if (isfinite(eig) && eig < 0) {
    e = pm_load_branch_switch(s, x, xc, goal, shift0, w, rep, msg, cap);
  } else if (isfinite(eig)) {
    const size_t used2 = pm_msg_appendf(msg, cap, "%s", msg[0] ? "; " : "");
    double limit = NAN;
    e = pm_load_arc(s, x, xc, xprev, lambda, lambda_prev, target, goal, aw, rep,
                    &limit, msg + used2, (long)(cap - used2));
    if (e == PM_SUCCESS || isfinite(limit))
      fprintf(stderr, "pointmech: load step %d: %s\n", rep->steps + 1,
              msg + used2);
    if (e == PM_SUCCESS) return e;
    if (recoverable(e) && isfinite(limit) && !ahead) {
      pm_error_clear();
      relaxed = true;
      e = snap_step(s, x, xc, lambda, target, limit, eig, w, rep, msg, cap);
      if (e == PM_SUCCESS || !recoverable(e)) return e;
    }
  }
  if (e != PM_SUCCESS && recoverable(e)) {
    pm_error_clear();
    memcpy(x, xc, (size_t)n * sizeof *x);
    e = pm_load_ptc_noted(s, x, goal, shift0, w, rep,
                          msg[0] ? "; from the state: " : "", msg, cap);
  }
  if (e == PM_SUCCESS) {
    rep->ptc_steps++;
    rep->last.reason = PM_NEWTON_CONVERGED_RESIDUAL;
    rep->last.status = PM_SUCCESS;
    rep->last.message[0] = '\0';
    return e;
  }
  if (!recoverable(e) || relaxed) return e;
  pm_error_clear();
  const size_t used = strlen(msg);
  char *rest = msg + used;
  const size_t left = cap - used;
  if (left < 3) return PM_ERR_NOT_CONVERGED;
  snprintf(rest, left, "; ");
  return relax_step(s, x, xc, w, rep, rest + 2, left - 2);
}

/* A step Newton solved (x, from the converged state xc) with its set made
 * consistent (pm_newton_problem.settle): solved again while the set
 * changes, at most PM_SETTLE_PASSES times; a set still changing then is a
 * recoverable failure (the step is cut) naming what changed. */
static pm_err settle_step(pm_newton *s, double *x, const double *xc,
                          double r_ref, pm_load_report *rep) {
  const pm_newton_problem *p = pm_newton_problem_of(s);
  /* (the tolerance stays relative to the step's first imbalance) */
  const double ref = fmax(r_ref, rep->last.residual_norm[0]);
  for (int pass = 0;; pass++) {
    long changed = 0;
    char what[256] = "";
    PM_CALL(p->settle(p->ctx, x, &changed, what, sizeof what));
    if (changed == 0) return PM_SUCCESS;
    if (pass == PM_SETTLE_PASSES) {
      rep->unsettled++;
      rep->last.status = PM_ERR_NOT_CONVERGED;
      snprintf(rep->last.message, sizeof rep->last.message,
               "the set did not settle: solved %d times, and the last solve "
               "changed %ld entries again (%s)",
               pass + 1, changed, what);
      return PM_ERROR(PM_ERR_NOT_CONVERGED, "%s", rep->last.message);
    }
    rep->resolves++;
    pm_err e = pm_newton_solve_from(s, x, xc, ref, &rep->last);
    add_solve(rep, &rep->last);
    if (e != PM_SUCCESS) return e;
  }
}

/* A step (lambda -> target) converged at x: x the last converged state
 * (the one before kept), the report's counts, the next step's size and
 * whether it relaxes first (relax_next), set before on_step (the state it
 * sees is the one the next step starts from, as a checkpoint keeps it);
 * nominal and largest the step sizes of pm_load_steps_from. */
static pm_err converged(pm_newton *s, const double *x, pm_load_state *st,
                        pm_load_report *rep, double lambda, double target,
                        double nominal, double largest, bool relax_next,
                        int *cuts) {
  const pm_newton_options *o = pm_newton_options_of(s);
  const pm_newton_problem *p = pm_newton_problem_of(s);
  const long n = p->n;
  memcpy(st->xprev, st->xc, (size_t)n * sizeof *st->xc);
  memcpy(st->xc, x, (size_t)n * sizeof *st->xc);
  st->lambda_prev = lambda;
  st->lambda = target;
  st->have_prev = 1;
  rep->steps++;
  rep->lambda = target;
  if (target - lambda < rep->dlambda_min) rep->dlambda_min = target - lambda;
  *cuts = 0;
  const bool easy =
      o->easy_iterations > 0 && rep->last.iterations <= o->easy_iterations;
  if (easy && st->dl < largest) {
    st->dl = fmin(1.5 * st->dl, largest);
    st->good = 0;
  } else if (st->dl < nominal && o->grow_after > 0 &&
             ++st->good >= o->grow_after) {
    st->dl = fmin(1.5 * st->dl, nominal);
    st->good = 0;
  }
  st->relax_first = o->relax_first && relax_next;
  if (st->relax_first) st->relax_carried = 1;
  st->done = *rep;
  PM_CALL(pm_newton_pc_save(s, st));
  if (p->on_step)
    PM_CALL(p->on_step(p->ctx, rep->steps, target, st->xc, &rep->last));
  return PM_SUCCESS;
}

/* options.predictor: x = the state at the load target the last two
 * converged states of st extrapolate to, where there are two; returns
 * whether x was set. */
static bool extrapolate(const pm_newton_options *o, const pm_load_state *st,
                        double target, long n, double *x) {
  if (!o->predictor || !st->have_prev || !(st->lambda > st->lambda_prev))
    return false;
  const double f = (target - st->lambda) / (st->lambda - st->lambda_prev);
  for (long i = 0; i < n; i++)
    x[i] = st->xc[i] + f * (st->xc[i] - st->xprev[i]);
  return true;
}

/* options.relax_first: the step at the load set (target), by relax_from
 * with the fallbacks' linear solver, from the state the last two
 * converged ones extrapolate to (options.predictor; where it is
 * inadmissible at the start, from the last converged state xc), else
 * from xc: the last converged state under the step's load can invert a
 * point beside a moved face (x, w, rep, msg and cap as relax_step's). */
static pm_err relaxed_first(pm_newton *s, double *x, const double *xc,
                            pm_load_state *st, double target, pm_relax_work *w,
                            pm_load_report *rep, char *msg, size_t cap) {
  const pm_newton_options *o = pm_newton_options_of(s);
  const long n = pm_newton_problem_of(s)->n;
  PM_CALL(pm_newton_use_fallback_linear(s, true));
  const bool predict = extrapolate(o, st, target, n, x);
  const long its = rep->relax_iterations;
  pm_err e = relax_from(s, x, predict, xc, w, rep, msg, cap);
  if (predict && recoverable(e) && rep->relax_iterations == its) {
    pm_error_clear();
    e = relax_step(s, x, xc, w, rep, msg, cap);
  }
  if (pm_newton_fallback_kept(s)) {
    st->fallback_kept = 1;
  } else if (e == PM_SUCCESS || recoverable(e)) {
    pm_err back = pm_newton_use_fallback_linear(s, false);
    if (back != PM_SUCCESS) return back;
  }
  return e;
}

pm_err pm_load_steps(pm_newton *s, double *x, pm_load_report *report) {
  pm_load_state state;
  PM_CHECK(s, PM_ERR_ARG, "pm_load_steps: solver is required");
  PM_CALL(pm_load_state_init(&state, pm_newton_problem_of(s)->n));
  pm_err e = pm_load_steps_from(s, x, &state, report);
  pm_load_state_free(&state);
  return e;
}

pm_err pm_load_steps_from(pm_newton *s, double *x, pm_load_state *st,
                          pm_load_report *report) {
  pm_err ret = PM_SUCCESS;
  pm_load_report local;
  pm_load_report *rep = report ? report : &local;
  pm_relax_work rw = {0};
  pm_arc_work aw = {0};
  double *r = NULL, *rh = NULL;
  double t0 = pm_wtime();
  const bool resumed = st && st->lambda > 0;
  if (!resumed || !report) memset(rep, 0, sizeof *rep);
  PM_CHECK(s && x && st && st->xc && st->xprev, PM_ERR_ARG,
           "pm_load_steps: solver, x and state are required");
  const pm_newton_problem *p = pm_newton_problem_of(s);
  const pm_newton_options *o = pm_newton_options_of(s);
  const long n = p->n;
  double *xc = st->xc, *xprev = st->xprev;
  PM_CHECK(p->set_load, PM_ERR_ARG,
           "pm_load_steps: the problem has no set_load");
  PM_CHECK(o->easy_iterations >= 0 && o->max_dlambda >= 0 &&
               o->max_dlambda <= 1,
           PM_ERR_ARG,
           "pm_load_steps: easy_iterations must be >= 0 and max_dlambda in "
           "[0, 1] (got %d, %g)",
           o->easy_iterations, o->max_dlambda);
  PM_CHECK(
      o->relax_after >= 0 &&
          (o->relax_after == 0 ||
           (o->relax_max_iter > 0 && o->relax_rtol > 0 && o->relax_rtol < 1)),
      PM_ERR_ARG,
      "pm_load_steps: relax_after must be >= 0, and with it relax_max_iter "
      "> 0 and relax_rtol in (0, 1) (got %d, %d, %g)",
      o->relax_after, o->relax_max_iter, o->relax_rtol);
  const bool relaxing = pm_load_relax_available(s);
  if (relaxing) PM_TRY(pm_relax_work_init(&rw, n));
  if (relaxing && o->ptc_max_iter > 0) PM_TRY(pm_arc_work_init(&aw, n));
  if (o->predictor) {
    PM_TRY(PM_ALLOC(r, n, "residual"));
    PM_TRY(PM_ALLOC(rh, n, "residual"));
  }
  const double nominal = 1.0 / o->load_steps;
  const double largest = o->max_dlambda > 0 ? o->max_dlambda : nominal;
  double relaxed_dl = -1; /* the step size relaxation was last tried at */
  if (!resumed) {
    memcpy(xc, x, (size_t)n * sizeof *xc);
    st->lambda = st->lambda_prev = 0;
    st->dl = nominal;
    st->good = st->have_prev = st->relax_first = st->relax_carried = 0;
    rep->dlambda_min = nominal;
  }
  if (resumed && st->fallback_kept)
    PM_TRY(pm_newton_use_fallback_linear(s, true));
  if (resumed && st->pc_built) {
    /* The factorisation the first run kept, made again where it was. */
    PM_TRY(set_load(s, st->pc_lambda));
    PM_TRY(pm_newton_pc_rebuild(s, st));
  }
  int cuts = 0;
  while (st->lambda < 1) {
    const double lambda = st->lambda, lambda_prev = st->lambda_prev;
    double target = lambda + st->dl;
    if (target > 1 - PM_LOAD_END_SLACK) target = 1;
    PM_TRY(set_load(s, target));
    char relaxed[2048] = "", failed[sizeof rep->last.message] = "";
    if (relaxing && st->relax_first) {
      /* The step before was carried by relaxation: this one too, first. */
      const long its = rep->relax_iterations;
      pm_err e = relaxed_first(s, x, xc, st, target, &rw, rep, relaxed,
                               sizeof relaxed);
      if (e == PM_SUCCESS && p->settle) e = settle_step(s, x, xc, 0, rep);
      if (e == PM_SUCCESS) {
        rep->relaxed_steps++;
        relaxed_dl = -1;
        PM_TRY(converged(s, x, st, rep, lambda, target, nominal, largest, true,
                         &cuts));
        continue;
      }
      if (!recoverable(e)) {
        ret = e;
        goto done;
      }
      if (rep->relax_iterations == its && cuts < o->max_cuts &&
          st->dl / 2 >= o->min_dlambda * (1 - 1e-12)) {
        /* Inadmissible before relaxation's first iteration, from the
         * extrapolation and from the last converged state alike (a point
         * beside the moved face inverted by the face's travel over the
         * step): a shorter step, relaxed first again. */
        fprintf(stderr,
                "pointmech: load step %d (lambda %.6g -> %.6g): relaxed "
                "first: %s; the step cut\n",
                rep->steps + 1, lambda, target, relaxed);
        pm_error_clear();
        cuts++;
        rep->cuts++;
        st->dl /= 2;
        continue;
      }
      /* Not carried: the ordinary way, from here on until relaxation
       * carries a step again. */
      fprintf(stderr,
              "pointmech: load step %d (lambda %.6g -> %.6g): relaxed first: "
              "%s; the ordinary way\n",
              rep->steps + 1, lambda, target, relaxed);
      pm_error_clear();
      st->relax_first = 0;
      relaxed[0] = '\0';
    }
    memcpy(x, xc, (size_t)n * sizeof *x);
    bool predicted = extrapolate(o, st, target, n, x);
    if (!predicted && o->predictor) {
      /* No two states to extrapolate from: the tangent predictor. */
      pm_err e = tangent_predictor(s, lambda, target, xc, r, rh, x, rep);
      if (e != PM_SUCCESS && !recoverable(e)) {
        ret = e;
        goto done;
      }
      predicted = e == PM_SUCCESS;
      if (!predicted) memcpy(x, xc, (size_t)n * sizeof *x);
      pm_error_clear();
    }
    double r_ref = 0;
    if (predicted) {
      /* rtol stays relative to the step's imbalance at the last state:
       * a good prediction must not tighten it to roundoff. */
      if (pm_newton_residual(s, xc, r) == PM_SUCCESS) {
        r_ref = pm_newton_norm(s, r);
      } else {
        pm_error_clear();
      }
    }
    pm_err e = pm_newton_solve_from(s, x, xc, r_ref, &rep->last);
    add_solve(rep, &rep->last);
    if (e != PM_SUCCESS && predicted && rep->last.iterations == 0 &&
        rep->last.reason == PM_NEWTON_DIVERGED_DOMAIN) {
      /* The extrapolated state is inadmissible: start from the last one. */
      memcpy(x, xc, (size_t)n * sizeof *x);
      e = pm_newton_solve_from(s, x, xc, r_ref, &rep->last);
      add_solve(rep, &rep->last);
    }
    bool by_relaxation = false;
    if (e != PM_SUCCESS && recoverable(e) && relaxing && st->dl != relaxed_dl &&
        (cuts == o->relax_after || cuts >= o->max_cuts ||
         st->dl / 2 < o->min_dlambda * (1 - 1e-12))) {
      /* Newton cannot finish this step, cut relax_after times or at its
       * floor: relaxation within the step. */
      pm_error_clear();
      relaxed_dl = st->dl;
      snprintf(failed, sizeof failed, "%s", rep->last.message);
      const int ptc_before = rep->ptc_steps, arc_before = rep->arc_passes;
      /* (with the fallbacks' own linear solver, if they have one) */
      PM_TRY(pm_newton_use_fallback_linear(s, true));
      e = fallback_step(s, x, xc, xprev, lambda, lambda_prev, target, r_ref,
                        o->relax_first && st->relax_carried, &rw, &aw, rep,
                        relaxed, sizeof relaxed);
      if (pm_newton_fallback_kept(s)) {
        st->fallback_kept = 1;
      } else {
        pm_err back = pm_newton_use_fallback_linear(s, false);
        if (back != PM_SUCCESS) {
          ret = back;
          goto done;
        }
      }
      if (e == PM_SUCCESS && rep->ptc_steps == ptc_before &&
          rep->arc_passes == arc_before) {
        rep->relaxed_steps++;
        by_relaxation = true;
      }
      if (e == PM_ERR_UNSUPPORTED) e = PM_ERR_NOT_CONVERGED;
    }
    if (e == PM_SUCCESS && p->settle) e = settle_step(s, x, xc, r_ref, rep);
    if (e == PM_SUCCESS) {
      relaxed_dl = -1;
      PM_TRY(converged(s, x, st, rep, lambda, target, nominal, largest,
                       by_relaxation, &cuts));
      continue;
    }
    if (!recoverable(e)) {
      ret = pm_error_trace(e, __FILE__, __LINE__, __func__,
                           "the Newton solve of a load step");
      goto done;
    }
    pm_error_clear();
    st->good = 0;
    if (cuts >= o->max_cuts || st->dl / 2 < o->min_dlambda * (1 - 1e-12)) {
      /* Where the last state tried stands, in the problem's words. */
      char where[512] = "";
      if (p->diagnose &&
          p->diagnose(p->ctx, x, where, sizeof where) != PM_SUCCESS) {
        where[0] = '\0';
        pm_error_clear();
      }
      ret = PM_ERROR(e,
                     "load step %d (lambda %.6g -> %.6g): %s%s%s; cut %d times "
                     "to dlambda %.3g: giving up%s%s",
                     rep->steps + 1, lambda, target,
                     failed[0] ? failed : rep->last.message,
                     relaxed[0] ? "; " : "", relaxed, cuts, target - lambda,
                     where[0] ? "; at the last state tried: " : "", where);
      goto done;
    }
    cuts++;
    rep->cuts++;
    st->dl /= 2;
  }
done:
  memcpy(x, xc, (size_t)n * sizeof *x);
  /* The load stays that of the state returned. */
  if (ret != PM_SUCCESS) (void)set_load(s, rep->lambda);
  rep->time_total += pm_wtime() - t0;
  free(r);
  free(rh);
  pm_relax_work_free(&rw);
  pm_arc_work_free(&aw);
  return ret;
}
