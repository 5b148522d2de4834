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

static void test_gmsh_nodes(void **state) {
  (void)state;
  const double lo[3] = {0, 0, 0}, hi[3] = {0.1, 0.1, 0.1};
  double hs[] = {8.72e-3, 6.4e-3, 4.15e-3};
  for (int dim = 2; dim <= 3; dim++)
  for (int t = 0; t < 3; t++) {
    gm_mesh *m = NULL;
    gm_dual *d = NULL;
    assert_ok(gm_mesh_box(dim, lo, hi, hs[t] / (dim == 2 ? 2 : 1), &m));
    assert_ok(gm_cells_find("voronoi")->build(m, &d));
    double closure = check_cells(d, lo, hi);
    long off = 0, offpts = 0;
    double maxoff = 0;
    char *seen = calloc(d->n_points, 1);
    for (long f = 0; f < d->n_facets; f++) {
      int b = d->facet_surface[f];
      double plane = b % 2 ? hi[b / 2] : lo[b / 2];
      double dist = fabs(d->x[3 * d->facet_point[f] + b / 2] - plane);
      if (dist > 1e-12) {
        off++;
        if (!seen[d->facet_point[f]]) offpts++;
        seen[d->facet_point[f]] = 1;
        maxoff = fmax(maxoff, dist);
      }
    }
    free(seen);
    print_message("%dD gmsh h %g: %ld points, %ld interfaces (median dual "
                  "%ld), %ld facets, closure %.2g, dropped %ld, slivers %ld, "
                  "lowest quality %.3f; %ld facets of %ld points off their "
                  "face (up to %.3g)\n",
                  dim, hs[t], d->n_points, d->n_ifaces, 0L, d->n_facets,
                  closure, d->n_dropped_faces, d->n_slivers, d->min_quality,
                  off, offpts, maxoff);
    gm_dual_destroy(d);
    gm_mesh_destroy(m);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_random_points),
      cmocka_unit_test(test_gmsh_nodes),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
