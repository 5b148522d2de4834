/* test_inside: CGAL's inside/outside test of closed triangulated surfaces
 * (gm_inside: serial and from several threads, its rate, points on the
 * surface, open surfaces refused) and the body shapes built on it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pm_testing.h"
#include "gm_testing.h"

#include "gm_inside.h"
#include "gm_shape.h"
#include "gm_trisurf.h"
#include "pm_omp.h"
#include "pm_tensor.h"

#define PI 3.14159265358979323846

static const double origin[3] = {0, 0, 0};

/* ---- inside / outside --------------------------------------------------- */

static void test_inside_sphere(void **state) {
  (void)state;
  const double *c = origin;
  gm_trisurf s = surf_sphere(c, 1.0, 4);
  gm_inside *in = NULL;
  assert_ok(gm_inside_create(&s, &in));
  const double d = surf_nearest_plane(&s, c);
  gm_trisurf_free(&s); /* the test keeps its own copy */
  assert_true(gm_inside_contains(in, c));
  uint64_t seed = 3;
  for (int i = 0; i < 200; i++) {
    double u[3] = {pm_test_uniform(&seed) - 0.5, pm_test_uniform(&seed) - 0.5,
                   pm_test_uniform(&seed) - 0.5};
    const double n = pm_v_norm(u);
    double a[3], b[3];
    for (int k = 0; k < 3; k++) {
      a[k] = 0.9 * u[k] / n;
      b[k] = 1.1 * u[k] / n;
    }
    assert_true(gm_inside_contains(in, a));
    assert_false(gm_inside_contains(in, b));
  }
  assert_false(gm_inside_contains(in, (const double[3]){NAN, 0, 0}));
  assert_false(gm_inside_contains(NULL, c));

  /* 100000 points of [-1.2, 1.2]^3, serially and from 4 threads: the same
   * answers, and |x| < 1 but in the band [d, 1] between the polyhedron's
   * inner ball and the sphere. */
  const long n = 100000;
  double *x = malloc(sizeof *x * 3 * (size_t)n);
  char *serial = malloc((size_t)n), *threaded = malloc((size_t)n);
  assert_true(x && serial && threaded);
  for (long i = 0; i < 3 * n; i++) x[i] = 2.4 * pm_test_uniform(&seed) - 1.2;
  for (long i = 0; i < n; i++) serial[i] = gm_inside_contains(in, x + 3 * i);
  PM_OMP(parallel for num_threads(4) schedule(dynamic, 256) default(none)
             shared(in, x, threaded, n))
  for (long i = 0; i < n; i++) threaded[i] = gm_inside_contains(in, x + 3 * i);
  long band = 0, inside = 0;
  for (long i = 0; i < n; i++) {
    assert_int_equal(serial[i], threaded[i]);
    const double r = pm_v_norm(x + 3 * i);
    inside += serial[i];
    if (r < d)
      assert_true(serial[i]);
    else if (r > 1.0)
      assert_false(serial[i]);
    else
      band++;
  }
  print_message("  r = 4 sphere: %ld of %ld points inside, %ld in the band "
                "[%.6f, 1]\n",
                inside, n, band, d);
  free(x);
  free(serial);
  free(threaded);
  gm_inside_destroy(in);
  gm_inside_destroy(NULL);
}

/* The build time and query rate at r = 6 (printed: 81920 triangles), or
 * at r = 4 without optimization (the sanitizer build), where CGAL's
 * templates and the sanitizers' unwinding on each allocation make the
 * build 100 times slower. */
#ifdef __OPTIMIZE__
#define RATE_REFINEMENT 6
#else
#define RATE_REFINEMENT 4
#endif

static void test_inside_rate(void **state) {
  (void)state;
  gm_trisurf s = surf_sphere(origin, 1.0, RATE_REFINEMENT);
  gm_inside *in = NULL;
  double t0 = surf_now();
  assert_ok(gm_inside_create(&s, &in));
  const double build = surf_now() - t0;
  const long n = 100000;
  uint64_t seed = 11;
  long hits = 0;
  t0 = surf_now();
  for (long i = 0; i < n; i++) {
    const double x[3] = {2.4 * pm_test_uniform(&seed) - 1.2,
                         2.4 * pm_test_uniform(&seed) - 1.2,
                         2.4 * pm_test_uniform(&seed) - 1.2};
    hits += gm_inside_contains(in, x);
  }
  const double query = surf_now() - t0;
  /* The hit fraction estimates the ball's share of the cube, 0.303 (the
   * polyhedron's deficit, 1e-4, is far below 5 sigma = 7e-3). */
  const double p = 4.0 / 3.0 * PI / (2.4 * 2.4 * 2.4);
  const double f = (double)hits / (double)n;
  assert_true(fabs(f - p) < 5.0 * sqrt(p * (1 - p) / (double)n));
  print_message("  inside test, r = %d sphere (%ld triangles): built in %.0f "
                "ms, %.2e queries/s on one thread\n",
                RATE_REFINEMENT, s.n_tris, 1e3 * build, (double)n / query);
  gm_inside_destroy(in);
  gm_trisurf_free(&s);
}

