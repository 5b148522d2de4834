/* test_surfaces: named boundary surfaces of meshes: the faces of a box, the
 * physical groups of a gmsh file matched to boundary faces by their nodes,
 * the facets of the dual on them, lookup by name, and the errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm_testing.h"

#include "gm_dual.h"
#include "gmsh_testing.h"

#define PI 3.14159265358979323846
#define DATA PM_TEST_DATA "/geometry/"

/* Per surface of d's mesh: the sum of its facets' area vectors and areas,
 * and how many facets it has (index n_surfaces: facets on none). */
typedef struct {
  double vec[8][3], area[8];
  long count[8];
} surface_sums;

static void sum_surfaces(const gm_mesh *m, const gm_dual *d, surface_sums *s) {
  assert_true(m->n_surfaces < 8);
  memset(s, 0, sizeof *s);
  for (long f = 0; f < d->n_facets; f++) {
    int k = d->facet_surface[f];
    assert_true(k >= -1 && k < m->n_surfaces);
    if (k < 0) k = m->n_surfaces;
    for (int a = 0; a < 3; a++) s->vec[k][a] += d->facet_area_vec[3 * f + a];
    s->area[k] += d->facet_area[f];
    s->count[k]++;
  }
}

/* Surface s of m sums to area vector a (to 1e-12 of |a|) and every facet on
 * it is parallel to a (a plane face, normal outward). */
static void check_plane_surface(const gm_mesh *m, const gm_dual *d,
                                const char *name, const double a[3]) {
  int s = gm_mesh_surface_find(m, name);
  assert_true(s >= 0);
  surface_sums sums;
  sum_surfaces(m, d, &sums);
  double area = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  print_message("  %-10s %5ld facets, area vector (%.3g, %.3g, %.3g)\n", name,
                sums.count[s], sums.vec[s][0], sums.vec[s][1], sums.vec[s][2]);
  assert_true(sums.count[s] > 0);
  for (int k = 0; k < 3; k++)
    assert_true(fabs(sums.vec[s][k] - a[k]) <= 1e-12 * area);
  assert_true(fabs(sums.area[s] - area) <= 1e-12 * area);
  for (long f = 0; f < d->n_facets; f++) {
    if (d->facet_surface[f] != s) continue;
    const double *af = d->facet_area_vec + 3 * f;
    double dot = (af[0] * a[0] + af[1] * a[1] + af[2] * a[2]) / area;
    assert_true(fabs(dot - d->facet_area[f]) <= 1e-12 * d->facet_area[f]);
  }
}

static void test_box_names(void **state) {
  (void)state;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 2, 3};
  char buf[128];
  for (int dim = 2; dim <= 3; dim++) {
    gm_mesh *m = NULL;
    assert_ok(gm_mesh_box(dim, lo, hi, 0.5, &m));
    assert_int_equal(m->n_surfaces, 2 * dim);
    for (int f = 0; f < 2 * dim; f++) {
      assert_string_equal(gm_mesh_surface_name(m, f), pm_face_name(f));
      assert_int_equal(gm_mesh_surface_find(m, pm_face_name(f)), f);
    }
    assert_int_equal(gm_mesh_surface_find(m, "top"), -1);
    assert_int_equal(gm_mesh_surface_find(m, "zmax"),
                     dim == 3 ? PM_FACE_ZMAX : -1);
    assert_null(gm_mesh_surface_name(m, 2 * dim));
    assert_null(gm_mesh_surface_name(m, -1));
    assert_string_equal(gm_mesh_surface_list(m, buf, sizeof buf),
                        dim == 3 ? "xmin, xmax, ymin, ymax, zmin, zmax"
                                 : "xmin, xmax, ymin, ymax");
    /* Too small a buffer: cut, with "..." to say so. */
    assert_string_equal(gm_mesh_surface_list(m, buf, 12), "xmin, xm...");
    gm_mesh_destroy(m);
  }
  assert_int_equal(gm_mesh_surface_find(NULL, "xmin"), -1);
  assert_string_equal(gm_mesh_surface_list(NULL, buf, sizeof buf), "(none)");
}

