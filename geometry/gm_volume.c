/* gm_volume: read (and if needed mesh) a solid with the gmsh C API, keep its
 * simplices as affine maps, and locate points through a bucket grid. */
#include "gm_volume.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "gm_gmsh.h"

/* Barycentric slack: a point counts as inside when its distance outside a
 * face is below this fraction of the element's height over that face, so
 * points on shared faces are never lost to round-off. */
#define GM_VOL_TOL 1e-12
/* Relative measure below which a simplex counts as flat (as in gm_mesh). */
#define GM_VOL_FLAT_TOL 1e-12
/* Buckets per element: about one element per bucket keeps the candidate
 * lists short while a tetrahedron's box spans only a few buckets. */
#define GM_VOL_BUCKETS_PER_ELEMENT 1.0
/* Bucket boxes grow by this fraction of the domain size, far more than the
 * barycentric slack above, so a point the slack admits is in the bucket. */
#define GM_VOL_PAD 1e-9

struct gm_volume {
  int dim;
  long n_elems;
  /* Per element, stride dim + dim * dim: corner p0, then the rows of the
   * inverse of J = [p1 - p0, p2 - p0 (, p3 - p0)], so that the barycentric
   * coordinates of x are l_a = row_a . (x - p0), l_0 = 1 - sum. */
  double *affine;
  double measure;
  double min[3], max[3];
  /* Bucket grid over [lo, hi]: n[k] buckets along axis k (1 beyond dim),
   * bucket b lists elements elem[start[b] .. start[b + 1]). */
  long n[3];
  double lo[3], inv[3];
  size_t *start;
  int32_t *elem;
};

void gm_volume_destroy(gm_volume *v) {
  if (!v) return;
  free(v->affine);
  free(v->start);
  free(v->elem);
  free(v);
}

/* ---- affine maps and the bucket grid ----------------------------------- */

static void cross(const double a[3], const double b[3], double c[3]) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

/* Affine map of the simplex with corners p (3 per corner) into a (stride
 * dim + dim * dim); returns its unsigned measure, 0 for a flat one. */
static double simplex_affine(int dim, const double *p, double *a) {
  const int npc = dim + 1;
  double l2 = 0.0, e[3][3];
  for (int i = 0; i < npc; i++)
    for (int j = i + 1; j < npc; j++) {
      double s = 0.0;
      for (int k = 0; k < dim; k++) {
        double d = p[3 * j + k] - p[3 * i + k];
        s += d * d;
      }
      if (s > l2) l2 = s;
    }
  for (int i = 1; i < npc; i++)
    for (int k = 0; k < 3; k++) e[i - 1][k] = p[3 * i + k] - p[k];
  if (dim == 2) {
    double det = e[0][0] * e[1][1] - e[0][1] * e[1][0];
    if (!(fabs(0.5 * det) > GM_VOL_FLAT_TOL * l2)) return 0.0;
    a[0] = p[0];
    a[1] = p[1];
    a[2] = e[1][1] / det;
    a[3] = -e[1][0] / det;
    a[4] = -e[0][1] / det;
    a[5] = e[0][0] / det;
    return 0.5 * fabs(det);
  }
  double r[3][3];
  cross(e[1], e[2], r[0]);
  cross(e[2], e[0], r[1]);
  cross(e[0], e[1], r[2]);
  double det = e[0][0] * r[0][0] + e[0][1] * r[0][1] + e[0][2] * r[0][2];
  if (!(fabs(det / 6.0) > GM_VOL_FLAT_TOL * l2 * sqrt(l2))) return 0.0;
  for (int k = 0; k < 3; k++) a[k] = p[k];
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) a[3 + 3 * i + k] = r[i][k] / det;
  return fabs(det) / 6.0;
}

/* Bucket coordinate of x along axis k, clamped to the grid.  Monotone in x,
 * so a point inside an element's box lands in a bucket the box covers. */
static long bucket_coord(const gm_volume *v, int k, double x) {
  double s = (x - v->lo[k]) * v->inv[k];
  if (!(s > 0.0)) return 0;
  if (s >= (double)v->n[k]) return v->n[k] - 1;
  return (long)s;
}

