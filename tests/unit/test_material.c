/* Unit tests of the constitutive models: stress is the derivative of the
 * energy, zero at rest, objective, and accurate near F = I. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "pm_material.h"

static pm_material gel(const char *model) {
  pm_material m;
  assert_int_equal(pm_material_elastic(&m, model, 1000, 3000, 0.495),
                   PM_SUCCESS);
  return m;
}

/* A deterministic, well-conditioned finite deformation. */
static const double F0[9] = {1.21, 0.13,  -0.07, 0.05, 0.83,
                             0.11, -0.09, 0.04,  0.64};

/* dW along dF equals S : sym(F^T dF) and P : dF (central differences,
 * step 1e-6, relative tolerance 1e-6 of |S| |dF|). */
static void check_derivative(const char *model, bool check_pk2) {
  pm_material m = gel(model);
  double S[9], P[9];
  assert_true(pm_material_pk2(&m, F0, NULL, S));
  assert_true(pm_material_stress(&m, F0, NULL, P, NULL, NULL));
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
    /* Small-strain elasticity is not objective: P F^T is not symmetric
     * at finite strain, so only P is its energy's derivative there. */
    if (check_pk2) assert_true(fabs(dW - pm_t_ddot(S, dE)) <= 1e-6 * scale);
    assert_true(fabs(dW - pm_t_ddot(P, dF)) <= 1e-6 * scale);
  }
}

static void test_neo_hookean_derivative(void **state) {
  (void)state;
  check_derivative("neo-hookean", true);
}

static void test_linear_derivative(void **state) {
  (void)state;
  check_derivative("linear-elastic", false);
}

/* The tangent: dP along dF matches central differences of P (relative
 * 1e-7 of |A| |dF|), and B : A : dF = dF : A : B (major symmetry). */
static void check_tangent(const char *model) {
  pm_material m = gel(model);
  double dF[9] = {0.3, -0.2, 0.1, 0.05, 0.7, -0.4, 0.2, 0.1, -0.6};
  double B[9] = {-0.1, 0.4, 0.2, 0.3, -0.2, 0.1, 0.5, -0.3, 0.25};
  double dP[9], dPB[9], Pp[9], Pm[9], Fp[9], Fm[9], eps = 1e-6;
  assert_true(pm_material_tangent(&m, F0, NULL, dF, dP));
  assert_true(pm_material_tangent(&m, F0, NULL, B, dPB));
  for (int k = 0; k < 9; k++) {
    Fp[k] = F0[k] + eps * dF[k];
    Fm[k] = F0[k] - eps * dF[k];
  }
  assert_true(pm_material_stress(&m, Fp, NULL, Pp, NULL, NULL));
  assert_true(pm_material_stress(&m, Fm, NULL, Pm, NULL, NULL));
  double scale = m.wave_modulus * pm_t_norm(dF);
  for (int k = 0; k < 9; k++)
    assert_true(fabs((Pp[k] - Pm[k]) / (2 * eps) - dP[k]) <= 1e-7 * scale);
  assert_true(fabs(pm_t_ddot(B, dP) - pm_t_ddot(dF, dPB)) <=
              1e-12 * scale * pm_t_norm(B));
}

static void test_tangent(void **state) {
  (void)state;
  check_tangent("neo-hookean");
  check_tangent("linear-elastic");
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

static void test_zero_at_rest(void **state) {
  (void)state;
  const char *models[] = {"neo-hookean", "linear-elastic"};
  for (int k = 0; k < 2; k++) {
    pm_material m = gel(models[k]);
    double I[9], P[9], S[9], W, J;
    pm_t_identity(I);
    assert_true(pm_material_stress(&m, I, NULL, P, &W, &J));
    assert_true(pm_material_pk2(&m, I, NULL, S));
    for (int k = 0; k < 9; k++) {
      assert_true(P[k] == 0.0);
      assert_true(S[k] == 0.0);
    }
    assert_true(W == 0.0);
    assert_true(J == 1.0);
  }
}

/* Near F = I the stress is linear in H and W quadratic: the neo-Hookean
 * response to H = 1e-9 sym matches linear elasticity to 1e-6 relative,
 * which fails if J - 1 or J^-2/3 - 1 are formed with cancellation. */
static void test_small_strain_limit(void **state) {
  (void)state;
  pm_material nh = gel("neo-hookean"), le = gel("linear-elastic");
  const double h = 1e-9;
  double H[9] = {0.3, 0.1, 0.0, 0.1, -0.2, 0.05, 0.0, 0.05, 0.4};
  double F[9], Pn[9], Pl[9], Wn, Wl;
  for (int k = 0; k < 9; k++) F[k] = h * H[k] + (k % 4 == 0);
  assert_true(pm_material_stress(&nh, F, NULL, Pn, &Wn, NULL));
  assert_true(pm_material_stress(&le, F, NULL, Pl, &Wl, NULL));
  double diff[9];
  for (int k = 0; k < 9; k++) diff[k] = Pn[k] - Pl[k];
  assert_true(pm_t_norm(diff) <= 1e-6 * pm_t_norm(Pl));
  assert_true(fabs(Wn - Wl) <= 1e-6 * Wl);
}

/* Objectivity: P(Q F) = Q P(F), W(Q F) = W(F). */
static void test_objectivity(void **state) {
  (void)state;
  pm_material m = gel("neo-hookean");
  double axis[3] = {1 / sqrt(3.0), -1 / sqrt(3.0), 1 / sqrt(3.0)}, Q[9];
  pm_t_rotation(axis, 0.7, Q);
  double QF[9], P[9], PQ[9], QP[9], W, WQ;
  pm_t_mul(Q, F0, QF);
  assert_true(pm_material_stress(&m, F0, NULL, P, &W, NULL));
  assert_true(pm_material_stress(&m, QF, NULL, PQ, &WQ, NULL));
  pm_t_mul(Q, P, QP);
  for (int k = 0; k < 9; k++)
    assert_true(fabs(PQ[k] - QP[k]) <= 1e-12 * pm_t_norm(P));
  assert_true(fabs(W - WQ) <= 1e-12 * W);
}

static void test_inverted_rejected(void **state) {
  (void)state;
  pm_material m = gel("neo-hookean");
  double F[9] = {1, 0, 0, 0, 1, 0, 0, 0, -0.1}, P[9], J;
  assert_false(pm_material_stress(&m, F, NULL, P, NULL, &J));
  assert_true(J < 0);
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
  assert_string_equal(pm_model_find("neo-hookean")->name, "neo-hookean");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_neo_hookean_derivative),
      cmocka_unit_test(test_linear_derivative),
      cmocka_unit_test(test_tangent),
      cmocka_unit_test(test_von_mises),
      cmocka_unit_test(test_zero_at_rest),
      cmocka_unit_test(test_small_strain_limit),
      cmocka_unit_test(test_objectivity),
      cmocka_unit_test(test_inverted_rejected),
      cmocka_unit_test(test_uniaxial),
      cmocka_unit_test(test_bad_constants),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
