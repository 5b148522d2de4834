/* test_volume: point-in-solid queries on volumes read from small .geo and
 * .msh files written at test time: membership, measure, bounds, and the
 * errors of the gmsh file reader it shares with gm_mesh_file. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm_testing.h"

#include <gmshc.h>

#include "gm_dual.h"
#include "gm_gmsh.h"
#include "gm_volume.h"
#include "pm_omp.h"

#define PI 3.14159265358979323846

/* Fraction of n uniform points of [lo, hi] that the volume contains, the
 * points drawn up front and queried in a parallel loop (the queries are
 * read-only). */
static double hit_fraction(const gm_volume *v, const double lo[3],
                           const double hi[3], long n, uint64_t seed) {
  double *x = malloc(sizeof *x * 3 * (size_t)n);
  assert_non_null(x);
  for (long i = 0; i < 3 * n; i++)
    x[i] = lo[i % 3] + (hi[i % 3] - lo[i % 3]) * pm_test_uniform(&seed);
  long hits = 0;
  PM_OMP(parallel for default(none) shared(v, x, n) reduction(+ : hits))
  for (long i = 0; i < n; i++) hits += gm_volume_contains(v, x + 3 * i);
  free(x);
  return (double)hits / (double)n;
}

/* The statistical check: the hit fraction of N points estimates
 * measure / box with standard deviation sqrt(p (1 - p) / N); allow 5 of
 * them (a false failure about once in 2 million runs, and the seed is
 * fixed anyway). */
static void check_hit_fraction(const gm_volume *v, const double lo[3],
                               const double hi[3], int dim) {
  const long n = 100000;
  double box = 1.0;
  for (int k = 0; k < dim; k++) box *= hi[k] - lo[k];
  double p = gm_volume_measure(v) / box;
  double f = hit_fraction(v, lo, hi, n, 12345);
  double sigma = sqrt(p * (1.0 - p) / (double)n);
  print_message("  %ld random points: hit fraction %.5f, measure/box %.5f "
                "(%.2f sigma)\n",
                n, f, p, fabs(f - p) / sigma);
  assert_true(fabs(f - p) <= 5.0 * sigma);
}

static const char sphere_geo[] = "SetFactory(\"OpenCASCADE\");\n"
                                 "Sphere(1) = {0, 0, 0, 0.5};\n";

/* Sphere of radius r = 0.5 at h = 0.08.  The mesh is inscribed (surface
 * nodes on the sphere), so it lies inside the sphere and its volume falls
 * short by about area * mean chord gap: the gap of a surface triangle of
 * size h is ~ h^2 / (8 r), so the relative deficit is ~ 3 h^2 / (8 r^2)
 * = 0.0096 here; we allow 2 h^2 / r^2 = 0.051 and check the sign. */
