/* snap_through: the one-unknown snap-through of the load-stepping tests
 * (test_load_steps, test_fallback_linear) and their options through a
 * fold. */
#ifndef SNAP_THROUGH_H
#define SNAP_THROUGH_H

#include <math.h>
#include <stdio.h>

#include "pm_newton.h"

/* ---- Snap-through: r(x) = x^3 - 3 x + q lambda, x = sqrt(3) at rest --------
 * The energy x^4/4 - 3 x^2/2 + q lambda x has its right well until q lambda
 * = 2 (a limit point at x = 1, lambda = 2/q); past it the only equilibrium
 * is in the left well, which Newton cannot reach from the right (the
 * residual's norm has its minimum at the limit point) but relaxation,
 * going downhill, does. */
typedef struct {
  double q, lambda;
} snap;

static inline pm_err snap_residual(void *ctx, const double *x, double *r) {
  const snap *sn = ctx;
  r[0] = x[0] * x[0] * x[0] - 3 * x[0] + sn->q * sn->lambda;
  return PM_SUCCESS;
}

static inline pm_err snap_apply(void *ctx, const double *x, const double *dx,
                                double *dr) {
  (void)ctx;
  dr[0] = (3 * x[0] * x[0] - 3) * dx[0];
  return PM_SUCCESS;
}

static inline pm_err snap_set_load(void *ctx, double lambda) {
  ((snap *)ctx)->lambda = lambda;
  return PM_SUCCESS;
}

static inline pm_err snap_diagnose(void *ctx, const double *x, char *buf,
                                   long cap) {
  (void)ctx;
  snprintf(buf, (size_t)cap, "x = %.4f", x[0]);
  return PM_SUCCESS;
}

/* The real root of x^3 - 3 x + c (c > 2: one real root), by Cardano. */
static inline double snap_root(double c) {
  double d = sqrt(c * c / 4 - 1);
  return cbrt(-c / 2 + d) + cbrt(-c / 2 - d);
}

/* Load stepping through a fold: tight Newton, six cuts, the fallbacks
 * (arc length, continuation, relaxation) after two. */
static inline pm_newton_options fold_options(void) {
  pm_newton_options opt = pm_newton_options_default();
  opt.rtol = 1e-10;
  opt.stall_after = 6;
  opt.max_cuts = 6;
  opt.relax_after = 2;
  opt.ptc_max_iter = 60;
  return opt;
}

#endif
