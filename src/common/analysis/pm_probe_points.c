/* pm_probe_points: a results frame's own per-point values (probe --at
 * points), at every point or at the point nearest each query.  The frame
 * is read by HDF5 in a child process (pm_isolate.h), as the displacement
 * pm_probe.c reads: libhdf5 1.10 stops the process on some damaged files,
 * which are then refused by name. */
#include <errno.h>
#include <hdf5.h>
#include <math.h>
#include <stdbool.h>
#include <limits.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_files.h"
#include "pm_h5.h"
#include "pm_isolate.h"
#include "pm_probe.h"
#include "pm_probe_impl.h"

/* More per-point fields than a frame writes. */
#define FIELDS_MAX 32

/* A per-point dataset of a frame: float [n], [n][k] or [n][3][3]. */
typedef struct {
  char name[OBJ_NAME_MAX];
  int rank, width; /* dataset rank; values per point (at most 9) */
  double *v;       /* [n][width] */
} field;

static void fields_free(field *f, int nf) {
  for (int k = 0; k < nf; k++) free(f[k].v);
}

/* Read one dataset of the frame into *f if it has a float row per point
 * and at most 9 values a row; *taken says whether it had. */
static pm_err read_field(hid_t group, const char *name, const char *path,
                         long n, field *f, bool *taken) {
  pm_err ret = PM_SUCCESS;
  hid_t dset = -1, space = -1, type = -1;
  hsize_t dims[3] = {0, 0, 0};
  int rank;
  *taken = false;
  /* a group (or anything not a dataset) is not a field */
  if ((dset = H5Dopen2(group, name, H5P_DEFAULT)) < 0) return PM_SUCCESS;
  H5_OK(type = H5Dget_type(dset), "H5Dget_type", name, path);
  H5_OK(space = H5Dget_space(dset), "H5Dget_space", name, path);
  H5_OK(rank = H5Sget_simple_extent_ndims(space), "H5Sget_simple_extent_ndims",
        name, path);
  if (H5Tget_class(type) != H5T_FLOAT || rank < 1 || rank > 3) goto done;
  H5_OK(H5Sget_simple_extent_dims(space, dims, NULL),
        "H5Sget_simple_extent_dims", name, path);
  const hsize_t width = (rank > 1 ? dims[1] : 1) * (rank > 2 ? dims[2] : 1);
  if (dims[0] != (hsize_t)n || width < 1 || width > 9) goto done;
  snprintf(f->name, sizeof f->name, "%s", name);
  f->rank = rank;
  f->width = (int)width;
  PM_TRY(PM_ALLOC(f->v, (size_t)n * width, name));
  H5_OK(H5Dread(dset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, f->v),
        "H5Dread", name, path);
  *taken = true;
done:
  if (ret != PM_SUCCESS) {
    free(f->v);
    f->v = NULL;
  }
  if (space >= 0) H5Sclose(space);
  if (type >= 0) H5Tclose(type);
  H5Dclose(dset);
  return ret;
}

/* Every per-point field of the frame, in the file's order. */
static pm_err read_fields(hid_t group, const char *path, long n, field *f,
                          int *nf) {
  pm_err ret = PM_SUCCESS;
  H5G_info_t info;
  char name[OBJ_NAME_MAX];
  *nf = 0;
  H5_OK(H5Gget_info(group, &info), "H5Gget_info", "frame", path);
  for (hsize_t k = 0; k < info.nlinks && *nf < FIELDS_MAX; k++) {
    bool taken;
    ssize_t len = H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, k,
                                     name, sizeof name, H5P_DEFAULT);
    if (len <= 0 || len >= (ssize_t)sizeof name) continue;
    PM_TRY(read_field(group, name, path, n, &f[*nf], &taken));
    *nf += taken;
  }
done:
  return ret;
}

/* A field's column names: a vector's _x _y _z, a 3 x 3 tensor's _xx .. _zz,
 * anything else _0, _1, ... */
