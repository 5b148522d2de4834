/* Unit tests of the material API around the models: PK2 and Cauchy stress
 * from P, von Mises, uniaxial states, bad constants and parameters (with
 * messages naming the key), the table's lookups, and the symmetric
 * eigen-decomposition of the principal-stretch models.  What every model must
 * satisfy (derivatives, rest, inverted states, frames, small strain) is in
 * test_models.c. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <float.h>
#include <string.h>

#include "pm_eigen.h"
#include "pm_material.h"
#include "pm_testing.h"

static pm_material gel(const char *model) {
  pm_material m;
  assert_int_equal(pm_material_elastic(&m, model, 1000, 3000, 0.495),
                   PM_SUCCESS);
  return m;
}

/* A deterministic, well-conditioned finite deformation. */
static const double F0[9] = {1.21, 0.13,  -0.07, 0.05, 0.83,
                             0.11, -0.09, 0.04,  0.64};

/* dW along dF equals S : sym(F^T dF) (central differences, step 1e-6,
 * relative tolerance 1e-6 of |S| |dF| |F|), and sigma = P F^T / J is
 * symmetric (to 1e-12 of |sigma|: rounding) with S = F^-1 P. */
static void test_pk2_and_cauchy(void **state) {
  (void)state;
  pm_material m = gel("neo-hookean");
  double S[9], P[9], sig[9], FS[9];
  assert_true(pm_material_pk2(&m, F0, NULL, S));
  assert_true(pm_material_stress(&m, F0, NULL, P, NULL, NULL));
  assert_true(pm_material_cauchy(&m, F0, NULL, sig));
  pm_t_mul(F0, S, FS);
  for (int k = 0; k < 9; k++)
    assert_true(fabs(FS[k] - P[k]) <= 1e-12 * pm_t_norm(P));
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      assert_true(fabs(sig[3 * i + j] - sig[3 * j + i]) <=
                  1e-12 * pm_t_norm(sig));
  for (int dir = 0; dir < 9; dir++) {
    double dF[9] = {0};
    dF[dir] = 1;
    dF[(dir + 4) % 9] += 0.5;
    double eps = 1e-6, Fp[9], Fm[9];
    for (int k = 0; k < 9; k++) {
      Fp[k] = F0[k] + eps * dF[k];
      Fm[k] = F0[k] - eps * dF[k];
    }
    double dW =
        (pm_material_energy(&m, Fp, NULL) - pm_material_energy(&m, Fm, NULL)) /
        (2 * eps);
    double FtdF[9], dE[9];
    pm_t_tmul(F0, dF, FtdF);
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        dE[3 * i + j] = 0.5 * (FtdF[3 * i + j] + FtdF[3 * j + i]);
    double scale = pm_t_norm(S) * pm_t_norm(dF) * pm_t_norm(F0);
    assert_true(fabs(dW - pm_t_ddot(S, dE)) <= 1e-6 * scale);
  }
}

/* Von Mises of a uniaxial stress is its magnitude; of a pressure, zero. */
static void test_von_mises(void **state) {
  (void)state;
  double uni[9] = {0, 0, 0, 0, 0, 0, 0, 0, -7.5};
  double pres[9] = {3, 0, 0, 0, 3, 0, 0, 0, 3};
  double shear[9] = {0, 2, 0, 2, 0, 0, 0, 0, 0};
  assert_true(fabs(pm_t_von_mises(uni) - 7.5) < 1e-14);
  assert_true(fabs(pm_t_von_mises(pres)) < 1e-14);
  assert_true(fabs(pm_t_von_mises(shear) - 2 * sqrt(3.0)) < 1e-14);
}

/* Uniaxial stress: the lateral stretch zeroes P_xx and P_yy. */
static void test_uniaxial(void **state) {
  (void)state;
  pm_material m = gel("neo-hookean");
  double lat[2];
  assert_int_equal(pm_material_uniaxial(&m, NULL, 0.6, lat), PM_SUCCESS);
  const double s = lat[0];
  assert_true(lat[1] == s);
  double F[9] = {s, 0, 0, 0, s, 0, 0, 0, 0.6}, P[9];
  assert_true(pm_material_stress(&m, F, NULL, P, NULL, NULL));
  assert_true(fabs(P[0]) <= 1e-10 * fabs(P[8]));
  assert_true(s > 1.2 && s < 1.3); /* nearly incompressible: ~1/sqrt(0.6) */
}

