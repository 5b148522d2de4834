/* Unit test of the Newton layer's augmented preconditioner
 * (pm_newton_problem.aux_n): the LU of a larger matrix whose Schur
 * complement is the Jacobian; and the direct solver's LU dense. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_newton.h"
#include "pm_testing.h"
#include "newton_chain.h"

/* ---- The augmented preconditioner (aux_n) ------------------------------
 * The chain of reach 2 with one value a distance-2 spring more, z_e =
 * t_e (u_b - u_a): the matrix [J1 G; C I], J1 the nearest springs'
 * tangent, G z their forces, C u = -t (u_b - u_a), whose Schur
 * complement is the chain's tangent. */
typedef struct {
  chain *ch;
  long *ptr, *idx;
} aug_chain;

/* The index in ch->tangent of the spring from node e to node e + dist
 * (nodes 0 and n + 1 are the fixed ends). */
static long spring_at(const chain *ch, long e, int dist) {
  long k = 0;
  for (long a = 0; a <= ch->n + 1; a++)
    for (int d = 1; d <= ch->reach && a + d <= ch->n + 1; d++, k++)
      if (a == e && d == dist) return k;
  fail_msg("no spring from node %ld at distance %d", e, dist);
  return -1;
}

/* The matrix row by row: with val NULL the pattern's columns into idx
 * (counts into ptr), else the values. */
static void aug_rows(const chain *ch, long *ptr, long *idx, double *val) {
  const long n = ch->n;
  long w = 0;
  for (long i = 0; i < n + n; i++) {
    if (i <
        n) { /* node g = i + 1: nearest springs, and z of (g-2, g), (g, g+2) */
      const long g = i + 1;
      const double tl = ch->tangent[spring_at(ch, g - 1, 1)],
                   tr = ch->tangent[spring_at(ch, g, 1)];
      const long col[5] = {i - 1, i, i + 1, n + g - 2, n + g};
      const double v[5] = {-tl, tl + tr, -tr, 1, -1};
      for (int q = 0; q < 5; q++) {
        if (col[q] < 0 || col[q] >= 2 * n || (q == 2 && i + 1 >= n) ||
            (q == 3 && g < 2))
          continue;
        if (val) val[w] = v[q];
        if (idx) idx[w] = col[q];
        w++;
      }
    } else { /* spring e = i - n between nodes e and e + 2 */
      const long e = i - n;
      const double t = ch->tangent[spring_at(ch, e, 2)];
      const long col[3] = {i, e - 1, e + 1};
      const double v[3] = {1, t, -t};
      for (int q = 0; q < 3; q++) {
        if (col[q] < 0 || (q == 2 && e + 2 > n)) continue;
        if (val) val[w] = v[q];
        if (idx) idx[w] = col[q];
        w++;
      }
    }
    if (ptr) ptr[i + 1] = w;
  }
}

/* The factor of M's last rows (D = aux_scale I: the Schur complement the
 * same). */
static double aux_scale = 1;

static pm_err aug_values(void *ctx, const double *x, double *val) {
  (void)x;
  const chain *ch = ctx;
  aug_rows(ch, NULL, NULL, val);
  if (aux_scale != 1) {
    long *ptr = calloc(2 * (size_t)ch->n + 1, sizeof *ptr);
    if (!ptr) return PM_ERR_MEMORY;
    aug_rows(ch, ptr, NULL, NULL);
    for (long k = ptr[ch->n]; k < ptr[2 * ch->n]; k++) val[k] *= aux_scale;
    free(ptr);
  }
  return PM_SUCCESS;
}

/* The chain (reach 2) with op matrix-free and the augmented LU: the
 * solution to 1e-8 and at most two GMRES iterations to 1e-10 a Newton
 * iteration (the LU is the exact tangent's: measured 1: 5 in 5 Newton
 * iterations, where the nearest springs' LU alone, the cheap preconditioner of
 * test_newton's test_linear_solvers, takes 69 in all); the same Newton
 * iterations as the assembled LU. */
