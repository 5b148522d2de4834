/* Verification of case I1, reduced (cases/mpm/i1-construct-reduced.yaml):
 * the synthetic construct (128 x 128 x 13 voxels, 10.4% vessels) pulled to
 * 10% by the implicit MPM, grid kept, with vessels twice as stiff as the
 * collagen and with vessels of collagen.
 *   - The stiffer vessels raise the reaction by a ratio between the
 *     bounds of a two-phase composite of 10.4% stiffer phase in the same
 *     shape: Reuss's (phases in series, 1 / (0.896 + 0.104 / 2) = 1.0549)
 *     and Voigt's (in parallel, 0.896 + 0.104 x 2 = 1.104).  They bound the
 *     effective modulus of a uniformly strained (Voigt) or stressed (Reuss)
 *     composite; the grips' lateral constraint is the same in both runs.
 *   - The vessels carry more stress than the collagen (the paper's
 *     finding): their mean von Mises stress is the larger. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>

#include "mpm_verify.h"
#include "pm_tensor.h"

#define SCENE PM_SOURCE_DIR "/cases/mpm/i1-construct-reduced.yaml"

typedef struct {
  double reaction;   /* at the pulled face, N */
  double vm[2];      /* mean von Mises stress of collagen, vessels */
  long particles[2]; /* of collagen, vessels */
  double wall;
} i1_result;

static i1_result run_i1(int n_sets, const char *const *sets) {
  pm_scene *s = load_scene(SCENE, n_sets, sets);
  verify_run *r = verify_create(s);
  verify_go(r, PM_STATUS_CONVERGED);
  const mpm_model *m = r->sim->model;
  i1_result res = {.reaction = r->out.fig.reaction[1][1],
                   .wall = r->out.fig.wall_seconds};
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    double sum = 0;
    for (long p = g->begin; p < g->end; p++)
      sum += pm_t_von_mises(r->sim->state->sigma + 9 * p);
    res.vm[gi] = sum / (double)(g->end - g->begin);
    res.particles[gi] = g->end - g->begin;
  }
  verify_destroy(r);
  pm_scene_destroy(s);
  return res;
}

static void test_i1_reduced(void **state) {
  (void)state;
  const i1_result base = run_i1(0, NULL);
  const char *soft[] = {"materials.1.shear_modulus=520.8",
                        "materials.1.bulk_modulus=1041.6"};
  const i1_result same = run_i1(2, soft);
  const double ratio = base.reaction / same.reaction;
  const double reuss = 1 / (0.896 + 0.104 / 2), voigt = 0.896 + 0.104 * 2;
  print_message("I1 reduced: %ld collagen and %ld vessel particles; "
                "reaction at 10%% %.2f nN (vessels 2 mu, %.1f s), %.2f nN "
                "(vessels of collagen, %.1f s): ratio %.4f, bounds Reuss "
                "%.4f and Voigt %.4f; mean von Mises collagen %.1f Pa, "
                "vessels %.1f Pa\n",
                base.particles[0], base.particles[1], base.reaction * 1e9,
                base.wall, same.reaction * 1e9, same.wall, ratio, reuss, voigt,
                base.vm[0], base.vm[1]);
  assert_int_equal(base.particles[1], 22151); /* 10.40% of the voxels */
  assert_true(ratio > reuss && ratio < voigt);
  assert_true(base.vm[1] > base.vm[0]);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_i1_reduced)};
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
