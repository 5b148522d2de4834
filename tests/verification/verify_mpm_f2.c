/* Verification of case F2 run by the explicit MPM
 * (cases/mpm/f2-unconstrained-compression.yaml): the neo-Hookean cube
 * compressed by 40% on rollers reaches the exact homogeneous state, u_z =
 * -0.4 z, with the exact reaction on the loaded face. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>

#include <string.h>

#include "mpm_verify.h"
#include "pm_scene.h"
#include "pm_tensor.h"

#define SCENE PM_SOURCE_DIR "/cases/mpm/f2-unconstrained-compression.yaml"

static void test_f2_mpm(void **state) {
  (void)state;
  pm_scene *s = NULL;
  verify_run *r = NULL;
  /* The coarsest cell of the study (1000 particles). */
  const char *sets[] = {"discretization.mesh_size=2e-2"};
  s = load_scene(SCENE, 1, sets);
  r = verify_create(s);
  if (pm_run_sim(s, r->sim, NULL, true, &r->out) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  assert_int_equal(r->out.fig.status, PM_STATUS_CONVERGED);
  /* The exact reaction: uniaxial stress at axial stretch 0.6, P_zz of
   * F = diag(s, s, 0.6) with the traction-free lateral stretch s, times
   * the reference area 0.1 x 0.1. */
  const pm_material *mat = &s->materials[0].mat;
  double lateral[2], P[9];
  assert_int_equal(pm_material_uniaxial(mat, NULL, 0.6, lateral), PM_SUCCESS);
  const double lat = lateral[0];
  double F[9] = {lat, 0, 0, 0, lat, 0, 0, 0, 0.6};
  assert_true(pm_material_stress(mat, F, NULL, P, NULL, NULL));
  double exact = P[8] * 0.01;
  int top = 3; /* boundary.3: zmax */
  double R[3];
  memcpy(R, r->out.fig.reaction[top], sizeof R);
  print_message("F2 by MPM, cell 0.02 m: %ld particles, %ld steps, %.2f s; "
                "NRMSE u_z %.3e; reaction %.4f N (exact %.4f N, %.2e); "
                "energy balance %.2e\n",
                r->sim->model->n, r->sim->state->step, r->out.fig.wall_seconds,
                r->out.nrmse_vector, -R[2], -exact, fabs(R[2] / exact - 1),
                r->out.fig.energy_error);
  /* NRMSE (eq. 28: over the range of the reference component): measured
   * 1.85e-3 (1.75e-3 over the largest |reference|, the form this test
   * used before both methods reported eq. 28), the level the relaxation's
   * tolerance (1e-4)
   * leaves (7.3e-4 at 1e-5 for the 0.01 m cell); bound 5e-3.  Reaction:
   * measured within 1e-4; bound 1%.  Energy: measured 5.5e-4; bound 1%. */
  assert_true(r->out.nrmse_vector <= 5e-3);
  assert_true(fabs(R[2] / exact - 1) <= 0.01);
  assert_true(fabs(r->out.fig.energy_error) <= 0.01);
  verify_destroy(r);
  pm_scene_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_f2_mpm)};
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