/* The block's whole boundary is in groups: every facet has a surface, and
 * each surface's area vectors add up to its faces'. */
static void test_block_file(void **state) {
  (void)state;
  gm_mesh *m = NULL;
  gm_dual *d = NULL;
  char buf[128];
  assert_ok(gm_mesh_file(DATA "block.geo", 3, 0.02, GM_SIZES_REPLACE, &m));
  assert_ok(gm_dual_build(m, &d));
  print_message("  block.geo: %ld nodes, %ld cells, surfaces %s\n", m->n_nodes,
                m->n_cells, gm_mesh_surface_list(m, buf, sizeof buf));
  assert_int_equal(m->n_surfaces, 4);
  assert_string_equal(buf, "bottom, top, sides, surface-17");
  for (long f = 0; f < d->n_facets; f++) assert_true(d->facet_surface[f] >= 0);
  const double lx = 0.2, ly = 0.1, lz = 0.05;
  check_plane_surface(m, d, "bottom", (const double[3]){0, 0, -lx * ly});
  check_plane_surface(m, d, "top", (const double[3]){0, 0, lx * ly});
  check_plane_surface(m, d, "surface-17", (const double[3]){-ly * lz, 0, 0});
  /* sides: xmax, ymin and ymax. */
  surface_sums s;
  sum_surfaces(m, d, &s);
  int k = gm_mesh_surface_find(m, "sides");
  const double sides[3] = {ly * lz, 0, 0}, sides_area = ly * lz + 2 * lx * lz;
  for (int a = 0; a < 3; a++)
    assert_true(fabs(s.vec[k][a] - sides[a]) <= 1e-12 * sides_area);
  assert_true(fabs(s.area[k] - sides_area) <= 1e-12 * sides_area);
  assert_int_equal(s.count[m->n_surfaces], 0);
  gm_dual_destroy(d);
  gm_mesh_destroy(m);
}

/* A cylinder of radius r: its end faces are inscribed polygons, short of
 * pi r^2 by the circular segments (a relative h^2 / (6 r^2) for chords of
 * length h; we allow h^2 / r^2); the lateral surface is in no group. */
static void test_cylinder_file(void **state) {
  (void)state;
  const double r = 0.05, len = 0.1, h = 0.01;
  gm_mesh *m = NULL;
  gm_dual *d = NULL;
  assert_ok(gm_mesh_file(DATA "cylinder.geo", 3, h, GM_SIZES_REPLACE, &m));
  assert_ok(gm_dual_build(m, &d));
  assert_int_equal(m->n_surfaces, 2);
  int top = gm_mesh_surface_find(m, "top");
  int bottom = gm_mesh_surface_find(m, "bottom");
  assert_true(top >= 0 && bottom >= 0);
  surface_sums s;
  sum_surfaces(m, d, &s);
  const double disk = PI * r * r;
  for (int e = 0; e < 2; e++) {
    int k = e ? top : bottom;
    double sign = e ? 1.0 : -1.0, area = s.area[k];
    print_message("  %s: %ld facets, area %.6e (disk %.6e, deficit %.2e)\n",
                  m->surface_name[k], s.count[k], area, disk,
                  (disk - area) / disk);
    assert_true(area < disk && area > disk * (1 - h * h / (r * r)));
    assert_true(fabs(s.vec[k][2] - sign * area) <= 1e-12 * area);
    assert_true(fabs(s.vec[k][0]) + fabs(s.vec[k][1]) <= 1e-12 * area);
  }
  /* Facets on no surface: the lateral one, pointing away from the axis. */
  const int none = m->n_surfaces;
  assert_true(s.count[none] > 0);
  for (long f = 0; f < d->n_facets; f++) {
    const double *a = d->facet_area_vec + 3 * f, *c = d->facet_centroid + 3 * f;
    if (d->facet_surface[f] >= 0) continue;
    assert_true(a[0] * c[0] + a[1] * c[1] > 0);
    assert_true(c[2] > -1e-12 && c[2] < len + 1e-12);
  }
  /* A closed surface: all facets together sum to zero. */
  double total[3] = {0, 0, 0}, area = 0;
  for (int k = 0; k <= none; k++) {
    area += s.area[k];
    for (int a = 0; a < 3; a++) total[a] += s.vec[k][a];
  }
  for (int a = 0; a < 3; a++) assert_true(fabs(total[a]) <= 1e-13 * area);
  gm_dual_destroy(d);
  gm_mesh_destroy(m);
}

