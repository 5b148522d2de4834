/* test_shape: body shapes of every kind against analytic answers: points
 * inside, outside and on the boundary, bounds (a tilted cylinder's, a
 * meshed sphere's), precedence of later bodies, the inside-the-box check,
 * thread safety flags and the errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm_testing.h"

#include "gm_shape.h"
#include "pm_omp.h"

#define DATA PM_TEST_DATA "/geometry/"

static const double box_lo[3] = {0, 0, 0}, box_hi[3] = {3, 4, 5};

static pm_scene_body body_of(pm_body_shape kind) {
  pm_scene_body b;
  memset(&b, 0, sizeof b);
  b.shape = kind;
  return b;
}

static gm_shape *make(const pm_scene_body *b, int dim) {
  gm_shape *s = NULL;
  assert_ok(gm_shape_create(b, dim, box_lo, box_hi, 0.1, &s));
  assert_non_null(s);
  return s;
}

/* Point p moved by d along axis k. */
static const double *moved(const double p[3], int k, double d) {
  static double q[3];
  memcpy(q, p, sizeof q);
  q[k] += d;
  return q;
}

static void test_domain(void **state) {
  (void)state;
  pm_scene_body b = body_of(PM_BODY_DOMAIN);
  gm_shape *s = make(&b, 3);
  assert_string_equal(gm_shape_kind(s), "domain");
  assert_true(gm_shape_thread_safe(s));
  const double in[][3] = {{1, 1, 1}, {0, 0, 0}, {3, 4, 5}, {3, 0, 2.5}};
  for (int i = 0; i < 4; i++) assert_true(gm_shape_contains(s, in[i]));
  /* Round-off on the faces is inside; a visible step out is not. */
  assert_true(gm_shape_contains(s, (const double[3]){3 + 1e-12, 2, 2}));
  assert_false(gm_shape_contains(s, (const double[3]){3 + 1e-6, 2, 2}));
  assert_false(gm_shape_contains(s, (const double[3]){1, -1e-6, 2}));
  double lo[3] = {7, 7, 7}, hi[3] = {7, 7, 7};
  assert_false(gm_shape_bounds(s, lo, hi));
  assert_true(lo[0] == 7 && hi[2] == 7);
  gm_shape_destroy(s);
  /* In 2D z is ignored. */
  s = make(&b, 2);
  assert_true(gm_shape_contains(s, (const double[3]){1, 1, 100}));
  gm_shape_destroy(s);
}

static void test_region(void **state) {
  (void)state;
  pm_scene_body b = body_of(PM_BODY_REGION);
  assert_ok(pm_expr_create("0.25 - (x*x + y*y + z*z)", &b.region));
  gm_shape *s = make(&b, 3);
  assert_string_equal(gm_shape_kind(s), "region");
  assert_false(gm_shape_thread_safe(s));
  assert_true(gm_shape_contains(s, (const double[3]){0, 0, 0}));
  assert_true(gm_shape_contains(s, (const double[3]){0.3, 0.3, 0.2}));
  assert_false(gm_shape_contains(s, (const double[3]){0.3, 0.3, 0.3}));
  /* The region is where the expression is > 0: its zero set is out. */
  assert_false(gm_shape_contains(s, (const double[3]){0.5, 0, 0}));
  double lo[3], hi[3];
  assert_false(gm_shape_bounds(s, lo, hi));
  assert_ok(gm_shape_check_inside(s, 0, box_lo, box_hi));
  gm_shape_destroy(s);
  /* In 2D the expression sees z = 0. */
  s = make(&b, 2);
  assert_true(gm_shape_contains(s, (const double[3]){0.3, 0.3, 0.3}));
  gm_shape_destroy(s);
  pm_expr_destroy(b.region);
}

