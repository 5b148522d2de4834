/* test_voronoi: Voronoi cells clipped to a box (gm_voronoi, the "voronoi"
 * cell builder): volumes fill the box, every cell's faces close, the faces
 * are the bisectors of the neighbours, a lattice gives cubes and squares,
 * bad point sets are refused with their indices. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "pm_testing.h"

#include "gm_cells.h"
#include "gm_voronoi.h"
#include "pm_random.h"

/* n seeded uniform points in [lo, hi] (z = 0 in 2D), into a new array. */
static double *random_points(int dim, long n, const double lo[3],
                             const double hi[3], uint64_t seed) {
  double *x = calloc(3 * (size_t)n, sizeof *x);
  assert_non_null(x);
  pm_random r = pm_random_seed(seed);
  for (long i = 0; i < n; i++)
    for (int k = 0; k < dim; k++)
      x[3 * i + k] = lo[k] + (hi[k] - lo[k]) * pm_random_uniform(&r);
  return x;
}

/* The properties every clipped Voronoi partition has, to round-off:
 *  - volumes are positive and sum to the box's;
 *  - each cell's area vectors (interfaces outward, facets) sum to zero and
 *    its moments about the point sum to V I (divergence theorem);
 *  - an interface is planar on the bisector of its pair: its area vector
 *    along x_j - x_i, its centroid as far from both;
 *  - adjacency lists are sorted and symmetric;
 *  - facets lie on their box face, outward, and cover each face.
 * Returns the largest closure defect relative to the cell's surface. */
