/* Unit tests of the shared Newton solver: quadratic convergence, the
 * stopping criteria, every linear solver and operator, and domain errors
 * (colouring: test_coloring; load stepping: test_load_steps). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_coloring.h"
#include "pm_newton.h"
#include "pm_newton_impl.h"
#include "pm_testing.h"
#include "newton_chain.h"

/* ---- Newton ------------------------------------------------------------ */

/* From rest to the full load in one solve: the solution is u*, and the
 * residual norms fall quadratically: r_{k+1} / r_k^2 stays bounded and the
 * observed order log(r_{k+1}/r_k) / log(r_k/r_{k-1}) is near 2 over the
 * last iterations. */
static void test_quadratic_convergence(void **state) {
  (void)state;
  chain ch;
  chain_init(&ch, 200, 2, 2);
  pm_newton_problem prob = chain_problem(&ch);
  pm_newton_options opt = pm_newton_options_default();
  opt.rtol = 1e-13;
  pm_newton_report rep;
  assert_ok(chain_solve(&ch, &prob, &opt, &rep));
  double *x = ch.x;
  assert_int_equal(rep.reason, PM_NEWTON_CONVERGED_RESIDUAL);
  assert_int_equal(rep.status, PM_SUCCESS);
  assert_true(rep.iterations >= 4 && rep.iterations <= 12);
  assert_true(chain_error(&ch, x, 1.0) < 1e-12);
  assert_int_equal(ch.prepares, rep.iterations);
  assert_int_equal(rep.jacobian_applications, 5L * rep.iterations);

  const double *r = rep.residual_norm;
  int last = rep.iterations, pairs = 0;
  double order_min = 1e300;
  for (int k = 1; k < last; k++) {
    /* Asymptotic range: well below the start, above roundoff. */
    if (!(r[k] < 0.05 * r[0] && r[k + 1] > 1e-11 * r[0])) continue;
    double c = r[k + 1] / (r[k] * r[k]);
    double order = log(r[k + 1] / r[k]) / log(r[k] / r[k - 1]);
    print_message("iteration %d: |r| %.3e, r_k+1/r_k^2 %.3e, order %.2f\n",
                  k + 1, r[k + 1], c, order);
    assert_true(c * r[0] < 50);
    order_min = fmin(order_min, order);
    pairs++;
  }
  assert_true(pairs >= 2);
  assert_true(order_min > 1.8);

  print_message("n %ld, %d iterations, %d colours: residual %.3f ms, "
                "assembly %.3f ms, linear %.3f ms, total %.3f ms\n",
                ch.n, rep.iterations, 5, 1e3 * rep.time_residual,
                1e3 * rep.time_assembly, 1e3 * rep.time_linear,
                1e3 * rep.time_total);
  assert_true(rep.time_total >= rep.time_residual + rep.time_assembly);
  for (int k = 1; k <= last; k++) {
    assert_true(rep.increment_norm[k] > 0);
    assert_true(rep.step_length[k] > 0 && rep.step_length[k] <= 1);
  }

  /* The same for the error e_k = |x_k - u*| / |u*|, each x_k from a solve
   * stopped after k iterations. */
  double e[8];
  int m = 0;
  for (int k = 1; k <= 6; k++, m++) {
    pm_newton_options stop = opt;
    stop.max_iter = k;
    stop.rtol = 1e-300;
    assert_int_equal(chain_solve(&ch, &prob, &stop, &rep),
                     PM_ERR_NOT_CONVERGED);
    pm_error_clear();
    e[m] = chain_error(&ch, x, 1.0);
  }
  pairs = 0;
  for (int k = 1; k + 1 < m; k++) {
    if (!(e[k] < 0.05 && e[k + 1] > 1e-13)) continue;
    double c = e[k + 1] / (e[k] * e[k]);
    double order = log(e[k + 1] / e[k]) / log(e[k] / e[k - 1]);
    print_message("error after %d iterations %.3e: e_k+1/e_k^2 %.3e, order "
                  "%.2f\n",
                  k + 2, e[k + 1], c, order);
    assert_true(c < 10);
    assert_true(order > 1.8);
    pairs++;
  }
  assert_true(pairs >= 2);

  /* Solving again from the solution converges at once (absolute floor
   * on, or r0 = 0 exactly). */
  opt.atol = 1e-9;
  pm_newton *s = NULL;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  for (long i = 0; i < ch.n; i++) x[i] = exact(&ch, 1, i + 1);
  assert_ok(pm_newton_solve(s, x, &rep));
  assert_int_equal(rep.iterations, 0);
  assert_int_equal(rep.reason, PM_NEWTON_CONVERGED_ABSOLUTE);
  pm_newton_destroy(&s);
  chain_free(&ch);
}

/* Each criterion alone stops the solve by itself with the solution
 * reached; all_criteria waits for both. */