static void test_box(void **state) {
  (void)state;
  pm_scene_body b = body_of(PM_BODY_BOX);
  const double lo[3] = {0.5, 1, 2}, hi[3] = {1.5, 3, 2.5};
  memcpy(b.a, lo, sizeof lo);
  memcpy(b.b, hi, sizeof hi);
  gm_shape *s = make(&b, 3);
  assert_string_equal(gm_shape_kind(s), "box");
  assert_true(gm_shape_thread_safe(s));
  const double mid[3] = {1, 2, 2.25};
  assert_true(gm_shape_contains(s, mid));
  for (int k = 0; k < 3; k++) {
    double h = 0.5 * (hi[k] - lo[k]);
    /* On each face (inside), and just beyond it (outside). */
    assert_true(gm_shape_contains(s, moved(mid, k, h)));
    assert_true(gm_shape_contains(s, moved(mid, k, -h)));
    assert_false(gm_shape_contains(s, moved(mid, k, h * (1 + 1e-12))));
    assert_false(gm_shape_contains(s, moved(mid, k, -h * (1 + 1e-12))));
  }
  assert_true(gm_shape_contains(s, lo));
  assert_true(gm_shape_contains(s, hi));
  double blo[3], bhi[3];
  assert_true(gm_shape_bounds(s, blo, bhi));
  assert_memory_equal(blo, lo, sizeof lo);
  assert_memory_equal(bhi, hi, sizeof hi);
  gm_shape_destroy(s);
  /* 2D: z ignored, bounds flat. */
  s = make(&b, 2);
  assert_true(gm_shape_contains(s, (const double[3]){1, 2, -7}));
  assert_true(gm_shape_bounds(s, blo, bhi));
  assert_true(blo[2] == 0 && bhi[2] == 0 && blo[1] == 1 && bhi[0] == 1.5);
  gm_shape_destroy(s);
}

static void test_sphere(void **state) {
  (void)state;
  pm_scene_body b = body_of(PM_BODY_SPHERE);
  const double c[3] = {1, 2, 3};
  memcpy(b.a, c, sizeof c);
  b.radius = 0.5;
  gm_shape *s = make(&b, 3);
  assert_string_equal(gm_shape_kind(s), "sphere");
  assert_true(gm_shape_contains(s, c));
  for (int k = 0; k < 3; k++) {
    /* 0.5 is exact in binary: the poles are on the sphere exactly. */
    assert_true(gm_shape_contains(s, moved(c, k, 0.5)));
    assert_true(gm_shape_contains(s, moved(c, k, -0.5)));
    assert_false(gm_shape_contains(s, moved(c, k, 0.5 + 1e-12)));
  }
  const double diag = 0.5 / sqrt(3.0);
  assert_true(gm_shape_contains(
      s, (const double[3]){1 + 0.999 * diag, 2 + 0.999 * diag, 3 - diag}));
  assert_false(gm_shape_contains(
      s, (const double[3]){1 + 1.001 * diag, 2 + 1.001 * diag, 3 - diag}));
  double lo[3], hi[3];
  assert_true(gm_shape_bounds(s, lo, hi));
  for (int k = 0; k < 3; k++) {
    assert_true(lo[k] == c[k] - 0.5);
    assert_true(hi[k] == c[k] + 0.5);
  }
  gm_shape_destroy(s);
  /* A disk in 2D. */
  s = make(&b, 2);
  assert_true(gm_shape_contains(s, (const double[3]){1, 2.5, 100}));
  assert_false(gm_shape_contains(s, (const double[3]){1.4, 2.4, 3}));
  assert_true(gm_shape_bounds(s, lo, hi));
  assert_true(lo[2] == 0 && hi[2] == 0);
  gm_shape_destroy(s);
}

/* A cylinder with its axis along (1, 2, 2) (length 3) and radius 0.5.
 * Its bounds are the end discs' boxes: a disc normal to unit n reaches
 * r sqrt(1 - n_k^2) along axis k, so lo = min(base, top) - e and
 * hi = max(base, top) + e, with e = r (sqrt(8), sqrt(5), sqrt(5)) / 3. */
