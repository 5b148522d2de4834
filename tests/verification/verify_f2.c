/* Verification of case F2 (FPM paper section 3.2): the 40% unconstrained
 * compression of the neo-Hookean cube run from rest to its quasi-static
 * state must reproduce the exact homogeneous solution. */
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
#include "pm_run.h"
#include "pm_metrics.h"
#include "pm_scene.h"
#include "gmsh_testing.h"

#define CASES PM_SOURCE_DIR "/cases/fpm/"

/* NRMSE (eq. 28) of u_z against -0.4 z must be <= 1e-5, and so must the
 * lateral components against (s - 1) x, (s - 1) y with s the exact lateral
 * stretch of uniaxial stress at axial stretch 0.6.  h: the mean edge,
 * mesh_size: the gmsh element size giving it (the scene's ladder); cells:
 * the fpm.cells builder. */
static void run_f2(const char *h, const char *mesh_size, const char *dt_rule,
                   const char *cells) {
  pm_scene *s = NULL;
  fpm_sim *sim = NULL;
  char set_size[64], set[64], set_cells[64];
  snprintf(set_size, sizeof set_size, "discretization.mesh_size=%s", mesh_size);
  snprintf(set, sizeof set, "time.dt_rule=%s", dt_rule);
  snprintf(set_cells, sizeof set_cells, "fpm.cells=%s", cells);
  const char *sets[] = {set_size, set, set_cells};
  if (pm_scene_load(CASES "f2-unconstrained-compression.yaml", 3, sets, &s) !=
      PM_SUCCESS)
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
  double *ref = malloc(3 * m->n * sizeof *ref);
  for (long i = 0; i < m->n; i++) {
    ref[3 * i] = (lat - 1) * m->x[3 * i];
    ref[3 * i + 1] = (lat - 1) * m->x[3 * i + 1];
    ref[3 * i + 2] = -0.4 * m->x[3 * i + 2];
  }
  double ex = pm_nrmse(m->n, 3, sim->state->u, ref);
  double ey = pm_nrmse(m->n, 3, sim->state->u + 1, ref + 1);
  double ez = pm_nrmse(m->n, 3, sim->state->u + 2, ref + 2);
  print_message("F2 h = %s m (mean edge %.3g m), %s cells, %s dt: %ld "
                "points, %ld steps, dt %.3g s, NRMSE u_z %.3e (scene "
                "reference %.3e), u_x %.3e, u_y %.3e, wall %.2f s\n",
                h, sim->mean_edge, cells, dt_rule, m->n, sim->last.step,
                sim->dt, ez, o.nrmse[2], ex, ey, o.fig.wall_seconds);
  /* Energy: kinetic + strain + interface + dissipated = work of the
   * supports. */
  const fpm_step_info *e = &sim->last;
  double balance = fpm_energy_error(e);
  print_message("  energy: strain %.6g J, dissipated %.6g J, external %.6g J, "
                "balance error %.2e\n",
                e->strain, e->dissipated, e->external_work, balance);
  assert_true(fabs(balance) <= 0.01);
  assert_true(ez <= 1e-5);
  assert_true(fabs(o.nrmse[2] - ez) <= 1e-12);
  assert_true(ex <= 1e-5);
  assert_true(ey <= 1e-5);
  free(ref);
  fpm_sim_destroy(sim);
  pm_scene_destroy(s);
}

static void test_f2_h1(void **state) {
  (void)state;
  run_f2("1.09e-2", "8.72e-3", "paper", "median-dual");
}

/* The measured spectral step (about 8 times the paper's bound here) keeps
 * the run stable and the answer the same, at both resolutions; the finer
 * one takes it so that the test holds on a shared machine (with the
 * paper's bound it took most of the test's 95 s). */
static void test_f2_h2(void **state) {
  (void)state;
  run_f2("8.02e-3", "6.42e-3", "spectral", "median-dual");
}

static void test_f2_spectral(void **state) {
  (void)state;
  run_f2("1.09e-2", "8.72e-3", "spectral", "median-dual");
}

/* On the Voronoi cells of the same nodes: the operator passes the patch
 * test on them too, so the exact state is again the discrete one. */
static void test_f2_voronoi(void **state) {
  (void)state;
  run_f2("1.09e-2", "8.72e-3", "spectral", "voronoi");
}

int main(void) {
  gmsh_testing_preload();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_f2_h1),
      cmocka_unit_test(test_f2_h2),
      cmocka_unit_test(test_f2_spectral),
      cmocka_unit_test(test_f2_voronoi),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