static double check_cells(const gm_dual *d, const double lo[3],
                          const double hi[3]) {
  const int dim = d->dim;
  const double eps = 1e-13;
  double vbox = 1, ext[3] = {0, 0, 0}, vsum = 0, worst = 0, xmax = 0;
  for (int k = 0; k < dim; k++) {
    ext[k] = hi[k] - lo[k];
    vbox *= ext[k];
    xmax = fmax(xmax, fmax(fabs(lo[k]), fabs(hi[k])));
  }
  double face_area[6] = {0, 0, 0, 0, 0, 0};
  double *sum = calloc(3 * (size_t)d->n_points, sizeof *sum);
  double *mom = calloc(9 * (size_t)d->n_points, sizeof *mom);
  double *surf = calloc((size_t)d->n_points, sizeof *surf);
  assert_true(sum && mom && surf);
  for (long e = 0; e < d->n_ifaces; e++) {
    long i = d->if_pair[2 * e], j = d->if_pair[2 * e + 1];
    assert_true(i < j);
    const double *a = d->if_area_vec + 3 * e, *M = d->if_moment + 9 * e;
    const double *c = d->if_centroid + 3 * e;
    const double *xi = d->x + 3 * i, *xj = d->x + 3 * j;
    double r[3], len = 0, ri = 0, rj = 0, along = 0;
    for (int k = 0; k < 3; k++) {
      r[k] = xj[k] - xi[k];
      len += r[k] * r[k];
      ri += (c[k] - xi[k]) * (c[k] - xi[k]);
      rj += (c[k] - xj[k]) * (c[k] - xj[k]);
      along += a[k] * r[k];
    }
    len = sqrt(len);
    assert_true(d->if_area[e] > 0);
    assert_close(along / len, d->if_area[e], 1e-12, 0);
    assert_close(sqrt(ri), sqrt(rj), 1e-12, 0);
    for (int s = 0; s < 2; s++) {
      long p = s ? j : i;
      double sg = s ? -1.0 : 1.0;
      const double *xp = d->x + 3 * p;
      surf[p] += d->if_area[e];
      for (int k = 0; k < 3; k++) {
        sum[3 * p + k] += sg * a[k];
        for (int q = 0; q < 3; q++)
          mom[9 * p + 3 * k + q] += sg * (M[3 * k + q] - a[k] * xp[q]);
      }
    }
  }
  for (long f = 0; f < d->n_facets; f++) {
    long i = d->facet_point[f];
    int b = d->facet_surface[f], axis = b / 2;
    assert_true(b >= 0 && b < 2 * dim);
    double plane = b % 2 ? hi[axis] : lo[axis], sg = b % 2 ? 1.0 : -1.0;
    const double *a = d->facet_area_vec + 3 * f, *M = d->facet_moment + 9 * f;
    const double *xi = d->x + 3 * i;
    assert_close(d->facet_centroid[3 * f + axis], plane, 0, eps * ext[axis]);
    assert_close(sg * a[axis], d->facet_area[f], 1e-13, 0);
    face_area[b] += d->facet_area[f];
    surf[i] += d->facet_area[f];
    for (int k = 0; k < 3; k++) {
      sum[3 * i + k] += a[k];
      for (int q = 0; q < 3; q++)
        mom[9 * i + 3 * k + q] += M[3 * k + q] - a[k] * xi[q];
    }
  }
  for (long i = 0; i < d->n_points; i++) {
    double V = d->volume[i];
    assert_true(V > 0);
    vsum += V;
    double s = sqrt(sum[3 * i] * sum[3 * i] + sum[3 * i + 1] * sum[3 * i + 1] +
                    sum[3 * i + 2] * sum[3 * i + 2]);
    worst = fmax(worst, s / surf[i]);
    assert_true(s <= eps * surf[i]);
    /* the moments' own scale is |a| |x|: their difference V I loses the
     * digits of |x| / h */
    for (int k = 0; k < dim; k++)
      for (int q = 0; q < dim; q++)
        assert_close(mom[9 * i + 3 * k + q], k == q ? V : 0, 0,
                     64 * DBL_EPSILON * surf[i] * xmax);
    for (long k = d->nbr_ptr[i]; k < d->nbr_ptr[i + 1]; k++) {
      if (k > d->nbr_ptr[i]) assert_true(d->nbr[k] > d->nbr[k - 1]);
      long e = d->nbr_iface[k], j = d->nbr[k];
      assert_true((d->if_pair[2 * e] == i && d->if_pair[2 * e + 1] == j) ||
                  (d->if_pair[2 * e] == j && d->if_pair[2 * e + 1] == i));
    }
  }
  assert_int_equal(d->nbr_ptr[d->n_points], 2 * d->n_ifaces);
  assert_close(vsum, vbox, 1e-13, 0);
  for (int b = 0; b < 2 * dim; b++)
    assert_close(face_area[b], vbox / ext[b / 2], 1e-13, 0);
  free(sum);
  free(mom);
  free(surf);
  return worst;
}

/* Random points in 2D and 3D, several seeds and sizes. */
static void test_random_points(void **state) {
  (void)state;
  const double lo[3] = {-0.5, 1.0, 2.0}, hi[3] = {1.5, 1.6, 2.3};
  for (int dim = 2; dim <= 3; dim++)
    for (int s = 0; s < 3; s++) {
      long n = s == 0 ? 1 : s == 1 ? 7 : dim == 3 ? 2000 : 1000;
      double *x = random_points(dim, n, lo, hi, 17 + s);
      gm_dual *d = NULL;
      assert_ok(gm_voronoi_build(dim, n, x, lo, hi, NULL, &d));
      double closure = check_cells(d, lo, hi);
      print_message("%dD, %ld random points: %ld interfaces, %ld facets, "
                    "closure %.2g, %ld faces dropped, %ld slivers, lowest "
                    "quality %.3f\n",
                    dim, n, d->n_ifaces, d->n_facets, closure,
                    d->n_dropped_faces, d->n_slivers, d->min_quality);
      gm_dual_destroy(d);
      free(x);
    }
}

/* Regular lattices: cell-centred points give cells that are the lattice's
 * boxes, with the axis neighbours as the only interfaces (the diagonal
 * neighbours of the degenerate Delaunay triangulation touch along an edge
 * or a corner: dropped or never cut); a lattice of nodes, boundary
 * included, gives half and quarter boxes on the boundary. */
