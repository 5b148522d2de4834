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
#include "gmsh_testing.h"

/* The stiffening's onset tau of the tests: about half the interfaces of
 * their rough fields have a linear jump beyond tau h (printed by
 * test_onset_free_below). */
#define ONSET_TEST 0.012

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
 * smaller); k = 5: SIPG, quadratic jump, fpm.volume_penalty p_v = 1e4;
 * k = 6: SIPG with the stiffening from an onset (fpm.stiffening_onset,
 * ONSET_TEST: some interfaces beyond it, some below); k = 7: the same
 * with the onset in the current spacing (fpm.stiffening_spacing: current,
 * whose onset depends on the state); k = 8: k = 4's stiffening on the
 * quadratic jump from that onset in the current spacing. */
static void test_sipg_is_gradient(void **state) {
  (void)state;
  for (int k = 0; k < 9; k++) {
    fixture *fx = fixture_new(3, 0.03, 100, false);
    fx->opt.flux = k == 1 ? FPM_FLUX_IIPG : FPM_FLUX_SIPG;
    fx->opt.jump = k == 2 || k >= 4 ? FPM_JUMP_QUADRATIC : FPM_JUMP_LINEAR;
    if (k == 3) fx->opt.stiffening = 1e6;
    if (k == 4 || k == 8) {
      fx->opt.stiffening = 1e9;
      fx->opt.stiffening_jump = FPM_JUMP_QUADRATIC;
    }
    if (k == 5) fx->opt.volume_penalty = 1e4;
    if (k == 8) {
      fx->opt.stiffening_onset = 1e-3 * ONSET_TEST; /* its jump is smaller */
      fx->opt.stiffening_spacing = FPM_SPACING_CURRENT;
    }
    if (k == 6 || k == 7) {
      fx->opt.stiffening = 1e6;
      fx->opt.stiffening_onset = 0.1 * ONSET_TEST; /* its field is smoother */
      if (k == 7) fx->opt.stiffening_spacing = FPM_SPACING_CURRENT;
    }
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
        "SIPG, volume penalty",
        "SIPG, stiffening from an onset",
        "SIPG, stiffening from an onset in the current spacing",
        "SIPG, quadratic-jump stiffening, onset in the current spacing"};
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
 * jump, for k = 7 with fpm.volume_penalty p_v = 1e3, for k = 8 with p_s =
 * 1e5 from the onset ONSET_TEST, for k = 9 the same in the current
 * spacing: its model and state. */
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
  if (k >= 8) {
    fx->opt.stiffening = 1e5;
    fx->opt.stiffening_onset = ONSET_TEST;
    if (k == 9) fx->opt.stiffening_spacing = FPM_SPACING_CURRENT;
  }
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
      "the default with the volume penalty",
      "the default with stiffening from an onset",
      "the default with stiffening from an onset in the current spacing"};
  return names[k];
}

/* fpm_force_linear is the derivative of fpm_force: K d against central
 * differences of f along a random d at a finite deformation, for both
 * fluxes and both jumps, the stiffening on either jump and the volume
 * penalty (relative 1e-6 of |K d|). */
