/* pm_probe: a results frame's displacement at arbitrary points, by linear
 * moving least squares over a bucket grid of the result points. */
#include "pm_probe.h"

#include <errno.h>
#include <hdf5.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm_files.h"
#include "pm_h5.h"

#define OBJ_NAME_MAX 64
#define NB_MAX 4          /* unknowns of the linear fit: 1 + d */
#define RADIUS_FACTOR 2.2 /* first radius, in mean spacings */
#define RADIUS_GROWTH 1.5 /* radius factor when too few points are found */
#define FLAT_TOL 1e-12    /* relative extent below which an axis is flat */
#define PIVOT_TOL 1e-10   /* relative pivot below which a fit is singular */
#define SHOW_MAX 60       /* bytes of a bad CSV line quoted in errors */

/* The result points, the chosen frame's displacement and their grid. */
typedef struct {
  long n;
  double *x, *u;       /* [n][3] each */
  int d, axis[3];      /* the d axes along which the points extend */
  double lo[3], hi[3]; /* bounding box */
  double spacing, h;   /* mean point spacing, grid cell size */
  long nc[3];          /* cells per axis (1 on flat axes) */
  long *start, *pts;   /* cell c holds pts[start[c] .. start[c+1]) */
  long *near;          /* scratch: the neighbours of one query point */
} cloud;

/* The query points and the CSV line each came from (for messages). */
typedef struct {
  long m, cap;
  double *p; /* [m][3] */
  long *line;
} queries;

/* ---- HDF5 input -------------------------------------------------------- */

/* Read dataset loc/name (shown as obj), float64 [rows][3], into a new
 * array.  *rows < 0 learns the row count, otherwise it must match. */
static pm_err read_n3(hid_t loc, const char *name, const char *obj,
                      const char *path, long *rows, double **out) {
  pm_err ret = PM_SUCCESS;
  hid_t dset = -1, space = -1;
  hsize_t dims[2] = {0, 0};
  double *buf = NULL;
  int rank;
  H5_OK(dset = H5Dopen2(loc, name, H5P_DEFAULT), "H5Dopen2", obj, path);
  H5_OK(space = H5Dget_space(dset), "H5Dget_space", obj, path);
  H5_OK(rank = H5Sget_simple_extent_ndims(space), "H5Sget_simple_extent_ndims",
        obj, path);
  PM_ENSURE(rank == 2, PM_ERR_HDF5, "%s in '%s' has rank %d, not 2", obj, path,
            rank);
  H5_OK(H5Sget_simple_extent_dims(space, dims, NULL),
        "H5Sget_simple_extent_dims", obj, path);
  PM_ENSURE(dims[0] >= 1 && dims[1] == 3, PM_ERR_HDF5,
            "%s in '%s' is %llu x %llu, not n x 3", obj, path,
            (unsigned long long)dims[0], (unsigned long long)dims[1]);
  PM_ENSURE(*rows < 0 || dims[0] == (hsize_t)*rows, PM_ERR_HDF5,
            "%s in '%s' has %llu rows for %ld mesh points", obj, path,
            (unsigned long long)dims[0], *rows);
  PM_TRY(PM_ALLOC(buf, 3 * dims[0], obj));
  H5_OK(H5Dread(dset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf),
        "H5Dread", obj, path);
  *rows = (long)dims[0];
  *out = buf;
  buf = NULL;
done:
  free(buf);
  if (space >= 0) H5Sclose(space);
  if (dset >= 0) H5Dclose(dset);
  return ret;
}

/* Coordinates and frame `frame` (last when < 0) of the results file. */
static pm_err read_results(const char *path, long frame, cloud *c) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1, frames = -1, group = -1;
  H5E_auto2_t old_func = NULL;
  void *old_data = NULL;
  H5G_info_t info;
  char gname[32], obj[OBJ_NAME_MAX];
  long nframes;
  htri_t has;
  /* Failures are reported through pm_error; the caller's HDF5 printing
   * setting is restored on the way out. */
  H5Eget_auto2(H5E_DEFAULT, &old_func, &old_data);
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  PM_ENSURE(access(path, R_OK) == 0, PM_ERR_IO,
            "cannot read results file '%s': %s", path, strerror(errno));
  H5_OK(file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT), "H5Fopen", "/",
        path);
  c->n = -1;
  PM_TRY(read_n3(file, "/mesh/coordinates", "/mesh/coordinates", path, &c->n,
                 &c->x));
  H5_OK(frames = H5Gopen2(file, "/frames", H5P_DEFAULT), "H5Gopen2", "/frames",
        path);
  H5_OK(H5Gget_info(frames, &info), "H5Gget_info", "/frames", path);
  nframes = (long)info.nlinks;
  PM_ENSURE(nframes > 0, PM_ERR_ARG, "results file '%s' holds no frames", path);
  if (frame < 0) frame = nframes - 1;
  PM_ENSURE(frame < nframes, PM_ERR_ARG,
            "frame %ld is out of range: '%s' has frames 0 to %ld", frame, path,
            nframes - 1);
  /* pm_output names frame i "%06ld" of i. */
  snprintf(gname, sizeof gname, "%06ld", frame);
  snprintf(obj, sizeof obj, "/frames/%s", gname);
  H5_OK(group = H5Gopen2(frames, gname, H5P_DEFAULT), "H5Gopen2", obj, path);
  H5_OK(has = H5Lexists(group, "displacement", H5P_DEFAULT), "H5Lexists", obj,
        path);
  PM_ENSURE(has > 0, PM_ERR_ARG, "frame %ld of '%s' has no displacement field",
            frame, path);
  snprintf(obj, sizeof obj, "/frames/%s/displacement", gname);
  PM_TRY(read_n3(group, "displacement", obj, path, &c->n, &c->u));
