/* Unit tests of load stepping on the shared Newton solver: steps cut and
 * grown (a run that completes), the iterations' bound, a load that no
 * step can carry, named with its cause, the relaxation fallback
 * through a limit point where Newton stalls (the tangent's lowest mode
 * and arc length: test_load_branch). */
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
#include "snap_through.h"

/* ---- Load stepping ----------------------------------------------------- */

/* Steps of 1/4 with an inadmissible jump above 0.1: the first is cut to
 * 1/16 (two cuts), steps grow by half after two converged ones and are cut
 * again past the limit, and the run reaches lambda = 1 on u*; on_step sees
 * each converged step. */
/* The chain with an inadmissible load jump above 0.1, and options of
 * steps of 1/4 to 1e-10. */
static pm_newton_options jump_chain(chain *ch, pm_newton_problem *prob) {
  chain_init(ch, 60, 2, 2);
  ch->jump_limit = 0.1;
  *prob = chain_problem(ch);
  pm_newton_options opt = pm_newton_options_default();
  opt.load_steps = 4;
  opt.rtol = 1e-10;
  return opt;
}

static void test_load_steps_cut(void **state) {
  (void)state;
  chain ch;
  pm_newton_problem prob;
  pm_newton_options opt = jump_chain(&ch, &prob);
  pm_load_report rep;
  assert_ok(chain_load_steps(&ch, &prob, &opt, &rep));
  print_message("jump limit 0.1, steps of 0.25: %d steps, %d cuts, smallest "
                "dlambda %g, %d Newton iterations, %.1f ms\n",
                rep.steps, rep.cuts, rep.dlambda_min, rep.newton_iterations,
                1e3 * rep.time_total);
  assert_true(rep.cuts >= 2);
  assert_true(rep.lambda == 1.0);
  assert_true(ch.lambda_done == 1.0);
  /* Every step at or below the limit, none below a cut of the largest
   * admissible one (0.1 / 2). */
  assert_true(rep.dlambda_min >= 0.05 && rep.dlambda_min <= 0.0625);
  assert_true(rep.steps >= 10 && rep.steps <= 20);
  assert_true(chain_error(&ch, ch.x, 1.0) < 1e-9);

  /* Without cutting room the same run fails at the first step. */
  opt.max_cuts = 1;
  assert_int_equal(chain_load_steps(&ch, &prob, &opt, &rep), PM_ERR_UNSTABLE);
  const char *msg = pm_error_message();
  print_message("%s\n", msg);
  assert_non_null(strstr(msg, "load step 1 (lambda 0 -> 0.125)"));
  assert_non_null(strstr(msg, "load jump 0.125 above 0.1"));
  assert_non_null(strstr(msg, "cut 1 times to dlambda 0.125: giving up"));
  assert_int_equal(rep.steps, 0);
  assert_true(ch.lambda == 0.0); /* the load of the state returned */
  pm_error_clear();
  chain_free(&ch);
}

/* Too few Newton iterations for the whole load at once: without the
 * predictor the step is cut until it converges; with it, the first step
 * starts from the tangent predictor (the linear response to the load
 * increment), which leaves Newton only the nonlinear remainder: no cut
 * and fewer iterations. */
/* The chain pulled twice as far as its default, and the options of one
 * load step to 1e-9. */
static pm_newton_problem far_chain(chain *ch) {
  chain_init(ch, 60, 2, 2);
  ch->amp *= 2;
  return chain_problem(ch);
}

static pm_newton_options one_step(void) {
  pm_newton_options opt = pm_newton_options_default();
  opt.load_steps = 1;
  opt.rtol = 1e-9;
  return opt;
}

static void test_load_steps_iterations(void **state) {
  (void)state;
  chain ch;
  pm_newton_problem prob = far_chain(&ch);
  int iterations[2];
  for (int predictor = 0; predictor < 2; predictor++) {
    pm_newton_options opt = one_step();
    opt.max_iter = 4;
    opt.predictor = predictor;
    pm_load_report rep;
    assert_ok(chain_load_steps(&ch, &prob, &opt, &rep));
    print_message("max_iter 4, %s: %d steps, %d cuts, %d Newton iterations\n",
                  predictor ? "predictor" : "no predictor", rep.steps, rep.cuts,
                  rep.newton_iterations);
    assert_true(predictor ? rep.cuts == 0 : rep.cuts >= 1);
    assert_true(chain_error(&ch, ch.x, 1.0) < 1e-8);
    iterations[predictor] = rep.newton_iterations;
  }
  assert_true(iterations[1] < iterations[0]);
  chain_free(&ch);
}

