/* pm_mls: linear moving least squares over a bucket grid of the points,
 * shared by probes, FE comparisons and method comparisons. */
#include "pm_mls.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

#define NB_MAX 4          /* unknowns of the linear fit: 1 + d */
#define RADIUS_FACTOR 2.2 /* first radius, in mean spacings */
#define RADIUS_GROWTH 1.5 /* radius factor when too few points are found */
#define FLAT_TOL 1e-12    /* relative extent below which an axis is flat */
#define PIVOT_TOL 1e-10   /* relative pivot below which a fit is singular */

struct pm_mls {
  long n;
  const double *x;     /* [n][3], borrowed */
  int d, axis[3];      /* the d axes along which the points extend */
  double lo[3], hi[3]; /* bounding box */
  double spacing, h;   /* mean point spacing, grid cell size */
  long nc[3];          /* cells per axis (1 on flat axes) */
  long *start, *pts;   /* cell c holds pts[start[c] .. start[c+1]) */
  long *near;          /* scratch: the neighbours of one query point */
  double gap;          /* mean nearest-neighbour distance (< 0: unknown) */
};

/* ---- Bucket grid ------------------------------------------------------- */

/* Cell of coordinate v along axis k, clamped to the grid. */
static long cell_of(const pm_mls *c, int k, double v) {
  double t = floor((v - c->lo[k]) / c->h);
  if (!(t >= 0.0)) return 0; /* also catches NaN */
  if (t >= (double)(c->nc[k] - 1)) return c->nc[k] - 1;
  return (long)t;
}

static long cell_index(const pm_mls *c, const double *x) {
  long i0 = cell_of(c, 0, x[0]), i1 = cell_of(c, 1, x[1]);
  return (i0 * c->nc[1] + i1) * c->nc[2] + cell_of(c, 2, x[2]);
}

/* Grid sizes for cell size c->h; false when the grid would be much larger
 * than the point count (a thin cloud). */
static bool grid_dims(pm_mls *c) {
  double total = 1.0;
  for (int k = 0; k < 3; k++) c->nc[k] = 1;
  for (int a = 0; a < c->d; a++) {
    int k = c->axis[a];
    double cells = floor((c->hi[k] - c->lo[k]) / c->h) + 1.0;
    total *= cells;
    if (total > 4.0 * (double)c->n + 64.0) return false;
    c->nc[k] = (long)cells;
  }
  return true;
}

/* Active axes, mean spacing and the grid of the points. */
static pm_err build_grid(pm_mls *c, const char *what) {
  pm_err ret = PM_SUCCESS;
  double ext_max = 0.0, volume = 1.0;
  long ncell;
  for (int k = 0; k < 3; k++) c->lo[k] = c->hi[k] = c->x[k];
  /* fmin and fmax pass NaN over: each coordinate is checked. */
  for (long i = 0; i < c->n; i++)
    for (int k = 0; k < 3; k++) {
      double v = c->x[3 * i + k];
      PM_ENSURE(isfinite(v), PM_ERR_GEOMETRY,
                "%s holds non-finite coordinates (point %ld)", what, i);
      c->lo[k] = fmin(c->lo[k], v);
      c->hi[k] = fmax(c->hi[k], v);
    }
  for (int k = 0; k < 3; k++) ext_max = fmax(ext_max, c->hi[k] - c->lo[k]);
  c->d = 0;
  for (int k = 0; k < 3; k++)
    if (c->hi[k] - c->lo[k] > FLAT_TOL * ext_max) {
      c->axis[c->d++] = k;
      volume *= c->hi[k] - c->lo[k];
    }
  PM_ENSURE(c->d >= 1, PM_ERR_GEOMETRY, "the %ld points of %s all coincide",
            c->n, what);
  c->spacing = pow(volume / (double)c->n, 1.0 / c->d);
  c->h = c->spacing;
  while (!grid_dims(c)) c->h *= 1.25;
  ncell = c->nc[0] * c->nc[1] * c->nc[2];
  PM_TRY(PM_ALLOC(c->start, ncell + 1, "moving-least-squares grid"));
  PM_TRY(PM_ALLOC(c->pts, c->n, "moving-least-squares grid"));
  PM_TRY(PM_ALLOC(c->near, c->n, "moving-least-squares neighbours"));
  /* Counting sort by cell: start[b] first holds the end of cell b, and
   * filling backwards turns it into the cell's beginning. */
  for (long i = 0; i < c->n; i++) c->start[cell_index(c, &c->x[3 * i])]++;
  for (long b = 1; b < ncell; b++) c->start[b] += c->start[b - 1];
  c->start[ncell] = c->n;
  for (long i = c->n - 1; i >= 0; i--)
    c->pts[--c->start[cell_index(c, &c->x[3 * i])]] = i;
done:
  return ret;
}

