/* pm_newton_impl: what load stepping uses of a Newton solver beyond the
 * public interface. */
#ifndef PM_NEWTON_IMPL_H
#define PM_NEWTON_IMPL_H

#include "pm_newton.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* Appends printf-style text to the message msg (capacity cap, NUL-ended,
 * truncated to fit); returns msg's length after it. */
__attribute__((format(printf, 3, 4))) static inline size_t
pm_msg_appendf(char *msg, size_t cap, const char *fmt, ...) {
  size_t used = strlen(msg);
  if (used + 1 < cap) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg + used, cap - used, fmt, ap);
    va_end(ap);
    used = strlen(msg);
  }
  return used;
}

const pm_newton_problem *pm_newton_problem_of(const pm_newton *s);
const pm_newton_options *pm_newton_options_of(const pm_newton *s);

/* pm_newton_solve with the displacement criterion measured from x_start
 * (n values, copied) instead of the initial guess, and rtol relative to the
 * larger of |r(x_0)| and r_ref; report is required. */
pm_err pm_newton_solve_from(pm_newton *s, double *x, const double *x_start,
                            double r_ref, pm_newton_report *report);

/* dx solves J(x) dx = b, with J assembled at x (jacobian_prepare there
 * first) and the solver's linear solver; for the tangent predictor of a
 * load step.  Times go to rep (required).  A linear solver failure is
 * PM_ERR_NOT_CONVERGED. */
pm_err pm_newton_tangent_solve(pm_newton *s, const double *x, const double *b,
                               double *dx, pm_newton_report *rep);

/* The load the problem was last set to (by load stepping): what a
 * factorisation built from here on is made under. */
void pm_newton_note_load(pm_newton *s, double lambda);

/* The kept factorisation or preconditioner (options.pc_reuse_its) into
 * st: whether one is built, the owned values of the state and the load it
 * was made at, the last linear solve's iterations and failure (st->pc_x
 * has the n owned values).  PETSc's failures as PM_ERR_LINALG. */
pm_err pm_newton_pc_save(const pm_newton *s, pm_load_state *st);

/* A resume's: the factorisation or preconditioner built at st->pc_x
 * (owned values, under the load set), as if the last linear solve it
 * served took st->pc_its iterations and failed or not, with the reuse
 * figure of st (pc_first_its): what the first run
 * kept, made again from the same values (collective across ranks).  A
 * callback's failure or PETSc's is returned. */
pm_err pm_newton_pc_rebuild(pm_newton *s, const pm_load_state *st);

/* The fallbacks' linear solver (pm_newton_set_fallback_linear) in place
 * (on) or the solver's own again (off): a new linear solver, built on the
 * next Jacobian; nothing when there is no other or it is in place
 * already. */
pm_err pm_newton_use_fallback_linear(pm_newton *s, bool on);
/* Whether the fallbacks' linear solver, once taken, is kept for the rest
 * of the run (pm_newton_set_fallback_linear's keep). */
bool pm_newton_fallback_kept(const pm_newton *s);
/* At most max_its iterations for each linear solve from now on (fewer
 * than the options' linear_max_iter; 0: theirs again): a solve that
 * reaches it fails as at linear_max_iter. */
void pm_newton_cap_linear(pm_newton *s, int max_its);

/* r = the residual at x (both of the n owned values): the problem's
 * callback, through the held values of a shared problem (collective then,
 * with the ranks' agreed answer). */
pm_err pm_newton_residual(pm_newton *s, const double *x, double *r);

/* The Euclidean norm of v (the n owned values) over all ranks. */
double pm_newton_norm(const pm_newton *s, const double *v);

/* The times and counts of one Newton solve (or linear solve) nr added to
 * rep's (pm_load_steps.c). */
void pm_load_add_costs(pm_load_report *rep, const pm_newton_report *nr);

/* ---- pm_load_relax.c: dynamic relaxation within a load step ---- */

/* Its work space: n values each. */
typedef struct {
  double *mass, *v, *r, *rt, *xt;
  double *mode; /* the tangent's lowest mode (pm_load_branch.c) */
} pm_relax_work;
pm_err pm_relax_work_init(pm_relax_work *w, long n);
void pm_relax_work_free(pm_relax_work *w);

/* Whether a fallback started at pm_cputime() cpu0 has used the
 * options.fallback_seconds it may take (never when they are 0); if so it
 * is counted in rep (fallbacks_timed_out): the fallback stops short of
 * its goal and the next is tried. */
bool pm_load_out_of_time(const pm_newton *s, double cpu0, pm_load_report *rep);

/* Dynamic relaxation at the load set, from x (in/out: the last admissible
 * state reached) until |r| <= max(rel |r(x start)|, goal) (the start's
 * residual into *r_start) or options.relax_max_iter iterations,
 * with masses from the tangent at the start.  Counts and times go to rep;
 * msg (cap bytes) gets one line of what it did.  PM_SUCCESS at the goal;
 * PM_ERR_NOT_CONVERGED short of it; PM_ERR_UNSTABLE for an inadmissible
 * start or no admissible increment; PM_ERR_UNSUPPORTED across ranks; a
 * hard failure of a callback as it is. */
pm_err pm_load_relax(pm_newton *s, double *x, double rel, double goal,
                     pm_relax_work *w, pm_load_report *rep, double *r_start,
                     char *msg, long cap);

/* Whether s can relax (options.relax_after > 0, one process's problem). */
bool pm_load_relax_available(const pm_newton *s);

/* r = the residual at x (n values), |r| into *norm; inadmissible
 * (PM_ERR_UNSTABLE) when not finite, the callback's failure as it is. */
pm_err pm_relax_residual(pm_newton *s, const double *x, double *r,
                         double *norm);

