/* test_curve: 2-D membranes as lines of points against analytic answers
 * (equal arc-length spacing on a quarter circle, a full circle and a curve
 * whose parameter is not its arc length; lengths; radial normals), the
 * polygon a membrane encloses (closed, or closed along the domain's
 * boundary) and point-in-polygon on edges and vertices (point files:
 * test_points_load). */
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

#define PI 3.14159265358979323846

/* The curve (xs(t), ys(t)) for t in [t0, t1], n points. */
static gm_curve parametric(const char *xs, const char *ys, double t0, double t1,
                           long n, bool closed) {
  pm_expr *ex = NULL, *ey = NULL;
  assert_ok(pm_expr_create(xs, &ex));
  assert_ok(pm_expr_create(ys, &ey));
  gm_curve c;
  assert_ok(gm_curve_parametric(ex, ey, t0, t1, n, closed, &c));
  assert_int_equal(c.n, n);
  assert_true(c.closed == closed);
  pm_expr_destroy(ex);
  pm_expr_destroy(ey);
  return c;
}

/* The error gm_curve_parametric gives for (xs, ys). */
static pm_err parametric_error(const char *xs, const char *ys, double t0,
                               double t1, long n, bool closed) {
  pm_expr *ex = NULL, *ey = NULL;
  assert_ok(pm_expr_create(xs, &ex));
  assert_ok(pm_expr_create(ys, &ey));
  gm_curve c;
  pm_err e = gm_curve_parametric(ex, ey, t0, t1, n, closed, &c);
  assert_null(c.x);
  assert_int_equal(c.n, 0);
  pm_expr_destroy(ex);
  pm_expr_destroy(ey);
  return e;
}

static double chord(const gm_curve *c, long a, long b) {
  const double *p = c->x + 3 * a, *q = c->x + 3 * b;
  return hypot(q[0] - p[0], q[1] - p[1]);
}

/* Every segment (with the closing one of a closed curve) within rel of
 * their mean; returns the mean. */
static double expect_equal_spacing(const gm_curve *c, double rel) {
  const long segments = c->closed ? c->n : c->n - 1;
  double mean = 0.0;
  for (long e = 0; e < segments; e++) mean += chord(c, e, (e + 1) % c->n);
  mean /= (double)segments;
  for (long e = 0; e < segments; e++)
    assert_close(chord(c, e, (e + 1) % c->n), mean, rel, 0);
  return mean;
}

static double length_sum(const gm_curve *c) {
  double *len = malloc(sizeof *len * (size_t)c->n), sum = 0.0;
  assert_non_null(len);
  gm_curve_point_lengths(c, len);
  for (long k = 0; k < c->n; k++) {
    assert_true(len[k] > 0.0);
    sum += len[k];
  }
  free(len);
  return sum;
}

/* The angle between normal m and the direction d (2-D). */
static double angle_to(const double *m, const double d[2]) {
  return fabs(atan2(m[0] * d[1] - m[1] * d[0], m[0] * d[0] + m[1] * d[1]));
}

/* ---- parametric curves -------------------------------------------------- */

static void test_quarter_circle(void **state) {
  (void)state;
  const long n = 91;
  gm_curve c = parametric("0.5*cos(pi/2*t)", "0.5*sin(pi/2*t)", 0, 1, n, 0);
  /* Ends at t0 and t1, every point on the circle. */
  assert_close(c.x[0], 0.5, 1e-15, 0);
  assert_close(c.x[1], 0.0, 0, 1e-15);
  assert_close(c.x[3 * (n - 1)], 0.0, 0, 1e-15);
  assert_close(c.x[3 * (n - 1) + 1], 0.5, 1e-15, 0);
  for (long k = 0; k < n; k++) {
    assert_close(hypot(c.x[3 * k], c.x[3 * k + 1]), 0.5, 1e-15, 0);
    assert_true(c.x[3 * k + 2] == 0.0);
  }
  /* 90 equal chords of 1 degree: their sum is pi/4 less the chords' own
   * shortfall, (pi/180)^2 / 24 of it (1e-5 absolute). */
  const double h = expect_equal_spacing(&c, 1e-6);
  assert_close(h, 2 * 0.5 * sin(PI / 360), 1e-7, 0);
  assert_close(length_sum(&c), PI / 4, 0, 1e-5);
  assert_close(length_sum(&c), 90 * sin(PI / 360), 1e-12, 0);
  /* Half a chord at each end, a whole one inside. */
  double len[91];
  gm_curve_point_lengths(&c, len);
  assert_close(len[0], 0.5 * chord(&c, 0, 1), 1e-15, 0);
  assert_close(len[n - 1], 0.5 * chord(&c, n - 2, n - 1), 1e-15, 0);
  assert_close(len[45], 0.5 * (chord(&c, 44, 45) + chord(&c, 45, 46)), 1e-15,
               0);
  gm_curve_free(&c);
  assert_null(c.x);
}

