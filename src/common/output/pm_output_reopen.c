/* pm_output_reopen: the results of a run being resumed: reopened with the
 * frames up to its checkpoint, the later ones and stale temporary files
 * removed. */
#include <dirent.h>
#include <errno.h>
#include <hdf5.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm_files.h"
#include "pm_h5.h"
#include "pm_h5_vet.h"
#include "pm_output_impl.h"

/* Remove frame files of index >= n_keep, and the temporary files and
 * spares (possibly torn) left in dir/results by a run that was killed. */
static pm_err drop_later_frames(const pm_results *r, long n_keep) {
  DIR *d = opendir(r->sub);
  PM_CHECK(d, PM_ERR_IO, "cannot read '%s': %s", r->sub, strerror(errno));
  struct dirent *e;
  char path[PM_PATH_MAX + 1];
  pm_err ret = PM_SUCCESS;
  while ((e = readdir(d))) {
    long k;
    int used = 0;
    bool tmp = strstr(e->d_name, ".tmp.") != NULL ||
               strncmp(e->d_name, SPARE_PREFIX, strlen(SPARE_PREFIX)) == 0;
    int piece;
    bool later = sscanf(e->d_name, "frame_%ld.h5%n", &k, &used) == 1 &&
                 e->d_name[used] == '\0' && k >= n_keep;
    /* A frame's pieces (written across ranks) go with it. */
    used = 0;
    later = later || (sscanf(e->d_name, "frame_%ld.piece_%d.h5%n", &k, &piece,
                             &used) == 2 &&
                      used > 0 && e->d_name[used] == '\0' && k >= n_keep);
    if (!tmp && !later) continue;
    if (pm_path_join(path, sizeof path, r->sub, e->d_name) != PM_SUCCESS)
      continue;
    if (unlink(path) != 0 && errno != ENOENT) {
      ret =
          PM_ERROR(PM_ERR_IO, "cannot remove '%s': %s", path, strerror(errno));
      break;
    }
  }
  closedir(d);
  return ret;
}

/* Frame k's attributes and field list, read back into the XDMF. */
static pm_err reread_frame(pm_results *r, long k) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1, dset = -1, space = -1;
  /* 16 fields at most, and a frame in pieces its index besides. */
  char path[PM_PATH_MAX + 1], names_buf[17][FIELD_NAME_MAX + 2];
  const char *names[17];
  int ncomp[17], nf = 0;
  H5G_info_t info;
  double time;
  long step;
  pm_output_frame_path(r, k, path, sizeof path);
  H5_OK(file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT), "H5Fopen", "/",
        path);
  PM_TRY(pm_h5_read_attr(file, "time", H5T_NATIVE_DOUBLE, &time, "/", path));
  PM_TRY(pm_h5_read_attr(file, "step", H5T_NATIVE_LONG, &step, "/", path));
  H5_OK(H5Gget_info(file, &info), "H5Gget_info", "/", path);
  PM_ENSURE(info.nlinks <= 17, PM_ERR_HDF5,
            "'%s' holds %llu fields (16 at most)", path,
            (unsigned long long)info.nlinks);
  for (hsize_t i = 0; i < info.nlinks; i++, nf++) {
    ssize_t len;
    hssize_t count;
    H5_OK(len = H5Lget_name_by_idx(file, ".", H5_INDEX_CRT_ORDER, H5_ITER_INC,
                                   i, names_buf[nf], sizeof names_buf[nf],
                                   H5P_DEFAULT),
          "H5Lget_name_by_idx", "/", path);
    PM_ENSURE((size_t)len < sizeof names_buf[nf], PM_ERR_HDF5,
              "field name too long in '%s'", path);
    /* A frame in pieces: its points' one-process indices, not a field. */
    if (strcmp(names_buf[nf], PM_PIECE_INDEX) == 0) {
      nf--;
      continue;
    }
    names[nf] = names_buf[nf];
    H5_OK(dset = H5Dopen2(file, names[nf], H5P_DEFAULT), "H5Dopen2", names[nf],
          path);
    H5_OK(space = H5Dget_space(dset), "H5Dget_space", names[nf], path);
    H5_OK(count = H5Sget_simple_extent_npoints(space),
          "H5Sget_simple_extent_npoints", names[nf], path);
    ncomp[nf] = (int)(count / r->n_points);
    PM_ENSURE(count == (hssize_t)ncomp[nf] * r->n_points &&
                  (ncomp[nf] == 1 || ncomp[nf] == 3 || ncomp[nf] == 9),
              PM_ERR_HDF5, "field %s of '%s' has %lld values for %ld points",
              names[nf], path, (long long)count, r->n_points);
    pm_h5_close_quiet(&space);
    pm_h5_close_quiet(&dset);
  }
  PM_ENSURE(nf <= 16, PM_ERR_HDF5, "'%s' holds %d fields (16 at most)", path,
            nf);
  PM_TRY(pm_output_xdmf_frame(r, k, step, time, nf, names, ncomp));