static void test_inside_cube(void **state) {
  char path[512];
  surf_write_cube_stl(*state, path);
  gm_trisurf s;
  assert_ok(gm_trisurf_load(path, &s));
  gm_inside *in = NULL;
  assert_ok(gm_inside_create(&s, &in));
  gm_trisurf_free(&s);
  double lo[3], hi[3];
  gm_inside_bounds(in, lo, hi);
  for (int k = 0; k < 3; k++) assert_true(lo[k] == 0 && hi[k] == 1);
  const double in_pts[][3] = {{0.5, 0.5, 0.5},
                              {0.999, 0.999, 0.999},
                              {0.25, 0.5, 0.5},
                              {1e-9, 0.3, 0.7}};
  const double out_pts[][3] = {
      {1.5, 0.5, 0.5}, {-1e-9, 0.5, 0.5}, {0.5, 0.5, 1 + 1e-9}, {2, 2, 2}};
  /* On the surface: a face, an edge, a corner. */
  const double on_pts[][3] = {{1, 0.5, 0.5}, {0.5, 0, 0}, {1, 1, 1}};
  for (int i = 0; i < 4; i++) {
    assert_true(gm_inside_contains(in, in_pts[i]));
    assert_false(gm_inside_contains(in, out_pts[i]));
  }
  for (int i = 0; i < 3; i++) assert_true(gm_inside_contains(in, on_pts[i]));
  gm_inside_destroy(in);
}

/* Two tetrahedra touching at the origin: closed and consistently
 * oriented, but no manifold at that point, which CGAL's mesh needs split
 * in two. */
static void test_inside_touching(void **state) {
  (void)state;
  double x[7][3] = {{0, 0, 0},  {1, 0, 0},  {0, 1, 0}, {0, 0, 1},
                    {0, -1, 0}, {-1, 0, 0}, {0, 0, -1}};
  /* Each tetrahedron (0, a, b, c) of positive volume: faces turning out. */
  long tri[24];
  for (int k = 0; k < 2; k++) {
    const long a = 1 + 3 * k, b = a + 1, c = a + 2;
    const long f[12] = {0, b, a, 0, a, c, 0, c, b, a, b, c};
    memcpy(tri + 12 * k, f, sizeof f);
  }
  const gm_trisurf s = {.n_points = 7, .x = x[0], .n_tris = 8, .tri = tri};
  surf_expect_closed(&s);
  assert_close(gm_trisurf_volume(&s), 1.0 / 3.0, 1e-15, 0);
  gm_inside *in = NULL;
  assert_ok(gm_inside_create(&s, &in));
  assert_true(gm_inside_contains(in, (const double[3]){0.1, 0.1, 0.1}));
  assert_true(gm_inside_contains(in, (const double[3]){-0.1, -0.2, -0.1}));
  assert_true(gm_inside_contains(in, (const double[3]){0, 0, 0}));
  assert_false(gm_inside_contains(in, (const double[3]){0.1, -0.1, 0.1}));
  assert_false(gm_inside_contains(in, (const double[3]){0.5, 0.5, 0.5}));
  gm_inside_destroy(in);
}

static void test_inside_refuses_open(void **state) {
  (void)state;
  gm_trisurf s = surf_unit_square(3);
  gm_inside *in = (void *)&s; /* must come back NULL */
  assert_fails(gm_inside_create(&s, &in), PM_ERR_ARG, "hole");
  assert_null(in);
  gm_trisurf_free(&s);
  assert_fails(gm_inside_create(&s, &in), PM_ERR_ARG, "no triangle");
}

/* ---- shapes ------------------------------------------------------------- */

static void test_shape_from_surface(void **state) {
  (void)state;
  const double c[3] = {1, 2, 3}, R = 2.0;
  gm_trisurf s = surf_sphere(c, R, 3);
  gm_shape *inner = NULL, *outer = NULL;
  assert_ok(gm_shape_from_surface(&s, false, &inner));
  assert_ok(gm_shape_from_surface(&s, true, &outer));
  assert_string_equal(gm_shape_kind(inner), "inside");
  assert_string_equal(gm_shape_kind(outer), "outside");
  assert_true(gm_shape_thread_safe(inner) && gm_shape_thread_safe(outer));

  double lo[3], hi[3], slo[3], shi[3];
  assert_true(gm_shape_bounds(inner, lo, hi));
  gm_trisurf_bounds(&s, slo, shi);
  for (int k = 0; k < 3; k++) assert_true(lo[k] == slo[k] && hi[k] == shi[k]);
  lo[0] = 7;
  assert_false(gm_shape_bounds(outer, lo, hi));
  assert_true(lo[0] == 7);

  const double far[3] = {c[0] + 1.1 * R, c[1], c[2]};
  const double *vertex = s.x + 3 * 17; /* on the surface */
  assert_true(gm_shape_contains(inner, c));
  assert_false(gm_shape_contains(inner, far));
  assert_true(gm_shape_contains(inner, vertex));
  assert_false(gm_shape_contains(outer, c));
  assert_true(gm_shape_contains(outer, far));
  assert_false(gm_shape_contains(outer, vertex));
  assert_ok(gm_shape_check_inside(outer, 0, (const double[3]){0, 0, 0},
                                  (const double[3]){1, 1, 1}));
  const gm_shape *both[2] = {inner, outer};
  assert_int_equal(gm_shape_last_containing(both, 2, c), 0);
  assert_int_equal(gm_shape_last_containing(both, 2, far), 1);
  gm_shape_destroy(inner);
  gm_shape_destroy(outer);
  gm_trisurf_free(&s);

  s = surf_unit_square(2);
  gm_shape *bad = (void *)&s; /* must come back NULL */
  assert_fails(gm_shape_from_surface(&s, false, &bad), PM_ERR_ARG, "hole");
  assert_null(bad);
  gm_trisurf_free(&s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_inside_sphere),
      cmocka_unit_test(test_inside_rate),
      cmocka_unit_test_setup_teardown(test_inside_cube, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test(test_inside_touching),
      cmocka_unit_test(test_inside_refuses_open),
      cmocka_unit_test(test_shape_from_surface),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
