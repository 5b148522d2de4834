/* Verification of the comparison with the finite-element referee: case F3
 * 60% (constrained extension) at the coarsest paper resolution is run as
 * the program runs it, and its reaction, mean strain energy density and
 * displacement are set against the CalculiX reference its scene names
 * (reference.fe: cases/fe/f3-extension-60).  The figures are printed; what
 * is asserted is that the comparison works (the FE figures are finite, the
 * run's displacement maps onto the FE lattice), not how close the run
 * comes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm_app.h"
#include "pm_fe.h"
#include "pm_run.h"
#include "pm_scene.h"

#define CASES PM_SOURCE_DIR "/cases/fpm/"

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

static void test_f3_60(void **state) {
  (void)state;
  pm_scene *s = NULL;
  pm_fe_reference *fe = NULL;
  pm_outcome o;
  pm_fe_errors e;
  char dir[] = "/tmp/verify_fe_blocks.XXXXXX";
  if (!mkdtemp(dir)) fail_msg("cannot create a temporary folder");
  if (pm_scene_load(CASES "f3-extension-60-h1.09e-2.yaml", 0, NULL, &s) !=
      PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  assert_non_null(s->reference_fe);
  if (pm_fe_load(s->reference_fe, &fe) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  if (pm_run_scene(s, dir, true, &o) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  assert_int_equal(o.fig.status, PM_STATUS_CONVERGED);
  if (pm_fe_compare(fe, dir, &o, &e) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  const pm_fe_row *f = &fe->rows[fe->finest];
  assert_int_equal(o.loaded_axis, 2);
  print_message("F3 60%%, h = 1.09e-2 m: %ld points, %ld steps, wall %.1f s\n",
                o.fig.points, o.fig.steps, o.fig.wall_seconds);
  print_message("  FE referee %s: N = %d, %s, %ld nodes, CalculiX %s\n",
                fe->dir, f->n, f->element, f->nodes, f->ccx_version);
  print_message("  reaction on the loaded face (z): FPM %.6g N, FE %.6g N, "
                "error %+.2f%%\n",
                o.loaded_reaction, fe->reaction[2], 100 * e.reaction_error);
  print_message("  mean strain energy density: FPM %.6g J/m^3, FE %.6g J/m^3, "
                "error %+.2f%%\n",
                o.fig.mean_sed, fe->mean_sed, 100 * e.sed_error);
  print_message("  displacement NRMSE at the %ld FE lattice points: %.4e\n",
                fe->n, e.nrmse);
  /* The machinery, not the formulation's accuracy. */
  assert_true(isfinite(fe->reaction[2]) && fe->reaction[2] > 0);
  assert_true(isfinite(fe->mean_sed) && fe->mean_sed > 0);
  assert_true(isfinite(e.reaction_error));
  assert_true(isfinite(e.sed_error));
  assert_true(isfinite(e.nrmse) && e.nrmse > 0 && e.nrmse < 1);
  pm_fe_free(fe);
  pm_scene_destroy(s);
  remove_run(dir);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_f3_60),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
