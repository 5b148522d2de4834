/* test_trisurf: triangulated surfaces against analytic answers (counts,
 * areas, the icosphere's area and volume within the inscribed
 * polyhedron's bound, incidence, closedness and orientation), files read
 * through gmsh (an STL cube, a .msh square of mixed elements); the
 * inside/outside test is test_inside's. */
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
#include "gmsh_testing.h"

#define PI 3.14159265358979323846

static double total_area(const gm_trisurf *s) {
  double a = 0.0;
  for (long t = 0; t < s->n_tris; t++) {
    double n[3];
    surf_area_vector(s, t, n);
    a += 0.5 * pm_v_norm(n);
  }
  return a;
}

/* The sum of gm_trisurf_point_areas. */
static double point_area_sum(const gm_trisurf *s) {
  double *a = malloc(sizeof *a * (size_t)s->n_points), sum = 0.0;
  assert_non_null(a);
  gm_trisurf_point_areas(s, a);
  for (long p = 0; p < s->n_points; p++) {
    assert_true(a[p] > 0.0);
    sum += a[p];
  }
  free(a);
  return sum;
}

static void expect_open(const gm_trisurf *s, const char *text) {
  char why[256];
  assert_false(gm_trisurf_closed(s, why, sizeof why));
  if (!strstr(why, text)) fail_msg("reason '%s' lacks '%s'", why, text);
}

static const double origin[3] = {0, 0, 0};

/* ---- rectangle ---------------------------------------------------------- */

static void test_rectangle(void **state) {
  (void)state;
  const double o[3] = {1, 2, 3}, u[3] = {2, 0, 0}, v[3] = {0.5, 1, 1};
  gm_trisurf s;
  assert_ok(gm_trisurf_rectangle(o, u, v, 5, 4, &s));
  assert_int_equal(s.n_points, 20);
  assert_int_equal(s.n_tris, 2 * 4 * 3);
  /* Points on the grid, i fastest. */
  const long p = 3 + 5 * 2;
  for (int k = 0; k < 3; k++)
    assert_close(s.x[3 * p + k], o[k] + 0.75 * u[k] + 2.0 / 3.0 * v[k], 1e-15,
                 1e-15);
  /* |u x v| = |(0, -2, 2)| = 2 sqrt(2), to round-off, however counted. */
  double uv[3];
  pm_v_cross(u, v, uv);
  assert_close(total_area(&s), 2.0 * sqrt(2.0), 1e-14, 0);
  assert_close(point_area_sum(&s), 2.0 * sqrt(2.0), 1e-14, 0);
  /* Every triangle's normal along u x v. */
  for (long t = 0; t < s.n_tris; t++) {
    double n[3];
    surf_area_vector(&s, t, n);
    assert_close(pm_v_dot(n, uv) / (pm_v_norm(n) * pm_v_norm(uv)), 1.0, 1e-14,
                 0);
  }
  expect_open(&s, "hole");
  double lo[3], hi[3];
  gm_trisurf_bounds(&s, lo, hi);
  assert_true(lo[0] == 1 && lo[1] == 2 && lo[2] == 3);
  assert_close(hi[0], 3.5, 1e-15, 0);
  assert_close(hi[1], 3, 1e-15, 0);
  gm_trisurf_free(&s);
  assert_null(s.x);
  gm_trisurf_free(NULL);

  assert_fails(gm_trisurf_rectangle(o, u, v, 1, 4, &s), PM_ERR_ARG,
               "at least 2 points");
  assert_null(s.x);
  const double w[3] = {-4, 0, 0};
  assert_fails(gm_trisurf_rectangle(o, u, w, 3, 3, &s), PM_ERR_ARG,
               "non-parallel");
}

/* ---- icosphere ---------------------------------------------------------- */