/* Bucket ranges [i0, i1] of element e's padded box. */
static void element_buckets(const gm_volume *v, const double *p, double pad,
                            long i0[3], long i1[3]) {
  for (int k = 0; k < 3; k++) i0[k] = i1[k] = 0;
  for (int k = 0; k < v->dim; k++) {
    double lo = p[k], hi = p[k];
    for (int a = 1; a <= v->dim; a++) {
      lo = fmin(lo, p[3 * a + k]);
      hi = fmax(hi, p[3 * a + k]);
    }
    i0[k] = bucket_coord(v, k, lo - pad);
    i1[k] = bucket_coord(v, k, hi + pad);
  }
}

/* Uniform grid of about GM_VOL_BUCKETS_PER_ELEMENT buckets per element over
 * the padded bounding box; each element listed in every bucket its box
 * touches (CSR, two passes). */
static pm_err build_grid(gm_volume *v, const double *corners) {
  pm_err ret = PM_SUCCESS;
  const int dim = v->dim, npc = dim + 1;
  double ext = 0.0;
  for (int k = 0; k < dim; k++) ext = fmax(ext, v->max[k] - v->min[k]);
  const double pad = GM_VOL_PAD * ext;
  double span[3] = {1.0, 1.0, 1.0}, box = 1.0;
  for (int k = 0; k < dim; k++) {
    v->lo[k] = v->min[k] - pad;
    span[k] = v->max[k] + pad - v->lo[k];
    box *= span[k];
  }
  const double cell =
      pow(box / (GM_VOL_BUCKETS_PER_ELEMENT * (double)v->n_elems), 1.0 / dim);
  size_t n_buckets = 1;
  for (int k = 0; k < 3; k++) {
    v->n[k] = 1;
    if (k < dim) {
      double nk = ceil(span[k] / cell);
      /* Guards a needle-like domain; the product stays below
       * 2^dim * buckets-per-element * n_elems otherwise. */
      v->n[k] = nk < 1.0 ? 1 : (nk > 1 << 20 ? 1 << 20 : (long)nk);
    }
    v->inv[k] = k < dim ? (double)v->n[k] / span[k] : 0.0;
    n_buckets *= (size_t)v->n[k];
  }
  PM_TRY(PM_ALLOC(v->start, n_buckets + 1, "bucket grid"));
  long i0[3], i1[3];
  for (long e = 0; e < v->n_elems; e++) {
    element_buckets(v, corners + 3 * (size_t)npc * e, pad, i0, i1);
    for (long z = i0[2]; z <= i1[2]; z++)
      for (long y = i0[1]; y <= i1[1]; y++)
        for (long x = i0[0]; x <= i1[0]; x++)
          v->start[1 + x + v->n[0] * (y + v->n[1] * z)]++;
  }
  for (size_t b = 0; b < n_buckets; b++) v->start[b + 1] += v->start[b];
  PM_TRY(PM_ALLOC(v->elem, v->start[n_buckets] + 1, "bucket lists"));
  /* start[b] serves as bucket b's fill cursor, then is shifted back. */
  for (long e = 0; e < v->n_elems; e++) {
    element_buckets(v, corners + 3 * (size_t)npc * e, pad, i0, i1);
    for (long z = i0[2]; z <= i1[2]; z++)
      for (long y = i0[1]; y <= i1[1]; y++)
        for (long x = i0[0]; x <= i1[0]; x++)
          v->elem[v->start[x + v->n[0] * (y + v->n[1] * z)]++] = (int32_t)e;
  }
  for (size_t b = n_buckets; b > 0; b--) v->start[b] = v->start[b - 1];
  v->start[0] = 0;
done:
  return ret;
}

/* Volume from n simplices' corners; drops flat simplices, compacting
 * corners in place. */