static void write_columns(FILE *out, const field *f) {
  static const char axis[] = "xyz";
  if (f->width == 1) {
    fprintf(out, ",%s", f->name);
    return;
  }
  for (int c = 0; c < f->width; c++) {
    if (f->rank == 2 && f->width == 3)
      fprintf(out, ",%s_%c", f->name, axis[c]);
    else if (f->rank == 3 && f->width == 9)
      fprintf(out, ",%s_%c%c", f->name, axis[c / 3], axis[c % 3]);
    else
      fprintf(out, ",%s_%d", f->name, c);
  }
}

static void write_point(FILE *out, const cloud *c, long i, const field *f,
                        int nf) {
  const double *x = c->x + 3 * i;
  fprintf(out, "%ld,%.10g,%.10g,%.10g", i, x[0], x[1], x[2]);
  for (int k = 0; k < nf; k++)
    for (int a = 0; a < f[k].width; a++)
      fprintf(out, ",%.10g", f[k].v[(size_t)i * f[k].width + a]);
  fputc('\n', out);
}

/* ---- The frame, read in a child ---------------------------------------- */

typedef struct {
  const char *path;
  long frame;
  cloud *c;
  field *f;
  int *nf;
} frame_arg;

/* The coordinates and every field of the frame, in one-process order. */
static pm_err frame_work(void *p) {
  pm_err ret = PM_SUCCESS;
  frame_arg *a = p;
  results r = {.file = -1, .group = -1, .order = NULL};
  PM_CALL(pm_probe_results_open(a->path, a->frame, a->c, &r));
  PM_TRY(read_fields(r.group, a->path, a->c->n, a->f, a->nf));
  for (int k = 0; k < *a->nf; k++)
    PM_TRY(pm_probe_in_order(a->f[k].v, a->c->n, a->f[k].width, r.order));
done:
  pm_probe_results_close(&r);
  return ret;
}

static pm_err frame_put(void *p, int fd) {
  const frame_arg *a = p;
  const int32_t nf = *a->nf;
  PM_CALL(
      pm_isolate_put_array(fd, a->c->x, 3 * (size_t)a->c->n, sizeof *a->c->x));
  PM_CALL(pm_isolate_put(fd, &nf, sizeof nf));
  for (int k = 0; k < nf; k++) {
    const field *f = &a->f[k];
    const int32_t shape[2] = {f->rank, f->width};
    PM_CALL(pm_isolate_put_array(fd, f->name, strlen(f->name) + 1, 1));
    PM_CALL(pm_isolate_put(fd, shape, sizeof shape));
    PM_CALL(pm_isolate_put_array(fd, f->v, (size_t)a->c->n * f->width,
                                 sizeof *f->v));
  }
  return PM_SUCCESS;
}

/* What frame_put wrote, checked as read_fields leaves it (the process
 * indexes by it: a child that lies is refused). */
static pm_err frame_get(void *p, int fd) {
  frame_arg *a = p;
  cloud *c = a->c;
  int32_t nf = 0, shape[2];
  size_t n = 0;
  char *name = NULL;
  PM_CALL(pm_isolate_get_array(fd, (void **)&c->x, &n, sizeof *c->x));
  PM_CHECK(n > 0 && n % 3 == 0 && n / 3 <= (size_t)LONG_MAX, PM_ERR_INTERNAL,
           "%zu coordinates passed back", n);
  c->n = (long)(n / 3);
  PM_CALL(pm_isolate_get(fd, &nf, sizeof nf));
  PM_CHECK(nf >= 0 && nf <= FIELDS_MAX, PM_ERR_INTERNAL,
           "%d fields passed back", (int)nf);
  for (int k = 0; k < nf; k++) {
    field *f = &a->f[k];
    PM_CALL(pm_isolate_get_array(fd, (void **)&name, &n, 1));
    const bool named = n > 0 && n <= OBJ_NAME_MAX && name[n - 1] == '\0' &&
                       strlen(name) == n - 1;
    if (named) memcpy(f->name, name, n);
    free(name);
    name = NULL;
    PM_CHECK(named, PM_ERR_INTERNAL, "field name passed back");
    PM_CALL(pm_isolate_get(fd, shape, sizeof shape));
    PM_CHECK(shape[0] >= 1 && shape[0] <= 3 && shape[1] >= 1 && shape[1] <= 9,
             PM_ERR_INTERNAL, "field of rank %d and %d values passed back",
             (int)shape[0], (int)shape[1]);
    f->rank = shape[0];
    f->width = shape[1];
    PM_CALL(pm_isolate_get_array(fd, (void **)&f->v, &n, sizeof *f->v));
    (*a->nf)++; /* freed with the others from here */
    PM_CHECK(n == (size_t)c->n * f->width, PM_ERR_INTERNAL,
             "%zu values of field %s passed back for %ld points", n, f->name,
             c->n);
  }
  return PM_SUCCESS;
}