/* A file with the box gm_mesh_box meshes, faces named as it names them,
 * gives the very same mesh: nodes, cells and face tags. */
static void check_same_as_box(int dim, const char *path, double h) {
  const double lo[3] = {0, 0, 0}, hi[3] = {0.1, 0.1, dim == 3 ? 0.1 : 0};
  gm_mesh *a = NULL, *b = NULL;
  assert_ok(gm_mesh_box(dim, lo, hi, h, &a));
  assert_ok(gm_mesh_file(path, dim, h, GM_SIZES_REPLACE, &b));
  print_message("  %dD: box %ld nodes, file %ld nodes\n", dim, a->n_nodes,
                b->n_nodes);
  assert_int_equal(a->n_nodes, b->n_nodes);
  assert_int_equal(a->n_cells, b->n_cells);
  assert_int_equal(a->n_surfaces, b->n_surfaces);
  for (int s = 0; s < a->n_surfaces; s++)
    assert_string_equal(a->surface_name[s], b->surface_name[s]);
  const size_t slots = (size_t)(dim + 1) * a->n_cells;
  assert_memory_equal(a->x, b->x, sizeof(double) * 3 * a->n_nodes);
  assert_memory_equal(a->cells, b->cells, sizeof(long) * slots);
  assert_memory_equal(a->face_surface, b->face_surface, sizeof(int) * slots);
  gm_mesh_destroy(a);
  gm_mesh_destroy(b);
}

static void test_same_as_box(void **state) {
  (void)state;
  check_same_as_box(3, DATA "box-faces.geo", 0.02);
  check_same_as_box(2, DATA "square-faces.geo", 0.01);
}

/* One tetrahedron given upside down (gm_mesh_file turns it over: the tags
 * must follow), its faces in groups: surfaces in order of group tag, a
 * group without a name called "surface-TAG", a face in two groups on the
 * later one's (so "a" keeps its name but no face), and a triangle that is
 * not a face of the mesh changing nothing. */
static void test_msh_groups(void **state) {
  (void)state;
  char buf[64];
  gm_mesh *m = NULL;
  gm_dual *d = NULL;
  assert_ok(gm_mesh_file(DATA "tet-groups.msh", 3, 0.0, GM_SIZES_REPLACE, &m));
  assert_int_equal(m->n_cells, 1);
  assert_int_equal(m->n_nodes, 4);
  assert_string_equal(gm_mesh_surface_list(m, buf, sizeof buf),
                      "a, c, b, surface-4, lid");
  /* Face o is opposite node o: z = 0 is "lid", y = 0 "c", x = 0 "b", the
   * slanted face "surface-4". */
  for (int o = 0; o < 4; o++) {
    const double *p = m->x + 3 * m->cells[o];
    int expect = p[2] == 1 ? 4 : p[1] == 1 ? 1 : p[0] == 1 ? 2 : 3;
    assert_int_equal(m->face_surface[o], expect);
  }
  assert_ok(gm_dual_build(m, &d));
  surface_sums s;
  sum_surfaces(m, d, &s);
  const long count[6] = {0, 3, 3, 3, 3, 0};
  for (int k = 0; k < 6; k++) assert_int_equal(s.count[k], count[k]);
  assert_true(fabs(s.vec[4][2] + 0.5) <= 1e-15);
  assert_true(fabs(s.vec[1][1] + 0.5) <= 1e-15);
  assert_true(fabs(s.vec[2][0] + 0.5) <= 1e-15);
  assert_true(fabs(s.area[3] - sqrt(3.0) / 2) <= 1e-15);
  gm_dual_destroy(d);
  gm_mesh_destroy(m);
  /* A node tagged 4e8 (.msh 4.1): numbered like the others, in memory that
   * follows the node count, not the largest tag. */
  assert_ok(gm_mesh_file(PM_SOURCE_DIR
                         "/tests/fuzz/regressions/gmsh/node-tag-4e8.msh",
                         3, 0.0, GM_SIZES_REPLACE, &m));
  assert_int_equal(m->n_cells, 1);
  assert_int_equal(m->n_nodes, 4);
  assert_true(fabs(gm_mesh_volume(m) - 1.0 / 6) <= 1e-15);
  gm_mesh_destroy(m);
}

