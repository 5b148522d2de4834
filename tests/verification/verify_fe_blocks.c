/* Verification against the finite-element referee: cases F3 100% and 200%
 * (constrained extension) at the paper's coarsest resolution, h = 1.09e-2 m
 * (1851 points; F3 200%'s scene grades its cloud toward the clamped
 * faces with mesh_size the point budget: 2009 points), run as the program
 * runs their scenes (the default formulation: IIPG, quadratic jump,
 * p = 0.05, averaged volume; dynamic relaxation), and set against the
 * CalculiX references they name (cases/fe: 20-node hexahedra, N = 20).
 * Asserted:
 *  - the top reaction within the 1% of FE for F3 100% (measured
 *    +0.82%; the former default, the standard volume at p = 0.05, gave
 *    +1.15% and was held to 2%) and for F3 200% (graded: +0.32%; on the
 *    uniform cloud +1.59%, held to 2% before the scene was graded);
 *  - the displacement NRMSE at the FE lattice at or below the FPM paper's
 *    figures for this h (1.28e-2, 1.63e-2 against its dense run).
 * F3 60% and F4 20% at this h are the finest level of the ladders that
 * verification.studies (tests/verification/studies.sh) runs against the
 * same referees, asserted there once.
 * F3 60% on the quarter x, y >= 0.05 (two symmetry planes, as the FE
 * referee is solved) by static solve at mesh_size 1e-2 (404 points): the
 * whole block's top reaction (four times the quarter's) within 1% of FE
 * (measured +0.71%), and the displacement at the whole block's lattice
 * (each point outside the quarter from its image) at or below the FPM
 * paper's NRMSE carried to this h by its rate (1.35e-3 at h = 3.73e-3,
 * q = 2.02: 1.43e-2 at h = 1.2e-2; measured 1.09e-2).
 * F4 60% (no converged referee) at 237 points by dynamic relaxation, as
 * its scene runs it (the default formulation and the quadratic jump's
 * stiffening from an onset in the current spacing, which the scene names:
 * without it the relaxation stops on the energy balance at t = 1.22 s):
 * it completes, every J stays positive and the energy balance error stays
 * under 5% (measured -2.4%). */
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
#include <unistd.h>

#include "pm_app.h"
#include "pm_fe.h"
#include "pm_run.h"
#include "pm_scene.h"
#include "gmsh_testing.h"

#define CASES PM_SOURCE_DIR "/cases/fpm/"

/* Every case at the coarsest level of the paper's ladder (h = 1.09e-2 m),
 * as its scene runs it: the default formulation. */
static const char *const COARSEST[] = {"discretization.mesh_size=8.72e-3"};

/* Remove the run's files and its folder. */
static void remove_run(const char *dir) {
  static const char *const files[] = {"results.h5", "results.xdmf",
                                      "history.csv", "summary.json"};
  char path[600];
  for (size_t k = 0; k < sizeof files / sizeof *files; k++) {
    snprintf(path, sizeof path, "%s/%s", dir, files[k]);
    unlink(path);
  }
  rmdir(dir);
}

typedef struct {
  const char *scene;
  double reaction_tol; /* |reaction error| bound */
  double nrmse_paper;  /* the paper's NRMSE at this h (rate: at h_paper) */
  bool nrmse_asserted;
  /* The overrides (NULL: COARSEST), and where the paper's figure is at
   * another h, that h and the paper's rate, which carry it to the run's. */
  const char *const *sets;
  int n_sets;
  double h_paper, rate;
} fe_case;

