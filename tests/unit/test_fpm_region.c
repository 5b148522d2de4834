/* The share a rank builds without the whole model, on the bytes of its
 * part of the cells that rank 0 cuts and sends (fpm_region.h), against
 * the share cut from the whole model (fpm_share_create): every array, bit
 * for bit, on 2 and 4 ranks, for the linear and quadratic jumps, IIPG and
 * SIPG, the averaged volume and a traction face; and no rank's build
 * reads a whole model (none is made on that path). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "fpm_gfd.h"
#include "fpm_region.h"
#include "fpm_share.h"
#include "fpm_share_testing.h"
#include "fpm_stream.h"
#include "fpm_testing.h"
#include "gmsh_testing.h"

static void assert_same_share(const fpm_model *a, const fpm_model *b) {
  assert_int_equal(a->n, b->n);
  assert_int_equal(a->n_own, b->n_own);
  assert_int_equal(a->n_flux, b->n_flux);
  assert_int_equal(a->n_stress, b->n_stress);
  assert_int_equal(a->nnz, b->nnz);
  assert_int_equal(a->n_dpts, b->n_dpts);
  assert_int_equal(a->n_tfacets, b->n_tfacets);
  assert_int_equal(a->n_cdofs, b->n_cdofs);
  fpm_share_array in_a[FPM_SHARE_ARRAYS], in_b[FPM_SHARE_ARRAYS];
  const int na = fpm_share_arrays(a, in_a);
  assert_int_equal(fpm_share_arrays(b, in_b), na);
  for (int k = 0; k < na; k++) {
    if (!in_a[k].data || !in_b[k].data) {
      if (in_a[k].data != in_b[k].data)
        fail_msg("%s: held by one share only", in_a[k].name);
      continue;
    }
    assert_int_equal(in_a[k].bytes, in_b[k].bytes);
    if (in_a[k].bytes && memcmp(in_a[k].data, in_b[k].data, in_a[k].bytes))
      fail_msg("%s: the shares differ", in_a[k].name);
  }
  if (memcmp(a->dual->volume, b->dual->volume, sizeof(double) * a->n))
    fail_msg("volume: the shares differ");
}

static void check_options(fixture *fx, const char *what) {
  fpm_model *m;
  fpm_state *st;
  fixture_model(fx, &m, &st);
  int *owner = malloc(sizeof(int) * m->n);
  for (int parts = 2; parts <= 4; parts += 2) {
    assert_int_equal(fpm_partition(fx->dual, parts, owner), PM_SUCCESS);
    long held = 0, least = m->n;
    for (int r = 0; r < parts; r++) {
      fpm_model *cut, *built;
      assert_int_equal(fpm_share_create(m, owner, r, &cut), PM_SUCCESS);
      assert_int_equal(fpm_share_build(&fx->scene, &fx->opt, fx->mesh,
                                       &fx->dual, false, owner, r, &built),
                       PM_SUCCESS);
      assert_same_share(cut, built);
      if (r == 0) { /* the whole cells let go on the way: the same share */
        gm_dual *cells = NULL;
        fpm_model *again;
        assert_int_equal(gm_dual_build(fx->mesh, &cells), PM_SUCCESS);
        assert_int_equal(fpm_share_build(&fx->scene, &fx->opt, fx->mesh, &cells,
                                         true, owner, r, &again),
                         PM_SUCCESS);
        assert_null(cells);
        assert_same_share(cut, again);
        fpm_model_destroy(again);
      }
      held += built->n;
      least = built->n < least ? built->n : least;
      fpm_model_destroy(cut);
      fpm_model_destroy(built);
    }
    /* Some share holds a part of the points: its edge is tested. */
    assert_true(least < m->n);
    print_message("%s, %d ranks: %ld points, %ld held by the shares built "
                  "without the whole model (%ld the fewest), each the share "
                  "cut from it\n",
                  what, parts, m->n, held, least);
  }
  free(owner);
  fpm_state_destroy(st);
  fpm_model_destroy(m);
}

static void test_shares_built(void **state) {
  (void)state;
  const int flux[3] = {FPM_FLUX_IIPG, FPM_FLUX_SIPG, FPM_FLUX_IIPG};
  const int jump[3] = {FPM_JUMP_LINEAR, FPM_JUMP_LINEAR, FPM_JUMP_QUADRATIC};
  const char *name[3] = {"IIPG linear", "SIPG linear", "IIPG quadratic"};
  for (int k = 0; k < 3; k++) {
    fixture *fx = fixture_new(3, 0.01, 20, true);
    fx->opt.flux = flux[k];
    fx->opt.jump = jump[k];
    check_options(fx, name[k]);
    fixture_free(fx);
  }
}

/* The default formulation (quadratic jump, averaged volume) with the top
 * face under a traction that varies along it. */
static void test_shares_built_defaults(void **state) {
  (void)state;
  fixture *fx = fixture_new(3, 0.01, 20, true);
  fixture_defaults(fx);
  fx->opt.volumetric = FPM_VOLUMETRIC_AVERAGED;
  pm_scene_bc *top = &fx->bcs[3];
  pm_expr_destroy(top->disp[2]);
  top->disp[2] = NULL;
  top->disp_mask = 0;
  top->traction_mask = 1u << 2;
  assert_int_equal(pm_expr_create("-100 * (1 + x)", &top->traction[2]),
                   PM_SUCCESS);
  check_options(fx, "defaults with a traction face");
  pm_expr_destroy(top->traction[2]);
  fixture_free(fx);
}

int main(void) {
  gmsh_testing_preload();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_shares_built),
      cmocka_unit_test(test_shares_built_defaults),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