/* The coordinates and the fields of frame `frame` of path into c, f, nf
 * (the caller frees them whatever this returns). */
static pm_err read_frame(const char *path, long frame, cloud *c, field *f,
                         int *nf) {
  frame_arg a = {path, frame, c, f, nf};
  *nf = 0;
  return pm_probe_isolate(path, frame_work, frame_put, frame_get, &a);
}

pm_err pm_probe_points(const char *out_dir, const char *points_csv, long frame,
                       FILE *out) {
  pm_err ret = PM_SUCCESS;
  cloud c = {.n = 0};
  queries qs = {.m = 0};
  field f[FIELDS_MAX] = {{.v = NULL}};
  int nf = 0;
  long *at = NULL;
  double *dist = NULL;
  char path[PM_PATH_MAX + 1];
  PM_CHECK(out_dir && out, PM_ERR_ARG, "pm_probe_points: NULL argument");
  PM_CALL(pm_path_join(path, sizeof path, out_dir, "results.h5"));
  PM_TRY(read_frame(path, frame, &c, f, &nf));
  if (points_csv) {
    PM_TRY(pm_probe_read_points(points_csv, &qs));
    PM_TRY(pm_probe_index_cloud(&c, path));
    PM_TRY(PM_ALLOC(at, qs.m, "probe points"));
    PM_TRY(PM_ALLOC(dist, qs.m, "probe distances"));
    /* A query farther than half the points' mean gap from every point is
     * at none of them: refused, not answered with a neighbour's value. */
    const double reach = c.n > 1 ? 0.5 * pm_mls_gap(c.mls) : INFINITY;
    for (long i = 0; i < qs.m; i++) {
      const double *q = &qs.p[3 * i];
      at[i] = pm_mls_nearest_point(c.mls, q, &dist[i]);
      const double *x = c.x + 3 * at[i];
      PM_ENSURE(dist[i] <= reach, PM_ERR_ARG,
                "%s:%ld: no point of '%s' at (%g, %g, %g): the nearest, point "
                "%ld at (%g, %g, %g), is %g away, more than half the points' "
                "mean gap (%g); `--at lattice` interpolates between points",
                points_csv, qs.line[i], path, q[0], q[1], q[2], at[i], x[0],
                x[1], x[2], dist[i], reach);
    }
  }
  /* Everything is read before the first byte is written: a failure leaves
   * no partial table. */
  if (points_csv) fprintf(out, "query_x,query_y,query_z,distance,");
  fprintf(out, "point,x,y,z");
  for (int k = 0; k < nf; k++) write_columns(out, &f[k]);
  fputc('\n', out);
  for (long i = 0; i < (points_csv ? qs.m : c.n); i++) {
    if (points_csv) {
      const double *q = &qs.p[3 * i];
      fprintf(out, "%.10g,%.10g,%.10g,%.3g,", q[0], q[1], q[2], dist[i]);
    }
    write_point(out, &c, points_csv ? at[i] : i, f, nf);
  }
  PM_ENSURE(fflush(out) == 0 && !ferror(out), PM_ERR_IO,
            "probe: cannot write the output: %s", strerror(errno));
done:
  fields_free(f, nf);
  free(at);
  free(dist);
  free(qs.p);
  free(qs.line);
  pm_probe_cloud_free(&c);
  return ret;
}