done:
  if (group >= 0) H5Gclose(group);
  if (frames >= 0) H5Gclose(frames);
  if (file >= 0) H5Fclose(file);
  H5Eset_auto2(H5E_DEFAULT, old_func, old_data);
  return ret;
}

/* ---- Query points ------------------------------------------------------ */

static const char *skip_blanks(const char *s) {
  while (*s == ' ' || *s == '\t') s++;
  return s;
}

/* "x,y,z" or "x,y" (z = 0), blanks allowed around the numbers. */
static bool parse_point(const char *s, double p[3]) {
  int k = 0;
  p[2] = 0.0;
  for (;;) {
    char *end;
    s = skip_blanks(s);
    if (k == 3) return false;
    p[k] = strtod(s, &end);
    if (end == s || !isfinite(p[k])) return false;
    k++;
    s = skip_blanks(end);
    if (*s != ',') return *s == '\0' && k >= 2;
    s++;
  }
}

/* A header names its columns: its first field is not a number. */
static bool is_header(const char *s) {
  char *end;
  s = skip_blanks(s);
  strtod(s, &end);
  return end == s;
}

static pm_err add_query(queries *qs, const double p[3], long line) {
  if (qs->m == qs->cap) {
    long cap = qs->cap ? 2 * qs->cap : 64;
    double *np = realloc(qs->p, (size_t)cap * 3 * sizeof *np);
    if (np) qs->p = np;
    long *nl = np ? realloc(qs->line, (size_t)cap * sizeof *nl) : NULL;
    if (nl) qs->line = nl;
    PM_CHECK(np && nl, PM_ERR_MEMORY, "out of memory for %ld query points",
             cap);
    qs->cap = cap;
  }
  memcpy(&qs->p[3 * qs->m], p, 3 * sizeof *p);
  qs->line[qs->m++] = line;
  return PM_SUCCESS;
}

/* Every point of the CSV file, skipping blanks, comments and a header. */
static pm_err read_points(const char *csv, queries *qs) {
  pm_err ret = PM_SUCCESS;
  pm_lines in = {0};
  char *s;
  bool first = true;
  double p[3];
  PM_TRY(pm_lines_open(&in, csv, "points file"));
  for (;;) {
    PM_TRY(pm_lines_next(&in, &s));
    if (!s) break;
    bool header = first && is_header(s);
    first = false;
    if (header) continue;
    if (!parse_point(s, p)) {
      int len = (int)strlen(s);
      PM_FAIL(PM_ERR_ARG, "%s:%ld: expected x,y,z numbers, got '%.*s%s'", csv,
              in.line, len > SHOW_MAX ? SHOW_MAX : len, s,
              len > SHOW_MAX ? "..." : "");
    }
    PM_TRY(add_query(qs, p, in.line));
  }
  PM_ENSURE(qs->m > 0, PM_ERR_ARG, "points file '%s' holds no points", csv);
done:
  pm_lines_close(&in);
  return ret;
}

/* ---- Bucket grid ------------------------------------------------------- */

/* Cell of coordinate v along axis k, clamped to the grid. */
static long cell_of(const cloud *c, int k, double v) {
  double t = floor((v - c->lo[k]) / c->h);
  if (!(t >= 0.0)) return 0; /* also catches NaN */
  if (t >= (double)(c->nc[k] - 1)) return c->nc[k] - 1;
  return (long)t;
}

