/* pm_newton_check: checks of a problem's linearisation: the Jacobian's
 * values at a state, and their largest difference from central differences
 * of the residual. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm_coloring.h"
#include "pm_newton_solver_impl.h"

pm_err pm_newton_jacobian_values(pm_newton *s, const double *x, double *val) {
  PM_CHECK(s && x && val, PM_ERR_ARG,
           "pm_newton_jacobian_values: solver, x and val are required");
  PM_CHECK(!s->dist, PM_ERR_UNSUPPORTED,
           "pm_newton_jacobian_values: one process's problems only");
  if (s->p.jacobian_prepare) PM_CALL(s->p.jacobian_prepare(s->p.ctx, x));
  double *vals;
  PM_CALL(pm_newton_jvals(s, &vals));
  PM_CALL(pm_newton_values_at(s, x, vals));
  for (long k = 0; k < s->jpat.nsrc; k++)
    val[k] = vals[s->jpat.src ? s->jpat.src[k] : k];
  return PM_SUCCESS;
}

pm_err pm_newton_check_jacobian(pm_newton *s, const double *x, double h,
                                double *max_error, long *row, long *col) {
  pm_err ret = PM_SUCCESS;
  double *xp = NULL, *rp = NULL, *rm = NULL, *column = NULL;
  PM_CHECK(s && x && max_error && h > 0, PM_ERR_ARG,
           "pm_newton_check_jacobian: solver, x, max_error and h > 0 are "
           "required (h %g)",
           h);
  PM_CHECK(!s->dist, PM_ERR_UNSUPPORTED,
           "pm_newton_check_jacobian: one process's problems only");
  long n = s->p.n;
  /* The pattern by columns (a caller-assembled Jacobian has no colouring
   * yet). */
  if (!s->jcol.col_ptr) {
    PM_CALL(pm_newton_pattern_columns(s));
    PM_CALL(pm_coloring_build(&s->jpat, s->o.coloring, &s->jcol));
  }
  const pm_coloring *c = &s->jcol;
  if (s->p.jacobian_prepare) PM_CALL(s->p.jacobian_prepare(s->p.ctx, x));
  double *vals;
  PM_CALL(pm_newton_jvals(s, &vals));
  PM_CALL(pm_newton_values_at(s, x, vals));
  PM_TRY(PM_ALLOC(xp, n, "perturbed state"));
  PM_TRY(PM_ALLOC(rp, n, "perturbed residual"));
  PM_TRY(PM_ALLOC(rm, n, "perturbed residual"));
  PM_TRY(PM_ALLOC(column, n, "Jacobian column"));
  memcpy(xp, x, (size_t)n * sizeof *xp);
  double worst = 0, largest = 0;
  long worst_row = 0, worst_col = 0;
  for (long j = 0; j < n; j++) {
    double step = h * fabs(x[j]) + h;
    xp[j] = x[j] + step;
    PM_TRY(s->p.residual(s->p.ctx, xp, rp));
    xp[j] = x[j] - step;
    PM_TRY(s->p.residual(s->p.ctx, xp, rm));
    xp[j] = x[j];
    for (long q = c->col_ptr[j]; q < c->col_ptr[j + 1]; q++)
      column[c->col_row[q]] = vals[c->col_pos[q]];
    for (long i = 0; i < n; i++) {
      double fd = (rp[i] - rm[i]) / (2 * step);
      double err = fabs(fd - column[i]);
      if (fabs(fd) > largest) largest = fabs(fd);
      if (!(err <= worst)) {
        worst = err;
        worst_row = i;
        worst_col = j;
      }
    }
    for (long q = c->col_ptr[j]; q < c->col_ptr[j + 1]; q++)
      column[c->col_row[q]] = 0;
  }
  *max_error = largest > 0 ? worst / largest : worst;
  if (row) *row = worst_row;
  if (col) *col = worst_col;
done:
  free(xp);
  free(rp);
  free(rm);
  free(column);
  return ret;
}