/* A disk in 2D, its rim a physical curve: the facets are the rim's half
 * edges, outward, adding up to a closed polygon shorter than 2 pi r. */
static void test_disk_2d(void **state) {
  (void)state;
  const double r = 0.5, h = 0.05;
  gm_mesh *m = NULL;
  gm_dual *d = NULL;
  assert_ok(gm_mesh_file(DATA "disk.geo", 2, h, GM_SIZES_REPLACE, &m));
  assert_ok(gm_dual_build(m, &d));
  assert_int_equal(m->n_surfaces, 1);
  assert_string_equal(m->surface_name[0], "rim");
  surface_sums s;
  sum_surfaces(m, d, &s);
  print_message("  disk rim: %ld facets, length %.6f (2 pi r %.6f)\n",
                s.count[0], s.area[0], 2 * PI * r);
  assert_int_equal(s.count[1], 0);
  assert_true(s.area[0] < 2 * PI * r && s.area[0] > 2 * PI * r * (1 - h / r));
  for (int a = 0; a < 3; a++) assert_true(fabs(s.vec[0][a]) <= 1e-14);
  for (long f = 0; f < d->n_facets; f++) {
    const double *a = d->facet_area_vec + 3 * f, *c = d->facet_centroid + 3 * f;
    assert_true(a[0] * c[0] + a[1] * c[1] > 0);
  }
  gm_dual_destroy(d);
  gm_mesh_destroy(m);
}

/* The shortest and longest edges of m's cells near x0 (within r) and of
 * all of them. */
static void edge_range(const gm_mesh *m, const double x0[3], double r,
                       double *near_min, double *all_max) {
  *near_min = INFINITY;
  *all_max = 0;
  const int k = m->nodes_per_cell;
  for (long c = 0; c < m->n_cells; c++)
    for (int a = 0; a < k; a++)
      for (int b = a + 1; b < k; b++) {
        const double *p = m->x + 3 * m->cells[k * c + a],
                     *q = m->x + 3 * m->cells[k * c + b];
        const double len = hypot(hypot(p[0] - q[0], p[1] - q[1]), p[2] - q[2]);
        *all_max = fmax(*all_max, len);
        if (hypot(p[0] - x0[0], p[1] - x0[1]) < r)
          *near_min = fmin(*near_min, len);
      }
}

/* A .geo's own sizes meet the scene's h by rule: scale keeps the corner's
 * tenfold refinement at h's level (its curves' longest edge h, none
 * longer than about h; halving h halves every size), replace meshes at h
 * everywhere, file keeps the file's sizes whatever h. */