static void test_lattice(void **state) {
  (void)state;
  const double lo[3] = {0.0, -1.0, 2.0}, hi[3] = {0.4, 0.5, 3.0};
  const int nc[3] = {4, 3, 5};
  for (int dim = 2; dim <= 3; dim++)
    for (int nodes = 0; nodes <= 1; nodes++) {
      int np[3] = {1, 1, 1};
      double h[3] = {0, 0, 0}, box = 1;
      long n = 1;
      for (int k = 0; k < dim; k++) {
        np[k] = nc[k] + nodes;
        h[k] = (hi[k] - lo[k]) / nc[k];
        box *= h[k];
        n *= np[k];
      }
      double *x = calloc(3 * (size_t)n, sizeof *x);
      int *ijk = calloc(3 * (size_t)n, sizeof *ijk);
      for (long p = 0; p < n; p++) {
        long r = p;
        for (int k = 0; k < dim; k++) {
          ijk[3 * p + k] = (int)(r % np[k]);
          r /= np[k];
          x[3 * p + k] = lo[k] + (ijk[3 * p + k] + (nodes ? 0.0 : 0.5)) * h[k];
        }
      }
      gm_dual *d = NULL;
      assert_ok(gm_voronoi_build(dim, n, x, lo, hi, NULL, &d));
      check_cells(d, lo, hi);
      for (long p = 0; p < n; p++) {
        /* a node on b box faces owns 1 / 2^b of a box */
        double expect = box;
        int axis_nbrs = 0;
        for (int k = 0; k < dim; k++) {
          int at = ijk[3 * p + k];
          if (nodes && (at == 0 || at == np[k] - 1)) expect *= 0.5;
          axis_nbrs += (at > 0) + (at < np[k] - 1);
        }
        assert_close(d->volume[p], expect, 1e-13, 0);
        assert_int_equal(d->nbr_ptr[p + 1] - d->nbr_ptr[p], axis_nbrs);
        for (long e = d->nbr_ptr[p]; e < d->nbr_ptr[p + 1]; e++) {
          long q = d->nbr[e], f = d->nbr_iface[e];
          int differ = 0, axis = 0;
          for (int k = 0; k < dim; k++)
            if (ijk[3 * p + k] != ijk[3 * q + k]) {
              differ++;
              axis = k;
            }
          assert_int_equal(differ, 1);
          /* the face's area: the box's face, halved per boundary crossed */
          double area = box / h[axis];
          for (int k = 0; k < dim; k++) {
            int at = ijk[3 * p + k];
            if (k != axis && nodes && (at == 0 || at == np[k] - 1)) area *= 0.5;
          }
          assert_close(d->if_area[f], area, 1e-13, 0);
          for (int k = 0; k < dim; k++) {
            double mid = 0.5 * (x[3 * p + k] + x[3 * q + k]);
            if (k == axis)
              assert_close(d->if_centroid[3 * f + k], mid, 0,
                           1e-13 * (hi[k] - lo[k]));
          }
        }
      }
      print_message("%dD lattice of %s, %ld points: %ld interfaces, %ld "
                    "round-off faces dropped, lowest quality %.3f\n",
                    dim, nodes ? "nodes" : "cell centres", n, d->n_ifaces,
                    d->n_dropped_faces, d->min_quality);
      gm_dual_destroy(d);
      free(x);
      free(ijk);
    }
}

/* Three points on a line across the unit square: the middle one's cell is
 * a strip 0.05 by 1, quality 16 A / P^2 = 0.18: the one sliver. */