static void test_force_linearisation(void **state) {
  (void)state;
  for (int k = 0; k < 10; k++) {
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
 * jumps and for the stiffening on the quadratic jump (its blocks at the
 * state; 1.0 of the coloured one's largest entry away without them) (IIPG:
 * exact; SIPG: the adjoint term's derivative is left out of the assembled
 * one, so only its distance is printed). */
static void test_static_tangent(void **state) {
  (void)state;
  for (int k = 0; k < 7; k += k == 4 ? 2 : 1) {
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

/* The onset makes the stiffening free below it and active beyond: on the
 * rough field of test_terms_act, the fraction of interfaces whose linear
 * jump exceeds tau h is printed (it must be strictly between 0 and 1, so
 * both branches are exercised above); with tau above every jump the
 * force equals the default formulation's exactly, and with ONSET_TEST it
 * differs from it by more than 1e-4 of its norm and from the plain
 * quartic's (tau = 0) too. */
static void test_onset_free_below(void **state) {
  (void)state;
  double *f[3] = {NULL, NULL, NULL};
  static const double onset[3] = {0, ONSET_TEST, 10};
  long nd = 0;
  for (int v = 0; v < 4; v++) {
    fpm_model *m;
    fpm_state *st;
    fixture *fx = variant(0.03, v < 3 ? 5 : 4, &m, &st);
    nd = 3 * m->n;
    if (v < 3) {
      fpm_state_destroy(st);
      fpm_model_destroy(m);
      fx->opt.stiffening_onset = onset[v];
      fixture_model(fx, &m, &st);
    }
    smooth_plus_rough(m, 777, 0.2, 1e-3, st->u, NULL);
    assert_int_equal(fpm_force(m, st), -1);
    if (v == 1) {
      long beyond = 0;
      for (long i = 0; i < m->n; i++)
        for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++) {
          const double *r = m->erec + FPM_EREC * e, *ui = st->u + 3 * i,
                       *uk = st->u + 3 * m->nbr[e];
          double jj = 0;
          for (int c = 0; c < 3; c++) {
            double j = ui[c] - uk[c];
            for (int a = 0; a < 3; a++)
              j += st->H[9 * i + 3 * c + a] * r[12 + a] -
                   st->H[9 * m->nbr[e] + 3 * c + a] * r[15 + a];
            jj += j * j;
          }
          beyond += jj > r[22];
        }
      const double frac = (double)beyond / (double)m->nnz;
      print_message("onset %g: %.3g of the interfaces beyond it\n", ONSET_TEST,
                    frac);
      assert_true(frac > 0.05 && frac < 0.95);
    }
    if (v < 3) {
      f[v] = calloc(nd, sizeof *f[v]);
      memcpy(f[v], st->f, nd * sizeof *f[v]);
    } else {
      double d_off = 0, d_on = 0, d_q = 0, norm = 0;
      for (long i = 0; i < nd; i++) {
        d_off = fmax(d_off, fabs(f[2][i] - st->f[i]));
        d_on += (f[1][i] - st->f[i]) * (f[1][i] - st->f[i]);
        d_q += (f[1][i] - f[0][i]) * (f[1][i] - f[0][i]);
        norm += st->f[i] * st->f[i];
      }
      print_message("onset above every jump: max |f - f_default| = %.3g; "
                    "onset %g: |f - f_default| / |f_default| = %.3g, "
                    "|f - f_quartic| / |f_default| = %.3g\n",
                    d_off, ONSET_TEST, sqrt(d_on / norm), sqrt(d_q / norm));
      assert_true(d_off == 0);
      assert_true(sqrt(d_on / norm) > 1e-4);
      assert_true(sqrt(d_q / norm) > 1e-4);
    }
    fpm_state_destroy(st);
    fpm_model_destroy(m);
    fixture_free(fx);
  }
  for (int v = 0; v < 3; v++) free(f[v]);
}

/* The onset in the current spacing is not the reference one's: on the
 * rough field of test_terms_act, at 20% smooth strain, the forces of
 * variants 8 and 9 differ by more than 1e-4 of variant 8's norm. */
static void test_current_spacing_acts(void **state) {
  (void)state;
  double *f8 = NULL, dif = 0, norm = 0;
  for (int k = 8; k < 10; k++) {
    fpm_model *m;
    fpm_state *st;
    fixture *fx = variant(0.03, k, &m, &st);
    const long nd = 3 * m->n;
    smooth_plus_rough(m, 777, 0.2, 1e-3, st->u, NULL);
    assert_int_equal(fpm_force(m, st), -1);
    if (k == 8) {
      f8 = calloc(nd, sizeof *f8);
      memcpy(f8, st->f, nd * sizeof *f8);
    } else
      for (long i = 0; i < nd; i++) {
        dif += (st->f[i] - f8[i]) * (st->f[i] - f8[i]);
        norm += f8[i] * f8[i];
      }
    fpm_state_destroy(st);
    fpm_model_destroy(m);
    fixture_free(fx);
  }
  print_message("current against reference spacing: |f9 - f8| / |f8| = %.3g\n",
                sqrt(dif / norm));
  assert_true(sqrt(dif / norm) > 1e-4);
  free(f8);
}

int main(void) {
  gmsh_testing_preload();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_sipg_is_gradient),
      cmocka_unit_test(test_force_linearisation),
      cmocka_unit_test(test_static_tangent),
      cmocka_unit_test(test_terms_act),
      cmocka_unit_test(test_onset_free_below),
      cmocka_unit_test(test_current_spacing_acts),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