static void test_closed_circle(void **state) {
  (void)state;
  const long n = 64;
  gm_curve c = parametric("2 + cos(2*pi*t)", "-1 + sin(2*pi*t)", 0, 1, n, 1);
  /* n points, the first at t0 and not repeated at the end. */
  assert_close(c.x[0], 3.0, 1e-15, 0);
  assert_close(c.x[1], -1.0, 1e-15, 0);
  assert_true(chord(&c, n - 1, 0) > 0.09);
  const double h = expect_equal_spacing(&c, 1e-7);
  assert_close(h, 2 * sin(PI / (double)n), 1e-7, 0);
  assert_close(length_sum(&c), 2.0 * (double)n * sin(PI / (double)n), 1e-7, 0);
  gm_curve_free(&c);
}

/* The arc length of (t^3, t) from 0 to t (Simpson's rule, 2000 panels:
 * error below 1e-13). */
static double cubic_arc(double t) {
  const int m = 2000;
  const double h = t / m;
  double sum = 0.0;
  for (int i = 0; i <= m; i++) {
    const double u = h * i, f = sqrt(1 + 9 * pow(u, 4));
    sum += f * (i == 0 || i == m ? 1 : i % 2 ? 4 : 2);
  }
  return sum * h / 3;
}

static void test_nonuniform_parameter(void **state) {
  (void)state;
  /* A quarter circle run with t^2: the points at equal arc length are
   * equally spaced, although equal steps of t would crowd its start. */
  gm_curve c =
      parametric("0.5*cos(pi/2*t^2)", "0.5*sin(pi/2*t^2)", 0, 1, 91, 0);
  expect_equal_spacing(&c, 1e-6);
  gm_curve_free(&c);
  /* (t^3, t): ds/dt runs from 1 to sqrt(10), and the curvature varies, so
   * that chords of equal arcs differ (by 1e-4): the arc lengths to each
   * point are checked instead, against quadrature.  The 64 n chords that
   * measure the length fall short of it by curvature^2 chord^2 / 24, about
   * 2e-8 of it here, below 1e-6 of a spacing. */
  const long n = 50;
  c = parametric("t^3", "t", 0, 1, n, 0);
  const double length = cubic_arc(1.0), h = length / (double)(n - 1);
  for (long k = 0; k < n; k++) {
    assert_close(c.x[3 * k], pow(c.x[3 * k + 1], 3), 1e-14, 1e-15);
    assert_close(cubic_arc(c.x[3 * k + 1]), h * (double)k, 0, 1e-6 * h);
  }
  gm_curve_free(&c);
  /* A straight line where dx/dt vanishes at the start: its chords are its
   * arcs, equal to round-off. */
  c = parametric("t^3", "0", 0, 1, 21, 0);
  const double step = expect_equal_spacing(&c, 1e-12);
  assert_close(step, 0.05, 1e-12, 0);
  gm_curve_free(&c);
  /* An ellipse, closed, its parameter running backwards: clockwise from
   * (3, 0), the polygon's area near -3 pi (less the 40 chords' share). */
  c = parametric("3*cos(t)", "sin(t)", 2 * PI, 0, 40, 1);
  assert_close(c.x[0], 3.0, 1e-15, 0);
  assert_close(c.x[1], 0.0, 0, 1e-15);
  assert_true(c.x[4] < 0.0);
  gm_polygon p;
  assert_ok(gm_curve_polygon(c.n, c.x, true, NULL, NULL, 0, &p));
  assert_close(gm_polygon_area(&p), -3 * PI, 2e-2, 0);
  gm_polygon_free(&p);
  gm_curve_free(&c);
}

