/* pm_output: results as one synced file per frame, an index (results.h5)
 * of external links and results.xdmf, both replaced atomically after each
 * frame (pm_output_append.c): creating the results, writing a frame,
 * closing. */
#include "pm_output.h"

#include <errno.h>
#include <hdf5.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pm_files.h"
#include "pm_h5.h"
#include "pm_output_impl.h"

static bool field_name_ok(const char *name) {
  size_t len = name ? strlen(name) : 0;
  if (len == 0 || len > FIELD_NAME_MAX || name[0] == '.') return false;
  for (const char *p = name; *p; p++) {
    char c = *p;
    bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
              (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

/* ---- Checks ------------------------------------------------------------- */

/* n items of npc point indices each, all in [0, n_points). */
static pm_err check_indices(const char *what, long n, int npc, const long *ids,
                            long n_points) {
  PM_CHECK(n >= 1 && ids, PM_ERR_ARG,
           "results: need at least one %s (%ld given)", what, n);
  for (long i = 0; i < n * npc; i++)
    PM_CHECK(ids[i] >= 0 && ids[i] < n_points, PM_ERR_ARG,
             "results: %s %ld refers to point %ld (%ld points)", what, i / npc,
             ids[i], n_points);
  return PM_SUCCESS;
}

static pm_err check_mesh(int dim, const pm_points *p) {
  int npc = p->nodes_per_cell;
  PM_CHECK(dim == 2 || dim == 3, PM_ERR_ARG, "results: dim %d is not 2 or 3",
           dim);
  PM_CHECK(p->n >= 1 && p->x, PM_ERR_ARG,
           "results: need at least one point (n_points %ld)", p->n);
  PM_CHECK(npc == 1 || npc == 3 || npc == 4, PM_ERR_ARG,
           "results: %d nodes per cell (1, 3 or 4 expected)", npc);
  if (npc != 1 || p->cells)
    PM_CALL(check_indices("cell", p->n_cells, npc, p->cells, p->n));
  PM_CHECK(p->n_surface >= 0, PM_ERR_ARG, "results: %ld surface triangles",
           p->n_surface);
  if (p->n_surface == 0) return PM_SUCCESS;
  return check_indices("surface triangle", p->n_surface, 3, p->surface, p->n);
}

/* The output directory must exist and be writable. */
pm_err pm_output_check_dir(const char *dir) {
  struct stat st;
  PM_CHECK(dir && dir[0], PM_ERR_ARG, "results: empty output directory");
  PM_CHECK(stat(dir, &st) == 0, PM_ERR_IO,
           "output directory '%s' is not accessible: %s", dir, strerror(errno));
  PM_CHECK(S_ISDIR(st.st_mode), PM_ERR_IO,
           "output directory '%s' is not a directory", dir);
  PM_CHECK(access(dir, W_OK | X_OK) == 0, PM_ERR_IO,
           "output directory '%s' is not writable: %s", dir, strerror(errno));
  return PM_SUCCESS;
}

pm_err pm_output_check_fields(int n_fields, const pm_field *fields) {
  PM_CHECK(n_fields >= 0 && (n_fields == 0 || fields), PM_ERR_ARG,
           "results frame: %d fields", n_fields);
  for (int i = 0; i < n_fields; i++) {
    const pm_field *f = &fields[i];
    PM_CHECK(field_name_ok(f->name), PM_ERR_ARG,
             "results frame: field %d name '%s' is not a plain name "
             "(letters, digits, _ - ., at most %d bytes)",
             i, f->name ? f->name : "(null)", FIELD_NAME_MAX);
    PM_CHECK(f->ncomp == 1 || f->ncomp == 3 || f->ncomp == 9, PM_ERR_ARG,
             "results frame: field '%s' has %d components (1, 3 or 9)", f->name,
             f->ncomp);
    PM_CHECK(f->data, PM_ERR_ARG, "results frame: field '%s' has no data",
             f->name);
    for (int k = 0; k < i; k++)
      PM_CHECK(strcmp(fields[k].name, f->name) != 0, PM_ERR_ARG,
               "results frame: field '%s' given twice", f->name);
  }
  return PM_SUCCESS;
}

/* ---- Paths -------------------------------------------------------------- */

pm_err pm_output_set_paths(pm_results *r, const char *dir) {
  PM_CHECK(strlen(dir) + 40 < sizeof r->dir, PM_ERR_ARG,
           "output directory name too long: '%.64s...'", dir);
  snprintf(r->dir, sizeof r->dir, "%s", dir);
  PM_CALL(pm_path_join(r->sub, sizeof r->sub, dir, RESULTS_SUBDIR));
  PM_CALL(pm_path_join(r->index_path, sizeof r->index_path, dir, "results.h5"));
  PM_CALL(pm_path_join(r->xdmf_path, sizeof r->xdmf_path, dir, "results.xdmf"));
  PM_CALL(pm_path_join(r->index_spare_path, sizeof r->index_spare_path, r->sub,
                       INDEX_SPARE));
  PM_CALL(pm_path_join(r->index_prev_path, sizeof r->index_prev_path, r->sub,
                       INDEX_SPARE ".prev"));
  PM_CALL(pm_path_join(r->xdmf_spare_path, sizeof r->xdmf_spare_path, r->sub,
                       XDMF_SPARE));
  PM_CALL(pm_path_join(r->xdmf_prev_path, sizeof r->xdmf_prev_path, r->sub,
                       XDMF_SPARE ".prev"));
  /* Nothing known of the files on disk yet: the first frames rewrite
   * them whole. */
  r->index_published = r->index_spare = -1;
  r->xdmf_published = r->xdmf_spare = -1;
  return pm_path_join(r->mesh_path, sizeof r->mesh_path, r->sub, "mesh.h5");
}

void pm_output_frame_path(const pm_results *r, long k, char *buf, size_t size) {
  char name[32];
  snprintf(name, sizeof name, FRAME_FMT, k);
  /* r->sub leaves room for the name (set_paths checks the length). */
  if (pm_path_join(buf, size, r->sub, name) != PM_SUCCESS) buf[0] = '\0';
}

/* ---- Create, reopen, close ---------------------------------------------- */

void pm_output_free(pm_results *r) {
  if (!r) return;
  free(r->scene_text);
  free(r->version);
  free(r->frames.s);
  free(r);
}

/* A point cloud's cells, point i's cell i, into the open dataset dset of
 * n rows, a block at a time (the whole would be a long a point). */
static pm_err write_cloud_cells(hid_t dset, long n, const char *path) {
  enum { block = 1 << 12 };
  pm_err ret = PM_SUCCESS;
  hid_t file = -1, mem = -1;
  long ids[block];
  H5_OK(file = H5Dget_space(dset), "H5Dget_space", "/cells", path);
  for (long at = 0; at < n; at += block) {
    const long k = n - at < block ? n - at : block;
    hsize_t start[2] = {(hsize_t)at, 0}, count[2] = {(hsize_t)k, 1};
    for (long i = 0; i < k; i++) ids[i] = at + i;
    H5_OK(H5Sselect_hyperslab(file, H5S_SELECT_SET, start, NULL, count, NULL),
          "H5Sselect_hyperslab", "/cells", path);
    H5_OK(mem = H5Screate_simple(2, count, NULL), "H5Screate_simple", "/cells",
          path);
    H5_OK(H5Dwrite(dset, H5T_NATIVE_LONG, mem, file, H5P_DEFAULT, ids),
          "H5Dwrite", "/cells", path);
    pm_h5_close_quiet(&mem);
  }
done:
  pm_h5_close_quiet(&mem);
  pm_h5_close_quiet(&file);
  return ret;
}

/* cells NULL: a point cloud's (point i's cell i). */
static pm_err write_mesh(const pm_results *r, const double *x,
                         const long *cells, const long *surface) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1, dset = -1;
  char tmp[PM_PATH_MAX + 40];
  const char *path = tmp;
  int npc = r->nodes_per_cell;
  hsize_t xd[2] = {(hsize_t)r->n_points, 3};
  hsize_t cd[2] = {(hsize_t)r->n_cells, (hsize_t)npc};
  hsize_t sd[2] = {(hsize_t)r->n_surface, 3};
  pm_output_tmp_name(tmp, sizeof tmp, r->mesh_path);
  PM_TRY(
      pm_output_check_room(r->sub, r->mesh_path,
                           H5_OVERHEAD + 8.0 * (3.0 * (double)r->n_points +
                                                (double)r->n_cells * npc +
                                                3.0 * (double)r->n_surface)));
  H5_OK(file = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
        "H5Fcreate", "/", path);
  PM_TRY(pm_output_dataset(file, "coordinates", 2, xd, H5T_IEEE_F64LE,
                           H5T_NATIVE_DOUBLE, x, path, NULL));
  PM_TRY(pm_output_dataset(file, "cells", 2, cd, H5T_STD_I64LE, H5T_NATIVE_LONG,
                           cells, path, &dset));
  if (!cells) PM_TRY(write_cloud_cells(dset, r->n_cells, path));
  PM_TRY(pm_h5_write_attr(dset, "nodes_per_cell", H5T_STD_I32LE, H5T_NATIVE_INT,
                          &npc, path));
  H5_OK(H5Dclose(dset), "H5Dclose", "/cells", path);
  dset = -1;
  if (r->n_surface > 0) {
    PM_TRY(pm_output_dataset(file, "surface", 2, sd, H5T_STD_I64LE,
                             H5T_NATIVE_LONG, surface, path, &dset));
    PM_TRY(pm_h5_write_string_attr(dset, "name", SURFACE_NAME, path));
    H5_OK(H5Dclose(dset), "H5Dclose", "/surface", path);
    dset = -1;
  }
  PM_TRY(pm_output_commit(&file, tmp, r->mesh_path));
done:
  pm_h5_close_quiet(&dset);
  pm_h5_close_quiet(&file);
  if (ret != PM_SUCCESS) unlink(tmp);
  return ret;
}

pm_err pm_results_create_ex(const char *dir, int dim, const pm_points *p,
                            const char *scene_text, const char *version,
                            pm_results **out) {
  pm_err ret = PM_SUCCESS;
  pm_results *r = NULL;
  PM_CHECK(out && p, PM_ERR_ARG, "pm_results_create: NULL out or points");
  *out = NULL;
  PM_CALL(check_mesh(dim, p));
  PM_CALL(pm_output_check_dir(dir));
  /* No clean-up at exit: after a write the system refused, HDF5's own
   * would close a file it cannot flush again. */
  H5dont_atexit();
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  const long *cells = p->cells;
  long n_cells = p->n_cells;
  if (p->nodes_per_cell == 1 && !cells) /* point cloud: cell i is point i */
    n_cells = p->n;
  PM_TRY(PM_ALLOC(r, 1, "results writer"));
  r->dim = dim;
  r->nodes_per_cell = p->nodes_per_cell;
  r->n_points = p->n;
  r->n_cells = n_cells;
  r->n_surface = p->n_surface;
  PM_TRY(pm_output_set_paths(r, dir));
  r->scene_text = strdup(scene_text ? scene_text : "");
  r->version = strdup(version ? version : "");
  PM_ENSURE(r->scene_text && r->version, PM_ERR_MEMORY,
            "cannot copy the scene text");
  PM_TRY(pm_mkdir_p(r->sub));
  r->created = true;
  int saved = 0;
  errno = 0;
  ret = write_mesh(r, p->x, cells, p->surface);
  if (ret == PM_SUCCESS) ret = pm_output_publish(r);
  saved = errno;
  PM_TRY(pm_output_classify(ret, saved, r->mesh_path));
  *out = r;
  r = NULL;
done:
  if (r) {
    pm_results_close(r, false);
    r = NULL;
  }
  return ret;
}

pm_err pm_results_create(const char *dir, int dim, long n_points,
                         const double *x, long n_cells, int nodes_per_cell,
                         const long *cells, const char *scene_text,
                         const char *version, pm_results **out) {
  pm_points p = {.n = n_points,
                 .x = x,
                 .n_cells = n_cells,
                 .nodes_per_cell = nodes_per_cell,
                 .cells = cells};
  return pm_results_create_ex(dir, dim, &p, scene_text, version, out);
}

void pm_results_close(pm_results *r, bool keep) {
  if (!r) return;
  if (!keep && r->created && r->n_frames == 0) {
    unlink(r->index_path);
    unlink(r->xdmf_path);
    unlink(r->mesh_path);
    unlink(r->index_spare_path);
    unlink(r->xdmf_spare_path);
    rmdir(r->sub);
  }
  pm_output_free(r);
}

/* ---- Frames ------------------------------------------------------------- */

pm_err pm_output_frame_open(const char *tmp, long step, double time,
                            hid_t *out) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1, fcpl = -1;
  const char *path = tmp;
  /* The fields keep their order (read back when a run resumes). */
  H5_OK(fcpl = H5Pcreate(H5P_FILE_CREATE), "H5Pcreate", "fcpl", path);
  H5_OK(H5Pset_link_creation_order(fcpl, H5P_CRT_ORDER_TRACKED |
                                             H5P_CRT_ORDER_INDEXED),
        "H5Pset_link_creation_order", "fcpl", path);
  H5_OK(file = H5Fcreate(tmp, H5F_ACC_TRUNC, fcpl, H5P_DEFAULT), "H5Fcreate",
        "/", path);
  PM_TRY(pm_h5_write_attr(file, "step", H5T_STD_I64LE, H5T_NATIVE_LONG, &step,
                          path));
  PM_TRY(pm_h5_write_attr(file, "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                          &time, path));
  *out = file;
  file = -1;
done:
  pm_h5_close_quiet(&fcpl);
  pm_h5_close_quiet(&file);
  return ret;
}

pm_err pm_output_frame_file(const char *tmp, long n, const long *index,
                            long step, double time, int n_fields,
                            const pm_field *fields) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1;
  const char *path = tmp;
  PM_TRY(pm_output_frame_open(tmp, step, time, &file));
  for (int i = 0; i < n_fields; i++) {
    const pm_field *f = &fields[i];
    hsize_t dims[3] = {(hsize_t)n, 3, 3};
    int rank = f->ncomp == 1 ? 1 : f->ncomp == 3 ? 2 : 3;
    PM_TRY(pm_output_dataset(file, f->name, rank, dims, H5T_IEEE_F64LE,
                             H5T_NATIVE_DOUBLE, f->data, path, NULL));
  }
  if (index) {
    const hsize_t dim = (hsize_t)n;
    PM_TRY(pm_output_dataset(file, PM_PIECE_INDEX, 1, &dim, H5T_STD_I64LE,
                             H5T_NATIVE_LONG, index, path, NULL));
  }
  H5_OK(H5Fclose(file), "H5Fclose", "/", path);
  file = -1;
done:
  pm_h5_close_quiet(&file);
  return ret;
}

pm_err pm_output_add_frame(pm_results *r, const char *tmp, pm_err written,
                           int written_errno, long step, double time,
                           int n_fields, const pm_field *fields) {
  pm_err ret = PM_SUCCESS;
  char path[PM_PATH_MAX + 1];
  pm_output_frame_path(r, r->n_frames, path, sizeof path);
  PM_TRY(pm_output_classify(written, written_errno, path));
  PM_TRY(pm_sync_rename(tmp, path));
  const char *names[16];
  int ncomp[16];
  const size_t frames_len = r->frames.len, last_at = r->last_at;
  int saved = 0;
  for (int i = 0; i < n_fields; i++) {
    names[i] = fields[i].name;
    ncomp[i] = fields[i].ncomp;
  }
  PM_TRY(
      pm_output_xdmf_frame(r, r->n_frames, step, time, n_fields, names, ncomp));
  r->n_frames++;
  errno = 0;
  ret = pm_output_publish(r);
  saved = errno;
  if (ret != PM_SUCCESS) { /* back to the frames before */
    r->n_frames--;
    r->frames.len = frames_len;
    r->last_at = last_at;
    pm_output_spares_unknown(r);
    unlink(path);
    /* The index may already list the frame: list the others again (best
     * effort; the earlier index and XDMF stay otherwise). */
    pm_err first = ret;
    r->index_published = r->n_frames;
    if (pm_output_index_commit(r) != PM_SUCCESS) {
      pm_error_clear();
      r->index_published = -1;
    }
    ret = first;
    PM_TRY(pm_output_classify(ret, saved, r->index_path));
  }
done:
  unlink(tmp);
  return ret;
}

pm_err pm_results_write_frame(pm_results *r, long step, double time,
                              int n_fields, const pm_field *fields) {
  char path[PM_PATH_MAX + 1], tmp[PM_PATH_MAX + 40];
  PM_CHECK(r, PM_ERR_ARG, "pm_results_write_frame: NULL results");
  PM_CALL(pm_output_check_fields(n_fields, fields));
  PM_CHECK(n_fields <= 16, PM_ERR_ARG, "results frame: %d fields (16 at most)",
           n_fields);
  pm_output_frame_path(r, r->n_frames, path, sizeof path);
  pm_output_tmp_name(tmp, sizeof tmp, path);
  double bytes = H5_OVERHEAD;
  for (int i = 0; i < n_fields; i++)
    bytes += 8.0 * fields[i].ncomp * (double)r->n_points;
  PM_CALL(pm_output_check_room(r->sub, path, bytes));
  errno = 0;
  pm_err written = pm_output_frame_file(tmp, r->n_points, NULL, step, time,
                                        n_fields, fields);
  return pm_output_add_frame(r, tmp, written, errno, step, time, n_fields,
                             fields);
}

long pm_results_frames(const pm_results *r) { return r ? r->n_frames : 0; }
