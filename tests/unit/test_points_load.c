/* test_points_load: point clouds read from CSV and .xyz files (a
 * membrane's points without connectivity, an image's voxel centres), good
 * and bad, each refusal naming the file and line. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_testing.h"

#include "gm_curve.h"

/* ---- point files -------------------------------------------------------- */

/* Loads dir/name holding text. */
static pm_err load(const char *dir, const char *name, const char *text, int dim,
                   long *n, double **x, double **share) {
  char path[512];
  pm_test_write_file(dir, name, text, path);
  return gm_points_load(path, dim, n, x, share);
}

static void test_points_good(void **state) {
  const char *dir = *state;
  long n = 0;
  double *x = NULL, *a = NULL;
  /* CSV, 3-D with areas: a comment, a header, spaces, a comment at a
   * line's end, a blank line, a Windows line end. */
  assert_ok(load(dir, "pts.csv",
                 "# from a scanner\nx, y, z, area\n0,0,0,0.1\n"
                 "1, 2 ,3e0, 0.2 # the second\n\n  \n-4,5.5,6,3e-1\r\n",
                 3, &n, &x, &a));
  assert_int_equal(n, 3);
  assert_non_null(a);
  const double want[9] = {0, 0, 0, 1, 2, 3, -4, 5.5, 6};
  for (int k = 0; k < 9; k++) assert_true(x[k] == want[k]);
  assert_true(a[0] == 0.1 && a[1] == 0.2 && a[2] == 0.3);
  free(x);
  free(a);
  /* .xyz, 3-D, no share column, tabs, no header, no final line end. */
  assert_ok(load(dir, "pts.xyz", "1\t2 3\n 4 5\t6 \n7 8 9", 3, &n, &x, &a));
  assert_int_equal(n, 3);
  assert_null(a);
  for (int k = 0; k < 9; k++) assert_true(x[k] == k + 1);
  free(x);
  /* 2-D with lengths, in a file of another extension: z is 0. */
  assert_ok(
      load(dir, "ring.txt", "x y length\n1 2 0.5\n3 4 0.25\n", 2, &n, &x, &a));
  assert_int_equal(n, 2);
  assert_non_null(a);
  assert_true(x[0] == 1 && x[1] == 2 && x[2] == 0 && x[3] == 3 && x[4] == 4 &&
              x[5] == 0);
  assert_true(a[0] == 0.5 && a[1] == 0.25);
  free(x);
  free(a);
  /* 2-D CSV without lengths, a byte order mark before its header. */
  assert_ok(
      load(dir, "ring.CSV", "\xEF\xBB\xBFx,y\n1,2\n3,4\n", 2, &n, &x, &a));
  assert_int_equal(n, 2);
  assert_null(a);
  assert_true(x[3] == 3 && x[4] == 4 && x[5] == 0);
  free(x);
}

/* Expect the file dir/name of text to fail with code and a message that
 * holds text1 and text2, leaving no output. */
static void expect_bad(const char *dir, const char *name, const char *text,
                       int dim, pm_err code, const char *text1,
                       const char *text2) {
  long n = -1;
  double *x = (double *)&n, *a = (double *)&n;
  pm_err e = load(dir, name, text, dim, &n, &x, &a);
  if (e != code || !strstr(pm_error_message(), text1) ||
      (text2 && !strstr(pm_error_message(), text2)))
    fail_msg("%s: expected %s with '%s' and '%s', got %s: %s", name,
             pm_err_name(code), text1, text2 ? text2 : "", pm_err_name(e),
             pm_error_message());
  assert_int_equal(n, 0);
  assert_null(x);
  assert_null(a);
}

