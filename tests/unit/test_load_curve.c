/* test_load_curve: load curves (pm_curve): a table read from CSV is linear
 * between its rows and held outside them, a header and comments are
 * skipped, an expression of t is evaluated as given, and bad tables fail
 * naming the file and line. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_curve.h"
#include "pm_testing.h"

static void test_table(void **state) {
  char path[512];
  pm_test_write_file(*state, "c.csv",
                     "# a ramp and a hold\nt, factor\n0, 0\n2, 1\n\n4, 1\n"
                     "6, -0.5\n",
                     path);
  pm_curve *c = NULL;
  assert_int_equal(pm_curve_create("c.csv", *state, &c), PM_SUCCESS);
  assert_int_equal(c->n, 4);
  assert_near(pm_curve_at(c, -1), 0, 0);
  assert_near(pm_curve_at(c, 0.5), 0.25, 1e-15);
  assert_near(pm_curve_at(c, 2), 1, 0);
  assert_near(pm_curve_at(c, 3), 1, 0);
  assert_near(pm_curve_at(c, 5.5), -0.125, 1e-15);
  assert_near(pm_curve_at(c, 100), -0.5, 0);
  assert_near(pm_curve_end(c), 6, 0);
  pm_curve_destroy(c);
  /* an absolute path ignores the folder */
  assert_int_equal(pm_curve_create(path, "/nowhere", &c), PM_SUCCESS);
  assert_near(pm_curve_at(c, 1), 0.5, 1e-15);
  pm_curve_destroy(c);
}

static void test_expression(void **state) {
  (void)state;
  pm_curve *c = NULL;
  assert_int_equal(pm_curve_create("1 - exp(-t)", NULL, &c), PM_SUCCESS);
  assert_near(pm_curve_at(c, 2), 1 - exp(-2), 1e-15);
  assert_near(pm_curve_end(c), 0, 0);
  pm_curve_destroy(c);
  assert_near(pm_curve_at(NULL, 3), 1, 0);
  assert_int_not_equal(pm_curve_create("1 +", NULL, &c), PM_SUCCESS);
  assert_null(c);
  pm_error_clear();
}

/* Each bad table fails with FILE:LINE and what was expected. */
static void test_bad_tables(void **state) {
  static const struct {
    const char *text, *message;
  } bad[] = {
      {"0, 0\n1, x\n", "b.csv:2: expected two numbers t, factor, got '1', "
                       "'x'"},
      {"0, 0\n1, 1\n1, 2\n", "b.csv:3: expected a time after 1"},
      {"0, 0\n1\n", "b.csv:2: expected two numbers t, factor, got 1 field"},
      {"0, 0, 0\n", "b.csv:1: expected two numbers t, factor, got 3 fields"},
      {"0, nan\n", "b.csv:1: expected finite numbers"},
      {"# nothing\n", "b.csv: expected rows t, factor, got none"},
      {"t, f\nu, g\n", "b.csv:2: expected two numbers t, factor, got 'u'"},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    char path[512];
    pm_test_write_file(*state, "b.csv", bad[k].text, path);
    pm_curve *c = NULL;
    assert_int_equal(pm_curve_create("b.csv", *state, &c), PM_ERR_SCENE);
    assert_null(c);
    if (!strstr(pm_error_message(), bad[k].message))
      fail_msg("table %zu: got '%s'", k, pm_error_message());
    pm_error_clear();
  }
  pm_curve *c = NULL;
  assert_int_equal(pm_curve_create("missing.csv", *state, &c), PM_ERR_IO);
  pm_error_clear();
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_table, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test(test_expression),
      cmocka_unit_test_setup_teardown(test_bad_tables, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