/* Steps relaxed first (relax_first, a resumed state whose last step
 * relaxation carried) whose start is inadmissible before relaxation's
 * first iteration (a load jump above 0.1, as a point beside a moved face
 * inverts when the face travels too far in one step): the step is cut and
 * relaxed first again, and every step of the run is carried by relaxation
 * to u*; before, the first such failure went the ordinary way (Newton,
 * cut there) and no later step was relaxed first. */
static void test_load_steps_relaxed_first_cut(void **state) {
  (void)state;
  chain ch;
  pm_newton_problem prob;
  pm_newton_options opt = jump_chain(&ch, &prob);
  opt.relax_after = 2;
  opt.relax_first = true;
  pm_newton *s = NULL;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  pm_load_state st;
  assert_ok(pm_load_state_init(&st, ch.n));
  st.lambda = 1e-6;
  st.dl = 1.0 / opt.load_steps;
  st.relax_first = st.relax_carried = 1;
  memset(ch.x, 0, (size_t)ch.n * sizeof *ch.x);
  ch.lambda_done = 0;
  pm_load_report rep;
  memset(&rep, 0, sizeof rep);
  rep.dlambda_min = st.dl;
  assert_ok(pm_load_steps_from(s, ch.x, &st, &rep));
  print_message("relaxed first, jump limit 0.1, steps of 0.25: %d steps, %d "
                "cuts, smallest dlambda %g, %d steps relaxed, %ld relaxation "
                "iterations, error %.2e\n",
                rep.steps, rep.cuts, rep.dlambda_min, rep.relaxed_steps,
                rep.relax_iterations, chain_error(&ch, ch.x, 1.0));
  assert_true(rep.lambda == 1.0);
  assert_true(rep.cuts >= 2);
  assert_true(rep.dlambda_min <= 0.1 && rep.dlambda_min >= 0.05);
  assert_int_equal(rep.relaxed_steps, rep.steps);
  assert_int_equal(st.relax_first, 1);
  assert_true(chain_error(&ch, ch.x, 1.0) < 1e-8);
  pm_load_state_free(&st);
  pm_newton_destroy(&s);
  chain_free(&ch);
}

/* A factorisation kept over Newton iterations (pc_reuse_its) and a load
 * step large enough to leave it stale: GMRES on the kept LU cannot meet
 * its tolerance within linear_max_iter.  Without pc_reuse_cost that linear
 * failure fails Newton and cuts the step; with it the solve is made again
 * on a new factorisation from the same iterate: no cut, and the state is
 * the same to the tolerance. */
static void test_load_steps_stale_factorisation(void **state) {
  (void)state;
  chain ch;
  pm_newton_problem prob = far_chain(&ch);
  pm_load_report rep[2];
  for (int cost = 0; cost < 2; cost++) {
    pm_newton_options opt = one_step();
    opt.predictor = true;
    opt.pc_reuse_its = 2;
    opt.linear_max_iter = 3;
    opt.pc_reuse_cost = cost;
    pm_err e = chain_load_steps(&ch, &prob, &opt, &rep[cost]);
    print_message("pc_reuse_cost %d: %s, %d steps, %d cuts, %d Newton, %d "
                  "linear iterations, %d set-ups\n",
                  cost, e == PM_SUCCESS ? "completed" : pm_error_message(),
                  rep[cost].steps, rep[cost].cuts, rep[cost].newton_iterations,
                  rep[cost].linear_iterations, rep[cost].pc_setups);
    if (cost == 0) {
      /* the stale factorisation's failures cut the step (and here end
       * the run) */
      assert_true(e != PM_SUCCESS || rep[0].cuts >= 1);
      pm_error_clear();
      continue;
    }
    assert_ok(e);
    assert_true(chain_error(&ch, ch.x, 1.0) < 1e-8);
  }
  assert_int_equal(rep[1].cuts, 0);
  assert_int_equal(rep[1].steps, 1);
  assert_true(rep[1].pc_setups >= 2);
  chain_free(&ch);
}

/* A bar of saturating springs, T(s) = Tmax tanh(s / s0), fixed at one end
 * and pulled by lambda P = lambda 2.2 Tmax at the other, has no state beyond
 * lambda = 1/2.2: the stepping creeps up to it and gives up with a message
 * naming the step and the loads. */
