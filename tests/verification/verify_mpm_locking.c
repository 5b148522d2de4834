/* Verification of F-bar (mpm.fbar) on volumetric locking: a nearly
 * incompressible simply supported beam under its own weight, plane strain,
 * linear shape functions (cases/mpm/locking-beam.yaml), settled by dynamic
 * relaxation at nu = 0.45, 0.48 and 0.495, with each particle's own J
 * (none) and with J averaged over the cells and over the nodes' patches.
 * The mid-span deflection is compared with Timoshenko's beam, and the
 * particles' pressure with the beam's. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_verify.h"
#include "mpm_model.h"
#include "pm_scene.h"

#define SCENE PM_SOURCE_DIR "/cases/mpm/locking-beam.yaml"

/* Bound on |deflection / Timoshenko's - 1| with F-bar, at every nu, set
 * before the runs as the error a locking-free linear discretization of 4
 * cells through the depth should stay within.  Besides the discretization
 * it holds the beam model against the plane problem (Timoshenko and
 * Goodier's plane stress solution differs from Timoshenko's beam by
 * 0.72 nu (H / L)^2 of the bending deflection at mid-span: 0.4%) and the
 * relaxation's residual (1e-4: the deflection moves by 0.1% down to
 * 1e-5). */
#define FBAR_DEFLECTION_BOUND 0.10
/* Without F-bar the beam locks: at nu = 0.495 its error must be at least
 * three times the F-bar bound. */
#define LOCKED_DEFLECTION_MIN 0.30

static const double nus[] = {0.45, 0.48, 0.495};
static const char *const modes[] = {"none", "cell", "patch"};
enum { N_NU = 3, N_MODE = 3 };

/* What a run gives. */
typedef struct {
  double deflection, reference; /* mid-span, m */
  double pressure_error;        /* rms(p - p_beam) / rms(p_beam) */
  long steps;
  double wall;
} beam_result;

/* The beam's constants, from the scene. */
typedef struct {
  double L, H, h, q, Ep, G, nu;
} beam;

static beam beam_of(const pm_scene *s) {
  const pm_material *m = &s->materials[0].mat;
  const pm_scene_body *b = &s->bodies[0];
  beam bm;
  bm.nu = m->poisson_ratio;
  bm.L = 2 * (b->b[0] - b->a[0]); /* the model is half the span */
  bm.H = b->b[1] - b->a[1];
  bm.h = s->mesh_size;
  bm.q = m->density * -s->gravity[1] * bm.H;
  bm.Ep = m->youngs_modulus / (1 - bm.nu * bm.nu); /* plane strain */
  bm.G = m->shear_modulus;
  return bm;
}

/* Timoshenko's deflection at x of the simply supported beam of span L
 * under q: bending plus shear with kappa = 5/6. */
static double timoshenko(const beam *b, double x) {
  const double I = b->H * b->H * b->H / 12, kGA = 5.0 / 6.0 * b->G * b->H;
  const double L = b->L;
  return b->q * x * (L * L * L - 2 * L * x * x + x * x * x) / (24 * b->Ep * I) +
         b->q * x * (L - x) / (2 * kGA);
}

/* The beam's pressure at (x, y): -(sigma_xx + sigma_yy + sigma_zz) / 3 with
 * sigma_zz = nu (sigma_xx + sigma_yy) (plane strain), sigma_yy neglected
 * (rho g H against the bending stress: 1.3% at the largest) and sigma_xx
 * = -M (y - H/2) / I, M = q x (L - x) / 2 (the beam lies on [0, H]). */
static double beam_pressure(const beam *b, double x, double y) {
  const double I = b->H * b->H * b->H / 12;
  const double M = b->q * x * (b->L - x) / 2;
  return (1 + b->nu) * M * (y - b->H / 2) / I / 3;
}

static pm_scene *load(double nu, const char *mode, int n_more,
                      const char *const *more) {
  char s_nu[64], s_mode[64];
  snprintf(s_nu, sizeof s_nu, "materials.0.poisson_ratio=%g", nu);
  snprintf(s_mode, sizeof s_mode, "mpm.fbar=%s", mode);
  const char *sets[8] = {s_nu, s_mode};
  for (int k = 0; k < n_more && k < 6; k++) sets[2 + k] = more[k];
  return load_scene(SCENE, 2 + n_more, sets);
}

/* Settle the beam; its mid-span deflection (the mean over the particles of
 * the last cell column, against the same mean of Timoshenko's) and the
 * pressure away from the support (x > 2 h). */