static void test_bad_constants(void **state) {
  (void)state;
  pm_material m;
  assert_int_equal(pm_material_elastic(&m, "neo-hookean", 1000, 3000, 0.5),
                   PM_ERR_ARG);
  assert_non_null(strstr(pm_error_message(), "poisson_ratio"));
  assert_int_equal(pm_material_elastic(&m, "neo-hookean", -1, 3000, 0.3),
                   PM_ERR_ARG);
  assert_null(pm_model_find("mooney"));
  /* The table's order: the solid models, then the fluid. */
  const char *order[] = {
      "neo-hookean", "neo-hookean-log",        "mooney-rivlin",
      "ogden",       "holzapfel-gasser-ogden", "linear-elastic",
      "fluid"};
  assert_int_equal(pm_model_count(), 7);
  for (int k = 0; k < 7; k++)
    assert_string_equal(pm_model_at(k)->name, order[k]);
  assert_null(pm_model_at(7));
  assert_string_equal(pm_model_find("neo-hookean")->name, "neo-hookean");
}

/* ---- bad parameters ------------------------------------------------------ */

/* Finish m and expect PM_ERR_ARG with a message containing text. */
static void expect_bad(pm_material *m, const char *text) {
  assert_int_equal(pm_material_finish(m), PM_ERR_ARG);
  if (!strstr(pm_error_message(), text))
    fail_msg("expected \"%s\" in: %s", text, pm_error_message());
}

/* Each model's bad parameters fail in init with "KEY: expected ..., got
 * ..." naming the key (a term of a list by its index), or naming the keys
 * in the message when no one key is at fault. */
static void test_bad_parameters(void **state) {
  (void)state;
  pm_material m;
  const double mu[3] = {1000, -5, 1}, al[3] = {2, 3, 1}, zero[1] = {0};
  /* Ogden: lists of different lengths; mu_p alpha_p <= 0 named by term;
   * missing keys; more than 8 terms. */
  assert_ok(pm_material_begin(&m, "ogden", 1000));
  assert_ok(pm_material_set_list(&m, "mu", 3, mu));
  assert_ok(pm_material_set_list(&m, "alpha", 2, al));
  assert_ok(pm_material_set(&m, "bulk_modulus", 1e5));
  expect_bad(&m, "alpha: expected as many alpha as mu (3), got 2");
  assert_ok(pm_material_set_list(&m, "alpha", 3, al));
  expect_bad(&m, "mu.1: expected mu_p alpha_p > 0");
  assert_ok(pm_material_set_list(&m, "mu", 1, mu));
  assert_ok(pm_material_set_list(&m, "alpha", 1, zero));
  expect_bad(&m, "alpha.0:");
  assert_ok(pm_material_begin(&m, "ogden", 1000));
  assert_ok(pm_material_set_list(&m, "alpha", 1, al));
  expect_bad(&m, "mu: expected a list of 1 to 8 numbers (required)");
  assert_ok(pm_material_set_list(&m, "mu", 1, mu));
  expect_bad(&m, "bulk_modulus: expected a number > 0 (required), got none");
  double nine[9] = {1, 1, 1, 1, 1, 1, 1, 1, 1};
  assert_int_equal(pm_material_set_list(&m, "mu", 9, nine), PM_ERR_ARG);
  /* HGO: a missing k2; dispersion out of [0, 1/3] from code and as a
   * reader would write it. */
  assert_ok(pm_material_begin(&m, "holzapfel-gasser-ogden", 1000));
  assert_ok(pm_material_set(&m, "shear_modulus", 1000));
  assert_ok(pm_material_set(&m, "k1", 1000));
  assert_ok(pm_material_set(&m, "bulk_modulus", 1e5));
  expect_bad(&m, "k2: expected a number > 0 (required)");
  assert_ok(pm_material_set(&m, "k2", 2));
  assert_int_equal(pm_material_set(&m, "dispersion", 0.5), PM_ERR_ARG);
  assert_non_null(strstr(pm_error_message(), "dispersion"));
  const pm_key *disp = pm_key_find(m.model->keys, "dispersion");
  *(double *)((char *)&m + disp->offset) = -0.1;
  expect_bad(&m, "dispersion: expected a number in [0, 0.3333333333], got "
                 "-0.1");
  /* Mooney-Rivlin: shear modulus 2 (c10 + c01) <= 0; a missing c01. */
  assert_ok(pm_material_begin(&m, "mooney-rivlin", 1000));
  assert_ok(pm_material_set(&m, "c10", 100));
  assert_ok(pm_material_set(&m, "bulk_modulus", 1e5));
  expect_bad(&m, "c01: expected a number (required), got none");
  assert_ok(pm_material_set(&m, "c01", -100));
  expect_bad(&m, "expected c10 + c01 > 0");
  /* neo-hookean-log: the elastic key sets. */
  assert_ok(pm_material_begin(&m, "neo-hookean-log", 1000));
  assert_ok(pm_material_set(&m, "shear_modulus", 1000));
  expect_bad(&m, "bulk_modulus");
}