typedef struct {
  long n;
  double tmax, s0, load;
  double ratio; /* P / Tmax */
} bar;

static pm_err bar_set_load(void *ctx, double lambda) {
  bar *b = ctx;
  b->load = lambda * b->ratio * b->tmax;
  return PM_SUCCESS;
}

static pm_err bar_residual(void *ctx, const double *x, double *r) {
  const bar *b = ctx;
  for (long i = 0; i < b->n; i++) {
    double left = b->tmax * tanh((x[i] - (i ? x[i - 1] : 0)) / b->s0);
    double right =
        i + 1 < b->n ? b->tmax * tanh((x[i + 1] - x[i]) / b->s0) : b->load;
    r[i] = left - right;
  }
  return PM_SUCCESS;
}

static pm_err bar_apply(void *ctx, const double *x, const double *dx,
                        double *dr) {
  const bar *b = ctx;
  for (long i = 0; i < b->n; i++) {
    double sl = x[i] - (i ? x[i - 1] : 0), dsl = dx[i] - (i ? dx[i - 1] : 0);
    double tl = tanh(sl / b->s0);
    dr[i] = b->tmax / b->s0 * (1 - tl * tl) * dsl;
    if (i + 1 < b->n) {
      double tr = tanh((x[i + 1] - x[i]) / b->s0);
      dr[i] -= b->tmax / b->s0 * (1 - tr * tr) * (dx[i + 1] - dx[i]);
    }
  }
  return PM_SUCCESS;
}

static void test_load_steps_impossible(void **state) {
  (void)state;
  enum { N = 10 };
  bar b = {N, 1.0, 0.01, 0, 2.2};
  long *ptr, *idx;
  band_pattern(N, 1, &ptr, &idx);
  pm_newton_problem prob = {.n = N,
                            .ctx = &b,
                            .residual = bar_residual,
                            .jacobian_apply = bar_apply,
                            .pat_ptr = ptr,
                            .pat_idx = idx,
                            .set_load = bar_set_load};
  pm_newton_options opt = pm_newton_options_default();
  opt.load_steps = 4;
  opt.max_cuts = 6;
  opt.atol = 1e-12;
  pm_newton *s = NULL;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  double x[N] = {0};
  pm_load_report rep;
  pm_err e = pm_load_steps(s, x, &rep);
  assert_true(e == PM_ERR_NOT_CONVERGED || e == PM_ERR_UNSTABLE);
  const char *msg = pm_error_message();
  print_message("%s\n", msg);
  char want[96];
  snprintf(want, sizeof want, "load step %d (lambda %.6g -> ", rep.steps + 1,
           rep.lambda);
  assert_non_null(strstr(msg, want));
  assert_non_null(strstr(msg, "Newton"));
  assert_non_null(strstr(msg, "times to dlambda 0.00391: giving up"));
  assert_true(rep.lambda < 1 / 2.2 && rep.lambda > 0.4);
  /* The state returned is the converged one at rep.lambda: each spring
   * carries the load. */
  double s_exact = b.s0 * atanh(rep.lambda * 2.2);
  for (long i = 0; i < N; i++)
    assert_close(x[i], s_exact * (double)(i + 1), 1e-8, 1e-14);
  assert_close(b.load, rep.lambda * 2.2, 1e-15, 0);
  pm_error_clear();
  pm_newton_destroy(&s);

  /* P = 2 Tmax: at lambda = 1/2 tanh saturates in floating point and J is
   * singular; MUMPS told to stop at a singular matrix fails inside the
   * linear solver with an error: a linear solver failure, after which a
   * new linear solver carries on. */
  b.ratio = 2;
  for (int icntl = 0; icntl < 2; icntl++) {
    opt.petsc_options =
        icntl ? "-pm_mat_mumps_icntl_24 1" : "-pm_mat_mumps_icntl_24 0";
    assert_ok(pm_newton_create(&prob, &opt, &s));
    memset(x, 0, sizeof x);
    e = pm_load_steps(s, x, &rep);
    print_message("%s: %s\n", pm_err_name(e), pm_error_message());
    assert_true(e == PM_ERR_NOT_CONVERGED || e == PM_ERR_UNSTABLE);
    pm_error_clear();
    pm_newton_destroy(&s);
  }
  free(ptr);
  free(idx);
}

/* ---- Snap-through (snap_through.h) ----------------------------------------
 */