static void test_criteria(void **state) {
  (void)state;
  chain ch;
  chain_init(&ch, 100, 2, 2);
  pm_newton_problem prob = chain_problem(&ch);
  struct {
    double rtol, dtol, etol;
    bool all;
    pm_newton_reason want;
  } cases[] = {
      {1e-10, 0, 0, false, PM_NEWTON_CONVERGED_RESIDUAL},
      {0, 1e-10, 0, false, PM_NEWTON_CONVERGED_DISPLACEMENT},
      {0, 0, 1e-20, false, PM_NEWTON_CONVERGED_ENERGY},
      {0, 1e-10, 1e-20, true, PM_NEWTON_CONVERGED_ALL},
  };
  int its[4];
  for (int c = 0; c < 4; c++) {
    pm_newton_options opt = pm_newton_options_default();
    opt.rtol = cases[c].rtol;
    opt.dtol = cases[c].dtol;
    opt.etol = cases[c].etol;
    opt.all_criteria = cases[c].all;
    pm_newton_report rep;
    assert_ok(chain_solve(&ch, &prob, &opt, &rep));
    const double *x = ch.x;
    assert_int_equal(rep.reason, cases[c].want);
    its[c] = rep.iterations;
    int k = rep.iterations;
    print_message("%s: %d iterations, |dx| %.2e, |dx.r| %.2e (first %.2e), "
                  "error %.2e\n",
                  pm_newton_reason_name(rep.reason), k, rep.increment_norm[k],
                  rep.energy[k], rep.energy[1], chain_error(&ch, x, 1));
    assert_true(chain_error(&ch, x, 1.0) < 1e-9);
    if (cases[c].etol > 0)
      assert_true(rep.energy[k] <= cases[c].etol * rep.energy[1]);
    assert_true(k >= 2);
  }
  assert_true(its[3] >= its[1] && its[3] >= its[2]);
  chain_free(&ch);
}

/* Every linear solver with every operator solves the problem to the same
 * solution; CG + Jacobi since the chain's J is symmetric positive
 * definite. */
static void test_linear_solvers(void **state) {
  (void)state;
  chain ch;
  chain_init(&ch, 150, 2, 2);
  pm_newton_problem prob = chain_problem(&ch);
  prob.precond_apply = chain_apply_nearest;
  long *tri_ptr, *tri_idx;
  band_pattern(ch.n, 1, &tri_ptr, &tri_idx);
  prob.pc_pat_ptr = tri_ptr;
  prob.pc_pat_idx = tri_idx;
  static const char *lin[] = {"direct", "gmres-gamg", "cg-jacobi", "gmres-ilu"};
  static const char *ops[] = {"assembled", "matrix-free",
                              "matrix-free, cheap pc"};
  for (int l = 0; l < 4; l++)
    for (int o = 0; o < 3; o++) {
      pm_newton_options opt = pm_newton_options_default();
      opt.rtol = 1e-10;
      opt.linear = (pm_newton_linear)l;
      opt.op = (pm_newton_operator)o;
      pm_newton *s = NULL;
      assert_ok(pm_newton_create(&prob, &opt, &s));
      assert_int_equal(pm_newton_pc_colors(s), o == 2 ? 3 : 0);
      pm_newton_destroy(&s);
      pm_newton_report rep;
      assert_ok(chain_solve(&ch, &prob, &opt, &rep));
      print_message("%-10s %-22s: %2d Newton, %4d linear iterations, "
                    "%.2f ms (linear %.2f ms), error %.1e\n",
                    lin[l], ops[o], rep.iterations, rep.linear_iterations,
                    1e3 * rep.time_total, 1e3 * rep.time_linear,
                    chain_error(&ch, ch.x, 1));
      assert_true(chain_error(&ch, ch.x, 1.0) < 1e-8);
      assert_true(rep.iterations <= 12);
    }
  /* Near-null vectors for multigrid (a constant, a dependent copy that is
   * dropped, a ramp): the same solution. */
  double *nn = malloc(3 * (size_t)ch.n * sizeof *nn);
  assert_non_null(nn);
  for (long i = 0; i < ch.n; i++) {
    nn[i] = 1;
    nn[ch.n + i] = 2;
    nn[2 * ch.n + i] = (double)i;
  }
  prob.near_null_count = 3;
  prob.near_null = nn;
  pm_newton_options opt = pm_newton_options_default();
  opt.rtol = 1e-10;
  opt.linear = PM_NEWTON_GMRES_GAMG;
  pm_newton_report rep;
  assert_ok(chain_solve(&ch, &prob, &opt, &rep));
  print_message("gmres-gamg with 3 near-null vectors: %d Newton, %d linear "
                "iterations, error %.1e\n",
                rep.iterations, rep.linear_iterations,
                chain_error(&ch, ch.x, 1));
  assert_true(chain_error(&ch, ch.x, 1.0) < 1e-8);
  free(nn);
  free(tri_ptr);
  free(tri_idx);
  chain_free(&ch);
}

