/* test_mls: moving least squares reproduces linear fields to round-off on
 * scattered points in 3-D and 2-D, whatever the units, inside the cloud, on
 * its corners and a little outside; a point with too few neighbours within
 * the reach is flagged; nearest distances; degenerate clouds are
 * refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
/* cmocka needs the three headers above first. */
#include <cmocka.h>

#include "pm_testing.h"

#include <math.h>
#include <stdlib.h>

#include "pm_mls.h"

#define NCOMP 4 /* a vector and a scalar fitted together */
#define EXACT 1e-12

/* Pseudo-random in [0, 1) from a fixed LCG: reproducible. */
static double uniform(unsigned *seed) {
  *seed = *seed * 1103515245u + 12345u;
  return ((*seed >> 8) & 0xffffff) / 16777216.0;
}

/* The linear field f_c = c_c + sum_k g_ck x_k / L at x (L: the units). */
static void field(const double *x, double L, double *f) {
  static const double c[NCOMP] = {0.01, -0.02, 0.03, 250.0};
  static const double g[NCOMP][3] = {{0.1, -0.05, 0.02},
                                     {0.03, 0.2, -0.1},
                                     {-0.07, 0.04, 0.15},
                                     {30.0, -12.0, 7.5}};
  for (int i = 0; i < NCOMP; i++) {
    f[i] = c[i];
    for (int k = 0; k < 3; k++) f[i] += g[i][k] * x[k] / L;
  }
}

/* n scattered points in the box [0, L]^d (z = 0 in 2-D) and the field. */
static void cloud(long n, int dim, double L, double *x, double *f) {
  unsigned seed = 2024u;
  for (long i = 0; i < n; i++) {
    for (int k = 0; k < 3; k++)
      x[3 * i + k] = k < dim ? L * uniform(&seed) : 0.0;
    field(&x[3 * i], L, &f[NCOMP * i]);
  }
}

/* Every query of a lattice over [-0.02 L, 1.02 L]^d (corners and a little
 * outside included) gets the exact value. */
static void check_linear(int dim, double L) {
  const long n = dim == 3 ? 2000 : 400;
  double *x = calloc(3 * n, sizeof *x), *f = calloc(NCOMP * n, sizeof *f);
  pm_mls *m = NULL;
  cloud(n, dim, L, x, f);
  assert_ok(pm_mls_create(n, x, "the test cloud", &m));
  assert_int_equal(pm_mls_dim(m), dim);
  assert_close(pm_mls_spacing(m), L * pow(1.0 / n, 1.0 / dim), 0.1, 0);
  const int side = 7;
  const int nz = dim == 3 ? side : 1;
  double worst = 0;
  for (int a = 0; a < side; a++)
    for (int b = 0; b < side; b++)
      for (int c = 0; c < nz; c++) {
        const int idx[3] = {a, b, c};
        double q[3], v[NCOMP], e[NCOMP];
        for (int k = 0; k < 3; k++)
          q[k] = k < dim ? L * (-0.02 + 1.04 * idx[k] / (side - 1)) : 0.0;
        field(q, L, e);
        /* In 2-D the query's z carries no information. */
        if (dim == 2) q[2] = 5 * L;
        assert_true(pm_mls_fit(m, q, NCOMP, f, 0, v) >= 3 * (dim + 1));
        for (int i = 0; i < NCOMP; i++) {
          double err = fabs(v[i] - e[i]) / fmax(fabs(e[i]), 1e-2);
          worst = fmax(worst, err);
          if (!(err <= EXACT))
            fail_msg("dim %d, L %g: component %d at (%g, %g, %g): %.17g, "
                     "exact %.17g",
                     dim, L, i, q[0], q[1], q[2], v[i], e[i]);
        }
      }
  print_message("linear field, %d-D, L = %g: worst relative error %.2e\n", dim,
                L, worst);
  pm_mls_free(m);
  free(x);
  free(f);
}

static void test_linear_3d(void **state) {
  (void)state;
  check_linear(3, 1.0);
  check_linear(3, 1e-4); /* a 0.1 mm body: the fit is unit-free */
}

static void test_linear_2d(void **state) {
  (void)state;
  check_linear(2, 10.0);
}

/* A point far from the cloud: flagged (0, NaN) within a reach of 3
 * spacings; fitted from the whole cloud with no cap. */
static void test_too_few(void **state) {
  (void)state;
  const long n = 500;
  double *x = calloc(3 * n, sizeof *x), *f = calloc(NCOMP * n, sizeof *f);
  pm_mls *m = NULL;
  cloud(n, 3, 1.0, x, f);
  assert_ok(pm_mls_create(n, x, "the test cloud", &m));
  const double far[3] = {3.0, 0.5, 0.5};
  double v[NCOMP], e[NCOMP];
  assert_int_equal(pm_mls_fit(m, far, NCOMP, f, 3.0, v), 0);
  for (int i = 0; i < NCOMP; i++) assert_true(isnan(v[i]));
  assert_true(pm_mls_fit(m, far, NCOMP, f, 0, v) > 0);
  field(far, 1.0, e);
  for (int i = 0; i < NCOMP; i++) assert_close(v[i], e[i], 1e-9, 1e-12);
  pm_mls_free(m);
  free(x);
  free(f);
}

/* On a regular lattice of spacing h: every point's nearest neighbour is h
 * away, and a query's nearest point is where geometry puts it. */
static void test_nearest(void **state) {
  (void)state;
  const int side = 5;
  const double h = 0.1;
  double x[3 * 5 * 5 * 5];
  long n = 0;
  pm_mls *m = NULL;
  for (int a = 0; a < side; a++)
    for (int b = 0; b < side; b++)
      for (int c = 0; c < side; c++, n++) {
        x[3 * n] = a * h;
        x[3 * n + 1] = b * h;
        x[3 * n + 2] = c * h;
      }
  assert_ok(pm_mls_create(n, x, "the lattice", &m));
  assert_close(pm_mls_gap(m), h, 1e-12, 0);
  const double on[3] = {0.2, 0.3, 0.1}, off[3] = {-0.3, 0.2, 0.2};
  const double inside[3] = {0.25, 0.25, 0.25}, far[3] = {2.0, 2.0, 2.0};
  assert_close(pm_mls_nearest(m, on), 0, 0, 1e-15);
  assert_close(pm_mls_nearest(m, off), 0.3, 1e-12, 0);
  assert_close(pm_mls_nearest(m, inside), sqrt(3) * 0.05, 1e-12, 0);
  assert_close(pm_mls_nearest(m, far), sqrt(3) * 1.6, 1e-12, 0);
  pm_mls_free(m);
}

static void test_degenerate(void **state) {
  (void)state;
  double x[9] = {1, 2, 3, 1, 2, 3, 1, 2, 3};
  pm_mls *m = NULL;
  assert_fails(pm_mls_create(3, x, "the stack", &m), PM_ERR_GEOMETRY,
               "the 3 points of the stack all coincide");
  assert_null(m);
  x[4] = NAN;
  assert_fails(pm_mls_create(3, x, "the cloud", &m), PM_ERR_GEOMETRY,
               "the cloud holds non-finite coordinates");
  assert_fails(pm_mls_create(0, x, "the void", &m), PM_ERR_ARG,
               "the void holds no points");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_linear_3d), cmocka_unit_test(test_linear_2d),
      cmocka_unit_test(test_too_few), cmocka_unit_test(test_nearest),
      cmocka_unit_test(test_degenerate)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