static void test_relaxation_fallback(void **state) {
  (void)state;
  snap sn = {3.6, 0};
  long ptr[2] = {0, 1}, idx[1] = {0};
  pm_newton_problem prob = {.n = 1,
                            .ctx = &sn,
                            .residual = snap_residual,
                            .jacobian_apply = snap_apply,
                            .pat_ptr = ptr,
                            .pat_idx = idx,
                            .set_load = snap_set_load,
                            .diagnose = snap_diagnose};
  pm_newton_options opt = pm_newton_options_default();
  opt.rtol = 1e-10;
  opt.stall_after = 6;
  opt.max_cuts = 6;
  pm_newton *s = NULL;
  pm_load_report rep;

  /* Plain Newton: stuck at the limit point, lambda 2/q = 0.5556. */
  opt.relax_after = 0;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  double x = sqrt(3);
  pm_err e = pm_load_steps(s, &x, &rep);
  print_message("without relaxation: %s\n", pm_error_message());
  assert_true(e == PM_ERR_NOT_CONVERGED || e == PM_ERR_UNSTABLE);
  assert_true(rep.lambda < 2 / 3.6 && rep.lambda > 0.5);
  assert_non_null(strstr(pm_error_message(), "giving up; at the last state "
                                             "tried: x = "));
  assert_int_equal(rep.relaxations, 0);
  pm_error_clear();
  pm_newton_destroy(&s);

  /* With relaxation: through to lambda = 1, on the left root. */
  opt.relax_after = 2;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  x = sqrt(3);
  assert_ok(pm_load_steps(s, &x, &rep));
  print_message("with relaxation: %d steps, %d cuts, %d relaxations (%ld "
                "iterations), %d steps converged by it, x = %.15f against "
                "%.15f\n",
                rep.steps, rep.cuts, rep.relaxations, rep.relax_iterations,
                rep.relaxed_steps, x, snap_root(3.6));
  assert_close(rep.lambda, 1, 0, 0);
  assert_close(x, snap_root(3.6), 1e-9, 0);
  assert_true(rep.relaxed_steps >= 1);
  pm_newton_destroy(&s);

  /* Relaxed first after the step relaxation carried (relax_first): every
   * step after the snap relaxed, then Newton from there, to the same end
   * state; the Newton attempts that fail before a relaxation do not
   * grow. */
  const int alone = rep.relaxed_steps, alone_cuts = rep.cuts;
  const int alone_newton = rep.newton_iterations;
  opt.relax_first = true;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  x = sqrt(3);
  assert_ok(pm_load_steps(s, &x, &rep));
  print_message("relaxed first: %d steps, %d cuts, %d relaxations, %d steps "
                "converged by it (%d alone), %d Newton iterations (%d), x = "
                "%.15f\n",
                rep.steps, rep.cuts, rep.relaxations, rep.relaxed_steps, alone,
                rep.newton_iterations, alone_newton, x);
  assert_close(rep.lambda, 1, 0, 0);
  assert_close(x, snap_root(3.6), 1e-9, 0);
  /* the steps before the snap are Newton's as before; every one after it
   * relaxed first */
  assert_true(rep.relaxed_steps > alone);
  assert_true(rep.cuts <= alone_cuts);
  opt.relax_first = false;
  pm_newton_destroy(&s);

  /* With the continuations first (pseudo_transient > 0): the lowest
   * eigenvalue at the last state is positive (a limit point); arc length
   * finds the load turning back at the limit point, lambda = 2/q, and
   * relaxation at the step's load carries the step to the left root, the
   * state the snap ends in. */
  opt.ptc_max_iter = 60;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  x = sqrt(3);
  assert_ok(pm_load_steps(s, &x, &rep));
  print_message("with continuation: %d steps, %d cuts, %d arc lengths (%ld "
                "arcs), %d snaps (limit point at lambda %.7f, exact %.7f), "
                "%d continuations, %d relaxations, x = %.15f against %.15f\n",
                rep.steps, rep.cuts, rep.arc_runs, rep.arc_steps,
                rep.snap_steps, rep.snap_lambda, 2 / 3.6, rep.ptc_runs,
                rep.relaxations, x, snap_root(3.6));
  assert_close(rep.lambda, 1, 0, 0);
  assert_close(x, snap_root(3.6), 1e-9, 0);
  assert_int_equal(rep.snap_steps, 1);
  assert_int_equal(rep.arc_passes, 0);
  assert_int_equal(rep.ptc_runs, 0);
  /* the highest load the arcs reached: at most the limit point's, within
   * the arc's first length of it */
  assert_true(rep.snap_lambda <= 2 / 3.6 && rep.snap_lambda > 0.55);
  assert_true(rep.mode_eigenvalue > 0);
  assert_non_null(strstr(rep.snap_note, "carried by relaxation past a limit "
                                        "point at lambda"));
  pm_newton_destroy(&s);

  /* follow_fold: arc length follows the path round the fold to lambda =
   * 1, the same root here (one unknown: a single branch past the fold),
   * without relaxation. */
  opt.follow_fold = true;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  x = sqrt(3);
  assert_ok(pm_load_steps(s, &x, &rep));
  print_message("following the fold: %d steps, %d cuts, %d arc lengths (%d "
                "passed, %ld arcs), %d continuations, %d relaxations, x = "
                "%.15f against %.15f\n",
                rep.steps, rep.cuts, rep.arc_runs, rep.arc_passes,
                rep.arc_steps, rep.ptc_runs, rep.relaxations, x,
                snap_root(3.6));
  assert_close(rep.lambda, 1, 0, 0);
  assert_close(x, snap_root(3.6), 1e-9, 0);
  assert_true(rep.arc_passes >= 1);
  assert_int_equal(rep.snap_steps, 0);
  assert_int_equal(rep.relaxations, 0);
  pm_newton_destroy(&s);
  opt.follow_fold = false;

  /* Relaxation ahead of the continuations (relax_first, once relaxation
   * has carried a step: a resumed state that says so): the step Newton
   * cannot finish at the snap is carried by relaxation alone, to the same
   * root, without the lowest mode or arc length. */
  opt.relax_first = true;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  pm_load_state st;
  assert_ok(pm_load_state_init(&st, 1));
  st.xc[0] = st.xprev[0] = sqrt(3);
  st.lambda = 1e-6;
  st.dl = 1.0 / opt.load_steps;
  st.relax_carried = 1;
  memset(&rep, 0, sizeof rep);
  x = sqrt(3);
  assert_ok(pm_load_steps_from(s, &x, &st, &rep));
  print_message("relaxation ahead: %d steps, %d cuts, %d relaxations, %d "
                "steps converged by it, %d lowest modes, %d arc lengths, %d "
                "continuations, x = %.15f\n",
                rep.steps, rep.cuts, rep.relaxations, rep.relaxed_steps,
                rep.mode_runs, rep.arc_runs, rep.ptc_runs, x);
  assert_close(rep.lambda, 1, 0, 0);
  assert_close(x, snap_root(3.6), 1e-9, 0);
  assert_true(rep.relaxed_steps >= 1);
  assert_int_equal(rep.mode_runs, 0);
  assert_int_equal(rep.arc_runs, 0);
  assert_int_equal(rep.ptc_runs, 0);
  assert_int_equal(rep.snap_steps, 0);
  assert_int_equal(st.relax_carried, 1);
  pm_load_state_free(&st);
  pm_newton_destroy(&s);
  opt.relax_first = false;

  /* A fallback out of CPU time stops and the next is tried: with a bound
   * no fallback can meet, the arc, relaxation and the continuation each
   * stop at once and the step is given up, named. */
  opt.fallback_seconds = 1e-300;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  x = sqrt(3);
  e = pm_load_steps(s, &x, &rep);
  print_message("without time for fallbacks: %d timed out: %s\n",
                rep.fallbacks_timed_out, pm_error_message());
  assert_int_equal(e, PM_ERR_NOT_CONVERGED);
  assert_true(rep.fallbacks_timed_out >= 2);
  assert_true(rep.lambda < 2 / 3.6);
  assert_non_null(strstr(pm_error_message(), "fallback_seconds"));
  pm_error_clear();
  pm_newton_destroy(&s);
  opt.fallback_seconds = 0;
  opt.ptc_max_iter = 0;

  /* Bad options are named. */
  opt.relax_rtol = 2;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  x = sqrt(3);
  assert_int_equal(pm_load_steps(s, &x, &rep), PM_ERR_ARG);
  assert_non_null(strstr(pm_error_message(), "relax_rtol"));
  pm_error_clear();
  pm_newton_destroy(&s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_load_steps_cut),
      cmocka_unit_test(test_load_steps_iterations),
      cmocka_unit_test(test_load_steps_stale_factorisation),
      cmocka_unit_test(test_load_steps_relaxed_first_cut),
      cmocka_unit_test(test_load_steps_impossible),
      cmocka_unit_test(test_relaxation_fallback),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
