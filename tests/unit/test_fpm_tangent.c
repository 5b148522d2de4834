/* Unit tests of the FPM force's derivatives: the symmetric flux is the
 * gradient of an energy, fpm_force_linear is the derivative of the force,
 * and the static solve's assembled tangent is exact, for every flux and
 * jump and for the default formulation. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_model.h"
#include "fpm_static.h"
#include "fpm_testing.h"

static double stored_energy(const fpm_model *m, fpm_state *st) {
  assert_int_equal(fpm_force(m, st), -1);
  double e = st->penalty_energy;
  for (long i = 0; i < m->n; i++) e += m->dual->volume[i] * st->W[i];
  return e;
}

/* With the symmetric flux the force is the gradient of the stored energy
 * sum V W - sum_e {P} : K_e + 1/2 sum_e beta |e| [[u]]^2: its derivative
 * along a random direction, by central differences, equals f . d (relative
 * 1e-6).  The incomplete flux is not a gradient: its mismatch is printed.
 * k = 3: SIPG with fpm.stiffening (p_s = 1e6, so that its quartic energy
 * is a sizeable part of the interfaces' at this small rough field); k = 4:
 * SIPG, quadratic jump, the stiffening on it (p_s = 1e9, its jump being
 * smaller); k = 5: SIPG, quadratic jump, fpm.volume_penalty p_v = 1e4. */
static void test_sipg_is_gradient(void **state) {
  (void)state;
  for (int k = 0; k < 6; k++) {
    fixture *fx = fixture_new(3, 0.03, 100, false);
    fx->opt.flux = k == 1 ? FPM_FLUX_IIPG : FPM_FLUX_SIPG;
    fx->opt.jump = k == 2 || k >= 4 ? FPM_JUMP_QUADRATIC : FPM_JUMP_LINEAR;
    if (k == 3) fx->opt.stiffening = 1e6;
    if (k == 4) {
      fx->opt.stiffening = 1e9;
      fx->opt.stiffening_jump = FPM_JUMP_QUADRATIC;
    }
    if (k == 5) fx->opt.volume_penalty = 1e4;
    fpm_model *m;
    fpm_state *st;
    fixture_model(fx, &m, &st);
    long nd = 3 * m->n;
    double *u0 = calloc(nd, sizeof *u0), *d = calloc(nd, sizeof *d);
    smooth_plus_rough(m, 12345, 0.1, 2e-4, u0, d);
    memcpy(st->u, u0, nd * sizeof *u0);
    stored_energy(m, st);
    double fd = 0;
    for (long i = 0; i < nd; i++) fd += st->f[i] * d[i];
    double eps = 1e-7, ep, em;
    for (long i = 0; i < nd; i++) st->u[i] = u0[i] + eps * d[i];
    ep = stored_energy(m, st);
    for (long i = 0; i < nd; i++) st->u[i] = u0[i] - eps * d[i];
    em = stored_energy(m, st);
    double dE = (ep - em) / (2 * eps);
    double rel = fabs(dE - fd) / fabs(fd);
    static const char *const names[] = {
        "SIPG",
        "IIPG",
        "SIPG, quadratic jump",
        "SIPG, stiffening",
        "SIPG, stiffening on the quadratic jump",
        "SIPG, volume penalty"};
    print_message("%s: dE/de = %.10g, f . d = %.10g, relative mismatch %.3g\n",
                  names[k], dE, fd, rel);
    if (k != 1) assert_true(rel <= 1e-6);
    free(u0);
    free(d);
    fpm_state_destroy(st);
    fpm_model_destroy(m);
    fixture_free(fx);
  }
}

/* The F2 cube at mesh size h, p = 20, with the flux and jump of variant k
 * (bit 0: SIPG, bit 1: quadratic jump), or for k = 4 the default
 * formulation (with its boundary penalty), for k = 5 the default with
 * fpm.stiffening p_s = 1e5, for k = 6 with p_s = 1e7 on the quadratic
 * jump, for k = 7 with fpm.volume_penalty p_v = 1e3: its model and state. */
