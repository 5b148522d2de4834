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
#include "pm_h5_vet.h"
#include "pm_isolate.h"
#include "pm_mls.h"
#include "pm_probe_impl.h"
#include "pm_output.h"
#include "pm_scene_mirror.h"

#define SHOW_MAX 60 /* bytes of a bad CSV line quoted in errors */

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

/* ---- One-process order ------------------------------------------------ */

/* A frame written in pieces across ranks (pm_results_join_pieces) holds
 * its rows in piece order with each row's one-process index beside, as
 * dataset PM_PIECE_INDEX: *index that index, checked to be a permutation
 * of the n points, or NULL for rows already in one-process order.  name is
 * the index's path under loc, obj how messages show it. */
static pm_err read_order(hid_t loc, const char *name, const char *obj,
                         const char *path, long n, long **index) {
  pm_err ret = PM_SUCCESS;
  hid_t dset = -1, space = -1;
  long *idx = NULL;
  char *seen = NULL;
  htri_t has;
  *index = NULL;
  H5_OK(has = H5Lexists(loc, name, H5P_DEFAULT), "H5Lexists", obj, path);
  if (has <= 0) return PM_SUCCESS;
  H5_OK(dset = H5Dopen2(loc, name, H5P_DEFAULT), "H5Dopen2", obj, path);
  H5_OK(space = H5Dget_space(dset), "H5Dget_space", obj, path);
  hssize_t count;
  H5_OK(count = H5Sget_simple_extent_npoints(space),
        "H5Sget_simple_extent_npoints", obj, path);
  PM_ENSURE(count == n, PM_ERR_HDF5, "%s in '%s' has %lld rows for %ld points",
            obj, path, (long long)count, n);
  PM_TRY(PM_ALLOC(idx, (size_t)n, obj));
  PM_TRY(PM_ALLOC(seen, (size_t)n, obj));
  H5_OK(H5Dread(dset, H5T_NATIVE_LONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, idx),
        "H5Dread", obj, path);
  for (long i = 0; i < n; i++) {
    PM_ENSURE(idx[i] >= 0 && idx[i] < n && !seen[idx[i]], PM_ERR_HDF5,
              "%s in '%s': row %ld holds %ld, not a point of 0 to %ld once",
              obj, path, i, idx[i], n - 1);
    seen[idx[i]] = 1;
  }
  *index = idx;
  idx = NULL;
done:
  free(idx);
  free(seen);
  if (space >= 0) H5Sclose(space);
  if (dset >= 0) H5Dclose(dset);
  return ret;
}

/* Rows v[n][width] in piece order into one-process order (index from
 * read_order; nothing to do when NULL). */
pm_err pm_probe_in_order(double *v, long n, int width, const long *index) {
  if (!index) return PM_SUCCESS;
  double *tmp = NULL;
  PM_CALL(PM_ALLOC(tmp, (size_t)n * width, "rows in one-process order"));
  for (long i = 0; i < n; i++)
    memcpy(tmp + (size_t)index[i] * width, v + (size_t)i * width,
           (size_t)width * sizeof *v);
  memcpy(v, tmp, (size_t)n * width * sizeof *v);
  free(tmp);
  return PM_SUCCESS;
}

void pm_probe_results_close(results *r) {
  if (r->group >= 0) H5Gclose(r->group);
  if (r->file >= 0) H5Fclose(r->file);
  r->group = r->file = -1;
  free(r->order);
  r->order = NULL;
  H5Eset_auto2(H5E_DEFAULT, r->old_func, r->old_data);
}

pm_err pm_probe_results_open(const char *path, long frame, cloud *c,
                             results *r) {
  pm_err ret = PM_SUCCESS;
  hid_t frames = -1, mesh = -1;
  H5G_info_t info;
  char gname[32], obj[OBJ_NAME_MAX];
  long nframes, *order = NULL;
  r->file = r->group = -1;
  r->order = NULL;
  H5Eget_auto2(H5E_DEFAULT, &r->old_func, &r->old_data);
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  PM_ENSURE(access(path, R_OK) == 0, PM_ERR_IO,
            "cannot read results file '%s': %s", path, strerror(errno));
  H5_OK(r->file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT), "H5Fopen", "/",
        path);
  c->n = -1;
  /* The mesh's file opened once (the link followed once, not once a
   * dataset: HDF5 opens an external link's file at every traversal). */
  H5_OK(mesh = H5Gopen2(r->file, "/mesh", H5P_DEFAULT), "H5Gopen2", "/mesh",
        path);
  PM_TRY(read_n3(mesh, "coordinates", "/mesh/coordinates", path, &c->n, &c->x));
  PM_TRY(read_order(mesh, PM_PIECE_INDEX, "/mesh/" PM_PIECE_INDEX, path, c->n,
                    &order));
  PM_TRY(pm_probe_in_order(c->x, c->n, 3, order));
  H5_OK(frames = H5Gopen2(r->file, "/frames", H5P_DEFAULT), "H5Gopen2",
        "/frames", path);
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
  H5_OK(r->group = H5Gopen2(frames, gname, H5P_DEFAULT), "H5Gopen2", obj, path);
  r->frame = frame;
  snprintf(obj, sizeof obj, "/frames/%s/%s", gname, PM_PIECE_INDEX);
  PM_TRY(read_order(r->group, PM_PIECE_INDEX, obj, path, c->n, &r->order));
