/* pm_newton_impl: what load stepping uses of a Newton solver beyond the
 * public interface. */
#ifndef PM_NEWTON_IMPL_H
#define PM_NEWTON_IMPL_H

#include "pm_newton.h"

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

/* A resume's: the factorisation or preconditioner built at the owned
 * values x (under the load set), as if the last linear solve it served
 * took its iterations and failed or not: what the first run kept, made
 * again from the same values (collective across ranks).  A callback's
 * failure or PETSc's is returned. */
pm_err pm_newton_pc_rebuild(pm_newton *s, const double *x, int its,
                            bool failed);

/* r = the residual at x (both of the n owned values): the problem's
 * callback, through the held values of a shared problem (collective then,
 * with the ranks' agreed answer). */
pm_err pm_newton_residual(pm_newton *s, const double *x, double *r);

/* The Euclidean norm of v (the n owned values) over all ranks. */
double pm_newton_norm(const pm_newton *s, const double *v);

/* ---- pm_load_relax.c: dynamic relaxation within a load step ---- */

/* Its work space: n values each. */
typedef struct {
  double *mass, *v, *r, *rt, *xt;
} pm_relax_work;
pm_err pm_relax_work_init(pm_relax_work *w, long n);
void pm_relax_work_free(pm_relax_work *w);

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

#endif
