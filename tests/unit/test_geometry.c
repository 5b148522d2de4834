/* test_geometry: median-dual cells of hand-made, gmsh box and gmsh file
 * meshes: volumes, closure, divergence theorem for moments, boundary
 * facets, adjacency; the figures of box meshes; the cell-builder table. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "pm_testing.h"

#include "gm_cells.h"
#include "gm_dual.h"
#include "gmsh_testing.h"

#define DATA PM_TEST_DATA "/geometry/"

/* Structured box of n[0] x n[1] (x n[2]) cubes (squares), each split into 6
 * Kuhn tetrahedra (2 triangles).  Some tetrahedra come out negatively
 * oriented on purpose: gm_mesh_from_arrays must flip them. */
static gm_mesh *kuhn_mesh(int dim, const int n[3], const double lo[3],
                          const double hi[3]) {
  int nz = dim == 3 ? n[2] : 0;
  long nx1 = n[0] + 1, ny1 = n[1] + 1, nz1 = nz + 1;
  long n_nodes = nx1 * ny1 * nz1;
  double *x = calloc(3 * (size_t)n_nodes, sizeof *x);
  long n_cubes = (long)n[0] * n[1] * (dim == 3 ? nz : 1);
  long n_cells = n_cubes * (dim == 3 ? 6 : 2);
  long *cells = calloc((size_t)(dim + 1) * n_cells, sizeof *cells);
  assert_non_null(x);
  assert_non_null(cells);
#define NODE(i, j, k) ((i) + nx1 * ((j) + ny1 * (long)(k)))
  for (long k = 0; k < nz1; k++)
    for (long j = 0; j < ny1; j++)
      for (long i = 0; i < nx1; i++) {
        double *p = x + 3 * NODE(i, j, k);
        p[0] = lo[0] + (hi[0] - lo[0]) * i / n[0];
        p[1] = lo[1] + (hi[1] - lo[1]) * j / n[1];
        p[2] = dim == 3 ? lo[2] + (hi[2] - lo[2]) * k / nz : 0.0;
      }
  static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                 {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  long c = 0;
  for (long k = 0; k < (dim == 3 ? nz : 1); k++)
    for (long j = 0; j < n[1]; j++)
      for (long i = 0; i < n[0]; i++) {
        if (dim == 2) {
          long a = NODE(i, j, 0), b = NODE(i + 1, j, 0);
          long d = NODE(i, j + 1, 0), e = NODE(i + 1, j + 1, 0);
          long t[6] = {a, b, e, a, d, e}; /* second one clockwise */
          memcpy(cells + 3 * c, t, sizeof t);
          c += 2;
          continue;
        }
        for (int p = 0; p < 6; p++) {
          long ijk[3] = {i, j, k};
          long *cell = cells + 4 * c++;
          cell[0] = NODE(ijk[0], ijk[1], ijk[2]);
          for (int s = 0; s < 3; s++) {
            ijk[perm[p][s]]++;
            cell[s + 1] = NODE(ijk[0], ijk[1], ijk[2]);
          }
        }
      }
#undef NODE
  gm_mesh *m = NULL;
  assert_int_equal(
      gm_mesh_from_arrays(dim, n_nodes, x, n_cells, cells, lo, hi, &m),
      PM_SUCCESS);
  free(x);
  free(cells);
  return m;
}

/* Sum of the cells' measures (volume in 3D, area in 2D). */
static double mesh_measure(const gm_mesh *m) {
  double sum = 0.0;
  for (long c = 0; c < m->n_cells; c++) {
    const long *cell = m->cells + (size_t)m->nodes_per_cell * c;
    double e[3][3];
    for (int a = 0; a < m->dim; a++)
      for (int k = 0; k < 3; k++)
        e[a][k] = m->x[3 * cell[a + 1] + k] - m->x[3 * cell[0] + k];
    if (m->dim == 2) {
      sum += 0.5 * (e[0][0] * e[1][1] - e[0][1] * e[1][0]);
      continue;
    }
    sum += (e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
            e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
            e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) /
           6.0;
  }
  return sum;
}

/* Checks every property the dual of any mesh promises: volumes positive
 * and summing to the mesh's measure, adjacency, interface orientation, and
 * cell by cell closure (interfaces and facets sum to a zero area vector)
 * and the divergence theorem (their moments sum to V I). */
static void check_partition(const gm_mesh *m, const gm_dual *d) {
  const int dim = m->dim;
  assert_int_equal(d->dim, dim);
  assert_int_equal(d->n_points, m->n_nodes);
  const long n = d->n_points;
  const double domain = mesh_measure(m);

  double vsum = 0.0;
  for (long i = 0; i < n; i++) {
    assert_true(d->volume[i] > 0.0);
    vsum += d->volume[i];
  }
  assert_true(fabs(vsum - domain) <= 1e-12 * domain);

  /* Adjacency: sorted, symmetric, consistent with the interface pairs. */
  assert_int_equal(d->nbr_ptr[0], 0);
  assert_int_equal(d->nbr_ptr[n], 2 * d->n_ifaces);
  for (long i = 0; i < n; i++)
    for (long k = d->nbr_ptr[i]; k < d->nbr_ptr[i + 1]; k++) {
      long j = d->nbr[k], f = d->nbr_iface[k];
      assert_true(j >= 0 && j < n && j != i);
      if (k > d->nbr_ptr[i]) assert_true(d->nbr[k - 1] < j);
      assert_true(f >= 0 && f < d->n_ifaces);
      assert_int_equal(d->if_pair[2 * f], i < j ? i : j);
      assert_int_equal(d->if_pair[2 * f + 1], i < j ? j : i);
    }
  for (long f = 0; f < d->n_ifaces; f++) {
    long i = d->if_pair[2 * f], j = d->if_pair[2 * f + 1];
    assert_true(i < j);
    /* Interfaces face from i to j and are no larger than their area. */
    double dot = 0.0;
    for (int k = 0; k < 3; k++)
      dot += d->if_area_vec[3 * f + k] * (d->x[3 * j + k] - d->x[3 * i + k]);
    assert_true(dot > 0.0);
    const double *a = d->if_area_vec + 3 * f;
    assert_true(sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) <=
                d->if_area[f] * (1 + 1e-12));
    if (dim == 2) assert_true(a[2] == 0.0);
  }

  double *sa = calloc(3 * (size_t)n, sizeof *sa);
  double *sm = calloc(9 * (size_t)n, sizeof *sm);
  double *scale = calloc((size_t)n, sizeof *scale);
  assert_non_null(sa);
  assert_non_null(sm);
  assert_non_null(scale);
  for (long f = 0; f < d->n_ifaces; f++) {
    long ij[2] = {d->if_pair[2 * f], d->if_pair[2 * f + 1]};
    for (int s = 0; s < 2; s++) {
      double sg = s == 0 ? 1.0 : -1.0;
      for (int k = 0; k < 3; k++)
        sa[3 * ij[s] + k] += sg * d->if_area_vec[3 * f + k];
      for (int k = 0; k < 9; k++)
        sm[9 * ij[s] + k] += sg * d->if_moment[9 * f + k];
      scale[ij[s]] += d->if_area[f];
    }
  }
  for (long f = 0; f < d->n_facets; f++) {
    long i = d->facet_point[f];
    assert_true(i >= 0 && i < n);
    for (int k = 0; k < 3; k++) sa[3 * i + k] += d->facet_area_vec[3 * f + k];
    for (int k = 0; k < 9; k++) sm[9 * i + k] += d->facet_moment[9 * f + k];
    scale[i] += d->facet_area[f];
  }
  double worst_a = 0.0, worst_m = 0.0;
  for (long i = 0; i < n; i++) {
    for (int k = 0; k < 3; k++)
      worst_a = fmax(worst_a, fabs(sa[3 * i + k]) / scale[i]);
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++) {
        double expect = (a == b && a < dim) ? d->volume[i] : 0.0;
        worst_m =
            fmax(worst_m, fabs(sm[9 * i + 3 * a + b] - expect) / d->volume[i]);
      }
  }
  print_message("  %ld points, %ld interfaces, %ld facets: closure %.2e, "
                "divergence %.2e\n",
                n, d->n_ifaces, d->n_facets, worst_a, worst_m);
  assert_true(worst_a <= 1e-14);
  assert_true(worst_m <= 1e-12);
  free(sa);
  free(sm);
  free(scale);
}

