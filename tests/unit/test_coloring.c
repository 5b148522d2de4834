/* Unit tests of the Newton solver's colouring: validity, counts, the
 * Jacobian against dense central differences, and a pattern that misses
 * an entry (the solver: test_newton). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_coloring.h"
#include "pm_newton.h"
#include "pm_newton_impl.h"
#include "pm_testing.h"
#include "newton_chain.h"

/* ---- Colouring --------------------------------------------------------- */

/* No two columns of a colour share a row; the colour lists cover every
 * column once. */
static void assert_valid_coloring(const pm_pattern *p, const pm_coloring *c) {
  long n = p->n;
  int *seen = calloc((size_t)c->ncolors, sizeof *seen);
  assert_non_null(seen);
  for (long i = 0; i < n; i++) {
    for (int k = 0; k < c->ncolors; k++) seen[k] = 0;
    for (long q = p->ptr[i]; q < p->ptr[i + 1]; q++) {
      int col = c->color[p->idx[q]];
      assert_true(col >= 0 && col < c->ncolors);
      assert_int_equal(seen[col], 0);
      seen[col] = 1;
    }
  }
  free(seen);
  assert_int_equal(c->color_ptr[c->ncolors], n);
  for (int k = 0; k < c->ncolors; k++)
    for (long q = c->color_ptr[k]; q < c->color_ptr[k + 1]; q++)
      assert_int_equal(c->color[c->color_col[q]], k);
}

/* A banded pattern takes exactly its longest row of colours (columns
 * within 2 band share a row); an unsorted, repeated, random pattern gets a
 * valid colouring by either order. */
static void test_coloring(void **state) {
  (void)state;
  for (int band = 1; band <= 3; band++) {
    chain ch;
    chain_init(&ch, 40, band, band);
    pm_pattern p;
    assert_ok(pm_pattern_build(ch.n, ch.ptr, ch.idx, true, &p));
    assert_int_equal(pm_pattern_max_row(&p), 2 * band + 1);
    for (int order = 0; order < 2; order++) {
      pm_coloring c;
      assert_ok(pm_coloring_build(&p, (pm_coloring_order)order, &c));
      assert_valid_coloring(&p, &c);
      print_message("band %d, %s: %d colours (longest row %ld)\n", band,
                    order ? "natural" : "largest-first", c.ncolors,
                    pm_pattern_max_row(&p));
      if (order == PM_COLORING_NATURAL)
        assert_int_equal(c.ncolors, 2 * band + 1);
      else
        assert_true(c.ncolors >= 2 * band + 1 && c.ncolors <= 4 * band + 1);
      pm_coloring_free(&c);
    }
    pm_pattern_free(&p);
    chain_free(&ch);
  }

  /* Random: 200 columns, rows of up to 8 random columns, some repeated. */
  enum { N = 200 };
  long ptr[N + 1], idx[N * 8];
  unsigned seed = 12345u;
  ptr[0] = 0;
  for (long i = 0; i < N; i++) {
    seed = seed * 1103515245u + 12345u;
    long len = 1 + (long)((seed >> 16) % 8);
    ptr[i + 1] = ptr[i] + len;
    for (long q = ptr[i]; q < ptr[i + 1]; q++) {
      seed = seed * 1103515245u + 12345u;
      idx[q] = (long)((seed >> 16) % N);
    }
    idx[ptr[i + 1] - 1] = idx[ptr[i]]; /* a repeat */
  }
  pm_pattern p;
  assert_ok(pm_pattern_build(N, ptr, idx, false, &p));
  for (long k = 0; k < ptr[N]; k++) assert_int_equal(p.idx[p.src[k]], idx[k]);
  for (int order = 0; order < 2; order++) {
    pm_coloring c;
    assert_ok(pm_coloring_build(&p, (pm_coloring_order)order, &c));
    assert_valid_coloring(&p, &c);
    assert_true(c.ncolors >= pm_pattern_max_row(&p));
    print_message("random 200 x 200, %s: %d colours (longest row %ld)\n",
                  order ? "natural" : "largest-first", c.ncolors,
                  pm_pattern_max_row(&p));
    pm_coloring_free(&c);
  }
  pm_pattern_free(&p);

  /* The same pattern with 3 unknowns per entry (identical rows and
   * columns in threes, grouped by the colouring): valid, and no more than
   * three times the colours. */
  long *bptr = calloc(3 * N + 1, sizeof *bptr);
  long *bidx = calloc(9 * (size_t)ptr[N], sizeof *bidx);
  assert_true(bptr && bidx);
  for (long i = 0; i < 3 * N; i++) {
    long pi = i / 3;
    bptr[i + 1] = bptr[i];
    for (long q = ptr[pi]; q < ptr[pi + 1]; q++)
      for (long a = 0; a < 3; a++) bidx[bptr[i + 1]++] = 3 * idx[q] + a;
  }
  assert_ok(pm_pattern_build(3 * N, bptr, bidx, true, &p));
  for (int order = 0; order < 2; order++) {
    pm_coloring c, single;
    pm_pattern sp;
    assert_ok(pm_pattern_build(N, ptr, idx, true, &sp));
    assert_ok(pm_coloring_build(&sp, (pm_coloring_order)order, &single));
    assert_ok(pm_coloring_build(&p, (pm_coloring_order)order, &c));
    assert_valid_coloring(&p, &c);
    assert_int_equal(c.ncolors, 3 * single.ncolors);
    pm_coloring_free(&c);
    pm_coloring_free(&single);
    pm_pattern_free(&sp);
  }
  pm_pattern_free(&p);
  free(bptr);
  free(bidx);

  /* Bad patterns are named. */
  long bad_ptr[3] = {0, 2, 1}, bad_idx[2] = {0, 1};
  assert_int_equal(pm_pattern_build(2, bad_ptr, bad_idx, true, &p), PM_ERR_ARG);
  assert_non_null(strstr(pm_error_message(), "row 1"));
  long out_ptr[3] = {0, 1, 2}, out_idx[2] = {0, 2};
  assert_int_equal(pm_pattern_build(2, out_ptr, out_idx, true, &p), PM_ERR_ARG);
  assert_non_null(strstr(pm_error_message(), "row 1 has column 2"));
  pm_error_clear();
}

