/* test_probe: moving-least-squares probing of results.h5 reproduces linear
 * fields in 3-D and 2-D, picks frames, reads a frame written in pieces in
 * one-process order, and reports bad files and lines. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
/* cmocka needs the three headers above first. */
#include <cmocka.h>

#include "pm_testing.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pm_output.h"
#include "pm_probe.h"

#define N_SIDE 8    /* lattice points per axis */
#define SPACING 0.1 /* lattice spacing */
#define MAX_ROWS 16

/* ---- Helpers ----------------------------------------------------------- */

/* A linear field u = c + G x. */
typedef struct {
  double c[3], g[3][3];
} linear;

static const linear FIELD0 = {
    {0.01, -0.02, 0.03},
    {{0.1, -0.05, 0.02}, {0.03, 0.2, -0.1}, {-0.07, 0.04, 0.15}}};
static const linear FIELD1 = {
    {-0.05, 0.04, 0.02},
    {{0.25, 0.1, -0.2}, {-0.15, 0.3, 0.05}, {0.12, -0.08, -0.25}}};

static void eval(const linear *f, const double *x, double *u) {
  for (int i = 0; i < 3; i++) {
    u[i] = f->c[i];
    for (int j = 0; j < 3; j++) u[i] += f->g[i][j] * x[j];
  }
}

/* Jitter in [-0.3, 0.3) spacings from a fixed LCG: reproducible, and
 * irregular enough that no neighbourhood is a symmetric lattice. */
static double jitter(unsigned *seed) {
  *seed = *seed * 1103515245u + 12345u;
  return SPACING * (0.6 * ((*seed >> 8) & 0xffff) / 65536.0 - 0.3);
}

/* dir/results.h5 for a jittered lattice (dim 3: N^3 points; dim 2: N^2
 * points at z = 0) with FIELD0 in frame 0 and FIELD1 in frame 1. */
static void write_results(const char *dir, int dim) {
  long n = dim == 3 ? N_SIDE * N_SIDE * N_SIDE : N_SIDE * N_SIDE;
  double *x = calloc(3 * n, sizeof *x), *u0 = calloc(3 * n, sizeof *u0);
  double *u1 = calloc(3 * n, sizeof *u1);
  unsigned seed = 12345u;
  pm_results *r = NULL;
  assert_true(x && u0 && u1);
  for (long p = 0; p < n; p++) {
    long idx[3] = {p % N_SIDE, (p / N_SIDE) % N_SIDE, p / (N_SIDE * N_SIDE)};
    for (int k = 0; k < dim; k++)
      x[3 * p + k] = SPACING * idx[k] + jitter(&seed);
    eval(&FIELD0, &x[3 * p], &u0[3 * p]);
    eval(&FIELD1, &x[3 * p], &u1[3 * p]);
  }
  assert_ok(
      pm_results_create(dir, dim, n, x, 0, 1, NULL, "scene: test", "t", &r));
  pm_field f0 = {"displacement", 3, u0}, f1 = {"displacement", 3, u1};
  assert_ok(pm_results_write_frame(r, 0, 0.0, 1, &f0));
  assert_ok(pm_results_write_frame(r, 10, 1.0, 1, &f1));
  pm_results_close(r, true);
  free(x);
  free(u0);
  free(u1);
}

/* dir/results.h5 of write_results(dir, 3)'s lattice with FIELD0 in one
 * frame written in two pieces across ranks (pm_results_join_pieces): the
 * odd points last to first, then the even ones, each row with its
 * one-process index.  x and u0 receive the lattice and FIELD0 in
 * one-process order. */
static void write_pieces(const char *dir, long n, double *x, double *u0) {
  double *px = calloc(3 * n, sizeof *px), *pu = calloc(3 * n, sizeof *pu);
  long *index = calloc(n, sizeof *index), counts[2] = {n / 2, n - n / 2};
  unsigned seed = 12345u;
  pm_results *r = NULL;
  assert_true(px && pu && index);
  for (long p = 0; p < n; p++) {
    long idx[3] = {p % N_SIDE, (p / N_SIDE) % N_SIDE, p / (N_SIDE * N_SIDE)};
    for (int k = 0; k < 3; k++) x[3 * p + k] = SPACING * idx[k] + jitter(&seed);
    eval(&FIELD0, &x[3 * p], &u0[3 * p]);
  }
  for (long j = 0; j < n; j++)
    index[j] = j < counts[0] ? n - 1 - 2 * j : 2 * (j - counts[0]);
  for (long j = 0; j < n; j++)
    for (int k = 0; k < 3; k++) {
      pu[3 * j + k] = u0[3 * index[j] + k];
      px[3 * j + k] = x[3 * index[j] + k] + pu[3 * j + k];
    }
  const pm_points pts = {.n = n, .x = x, .nodes_per_cell = 1};
  assert_ok(pm_results_create_ex(dir, 3, &pts, "scene: test", "t", &r));
  for (int piece = 0, at = 0; piece < 2; at += counts[piece++]) {
    const pm_field f[2] = {{"position", 3, px + 3 * at},
                           {"displacement", 3, pu + 3 * at}};
    assert_ok(pm_results_write_piece(dir, 0, piece, counts[piece], index + at,
                                     0, 0.0, 2, f));
  }
  const pm_field names[2] = {{"position", 3, px}, {"displacement", 3, pu}};
  assert_ok(pm_results_join_pieces(r, 0, 0.0, 2, counts, 2, names));
  pm_results_close(r, true);
  free(px);
  free(pu);
  free(index);
}