/* Checks the dual of a mesh of its box: the partition properties, and
 * every facet on the box face its surface names, pointing out of the box,
 * the faces' areas adding up. */
static void check_dual(const gm_mesh *m, const gm_dual *d) {
  const int dim = m->dim;
  double ext[3] = {0, 0, 0}, domain = 1.0;
  for (int k = 0; k < dim; k++) {
    ext[k] = m->box_max[k] - m->box_min[k];
    domain *= ext[k];
  }
  assert_true(fabs(mesh_measure(m) - domain) <= 1e-12 * domain);
  check_partition(m, d);
  double face_area[PM_FACE_COUNT] = {0};
  for (long f = 0; f < d->n_facets; f++) {
    long i = d->facet_point[f];
    int face = d->facet_surface[f];
    assert_true(face >= 0 && face < 2 * dim);
    int axis = face / 2;
    double plane = (face % 2) ? m->box_max[axis] : m->box_min[axis];
    double sign = (face % 2) ? 1.0 : -1.0;
    assert_true(fabs(d->facet_centroid[3 * f + axis] - plane) <=
                1e-12 * ext[axis]);
    assert_true(fabs(d->x[3 * i + axis] - plane) <= 1e-12 * ext[axis]);
    assert_true(fabs(sign * d->facet_area_vec[3 * f + axis] -
                     d->facet_area[f]) <= 1e-12 * d->facet_area[f]);
    face_area[face] += d->facet_area[f];
  }
  for (int face = 0; face < 2 * dim; face++) {
    double expect = dim == 2 ? ext[1 - face / 2] : domain / ext[face / 2];
    assert_true(fabs(face_area[face] - expect) <= 1e-12 * expect);
  }
}

