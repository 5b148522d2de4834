/* The share a rank builds without the whole model (fpm_region.h) against
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
#include "fpm_stream.h"
#include "fpm_testing.h"

/* Arrays of count items of size bytes each, equal bit for bit (both NULL,
 * or both held). */
static void same(const char *what, const void *a, const void *b, long count,
                 size_t size) {
  if (!a || !b) {
    if (a != b) fail_msg("%s: held by one share only", what);
    return;
  }
  if (count > 0 && memcmp(a, b, size * (size_t)count) != 0)
    fail_msg("%s: the shares differ", what);
}

#define SAME(field, count)                                                     \
  same(#field, a->field, b->field, (long)(count), sizeof *a->field)

static void assert_same_share(const fpm_model *a, const fpm_model *b) {
  assert_int_equal(a->n, b->n);
  assert_int_equal(a->n_own, b->n_own);
  assert_int_equal(a->n_flux, b->n_flux);
  assert_int_equal(a->n_stress, b->n_stress);
  assert_int_equal(a->nnz, b->nnz);
  const long n = a->n, nnz = a->nnz, blocks = a->fs_ptr[a->n_stress];
  SAME(gid, n);
  SAME(x, 3 * n);
  SAME(nbr_ptr, n + 1);
  SAME(nbr, nnz);
  SAME(g, 3 * nnz);
  SAME(gsum, 3 * n);
  SAME(mirror, nnz);
  SAME(cond, n);
  SAME(erec, FPM_EREC * nnz);
  SAME(p_area, 3 * n);
  SAME(p_mrel, 9 * n);
  SAME(fs_ptr, a->n_stress + 1);
  SAME(fs_nbr, FPM_LANES * blocks);
  SAME(fs_g, 3 * FPM_LANES * blocks);
  SAME(fs_gm, 3 * FPM_LANES * blocks);
  if (a->fs_rec) SAME(fs_rec, 19 * FPM_LANES * blocks);
  SAME(mat, n);
  SAME(mass, n);
  SAME(fixed, 3 * n);
  same("volume", a->dual->volume, b->dual->volume, n, sizeof(double));
  SAME(vavg, nnz);
  SAME(vself, n);
  if (a->qs_ptr) {
    SAME(qs_ptr, n + 1);
    SAME(qs_nbr, a->qs_ptr[n]);
    SAME(qs_own, a->qs_ptr[n]);
    SAME(q, FPM_QFIT * a->qs_ptr[n]);
    SAME(qsum, FPM_QFIT * n);
    SAME(qt_ptr, n + 1);
    SAME(qt_entry, a->qt_ptr[n]);
  }
  /* The boundary: its counts, then each list of the flux points, the
   * traction facets and the prescribed dofs. */
  assert_int_equal(a->n_dpts, b->n_dpts);
  assert_int_equal(a->n_tfacets, b->n_tfacets);
  assert_int_equal(a->n_cdofs, b->n_cdofs);
  const long nd = a->n_dpts, nt = a->n_tfacets, nc = a->n_cdofs;
  const char *name[] = {"dpt_point",   "dpt_area", "dpt_mrel", "tf_point",
                        "tf_gid",      "tf_bc",    "tf_area",  "tf_rel",
                        "tf_centroid", "tf_base",  "cd_point", "cd_comp",
                        "cd_bc",       "cd_base"};
  const void *in_a[] = {a->dpt_point,   a->dpt_area, a->dpt_mrel, a->tf_point,
                        a->tf_gid,      a->tf_bc,    a->tf_area,  a->tf_rel,
                        a->tf_centroid, a->tf_base,  a->cd_point, a->cd_comp,
                        a->cd_bc,       a->cd_base};
  const void *in_b[] = {b->dpt_point,   b->dpt_area, b->dpt_mrel, b->tf_point,
                        b->tf_gid,      b->tf_bc,    b->tf_area,  b->tf_rel,
                        b->tf_centroid, b->tf_base,  b->cd_point, b->cd_comp,
                        b->cd_bc,       b->cd_base};
  const long count[] = {nd,     9 * nd, 27 * nd, nt, nt, nt, nt,
                        3 * nt, 3 * nt, 3 * nt,  nc, nc, nc, nc};
  const size_t d = sizeof(double), l = sizeof(long), i = sizeof(int);
  const size_t size[] = {l, d, d, l, l, i, d, d, d, d, l, i, i, d};
  for (int k = 0; k < 14; k++)
    same(name[k], in_a[k], in_b[k], count[k], size[k]);
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
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_shares_built),
      cmocka_unit_test(test_shares_built_defaults),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
