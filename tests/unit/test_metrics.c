/* Unit tests of the error norms and the observed rate. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "pm_metrics.h"

/* NRMSE is the root mean square over the reference's range. */
static void test_nrmse(void **state) {
  (void)state;
  const double ref[4] = {0, 1, 2, 4}, u[4] = {0.1, 1, 2, 3.9};
  /* sqrt((0.01 + 0.01) / 4) / 4 */
  assert_true(fabs(pm_nrmse(4, 1, u, ref) - sqrt(0.005) / 4) < 1e-15);
  const double flat[2] = {1, 1};
  assert_true(isnan(pm_nrmse(2, 1, flat, flat)));
  /* Stride: every third value of interleaved vectors. */
  const double v[6] = {0, 9, 9, 2, 9, 9}, r[6] = {0, 7, 7, 1, 7, 7};
  assert_true(fabs(pm_nrmse(2, 3, v, r) - sqrt(0.5)) < 1e-15);
}

/* The vector form uses |u - r| over the range of |r|, on the masked
 * components. */
static void test_nrmse_vector(void **state) {
  (void)state;
  const double r[6] = {0, 0, 0, 3, 4, 100}, u[6] = {0, 0, 1, 3, 4, -50};
  /* x, y only: errors 0 and 0 */
  assert_true(pm_nrmse_vector(2, 3u, u, r) == 0);
  /* all: |d|^2 = 1 and 150^2; range of |r| = |(3,4,100)| */
  double range = sqrt(9 + 16 + 10000.0);
  double want = sqrt((1 + 22500.0) / 2) / range;
  assert_true(fabs(pm_nrmse_vector(2, 7u, u, r) - want) < 1e-14 * want);
}

/* The rate of err = C h^2 is 2; non-positive pairs are skipped. */
static void test_rate(void **state) {
  (void)state;
  const double h[5] = {0.1, 0.05, 0.025, 0, 0.0125};
  double e[5];
  for (int k = 0; k < 5; k++) e[k] = 3 * h[k] * h[k];
  assert_true(fabs(pm_convergence_rate(5, h, e) - 2) < 1e-12);
  assert_true(isnan(pm_convergence_rate(1, h, e)));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_nrmse),
      cmocka_unit_test(test_nrmse_vector),
      cmocka_unit_test(test_rate),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
