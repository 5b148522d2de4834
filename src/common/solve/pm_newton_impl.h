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

/* r = the residual at x (both of the n owned values): the problem's
 * callback, through the held values of a shared problem (collective then,
 * with the ranks' agreed answer). */
pm_err pm_newton_residual(pm_newton *s, const double *x, double *r);

/* The Euclidean norm of v (the n owned values) over all ranks. */
double pm_newton_norm(const pm_newton *s, const double *v);

#endif
