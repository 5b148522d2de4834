/* Unit tests of the Newton line search against inadmissible trial states:
 * a trial whose residual is refused (an inverted point) or not finite (a
 * stress the model cannot evaluate) is shortened, not accepted, by
 * backtracking and by the whole step else the secant; and the latter takes
 * backtracking's very steps where every whole step passes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pm_newton.h"
#include "pm_testing.h"

/* r(x) = x^3 - 1 (root 1), with every x > 1.5 inadmissible: refused when
 * nan is false, a residual of NaN when true.  From x = 0.2 the full Newton
 * step goes to 8.47. */
typedef struct {
  bool nan;
  long refused;
} cubic;

static pm_err cubic_residual(void *ctx, const double *x, double *r) {
  cubic *c = ctx;
  if (x[0] > 1.5) {
    c->refused++;
    if (!c->nan)
      return PM_ERROR(PM_ERR_UNSTABLE, "x = %g past the limit", x[0]);
    r[0] = NAN;
    return PM_SUCCESS;
  }
  r[0] = x[0] * x[0] * x[0] - 1;
  return PM_SUCCESS;
}

static pm_err cubic_apply(void *ctx, const double *x, const double *dx,
                          double *dr) {
  (void)ctx;
  dr[0] = 3 * x[0] * x[0] * dx[0];
  return PM_SUCCESS;
}

/* x^3 - 1 = 0 solved from x (in place) to 1e-14 with line search ls; c
 * counts the refused trials. */
static void solve_cubic(cubic *c, pm_line_search ls, double *x,
                        pm_newton_report *rep) {
  long ptr[2] = {0, 1}, idx[1] = {0};
  pm_newton_problem prob = {.n = 1,
                            .ctx = c,
                            .residual = cubic_residual,
                            .jacobian_apply = cubic_apply,
                            .pat_ptr = ptr,
                            .pat_idx = idx};
  pm_newton_options opt = pm_newton_options_default();
  opt.rtol = 1e-14;
  opt.line_search = ls;
  pm_newton *s = NULL;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  assert_ok(pm_newton_solve(s, x, rep));
  pm_newton_destroy(&s);
}

static void test_inadmissible_trials(void **state) {
  (void)state;
  for (int k = 0; k < 4; k++) {
    const int nan = k % 2;
    const pm_line_search ls =
        k < 2 ? PM_LINE_SEARCH_BT : PM_LINE_SEARCH_FULL_L2;
    cubic c = {nan != 0, 0};
    double x = 0.2;
    pm_newton_report rep;
    solve_cubic(&c, ls, &x, &rep);
    print_message("%s, %s trials: %s in %d iterations, %ld residuals (%ld "
                  "refused), first step length %.3g, x - 1 = %.1e\n",
                  ls == PM_LINE_SEARCH_BT ? "backtracking"
                                          : "whole-then-secant",
                  nan ? "NaN" : "refused", pm_newton_reason_name(rep.reason),
                  rep.iterations, rep.residual_evaluations, c.refused,
                  rep.step_length[1], x - 1);
    assert_close(x, 1, 1e-13, 0);
    assert_true(c.refused >= 1);
    assert_true(rep.step_length[1] < 1);
    assert_true(rep.reason == PM_NEWTON_CONVERGED_RESIDUAL ||
                rep.reason == PM_NEWTON_CONVERGED_ABSOLUTE);
  }
}

/* From x = 1.2 every whole Newton step on x^3 - 1 lowers |r| (the cubic
 * is convex there): the whole step, else the secant, takes backtracking's
 * iterates to the last bit. */
static void test_whole_steps_as_backtracking(void **state) {
  (void)state;
  double x[2];
  pm_newton_report rep[2];
  for (int k = 0; k < 2; k++) {
    cubic c = {false, 0};
    x[k] = 1.2;
    solve_cubic(&c, k ? PM_LINE_SEARCH_FULL_L2 : PM_LINE_SEARCH_BT, &x[k],
                &rep[k]);
  }
  print_message("from x = 1.2: %d and %d iterations, %ld and %ld residuals, "
                "x - 1 = %.1e and %.1e\n",
                rep[0].iterations, rep[1].iterations,
                rep[0].residual_evaluations, rep[1].residual_evaluations,
                x[0] - 1, x[1] - 1);
  assert_int_equal(rep[1].iterations, rep[0].iterations);
  assert_int_equal(rep[1].residual_evaluations, rep[0].residual_evaluations);
  assert_true(x[1] == x[0]);
  for (int i = 0; i <= rep[0].iterations; i++)
    assert_true(rep[1].residual_norm[i] == rep[0].residual_norm[i]);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_inadmissible_trials),
      cmocka_unit_test(test_whole_steps_as_backtracking),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