/* PETSc options with the "pm_" prefix override the struct: Jacobi-
 * preconditioned GMRES in place of LU takes many linear iterations. */
static void test_petsc_options(void **state) {
  (void)state;
  chain ch;
  chain_init(&ch, 80, 2, 2);
  pm_newton_problem prob = chain_problem(&ch);
  pm_newton_options opt = pm_newton_options_default();
  opt.petsc_options = "-pm_ksp_type gmres -pm_pc_type jacobi "
                      "-pm_ksp_rtol 1e-12";
  pm_newton_report rep;
  assert_ok(chain_solve(&ch, &prob, &opt, &rep));
  assert_true(rep.linear_iterations > 5 * rep.iterations);
  assert_true(chain_error(&ch, ch.x, 1.0) < 1e-8);

  /* A cap on the linear iterations (pm_newton_cap_linear, the relaxation's
   * Newton in load stepping): at 2 a solve stops there and Newton fails on
   * it, named; lifted, the same solver converges as before. */
  pm_newton *s = NULL;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  pm_newton_cap_linear(s, 2);
  memset(ch.x, 0, (size_t)ch.n * sizeof *ch.x);
  pm_err e = pm_newton_solve(s, ch.x, &rep);
  print_message("capped at 2 linear iterations: %s\n", pm_error_message());
  assert_int_equal(e, PM_ERR_NOT_CONVERGED);
  assert_int_equal(rep.reason, PM_NEWTON_DIVERGED_LINEAR);
  assert_true(rep.linear_iterations <= 2 * (rep.iterations + 1));
  assert_non_null(strstr(pm_error_message(), "iteration limit"));
  pm_error_clear();
  pm_newton_cap_linear(s, 0);
  memset(ch.x, 0, (size_t)ch.n * sizeof *ch.x);
  assert_ok(pm_newton_solve(s, ch.x, &rep));
  assert_true(rep.linear_iterations > 5 * rep.iterations);
  assert_true(chain_error(&ch, ch.x, 1.0) < 1e-8);
  pm_newton_destroy(&s);

  /* An option PETSc rejects inside the solve is an error with PETSc's
   * message, not a failed step. */
  opt.petsc_options = "-pm_pc_type lu -pm_pc_factor_mat_solver_type nonesuch";
  assert_int_equal(chain_solve(&ch, &prob, &opt, &rep), PM_ERR_LINALG);
  print_message("%s\n", pm_error_message());
  assert_non_null(strstr(pm_error_message(), "nonesuch"));
  pm_error_clear();
  chain_free(&ch);
}

/* Failures: an inadmissible start, a NaN residual, too few iterations, a
 * hard callback failure, and bad options, each with its reason and a
 * message that says so. */
static void test_failures(void **state) {
  (void)state;
  chain ch;
  chain_init(&ch, 20, 1, 1);
  pm_newton_problem prob = chain_problem(&ch);
  pm_newton_options opt = pm_newton_options_default();
  pm_newton *s = NULL;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  double x[20] = {0};
  pm_newton_report rep;

  x[5] = -1.0; /* node 6 behind node 5: spring 5 inverted */
  assert_int_equal(pm_newton_solve(s, x, &rep), PM_ERR_UNSTABLE);
  assert_int_equal(rep.reason, PM_NEWTON_DIVERGED_DOMAIN);
  assert_non_null(strstr(rep.message, "initial state is inadmissible"));
  assert_non_null(strstr(rep.message, "spring from node 5 inverted"));
  assert_non_null(strstr(pm_error_message(), "spring from node 5"));
  assert_true(x[5] == -1.0);

  memset(x, 0, sizeof x);
  /* A residual not finite is an inadmissible state. */
  ch.nan_residual = true;
  assert_int_equal(pm_newton_solve(s, x, &rep), PM_ERR_UNSTABLE);
  assert_int_equal(rep.reason, PM_NEWTON_DIVERGED_DOMAIN);
  assert_non_null(strstr(rep.message, "residual not finite at unknown"));
  ch.nan_residual = false;

  ch.hard_failure = true;
  assert_int_equal(pm_newton_solve(s, x, &rep), PM_ERR_MEMORY);
  assert_non_null(strstr(pm_error_message(), "test residual"));
  ch.hard_failure = false;
  pm_newton_destroy(&s);

  opt.max_iter = 2;
  opt.rtol = 1e-12;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  memset(x, 0, sizeof x);
  assert_int_equal(pm_newton_solve(s, x, &rep), PM_ERR_NOT_CONVERGED);
  assert_int_equal(rep.reason, PM_NEWTON_DIVERGED_MAX_ITER);
  assert_non_null(strstr(rep.message, "did not converge in 2 iterations"));
  assert_true(x[3] != 0); /* the last iterate */
  pm_newton_destroy(&s);

  opt = pm_newton_options_default();
  opt.rtol = 0;
  assert_int_equal(pm_newton_create(&prob, &opt, &s), PM_ERR_ARG);
  assert_non_null(strstr(pm_error_message(), "convergence criterion"));
  opt = pm_newton_options_default();
  opt.op = PM_NEWTON_MATRIX_FREE_CHEAP_PC;
  assert_int_equal(pm_newton_create(&prob, &opt, &s), PM_ERR_ARG);
  assert_non_null(strstr(pm_error_message(), "precond_apply"));
  assert_null(s);
  pm_error_clear();
  chain_free(&ch);
}