static void test_hand_made_3d(void **state) {
  (void)state;
  const double lo[3] = {1.0, -0.5, 0.0}, hi[3] = {3.0, 0.5, 3.0};
  const int sizes[2][3] = {{1, 1, 1}, {2, 3, 2}};
  for (int s = 0; s < 2; s++) {
    gm_mesh *m = kuhn_mesh(3, sizes[s], lo, hi);
    gm_dual *d = NULL;
    assert_int_equal(gm_dual_build(m, &d), PM_SUCCESS);
    check_dual(m, d);
    /* An interior node of a Kuhn mesh owns exactly one cube's volume. */
    if (s == 1) {
      double cube = 1.0;
      for (int k = 0; k < 3; k++) cube *= (hi[k] - lo[k]) / sizes[s][k];
      long inner = 1 + 3 * (1 + 4 * 1);
      assert_true(fabs(d->volume[inner] - cube) <= 1e-14 * cube);
    }
    gm_dual_destroy(d);
    gm_mesh_destroy(m);
  }
}

static void test_hand_made_2d(void **state) {
  (void)state;
  const double lo[3] = {-1.0, 0.0, 0.0}, hi[3] = {2.0, 2.0, 0.0};
  const int sizes[2][3] = {{1, 1, 0}, {3, 2, 0}};
  for (int s = 0; s < 2; s++) {
    gm_mesh *m = kuhn_mesh(2, sizes[s], lo, hi);
    gm_dual *d = NULL;
    assert_int_equal(gm_dual_build(m, &d), PM_SUCCESS);
    check_dual(m, d);
    if (s == 1) {
      double sq = (hi[0] - lo[0]) / 3 * (hi[1] - lo[1]) / 2;
      long inner = 1 + 4 * 1;
      assert_true(fabs(d->volume[inner] - sq) <= 1e-14 * sq);
    }
    gm_dual_destroy(d);
    gm_mesh_destroy(m);
  }
}