static void test_sphere(void **state) {
  const double r = 0.5, h = 0.08;
  char path[512];
  pm_test_write_file(*state, "sphere.geo", sphere_geo, path);
  char cwd[1024], cwd2[1024];
  assert_non_null(getcwd(cwd, sizeof cwd));
  gm_volume *v = NULL;
  assert_ok(gm_volume_load(path, 3, h, GM_SIZES_REPLACE, &v));
  assert_non_null(getcwd(cwd2, sizeof cwd2));
  assert_string_equal(cwd, cwd2); /* gmsh left the working directory */
  assert_int_equal(gm_volume_dim(v), 3);

  const double exact = 4.0 / 3.0 * PI * r * r * r;
  double m = gm_volume_measure(v), rel = (exact - m) / exact;
  double lo[3], hi[3];
  gm_volume_bounds(v, lo, hi);
  print_message("  sphere h=%g: %ld tetrahedra, volume %.6f (exact %.6f, "
                "deficit %.2e), bounds [%.4f %.4f %.4f] [%.4f %.4f %.4f]\n",
                h, gm_volume_elements(v), m, exact, rel, lo[0], lo[1], lo[2],
                hi[0], hi[1], hi[2]);
  assert_true(gm_volume_elements(v) > 1000);
  assert_true(rel > 0.0 && rel < 2.0 * h * h / (r * r));
  /* Bounds: inside the sphere, and within a chord gap (h^2 / r) of it. */
  for (int k = 0; k < 3; k++) {
    assert_true(lo[k] >= -r * (1 + 1e-9) && lo[k] < -r + h * h / r);
    assert_true(hi[k] <= r * (1 + 1e-9) && hi[k] > r - h * h / r);
  }

  /* Random points: inside a ball of radius r - h (the chord gaps are far
   * smaller) always in, outside the sphere always out. */
  uint64_t seed = 7;
  long in = 0, out = 0;
  for (int i = 0; i < 20000; i++) {
    double x[3], d = 0.0;
    for (int k = 0; k < 3; k++) {
      x[k] = 0.6 * (2.0 * pm_test_uniform(&seed) - 1.0);
      d += x[k] * x[k];
    }
    d = sqrt(d);
    if (d < r - h) {
      assert_true(gm_volume_contains(v, x));
      in++;
    } else if (d > r * (1 + 1e-9)) {
      assert_false(gm_volume_contains(v, x));
      out++;
    }
  }
  assert_true(in > 1000 && out > 1000);
  const double centre[3] = {0, 0, 0}, far[3] = {0, 0, 10};
  const double bad[3] = {NAN, 0, 0}, inf[3] = {INFINITY, 0, 0};
  assert_true(gm_volume_contains(v, centre));
  assert_false(gm_volume_contains(v, far));
  assert_false(gm_volume_contains(v, bad));
  assert_false(gm_volume_contains(v, inf));
  assert_false(gm_volume_contains(NULL, centre));

  const double blo[3] = {-r, -r, -r}, bhi[3] = {r, r, r};
  check_hit_fraction(v, blo, bhi, 3);
  gm_volume_destroy(v);

  /* h <= 0: gmsh's own sizes (coarser here), still an inscribed mesh. */
  assert_ok(gm_volume_load(path, 3, 0.0, GM_SIZES_REPLACE, &v));
  m = gm_volume_measure(v);
  print_message("  sphere, gmsh default size: %ld tetrahedra, volume %.6f\n",
                gm_volume_elements(v), m);
  assert_true(gm_volume_elements(v) > 0);
  assert_true(m < exact && m > 0.5 * exact);
  gm_volume_destroy(v);
}

/* A polyhedron is meshed exactly: volume and bounds to round-off, and
 * every point of a lattice that includes the boundary, the edges and the
 * corners is inside (points on faces shared by two tetrahedra must not slip
 * through), while points 1e-7 outside a face are not. */
static void test_box(void **state) {
  char path[512];
  pm_test_write_file(*state, "box.geo",
                     "SetFactory(\"OpenCASCADE\");\n"
                     "Box(1) = {-1, 0, 2, 2, 1, 0.5};\n",
                     path);
  const double lo[3] = {-1, 0, 2}, hi[3] = {1, 1, 2.5};
  gm_volume *v = NULL;
  assert_ok(gm_volume_load(path, 3, 0.2, GM_SIZES_REPLACE, &v));
  double blo[3], bhi[3];
  gm_volume_bounds(v, blo, bhi);
  double m = gm_volume_measure(v);
  print_message("  box h=0.2: %ld tetrahedra, volume %.15f (exact 1)\n",
                gm_volume_elements(v), m);
  assert_true(fabs(m - 1.0) <= 1e-12);
  for (int k = 0; k < 3; k++) {
    assert_true(fabs(blo[k] - lo[k]) <= 1e-12);
    assert_true(fabs(bhi[k] - hi[k]) <= 1e-12);
  }
  const int n = 20;
  long checked = 0;
  for (int i = 0; i <= n; i++)
    for (int j = 0; j <= n; j++)
      for (int k = 0; k <= n; k++) {
        const int ijk[3] = {i, j, k};
        double x[3];
        for (int a = 0; a < 3; a++) x[a] = lo[a] + (hi[a] - lo[a]) * ijk[a] / n;
        assert_true(gm_volume_contains(v, x));
        /* Pushed out through each face the point is on. */
        for (int a = 0; a < 3; a++) {
          if (ijk[a] != 0 && ijk[a] != n) continue;
          double y[3] = {x[0], x[1], x[2]};
          y[a] += (ijk[a] == 0 ? -1e-7 : 1e-7);
          assert_false(gm_volume_contains(v, y));
          checked++;
        }
      }
  assert_true(checked > 6 * n * n);
  check_hit_fraction(v, (const double[3]){-1.5, -0.5, 1.5},
                     (const double[3]){1.5, 1.5, 3.0}, 3);
  gm_volume_destroy(v);
}

