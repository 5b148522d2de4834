/* test_expr: compiled expressions in x, y, z, t (values, constants, the
 * variable whitelist and syntax errors). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <string.h>

#include "pm_expr.h"
#include "pm_testing.h"

static double eval_text(const char *text, double x, double y, double z,
                        double t) {
  pm_expr *e = NULL;
  assert_int_equal(pm_expr_create(text, &e), PM_SUCCESS);
  double v = pm_expr_eval(e, x, y, z, t);
  pm_expr_destroy(e);
  return v;
}

static void test_values(void **state) {
  (void)state;
  assert_near(eval_text("0", 1, 2, 3, 4), 0.0, 0.0);
  assert_near(eval_text("-0.04", 1, 2, 3, 4), -0.04, 1e-15);
  assert_near(eval_text("1.5e-3", 0, 0, 0, 0), 1.5e-3, 1e-18);
  assert_near(eval_text("-0.4*z", 0, 0, 0.05, 0), -0.02, 1e-15);
  assert_near(eval_text("x + 2*y - z^2 + t", 1, 2, 3, 4), 0.0, 1e-12);
  assert_near(eval_text("0.01*sin(2*pi*t)", 0, 0, 0, 0.25), 0.01, 1e-15);
  assert_near(eval_text("e", 0, 0, 0, 0), exp(1.0), 1e-15);
  assert_near(eval_text("100*t", 0, 0, 0, 0.5), 50.0, 1e-12);
}

static void test_text_and_uses(void **state) {
  (void)state;
  pm_expr *e = NULL;
  assert_int_equal(pm_expr_create("x*t + 3", &e), PM_SUCCESS);
  assert_string_equal(pm_expr_text(e), "x*t + 3");
  assert_true(pm_expr_uses(e, 'x'));
  assert_false(pm_expr_uses(e, 'y'));
  assert_false(pm_expr_uses(e, 'z'));
  assert_true(pm_expr_uses(e, 't'));
  assert_false(pm_expr_uses(e, 'q'));
  assert_false(pm_expr_uses(e, '\0'));
  pm_expr_destroy(e);

  assert_int_equal(pm_expr_create("2*pi", &e), PM_SUCCESS);
  for (const char *v = "xyzt"; *v; v++) assert_false(pm_expr_uses(e, *v));
  pm_expr_destroy(e);
  pm_expr_destroy(NULL);
}

static void expect_error(const char *text, const char *fragment) {
  pm_expr *e = (pm_expr *)&e; /* must be reset to NULL on failure */
  pm_error_clear();
  assert_int_equal(pm_expr_create(text, &e), PM_ERR_EXPR);
  assert_null(e);
  const char *msg = pm_error_message();
  if (!strstr(msg, fragment))
    fail_msg("message \"%s\" lacks \"%s\"", msg, fragment);
}

static void test_errors(void **state) {
  (void)state;
  expect_error("-0.4*q", "invalid expression \"-0.4*q\": unknown variable q "
                         "(allowed: x, y, z, t)");
  expect_error("xx + 1", "unknown variable xx");
  expect_error("x +", "invalid expression \"x +\": syntax error");
  expect_error("", "empty");
  expect_error("x > 1", "syntax error at character 3");
  expect_error("2*(x + 1", "expected ')'");
  expect_error("sin x", "expected '(' after a function name");
  expect_error("3 4", "unexpected text");
  expect_error("foo(x)", "syntax error");
}

/* Numbers that are not finite, and constants whose value is not, are
 * refused when compiled; a variable expression is not (its value depends
 * on where and when), and its failure names where it comes from. */
static void test_not_finite(void **state) {
  (void)state;
  expect_error("nan", "invalid expression \"nan\": not a number (expected a "
                      "finite value)");
  expect_error(".nan", "invalid expression \".nan\": not a number");
  expect_error("-.inf", "invalid expression \"-.inf\": infinite");
  expect_error("inf", "invalid expression \"inf\": infinite");
  expect_error("1e999", "invalid expression \"1e999\": too large for a "
                        "double");
  expect_error("1/0", "invalid expression \"1/0\": its value is inf "
                      "(expected a finite value)");
  expect_error("sqrt(-1)", "invalid expression \"sqrt(-1)\": its value is "
                           "nan");
  expect_error("-log(0)*2", "its value is inf");
  expect_error("log(0)", "its value is -inf");
  expect_error("2*t + 1e999",
               "syntax error at character 7: number too large for a double");

  pm_expr *e = NULL;
  assert_int_equal(pm_expr_create("sqrt(0.5 - t)", &e), PM_SUCCESS);
  assert_null(pm_expr_origin(e));
  assert_true(isnan(pm_expr_eval(e, 0, 0, 0, 1)));
  assert_int_equal(pm_expr_set_origin(e, "a.yaml:3:7: boundary.1.velocity.x"),
                   PM_SUCCESS);
  assert_string_equal(pm_expr_origin(e), "a.yaml:3:7: boundary.1.velocity.x");
  const double x[3] = {0.5, 0.25, 0};
  pm_error_clear();
  assert_int_equal(
      pm_expr_fail_value(e, pm_expr_eval(e, 0, 0, 0, 1), 12, 1, "node", 40, x),
      PM_ERR_UNSTABLE);
  assert_string_equal(pm_error_message(),
                      "step 12, t = 1 s: node 40 at (0.5, 0.25, 0): "
                      "a.yaml:3:7: boundary.1.velocity.x: \"sqrt(0.5 - t)\" "
                      "= nan, not a finite value");
  pm_expr_destroy(e);

  assert_null(pm_number_not_finite("1e308"));
  assert_null(pm_number_not_finite("x"));
  assert_null(pm_number_not_finite(""));
  assert_string_equal(pm_number_not_finite("+.Inf"), "infinite");
  assert_string_equal(pm_number_not_finite("NaN"), "not a number");
  assert_string_equal(pm_number_not_finite("-1e400"), "too large for a double");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_values),
      cmocka_unit_test(test_text_and_uses),
      cmocka_unit_test(test_errors),
      cmocka_unit_test(test_not_finite),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
