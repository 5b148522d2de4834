/* Unit tests of load stepping's branch tools on the shared Newton solver:
 * the tangent's lowest mode by inverse iteration (also where the tangent
 * is indefinite), and arc length round a limit point (load stepping:
 * test_load_steps). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_newton.h"
#include "pm_newton_impl.h"
#include "pm_testing.h"
#include "snap_through.h"

/* ---- The lowest mode and the branch switch ----------------------------- */

#define PM_TEST_PI 3.14159265358979323846

/* r = K x, K = tridiag(-1, 2, -1) - beta I of n unknowns. */
typedef struct {
  long n;
  double beta;
} shifted_chain;

static pm_err sc_residual(void *ctx, const double *x, double *r) {
  const shifted_chain *c = ctx;
  for (long i = 0; i < c->n; i++)
    r[i] = (2 - c->beta) * x[i] - (i > 0 ? x[i - 1] : 0) -
           (i + 1 < c->n ? x[i + 1] : 0);
  return PM_SUCCESS;
}

static pm_err sc_apply(void *ctx, const double *x, const double *dx,
                       double *dr) {
  (void)x;
  return sc_residual(ctx, dx, dr);
}

/* Inverse iteration finds K's eigenvalue nearest zero, 2 - 2 cos(pi /
 * (n + 1)) - beta, and its mode sin(pi i / (n + 1)) (unit masses), also
 * where K is indefinite. */
static void test_lowest_mode(void **state) {
  (void)state;
  enum { N = 20 };
  long ptr[N + 1], idx[3 * N], k = 0;
  for (long i = 0; i < N; i++) {
    ptr[i] = k;
    for (long j = i - 1; j <= i + 1; j++)
      if (j >= 0 && j < N) idx[k++] = j;
  }
  ptr[N] = k;
  const double mu1 = 2 - 2 * cos(PM_TEST_PI / (N + 1));
  const double betas[2] = {0.5 * mu1, 1.3 * mu1}; /* definite, indefinite */
  for (int t = 0; t < 2; t++) {
    shifted_chain c = {N, betas[t]};
    pm_newton_problem prob = {.n = N,
                              .ctx = &c,
                              .residual = sc_residual,
                              .jacobian_apply = sc_apply,
                              .pat_ptr = ptr,
                              .pat_idx = idx};
    pm_newton_options opt = pm_newton_options_default();
    pm_newton *s = NULL;
    assert_ok(pm_newton_create(&prob, &opt, &s));
    double x[N] = {0}, m[N], v[N], u[N], b[N], q = 0;
    for (long i = 0; i < N; i++) m[i] = 1;
    int its = 0;
    pm_load_report rep;
    memset(&rep, 0, sizeof rep);
    assert_ok(pm_load_lowest_mode(s, x, m, v, u, b, &rep, &q, &its));
    const double exact = mu1 - betas[t];
    double err = 0, sign = v[N / 2] > 0 ? 1 : -1, norm = 0;
    for (long i = 0; i < N; i++)
      norm += pow(sin(PM_TEST_PI * (i + 1) / (N + 1)), 2);
    for (long i = 0; i < N; i++)
      err = fmax(err, fabs(sign * v[i] -
                           sin(PM_TEST_PI * (i + 1) / (N + 1)) / sqrt(norm)));
    print_message("beta %.4f: eigenvalue %.10f against %.10f, %d "
                  "iterations, mode within %.2e\n",
                  betas[t], q, exact, its, err);
    assert_close(q, exact, 1e-6, 0);
    assert_true(err < 1e-4);
    pm_newton_destroy(&s);
  }
}

/* A local snap driven by a stiff load path: r_x = k (x - lambda) + c y,
 * r_y = y^3 - 3 y + c x (the gradient of an energy).  y snaps from its
 * upper root when c x passes 2: the tangent's lowest mode (mostly y) goes
 * to zero there (a limit point, the eigenvalue positive before it),
 * Newton stalls at every step size; arc length finds the load turning
 * back and relaxation carries the step to the lower root, the state the
 * snap ends in (with follow_fold, the arc follows the path round the fold,
 * the load falling, then rising again, to the same root). */