static void test_parametric_errors(void **state) {
  (void)state;
  pm_expr *ex = NULL;
  gm_curve c;
  assert_ok(pm_expr_create("t", &ex));
  assert_fails(gm_curve_parametric(ex, ex, 0, 1, 1, false, &c), PM_ERR_ARG,
               "at least 2 points (got 1)");
  assert_fails(gm_curve_parametric(ex, ex, 0, NAN, 5, false, &c), PM_ERR_ARG,
               "finite");
  pm_expr_destroy(ex);
  assert_int_equal(parametric_error("sqrt(t - 0.5)", "t", 0, 1, 10, false),
                   PM_ERR_EXPR);
  assert_non_null(strstr(pm_error_message(), "\"sqrt(t - 0.5)\" is"));
  assert_non_null(strstr(pm_error_message(), "expected a finite value"));
  assert_int_equal(parametric_error("t", "1/(t - 0.5)", 0, 1, 10, false),
                   PM_ERR_EXPR);
  assert_non_null(strstr(pm_error_message(), "y(t)"));
  assert_int_equal(parametric_error("1", "2", 0, 1, 10, false),
                   PM_ERR_GEOMETRY);
  assert_non_null(strstr(pm_error_message(), "has length 0"));
  assert_int_equal(parametric_error("t", "t", 0.5, 0.5, 10, false),
                   PM_ERR_GEOMETRY);
  /* A closed curve must return to its start. */
  assert_int_equal(parametric_error("cos(t)", "sin(t)", 0, 3, 10, true),
                   PM_ERR_GEOMETRY);
  assert_non_null(strstr(pm_error_message(), "return to its start"));
}

static void test_from_points(void **state) {
  (void)state;
  const double x[9] = {0, 0, 0, 1, 0, 0, 1, 2, 0};
  gm_curve c;
  assert_ok(gm_curve_from_points(3, x, false, &c));
  assert_true(c.x != x && c.x[7] == 2.0);
  double len[3];
  gm_curve_point_lengths(&c, len);
  assert_close(len[0], 0.5, 1e-15, 0);
  assert_close(len[1], 1.5, 1e-15, 0);
  assert_close(len[2], 1.0, 1e-15, 0);
  gm_curve_free(&c);
  /* Closed, the hypotenuse shared by the two ends. */
  assert_ok(gm_curve_from_points(3, x, true, &c));
  gm_curve_point_lengths(&c, len);
  assert_close(len[0], 0.5 + 0.5 * sqrt(5.0), 1e-15, 0);
  assert_close(len[2], 1.0 + 0.5 * sqrt(5.0), 1e-15, 0);
  gm_curve_free(&c);
  assert_fails(gm_curve_from_points(2, x, true, &c), PM_ERR_ARG,
               "at least 3 points (got 2)");
  const double bad[6] = {0, 0, 0, 1, NAN, 0};
  assert_fails(gm_curve_from_points(2, bad, false, &c), PM_ERR_GEOMETRY,
               "point 1");
  assert_null(c.x);
}

/* ---- normals ------------------------------------------------------------ */