static void write_text(const char *path, const char *text) {
  FILE *fp = fopen(path, "w");
  assert_non_null(fp);
  fputs(text, fp);
  assert_int_equal(fclose(fp), 0);
}

/* Run pm_probe into memory; rows receives up to MAX_ROWS rows of six
 * values.  Returns the error code and the row count in *nrows. */
static pm_err probe(const char *dir, const char *csv, long frame,
                    double rows[][6], int *nrows) {
  char *buf = NULL;
  size_t size = 0;
  FILE *out = open_memstream(&buf, &size);
  assert_non_null(out);
  pm_err e = pm_probe(dir, csv, frame, out);
  assert_int_equal(fclose(out), 0);
  *nrows = 0;
  if (e == PM_SUCCESS) {
    const char *header = "x,y,z,u_x,u_y,u_z\n";
    assert_memory_equal(buf, header, strlen(header));
    for (char *s = strchr(buf, '\n') + 1; *s; s = strchr(s, '\n') + 1) {
      assert_true(*nrows < MAX_ROWS);
      double *v = rows[(*nrows)++];
      assert_int_equal(sscanf(s, "%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2],
                              &v[3], &v[4], &v[5]),
                       6);
    }
  } else {
    assert_int_equal(size, 0); /* no partial table */
  }
  free(buf);
  return e;
}

/* Each row's displacement is f at its coordinates, to 1e-10. */
static void check_rows(const linear *f, double rows[][6], int nrows) {
  for (int i = 0; i < nrows; i++) {
    double u[3];
    eval(f, rows[i], u);
    for (int k = 0; k < 3; k++)
      if (fabs(rows[i][3 + k] - u[k]) > 1e-10)
        fail_msg("row %d (%g, %g, %g): u_%c = %.12g, expected %.12g", i,
                 rows[i][0], rows[i][1], rows[i][2], "xyz"[k], rows[i][3 + k],
                 u[k]);
  }
}

static void csv_path(char *buf, size_t size, const char *dir) {
  snprintf(buf, size, "%s/points.csv", dir);
}

/* ---- Tests ------------------------------------------------------------- */

static void test_linear_3d(void **state) {
  const char *dir = *state;
  char csv[256];
  double rows[MAX_ROWS][6];
  int n;
  write_results(dir, 3);
  csv_path(csv, sizeof csv, dir);
  write_text(csv, "x,y,z\n"
                  "# interior points\n"
                  "0.35,0.35,0.35\n"
                  "\n"
                  "0.123, 0.456 ,0.611\n"
                  "  # indented comment\n"
                  "0.5,0.2,0.1\r\n"
                  "0.05,0.65,0.3\n"
                  "0.3,0.3\n");
  assert_ok(probe(dir, csv, -1, rows, &n)); /* last frame */
  assert_int_equal(n, 5);
  assert_true(rows[1][0] == 0.123 && rows[1][2] == 0.611);
  assert_true(rows[4][2] == 0.0); /* "x,y" means z = 0 */
  check_rows(&FIELD1, rows, n);
  assert_ok(probe(dir, csv, 1, rows, &n));
  assert_int_equal(n, 5);
  check_rows(&FIELD1, rows, n);
  assert_ok(probe(dir, csv, 0, rows, &n));
  assert_int_equal(n, 5);
  check_rows(&FIELD0, rows, n);
}

/* All z equal: the fit is 2-D (a 3-D fit would be singular). */
static void test_linear_2d(void **state) {
  const char *dir = *state;
  char csv[256];
  double rows[MAX_ROWS][6];
  int n;
  write_results(dir, 2);
  csv_path(csv, sizeof csv, dir);
  write_text(csv, "0.35,0.35\n0.61,0.07\n0.2,0.5,0\n");
  assert_ok(probe(dir, csv, -1, rows, &n));
  assert_int_equal(n, 3);
  check_rows(&FIELD1, rows, n);
  assert_ok(probe(dir, csv, 0, rows, &n));
  check_rows(&FIELD0, rows, n);
}