static void test_augmented_preconditioner(void **state) {
  (void)state;
  chain ch;
  chain_init(&ch, 120, 2, 2);
  pm_newton_problem prob = chain_problem(&ch);
  long *ptr = calloc(2 * (size_t)ch.n + 1, sizeof *ptr);
  aug_rows(&ch, ptr, NULL, NULL);
  long *idx = calloc((size_t)ptr[2 * ch.n], sizeof *idx);
  assert_true(ptr && idx);
  aug_rows(&ch, NULL, idx, NULL);
  prob.aux_n = ch.n;
  prob.aux_ptr = ptr;
  prob.aux_idx = idx;
  prob.aux_values = aug_values;
  pm_newton_options opt = pm_newton_options_default();
  opt.rtol = 1e-10;
  opt.op = PM_NEWTON_MATRIX_FREE;
  pm_newton_report rep, ref;
  assert_ok(chain_solve(&ch, &prob, &opt, &rep));
  print_message("augmented LU: %d Newton, %d linear iterations, error %.1e\n",
                rep.iterations, rep.linear_iterations,
                chain_error(&ch, ch.x, 1));
  assert_true(chain_error(&ch, ch.x, 1.0) < 1e-8);
  assert_true(rep.linear_iterations <= 2 * rep.iterations);
  /* That was dense (the Schur complement by LAPACK, n = 120 within
   * PM_NEWTON_AUG_DENSE_MAX); then MUMPS's LU of M (-pm_aug_dense_max 0),
   * and dense again with D = 3 I: the same preconditioner each time, so
   * the same Newton iterations and at most two GMRES iterations each. */
  const char *modes[2] = {"-pm_aug_dense_max 0", NULL};
  for (int m = 0; m < 2; m++) {
    pm_newton_report r2;
    aux_scale = m == 1 ? 3 : 1;
    opt.petsc_options = modes[m];
    assert_ok(chain_solve(&ch, &prob, &opt, &r2));
    print_message("augmented LU (%s, D = %g I): %d Newton, %d linear, error "
                  "%.1e\n",
                  m == 0 ? "sparse" : "dense", aux_scale, r2.iterations,
                  r2.linear_iterations, chain_error(&ch, ch.x, 1));
    assert_true(chain_error(&ch, ch.x, 1.0) < 1e-8);
    assert_int_equal(r2.iterations, rep.iterations);
    assert_true(r2.linear_iterations <= 2 * r2.iterations);
  }
  aux_scale = 1;
  opt.petsc_options = NULL;
  prob.aux_n = 0;
  opt.op = PM_NEWTON_ASSEMBLED;
  assert_ok(chain_solve(&ch, &prob, &opt, &ref));
  assert_int_equal(rep.iterations, ref.iterations);
  /* refused where it does not apply: an assembled operator */
  prob.aux_n = ch.n;
  pm_newton *s = NULL;
  assert_int_equal(pm_newton_create(&prob, &opt, &s), PM_ERR_UNSUPPORTED);
  free(ptr);
  free(idx);
  chain_free(&ch);
}

/* The direct solver's own LU dense (pm_newton_dense.c: the chain of 30
 * unknowns and reach 2, its pattern 5 n entries, a sixth full) against
 * MUMPS's (-pm_aug_dense_max 0), with the operator assembled (the LU
 * alone) and matrix-free (the LU preconditions GMRES): the same Newton
 * and linear iterations and the solution to 1e-8. */
static void test_dense_direct(void **state) {
  (void)state;
  chain ch;
  chain_init(&ch, 30, 2, 2);
  pm_newton_problem prob = chain_problem(&ch);
  for (int o = 0; o < 2; o++) {
    pm_newton_report rep[2];
    for (int m = 0; m < 2; m++) {
      pm_newton_options opt = pm_newton_options_default();
      opt.rtol = 1e-10;
      opt.linear = PM_NEWTON_DIRECT;
      opt.op = o ? PM_NEWTON_MATRIX_FREE : PM_NEWTON_ASSEMBLED;
      opt.petsc_options = m ? "-pm_aug_dense_max 0" : NULL;
      assert_ok(chain_solve(&ch, &prob, &opt, &rep[m]));
      print_message("direct, %s, %s: %d Newton, %d linear, error %.1e\n",
                    o ? "matrix-free" : "assembled", m ? "MUMPS" : "dense",
                    rep[m].iterations, rep[m].linear_iterations,
                    chain_error(&ch, ch.x, 1));
      assert_true(chain_error(&ch, ch.x, 1.0) < 1e-8);
    }
    assert_int_equal(rep[0].iterations, rep[1].iterations);
    assert_int_equal(rep[0].linear_iterations, rep[1].linear_iterations);
  }
  chain_free(&ch);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_augmented_preconditioner),
      cmocka_unit_test(test_dense_direct),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