/* Disk of radius 0.5 in the z = 0 plane at h = 0.05: an inscribed polygon,
 * whose area falls short by the circular segments, 2 pi r h^2 / (12 r) in
 * all, a relative h^2 / (6 r^2) = 0.0017 for edges of length h; we allow
 * h^2 / r^2 = 0.01 and check the sign. */
static void test_disk_2d(void **state) {
  const double r = 0.5, h = 0.05;
  char path[512];
  pm_test_write_file(*state, "disk.geo",
                     "SetFactory(\"OpenCASCADE\");\n"
                     "Disk(1) = {0, 0, 0, 0.5};\n",
                     path);
  gm_volume *v = NULL;
  assert_ok(gm_volume_load(path, 2, h, GM_SIZES_REPLACE, &v));
  assert_int_equal(gm_volume_dim(v), 2);
  const double exact = PI * r * r;
  double m = gm_volume_measure(v), rel = (exact - m) / exact;
  double lo[3], hi[3];
  gm_volume_bounds(v, lo, hi);
  print_message("  disk h=%g: %ld triangles, area %.6f (exact %.6f, deficit "
                "%.2e)\n",
                h, gm_volume_elements(v), m, exact, rel);
  assert_true(rel > 0.0 && rel < h * h / (r * r));
  for (int k = 0; k < 2; k++) {
    assert_true(lo[k] >= -r * (1 + 1e-9) && lo[k] < -r + h * h / r);
    assert_true(hi[k] <= r * (1 + 1e-9) && hi[k] > r - h * h / r);
  }
  assert_true(lo[2] == 0.0 && hi[2] == 0.0);
  /* z is ignored in 2D. */
  const double a[3] = {0.3, -0.2, 5.0}, b[3] = {0.4, 0.4, 0.0};
  const double c[3] = {0.0, 0.5 - h, -1.0}, d[3] = {0.0, 0.5 + 1e-6, 0.0};
  assert_true(gm_volume_contains(v, a));
  assert_false(gm_volume_contains(v, b)); /* |b| = 0.566 */
  assert_true(gm_volume_contains(v, c));
  assert_false(gm_volume_contains(v, d));
  check_hit_fraction(v, (const double[3]){-r, -r, 0},
                     (const double[3]){r, r, 0}, 2);
  gm_volume_destroy(v);
}

/* A .msh with one linear and one quadratic tetrahedron (its edge nodes
 * moved off the edges: only the corners count), used as it is whatever h. */
