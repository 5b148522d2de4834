/* Unit tests of the fallbacks' own linear solver
 * (pm_newton_set_fallback_linear): load stepping hands a step's fallbacks
 * to it and takes its own back after. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "pm_newton.h"
#include "pm_newton_impl.h"
#include "pm_testing.h"
#include "snap_through.h"

/* ---- The fallbacks' own linear solver ------------------------------------
 * The snap-through with GMRES + ILU(0) as the solver's linear solver and
 * the LU as its fallbacks' (pm_newton_set_fallback_linear): the same root
 * and snap as with one solver throughout; the Jacobians of the fallbacks
 * are made under the LU, those of the steps under GMRES, and the solver's
 * own settings are back after the run.  Bad settings are named. */
typedef struct {
  snap sn;
  pm_newton *s;
  int seen[PM_NEWTON_CG_GAMG + 1]; /* Jacobian products under each solver */
} snap_watched;

static pm_err watched_residual(void *ctx, const double *x, double *r) {
  return snap_residual(&((snap_watched *)ctx)->sn, x, r);
}

static pm_err watched_apply(void *ctx, const double *x, const double *dx,
                            double *dr) {
  snap_watched *w = ctx;
  if (w->s) w->seen[pm_newton_options_of(w->s)->linear]++;
  return snap_apply(&w->sn, x, dx, dr);
}

static pm_err watched_set_load(void *ctx, double lambda) {
  return snap_set_load(&((snap_watched *)ctx)->sn, lambda);
}

static void test_fallback_linear(void **state) {
  (void)state;
  snap_watched w = {.sn = {3.6, 0}};
  long ptr[2] = {0, 1}, idx[1] = {0};
  pm_newton_problem prob = {.n = 1,
                            .ctx = &w,
                            .residual = watched_residual,
                            .jacobian_apply = watched_apply,
                            .pat_ptr = ptr,
                            .pat_idx = idx,
                            .set_load = watched_set_load};
  pm_newton_options opt = fold_options();
  opt.linear = PM_NEWTON_GMRES_ILU;
  pm_newton_options alt = pm_newton_options_default();
  alt.linear = PM_NEWTON_DIRECT;
  alt.pc_reuse_its = 10;
  pm_load_report rep;

  /* one solver throughout, then the LU in the fallbacks */
  double x1 = sqrt(3), x2 = sqrt(3);
  pm_load_report one;
  assert_ok(pm_newton_create(&prob, &opt, &w.s));
  assert_ok(pm_load_steps(w.s, &x1, &one));
  assert_int_equal(w.seen[PM_NEWTON_DIRECT], 0);
  pm_newton_destroy(&w.s);
  memset(w.seen, 0, sizeof w.seen);
  assert_ok(pm_newton_create(&prob, &opt, &w.s));
  assert_ok(pm_newton_set_fallback_linear(w.s, &alt, false));
  assert_ok(pm_load_steps(w.s, &x2, &rep));
  print_message("GMRES + ILU(0) throughout: x = %.15f, %d snaps; with the LU "
                "in the fallbacks: x = %.15f, %d snaps, Jacobian products "
                "%d under GMRES, %d under the LU\n",
                x1, one.snap_steps, x2, rep.snap_steps,
                w.seen[PM_NEWTON_GMRES_ILU], w.seen[PM_NEWTON_DIRECT]);
  assert_close(x2, snap_root(3.6), 1e-9, 0);
  assert_close(x1, x2, 1e-12, 0);
  assert_int_equal(rep.snap_steps, 1);
  assert_int_equal(one.snap_steps, 1);
  assert_true(w.seen[PM_NEWTON_DIRECT] > 0);
  assert_true(w.seen[PM_NEWTON_GMRES_ILU] > 0);
  assert_int_equal(pm_newton_options_of(w.s)->linear, PM_NEWTON_GMRES_ILU);
  pm_newton_destroy(&w.s);
  /* kept once a step has fallen back: the state says so, and the LU
   * stays to the end */
  memset(w.seen, 0, sizeof w.seen);
  double x3 = sqrt(3);
  pm_load_state st;
  assert_ok(pm_load_state_init(&st, 1));
  assert_ok(pm_newton_create(&prob, &opt, &w.s));
  assert_ok(pm_newton_set_fallback_linear(w.s, &alt, true));
  assert_ok(pm_load_steps_from(w.s, &x3, &st, &rep));
  print_message("kept: x = %.15f, %d snaps, Jacobian products %d under "
                "GMRES, %d under the LU\n",
                x3, rep.snap_steps, w.seen[PM_NEWTON_GMRES_ILU],
                w.seen[PM_NEWTON_DIRECT]);
  assert_close(x3, x2, 1e-12, 0);
  assert_int_equal(st.fallback_kept, 1);
  assert_int_equal(pm_newton_options_of(w.s)->linear, PM_NEWTON_DIRECT);
  pm_load_state_free(&st);
  pm_newton_destroy(&w.s);
  /* settings out of range, named */
  assert_ok(pm_newton_create(&prob, &opt, &w.s));
  alt.linear_rtol = 2;
  assert_int_equal(pm_newton_set_fallback_linear(w.s, &alt, false), PM_ERR_ARG);
  assert_non_null(strstr(pm_error_message(), "linear_rtol 2"));
  pm_error_clear();
  pm_newton_destroy(&w.s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_fallback_linear),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