pm_err pm_mls_create(long n, const double *x, const char *what, pm_mls **out) {
  pm_err ret = PM_SUCCESS;
  pm_mls *c = NULL;
  *out = NULL;
  PM_CHECK(n >= 1 && x, PM_ERR_ARG, "%s holds no points", what);
  PM_TRY(PM_ALLOC(c, 1, "moving-least-squares cloud"));
  c->n = n;
  c->x = x;
  c->gap = -1;
  PM_TRY(build_grid(c, what));
  *out = c;
  c = NULL;
done:
  pm_mls_free(c);
  return ret;
}

void pm_mls_free(pm_mls *m) {
  if (!m) return;
  free(m->start);
  free(m->pts);
  free(m->near);
  free(m);
}

int pm_mls_dim(const pm_mls *m) { return m->d; }

double pm_mls_spacing(const pm_mls *m) { return m->spacing; }

/* ---- Fit --------------------------------------------------------------- */

/* Cubic B-spline weight of s = r/R in [0, 1], 1 at the centre. */
static double spline(double s) {
  if (s <= 0.5) return 1.0 - 6.0 * s * s + 6.0 * s * s * s;
  double t = 1.0 - s;
  return 2.0 * t * t * t;
}

/* Squared distance from q to point i along the active axes only: flat axes
 * carry no information, whatever the query's coordinate there. */
static double dist2(const pm_mls *c, const double *q, long i) {
  double r2 = 0.0;
  for (int a = 0; a < c->d; a++) {
    int k = c->axis[a];
    double dx = c->x[3 * i + k] - q[k];
    r2 += dx * dx;
  }
  return r2;
}

/* Points strictly within R of q into c->near; returns their count. */
static long gather(pm_mls *c, const double *q, double R) {
  long lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, m = 0;
  for (int a = 0; a < c->d; a++) {
    int k = c->axis[a];
    lo[k] = cell_of(c, k, q[k] - R);
    hi[k] = cell_of(c, k, q[k] + R);
  }
  for (long i0 = lo[0]; i0 <= hi[0]; i0++)
    for (long i1 = lo[1]; i1 <= hi[1]; i1++)
      for (long i2 = lo[2]; i2 <= hi[2]; i2++) {
        long b = (i0 * c->nc[1] + i1) * c->nc[2] + i2;
        for (long j = c->start[b]; j < c->start[b + 1]; j++)
          if (dist2(c, q, c->pts[j]) < R * R) c->near[m++] = c->pts[j];
      }
  return m;
}

/* Weighted fit f ~ a + B (x - q) / R over the m gathered points: the
 * coordinates are centred on q and scaled by R so that a is f(q) and the
 * normal matrix is O(1) whatever the units.  Gaussian elimination with
 * partial pivoting; false when the system is (nearly) singular. */