static beam_result run_beam(double nu, const char *mode, int n_more,
                            const char *const *more) {
  pm_scene *s = load(nu, mode, n_more, more);
  const beam b = beam_of(s);
  verify_run *r = verify_create(s);
  verify_go(r, PM_STATUS_CONVERGED);
  const mpm_model *m = r->sim->model;
  const mpm_state *st = r->sim->state;
  beam_result res = {.steps = st->step, .wall = r->out.fig.wall_seconds};
  long n_mid = 0;
  double e2 = 0, p2 = 0;
  for (long p = 0; p < m->n; p++) {
    const double *x0 = m->x0 + 3 * p, *sg = st->sigma + 9 * p;
    if (x0[0] > b.L / 2 - b.h) {
      res.deflection -= st->x[3 * p + 1] - x0[1];
      res.reference += timoshenko(&b, x0[0]);
      n_mid++;
    }
    if (x0[0] > 2 * b.h) {
      const double pb = beam_pressure(&b, x0[0], x0[1]);
      const double pp = -(sg[0] + sg[4] + sg[8]) / 3;
      e2 += (pp - pb) * (pp - pb);
      p2 += pb * pb;
    }
  }
  res.deflection /= n_mid;
  res.reference /= n_mid;
  res.pressure_error = sqrt(e2 / p2);
  verify_destroy(r);
  pm_scene_destroy(s);
  return res;
}

/* The table of every nu and mode, and the checks. */
static void test_locking_beam(void **state) {
  (void)state;
  beam_result res[N_NU][N_MODE];
  for (int i = 0; i < N_NU; i++)
    for (int j = 0; j < N_MODE; j++)
      res[i][j] = run_beam(nus[i], modes[j], 0, NULL);
  printf("\nSimply supported beam under its own weight (%s):\n"
         "  mid-span deflection against Timoshenko's (plane strain, kappa "
         "5/6),\n  pressure: rms(p - p_beam) / rms(p_beam) for x > 2 h\n",
         SCENE);
  printf("  %-6s %-6s %12s %12s %9s %10s %8s %7s\n", "nu", "fbar", "deflection",
         "Timoshenko", "error", "pressure", "steps", "wall");
  bool ok = true;
  for (int i = 0; i < N_NU; i++)
    for (int j = 0; j < N_MODE; j++) {
      const beam_result *b = &res[i][j];
      const double err = b->deflection / b->reference - 1;
      const bool fbar = j > 0;
      /* NaN-safe: a NaN fails */
      const bool good = !fbar || fabs(err) <= FBAR_DEFLECTION_BOUND;
      ok &= good;
      printf("  %-6g %-6s %12.5e %12.5e %+9.4f %10.3f %8ld %6.1fs %s\n", nus[i],
             modes[j], b->deflection, b->reference, err, b->pressure_error,
             b->steps, b->wall, fbar ? (good ? "ok" : "FAIL") : "");
    }
  const double locked =
      res[N_NU - 1][0].deflection / res[N_NU - 1][0].reference;
  printf("  bounds: |error| <= %g with F-bar at every nu; without it, at nu "
         "= %g, error <= -%g: %s\n",
         FBAR_DEFLECTION_BOUND, nus[N_NU - 1], LOCKED_DEFLECTION_MIN,
         1 - locked >= LOCKED_DEFLECTION_MIN ? "ok" : "FAIL");
  fflush(stdout);
  assert_true(ok);
  /* Locking makes the beam too stiff. */
  assert_true(1 - locked >= LOCKED_DEFLECTION_MIN);
  /* F-bar's pressure follows the beam's more closely than each particle's
   * own J does, at every nu. */
  for (int i = 0; i < N_NU; i++)
    for (int j = 1; j < N_MODE; j++)
      assert_true(res[i][j].pressure_error < res[i][0].pressure_error);
}

/* Linear elasticity in its Jaumann rate form (no F in the stress): F-bar
 * replaces the volumetric part of D by the rate of the averaged J.  The
 * same bounds at nu = 0.495. */
static void test_rate_form(void **state) {
  (void)state;
  const char *const more[] = {"materials.0.model=linear-elastic"};
  const double nu = nus[N_NU - 1];
  printf("\nThe same beam, linear-elastic (Jaumann rate form), nu = %g:\n", nu);
  printf("  %-6s %12s %12s %9s %10s %8s\n", "fbar", "deflection", "Timoshenko",
         "error", "pressure", "steps");
  double err[N_MODE], pe[N_MODE];
  for (int j = 0; j < N_MODE; j++) {
    const beam_result b = run_beam(nu, modes[j], 1, more);
    err[j] = b.deflection / b.reference - 1;
    pe[j] = b.pressure_error;
    printf("  %-6s %12.5e %12.5e %+9.4f %10.3f %8ld\n", modes[j], b.deflection,
           b.reference, err[j], pe[j], b.steps);
  }
  fflush(stdout);
  assert_true(-err[0] >= LOCKED_DEFLECTION_MIN);
  for (int j = 1; j < N_MODE; j++) {
    assert_true(fabs(err[j]) <= FBAR_DEFLECTION_BOUND);
    assert_true(pe[j] < pe[0]);
  }
}