/* r(x) = x - 2 with every x >= 1 inadmissible: each step is shortened to
 * stay below 1 until no admissible step is left; the state returned is
 * admissible and the message names the cause. */
static pm_err wall_residual(void *ctx, const double *x, double *r) {
  (void)ctx;
  if (x[0] >= 1)
    return PM_ERROR(PM_ERR_UNSTABLE, "x = %g beyond the wall", x[0]);
  r[0] = x[0] - 2;
  return PM_SUCCESS;
}

static pm_err wall_apply(void *ctx, const double *x, const double *dx,
                         double *dr) {
  (void)ctx;
  (void)x;
  dr[0] = dx[0];
  return PM_SUCCESS;
}

static void test_no_admissible_step(void **state) {
  (void)state;
  long ptr[2] = {0, 1}, idx[1] = {0};
  pm_newton_problem prob = {.n = 1,
                            .residual = wall_residual,
                            .jacobian_apply = wall_apply,
                            .pat_ptr = ptr,
                            .pat_idx = idx};
  pm_newton_options opt = pm_newton_options_default();
  opt.max_iter = PM_NEWTON_MAX_ITER;
  pm_newton *s = NULL;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  double x = 0;
  pm_newton_report rep;
  assert_int_equal(pm_newton_solve(s, &x, &rep), PM_ERR_UNSTABLE);
  print_message("%s (x = %.17g)\n", rep.message, x);
  assert_int_equal(rep.reason, PM_NEWTON_DIVERGED_DOMAIN);
  assert_non_null(strstr(rep.message, "no admissible step in iteration"));
  assert_non_null(strstr(rep.message, "beyond the wall"));
  assert_true(x < 1 && x > 0.999);
  assert_true(rep.step_length[1] < 1);
  pm_error_clear();
  pm_newton_destroy(&s);

  /* With stall_after, the creep toward the wall (the residual stuck near
   * 1) stops as stalled at that iteration, a failure load stepping cuts. */
  opt.stall_after = 4;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  x = 0;
  assert_int_equal(pm_newton_solve(s, &x, &rep), PM_ERR_NOT_CONVERGED);
  print_message("%s\n", rep.message);
  assert_int_equal(rep.reason, PM_NEWTON_DIVERGED_STALLED);
  assert_int_equal(rep.iterations, 4);
  assert_true(rep.residual_norm[4] > 0.5 * rep.residual_norm[2]);
  assert_non_null(strstr(rep.message, "not halved over iterations 3 and 4"));
  assert_string_equal(pm_newton_reason_name(rep.reason), "diverged (stalled)");
  pm_error_clear();
  pm_newton_destroy(&s);
  opt.stall_after = 1;
  assert_int_equal(pm_newton_create(&prob, &opt, &s), PM_ERR_ARG);
  assert_non_null(strstr(pm_error_message(), "stall_after"));
  pm_error_clear();

  /* With stall_linear, from the second iteration once its linear solves
   * have taken more iterations than that (the LU: one a solve). */
  opt.stall_after = 0;
  opt.stall_linear = 1;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  x = 0;
  assert_int_equal(pm_newton_solve(s, &x, &rep), PM_ERR_NOT_CONVERGED);
  print_message("%s (%d linear iterations)\n", rep.message,
                rep.linear_iterations);
  assert_int_equal(rep.reason, PM_NEWTON_DIVERGED_STALLED);
  assert_int_equal(rep.iterations, 2);
  assert_true(rep.linear_iterations > 1);
  pm_error_clear();
  pm_newton_destroy(&s);
  opt.stall_linear = -1;
  assert_int_equal(pm_newton_create(&prob, &opt, &s), PM_ERR_ARG);
  assert_non_null(strstr(pm_error_message(), "stall_linear"));
  pm_error_clear();
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_quadratic_convergence),
      cmocka_unit_test(test_criteria),
      cmocka_unit_test(test_linear_solvers),
      cmocka_unit_test(test_petsc_options),
      cmocka_unit_test(test_failures),
      cmocka_unit_test(test_no_admissible_step),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