static pm_err volume_build(const char *path, int dim, double *corners, long n,
                           gm_volume **out) {
  pm_err ret = PM_SUCCESS;
  gm_volume *v = NULL;
  const int npc = dim + 1, stride = dim + dim * dim;
  PM_ENSURE(n < INT32_MAX, PM_ERR_UNSUPPORTED,
            "'%s' has %ld elements, more than a volume can index", path, n);
  PM_TRY(PM_ALLOC(v, 1, "volume"));
  PM_TRY(PM_ALLOC(v->affine, (size_t)stride * n, "element maps"));
  v->dim = dim;
  for (int k = 0; k < 3; k++) {
    v->min[k] = INFINITY;
    v->max[k] = -INFINITY;
  }
  long kept = 0;
  for (long e = 0; e < n; e++) {
    const double *p = corners + 3 * (size_t)npc * e;
    double m = simplex_affine(dim, p, v->affine + (size_t)stride * kept);
    if (m == 0.0) continue;
    v->measure += m;
    for (int a = 0; a < npc; a++)
      for (int k = 0; k < 3; k++) {
        v->min[k] = fmin(v->min[k], p[3 * a + k]);
        v->max[k] = fmax(v->max[k], p[3 * a + k]);
      }
    if (kept != e)
      memmove(corners + 3 * (size_t)npc * kept, p, sizeof *p * 3 * npc);
    kept++;
  }
  PM_ENSURE(kept > 0, PM_ERR_MESH, "all %ld %s of '%s' are flat", n,
            dim == 3 ? "tetrahedra" : "triangles", path);
  v->n_elems = kept;
  PM_TRY(build_grid(v, corners));
  *out = v;
  v = NULL;
done:
  gm_volume_destroy(v);
  return ret;
}

pm_err gm_volume_load(const char *path, int dim, double h, gm_sizes rule,
                      gm_volume **out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_volume_load: out is NULL");
  *out = NULL;
  pm_err ret = PM_SUCCESS;
  gm_gmsh_mesh raw = {.dim = 0};
  double *corners = NULL;
  PM_TRY(gm_gmsh_load(path, dim, h, rule, false, &raw));
  const size_t npc = (size_t)dim + 1;
  PM_TRY(PM_ALLOC(corners, 3 * npc * (size_t)raw.n_elems, "element corners"));
  for (size_t k = 0; k < npc * (size_t)raw.n_elems; k++)
    memcpy(corners + 3 * k, raw.x + 3 * raw.elem[k], 3 * sizeof *corners);
  PM_TRY(volume_build(path, dim, corners, raw.n_elems, out));
done:
  gm_gmsh_mesh_free(&raw);
  free(corners);
  return ret;
}

/* ---- queries ----------------------------------------------------------- */

bool gm_volume_contains(const gm_volume *v, const double x[3]) {
  if (!v || !x) return false;
  size_t b = 0, stride = 1;
  for (int k = 0; k < v->dim; k++) {
    double s = (x[k] - v->lo[k]) * v->inv[k];
    if (!(s >= 0.0 && s <= (double)v->n[k])) return false; /* NaN too */
    long i = s >= (double)v->n[k] ? v->n[k] - 1 : (long)s;
    b += (size_t)i * stride;
    stride *= (size_t)v->n[k];
  }
  const int32_t *e = v->elem + v->start[b], *end = v->elem + v->start[b + 1];
  if (v->dim == 3) {
    for (; e < end; e++) {
      const double *a = v->affine + 12 * (size_t)*e;
      double d0 = x[0] - a[0], d1 = x[1] - a[1], d2 = x[2] - a[2];
      double l1 = a[3] * d0 + a[4] * d1 + a[5] * d2;
      if (l1 < -GM_VOL_TOL) continue;
      double l2 = a[6] * d0 + a[7] * d1 + a[8] * d2;
      if (l2 < -GM_VOL_TOL) continue;
      double l3 = a[9] * d0 + a[10] * d1 + a[11] * d2;
      if (l3 < -GM_VOL_TOL) continue;
      if (1.0 - l1 - l2 - l3 >= -GM_VOL_TOL) return true;
    }
    return false;
  }
  for (; e < end; e++) {
    const double *a = v->affine + 6 * (size_t)*e;
    double d0 = x[0] - a[0], d1 = x[1] - a[1];
    double l1 = a[2] * d0 + a[3] * d1;
    if (l1 < -GM_VOL_TOL) continue;
    double l2 = a[4] * d0 + a[5] * d1;
    if (l2 < -GM_VOL_TOL) continue;
    if (1.0 - l1 - l2 >= -GM_VOL_TOL) return true;
  }
  return false;
}

void gm_volume_bounds(const gm_volume *v, double min[3], double max[3]) {
  for (int k = 0; k < 3; k++) {
    if (min) min[k] = v ? v->min[k] : 0.0;
    if (max) max[k] = v ? v->max[k] : 0.0;
  }
}

double gm_volume_measure(const gm_volume *v) { return v ? v->measure : 0.0; }

long gm_volume_elements(const gm_volume *v) { return v ? v->n_elems : 0; }

int gm_volume_dim(const gm_volume *v) { return v ? v->dim : 0; }