static void test_points_bad(void **state) {
  const char *dir = *state;
  const char *head = "x,y,z,area\n0,0,0,1\n1,0,0,1\n2,0,0,1\n3,0,0,1\n"
                     "4,0,0,1\n";
  char text[512];
  snprintf(text, sizeof text, "%s0.5, 0.25, abc, 1\n", head);
  expect_bad(dir, "pts.csv", text, 3, PM_ERR_SCENE,
             "pts.csv:7:12: expected a number (x, y, z[, area]), got 'abc'",
             NULL);
  snprintf(text, sizeof text, "%s5,0,0,1\n6,0,0\n", head);
  expect_bad(dir, "pts.csv", text, 3, PM_ERR_SCENE,
             "pts.csv:8:1: expected 4 columns like line 2, got 3", NULL);
  /* Comments and blank lines count as lines. */
  expect_bad(dir, "cols.xyz", "# c\n\n1 2 3\n4 5 6 7\n", 3, PM_ERR_SCENE,
             "cols.xyz:4:1: expected 3 columns like line 3, got 4", NULL);
  expect_bad(dir, "five.xyz", "1 2 3 4 5\n", 3, PM_ERR_SCENE,
             "five.xyz:1:1: expected 3 or 4 columns (x, y, z[, area]), got 5",
             NULL);
  expect_bad(dir, "one.xyz", "1\n", 2, PM_ERR_SCENE,
             "one.xyz:1:1: expected 2 or 3 columns (x, y[, length]), got 1",
             NULL);
  expect_bad(dir, "nan.xyz", "0 0 0\n1 2 nan\n", 3, PM_ERR_SCENE,
             "nan.xyz:2:5: expected a finite number",
             "got 'nan' (not a number)");
  expect_bad(dir, "big.csv", "1e999,2\n", 2, PM_ERR_SCENE,
             "big.csv:1:1: expected a finite number", "too large for a double");
  expect_bad(dir, "inf.xyz", "1 -inf\n", 2, PM_ERR_SCENE,
             "inf.xyz:1:3:", "(infinite)");
  expect_bad(dir, "gap.csv", "1,,2\n", 2, PM_ERR_SCENE,
             "gap.csv:1:3: expected a number (x, y[, length]), got an empty "
             "field",
             NULL);
  expect_bad(dir, "comma.xyz", "1,5 2\n", 2, PM_ERR_SCENE,
             "comma.xyz:1:1: expected a number", "got '1,5'");
  expect_bad(dir, "neg.xyz", "0 0 1\n1 1 -2\n", 2, PM_ERR_SCENE,
             "neg.xyz:2:5: expected a positive length, got '-2'", NULL);
  /* A first line mixing numbers and words is no header. */
  expect_bad(dir, "typo.csv", "1,2,x3\n4,5,6\n", 3, PM_ERR_SCENE,
             "typo.csv:1:5: expected a number", "got 'x3'");
  /* A header after the first line is a bad line. */
  expect_bad(dir, "twice.csv", "x,y\n1,2\nx,y\n", 2, PM_ERR_SCENE,
             "twice.csv:3:1: expected a number", "got 'x'");
  expect_bad(dir, "empty.csv", "", 3, PM_ERR_SCENE, "empty.csv: no points",
             NULL);
  expect_bad(dir, "header.csv", "# nothing\nx,y,z\n\n", 3, PM_ERR_SCENE,
             "header.csv: no points", NULL);
  /* The error comes after points were read (and are let go). */
  char big[16 * 601] = "";
  for (int k = 0; k < 600; k++) strcpy(big + 14 * k, "1.25 2.5 3.75\n");
  strcpy(big + 14 * 600, "1 2 3 4\n");
  expect_bad(dir, "late.xyz", big, 3, PM_ERR_SCENE, "late.xyz:601:1:", NULL);
}

static void test_points_files(void **state) {
  const char *dir = *state;
  long n = -1;
  double *x = NULL, *a = NULL;
  char path[512];
  snprintf(path, sizeof path, "%s/missing.csv", dir);
  assert_fails(gm_points_load(path, 3, &n, &x, &a), PM_ERR_IO,
               "missing.csv': No such file or directory");
  assert_int_equal(n, 0);
  assert_null(x);
  assert_fails(gm_points_load(dir, 3, &n, &x, &a), PM_ERR_IO, "Is a directory");
  assert_fails(gm_points_load(path, 4, &n, &x, &a), PM_ERR_ARG,
               "dimension must be 2 or 3 (got 4)");
  /* A NUL byte: a binary file. */
  snprintf(path, sizeof path, "%s/bin.xyz", dir);
  FILE *f = fopen(path, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite("1 2\n3\0 4\n", 1, 9, f), 9);
  assert_int_equal(fclose(f), 0);
  assert_fails(gm_points_load(path, 2, &n, &x, &a), PM_ERR_SCENE,
               "bin.xyz:2:2: expected text, got a NUL byte");
  assert_null(x);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_points_good, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_points_bad, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_points_files, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