/* Counts, closedness, points on the sphere, outward normals, r = 0..6. */
static void test_sphere_counts(void **state) {
  (void)state;
  const double c[3] = {0.5, -1, 2}, radius = 1.5;
  for (int r = 0; r <= 6; r++) {
    gm_trisurf s;
    const double t0 = surf_now();
    assert_ok(gm_trisurf_sphere(c, radius, r, &s));
    const double dt = surf_now() - t0;
    const long n4 = 1L << (2 * r);
    assert_int_equal(s.n_points, 10 * n4 + 2);
    assert_int_equal(s.n_tris, 20 * n4);
    for (long p = 0; p < s.n_points; p++) {
      const double d[3] = {s.x[3 * p] - c[0], s.x[3 * p + 1] - c[1],
                           s.x[3 * p + 2] - c[2]};
      assert_close(pm_v_norm(d), radius, 1e-14, 0);
    }
    surf_expect_closed(&s);
    assert_true(gm_trisurf_volume(&s) > 0.0);
    assert_true(surf_nearest_plane(&s, c) > 0.0); /* every normal outward */
    if (r == 6) {
      print_message("  icosphere r = 6: %ld points, %ld triangles in %.1f "
                    "ms\n",
                    s.n_points, s.n_tris, 1e3 * dt);
      /* About 10 ms; the bound leaves room for a sanitizer or valgrind. */
      assert_true(dt < 1.0);
    }
    gm_trisurf_free(&s);
  }
  gm_trisurf s;
  assert_fails(gm_trisurf_sphere(c, 0.0, 2, &s), PM_ERR_ARG, "radius > 0");
  assert_fails(gm_trisurf_sphere(c, 1.0, 10, &s), PM_ERR_ARG, "[0, 9]");
  assert_fails(gm_trisurf_sphere(c, 1.0, -1, &s), PM_ERR_ARG, "[0, 9]");
}

/* Area and volume at r = 6 against the sphere's.  The icosphere is
 * inscribed (points on the sphere) and star-shaped about the centre, each
 * face's plane at a distance d_f in [d, R] (d = the nearest), so it lies
 * between the balls of radii d and R: V in [4/3 pi d^3, 4/3 pi R^3]; and
 * V = sum A_f d_f / 3 gives A in [3 V / R, 3 V / d].  With eps = 1 - d / R
 * both relative errors are within 3 eps ((1 - eps)^3 >= 1 - 3 eps, and
 * 1 / (1 - eps) <= 1 + 3 eps for eps <= 2/3).  At r = 6, eps = 7.1e-5:
 * the errors are below 2.2e-4 (they are 7.5e-5 for the area and 1.35e-4
 * for the volume). */
static void test_sphere_measures(void **state) {
  (void)state;
  const double *c = origin, R = 2.0;
  gm_trisurf s = surf_sphere(c, R, 6);
  const double d = surf_nearest_plane(&s, c), eps = 1.0 - d / R;
  const double A = total_area(&s), V = gm_trisurf_volume(&s);
  const double A0 = 4.0 * PI * R * R, V0 = 4.0 / 3.0 * PI * R * R * R;
  print_message("  r = 6: 1 - d/R = %.3e; area error %.3e, volume error "
                "%.3e (bound 3 eps = %.3e)\n",
                eps, 1.0 - A / A0, 1.0 - V / V0, 3.0 * eps);
  assert_true(eps > 0.0 && 3.0 * eps < 2.2e-4);
  const double vlo = 4.0 / 3.0 * PI * d * d * d, rounding = 1e-12 * V0;
  assert_true(V >= vlo - rounding && V <= V0 + rounding);
  assert_true(A >= 3.0 * V / R - 1e-12 * A0 && A <= 3.0 * V / d + 1e-12 * A0);
  assert_true(fabs(1.0 - V / V0) <= 3.0 * eps);
  assert_true(fabs(1.0 - A / A0) <= 3.0 * eps);
  /* Areas per point: a third of each triangle's, summing to the total. */
  assert_close(point_area_sum(&s), A, 1e-12, 0);
  gm_trisurf_free(&s);
}

