/* gm_testing: what the tests of triangulated surfaces and of the
 * inside/outside test share (test_trisurf, test_inside): icospheres and
 * squares, areas, closedness, a clock.  Include after cmocka.h and
 * pm_testing.h. */
#ifndef GM_TESTING_H
#define GM_TESTING_H

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "gm_trisurf.h"
#include "pm_tensor.h"

static inline double surf_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Twice the area vector of triangle t. */
static inline void surf_area_vector(const gm_trisurf *s, long t, double n[3]) {
  const long *v = s->tri + 3 * t;
  double e1[3], e2[3];
  for (int k = 0; k < 3; k++) {
    e1[k] = s->x[3 * v[1] + k] - s->x[3 * v[0] + k];
    e2[k] = s->x[3 * v[2] + k] - s->x[3 * v[0] + k];
  }
  pm_v_cross(e1, e2, n);
}

/* The nearest a triangle's plane comes to c: the inscribed polyhedron
 * holds the ball of that radius, as every face's normal points away from
 * c. */
static inline double surf_nearest_plane(const gm_trisurf *s,
                                        const double c[3]) {
  double d = INFINITY;
  for (long t = 0; t < s->n_tris; t++) {
    double n[3], a[3];
    surf_area_vector(s, t, n);
    for (int k = 0; k < 3; k++) a[k] = s->x[3 * s->tri[3 * t] + k] - c[k];
    d = fmin(d, pm_v_dot(n, a) / pm_v_norm(n));
  }
  return d;
}

static inline void surf_expect_closed(const gm_trisurf *s) {
  char why[256];
  if (!gm_trisurf_closed(s, why, sizeof why)) fail_msg("not closed: %s", why);
}

/* The icosphere of refinement r, radius R about c. */
static inline gm_trisurf surf_sphere(const double c[3], double R, int r) {
  gm_trisurf s;
  assert_ok(gm_trisurf_sphere(c, R, r, &s));
  return s;
}

/* The unit square in z = 0, n x n points: an open surface. */
static inline gm_trisurf surf_unit_square(long n) {
  const double u[3] = {1, 0, 0}, v[3] = {0, 1, 0};
  gm_trisurf s;
  const double o[3] = {0, 0, 0};
  assert_ok(gm_trisurf_rectangle(o, u, v, n, n, &s));
  return s;
}

/* The unit cube as an ASCII STL, 12 facets turning outward, each listing
 * its corners again (36 vertices for 8 points). */
static inline void surf_write_cube_stl(const char *dir, char path[512]) {
  static const double quad[6][4][3] = {
      {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}},
      {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}},
      {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}},
      {{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}},
      {{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}},
      {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};
  static const int half[2][3] = {{0, 1, 2}, {0, 2, 3}};
  char text[8192];
  size_t len = (size_t)snprintf(text, sizeof text, "solid cube\n");
  for (int f = 0; f < 6; f++)
    for (int h = 0; h < 2; h++) {
      len += (size_t)snprintf(text + len, sizeof text - len,
                              "facet normal 0 0 0\n outer loop\n");
      for (int c = 0; c < 3; c++) {
        const double *p = quad[f][half[h][c]];
        len += (size_t)snprintf(text + len, sizeof text - len,
                                "  vertex %g %g %g\n", p[0], p[1], p[2]);
      }
      len += (size_t)snprintf(text + len, sizeof text - len,
                              " endloop\nendfacet\n");
    }
  len += (size_t)snprintf(text + len, sizeof text - len, "endsolid cube\n");
  assert_true(len < sizeof text);
  pm_test_write_file(dir, "cube.stl", text, path);
}

#endif