static fixture *variant(double h, int k, fpm_model **m, fpm_state **st) {
  fixture *fx = fixture_new(3, h, 20, true);
  fx->opt.flux = k & 1 ? FPM_FLUX_SIPG : FPM_FLUX_IIPG;
  fx->opt.jump = k & 2 ? FPM_JUMP_QUADRATIC : FPM_JUMP_LINEAR;
  if (k >= 4) fixture_defaults(fx);
  if (k == 5) fx->opt.stiffening = 1e5;
  if (k == 6) {
    fx->opt.stiffening = 1e7;
    fx->opt.stiffening_jump = FPM_JUMP_QUADRATIC;
  }
  if (k == 7) fx->opt.volume_penalty = 1e3;
  fixture_model(fx, m, st);
  return fx;
}

static const char *variant_name(int k) {
  static const char *const names[] = {
      "IIPG, linear jump",
      "SIPG, linear jump",
      "IIPG, quadratic jump",
      "SIPG, quadratic jump",
      "the default formulation",
      "the default formulation with stiffening",
      "the default with stiffening on the quadratic jump",
      "the default with the volume penalty"};
  return names[k];
}

/* fpm_force_linear is the derivative of fpm_force: K d against central
 * differences of f along a random d at a finite deformation, for both
 * fluxes and both jumps, the stiffening on either jump and the volume
 * penalty (relative 1e-6 of |K d|). */
static void test_force_linearisation(void **state) {
  (void)state;
  for (int k = 0; k < 8; k++) {
    fpm_model *m;
    fpm_state *st;
    fixture *fx = variant(0.03, k, &m, &st);
    const double rel = linearisation_error(m, st, 777);
    print_message("%s: |K d - central difference| / |K d| = %.3g\n",
                  variant_name(k), rel);
    assert_true(rel <= 1e-6);
    fpm_state_destroy(st);
    fpm_model_destroy(m);
    fixture_free(fx);
  }
}

/* The tangent the static solver assembles directly equals the one coloured
 * from fpm_force_linear and central differences of the force, for both
 * jumps (IIPG: exact; SIPG: the adjoint term's derivative is left out of
 * the assembled one, so only its distance is printed). */
static void test_static_tangent(void **state) {
  (void)state;
  for (int k = 0; k < 5; k++) {
    fpm_model *m;
    fpm_state *st;
    fixture *fx = variant(0.04, k, &m, &st);
    long nd = 3 * m->n;
    double *u = calloc(nd, sizeof *u);
    smooth_plus_rough(m, 99, 0.2, 1e-3, u, NULL);
    double ea, ed;
    assert_int_equal(fpm_static_check_tangent(m, st, u, &ea, &ed), PM_SUCCESS);
    print_message("%s: assembled tangent against coloured %.3g, "
                  "against differences %.3g\n",
                  variant_name(k), ea, ed);
    if (m->flux == FPM_FLUX_IIPG) {
      assert_true(ea <= 1e-10);
      assert_true(ed <= 1e-6);
    }
    free(u);
    fpm_state_destroy(st);
    fpm_model_destroy(m);
    fixture_free(fx);
  }
}

/* The tests above would pass with a term that does nothing: the
 * stiffening on the quadratic jump and the volume penalty change the
 * force of the default formulation (variants 6 and 7 against 4) by more
 * than 1e-3 of its norm at the finite deformation they are tested at. */
static void test_terms_act(void **state) {
  (void)state;
  double *f4 = NULL;
  long nd = 0;
  for (int k = 4; k < 8; k += (k == 4 ? 2 : 1)) {
    fpm_model *m;
    fpm_state *st;
    fixture *fx = variant(0.03, k, &m, &st);
    nd = 3 * m->n;
    smooth_plus_rough(m, 777, 0.2, 1e-3, st->u, NULL);
    assert_int_equal(fpm_force(m, st), -1);
    if (k == 4) {
      f4 = calloc(nd, sizeof *f4);
      memcpy(f4, st->f, nd * sizeof *f4);
    } else {
      double dif = 0, norm = 0;
      for (long i = 0; i < nd; i++) {
        dif += (st->f[i] - f4[i]) * (st->f[i] - f4[i]);
        norm += f4[i] * f4[i];
      }
      print_message("%s: |f - f_default| / |f_default| = %.3g\n",
                    variant_name(k), sqrt(dif / norm));
      assert_true(sqrt(dif / norm) > 1e-3);
    }
    fpm_state_destroy(st);
    fpm_model_destroy(m);
    fixture_free(fx);
  }
  free(f4);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_sipg_is_gradient),
      cmocka_unit_test(test_force_linearisation),
      cmocka_unit_test(test_static_tangent),
      cmocka_unit_test(test_terms_act),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