static void test_incidence(void **state) {
  (void)state;
  gm_trisurf s = surf_sphere(origin, 1.0, 3);
  long *start = NULL, *tris = NULL;
  assert_ok(gm_trisurf_incidence(&s, &start, &tris));
  assert_int_equal(start[0], 0);
  assert_int_equal(start[s.n_points], 3 * s.n_tris);
  long fives = 0;
  for (long p = 0; p < s.n_points; p++) {
    const long n = start[p + 1] - start[p];
    assert_true(n == 5 || n == 6);
    fives += n == 5;
    for (long k = start[p]; k < start[p + 1]; k++) {
      if (k > start[p]) assert_true(tris[k] > tris[k - 1]);
      const long *v = s.tri + 3 * tris[k];
      assert_true(v[0] == p || v[1] == p || v[2] == p);
    }
  }
  assert_int_equal(fives, 12); /* the icosahedron's own points */
  free(start);
  free(tris);
  gm_trisurf_free(&s);
}

/* orient_outward, and each reason a surface is not closed. */
static void test_orientation(void **state) {
  (void)state;
  const double c[3] = {1, 1, 1};
  gm_trisurf s = surf_sphere(c, 1.0, 2);
  const double v = gm_trisurf_volume(&s);
  for (long t = 0; t < s.n_tris; t++) {
    const long b = s.tri[3 * t + 1];
    s.tri[3 * t + 1] = s.tri[3 * t + 2];
    s.tri[3 * t + 2] = b;
  }
  surf_expect_closed(&s); /* reversed, but consistently */
  assert_close(gm_trisurf_volume(&s), -v, 1e-14, 0);
  gm_trisurf_orient_outward(&s);
  assert_close(gm_trisurf_volume(&s), v, 1e-14, 0);
  gm_trisurf_orient_outward(&s); /* already outward: unchanged */
  assert_close(gm_trisurf_volume(&s), v, 1e-14, 0);
  assert_true(surf_nearest_plane(&s, c) > 0.0);

  /* One triangle turned over. */
  long keep[3];
  memcpy(keep, s.tri + 15, sizeof keep);
  s.tri[16] = keep[2];
  s.tri[17] = keep[1];
  expect_open(&s, "inconsistent orientation");
  expect_open(&s, "triangles");
  memcpy(s.tri + 15, keep, sizeof keep);
  surf_expect_closed(&s);
  /* The last triangle dropped: a hole. */
  s.n_tris--;
  expect_open(&s, "belongs to 1 triangle");
  /* A copy of the first one added: three triangles on its edges. */
  s.n_tris++;
  long *grown = realloc(s.tri, sizeof *s.tri * 3 * (size_t)(s.n_tris + 1));
  assert_non_null(grown);
  s.tri = grown;
  memcpy(s.tri + 3 * s.n_tris, s.tri, 3 * sizeof *s.tri);
  s.n_tris++;
  expect_open(&s, "belongs to 3 triangles");
  s.tri[4] = s.n_points;
  expect_open(&s, "refers to point");
  s.tri[4] = s.tri[3];
  expect_open(&s, "lists point");
  gm_trisurf_free(&s);
  expect_open(&s, "no triangle");
}

/* ---- files -------------------------------------------------------------- */

static void test_load_stl(void **state) {
  char path[512];
  surf_write_cube_stl(*state, path);
  gm_trisurf s;
  assert_ok(gm_trisurf_load(path, &s));
  assert_int_equal(s.n_points, 8);
  assert_int_equal(s.n_tris, 12);
  surf_expect_closed(&s);
  assert_close(gm_trisurf_volume(&s), 1.0, 1e-14, 0);
  assert_close(total_area(&s), 6.0, 1e-14, 0);
  double lo[3], hi[3];
  gm_trisurf_bounds(&s, lo, hi);
  for (int k = 0; k < 3; k++) assert_true(lo[k] == 0 && hi[k] == 1);
  gm_trisurf_free(&s);
}