static void test_msh_tetrahedra(void **state) {
  char path[512];
  pm_test_write_file(*state, "tets.msh",
                     "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                     "$Nodes\n14\n"
                     "1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"
                     "11 10 0 0\n12 11 0 0\n13 10 1 0\n14 10 0 1\n"
                     "15 10.5 0 0.3\n16 10.6 0.6 0\n17 10 0.5 0\n"
                     "18 10 0 0.5\n19 10.5 0 0.5\n20 10 0.5 0.5\n"
                     "$EndNodes\n"
                     "$Elements\n2\n"
                     "1 4 2 1 1 1 3 2 4\n"
                     "2 11 2 2 2 11 12 13 14 15 16 17 18 19 20\n"
                     "$EndElements\n",
                     path);
  gm_volume *v = NULL;
  assert_ok(gm_volume_load(path, 3, 0.01, GM_SIZES_REPLACE, &v));
  assert_int_equal(gm_volume_elements(v), 2);
  assert_true(fabs(gm_volume_measure(v) - 2.0 / 6.0) <= 1e-15);
  double lo[3], hi[3];
  gm_volume_bounds(v, lo, hi);
  assert_true(lo[0] == 0 && lo[1] == 0 && lo[2] == 0);
  assert_true(hi[0] == 11 && hi[1] == 1 && hi[2] == 1);
  const double in[][3] = {{0, 0, 0},
                          {1, 0, 0},
                          {0.25, 0.25, 0.25},
                          {0.5, 0.5, 0},
                          {1. / 3, 1. / 3, 1. / 3},
                          {10, 0, 0},
                          {10.2, 0.2, 0.2}};
  const double out[][3] = {{0.5, 0.5, 0.1},   {-1e-9, 0.5, 0.1},
                           {0.4, 0.4, 0.21},  {5, 0.1, 0.1},
                           {10.55, 0.5, 0.0}, {9.999, 0.1, 0.1}};
  for (size_t i = 0; i < sizeof in / sizeof in[0]; i++)
    assert_true(gm_volume_contains(v, in[i]));
  for (size_t i = 0; i < sizeof out / sizeof out[0]; i++)
    assert_false(gm_volume_contains(v, out[i]));
  gm_volume_destroy(v);
}

/* CAD files: a unit box and a ball of radius 0.5 around (3, 0, 0), written
 * as .brep and .step with gmsh's OpenCASCADE kernel, read back and meshed
 * at h = 0.1.  Volume: exact for the box, the ball short by its chord
 * deficit (< 2 h^2 / r^2 as in test_sphere). */
static void test_cad_files(void **state) {
  const char *names[2] = {"shapes.brep", "shapes.step"};
  char path[2][512];
  int ierr = 0;
  gmshInitialize(0, NULL, 0, &ierr);
  assert_int_equal(ierr, 0);
  gmshOptionSetNumber("General.Terminal", 0, &ierr);
  gmshModelAdd("shapes", &ierr);
  gmshModelOccAddBox(0, 0, 0, 1, 1, 1, -1, &ierr);
  gmshModelOccAddSphere(3, 0, 0, 0.5, -1, -PI / 2, PI / 2, 2 * PI, &ierr);
  gmshModelOccSynchronize(&ierr);
  /* OpenCASCADE prints a banner on stdout when it writes STEP. */
  fflush(stdout);
  int saved = dup(STDOUT_FILENO), null = open("/dev/null", O_WRONLY);
  assert_true(saved >= 0 && null >= 0);
  dup2(null, STDOUT_FILENO);
  for (int i = 0; i < 2 && ierr == 0; i++) {
    snprintf(path[i], sizeof path[i], "%s/%s", (char *)*state, names[i]);
    gmshWrite(path[i], &ierr);
  }
  fflush(stdout);
  dup2(saved, STDOUT_FILENO);
  close(saved);
  close(null);
  assert_int_equal(ierr, 0);
  gmshFinalize(&ierr);
  const double r = 0.5, h = 0.1, ball = 4.0 / 3.0 * PI * r * r * r;
  for (int i = 0; i < 2; i++) {
    gm_volume *v = NULL;
    assert_ok(gm_volume_load(path[i], 3, h, GM_SIZES_REPLACE, &v));
    double m = gm_volume_measure(v), rel = (1.0 + ball - m) / ball;
    print_message("  %s: %ld tetrahedra, volume %.6f (box + ball %.6f, ball "
                  "deficit %.2e)\n",
                  names[i], gm_volume_elements(v), m, 1.0 + ball, rel);
    assert_true(rel > 0.0 && rel < 2.0 * h * h / (r * r));
    double lo[3], hi[3];
    gm_volume_bounds(v, lo, hi);
    assert_true(fabs(lo[0]) < 1e-9 && hi[0] <= 3.5 * (1 + 1e-9));
    const double in[][3] = {{0.5, 0.5, 0.5}, {1, 1, 1}, {3, 0, 0}, {3, 0.3, 0}};
    const double out[][3] = {{2, 0.5, 0.5}, {3, 0.5, 0.5}, {1.5, 0, 0}};
    for (int k = 0; k < 4; k++) assert_true(gm_volume_contains(v, in[k]));
    for (int k = 0; k < 3; k++) assert_false(gm_volume_contains(v, out[k]));
    gm_volume_destroy(v);
  }
}