static void check_case(const fe_case *c) {
  pm_scene *s = NULL;
  pm_fe_reference *fe = NULL;
  pm_outcome o;
  pm_fe_errors e;
  char dir[] = "/tmp/verify_fe_blocks.XXXXXX", path[512];
  if (!mkdtemp(dir)) fail_msg("cannot create a temporary folder");
  snprintf(path, sizeof path, CASES "%s", c->scene);
  if (pm_scene_load(path, c->sets ? c->n_sets : 1, c->sets ? c->sets : COARSEST,
                    &s) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  assert_non_null(s->reference_fe);
  if (pm_fe_load(s->reference_fe, &fe) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  if (pm_run_scene(s, dir, true, &o) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  assert_int_equal(o.fig.status, PM_STATUS_CONVERGED);
  if (pm_fe_compare(fe, s, dir, &o, &e) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  const pm_fe_row *f = &fe->rows[fe->finest];
  const double nrmse_bound =
      c->rate > 0 ? c->nrmse_paper * pow(o.fig.h / c->h_paper, c->rate)
                  : c->nrmse_paper;
  assert_int_equal(o.loaded_axis, 2);
  print_message("%s%s: %ld points (h %.3g m), %ld steps, wall %.1f s; FE N = "
                "%d %s\n",
                c->scene, s->mirror_mask ? " on the quarter" : "", o.fig.points,
                o.fig.h, o.fig.steps, o.fig.wall_seconds, f->n, f->element);
  print_message("  top reaction: FPM %.6g N, FE %.6g N, error %+.2f%% "
                "(bound %.0f%%)\n",
                o.loaded_reaction, fe->reaction[2], 100 * e.reaction_error,
                100 * c->reaction_tol);
  print_message("  mean strain energy density: FPM %.6g, FE %.6g J/m^3, "
                "error %+.2f%%\n",
                o.fig.mean_sed, fe->mean_sed, 100 * e.sed_error);
  print_message("  displacement NRMSE at the %ld FE lattice points: %.3e "
                "(paper%s %.3e%s)\n",
                fe->n, e.nrmse, c->rate > 0 ? ", carried to this h" : "",
                nrmse_bound, c->nrmse_asserted ? ", bound" : ", not asserted");
  print_message("  the same off the lattice's faces: %.3e\n", e.nrmse_interior);
  assert_true(isfinite(e.reaction_error) && isfinite(e.nrmse));
  assert_true(fabs(e.reaction_error) <= c->reaction_tol);
  if (c->nrmse_asserted) assert_true(e.nrmse <= nrmse_bound);
  pm_fe_free(fe);
  pm_scene_destroy(s);
  remove_run(dir);
}

static void test_f3_100(void **state) {
  (void)state;
  check_case(&(fe_case){.scene = "f3-extension-100.yaml",
                        .reaction_tol = 0.01,
                        .nrmse_paper = 1.28e-2,
                        .nrmse_asserted = true});
}
static void test_f3_200(void **state) {
  (void)state;
  check_case(&(fe_case){.scene = "f3-extension-200.yaml",
                        .reaction_tol = 0.01,
                        .nrmse_paper = 1.63e-2,
                        .nrmse_asserted = true});
}

/* F3 60% on the quarter by static solve (see the head of this file). */
static void test_f3_60_quarter(void **state) {
  (void)state;
  static const char *const quarter[] = {
      "discretization.mesh_size=1e-2", "time.quasi_static.method=static",
      "domain.box.min=[0.05, 0.05, 0]", "boundary.2={on: xmin, symmetry: true}",
      "boundary.3={on: ymin, symmetry: true}"};
  check_case(&(fe_case){.scene = "f3-extension-60.yaml",
                        .reaction_tol = 0.01,
                        .nrmse_paper = 1.35e-3,
                        .nrmse_asserted = true,
                        .sets = quarter,
                        .n_sets = 5,
                        .h_paper = 3.73e-3,
                        .rate = 2.02});
}

/* F4 60% completes as its scene runs it at a coarse cloud. */
static void test_f4_60_completes(void **state) {
  (void)state;
  static const char *const coarse[] = {"discretization.mesh_size=0.02"};
  pm_scene *s = NULL;
  pm_outcome o;
  char dir[] = "/tmp/verify_fe_blocks.XXXXXX";
  if (!mkdtemp(dir)) fail_msg("cannot create a temporary folder");
  if (pm_scene_load(CASES "f4-compression-60.yaml", 1, coarse, &s) !=
      PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  if (pm_run_scene(s, dir, true, &o) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  print_message("f4-compression-60.yaml: %ld points, %ld steps, top reaction "
                "%.6g N, smallest J %.3f, energy balance error %+.4f "
                "(bound 0.05)\n",
                o.fig.points, o.fig.steps, o.loaded_reaction,
                o.fig.min_jacobian, o.fig.energy_error);
  assert_int_equal(o.fig.status, PM_STATUS_CONVERGED);
  assert_true(o.fig.min_jacobian > 0);
  assert_true(fabs(o.fig.energy_error) <= 0.05);
  pm_scene_destroy(s);
  remove_run(dir);
}

int main(void) {
  gmsh_testing_preload();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_f4_60_completes),
      cmocka_unit_test(test_f3_60_quarter),
      cmocka_unit_test(test_f3_100),
      cmocka_unit_test(test_f3_200),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