static void test_normals_circle(void **state) {
  (void)state;
  const long n = 91;
  double normal[3 * 91];
  /* Closed, counter-clockwise: outward and radial, to round-off (the
   * central difference is parallel to the tangent on equally spaced points
   * of a circle). */
  gm_curve c = parametric("cos(2*pi*t)", "sin(2*pi*t)", 0, 1, n, 1);
  assert_int_equal(gm_curve_normals(n, c.x, true, normal), 0);
  for (long k = 0; k < n; k++) {
    const double *m = normal + 3 * k;
    assert_close(hypot(m[0], m[1]), 1.0, 1e-15, 0);
    assert_true(m[2] == 0.0);
    assert_true(angle_to(m, c.x + 3 * k) < 1e-9); /* 1e-3 asked */
  }
  gm_curve_free(&c);
  /* Open quarter circle: interior normals as closely radial; at each end
   * the tangent is the end chord, whose direction is off the circle's by
   * half the angle it subtends: pi/360 = 0.0087 rad, one-sided accuracy
   * (allowed 1e-9 more). */
  c = parametric("0.5*cos(pi/2*t)", "0.5*sin(pi/2*t)", 0, 1, n, 0);
  assert_int_equal(gm_curve_normals(n, c.x, false, normal), 0);
  for (long k = 1; k < n - 1; k++)
    assert_true(angle_to(normal + 3 * k, c.x + 3 * k) < 1e-9);
  const double end = PI / 360;
  assert_close(angle_to(normal, c.x), end, 0, 1e-9);
  assert_close(angle_to(normal + 3 * (n - 1), c.x + 3 * (n - 1)), end, 0, 1e-9);
  /* Run clockwise (the points reversed), the normals point inward. */
  double rev[3 * 91];
  for (long k = 0; k < n; k++)
    memcpy(rev + 3 * k, c.x + 3 * (n - 1 - k), 3 * sizeof *rev);
  assert_int_equal(gm_curve_normals(n, rev, false, normal), 0);
  for (long k = 0; k < n; k++) {
    const double in[2] = {-rev[3 * k], -rev[3 * k + 1]};
    assert_true(angle_to(normal + 3 * k, in) <= end + 1e-9);
  }
  gm_curve_free(&c);
}

static void test_normals_vanishing(void **state) {
  (void)state;
  /* Points 1 and 3 have coincident neighbours; the ends of two
   * coincident points have none at all. */
  const double x[15] = {0, 0, 0, 1, 0, 0, 0, 0, 0, 2, 2, 0, 0, 0, 0};
  double normal[15];
  assert_int_equal(gm_curve_normals(5, x, false, normal), 2);
  assert_true(normal[3] == 0 && normal[4] == 0 && normal[5] == 0);
  assert_true(normal[9] == 0 && normal[10] == 0 && normal[11] == 0);
  assert_close(normal[0], 0.0, 0, 1e-15); /* tangent (1, 0): n = (0, -1) */
  assert_close(normal[1], -1.0, 1e-15, 0);
  const double two[6] = {1, 1, 0, 1, 1, 0};
  assert_int_equal(gm_curve_normals(2, two, false, normal), 2);
}

/* ---- the enclosed polygon ----------------------------------------------- */

static const double box_lo[3] = {0, 0, 0}, box_hi[3] = {1, 1, 1};

/* The region the n points x enclose in the box [0, 1]^2 (tol 1e-9): nv
 * vertices, the last at corner (when not NULL), its signed area within rel
 * of area, holding in and not out (z of no account). */
static void expect_region(long n, const double *x, bool closed, long nv,
                          const double *corner, double area, double rel,
                          const double in[2], const double out[2]) {
  gm_polygon p;
  assert_ok(gm_curve_polygon(n, x, closed, box_lo, box_hi, 1e-9, &p));
  assert_int_equal(p.n, nv);
  if (corner)
    assert_true(p.xy[2 * nv - 2] == corner[0] && p.xy[2 * nv - 1] == corner[1]);
  assert_close(gm_polygon_area(&p), area, rel, 0);
  const double a[3] = {in[0], in[1], 7}, b[3] = {out[0], out[1], -7};
  assert_true(gm_polygon_contains(&p, a));
  assert_false(gm_polygon_contains(&p, b));
  gm_polygon_free(&p);
  assert_null(p.xy);
}