static void test_sliver_reported(void **state) {
  (void)state;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0};
  const double x[9] = {0.5, 0.45, 0, 0.5, 0.5, 0, 0.5, 0.55, 0};
  gm_dual *d = NULL;
  assert_ok(gm_voronoi_build(2, 3, x, lo, hi, NULL, &d));
  check_cells(d, lo, hi);
  assert_int_equal(d->n_slivers, 1);
  assert_int_equal(d->min_quality_point, 1);
  assert_close(d->min_quality, 16 * 0.05 / (2.1 * 2.1), 1e-12, 0);
  gm_dual_destroy(d);
}

/* Bad point sets are refused, naming the points. */
static void test_bad_points(void **state) {
  (void)state;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 2, 3};
  const long n = 50;
  double *x = random_points(3, n, lo, hi, 5);
  gm_dual *d = (gm_dual *)1;
  int surf[6] = {0, 1, 2, 3, 4, 5};
  x[3 * 31 + 2] = hi[2] + 1e-3; /* outside */
  assert_fails(gm_voronoi_build(3, n, x, lo, hi, surf, &d), PM_ERR_ARG,
               "point 31 at (");
  assert_null(d);
  print_message("%s\n", pm_error_message());
  assert_non_null(strstr(pm_error_message(), "outside the domain box"));
  x[3 * 31 + 2] = hi[2]; /* on the boundary: in */
  assert_ok(gm_voronoi_build(3, n, x, lo, hi, surf, &d));
  gm_dual_destroy(d);
  memcpy(x + 3 * 40, x + 3 * 12, 3 * sizeof *x); /* exact duplicate */
  assert_fails(gm_voronoi_build(3, n, x, lo, hi, surf, &d), PM_ERR_ARG,
               "points 12 and 40 are duplicates, both at (");
  print_message("%s\n", pm_error_message());
  x[3 * 40] *= 1 + 1e-14; /* closer than 1e-10 of the spacing */
  assert_fails(gm_voronoi_build(3, n, x, lo, hi, surf, &d), PM_ERR_ARG,
               "points 12 at (");
  assert_non_null(strstr(pm_error_message(), "and 40 at ("));
  assert_non_null(strstr(pm_error_message(), "duplicates"));
  print_message("%s\n", pm_error_message());
  x[3 * 40] = NAN;
  assert_fails(gm_voronoi_build(3, n, x, lo, hi, surf, &d), PM_ERR_ARG,
               "point 40 has a non-finite coordinate");
  assert_fails(gm_voronoi_build(3, 0, x, lo, hi, surf, &d), PM_ERR_ARG,
               "Voronoi cells of 0 points");
  assert_fails(gm_voronoi_build(4, n, x, lo, hi, surf, &d), PM_ERR_ARG,
               "expected 2 or 3");
  const double flat[3] = {1, 0, 3};
  assert_fails(gm_voronoi_build(3, n, x, lo, flat, surf, &d), PM_ERR_ARG,
               "empty along axis 1");
  assert_fails(gm_voronoi_build(3, n, x, lo, hi, surf, NULL), PM_ERR_ARG,
               "out is NULL");
  free(x);
}

/* The "voronoi" builder of gm_cells on gmsh box meshes (the F2 cube, the
 * square): the cells of the mesh nodes, facets tagged with the mesh's box
 * surfaces, every facet's point on its face; the median duals of the same
 * mesh fill the same volume. */
