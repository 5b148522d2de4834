/* Verification of rigid plates in contact (FPM): the F2 cube on rollers
 * compressed 40% by a frictionless plate must reach the exact homogeneous
 * solution (u_z = -0.4 z, free lateral expansion) and its reaction. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "fpm_backend.h"
#include "pm_app.h"
#include "pm_metrics.h"
#include "pm_run.h"
#include "pm_scene.h"

#define CASES PM_SOURCE_DIR "/cases/fpm/"

/* The plate's reaction against the exact one, P_zz of uniaxial stress at
 * axial stretch 0.6 times the face's 0.01 m^2, within 1%; the displacement
 * NRMSE against the exact field within 5e-3 (the penalty's penetration,
 * about p h / (kappa E) = 6e-5 m of the 0.04 m, is most of it); the energy
 * balance, the plate's work booked, within 1%. */
static void run_plate(const char *penalty, double tol_reaction, double tol_u) {
  pm_scene *s = NULL;
  fpm_sim *sim = NULL;
  char set_penalty[64];
  snprintf(set_penalty, sizeof set_penalty, "boundary.3.penalty=%s", penalty);
  const char *sets[] = {set_penalty, "time.dt_rule=spectral"};
  if (pm_scene_load(CASES "f2-plates.yaml", 2, sets, &s) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  if (fpm_sim_create(s, &sim) != PM_SUCCESS) fail_msg("%s", pm_error_message());
  pm_outcome o;
  if (pm_run_sim(s, sim, NULL, true, &o) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  assert_int_equal(sim->status, PM_STATUS_CONVERGED);
  const fpm_model *m = sim->model;
  double lateral[2];
  assert_int_equal(pm_material_uniaxial(&m->mats[0], NULL, 0.6, lateral),
                   PM_SUCCESS);
  const double lat = lateral[0];
  const double F[9] = {lat, 0, 0, 0, lat, 0, 0, 0, 0.6};
  double P[9], W, J;
  assert_true(pm_material_stress(&m->mats[0], F, NULL, P, &W, &J));
  const double exact = P[8] * 0.01;
  double *ref = malloc(3 * m->n * sizeof *ref);
  for (long i = 0; i < m->n; i++) {
    ref[3 * i] = (lat - 1) * m->x[3 * i];
    ref[3 * i + 1] = (lat - 1) * m->x[3 * i + 1];
    ref[3 * i + 2] = -0.4 * m->x[3 * i + 2];
  }
  double e[3];
  for (int a = 0; a < 3; a++)
    e[a] = pm_nrmse(m->n, 3, sim->state->u + a, ref + a);
  const double R = o.fig.reaction[3][2], balance = fpm_energy_error(&sim->last);
  print_message("F2 between plates, penalty %s: %ld points, %ld steps, dt "
                "%.3g s; reaction %.5g N (exact %.5g N, %+.3f%%), lateral "
                "%.3g %.3g N; NRMSE u_x %.2e u_y %.2e u_z %.2e; energy "
                "balance %.2e\n",
                penalty, m->n, sim->last.step, sim->dt, R, exact,
                100 * (R / exact - 1), o.fig.reaction[3][0],
                o.fig.reaction[3][1], e[0], e[1], e[2], balance);
  assert_true(fabs(R / exact - 1) <= tol_reaction);
  for (int a = 0; a < 3; a++) assert_true(e[a] <= tol_u);
  assert_true(fabs(balance) <= 0.01);
  free(ref);
  fpm_sim_destroy(sim);
  pm_scene_destroy(s);
}

static void test_plate_frictionless(void **state) {
  (void)state;
  run_plate("100", 0.01, 5e-3);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_plate_frictionless),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