static void test_polygon_quarter(void **state) {
  (void)state;
  const long n = 91;
  const double origin[2] = {0, 0}, in[2] = {0.1, 0.1}, out[2] = {0.45, 0.45};
  gm_curve c = parametric("0.5*cos(pi/2*t)", "0.5*sin(pi/2*t)", 0, 1, n, 0);
  /* Closed through the corner (0, 0) the two faces share: pi 0.25 / 4 to
   * 1e-3, and to round-off that of 90 triangles of 1 degree. */
  const double area = 45 * 0.25 * sin(PI / 180);
  assert_close(area, PI * 0.25 / 4, 0, 1e-3);
  expect_region(n, c.x, false, n + 1, origin, area, 1e-12, in, out);
  /* Clockwise, the same region of negative area. */
  double rev[3 * 91];
  for (long k = 0; k < n; k++)
    memcpy(rev + 3 * k, c.x + 3 * (n - 1 - k), 3 * sizeof *rev);
  expect_region(n, rev, false, n + 1, origin, -area, 1e-12, in, out);
  gm_curve_free(&c);
  /* About the corner (1, 1), ends just inside the faces (within tol). */
  const double one[2] = {1, 1}, in1[2] = {0.9, 0.9}, out1[2] = {0.55, 0.55};
  c = parametric("1 - 0.5*cos(pi/2*t) - 1e-10", "1 - 0.5*sin(pi/2*t)", 0, 1, n,
                 0);
  expect_region(n, c.x, false, n + 1, one, area, 1e-6, in1, out1);
  gm_curve_free(&c);
}

static void test_polygon_same_face(void **state) {
  (void)state;
  /* A half circle standing on the face y = 0: closed straight along it. */
  const double in[2] = {0.5, 0.1}, out[2] = {0.1, 0.1};
  gm_curve c = parametric("0.5 + 0.3*cos(pi*t)", "0.3*sin(pi*t)", 0, 1, 61, 0);
  expect_region(c.n, c.x, false, c.n, NULL, PI * 0.09 / 2, 1e-3, in, out);
  gm_curve_free(&c);
}

static void test_polygon_closed(void **state) {
  (void)state;
  const double in[2] = {0.5, 0.5}, out[2] = {0.1, 0.5};
  gm_curve c =
      parametric("0.5 + 0.2*cos(2*pi*t)", "0.5 + 0.2*sin(2*pi*t)", 0, 1, 50, 1);
  expect_region(c.n, c.x, true, c.n, NULL, 25 * 0.04 * sin(2 * PI / 50), 1e-12,
                in, out);
  gm_curve_free(&c);
}

static void test_polygon_open_fails(void **state) {
  (void)state;
  gm_polygon p;
  /* One end inside the domain. */
  const double x[9] = {0.5, 0, 0, 0.5, 0.25, 0, 0.3, 0.4, 0};
  assert_fails(gm_curve_polygon(3, x, false, box_lo, box_hi, 1e-9, &p),
               PM_ERR_GEOMETRY, "open and its ends (0.5, 0) and (0.3, 0.4)");
  assert_non_null(strstr(pm_error_message(), "not both on the boundary"));
  assert_null(p.xy);
  /* Both inside; one just beyond tol of a face. */
  const double y[6] = {0.2, 0.2, 0, 1 - 1e-6, 0.5, 0};
  assert_fails(gm_curve_polygon(2, y, false, box_lo, box_hi, 1e-9, &p),
               PM_ERR_GEOMETRY, "not both on the boundary");
  /* On the boundary's line but outside the box. */
  const double z[6] = {0, 0.5, 0, 1.5, 0, 0};
  assert_fails(gm_curve_polygon(2, z, false, box_lo, box_hi, 1e-9, &p),
               PM_ERR_GEOMETRY, "not both on the boundary");
  /* Opposite faces: which side is meant is not known. */
  const double w[9] = {0, 0.5, 0, 0.5, 0.6, 0, 1, 0.5, 0};
  assert_fails(gm_curve_polygon(3, w, false, box_lo, box_hi, 1e-9, &p),
               PM_ERR_GEOMETRY, "opposite faces");
  const double v[9] = {0, 0, 0, 0.4, 0.6, 0, 1, 1, 0};
  assert_fails(gm_curve_polygon(3, v, false, box_lo, box_hi, 1e-9, &p),
               PM_ERR_GEOMETRY, "opposite corners");
  assert_fails(gm_curve_polygon(1, w, false, box_lo, box_hi, 1e-9, &p),
               PM_ERR_ARG, "at least 2 points");
}

/* The unit square's edges and vertices: half-open, [0, 1) x [0, 1),
 * whichever way the square runs. */