/* A single tetrahedron: each node gets V/4 and three facets, one of which
 * (the slanted face) lies on no box face. */
static void test_single_tet(void **state) {
  (void)state;
  const double x[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const long cells[4] = {0, 2, 1, 3}; /* negative: gets flipped */
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  gm_mesh *m = NULL;
  gm_dual *d = NULL;
  assert_int_equal(gm_mesh_from_arrays(3, 4, x, 1, cells, lo, hi, &m),
                   PM_SUCCESS);
  assert_int_equal(gm_dual_build(m, &d), PM_SUCCESS);
  assert_int_equal(d->n_ifaces, 6);
  assert_int_equal(d->n_facets, 12);
  int count[PM_FACE_COUNT + 1] = {0};
  for (long f = 0; f < d->n_facets; f++) {
    int face = d->facet_surface[f];
    count[face == PM_FACE_NONE ? PM_FACE_COUNT : face]++;
  }
  assert_int_equal(count[PM_FACE_XMIN], 3);
  assert_int_equal(count[PM_FACE_YMIN], 3);
  assert_int_equal(count[PM_FACE_ZMIN], 3);
  assert_int_equal(count[PM_FACE_COUNT], 3);
  for (int i = 0; i < 4; i++)
    assert_true(fabs(d->volume[i] - 1.0 / 24) < 1e-15);
  /* Node 0's facet on z = 0 is a third of that face (area 1/2). */
  for (long f = 0; f < d->n_facets; f++)
    if (d->facet_point[f] == 0 && d->facet_surface[f] == PM_FACE_ZMIN) {
      assert_true(fabs(d->facet_area[f] - 1.0 / 6) < 1e-15);
      assert_true(fabs(d->facet_area_vec[3 * f + 2] + 1.0 / 6) < 1e-15);
    }
  gm_dual_destroy(d);
  gm_mesh_destroy(m);
}

static void test_bad_input(void **state) {
  (void)state;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  gm_mesh *m = (gm_mesh *)0x1;
  assert_int_equal(gm_mesh_box(3, lo, hi, 0.0, &m), PM_ERR_ARG);
  assert_null(m);
  assert_int_equal(gm_mesh_box(2, lo, hi, -1.0, &m), PM_ERR_ARG);
  assert_int_equal(gm_mesh_box(3, lo, hi, NAN, &m), PM_ERR_ARG);
  assert_int_equal(gm_mesh_box(3, hi, lo, 0.1, &m), PM_ERR_ARG);
  assert_int_equal(gm_mesh_box(4, lo, hi, 0.1, &m), PM_ERR_ARG);
  /* Flat tetrahedron and a node index out of range. */
  const double x[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  const long flat[4] = {0, 1, 2, 3}, out[4] = {0, 1, 2, 4};
  assert_int_equal(gm_mesh_from_arrays(3, 4, x, 1, flat, lo, hi, &m),
                   PM_ERR_GEOMETRY);
  assert_null(m);
  assert_int_equal(gm_mesh_from_arrays(3, 4, x, 1, out, lo, hi, &m),
                   PM_ERR_ARG);
  /* A node no cell uses would get a zero-volume dual cell. */
  const double y[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  const long tet[4] = {0, 1, 2, 3};
  gm_dual *d = (gm_dual *)0x1;
  assert_int_equal(gm_mesh_from_arrays(3, 5, y, 1, tet, lo, hi, &m),
                   PM_SUCCESS);
  assert_int_equal(gm_dual_build(m, &d), PM_ERR_GEOMETRY);
  assert_null(d);
  gm_mesh_destroy(m);
  pm_error_clear();
}

/* Meshes box [lo, hi] twice, checks the dual and that gmsh repeats itself. */
static void check_gmsh_box(int dim, const double lo[3], const double hi[3],
                           double h) {
  gm_mesh *m = NULL, *m2 = NULL;
  gm_dual *d = NULL;
  assert_int_equal(gm_mesh_box(dim, lo, hi, h, &m), PM_SUCCESS);
  assert_int_equal(m->dim, dim);
  assert_int_equal(m->nodes_per_cell, dim + 1);
  assert_true(m->n_nodes > 10);
  assert_int_equal(gm_dual_build(m, &d), PM_SUCCESS);
  check_dual(m, d);
  double me = gm_mesh_mean_edge(m);
  print_message("  gmsh %dD h=%g: %ld nodes, %ld cells, mean edge %g\n", dim, h,
                m->n_nodes, m->n_cells, me);
  assert_true(me > 0.5 * h && me < 1.5 * h);
  assert_int_equal(gm_mesh_box(dim, lo, hi, h, &m2), PM_SUCCESS);
  assert_int_equal(m2->n_nodes, m->n_nodes);
  assert_int_equal(m2->n_cells, m->n_cells);
  assert_memory_equal(m2->x, m->x, sizeof(double) * 3 * m->n_nodes);
  assert_memory_equal(m2->cells, m->cells,
                      sizeof(long) * (dim + 1) * m->n_cells);
  gm_dual_destroy(d);
  gm_mesh_destroy(m);
  gm_mesh_destroy(m2);
}

static void test_gmsh_box_3d(void **state) {
  (void)state;
  const double lo[3] = {0, 0, 0}, hi[3] = {0.1, 0.1, 0.1};
  check_gmsh_box(3, lo, hi, 0.02);
}

static void test_gmsh_rect_2d(void **state) {
  (void)state;
  const double lo[3] = {0, 0, 0}, hi[3] = {10, 4, 0};
  check_gmsh_box(2, lo, hi, 1.0);
}

/* Meshes of files (a block, a cylinder, a disk in 2D): the partition
 * properties hold whatever the boundary, and every facet of a closed
 * boundary all in groups has a surface. */
static void test_file_meshes(void **state) {
  (void)state;
  const struct {
    const char *path;
    int dim;
    double h;
    bool all_named;
  } files[] = {{DATA "block.geo", 3, 0.02, true},
               {DATA "cylinder.geo", 3, 0.01, false},
               {DATA "disk.geo", 2, 0.05, true}};
  for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
    gm_mesh *m = NULL;
    gm_dual *d = NULL;
    assert_ok(gm_mesh_file(files[k].path, files[k].dim, files[k].h,
                           GM_SIZES_REPLACE, &m));
    assert_ok(gm_dual_build(m, &d));
    print_message("  %s\n", files[k].path);
    check_partition(m, d);
    long none = 0;
    for (long f = 0; f < d->n_facets; f++) {
      assert_true(d->facet_surface[f] >= -1 &&
                  d->facet_surface[f] < m->n_surfaces);
      none += d->facet_surface[f] < 0;
    }
    if (files[k].all_named)
      assert_int_equal(none, 0);
    else
      assert_true(none > 0);
    gm_dual_destroy(d);
    gm_mesh_destroy(m);
  }
}

/* Box meshes and their duals as they were before meshes carried surfaces
 * (figures of gmsh 4.8: another gmsh version may mesh differently): counts
 * exactly, position-weighted sums to round-off, so that node order, cell
 * orientation and facet order are all pinned. */
static void test_box_figures(void **state) {
  (void)state;
  const struct {
    int dim;
    double h;
    long nodes, cells, ifaces, facets;
    double sum_x, sum_v, sum_a, sum_f;
  } ref[] = {{3, 0.02, 237, 734, 1169, 1194, 35.599350903805131,
              0.11930048398625899, 82.419554735275753, 124.98788923142524},
             {2, 0.01, 142, 242, 383, 80, 14.130367474295316,
              0.71672546600843778, 394.85955103002891, 41.239999999999988}};
  const double lo[3] = {0, 0, 0}, hi[3] = {0.1, 0.1, 0.1};
  for (size_t k = 0; k < sizeof ref / sizeof ref[0]; k++) {
    gm_mesh *m = NULL;
    gm_dual *d = NULL;
    assert_ok(gm_mesh_box(ref[k].dim, lo, hi, ref[k].h, &m));
    assert_ok(gm_dual_build(m, &d));
    assert_int_equal(m->n_nodes, ref[k].nodes);
    assert_int_equal(m->n_cells, ref[k].cells);
    assert_int_equal(d->n_ifaces, ref[k].ifaces);
    assert_int_equal(d->n_facets, ref[k].facets);
    double sx = 0, sv = 0, sa = 0, sf = 0;
    for (long i = 0; i < 3 * m->n_nodes; i++) sx += m->x[i];
    for (long i = 0; i < d->n_points; i++) sv += d->volume[i] * (i + 1);
    for (long i = 0; i < d->n_ifaces; i++) sa += d->if_area[i] * (i + 1);
    /* The facets' surfaces count too: they were their box faces then. */
    for (long i = 0; i < d->n_facets; i++)
      sf += d->facet_area[i] * (i + 1) * (1 + d->facet_surface[i]);
    assert_true(fabs(sx - ref[k].sum_x) <= 1e-14 * ref[k].sum_x);
    assert_true(fabs(sv - ref[k].sum_v) <= 1e-14 * ref[k].sum_v);
    assert_true(fabs(sa - ref[k].sum_a) <= 1e-14 * ref[k].sum_a);
    assert_true(fabs(sf - ref[k].sum_f) <= 1e-14 * ref[k].sum_f);
    gm_dual_destroy(d);
    gm_mesh_destroy(m);
  }
}

/* The builder table: "median-dual" is gm_dual_build; unknown names give
 * NULL. */
static void test_cells_table(void **state) {
  (void)state;
  const gm_cells_builder *b = gm_cells_find("median-dual");
  assert_non_null(b);
  assert_string_equal(b->name, "median-dual");
  assert_non_null(b->summary);
  assert_true(b->build == gm_dual_build);
  assert_null(gm_cells_find("delaunay"));
  assert_null(gm_cells_find("Median-Dual"));
  assert_null(gm_cells_find(""));
  assert_null(gm_cells_find(NULL));
  assert_true(gm_cells_count() >= 1);
  assert_true(gm_cells_at(0) == b);
  assert_null(gm_cells_at(gm_cells_count()));
  assert_null(gm_cells_at(-1));
  /* Through the table, a box mesh's cells as gm_dual_build makes them. */
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0};
  gm_mesh *m = NULL;
  gm_dual *d = NULL;
  assert_ok(gm_mesh_box(2, lo, hi, 0.25, &m));
  assert_ok(b->build(m, &d));
  check_dual(m, d);
  gm_dual_destroy(d);
  gm_mesh_destroy(m);
}

int main(void) {
  gmsh_testing_preload();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_hand_made_3d), cmocka_unit_test(test_hand_made_2d),
      cmocka_unit_test(test_single_tet),   cmocka_unit_test(test_bad_input),
      cmocka_unit_test(test_gmsh_box_3d),  cmocka_unit_test(test_gmsh_rect_2d),
      cmocka_unit_test(test_file_meshes),  cmocka_unit_test(test_box_figures),
      cmocka_unit_test(test_cells_table),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