static void test_tilted_cylinder(void **state) {
  (void)state;
  pm_scene_body b = body_of(PM_BODY_CYLINDER);
  const double base[3] = {0.5, 0.5, 0.5}, axis[3] = {1, 2, 2}, r = 0.5;
  memcpy(b.a, base, sizeof base);
  memcpy(b.b, axis, sizeof axis);
  b.radius = r;
  gm_shape *s = make(&b, 3);
  assert_string_equal(gm_shape_kind(s), "cylinder");
  const double top[3] = {1.5, 2.5, 2.5}, n[3] = {1. / 3, 2. / 3, 2. / 3};
  assert_true(gm_shape_contains(s, base));
  assert_true(gm_shape_contains(s, top));
  /* Along the axis beyond either end: out. */
  double past[3], before[3];
  for (int k = 0; k < 3; k++) {
    past[k] = top[k] + 1e-9 * n[k];
    before[k] = base[k] - 1e-9 * n[k];
  }
  assert_false(gm_shape_contains(s, past));
  assert_false(gm_shape_contains(s, before));
  /* Halfway up, across the axis along u (unit, normal to the axis). */
  const double u[3] = {2 / sqrt(5.0), -1 / sqrt(5.0), 0};
  for (int side = -1; side <= 1; side += 2) {
    double in[3], out[3];
    for (int k = 0; k < 3; k++) {
      double mid = 0.5 * (base[k] + top[k]);
      in[k] = mid + side * r * (1 - 1e-9) * u[k];
      out[k] = mid + side * r * (1 + 1e-9) * u[k];
    }
    assert_true(gm_shape_contains(s, in));
    assert_false(gm_shape_contains(s, out));
  }
  double lo[3], hi[3];
  assert_true(gm_shape_bounds(s, lo, hi));
  const double e[3] = {r * sqrt(8.0) / 3, r * sqrt(5.0) / 3, r * sqrt(5.0) / 3};
  for (int k = 0; k < 3; k++) {
    print_message("  axis %c: [%.15f, %.15f] (analytic [%.15f, %.15f])\n",
                  "xyz"[k], lo[k], hi[k], base[k] - e[k], top[k] + e[k]);
    assert_true(fabs(lo[k] - (base[k] - e[k])) <= 1e-15);
    assert_true(fabs(hi[k] - (top[k] + e[k])) <= 1e-15);
  }
  /* The bounds are tight: points of the rims reach them (to the sampling
   * of the rim), and none passes them. */
  const double v[3] = {(n[1] * u[2] - n[2] * u[1]), (n[2] * u[0] - n[0] * u[2]),
                       (n[0] * u[1] - n[1] * u[0])};
  double reach_lo[3] = {1e9, 1e9, 1e9}, reach_hi[3] = {-1e9, -1e9, -1e9};
  for (int end = 0; end < 2; end++)
    for (int i = 0; i < 3600; i++) {
      double t = 2 * 3.14159265358979323846 * i / 3600, p[3];
      for (int k = 0; k < 3; k++) {
        p[k] = (end ? top[k] : base[k]) + r * (cos(t) * u[k] + sin(t) * v[k]);
        reach_lo[k] = fmin(reach_lo[k], p[k]);
        reach_hi[k] = fmax(reach_hi[k], p[k]);
      }
    }
  for (int k = 0; k < 3; k++) {
    assert_true(reach_lo[k] >= lo[k] - 1e-15 && reach_lo[k] < lo[k] + 1e-6);
    assert_true(reach_hi[k] <= hi[k] + 1e-15 && reach_hi[k] > hi[k] - 1e-6);
  }
  gm_shape_destroy(s);
}

/* A ball of radius 0.5 about (1, 2, 3) meshed at h = 0.1: an inscribed
 * mesh, so its bounds lie inside the sphere's box and within a chord gap
 * (h^2 / r) of it. */