/* ---- the symmetric eigen-decomposition behind Ogden --------------------- */

static double eigen_worst; /* largest error / tolerance, for the log */

/* Fail unless err <= tol, naming the case. */
static void eigen_check(const char *what, const double w[3], double scale,
                        double err, double tol) {
  if (!(err <= tol))
    fail_msg("eigen %s of (%g, %g, %g) x %g: error %.3g above %.3g", what, w[0],
             w[1], w[2], scale, err, tol);
  eigen_worst = fmax(eigen_worst, err / tol);
}

/* A = Q diag(w) Q^T, scaled: the eigenvalues match w, V is orthonormal and
 * A V = V diag(w), each to 50 eps of max |w|: forming A rounds to a few
 * eps, and each Jacobi rotation (a dozen or two) is backward stable. */
static void eigen_case(const double w[3], double scale, bool rotate) {
  double axis[3] = {0.36, 0.48, 0.8}, Q[9], D[9] = {0}, t[9], A[9], V[9];
  double e[3], big = 0, tol = 50 * DBL_EPSILON;
  pm_t_rotation(axis, rotate ? 0.8 : 0, Q);
  for (int i = 0; i < 3; i++) {
    D[4 * i] = scale * w[i];
    big = fmax(big, fabs(scale * w[i]));
  }
  pm_t_mul(Q, D, t);
  pm_t_mult(t, Q, A);
  assert_true(pm_eigen_sym3(A, e, V));
  double sorted[3] = {w[0], w[1], w[2]};
  for (int i = 0; i < 3; i++)
    for (int j = 0; j + 1 < 3 - i; j++)
      if (sorted[j + 1] < sorted[j]) {
        double s = sorted[j];
        sorted[j] = sorted[j + 1];
        sorted[j + 1] = s;
      }
  for (int i = 0; i < 3; i++) {
    eigen_check("eigenvalues", w, scale, fabs(e[i] - scale * sorted[i]),
                tol * fmax(big, 1e-300));
    for (int j = 0; j < 3; j++) {
      double vv = 0, av = 0;
      for (int k = 0; k < 3; k++) {
        vv += V[3 * k + i] * V[3 * k + j];
        av += A[3 * i + k] * V[3 * k + j];
      }
      eigen_check("V^T V = I", w, scale, fabs(vv - (i == j)), tol);
      eigen_check("A V = V diag(w)", w, scale, fabs(av - e[j] * V[3 * i + j]),
                  tol * fmax(big, 1e-300));
    }
  }
}

/* Repeated, near-repeated (1e-12 and 1e-15 apart), tiny (C - I near
 * rest), widely spread and indefinite spectra, each at the scales 1,
 * 1e-150 and 1e150, in a rotated frame and on the diagonal. */
static void test_eigen(void **state) {
  (void)state;
  const double cases[][3] = {
      {0, 0, 0},
      {1, 1, 1},
      {1, 1, 2},
      {-1, 2, 2},
      {3, 1, 2},
      {1, 1 + 1e-12, 2},
      {1, 1 + 1e-15, 1 + 2e-15},
      {-1e-9, 1e-9, 3e-9},
      {1e-8, 1, 1e8},
      {-1, 0, 1},
  };
  const double scales[3] = {1, 1e-150, 1e150};
  for (size_t c = 0; c < sizeof cases / sizeof *cases; c++)
    for (int s = 0; s < 3; s++) {
      eigen_case(cases[c], scales[s], true);
      eigen_case(cases[c], scales[s], false);
    }
  /* A diagonal matrix is returned exactly; a zero diagonal is rotated. */
  double A[9] = {3, 0, 0, 0, 1, 0, 0, 0, 2}, w[3], V[9];
  assert_true(pm_eigen_sym3(A, w, V));
  assert_true(w[0] == 1 && w[1] == 2 && w[2] == 3);
  double Z[9] = {0, 1, 0, 1, 0, 1, 0, 1, 0};
  assert_true(pm_eigen_sym3(Z, w, V));
  assert_true(fabs(w[2] - sqrt(2.0)) + fabs(w[1]) <= 4 * DBL_EPSILON);
  A[4] = NAN;
  assert_false(pm_eigen_sym3(A, w, V));
  print_message("eigen: worst error %.2g of its tolerance\n", eigen_worst);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_pk2_and_cauchy),
      cmocka_unit_test(test_von_mises),
      cmocka_unit_test(test_uniaxial),
      cmocka_unit_test(test_bad_constants),
      cmocka_unit_test(test_bad_parameters),
      cmocka_unit_test(test_eigen),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