static void test_file_sizes(void **state) {
  (void)state;
  const double origin[3] = {0, 0, 0};
  struct {
    double h;
    gm_sizes rule;
    double factor, near_lo, near_hi, max_hi;
  } want[] = {
      /* the corner asks 0.05 at lc 0.5: 0.05 h / 0.5 */
      {0.5, GM_SIZES_SCALE, 1, 0.02, 0.1, 0.75},
      {0.25, GM_SIZES_SCALE, 0.5, 0.01, 0.05, 0.375},
      {0.5, GM_SIZES_REPLACE, 0, 0.2, 0.75, 0.75},
      {0.25, GM_SIZES_FILE, 1, 0.02, 0.1, 0.75},
  };
  long n[4];
  for (int i = 0; i < 4; i++) {
    gm_mesh *m = NULL;
    assert_ok(
        gm_mesh_file(DATA "panel-corner.geo", 2, want[i].h, want[i].rule, &m));
    double near_min, all_max;
    edge_range(m, origin, 0.5, &near_min, &all_max);
    print_message("  rule %d h %g: %ld nodes, factor %g, shortest edge near "
                  "the corner %.4g, longest %.4g\n",
                  (int)want[i].rule, want[i].h, m->n_nodes, m->size_factor,
                  near_min, all_max);
    assert_true(m->meshed);
    assert_true(fabs(m->size_factor - want[i].factor) <
                0.05 * want[i].factor + 1e-12);
    assert_true(near_min > want[i].near_lo && near_min < want[i].near_hi);
    assert_true(all_max < want[i].max_hi);
    n[i] = m->n_nodes;
    gm_mesh_destroy(m);
  }
  /* halving h: about four times the nodes (3.5-4.2 with the boundary) */
  assert_true(n[1] > 3.4 * n[0] && n[1] < 4.3 * n[0]);
  assert_true(n[2] < n[0] / 2);
  assert_int_equal(n[3], n[0]);
}

/* A closed surface mesh without a volume (an STL of the unit cube, twelve
 * triangles) is the boundary of the volume gmsh meshes in it: the tets
 * fill the cube exactly, its triangles kept. */
static void test_stl_volume(void **state) {
  (void)state;
  gm_mesh *m = NULL;
  assert_ok(gm_mesh_file(DATA "cube.stl", 3, 0.25, GM_SIZES_SCALE, &m));
  double vol = 0;
  for (long c = 0; c < m->n_cells; c++) {
    const long *t = m->cells + 4 * c;
    double e[3][3];
    for (int a = 0; a < 3; a++)
      for (int k = 0; k < 3; k++)
        e[a][k] = m->x[3 * t[a + 1] + k] - m->x[3 * t[0] + k];
    vol += (e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
            e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
            e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) /
           6;
  }
  print_message("  cube.stl: %ld nodes, %ld tets, volume %.15f\n", m->n_nodes,
                m->n_cells, vol);
  assert_true(fabs(vol - 1) < 1e-12);
  assert_true(m->meshed && m->size_factor == 0); /* scale: replaced */
  for (int k = 0; k < 3; k++) {
    assert_true(m->box_min[k] == 0 && m->box_max[k] == 1);
  }
  assert_true(m->n_nodes > 8); /* nodes inside */
  gm_mesh_destroy(m);
}

/* The errors of gm_mesh_file of its own (those of reading the file, which
 * it shares with gm_volume_load, are in test_volume). */
static void test_errors(void **state) {
  (void)state;
  gm_mesh *m = (gm_mesh *)0x1;
  /* A quadrangle in a physical surface. */
  assert_int_equal(
      gm_mesh_file(DATA "quad-in-group.msh", 3, 0.1, GM_SIZES_REPLACE, &m),
      PM_ERR_UNSUPPORTED);
  assert_null(m);
  print_message("  %s\n", pm_error_message());
  assert_non_null(strstr(pm_error_message(), "quad-in-group.msh"));
  assert_non_null(strstr(pm_error_message(), "physical group 'lid'"));
  /* A flat tetrahedron. */
  assert_int_equal(
      gm_mesh_file(DATA "flat-tet.msh", 3, 0.1, GM_SIZES_REPLACE, &m),
      PM_ERR_GEOMETRY);
  print_message("  %s\n", pm_error_message());
  assert_non_null(strstr(pm_error_message(), "flat-tet.msh"));
  assert_int_equal(
      gm_mesh_file(DATA "flat-tet.msh", 3, 0.1, GM_SIZES_REPLACE, NULL),
      PM_ERR_ARG);
  assert_null(m);
  pm_error_clear();
}

int main(void) {
  gmsh_testing_preload();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_box_names),     cmocka_unit_test(test_block_file),
      cmocka_unit_test(test_cylinder_file), cmocka_unit_test(test_same_as_box),
      cmocka_unit_test(test_msh_groups),    cmocka_unit_test(test_disk_2d),
      cmocka_unit_test(test_file_sizes),    cmocka_unit_test(test_stl_volume),
      cmocka_unit_test(test_errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