static bool fit(const pm_mls *c, const double *q, long m, double R, int nc,
                const double *f, double *v) {
  int nb = c->d + 1;
  double A[NB_MAX][NB_MAX] = {{0}}, rhs[NB_MAX][PM_MLS_MAX_COMP] = {{0}};
  double sol[NB_MAX][PM_MLS_MAX_COMP];
  for (long j = 0; j < m; j++) {
    long i = c->near[j];
    double p[NB_MAX] = {1.0};
    double w = spline(sqrt(dist2(c, q, i)) / R);
    for (int a = 0; a < c->d; a++)
      p[1 + a] = (c->x[3 * i + c->axis[a]] - q[c->axis[a]]) / R;
    for (int r = 0; r < nb; r++) {
      for (int s = 0; s < nb; s++) A[r][s] += w * p[r] * p[s];
      for (int k = 0; k < nc; k++) rhs[r][k] += w * p[r] * f[nc * i + k];
    }
  }
  /* Entries are bounded by A[0][0] (the weight sum): a relative pivot test
   * is meaningful. */
  double tol = PIVOT_TOL * A[0][0];
  if (!(tol > 0.0)) return false;
  for (int col = 0; col < nb; col++) {
    int piv = col;
    for (int r = col + 1; r < nb; r++)
      if (fabs(A[r][col]) > fabs(A[piv][col])) piv = r;
    if (!(fabs(A[piv][col]) > tol)) return false;
    if (piv != col) {
      for (int s = 0; s < nb; s++) {
        double t = A[col][s];
        A[col][s] = A[piv][s];
        A[piv][s] = t;
      }
      for (int k = 0; k < nc; k++) {
        double t = rhs[col][k];
        rhs[col][k] = rhs[piv][k];
        rhs[piv][k] = t;
      }
    }
    for (int r = col + 1; r < nb; r++) {
      double g = A[r][col] / A[col][col];
      for (int s = col; s < nb; s++) A[r][s] -= g * A[col][s];
      for (int k = 0; k < nc; k++) rhs[r][k] -= g * rhs[col][k];
    }
  }
  for (int r = nb - 1; r >= 0; r--)
    for (int k = 0; k < nc; k++) {
      double t = rhs[r][k];
      for (int s = r + 1; s < nb; s++) t -= A[r][s] * sol[s][k];
      sol[r][k] = t / A[r][r];
    }
  for (int k = 0; k < nc; k++) v[k] = sol[0][k];
  return true;
}

/* The nearest of the points within growing radii of q, other than point
 * self (-1: none); its distance. */
static double nearest_other(pm_mls *m, const double *q, long self,
                            long *which) {
  double R = m->spacing, rmax2 = 0.0;
  for (int a = 0; a < m->d; a++) {
    int k = m->axis[a];
    double dx = fmax(fabs(q[k] - m->lo[k]), fabs(q[k] - m->hi[k]));
    rmax2 += dx * dx;
  }
  for (;;) {
    long found = gather(m, q, R);
    double best = INFINITY;
    for (long j = 0; j < found; j++) {
      const double d2 = m->near[j] != self ? dist2(m, q, m->near[j]) : INFINITY;
      if (d2 < best) {
        best = d2;
        if (which) *which = m->near[j];
      }
    }
    /* Every point within R was gathered: the nearest is among them. */
    if (isfinite(best) || R * R > rmax2) return sqrt(best);
    R *= 2;
  }
}

double pm_mls_nearest(pm_mls *m, const double *q) {
  return nearest_other(m, q, -1, NULL);
}

long pm_mls_nearest_point(pm_mls *m, const double *q, double *dist) {
  long which = -1;
  const double d = nearest_other(m, q, -1, &which);
  if (dist) *dist = d;
  return which;
}

double pm_mls_gap(pm_mls *m) {
  if (m->gap >= 0) return m->gap;
  double sum = 0;
  for (long i = 0; i < m->n && m->n > 1; i++)
    sum += nearest_other(m, m->x + 3 * i, i, NULL);
  m->gap = m->n > 1 ? sum / (double)m->n : 0;
  return m->gap;
}

long pm_mls_fit(pm_mls *m, const double *q, int ncomp, const double *f,
                double reach, double *v) {
  const long need = 3 * (m->d + 1);
  const double cap = reach > 0 ? reach * m->spacing : INFINITY;
  double R = fmin(RADIUS_FACTOR * m->spacing, cap), rmax2 = 0.0;
  for (int k = 0; k < ncomp; k++) v[k] = NAN;
  if (ncomp < 1 || ncomp > PM_MLS_MAX_COMP) return 0;
  /* Beyond the farthest corner of the box every point is inside R. */
  for (int a = 0; a < m->d; a++) {
    int k = m->axis[a];
    double dx = fmax(fabs(q[k] - m->lo[k]), fabs(q[k] - m->hi[k]));
    rmax2 += dx * dx;
  }
  for (;;) {
    bool all = R * R > rmax2;
    long found = gather(m, q, R);
    if ((found >= need || all) && fit(m, q, found, R, ncomp, f, v))
      return found;
    if (all || R >= cap) break;
    R = fmin(R * RADIUS_GROWTH, cap);
  }
  for (int k = 0; k < ncomp; k++) v[k] = NAN;
  return 0;
}
