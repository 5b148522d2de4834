/* pm_fe_errors: a run against a finite-element reference: the NRMSE over
 * the lattice (whole, interior, volume-weighted), the reaction, energy and
 * tip errors, and the pointwise errors for maps. */
#include "pm_fe.h"

#include <math.h>
#include <stdbool.h>

#include "pm_metrics.h"
#include "pm_probe.h"

/* The lattice's bounding box. */
static void lattice_box(const pm_fe_reference *r, double lo[3], double hi[3]) {
  for (int c = 0; c < 3; c++) lo[c] = INFINITY, hi[c] = -INFINITY;
  for (long j = 0; j < r->n; j++)
    for (int c = 0; c < 3; c++) {
      lo[c] = fmin(lo[c], r->x[3 * j + c]);
      hi[c] = fmax(hi[c], r->x[3 * j + c]);
    }
}

/* Whether coordinate c of lattice point j lies on a bounding plane. */
static bool on_plane(const pm_fe_reference *r, long j, int c,
                     const double lo[3], const double hi[3]) {
  double tol = 1e-9 * (hi[c] - lo[c]);
  double xc = r->x[3 * j + c];
  return xc <= lo[c] + tol || xc >= hi[c] - tol;
}

/* The weighted root mean square of the error over the lattice, each
 * point's weight halved on every bounding plane it lies on (volume) or
 * nil on any (interior); the smallest and largest |u| of the reference
 * over every point into *small and *big.  NAN for no weight. */
static double lattice_rms(const pm_fe_reference *r, const double *mapped,
                          bool interior, double *small, double *big) {
  double lo[3], hi[3], sum = 0, weight = 0;
  const int dim = r->dim == 2 ? 2 : 3;
  lattice_box(r, lo, hi);
  *small = INFINITY, *big = 0;
  for (long j = 0; j < r->n; j++) {
    double u2 = 0, d2 = 0, w = 1;
    for (int c = 0; c < dim; c++) {
      if (on_plane(r, j, c, lo, hi)) w *= interior ? 0 : 0.5;
      double d = mapped[3 * j + c] - r->u[3 * j + c];
      d2 += d * d;
      u2 += r->u[3 * j + c] * r->u[3 * j + c];
    }
    *small = fmin(*small, sqrt(u2));
    *big = fmax(*big, sqrt(u2));
    sum += w * d2;
    weight += w;
  }
  return weight > 0 ? sqrt(sum / weight) : NAN;
}

double pm_fe_nrmse_interior(const pm_fe_reference *r, const double *mapped) {
  double small, big;
  const double rms = lattice_rms(r, mapped, true, &small, &big);
  return big > 0 ? rms / big : NAN;
}

double pm_fe_nrmse_volume(const pm_fe_reference *r, const double *mapped) {
  double small, big;
  const double rms = lattice_rms(r, mapped, false, &small, &big);
  return big > small ? rms / (big - small) : NAN;
}

pm_err pm_fe_write_errors(const pm_fe_reference *r, const double *mapped,
                          const char *path) {
  pm_err ret = PM_SUCCESS;
  pm_afile *f = NULL;
  PM_TRY(pm_afile_open(path, &f));
  FILE *s = pm_afile_stream(f);
  fprintf(s, "x,y,z,u_fe_x,u_fe_y,u_fe_z,u_x,u_y,u_z,error\n");
  for (long j = 0; j < r->n; j++) {
    const double *x = r->x + 3 * j, *a = r->u + 3 * j, *b = mapped + 3 * j;
    double d =
        sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
             (b[2] - a[2]) * (b[2] - a[2]));
    fprintf(s, "%.9g,%.9g,%.9g,%.9e,%.9e,%.9e,%.9e,%.9e,%.9e,%.6e\n", x[0],
            x[1], x[2], a[0], a[1], a[2], b[0], b[1], b[2], d);
  }
  PM_TRY(pm_afile_commit(f));
  f = NULL;
done:
  if (f) pm_afile_abort(f);
  return ret;
}

double pm_fe_tip(const pm_fe_reference *r, const double *mapped) {
  if (r->tip_face < 0 || r->tip_axis < 0 || r->n < 1) return NAN;
  int a = r->tip_face / 2;
  double plane = r->x[a];
  for (long j = 1; j < r->n; j++)
    plane = r->tip_face % 2 ? fmax(plane, r->x[3 * j + a])
                            : fmin(plane, r->x[3 * j + a]);
  double sum = 0, tol = 1e-9 * fmax(1.0, fabs(plane));
  long m = 0;
  for (long j = 0; j < r->n; j++)
    if (fabs(r->x[3 * j + a] - plane) <= tol) {
      sum += mapped[3 * j + r->tip_axis];
      m++;
    }
  return sum / (double)m;
}

void pm_fe_errors_of(const pm_fe_reference *r, const double *mapped,
                     const pm_outcome *o, pm_fe_errors *e) {
  e->nrmse = pm_nrmse_vector(r->n, r->dim == 2 ? 3u : 7u, mapped, r->u);
  e->nrmse_interior = pm_fe_nrmse_interior(r, mapped);
  e->nrmse_volume = pm_fe_nrmse_volume(r, mapped);
  e->reaction_error = NAN;
  /* A traction case's reaction is the applied load: no check. */
  int axis = r->tip_face < 0 ? o->loaded_axis : -1;
  if (axis >= 0 && axis < 3)
    e->reaction_error =
        (o->loaded_reaction - r->reaction[axis]) / r->reaction[axis];
  e->sed_error = (o->fig.mean_sed - r->mean_sed) / r->mean_sed;
  e->tip_error = (pm_fe_tip(r, mapped) - r->tip_u) / r->tip_u;
}

pm_err pm_fe_compare(const pm_fe_reference *r, const pm_scene *s,
                     const char *out_dir, const pm_outcome *o,
                     pm_fe_errors *e) {
  pm_err ret = PM_SUCCESS;
  double *mapped = NULL;
  char path[PM_PATH_MAX + 1];
  e->nrmse = e->nrmse_interior = e->reaction_error = e->sed_error = NAN;
  e->nrmse_volume = e->tip_error = NAN;
  PM_TRY(PM_ALLOC(mapped, 3 * r->n, "displacement at the FE lattice"));
  PM_TRY(pm_probe_map(out_dir, -1, s, r->n, r->x, mapped));
  pm_fe_errors_of(r, mapped, o, e);
  PM_TRY(pm_path_join(path, sizeof path, out_dir, "fe-errors.csv"));
  PM_TRY(pm_fe_write_errors(r, mapped, path));
done:
  free(mapped);
  return ret;
}