static void test_builder_box_mesh(void **state) {
  (void)state;
  const gm_cells_builder *b = gm_cells_find("voronoi");
  assert_non_null(b);
  assert_non_null(b->summary);
  const double lo[3] = {0, 0, 0}, hi[3] = {0.1, 0.1, 0.1};
  for (int dim = 2; dim <= 3; dim++) {
    gm_mesh *m = NULL;
    gm_dual *d = NULL, *md = NULL;
    assert_ok(gm_mesh_box(dim, lo, hi, dim == 3 ? 8.72e-3 : 4e-3, &m));
    assert_ok(b->build(m, &d));
    assert_ok(gm_dual_build(m, &md));
    assert_int_equal(d->n_points, m->n_nodes);
    assert_int_equal(md->min_quality_point, -1);
    double closure = check_cells(d, lo, hi);
    for (long f = 0; f < d->n_facets; f++) {
      int face = d->facet_surface[f];
      assert_string_equal(gm_mesh_surface_name(m, face), pm_face_name(face));
      assert_close(d->x[3 * d->facet_point[f] + face / 2],
                   pm_face_plane(face, lo, hi), 0, 1e-15);
    }
    double vm = 0, vv = 0;
    for (long i = 0; i < m->n_nodes; i++) {
      vm += md->volume[i];
      vv += d->volume[i];
    }
    assert_close(vv, vm, 1e-13, 0);
    print_message("%dD gmsh box: %ld nodes, %ld Voronoi interfaces (median "
                  "duals %ld), %ld facets (%ld), closure %.2g, %ld faces "
                  "dropped, %ld slivers, lowest quality %.3f\n",
                  dim, d->n_points, d->n_ifaces, md->n_ifaces, d->n_facets,
                  md->n_facets, closure, d->n_dropped_faces, d->n_slivers,
                  d->min_quality);
    gm_dual_destroy(d);
    gm_dual_destroy(md);
    gm_mesh_destroy(m);
  }
}

/* What the builder refuses: a mesh that does not fill its box, a box face
 * with two surfaces, a node inside whose cell reaches the boundary. */
static void test_builder_refusals(void **state) {
  (void)state;
  const gm_cells_builder *b = gm_cells_find("voronoi");
  gm_mesh *m = NULL;
  gm_dual *d = NULL;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const double tet[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const long tcell[4] = {0, 1, 2, 3};
  assert_ok(gm_mesh_from_arrays(3, 4, tet, 1, tcell, lo, hi, &m));
  assert_fails(b->build(m, &d), PM_ERR_UNSUPPORTED, "the domain is not one");
  print_message("%s\n", pm_error_message());
  assert_null(d);
  gm_mesh_destroy(m);

  /* [0, 2] x [0, 1] in four triangles; one of the two edges on y = 0
   * re-tagged xmin */
  const double rect[18] = {0, 0, 0, 1, 0, 0, 2, 0, 0,
                           0, 1, 0, 1, 1, 0, 2, 1, 0};
  const long rcells[12] = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4};
  const double rhi[3] = {2, 1, 0};
  assert_ok(gm_mesh_from_arrays(2, 6, rect, 4, rcells, lo, rhi, &m));
  assert_ok(b->build(m, &d));
  gm_dual_destroy(d);
  int done = 0;
  for (long c = 0; c < m->n_cells && !done; c++)
    for (int o = 0; o < 3 && !done; o++)
      if (m->face_surface[3 * c + o] == PM_FACE_YMIN) {
        m->face_surface[3 * c + o] = PM_FACE_XMIN;
        done = 1;
      }
  assert_true(done);
  assert_fails(b->build(m, &d), PM_ERR_UNSUPPORTED,
               "the box face ymin of the mesh carries two surfaces");
  print_message("%s\n", pm_error_message());
  gm_mesh_destroy(m);

  /* the unit square's corners and a node 0.01 above the bottom */
  const double fan[15] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.01, 0};
  const long fcells[12] = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4};
  assert_ok(gm_mesh_from_arrays(2, 5, fan, 4, fcells, lo, hi, &m));
  assert_fails(b->build(m, &d), PM_ERR_UNSUPPORTED,
               "the Voronoi cell of node 4 at (0.5, 0.01, 0) reaches the box "
               "face ymin");
  print_message("%s\n", pm_error_message());
  assert_null(d);
  gm_mesh_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_random_points),
      cmocka_unit_test(test_lattice),
      cmocka_unit_test(test_sliver_reported),
      cmocka_unit_test(test_bad_points),
      cmocka_unit_test(test_builder_box_mesh),
      cmocka_unit_test(test_builder_refusals),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