/* An open unit square at z = 0.25 in gmsh's 2.2 format, of a quadrangle
 * (1 2 5 4), a triangle through node 11 (node 2 again, 1e-13 away), a
 * 6-node triangle (2 6 5, midside nodes 7-9), a flat triangle (1 2 3) and
 * a line; node 10 is unused.  The 6-node triangle has a surface of its
 * own: gmsh's API takes one order of triangles per surface. */
static const char square_msh[] = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                                 "$Nodes\n11\n"
                                 "1 0 0 0.25\n2 0.5 0 0.25\n3 1 0 0.25\n"
                                 "4 0 1 0.25\n5 0.5 1 0.25\n6 1 1 0.25\n"
                                 "7 0.75 0.5 0.25\n8 0.75 1 0.25\n"
                                 "9 0.5 0.5 0.25\n10 3 3 3\n"
                                 "11 0.5000000000001 0 0.25\n"
                                 "$EndNodes\n$Elements\n5\n"
                                 "1 3 2 1 1 1 2 5 4\n"
                                 "2 2 2 1 1 11 3 6\n"
                                 "3 9 2 1 2 2 6 5 7 8 9\n"
                                 "4 2 2 1 1 1 2 3\n"
                                 "5 1 2 1 1 1 3\n"
                                 "$EndElements\n";

static void test_load_msh(void **state) {
  char path[512];
  pm_test_write_file(*state, "square.msh", square_msh, path);
  gm_trisurf s;
  assert_ok(gm_trisurf_load(path, &s));
  /* Nodes 1-6: 11 merged into 2, 7-10 no corner of a kept triangle. */
  assert_int_equal(s.n_points, 6);
  assert_int_equal(s.n_tris, 4);
  assert_close(total_area(&s), 1.0, 1e-14, 0);
  for (long t = 0; t < s.n_tris; t++) {
    double n[3];
    surf_area_vector(&s, t, n);
    assert_true(n[2] > 0 && fabs(n[0]) + fabs(n[1]) < 1e-12);
  }
  for (long p = 0; p < s.n_points; p++) assert_true(s.x[3 * p + 2] == 0.25);
  expect_open(&s, "hole");
  gm_trisurf_free(&s);

  /* The 6-node triangle on surface 1 with the others: gmsh 4.8's
   * getElementsByType wrote past its array there (caught by valgrind and
   * the sanitizers); getElements lists the surface's first order alone. */
  char mixed[sizeof square_msh];
  memcpy(mixed, square_msh, sizeof mixed);
  char *p2 = strstr(mixed, "3 9 2 1 2 ");
  assert_non_null(p2);
  p2[8] = '1';
  pm_test_write_file(*state, "mixed.msh", mixed, path);
  assert_ok(gm_trisurf_load(path, &s));
  assert_true(s.n_tris == 3 || s.n_tris == 4);
  gm_trisurf_free(&s);
}

static void test_load_errors(void **state) {
  char path[512], missing[600];
  gm_trisurf s;
  snprintf(missing, sizeof missing, "%s/none.stl", (char *)*state);
  assert_fails(gm_trisurf_load(missing, &s), PM_ERR_IO, missing);
  assert_null(s.x);
  assert_fails(gm_trisurf_load(*state, &s), PM_ERR_IO, "is a directory");
  pm_test_write_file(*state, "lines.msh",
                     "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                     "$Nodes\n2\n1 0 0 0\n2 1 0 0\n$EndNodes\n"
                     "$Elements\n1\n1 1 2 1 1 1 2\n$EndElements\n",
                     path);
  assert_fails(gm_trisurf_load(path, &s), PM_ERR_MESH, path);
  assert_fails(gm_trisurf_load(path, &s), PM_ERR_MESH, "no surface element");
  assert_null(s.x);
}

int main(void) {
  gmsh_testing_preload();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_rectangle),
      cmocka_unit_test(test_sphere_counts),
      cmocka_unit_test(test_sphere_measures),
      cmocka_unit_test(test_incidence),
      cmocka_unit_test(test_orientation),
      cmocka_unit_test_setup_teardown(test_load_stl, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_load_msh, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_load_errors, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
