/* pm_probe: a results frame's displacement at arbitrary points, by linear
 * moving least squares over the result points (pm_mls). */
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
#include "pm_mls.h"

#define OBJ_NAME_MAX 64
#define SHOW_MAX 60 /* bytes of a bad CSV line quoted in errors */

/* The result points, the chosen frame's displacement and their
 * moving-least-squares cloud. */
typedef struct {
  long n;
  double *x, *u; /* [n][3] each */
  pm_mls *mls;
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

static void cloud_free(cloud *c) {
  free(c->x);
  free(c->u);
  pm_mls_free(c->mls);
}

/* The cloud's fit structure, named by its results file in messages. */
static pm_err index_cloud(cloud *c, const char *path) {
  char what[PM_PATH_MAX + 32];
  snprintf(what, sizeof what, "'%s'", path);
  return pm_mls_create(c->n, c->x, what, &c->mls);
}

/* The displacement at q; false only when even every point together gives
 * no regular fit. */
static bool probe_at(cloud *c, const double *q, double u[3]) {
  return pm_mls_fit(c->mls, q, 3, c->u, 0, u) > 0;
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
  PM_TRY(index_cloud(&c, path));
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
  PM_TRY(index_cloud(&c, path));
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