static void test_missing_results(void **state) {
  const char *dir = *state;
  char csv[256], missing[256];
  double rows[MAX_ROWS][6];
  int n;
  csv_path(csv, sizeof csv, dir);
  write_text(csv, "0.1,0.1,0.1\n");
  snprintf(missing, sizeof missing, "%s/no_such_run", dir);
  assert_fails(probe(missing, csv, -1, rows, &n), PM_ERR_IO, "no_such_run");
}

static void test_bad_points(void **state) {
  const char *dir = *state;
  char csv[256], where[300];
  double rows[MAX_ROWS][6];
  int n;
  write_results(dir, 3);
  csv_path(csv, sizeof csv, dir);
  const char *bad[] = {"0.1,abc,0.3\n", "0.1,0.2,0.3,0.4\n", "0.1\n",
                       "0.1,0.2,\n",    "0.1;0.2;0.3\n",     "0.1,0.2,0.3 x\n",
                       "0.1,nan,0.3\n"};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    char text[128];
    snprintf(text, sizeof text, "x,y,z\n0.3,0.3,0.3\n%s", bad[i]);
    write_text(csv, text);
    snprintf(where, sizeof where, "%s:3: expected x,y,z numbers", csv);
    assert_fails(probe(dir, csv, -1, rows, &n), PM_ERR_ARG, where);
  }
  /* Only the first line may be a header. */
  write_text(csv, "0.3,0.3,0.3\nx,y,z\n");
  snprintf(where, sizeof where, "%s:2:", csv);
  assert_fails(probe(dir, csv, -1, rows, &n), PM_ERR_ARG, where);
  write_text(csv, "x,y,z\n# nothing\n");
  assert_fails(probe(dir, csv, -1, rows, &n), PM_ERR_ARG, "no points");
  snprintf(where, sizeof where, "%s/absent.csv", dir);
  assert_fails(probe(dir, where, -1, rows, &n), PM_ERR_IO, "absent.csv");
}

static void test_frame_range(void **state) {
  const char *dir = *state;
  char csv[256];
  double rows[MAX_ROWS][6];
  int n;
  write_results(dir, 3);
  csv_path(csv, sizeof csv, dir);
  write_text(csv, "0.3,0.3,0.3\n");
  assert_fails(probe(dir, csv, 2, rows, &n), PM_ERR_ARG, "0 to 1");
  assert_fails(probe(dir, csv, 1000000, rows, &n), PM_ERR_ARG, "0 to 1");
}

/* A frame written in pieces is read in one-process order: the points'
 * displacements, the probe between them, and --at points' rows. */
static void test_pieces(void **state) {
  const char *dir = *state;
  const long np = N_SIDE * N_SIDE * N_SIDE;
  double *x = calloc(3 * np, sizeof *x), *u0 = calloc(3 * np, sizeof *u0);
  double *rx = NULL, *ru = NULL, rows[MAX_ROWS][6];
  long rn = 0;
  int n;
  char csv[256];
  assert_true(x && u0);
  write_pieces(dir, np, x, u0);
  assert_ok(pm_results_read(dir, -1, &rn, &rx, &ru));
  assert_int_equal(rn, np);
  assert_memory_equal(rx, x, 3 * np * sizeof *x);
  assert_memory_equal(ru, u0, 3 * np * sizeof *u0);
  csv_path(csv, sizeof csv, dir);
  write_text(csv, "0.35,0.35,0.35\n0.123,0.456,0.611\n0.05,0.65,0.3\n");
  assert_ok(probe(dir, csv, 0, rows, &n));
  assert_int_equal(n, 3);
  check_rows(&FIELD0, rows, n);
  /* Point 5's own row, by --at points: its coordinates and FIELD0 there. */
  char *buf = NULL;
  size_t size = 0;
  FILE *out = open_memstream(&buf, &size);
  assert_non_null(out);
  assert_ok(pm_probe_points(dir, NULL, 0, out));
  assert_int_equal(fclose(out), 0);
  const char *s = buf;
  for (int line = 0; line < 6; line++) s = strchr(s, '\n') + 1;
  long point;
  double v[6];
  assert_int_equal(sscanf(s, "%ld,%lf,%lf,%lf,%lf,%lf,%lf", &point, &v[0],
                          &v[1], &v[2], &v[3], &v[4], &v[5]),
                   7);
  assert_int_equal(point, 5);
  for (int k = 0; k < 3; k++) {
    assert_true(fabs(v[k] - x[15 + k]) <= 1e-9 * (1 + fabs(x[15 + k])));
    assert_true(fabs(v[3 + k] - u0[15 + k]) <= 1e-9 * (1 + fabs(u0[15 + k])));
  }
  free(buf);
  free(rx);
  free(ru);
  free(x);
  free(u0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_linear_3d, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_linear_2d, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_missing_results, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_bad_points, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_frame_range, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_pieces, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