static void test_meshed_sphere(void **state) {
  (void)state;
  const double c[3] = {1, 2, 3}, r = 0.5, h = 0.1;
  pm_scene_body b = body_of(PM_BODY_MESH);
  b.mesh = DATA "sphere.geo";
  gm_shape *s = NULL;
  assert_ok(gm_shape_create(&b, 3, box_lo, box_hi, h, &s));
  assert_string_equal(gm_shape_kind(s), "mesh");
  assert_true(gm_shape_thread_safe(s));
  double lo[3], hi[3];
  assert_true(gm_shape_bounds(s, lo, hi));
  for (int k = 0; k < 3; k++) {
    print_message("  axis %c: [%.5f, %.5f] (sphere [%.5f, %.5f])\n", "xyz"[k],
                  lo[k], hi[k], c[k] - r, c[k] + r);
    assert_true(lo[k] >= c[k] - r - 1e-12 && lo[k] < c[k] - r + h * h / r);
    assert_true(hi[k] <= c[k] + r + 1e-12 && hi[k] > c[k] + r - h * h / r);
  }
  assert_true(gm_shape_contains(s, c));
  assert_true(gm_shape_contains(s, moved(c, 0, r - h)));
  assert_false(gm_shape_contains(s, moved(c, 1, r + 1e-9)));
  assert_false(gm_shape_contains(s, (const double[3]){1.4, 2.4, 3.3}));
  assert_ok(gm_shape_check_inside(s, 0, box_lo, box_hi));
  /* Read-only queries from several threads agree with one thread (two
   * threads whatever OMP_NUM_THREADS says: the unit tests run one). */
  long disagree = 0;
  PM_OMP(parallel for num_threads(2) default(none) shared(s, c, r, h)
             reduction(+ : disagree))
  for (int i = 0; i < 20000; i++) {
    double x[3] = {c[0] - 0.6 + 1.2 * (i % 37) / 36.0,
                   c[1] - 0.6 + 1.2 * (i / 37 % 23) / 22.0, c[2] + 0.01 * i};
    double d2 = 0;
    for (int k = 0; k < 3; k++) d2 += (x[k] - c[k]) * (x[k] - c[k]);
    if (d2 < (r - h) * (r - h)) disagree += !gm_shape_contains(s, x);
    if (d2 > r * r) disagree += gm_shape_contains(s, x);
  }
  assert_int_equal(disagree, 0);
  gm_shape_destroy(s);
}

static void test_last_containing(void **state) {
  (void)state;
  pm_scene_body dom = body_of(PM_BODY_DOMAIN), box = body_of(PM_BODY_BOX);
  pm_scene_body ball = body_of(PM_BODY_SPHERE);
  const double blo[3] = {0, 0, 0}, bhi[3] = {1, 1, 1};
  memcpy(box.a, blo, sizeof blo);
  memcpy(box.b, bhi, sizeof bhi);
  ball.a[0] = ball.a[1] = ball.a[2] = 1;
  ball.radius = 0.5;
  const gm_shape *shapes[4] = {make(&dom, 3), make(&box, 3), NULL,
                               make(&ball, 3)};
  const double a[3] = {0.9, 0.9, 0.9}, b[3] = {0.2, 0.2, 0.2};
  const double c[3] = {2, 2, 2}, d[3] = {1.2, 1.2, 1.2}, e[3] = {9, 9, 9};
  assert_int_equal(gm_shape_last_containing(shapes, 4, a), 3);
  assert_int_equal(gm_shape_last_containing(shapes, 3, a), 1);
  assert_int_equal(gm_shape_last_containing(shapes, 4, b), 1);
  assert_int_equal(gm_shape_last_containing(shapes, 4, c), 0);
  assert_int_equal(gm_shape_last_containing(shapes, 4, d), 3);
  assert_int_equal(gm_shape_last_containing(shapes, 4, e), -1);
  assert_int_equal(gm_shape_last_containing(shapes, 0, a), -1);
  assert_int_equal(gm_shape_last_containing(NULL, 4, a), -1);
  for (int i = 0; i < 4; i++) gm_shape_destroy((gm_shape *)shapes[i]);
}

static void test_check_inside(void **state) {
  (void)state;
  pm_scene_body b = body_of(PM_BODY_SPHERE);
  b.a[0] = 2.6;
  b.a[1] = b.a[2] = 1;
  b.radius = 0.4;
  gm_shape *s = make(&b, 3);
  /* Touching the face x = 3 (to round-off) is inside. */
  assert_ok(gm_shape_check_inside(s, 2, box_lo, box_hi));
  gm_shape_destroy(s);
  b.radius = 0.5;
  s = make(&b, 3);
  assert_int_equal(gm_shape_check_inside(s, 2, box_lo, box_hi), PM_ERR_SCENE);
  print_message("  %s\n", pm_error_message());
  assert_string_equal(pm_error_message(),
                      "bodies.2.sphere: expected a shape inside domain.box "
                      "(x in [0, 3]), got one reaching x = 3.1");
  gm_shape_destroy(s);
  /* The low side, and the unbounded domain. */
  pm_scene_body box = body_of(PM_BODY_BOX), dom = body_of(PM_BODY_DOMAIN);
  box.a[1] = -0.25;
  box.b[0] = box.b[1] = box.b[2] = 1;
  s = make(&box, 3);
  assert_int_equal(gm_shape_check_inside(s, 0, box_lo, box_hi), PM_ERR_SCENE);
  assert_non_null(strstr(pm_error_message(), "reaching y = -0.25"));
  gm_shape_destroy(s);
  s = make(&dom, 3);
  assert_ok(gm_shape_check_inside(s, 0, box_lo, box_hi));
  gm_shape_destroy(s);
  pm_error_clear();
}