/* Both readers of gmsh files, gm_volume_load and gm_mesh_file, fail on
 * path (dimension dim, size h) with code, no result and a message that
 * names the file and holds what. */
static void expect_failure(const char *path, int dim, double h, pm_err code,
                           const char *what) {
  gm_volume *v = (gm_volume *)0x1;
  gm_mesh *m = (gm_mesh *)0x1;
  assert_int_equal(gm_volume_load(path, dim, h, GM_SIZES_REPLACE, &v), code);
  assert_null(v);
  print_message("  %s\n", pm_error_message());
  assert_non_null(strstr(pm_error_message(), what));
  if (path) assert_non_null(strstr(pm_error_message(), path));
  assert_int_equal(gm_mesh_file(path, dim, h, GM_SIZES_REPLACE, &m), code);
  assert_null(m);
  assert_non_null(strstr(pm_error_message(), what));
  if (path) assert_non_null(strstr(pm_error_message(), path));
}

/* The error paths. */
static void test_errors(void **state) {
  char path[512], missing[512];
  gm_volume *v = (gm_volume *)0x1;
  snprintf(missing, sizeof missing, "%s/no_such_file.geo", (char *)*state);
  expect_failure(missing, 3, 0.1, PM_ERR_IO, "No such file");
  expect_failure(*state, 3, 0.1, PM_ERR_IO, "directory");

  /* A 2D disk asked for as a 3D solid: gmsh makes no tetrahedra. */
  pm_test_write_file(
      *state, "disk.geo",
      "SetFactory(\"OpenCASCADE\");\nDisk(1) = {0, 0, 0, 0.5};\n", path);
  expect_failure(path, 3, 0.1, PM_ERR_MESH, "no tetrahedra");
  /* A .msh holding only a triangle. */
  pm_test_write_file(*state, "tri.msh",
                     "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                     "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"
                     "$Elements\n1\n1 2 2 1 1 1 2 3\n$EndElements\n",
                     path);
  expect_failure(path, 3, 0.1, PM_ERR_MESH, "no tetrahedra");
  /* The node count its header states, read without gmsh (plan's points):
   * 2.2 as above, 4.1 (blocks, nodes, tags), binary 4.1 and no file. */
  assert_int_equal(gm_msh_node_count(path), 3);
  char v4[512];
  pm_test_write_file(*state, "v4.msh",
                     "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n"
                     "0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities\n"
                     "$Nodes\n2 1201 1 1201\n",
                     v4);
  assert_int_equal(gm_msh_node_count(v4), 1201);
  pm_test_write_file(*state, "v4b.msh",
                     "$MeshFormat\n4.1 1 8\n\x01\n$EndMeshFormat\n$Nodes\n",
                     v4);
  assert_int_equal(gm_msh_node_count(v4), -1);
  assert_int_equal(gm_msh_node_count(missing), -1);
  /* ... which is fine in 2D. */
  assert_ok(gm_volume_load(path, 2, 0.1, GM_SIZES_REPLACE, &v));
  assert_true(fabs(gm_volume_measure(v) - 0.5) <= 1e-15);
  gm_volume_destroy(v);
  /* A syntax error: gmsh's own message is quoted. */
  pm_test_write_file(
      *state, "bad.geo",
      "SetFactory(\"OpenCASCADE\");\nSphere(1) = {0, 0, 0, 0.5;\n", path);
  expect_failure(path, 3, 0.1, PM_ERR_MESH, "syntax error");
  /* A 3D solid asked for in 2D: its surface triangles leave z = 0. */
  pm_test_write_file(*state, "sphere.geo", sphere_geo, path);
  expect_failure(path, 2, 0.2, PM_ERR_MESH, "z = 0");
  /* Hexahedra are not simplices. */
  pm_test_write_file(*state, "hex.msh",
                     "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                     "$Nodes\n8\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n"
                     "5 0 0 1\n6 1 0 1\n7 1 1 1\n8 0 1 1\n$EndNodes\n"
                     "$Elements\n1\n1 5 2 1 1 1 2 3 4 5 6 7 8\n$EndElements\n",
                     path);
  expect_failure(path, 3, 0.1, PM_ERR_UNSUPPORTED, "Hexahedron");
  /* gmsh scripts that would start a program are refused before gmsh runs
   * them (each would create the file "ran"), also through an Include; a
   * command's name in a comment or a string is not a call; an Include
   * named by an expression cannot be followed. */
  char ran[512];
  snprintf(ran, sizeof ran, "%s/ran", (char *)*state);
  pm_test_write_file(*state, "call.geo",
                     "// SystemCall \"touch ran\";\nPrintf(\"OnelabRun\");\n"
                     "SetFactory(\"OpenCASCADE\");\nSphere(1) = {0, 0, 0, 1};\n"
                     "SystemCall \"touch ran\";\n",
                     path);
  expect_failure(path, 3, 0.5, PM_ERR_MESH,
                 "call.geo:5: the gmsh script "
                 "calls SystemCall");
  pm_test_write_file(*state, "onelab.geo", "OnelabRun(\"x\", \"touch ran\");\n",
                     path);
  expect_failure(path, 3, 0.5, PM_ERR_MESH, "calls OnelabRun");
  pm_test_write_file(*state, "outer.geo", "Include \"call.geo\";\n", path);
  expect_failure(path, 3, 0.5, PM_ERR_MESH, "calls SystemCall");
  pm_test_write_file(*state, "expr.geo",
                     "Include StrCat(\"ca\", \"ll.geo\");\n", path);
  expect_failure(path, 3, 0.5, PM_ERR_MESH, "not named by a plain string");
  assert_int_equal(access(ran, F_OK), -1);
  /* Arguments. */
  expect_failure(path, 4, 0.1, PM_ERR_ARG, "2 or 3");
  expect_failure(path, 3, NAN, PM_ERR_ARG, "finite");
  expect_failure(NULL, 3, 0.1, PM_ERR_ARG, "no volume file name");
  assert_int_equal(gm_volume_load(path, 3, 0.1, GM_SIZES_REPLACE, NULL),
                   PM_ERR_ARG);
  gm_volume_destroy(NULL);
  pm_error_clear();
}