static void test_contains_edges(void **state) {
  (void)state;
  double ccw[8] = {0, 0, 1, 0, 1, 1, 0, 1}, cw[8];
  for (int k = 0; k < 4; k++) {
    cw[2 * k] = ccw[2 * (3 - k)];
    cw[2 * k + 1] = ccw[2 * (3 - k) + 1];
  }
  const gm_polygon sq[2] = {{4, ccw}, {4, cw}};
  for (int s = 0; s < 2; s++)
    for (int i = -1; i <= 5; i++)
      for (int j = -1; j <= 5; j++) {
        const double x[3] = {0.25 * i, 0.25 * j, 0};
        const bool want = i >= 0 && i < 4 && j >= 0 && j < 4;
        if (gm_polygon_contains(&sq[s], x) != want)
          fail_msg("(%g, %g) in the %s square: %d", x[0], x[1],
                   s ? "clockwise" : "counter-clockwise", !want);
      }
  /* A ray through a vertex: once through the diamond's right vertex,
   * twice through its left and right ones, tangent at its bottom one. */
  double d[8] = {1, 0, 2, 1, 1, 2, 0, 1};
  const gm_polygon diamond = {4, d};
  const double a[3] = {0.5, 1, 0}, b[3] = {-1, 1, 0}, c[3] = {0.5, 0, 0};
  assert_true(gm_polygon_contains(&diamond, a));
  assert_false(gm_polygon_contains(&diamond, b));
  assert_false(gm_polygon_contains(&diamond, c));
}

/* Eight triangles tiling [0, 2)^2, in both orientations and both
 * diagonals: a point anywhere in it, on an edge or a vertex included, lies
 * in exactly one (the shared edges give the same crossing either way). */
static void test_contains_tiling(void **state) {
  (void)state;
  double xy[8][6];
  gm_polygon tri[8];
  int t = 0;
  for (int i = 0; i < 2; i++)
    for (int j = 0; j < 2; j++) {
      const double x0 = i, y0 = j, x1 = i + 1, y1 = j + 1;
      const double sq[4][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
      const int s = (i + j) % 2; /* which diagonal */
      const int halves[2][3] = {{s, s + 1, s + 2}, {s + 2, (s + 3) % 4, s}};
      for (int h = 0; h < 2; h++, t++) {
        for (int v = 0; v < 3; v++) {
          /* Every other triangle clockwise. */
          const int c = halves[h][(t % 2) ? 2 - v : v];
          xy[t][2 * v] = sq[c][0];
          xy[t][2 * v + 1] = sq[c][1];
        }
        tri[t] = (gm_polygon){3, xy[t]};
      }
    }
  uint64_t seed = 12345;
  for (int k = 0; k < 20000; k++) {
    double x[3] = {2 * pm_test_uniform(&seed), 2 * pm_test_uniform(&seed), 0};
    if (k % 4 == 1) x[1] = x[0];     /* on the diagonal y = x */
    if (k % 4 == 2) x[1] = 2 - x[0]; /* on the diagonal x + y = 2 */
    if (k % 4 == 3) {                /* on the grid's lines and vertices */
      x[0] = 0.125 * (double)(k / 4 % 16);
      x[1] = 0.125 * (double)(k / 64 % 16);
    }
    if (x[1] >= 2.0) continue;
    int count = 0;
    for (int s = 0; s < 8; s++) count += gm_polygon_contains(&tri[s], x);
    if (count != 1)
      fail_msg("(%.17g, %.17g) lies in %d triangles", x[0], x[1], count);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_quarter_circle),
      cmocka_unit_test(test_closed_circle),
      cmocka_unit_test(test_nonuniform_parameter),
      cmocka_unit_test(test_parametric_errors),
      cmocka_unit_test(test_from_points),
      cmocka_unit_test(test_normals_circle),
      cmocka_unit_test(test_normals_vanishing),
      cmocka_unit_test(test_polygon_quarter),
      cmocka_unit_test(test_polygon_same_face),
      cmocka_unit_test(test_polygon_closed),
      cmocka_unit_test(test_polygon_open_fails),
      cmocka_unit_test(test_contains_edges),
      cmocka_unit_test(test_contains_tiling),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
