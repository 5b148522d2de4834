/* Unit tests of fpm.volumetric: averaged: the stress is the gradient of the
 * averaged energy, a uniform dilatation gives the exact pressure at every
 * point, the linearisation is the force's derivative, the models
 * without the volumetric split are refused, and a rank's share computes
 * one process's force. */
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
#include "fpm_share.h"
#include "fpm_testing.h"
#include "gmsh_testing.h"

static fixture *averaged(double h, bool defaults, fpm_model **m,
                         fpm_state **st) {
  fixture *fx = fixture_new(3, h, 20, true);
  if (defaults) fixture_defaults(fx);
  fx->opt.volumetric = FPM_VOLUMETRIC_AVERAGED;
  fixture_model(fx, m, st);
  return fx;
}

/* sum_i V_i W_i: with averaged J, sum V [W_iso(F) + U(Jbar)]. */
static double bulk_energy(const fpm_model *m, fpm_state *st) {
  assert_int_equal(fpm_force(m, st), -1);
  double e = 0;
  for (long i = 0; i < m->n; i++) e += m->dual->volume[i] * st->W[i];
  return e;
}

/* The averaged stress is the exact gradient of the averaged energy: with
 * F_i = I + sum_k (u_k - u_i) (x) g_ik, the force of the stresses,
 * f_k = sum_i V_i P_i : dF_i/du_k, along a random direction equals the
 * central difference of sum V W (relative 1e-6; the mismatch of the
 * standard stress against the averaged energy is printed beside it, to
 * show the test can tell them apart). */
static void test_stress_is_gradient(void **state) {
  (void)state;
  fpm_model *m;
  fpm_state *st;
  fixture *fx = averaged(0.03, false, &m, &st);
  const long n = m->n, nd = 3 * n;
  double *u0 = calloc(nd, sizeof *u0), *d = calloc(nd, sizeof *d);
  smooth_plus_rough(m, 4242, 0.15, 1e-3, u0, d);
  memcpy(st->u, u0, nd * sizeof *u0);
  bulk_energy(m, st);
  /* f . d = sum_i V_i P_i : dF_i[d] */
  double fd = 0, fd_std = 0;
  for (long i = 0; i < n; i++) {
    double dF[9] = {0}, F[9], Ps[9];
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++)
      for (int c = 0; c < 3; c++)
        for (int a = 0; a < 3; a++)
          dF[3 * c + a] +=
              (d[3 * m->nbr[e] + c] - d[3 * i + c]) * m->g[3 * e + a];
    for (int a = 0; a < 9; a++) F[a] = st->H[9 * i + a] + (a % 4 == 0);
    assert_true(pm_material_stress(&m->mats[0], F, NULL, Ps, NULL, NULL));
    for (int a = 0; a < 9; a++) {
      fd += m->dual->volume[i] * st->P[9 * i + a] * dF[a];
      fd_std += m->dual->volume[i] * Ps[a] * dF[a];
    }
  }
  const double eps = 1e-7;
  for (long i = 0; i < nd; i++) st->u[i] = u0[i] + eps * d[i];
  const double ep = bulk_energy(m, st);
  for (long i = 0; i < nd; i++) st->u[i] = u0[i] - eps * d[i];
  const double em = bulk_energy(m, st);
  const double dE = (ep - em) / (2 * eps);
  const double rel = fabs(dE - fd) / fabs(fd);
  print_message("averaged: dE/de = %.10g, f . d = %.10g, mismatch %.3g "
                "(standard stress: %.3g)\n",
                dE, fd, rel, fabs(dE - fd_std) / fabs(fd));
  assert_true(rel <= 1e-6);
  assert_true(fabs(dE - fd_std) / fabs(fd) > 1e-3);
  free(u0);
  free(d);
  fpm_state_destroy(st);
  fpm_model_destroy(m);
  fixture_free(fx);
}

/* u = e x: F = (1 + e) I at every point (the GFD gradient is exact on
 * linear fields), so Jbar = J and the stress is the exact pressure
 * P = K (J - 1) J F^-T (the neo-Hookean's isochoric part vanishes) at
 * every point, the boundary's included (relative 1e-12 of K (J - 1)). */
static void test_uniform_dilatation(void **state) {
  (void)state;
  fpm_model *m;
  fpm_state *st;
  fixture *fx = averaged(0.03, true, &m, &st);
  const double e = 0.02, J = (1 + e) * (1 + e) * (1 + e);
  const double K = m->mats[0].bulk_modulus, p = K * (J - 1);
  for (long i = 0; i < m->n; i++)
    for (int c = 0; c < 3; c++) st->u[3 * i + c] = e * m->x[3 * i + c];
  assert_int_equal(fpm_force(m, st), -1);
  double worst = 0;
  for (long i = 0; i < m->n; i++)
    for (int a = 0; a < 9; a++) {
      const double exact = a % 4 == 0 ? p * J / (1 + e) : 0;
      const double err = fabs(st->P[9 * i + a] - exact) / p;
      if (err > worst) worst = err;
    }
  print_message("uniform dilatation J = %.6f: largest |P - exact| / p = %.3g "
                "over %ld points\n",
                J, worst, m->n);
  assert_true(worst <= 1e-12);
  fpm_state_destroy(st);
  fpm_model_destroy(m);
  fixture_free(fx);
}

/* fpm_force_linear with the averages' coupling is the derivative of
 * fpm_force: K d against central differences along a random d at a
 * finite deformation, for the paper's IIPG flux and for the default
 * formulation (relative 1e-6 of |K d|). */