done:
  pm_h5_close_quiet(&space);
  pm_h5_close_quiet(&dset);
  pm_h5_close_quiet(&file);
  return ret;
}

/* The sizes of mesh.h5's table (a rank-2 dataset) /name. */
static pm_err table_dims(hid_t file, const char *name, hsize_t dims[2],
                         const char *path) {
  pm_err ret = PM_SUCCESS;
  hid_t dset = -1, space = -1;
  H5_OK(dset = H5Dopen2(file, name, H5P_DEFAULT), "H5Dopen2", name, path);
  H5_OK(space = H5Dget_space(dset), "H5Dget_space", name, path);
  PM_ENSURE(H5Sget_simple_extent_ndims(space) == 2, PM_ERR_HDF5,
            "'%s': /%s is not a table", path, name);
  H5_OK(H5Sget_simple_extent_dims(space, dims, NULL),
        "H5Sget_simple_extent_dims", name, path);
done:
  pm_h5_close_quiet(&space);
  pm_h5_close_quiet(&dset);
  return ret;
}

/* The mesh's sizes (and its surface's) from mesh.h5. */
static pm_err reread_mesh(pm_results *r) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1;
  hsize_t dims[2];
  htri_t has_surface;
  const char *path = r->mesh_path;
  H5_OK(file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT), "H5Fopen", "/",
        path);
  PM_TRY(table_dims(file, "cells", dims, path));
  r->n_cells = (long)dims[0];
  r->nodes_per_cell = (int)dims[1];
  PM_TRY(table_dims(file, "coordinates", dims, path));
  r->n_points = (long)dims[0];
  H5_OK(has_surface = H5Lexists(file, "surface", H5P_DEFAULT), "H5Lexists",
        "surface", path);
  if (has_surface) {
    PM_TRY(table_dims(file, "surface", dims, path));
    PM_ENSURE(dims[0] >= 1 && dims[1] == 3, PM_ERR_HDF5,
              "'%s': /surface is not a table of triangles (%llu x %llu)", path,
              (unsigned long long)dims[0], (unsigned long long)dims[1]);
    r->n_surface = (long)dims[0];
  }
done:
  pm_h5_close_quiet(&file);
  return ret;
}

pm_err pm_results_reopen(const char *dir, long n_points, long n_keep,
                         pm_results **out) {
  pm_err ret = PM_SUCCESS;
  pm_results *r = NULL;
  hid_t file = -1;
  const char *path = "";
  PM_CHECK(out && n_keep >= 0, PM_ERR_ARG, "pm_results_reopen: bad arguments");
  *out = NULL;
  PM_CALL(pm_output_check_dir(dir));
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  PM_TRY(PM_ALLOC(r, 1, "results writer"));
  PM_TRY(pm_output_set_paths(r, dir));
  path = r->index_path;
  PM_TRY(pm_results_vet(r, n_keep));
  H5_OK(file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT), "H5Fopen", "/",
        path);
  PM_TRY(pm_h5_read_string_attr(file, "scene", &r->scene_text, path));
  PM_TRY(pm_h5_read_string_attr(file, "version", &r->version, path));
  PM_TRY(pm_h5_read_attr(file, "dim", H5T_NATIVE_INT, &r->dim, "/", path));
  pm_h5_close_quiet(&file);
  PM_TRY(reread_mesh(r));
  PM_ENSURE(r->n_points == n_points, PM_ERR_ARG,
            "'%s' holds %ld points, the run has %ld", r->mesh_path, r->n_points,
            n_points);
  /* The frames kept must all be readable before anything changes. */
  for (long k = 0; k < n_keep; k++) PM_TRY(reread_frame(r, k));
  r->n_frames = n_keep;
  PM_TRY(pm_output_publish(r));
  PM_TRY(drop_later_frames(r, n_keep));
  *out = r;
  r = NULL;
done:
  pm_h5_close_quiet(&file);
  pm_output_free(r);
  return ret;
}
