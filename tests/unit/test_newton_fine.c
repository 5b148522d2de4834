/* Unit tests of multigrid's finest level on every thread
 * (pm_newton_fine.c): its single-precision copy, in 3 x 3 blocks where the
 * matrix is made of them, preconditions GMRES to the solution in the
 * iterations the values in double take, within a tenth; a pattern not in
 * blocks takes the copy row by row, and values a float cannot hold keep
 * the double ones. */
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
#include "pm_omp.h"
#include "pm_testing.h"
#include "newton_chain.h"

/* The chain's nodes taken three at a time as points, and the pattern of
 * whole points within one point of each other: a matrix of 3 x 3 blocks
 * (the springs reach two nodes, so every coupling is in it). */
static void point_pattern(long n, long **ptr, long **idx) {
  const long points = n / 3;
  *ptr = calloc((size_t)n + 1, sizeof **ptr);
  *idx = calloc((size_t)n * 9, sizeof **idx);
  assert_true(*ptr && *idx);
  for (long i = 0; i < n; i++) {
    const long p = i / 3;
    (*ptr)[i + 1] = (*ptr)[i];
    for (long q = p - 1; q <= p + 1; q++)
      if (q >= 0 && q < points)
        for (long c = 0; c < 3; c++) (*idx)[(*ptr)[i + 1]++] = 3 * q + c;
  }
}

typedef struct {
  int newton, linear;
  double error;
  char storage[32];
} outcome;

/* The chain solved from rest by GMRES with multigrid whose finest level is
 * smoothed by the assembled tangent on two threads. */
static outcome solve(chain *ch, const pm_newton_problem *prob,
                     const char *petsc_options) {
  pm_newton_options opt = pm_newton_options_default();
  opt.rtol = 1e-10;
  opt.linear = PM_NEWTON_GMRES_GAMG;
  opt.amg_assembled_smoother = true;
  opt.amg_threaded = true;
  opt.petsc_options = petsc_options;
  pm_newton *s = NULL;
  assert_ok(pm_newton_create(prob, &opt, &s));
  memset(ch->x, 0, (size_t)ch->n * sizeof *ch->x);
  pm_newton_report rep;
  assert_ok(pm_newton_solve(s, ch->x, &rep));
  outcome o = {rep.iterations, rep.linear_iterations,
               chain_error(ch, ch->x, 1.0), ""};
  snprintf(o.storage, sizeof o.storage, "%s", pm_newton_fine_storage(s));
  pm_newton_destroy(&s);
  print_message("%-24s %-22s: %2d Newton, %4d GMRES iterations, error %.1e\n",
                petsc_options ? petsc_options : "(default)", o.storage,
                o.newton, o.linear, o.error);
  return o;
}

/* The copy in its storage against the values in double: both solve, in
 * the same Newton iterations and GMRES's within a tenth. */
static void single_against_double(chain *ch, const pm_newton_problem *prob,
                                  const char *storage) {
  const outcome single = solve(ch, prob, NULL);
  const outcome dbl = solve(ch, prob, "-pm_fine_single false");
  assert_string_equal(single.storage, storage);
  assert_string_equal(dbl.storage, "double");
  assert_true(single.error < 1e-8 && dbl.error < 1e-8);
  assert_int_equal(single.newton, dbl.newton);
  assert_true(abs(single.linear - dbl.linear) <= 1 + dbl.linear / 10);
}

static void test_fine_storage(void **state) {
  (void)state;
  const int threads = pm_omp_threads();
  pm_omp_set_threads(2);
  chain ch;
  chain_init(&ch, 1500, 2, 2);
  pm_newton_problem prob = chain_problem(&ch);
  long *ptr, *idx;
  point_pattern(ch.n, &ptr, &idx);
  prob.pat_ptr = ptr;
  prob.pat_idx = idx;

  single_against_double(&ch, &prob, "single, 3 x 3 blocks");
  /* The chain's own band: rows that share no columns in threes. */
  prob.pat_ptr = ch.ptr;
  prob.pat_idx = ch.idx;
  single_against_double(&ch, &prob, "single");

  /* Springs 1e32 times stiffer: tangent values past 1e30 stay double. */
  prob.pat_ptr = ptr;
  prob.pat_idx = idx;
  ch.k *= 1e32;
  assert_ok(chain_set_load(&ch, 1.0));
  const outcome stiff = solve(&ch, &prob, NULL);
  assert_string_equal(stiff.storage, "double");
  assert_true(stiff.error < 1e-8);

  free(ptr);
  free(idx);
  chain_free(&ch);
  pm_omp_set_threads(threads);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_fine_storage),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