static void test_linearisation(void **state) {
  (void)state;
  for (int k = 0; k < 2; k++) {
    fpm_model *m;
    fpm_state *st;
    fixture *fx = averaged(0.03, k == 1, &m, &st);
    const double rel = linearisation_error(m, st, 777);
    print_message("%s, averaged J: |K d - central difference| / |K d| = "
                  "%.3g\n",
                  k ? "default formulation" : "IIPG, linear jump", rel);
    assert_true(rel <= 1e-6);
    fpm_state_destroy(st);
    fpm_model_destroy(m);
    fixture_free(fx);
  }
}

/* A share's exchange on one process: the ghosts' scalars are those of the
 * whole model's array `whole` (what their owners compute). */
typedef struct {
  const fpm_model *share;
  const double *whole;
} ghost_source;

static void ghost_scalars_from_whole(void *ctx, double *v) {
  const ghost_source *g = ctx;
  for (long i = g->share->n_own; i < g->share->n; i++)
    v[i] = g->whole[g->share->gid[i]];
}

static void release_nothing(void *ctx) { (void)ctx; }

/* Each share of 2 and 3 of a model with the averaged volume (the default
 * formulation, or the paper's) against the whole model. */
static void shares_as_whole(bool defaults) {
  fpm_model *m;
  fpm_state *st;
  fixture *fx = averaged(0.03, defaults, &m, &st);
  smooth_plus_rough(m, 99, 0.1, 1e-3, st->u, NULL);
  assert_int_equal(fpm_force(m, st), -1);
  int *owner = malloc(sizeof(int) * m->n);
  for (int parts = 2; parts <= 3; parts++) {
    assert_int_equal(fpm_partition(m->dual, parts, owner), PM_SUCCESS);
    for (int r = 0; r < parts; r++) {
      fpm_model *s;
      fpm_state *ss;
      assert_int_equal(fpm_share_create(m, owner, r, &s), PM_SUCCESS);
      assert_int_equal(fpm_state_create(s, &ss), PM_SUCCESS);
      assert_non_null(s->vavg);
      ghost_source src = {.share = s, .whole = st->dUbar};
      fpm_exchange xc = {.ctx = &src,
                         .ghost_scalars = ghost_scalars_from_whole,
                         .release = release_nothing};
      s->xc = &xc;
      for (long i = 0; i < s->n; i++)
        memcpy(ss->u + 3 * i, st->u + 3 * s->gid[i], 3 * sizeof(double));
      assert_int_equal(fpm_force(s, ss), -1);
      assert_share_is_whole(s, ss, st);
      for (long i = 0; i < s->n_own; i++) {
        assert_memory_equal(ss->W + i, st->W + s->gid[i], sizeof(double));
        assert_memory_equal(ss->Jbar + i, st->Jbar + s->gid[i], sizeof(double));
      }
      print_message("averaged J, %s jump, share %d of %d: %ld points, %ld "
                    "ghosts: forces on own points as one process's\n",
                    defaults ? "quadratic" : "linear", r, parts, s->n_own,
                    s->n - s->n_own);
      fpm_state_destroy(ss);
      fpm_model_destroy(s);
    }
  }
  free(owner);
  fpm_state_destroy(st);
  fpm_model_destroy(m);
  fixture_free(fx);
}

/* Across ranks the averaged volume needs no more rings of ghosts: a
 * share's force on its own points, with the ghosts' U'(Jbar) taken from
 * their owners, is one process's bit for bit (f, P, J, W, Jbar), on each
 * of 2 and 3 shares, with the paper's linear jump and with the default
 * formulation's quadratic jump (its ghosts reach over the fits). */
static void test_shares(void **state) {
  for (int k = 0; k < 2; k++) shares_as_whole(k == 1);
  (void)state;
}

/* Every solid model but linear-elastic has the split; a model without it
 * is refused by the model's set-up. */
static void test_split_models(void **state) {
  (void)state;
  const char *const with[] = {"neo-hookean", "neo-hookean-log", "mooney-rivlin",
                              "ogden", "holzapfel-gasser-ogden"};
  for (int k = 0; k < 5; k++) {
    pm_scene_material mat = {0};
    pm_scene_body body = {0};
    gel_model(with[k], &mat, &body);
    assert_true(pm_material_has_volumetric(&mat.mat));
    /* U' is the derivative of U and U'' of U' (central differences) */
    double up[3], um[3], u0[3], J = 1.07, h = 1e-6;
    pm_material_volumetric(&mat.mat, J, u0);
    pm_material_volumetric(&mat.mat, J + h, up);
    pm_material_volumetric(&mat.mat, J - h, um);
    assert_true(fabs((up[0] - um[0]) / (2 * h) - u0[1]) <= 1e-6 * fabs(u0[1]));
    assert_true(fabs((up[1] - um[1]) / (2 * h) - u0[2]) <= 1e-6 * fabs(u0[2]));
  }
  fixture *fx = fixture_new(3, 0.05, 20, true);
  assert_int_equal(
      pm_material_elastic(&fx->mat.mat, "linear-elastic", 1000, 3000, 0.3),
      PM_SUCCESS);
  assert_false(pm_material_has_volumetric(&fx->mat.mat));
  fx->opt.volumetric = FPM_VOLUMETRIC_AVERAGED;
  fpm_model *m = NULL;
  assert_int_equal(
      fpm_model_create(&fx->scene, &fx->opt, fx->mesh, fx->dual, &m),
      PM_ERR_ARG);
  assert_null(m);
  fixture_free(fx);
}

int main(void) {
  gmsh_testing_preload();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_stress_is_gradient),
      cmocka_unit_test(test_uniform_dilatation),
      cmocka_unit_test(test_linearisation),
      cmocka_unit_test(test_split_models),
      cmocka_unit_test(test_shares),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