/* The state after `steps` steps of the beam at nu = 0.495 with F-bar in
 * `mode`, in dynamics (OpenMP's sum reductions of the dynamic relaxation
 * combine threads' shares in no fixed order once there are more than two):
 * positions, velocities, stresses and the group's arrays (F and Jbar - 1),
 * concatenated into a new array of *count doubles. */
static double *state_after(const char *mode, const char *model, long steps,
                           long *count) {
  char s_steps[64], s_model[64];
  snprintf(s_steps, sizeof s_steps, "time.max_steps=%ld", steps);
  snprintf(s_model, sizeof s_model, "materials.0.model=%s", model);
  const char *more[] = {s_steps, s_model, "time.quasi_static.method=none"};
  pm_scene *s = load(0.495, mode, 3, more);
  verify_run *r = verify_create(s);
  verify_go(r, PM_STATUS_COMPLETED);
  const mpm_model *m = r->sim->model;
  const mpm_state *st = r->sim->state;
  mpm_array a[MPM_STATE_MAX_ARRAYS];
  const int na = mpm_state_arrays(m, st, a, MPM_STATE_MAX_ARRAYS);
  long n = 0;
  for (int k = 0; k < na; k++) n += a[k].ncomp * a[k].count;
  double *all = malloc(sizeof(double) * (size_t)n);
  assert_non_null(all);
  n = 0;
  for (int k = 0; k < na; k++) {
    memcpy(all + n, a[k].data, sizeof(double) * a[k].ncomp * a[k].count);
    n += a[k].ncomp * a[k].count;
  }
  assert_non_null(mpm_group_state_find(&st->group[0], "Jbar_minus_1"));
  verify_destroy(r);
  pm_scene_destroy(s);
  *count = n;
  return all;
}

/* The averages are partial sums per thread added in thread order: two runs
 * on the same threads end bit for bit the same (on any number of threads),
 * for both averages and both kinds of stress update (from Fbar, and the
 * rate form's averaged tr D). */
static void test_repeats_bit_for_bit(void **state) {
  (void)state;
  const char *const models[] = {"neo-hookean", "linear-elastic"};
  for (int j = 1; j < N_MODE; j++)
    for (int k = 0; k < 2; k++) {
      long na, nb;
      double *a = state_after(modes[j], models[k], 400, &na);
      double *b = state_after(modes[j], models[k], 400, &nb);
      assert_int_equal(na, nb);
      const bool same = memcmp(a, b, sizeof(double) * (size_t)na) == 0;
      printf("  fbar %-5s %-14s 400 steps twice: %s\n", modes[j], models[k],
             same ? "identical" : "DIFFERENT");
      free(a);
      free(b);
      assert_true(same);
    }
}

/* The same beam by the implicit MPM (grid kept, Newton to the
 * equilibrium: no relaxation's residual), with each particle's own J and
 * with F-bar over the cells, at every nu. */
static void test_implicit(void **state) {
  (void)state;
  const char *const more[] = {"method=mpm-implicit",
                              "time.quasi_static.tolerance=1e-10"};
  const char *const imodes[] = {"none", "cell"};
  printf("\nThe same beam by the implicit MPM (grid kept):\n");
  printf("  %-6s %-6s %12s %12s %9s %10s %7s\n", "nu", "fbar", "deflection",
         "Timoshenko", "error", "pressure", "wall");
  double err[N_NU][2], pe[N_NU][2];
  for (int i = 0; i < N_NU; i++)
    for (int j = 0; j < 2; j++) {
      const beam_result b = run_beam(nus[i], imodes[j], 2, more);
      err[i][j] = b.deflection / b.reference - 1;
      pe[i][j] = b.pressure_error;
      printf("  %-6g %-6s %12.5e %12.5e %+9.4f %10.3f %6.2fs\n", nus[i],
             imodes[j], b.deflection, b.reference, err[i][j], pe[i][j], b.wall);
    }
  fflush(stdout);
  for (int i = 0; i < N_NU; i++) {
    assert_true(fabs(err[i][1]) <= FBAR_DEFLECTION_BOUND);
    assert_true(pe[i][1] < pe[i][0]);
  }
  assert_true(-err[N_NU - 1][0] >= LOCKED_DEFLECTION_MIN);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_locking_beam),
      cmocka_unit_test(test_rate_form),
      cmocka_unit_test(test_implicit),
      cmocka_unit_test(test_repeats_bit_for_bit),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