typedef struct {
  double k, c, lambda;
} snap2;

static pm_err snap2_residual(void *ctx, const double *x, double *r) {
  const snap2 *p = ctx;
  r[0] = p->k * (x[0] - p->lambda) + p->c * x[1];
  r[1] = x[1] * x[1] * x[1] - 3 * x[1] + p->c * x[0];
  return PM_SUCCESS;
}

static pm_err snap2_apply(void *ctx, const double *x, const double *dx,
                          double *dr) {
  const snap2 *p = ctx;
  dr[0] = p->k * dx[0] + p->c * dx[1];
  dr[1] = p->c * dx[0] + (3 * x[1] * x[1] - 3) * dx[1];
  return PM_SUCCESS;
}

static pm_err snap2_set_load(void *ctx, double lambda) {
  ((snap2 *)ctx)->lambda = lambda;
  return PM_SUCCESS;
}

static void test_arc_length(void **state) {
  (void)state;
  snap2 p = {100, 3.6, 0};
  long ptr[3] = {0, 2, 4}, idx[4] = {0, 1, 0, 1};
  pm_newton_problem prob = {.n = 2,
                            .ctx = &p,
                            .residual = snap2_residual,
                            .jacobian_apply = snap2_apply,
                            .pat_ptr = ptr,
                            .pat_idx = idx,
                            .set_load = snap2_set_load};
  pm_newton_options opt = fold_options();
  pm_newton *s = NULL;
  pm_load_report rep;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  double x[2] = {0, sqrt(3)};
  assert_ok(pm_load_steps(s, x, &rep));
  /* the exact end: y^3 - 3 y + c x = 0 with x = 1 - c y / k */
  double y = x[1];
  for (int i = 0; i < 50; i++) {
    const double f = y * y * y - 3 * y + p.c * (1 - p.c * y / p.k);
    const double df = 3 * y * y - 3 - p.c * p.c / p.k;
    y -= f / df;
  }
  print_message("%d steps, %d cuts, %d lowest modes (smallest eigenvalue "
                "%.2e), %d arc lengths (%d passed; %ld arcs, %ld iterations), "
                "%d continuations, %d relaxations: y = %.15f against %.15f\n"
                "%s\n",
                rep.steps, rep.cuts, rep.mode_runs, rep.mode_eigenvalue,
                rep.arc_runs, rep.arc_passes, rep.arc_steps, rep.arc_iterations,
                rep.ptc_runs, rep.relaxations, x[1], y, rep.mode_note);
  assert_close(rep.lambda, 1, 0, 0);
  assert_true(y < -1);
  assert_close(x[1], y, 1e-9, 0);
  assert_close(x[0], 1 - p.c * y / p.k, 1e-9, 0);
  assert_true(rep.mode_runs >= 1);
  assert_true(rep.mode_eigenvalue > 0);
  assert_int_equal(rep.snap_steps, 1);
  assert_int_equal(rep.ptc_runs, 0);
  pm_newton_destroy(&s);

  /* follow_fold: arc length round the fold to the same root */
  opt.follow_fold = true;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  x[0] = 0;
  x[1] = sqrt(3);
  assert_ok(pm_load_steps(s, x, &rep));
  print_message("following the fold: %d arc lengths (%d passed; %ld arcs), "
                "%d relaxations: y = %.15f\n",
                rep.arc_runs, rep.arc_passes, rep.arc_steps, rep.relaxations,
                x[1]);
  assert_close(x[1], y, 1e-9, 0);
  assert_true(rep.arc_passes >= 1);
  assert_int_equal(rep.ptc_runs, 0);
  assert_int_equal(rep.relaxations, 0);
  pm_newton_destroy(&s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_lowest_mode),
      cmocka_unit_test(test_arc_length),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