static long cell_index(const cloud *c, const double *x) {
  long i0 = cell_of(c, 0, x[0]), i1 = cell_of(c, 1, x[1]);
  return (i0 * c->nc[1] + i1) * c->nc[2] + cell_of(c, 2, x[2]);
}

/* Grid sizes for cell size c->h; false when the grid would be much larger
 * than the point count (a thin cloud). */
static bool grid_dims(cloud *c) {
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

/* Active axes, mean spacing and the grid of the result points.  The
 * spacing is (V/n)^(1/d) over the bounding box of the active axes. */
static pm_err build_grid(cloud *c, const char *path) {
  pm_err ret = PM_SUCCESS;
  double ext_max = 0.0, volume = 1.0;
  long ncell;
  for (int k = 0; k < 3; k++) c->lo[k] = c->hi[k] = c->x[k];
  for (long i = 1; i < c->n; i++)
    for (int k = 0; k < 3; k++) {
      c->lo[k] = fmin(c->lo[k], c->x[3 * i + k]);
      c->hi[k] = fmax(c->hi[k], c->x[3 * i + k]);
    }
  for (int k = 0; k < 3; k++) ext_max = fmax(ext_max, c->hi[k] - c->lo[k]);
  PM_ENSURE(isfinite(ext_max), PM_ERR_HDF5, "'%s' holds non-finite coordinates",
            path);
  c->d = 0;
  for (int k = 0; k < 3; k++)
    if (c->hi[k] - c->lo[k] > FLAT_TOL * ext_max) {
      c->axis[c->d++] = k;
      volume *= c->hi[k] - c->lo[k];
    }
  PM_ENSURE(c->d >= 1, PM_ERR_GEOMETRY,
            "the %ld result points of '%s' all coincide", c->n, path);
  c->spacing = pow(volume / (double)c->n, 1.0 / c->d);
  c->h = c->spacing;
  while (!grid_dims(c)) c->h *= 1.25;
  ncell = c->nc[0] * c->nc[1] * c->nc[2];
  PM_TRY(PM_ALLOC(c->start, ncell + 1, "probe grid"));
  PM_TRY(PM_ALLOC(c->pts, c->n, "probe grid"));
  PM_TRY(PM_ALLOC(c->near, c->n, "probe neighbours"));
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

/* ---- Moving least squares ---------------------------------------------- */

/* Cubic B-spline weight of s = r/R in [0, 1], 1 at the centre. */
static double spline(double s) {
  if (s <= 0.5) return 1.0 - 6.0 * s * s + 6.0 * s * s * s;
  double t = 1.0 - s;
  return 2.0 * t * t * t;
}

/* Squared distance from q to point i along the active axes only: flat axes
 * carry no information, whatever the query's coordinate there. */
static double dist2(const cloud *c, const double *q, long i) {
  double r2 = 0.0;
  for (int a = 0; a < c->d; a++) {
    int k = c->axis[a];
    double dx = c->x[3 * i + k] - q[k];
    r2 += dx * dx;
  }
  return r2;
}

/* Points strictly within R of q into c->near; returns their count. */
static long gather(cloud *c, const double *q, double R) {
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

/* Weighted fit u ~ a + B (x - q) / R over the m gathered points: the
 * coordinates are centred on q and scaled by R so that a is u(q) and the
 * normal matrix is O(1) whatever the units.  Gaussian elimination with
 * partial pivoting; false when the system is (nearly) singular. */
static bool fit(const cloud *c, const double *q, long m, double R,
                double u[3]) {
  int nb = c->d + 1;
  double A[NB_MAX][NB_MAX] = {{0}}, rhs[NB_MAX][3] = {{0}};
  double sol[NB_MAX][3];
  for (long j = 0; j < m; j++) {
    long i = c->near[j];
    double p[NB_MAX] = {1.0};
    double w = spline(sqrt(dist2(c, q, i)) / R);
    for (int a = 0; a < c->d; a++)
      p[1 + a] = (c->x[3 * i + c->axis[a]] - q[c->axis[a]]) / R;
    for (int r = 0; r < nb; r++) {
      for (int s = 0; s < nb; s++) A[r][s] += w * p[r] * p[s];
      for (int k = 0; k < 3; k++) rhs[r][k] += w * p[r] * c->u[3 * i + k];
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
      for (int k = 0; k < 3; k++) {
        double t = rhs[col][k];
        rhs[col][k] = rhs[piv][k];
        rhs[piv][k] = t;
      }
    }
    for (int r = col + 1; r < nb; r++) {
      double f = A[r][col] / A[col][col];
      for (int s = col; s < nb; s++) A[r][s] -= f * A[col][s];
      for (int k = 0; k < 3; k++) rhs[r][k] -= f * rhs[col][k];
    }
  }
  for (int r = nb - 1; r >= 0; r--)
    for (int k = 0; k < 3; k++) {
      double v = rhs[r][k];
      for (int s = r + 1; s < nb; s++) v -= A[r][s] * sol[s][k];
      sol[r][k] = v / A[r][r];
    }
  for (int k = 0; k < 3; k++) u[k] = sol[0][k];
  return true;
}

/* Displacement at q.  The radius grows until enough points give a regular
 * fit; false only when even every point together cannot. */
static bool probe_at(cloud *c, const double *q, double u[3]) {
  long need = 3 * (c->d + 1);
  double R = RADIUS_FACTOR * c->spacing, rmax2 = 0.0;
  /* Beyond the farthest corner of the box every point is inside R. */
  for (int a = 0; a < c->d; a++) {
    int k = c->axis[a];
    double dx = fmax(fabs(q[k] - c->lo[k]), fabs(q[k] - c->hi[k]));
    rmax2 += dx * dx;
  }
  for (;;) {
    bool all = R * R > rmax2;
    long m = gather(c, q, R);
    if ((m >= need || all) && fit(c, q, m, R, u)) return true;
    if (all) return false;
    R *= RADIUS_GROWTH;
  }
}

static void cloud_free(cloud *c) {
  free(c->x);
  free(c->u);
  free(c->start);
  free(c->pts);
  free(c->near);
}

pm_err pm_results_read(const char *out_dir, long frame, long *n, double **x,
                       double **u) {
  pm_err ret = PM_SUCCESS;
  cloud c = {.n = 0};
  char path[PM_PATH_MAX + 1];
  *x = *u = NULL;
  PM_CALL(pm_path_join(path, sizeof path, out_dir, "results.h5"));
  PM_TRY(read_results(path, frame, &c));
  *n = c.n;
  *x = c.x;
  *u = c.u;
  c.x = c.u = NULL;
done:
  cloud_free(&c);
  return ret;
}

pm_err pm_probe_map(const char *out_dir, long frame, long m, const double *q,
                    double *u) {
  pm_err ret = PM_SUCCESS;
  cloud c = {.n = 0};
  char path[PM_PATH_MAX + 1];
  PM_CALL(pm_path_join(path, sizeof path, out_dir, "results.h5"));
  PM_TRY(read_results(path, frame, &c));
  PM_TRY(build_grid(&c, path));
  for (long i = 0; i < m; i++)
    PM_ENSURE(probe_at(&c, q + 3 * i, u + 3 * i), PM_ERR_GEOMETRY,
              "no regular moving-least-squares fit at (%g, %g, %g) from the "
              "%ld points of '%s'",
              q[3 * i], q[3 * i + 1], q[3 * i + 2], c.n, path);
done:
  cloud_free(&c);
  return ret;
}

/* ---- Entry point ------------------------------------------------------- */

pm_err pm_probe(const char *out_dir, const char *points_csv, long frame,
                FILE *out) {
  pm_err ret = PM_SUCCESS;
  cloud c = {.n = 0};
  queries qs = {.m = 0};
  double *val = NULL;
  char path[PM_PATH_MAX + 1];
  PM_CHECK(out_dir && points_csv && out, PM_ERR_ARG, "pm_probe: NULL argument");
  PM_CALL(pm_path_join(path, sizeof path, out_dir, "results.h5"));
  PM_TRY(read_results(path, frame, &c));
  PM_TRY(read_points(points_csv, &qs));
  PM_TRY(build_grid(&c, path));
  PM_TRY(PM_ALLOC(val, 3 * qs.m, "probe values"));
  for (long i = 0; i < qs.m; i++) {
    const double *q = &qs.p[3 * i];
    PM_ENSURE(probe_at(&c, q, &val[3 * i]), PM_ERR_GEOMETRY,
              "%s:%ld: no regular moving-least-squares fit at (%g, %g, %g) "
              "from the %ld points of '%s'",
              points_csv, qs.line[i], q[0], q[1], q[2], c.n, path);
  }
  /* Everything is computed before the first byte is written: a failure
   * leaves no partial table. */
  fprintf(out, "x,y,z,u_x,u_y,u_z\n");
  for (long i = 0; i < qs.m; i++) {
    const double *q = &qs.p[3 * i], *v = &val[3 * i];
    fprintf(out, "%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", q[0], q[1], q[2],
            v[0], v[1], v[2]);
  }
  PM_ENSURE(fflush(out) == 0 && !ferror(out), PM_ERR_IO,
            "probe: cannot write the output: %s", strerror(errno));
done:
  free(val);
  free(qs.p);
  free(qs.line);
  cloud_free(&c);
  return ret;
}