/* gm_volume_load and gm_mesh_box each open and close gmsh: they must work
 * in any order, with gm_volume_load's size not leaking into gm_mesh_box,
 * and the OpenMP thread count must survive. */
static void test_gmsh_state(void **state) {
  char path[512];
  pm_test_write_file(*state, "sphere.geo", sphere_geo, path);
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  gm_mesh *m1 = NULL, *m2 = NULL;
  gm_volume *v1 = NULL, *v2 = NULL;
  /* Two threads, not the unit tests' one: gmsh's own setting of one
   * thread would go unseen against a caller's one. */
  const int before = pm_omp_threads();
  pm_omp_set_threads(2);
  int threads = pm_omp_threads();
  assert_ok(gm_mesh_box(3, lo, hi, 0.25, &m1));
  assert_ok(gm_volume_load(path, 3, 0.1, GM_SIZES_REPLACE, &v1));
  assert_ok(gm_mesh_box(3, lo, hi, 0.25, &m2));
  assert_ok(gm_volume_load(path, 3, 0.1, GM_SIZES_REPLACE, &v2));
  assert_int_equal(pm_omp_threads(), threads);
  pm_omp_set_threads(before);
  assert_int_equal(m1->n_cells, m2->n_cells);
  assert_int_equal(gm_volume_elements(v1), gm_volume_elements(v2));
  assert_true(gm_volume_measure(v1) == gm_volume_measure(v2));
  gm_volume_destroy(v1);
  gm_volume_destroy(v2);
  gm_mesh_destroy(m1);
  gm_mesh_destroy(m2);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_sphere, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_box, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_disk_2d, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_msh_tetrahedra, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_cad_files, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_errors, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_gmsh_state, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