done:
  free(order);
  if (mesh >= 0) H5Gclose(mesh);
  if (frames >= 0) H5Gclose(frames);
  if (ret != PM_SUCCESS) pm_probe_results_close(r);
  return ret;
}

/* Coordinates and frame `frame` (last when < 0) of the results file, read
 * in this process. */
static pm_err read_results_here(const char *path, long frame, cloud *c) {
  pm_err ret = PM_SUCCESS;
  results r;
  char obj[OBJ_NAME_MAX];
  htri_t has;
  PM_CALL(pm_probe_results_open(path, frame, c, &r));
  snprintf(obj, sizeof obj, "/frames/%06ld", r.frame);
  H5_OK(has = H5Lexists(r.group, "displacement", H5P_DEFAULT), "H5Lexists", obj,
        path);
  PM_ENSURE(has > 0, PM_ERR_ARG, "frame %ld of '%s' has no displacement field",
            r.frame, path);
  snprintf(obj, sizeof obj, "/frames/%06ld/displacement", r.frame);
  PM_TRY(read_n3(r.group, "displacement", obj, path, &c->n, &c->u));
  PM_TRY(pm_probe_in_order(c->u, c->n, 3, r.order));
done:
  pm_probe_results_close(&r);
  return ret;
}

/* read_results in a child process (pm_isolate.h): libhdf5 1.10 stops the
 * process on some damaged files, which are then refused by name. */
typedef struct {
  const char *path;
  long frame;
  cloud *c;
} read_arg;

static pm_err read_work(void *p) {
  read_arg *a = p;
  return read_results_here(a->path, a->frame, a->c);
}

static pm_err read_put(void *p, int fd) {
  const cloud *c = ((read_arg *)p)->c;
  PM_CALL(pm_isolate_put_array(fd, c->x, 3 * (size_t)c->n, sizeof *c->x));
  return pm_isolate_put_array(fd, c->u, 3 * (size_t)c->n, sizeof *c->u);
}

static pm_err read_get(void *p, int fd) {
  cloud *c = ((read_arg *)p)->c;
  size_t nx = 0, nu = 0;
  PM_CALL(pm_isolate_get_array(fd, (void **)&c->x, &nx, sizeof *c->x));
  PM_CALL(pm_isolate_get_array(fd, (void **)&c->u, &nu, sizeof *c->u));
  c->n = (long)(nx / 3);
  PM_CHECK(nx == nu && nx % 3 == 0, PM_ERR_INTERNAL, "results passed back");
  return PM_SUCCESS;
}

pm_err pm_probe_isolate(const char *path, pm_err (*work)(void *),
                        pm_err (*put)(void *, int), pm_err (*get)(void *, int),
                        void *arg) {
  const pm_isolate_job job = {.path = path,
                              .library = "HDF5",
                              .what = "results of this program",
                              .code = PM_ERR_HDF5,
                              .cpu_seconds = PM_H5_VET_CPU_SECONDS,
                              .work = work,
                              .put = put,
                              .get = get,
                              .arg = arg};
  return pm_isolate_run(&job);
}

/* Coordinates and frame `frame` (last when < 0) of the results file. */
static pm_err read_results(const char *path, long frame, cloud *c) {
  read_arg a = {path, frame, c};
  return pm_probe_isolate(path, read_work, read_put, read_get, &a);
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
pm_err pm_probe_read_points(const char *csv, queries *qs) {
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

void pm_probe_cloud_free(cloud *c) {
  free(c->x);
  free(c->u);
  pm_mls_free(c->mls);
}

/* The cloud's fit structure, named by its results file in messages. */
pm_err pm_probe_index_cloud(cloud *c, const char *path) {
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
  pm_probe_cloud_free(&c);
  return ret;
}

pm_err pm_probe_map(const char *out_dir, long frame, const pm_scene *part,
                    long m, const double *q, double *u) {
  pm_err ret = PM_SUCCESS;
  cloud c = {.n = 0};
  char path[PM_PATH_MAX + 1];
  PM_CALL(pm_path_join(path, sizeof path, out_dir, "results.h5"));
  PM_TRY(read_results(path, frame, &c));
  PM_TRY(pm_probe_index_cloud(&c, path));
  for (long i = 0; i < m; i++) {
    double y[3] = {q[3 * i], q[3 * i + 1], q[3 * i + 2]};
    const unsigned flips = part ? pm_scene_mirror_fold(part, q + 3 * i, y) : 0;
    PM_ENSURE(probe_at(&c, y, u + 3 * i), PM_ERR_GEOMETRY,
              "no regular moving-least-squares fit at (%g, %g, %g) from the "
              "%ld points of '%s'",
              y[0], y[1], y[2], c.n, path);
    pm_scene_mirror_unfold(flips, u + 3 * i);
  }
done:
  pm_probe_cloud_free(&c);
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
  PM_TRY(pm_probe_read_points(points_csv, &qs));
  PM_TRY(pm_probe_index_cloud(&c, path));
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
  pm_probe_cloud_free(&c);
  return ret;
}