/* The coloured Jacobian equals dense central differences of the residual
 * (all n^2 entries, so a pattern missing an entry would show) to 1e-7,
 * at a state away from the solution. */
static void test_jacobian_against_differences(void **state) {
  (void)state;
  chain ch;
  chain_init(&ch, 30, 2, 2);
  pm_newton_problem prob = chain_problem(&ch);
  pm_newton_options opt = pm_newton_options_default();
  pm_newton *s = NULL;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  assert_int_equal(pm_newton_colors(s), 5);

  long n = ch.n;
  double *x = calloc((size_t)n, sizeof *x);
  double *val = calloc((size_t)ch.ptr[n], sizeof *val);
  double *dense = calloc((size_t)(n * n), sizeof *dense);
  double *rp = calloc((size_t)n, sizeof *rp), *rm = calloc((size_t)n, 8);
  assert_true(x && val && dense && rp && rm);
  for (long i = 0; i < n; i++)
    x[i] = 0.7 * exact(&ch, 1, i + 1) + 0.01 * sin(3.0 * (double)i);
  long prepares = ch.prepares;
  assert_ok(pm_newton_jacobian_values(s, x, val));
  assert_int_equal(ch.prepares, prepares + 1);
  for (long i = 0; i < n; i++)
    for (long q = ch.ptr[i]; q < ch.ptr[i + 1]; q++)
      dense[i * n + ch.idx[q]] = val[q];

  double worst = 0, largest = 0;
  for (long j = 0; j < n; j++) {
    double xj = x[j], step = 1e-6 * (fabs(xj) + 1e-2);
    x[j] = xj + step;
    assert_ok(chain_residual(&ch, x, rp));
    x[j] = xj - step;
    assert_ok(chain_residual(&ch, x, rm));
    x[j] = xj;
    for (long i = 0; i < n; i++) {
      double fd = (rp[i] - rm[i]) / (2 * step);
      worst = fmax(worst, fabs(fd - dense[i * n + j]));
      largest = fmax(largest, fabs(fd));
    }
  }
  print_message("coloured vs dense differences: %.2e relative (5 colours, "
                "n = %ld)\n",
                worst / largest, n);
  assert_true(worst / largest < 1e-7);

  double err;
  long row, col;
  assert_ok(pm_newton_check_jacobian(s, x, 1e-6, &err, &row, &col));
  assert_true(err < 1e-7);

  free(x);
  free(val);
  free(dense);
  free(rp);
  free(rm);
  pm_newton_destroy(&s);
  assert_null(s);
  chain_free(&ch);
}

/* A pattern that misses an entry of J is caught by the dense check. */
static void test_missing_pattern_entry(void **state) {
  (void)state;
  chain ch;
  chain_init(&ch, 12, 2, 1); /* reach 2 needs band 2 */
  pm_newton_problem prob = chain_problem(&ch);
  pm_newton_options opt = pm_newton_options_default();
  pm_newton *s = NULL;
  assert_ok(pm_newton_create(&prob, &opt, &s));
  double x[12] = {0}, err;
  long row, col;
  assert_ok(pm_newton_check_jacobian(s, x, 1e-6, &err, &row, &col));
  assert_true(err > 0.1);
  assert_true(labs(row - col) == 2);
  pm_newton_destroy(&s);
  chain_free(&ch);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_coloring),
      cmocka_unit_test(test_jacobian_against_differences),
      cmocka_unit_test(test_missing_pattern_entry),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