/* The end of a relaxation or continuation named what, in one line into
 * msg (cap bytes): reached its goal or not (residual rn from r0, goal,
 * it iterations, then tail), or failed (with the error's message).
 * Returns e, PM_ERR_NOT_CONVERGED raised with that line. */
pm_err pm_relax_outcome(pm_err e, const char *what, double rn, double r0,
                        double goal, long it, const char *tail, char *msg,
                        long cap);

/* Masses m_i = sum_j |K_ij| / 2 of the tangent K at x (Gershgorin: every
 * frequency of M^-1 K at most 2, within the central difference's limit
 * of 4 at a unit step), a row without entries taking the largest; into m
 * (n values).  PM_ERR_UNSTABLE for a tangent zero or not finite. */
pm_err pm_relax_masses(pm_newton *s, const double *x, double *m);

/* ---- pm_load_ptc.c: pseudo-transient continuation within a load step ---- */

/* Pseudo-transient continuation at the load set, from x (in/out: the last
 * admissible state reached) until |r| <= goal or options.ptc_max_iter
 * iterations: x += dx with (J(x) + M / dtau) dx = -r(x), M the
 * relaxation's masses at the start, dtau growing as |r| falls (switched
 * evolution relaxation) so that the last iterations are Newton's.  An
 * inadmissible or diverging trial is not taken and dtau is cut.  The
 * start's residual into *r_start; the smallest curvature along the
 * increments, min dx.J dx / dx.M dx (negative: J is indefinite there),
 * into *curvature.  Work space w (pm_relax_work's); counts and times to
 * rep; msg (cap bytes) one line of what it did.  PM_SUCCESS at the goal,
 * PM_ERR_NOT_CONVERGED short of it, PM_ERR_UNSTABLE for an inadmissible
 * start, a hard failure of a callback as it is.  One process only. */
pm_err pm_load_ptc(pm_newton *s, double *x, double goal, double shift0,
                   pm_relax_work *w, pm_load_report *rep, double *r_start,
                   double *curvature, char *msg, long cap);

/* The continuation's first shift, in units of the masses, when no lowest
 * mode says otherwise. */
#define PM_PTC_SHIFT0 1e-2

/* ---- pm_load_branch.c: the lowest mode and the branch switch ---- */

/* The eigenvalue q of K(x) v = q M v nearest zero (M diagonal, m; K the
 * tangent at x, factorised afresh there) by inverse iteration from a fixed
 * start, at most 12 iterations: into *eig, the mode (v.M v = 1) into v,
 * the iterations into *iters; u and b are work space (n values each).
 * The next Newton solve factorises again.  The linear solve's failure as
 * it is (recoverable: PM_ERR_NOT_CONVERGED); one process only. */
pm_err pm_load_lowest_mode(pm_newton *s, const double *x, const double *m,
                           double *v, double *u, double *b, pm_load_report *rep,
                           double *eig, int *iters);

/* The lowest mode (into w->mode, its eigenvalue into *eig) of the tangent
 * at the converged state x of load lambda, with the relaxation's masses
 * there (w->mass); the load is set back to target.  One line into msg
 * (cap bytes): the eigenvalue and, by the problem's describe_mode, where
 * the mode is.  Counts to rep (mode_runs, mode_eigenvalue). */
pm_err pm_load_mode_at(pm_newton *s, double lambda, double target,
                       const double *x, pm_relax_work *w, pm_load_report *rep,
                       double *eig, char *msg, long cap);

/* pm_load_ptc from x with the first shift shift0, its line appended to msg
 * (cap bytes) after label, and its smallest curvature kept in rep. */
pm_err pm_load_ptc_noted(pm_newton *s, double *x, double goal, double shift0,
                         pm_relax_work *w, pm_load_report *rep,
                         const char *label, char *msg, size_t cap);

/* The continuation (pm_load_ptc, first shift shift0) from xc + a w->mode
 * at the step's load (set), the mode scaled so that its largest entry is
 * 1% of xc's, taken with + first, then with -: the imperfection a
 * symmetric path needs to leave a bifurcation.  Goal, x and msg (cap
 * bytes, appended to) as pm_load_ptc's; counts to rep (branch_switches
 * for a success).  PM_SUCCESS, or the last continuation's failure. */
pm_err pm_load_branch_switch(pm_newton *s, double *x, const double *xc,
                             double goal, double shift0, pm_relax_work *w,
                             pm_load_report *rep, char *msg, size_t cap);

/* ---- pm_load_arc.c: arc-length continuation within a load step ---- */

/* Its work space: n values each. */
typedef struct {
  double *xa, *r, *t, *fl, *b, *dxr, *dxf, *ox;
} pm_arc_work;
pm_err pm_arc_work_init(pm_arc_work *w, long n);
void pm_arc_work_free(pm_arc_work *w);

/* Arc-length continuation (Riks: predictor along the path's tangent,
 * corrector in its normal plane, the load factor an unknown, dr/dlambda
 * by a forward difference) from the converged state xc at lambda (xprev
 * at lambda_prev orients it) until the path passes target, then Newton at
 * target from the chord's point there; |r| <= goal ends a corrector.  x:
 * the state at target on success, else xc; the load is left at target.
 * Without options.follow_fold it stops where the load first falls along
 * the path (a limit point) and sets *limit to the highest load the path
 * reached (NAN otherwise).  Counts to rep (arc_*); msg (cap bytes) one
 * line of what it did.
 * PM_SUCCESS; PM_ERR_NOT_CONVERGED raised with that line; a hard failure
 * of a callback as it is.  One process only. */
pm_err pm_load_arc(pm_newton *s, double *x, const double *xc,
                   const double *xprev, double lambda, double lambda_prev,
                   double target, double goal, pm_arc_work *w,
                   pm_load_report *rep, double *limit, char *msg, long cap);

#endif