static void test_errors(void **state) {
  (void)state;
  gm_shape *s = (gm_shape *)0x1;
  pm_scene_body b = body_of(PM_BODY_BOX);
  b.b[0] = 1;
  b.b[1] = 1;
  assert_int_equal(gm_shape_create(&b, 3, box_lo, box_hi, 0.1, &s),
                   PM_ERR_ARG); /* zero thickness along z */
  assert_null(s);
  print_message("  %s\n", pm_error_message());
  assert_ok(gm_shape_create(&b, 2, box_lo, box_hi, 0.1, &s));
  gm_shape_destroy(s);
  b = body_of(PM_BODY_SPHERE);
  assert_int_equal(gm_shape_create(&b, 3, box_lo, box_hi, 0.1, &s), PM_ERR_ARG);
  b.radius = NAN;
  assert_int_equal(gm_shape_create(&b, 3, box_lo, box_hi, 0.1, &s), PM_ERR_ARG);
  b = body_of(PM_BODY_CYLINDER);
  b.radius = 1;
  assert_int_equal(gm_shape_create(&b, 3, box_lo, box_hi, 0.1, &s),
                   PM_ERR_ARG); /* zero axis */
  b.b[2] = 1;
  assert_int_equal(gm_shape_create(&b, 2, box_lo, box_hi, 0.1, &s), PM_ERR_ARG);
  print_message("  %s\n", pm_error_message());
  b = body_of(PM_BODY_REGION);
  assert_int_equal(gm_shape_create(&b, 3, box_lo, box_hi, 0.1, &s), PM_ERR_ARG);
  b = body_of(PM_BODY_MESH);
  assert_int_equal(gm_shape_create(&b, 3, box_lo, box_hi, 0.1, &s), PM_ERR_ARG);
  b.mesh = DATA "no-such-file.geo";
  assert_int_equal(gm_shape_create(&b, 3, box_lo, box_hi, 0.1, &s), PM_ERR_IO);
  assert_non_null(strstr(pm_error_message(), "no-such-file.geo"));
  b = body_of((pm_body_shape)99);
  assert_int_equal(gm_shape_create(&b, 3, box_lo, box_hi, 0.1, &s),
                   PM_ERR_UNSUPPORTED);
  b = body_of(PM_BODY_DOMAIN);
  assert_int_equal(gm_shape_create(&b, 4, box_lo, box_hi, 0.1, &s), PM_ERR_ARG);
  assert_int_equal(gm_shape_create(&b, 3, box_hi, box_lo, 0.1, &s), PM_ERR_ARG);
  assert_int_equal(gm_shape_create(NULL, 3, box_lo, box_hi, 0.1, &s),
                   PM_ERR_ARG);
  assert_int_equal(gm_shape_create(&b, 3, box_lo, box_hi, 0.1, NULL),
                   PM_ERR_ARG);
  assert_null(s);
  /* NULL shapes answer no. */
  const double x[3] = {0, 0, 0};
  double lo[3], hi[3];
  assert_false(gm_shape_contains(NULL, x));
  assert_false(gm_shape_bounds(NULL, lo, hi));
  assert_false(gm_shape_thread_safe(NULL));
  assert_string_equal(gm_shape_kind(NULL), "?");
  gm_shape_destroy(NULL);
  pm_error_clear();
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_domain),
      cmocka_unit_test(test_region),
      cmocka_unit_test(test_box),
      cmocka_unit_test(test_sphere),
      cmocka_unit_test(test_tilted_cylinder),
      cmocka_unit_test(test_meshed_sphere),
      cmocka_unit_test(test_last_containing),
      cmocka_unit_test(test_check_inside),
      cmocka_unit_test(test_errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
