/* pm_checkpoint: named items in one HDF5 file with a checksum over them. */
#include "pm_checkpoint.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm_checkpoint_impl.h"
#include "pm_h5.h"

static void sum_bytes(pm_ckpt *c, const void *data, size_t n) {
  const unsigned char *p = data;
  uint64_t h = c->sum;
  for (size_t i = 0; i < n; i++) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  c->sum = h;
}

bool pm_ckpt_reading(const pm_ckpt *c) { return c->reading; }

const char *pm_ckpt_path(const pm_ckpt *c) { return c->path; }

static pm_ckpt *ckpt_new(void) {
  pm_ckpt *c = calloc(1, sizeof *c);
  if (c) {
    c->file = -1;
    c->pieces_id = -1;
    c->sum = 14695981039346656037ull;
  }
  return c;
}

pm_err pm_ckpt_create(const char *dir, pm_ckpt **out) {
  char path[PM_PATH_MAX + 1];
  *out = NULL;
  PM_CALL(pm_path_join(path, sizeof path, dir, "checkpoint.h5"));
  PM_CALL(pm_ckpt_create_at(path, out));
  (*out)->index = true;
  snprintf((*out)->dir, sizeof(*out)->dir, "%s", dir);
  return PM_SUCCESS;
}

pm_err pm_ckpt_create_at(const char *path, pm_ckpt **out) {
  pm_err ret = PM_SUCCESS;
  pm_ckpt *c = ckpt_new();
  *out = NULL;
  PM_CHECK(c, PM_ERR_MEMORY, "cannot allocate a checkpoint writer");
  PM_TRY(pm_path_join(c->path, sizeof c->path, "", path));
  snprintf(c->tmp, sizeof c->tmp, "%s.tmp.%ld", c->path, (long)getpid());
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  H5_OK(c->file = H5Fcreate(c->tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
        "H5Fcreate", "/", c->tmp);
  PM_TRY(pm_h5_write_string_attr(c->file, "format", CKPT_FORMAT, c->tmp));
  *out = c;
  c = NULL;
done:
  pm_ckpt_abort(c);
  return ret;
}

pm_err pm_ckpt_open(const char *dir, pm_ckpt **out) {
  char path[PM_PATH_MAX + 1];
  *out = NULL;
  PM_CALL(pm_path_join(path, sizeof path, dir, "checkpoint.h5"));
  PM_CHECK(access(path, F_OK) == 0, PM_ERR_IO,
           "'%s' holds no checkpoint (%s): set output.checkpoint in the "
           "scene, or stop runs with SIGINT or SIGTERM, to have one",
           dir, path);
  PM_CALL(pm_ckpt_open_at(path, out));
  snprintf((*out)->dir, sizeof(*out)->dir, "%s", dir);
  return PM_SUCCESS;
}

pm_err pm_ckpt_open_at(const char *path, pm_ckpt **out) {
  pm_err ret = PM_SUCCESS;
  pm_ckpt *c = ckpt_new();
  char *fmt = NULL;
  *out = NULL;
  PM_CHECK(c, PM_ERR_MEMORY, "cannot allocate a checkpoint reader");
  c->reading = true;
  PM_TRY(pm_path_join(c->path, sizeof c->path, "", path));
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  c->file = H5Fopen(c->path, H5F_ACC_RDONLY, H5P_DEFAULT);
  PM_ENSURE(c->file >= 0, PM_ERR_IO,
            "checkpoint '%s' is damaged: HDF5 cannot open it (%s)", c->path,
            pm_h5_message());
  if (pm_h5_read_string_attr(c->file, "format", &fmt, c->path) != PM_SUCCESS)
    pm_error_clear();
  PM_ENSURE(fmt && strcmp(fmt, CKPT_FORMAT) == 0, PM_ERR_IO,
            "'%s' is not a checkpoint of this program (format %s)", c->path,
            fmt ? fmt : "missing");
  *out = c;
  c = NULL;
done:
  free(fmt);
  pm_ckpt_abort(c);
  return ret;
}

/* Write or read item name of n values of size bytes each (HDF5 types ftype
 * in the file, mtype in memory). */
static pm_err item(pm_ckpt *c, const char *name, long n, size_t size,
                   hid_t ftype, hid_t mtype, void *data) {
  pm_err ret = PM_SUCCESS;
  hid_t space = -1, dset = -1;
  hsize_t dims[1] = {(hsize_t)(n > 0 ? n : 0)};
  const char *path = c->reading ? c->path : c->tmp;
  PM_CHECK(n >= 0 && (n == 0 || data), PM_ERR_ARG,
           "checkpoint item %s: %ld values", name, n);
  sum_bytes(c, name, strlen(name) + 1);
  if (c->reading) {
    hsize_t have = 0;
    dset = H5Dopen2(c->file, name, H5P_DEFAULT);
    PM_ENSURE(dset >= 0, PM_ERR_IO,
              "checkpoint '%s' is damaged or from another scene: it has no "
              "item %s",
              path, name);
    H5_OK(space = H5Dget_space(dset), "H5Dget_space", name, path);
    PM_ENSURE(H5Sget_simple_extent_ndims(space) == 1, PM_ERR_IO,
              "checkpoint '%s' is damaged: item %s is not a list", path, name);
    H5_OK(H5Sget_simple_extent_dims(space, &have, NULL),
          "H5Sget_simple_extent_dims", name, path);
    PM_ENSURE(have == dims[0], PM_ERR_IO,
              "checkpoint '%s': item %s has %llu values, this run has %ld "
              "(another scene or program version)",
              path, name, (unsigned long long)have, n);
    if (n > 0)
      H5_OK(H5Dread(dset, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data),
            "H5Dread", name, path);
  } else {
    H5_OK(space = H5Screate_simple(1, dims, NULL), "H5Screate_simple", name,
          path);
    H5_OK(dset = H5Dcreate2(c->file, name, ftype, space, H5P_DEFAULT,
                            H5P_DEFAULT, H5P_DEFAULT),
          "H5Dcreate2", name, path);
    if (n > 0)
      H5_OK(H5Dwrite(dset, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data),
            "H5Dwrite", name, path);
  }
  sum_bytes(c, data, (size_t)n * size);
  c->items++;
done:
  if (dset >= 0) H5Dclose(dset);
  if (space >= 0) H5Sclose(space);
  return ret;
}

pm_err pm_ckpt_doubles(pm_ckpt *c, const char *name, long n, double *data) {
  return item(c, name, n, sizeof *data, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
              data);
}

pm_err pm_ckpt_longs(pm_ckpt *c, const char *name, long n, long *data) {
  return item(c, name, n, sizeof *data, H5T_STD_I64LE, H5T_NATIVE_LONG, data);
}

pm_err pm_ckpt_ints(pm_ckpt *c, const char *name, long n, int *data) {
  return item(c, name, n, sizeof *data, H5T_STD_I32LE, H5T_NATIVE_INT, data);
}

pm_err pm_ckpt_bytes(pm_ckpt *c, const char *name, long n,
                     unsigned char *data) {
  return item(c, name, n, 1, H5T_STD_U8LE, H5T_NATIVE_UCHAR, data);
}

pm_err pm_ckpt_double(pm_ckpt *c, const char *name, double *v) {
  return pm_ckpt_doubles(c, name, 1, v);
}

pm_err pm_ckpt_long(pm_ckpt *c, const char *name, long *v) {
  return pm_ckpt_longs(c, name, 1, v);
}

pm_err pm_ckpt_string(pm_ckpt *c, const char *name, char **text) {
  /* Its length first, then its bytes. */
  char lname[96];
  long len = c->reading ? 0 : (long)strlen(*text);
  snprintf(lname, sizeof lname, "%s.length", name);
  PM_CALL(pm_ckpt_long(c, lname, &len));
  if (c->reading) {
    PM_CHECK(len >= 0 && len < (1L << 30), PM_ERR_IO,
             "checkpoint '%s' is damaged: string %s of length %ld", c->path,
             name, len);
    *text = calloc((size_t)len + 1, 1);
    PM_CHECK(*text, PM_ERR_MEMORY, "cannot allocate checkpoint string %s",
             name);
  }
  return pm_ckpt_bytes(c, name, len, (unsigned char *)*text);
}

pm_err pm_ckpt_finish(pm_ckpt *c) {
  pm_err ret = PM_SUCCESS;
  hid_t space = -1, attr = -1;
  unsigned long long stored[2] = {0, 0}, now[2] = {c->sum, (uint64_t)c->items};
  hsize_t two = 2;
  if (!c) return PM_SUCCESS;
  if (c->reading) {
    attr = H5Aopen(c->file, "checksum", H5P_DEFAULT);
    if (attr >= 0) {
      space = H5Aget_space(attr);
      bool two = space >= 0 && H5Sget_simple_extent_npoints(space) == 2;
      PM_ENSURE(two, PM_ERR_IO,
                "checkpoint '%s' is damaged: its checksum is not two numbers",
                c->path);
    }
    PM_ENSURE(attr >= 0 && H5Aread(attr, H5T_NATIVE_ULLONG, stored) >= 0,
              PM_ERR_IO, "checkpoint '%s' is damaged: it has no checksum",
              c->path);
    PM_ENSURE(stored[1] == now[1], PM_ERR_IO,
              "checkpoint '%s' holds %llu items, this run reads %llu "
              "(another scene or program version)",
              c->path, stored[1], now[1]);
    PM_ENSURE(stored[0] == now[0], PM_ERR_IO,
              "checkpoint '%s' is damaged: checksum %016llx, the data sum to "
              "%016llx",
              c->path, stored[0], now[0]);
    PM_ENSURE(!c->expect_set || stored[0] == c->expect, PM_ERR_IO,
              "checkpoint '%s' is not the one its index names: checksum "
              "%016llx, the index has %016llx (a piece of another "
              "checkpoint)",
              c->path, stored[0], (unsigned long long)c->expect);
  } else {
    H5_OK(space = H5Screate_simple(1, &two, NULL), "H5Screate_simple",
          "checksum", c->tmp);
    H5_OK(attr = H5Acreate2(c->file, "checksum", H5T_STD_U64LE, space,
                            H5P_DEFAULT, H5P_DEFAULT),
          "H5Acreate2", "checksum", c->tmp);
    H5_OK(H5Awrite(attr, H5T_NATIVE_ULLONG, now), "H5Awrite", "checksum",
          c->tmp);
    H5_OK(H5Aclose(attr), "H5Aclose", "checksum", c->tmp);
    attr = -1;
    hid_t f = c->file;
    c->file = -1;
    H5_OK(H5Fclose(f), "H5Fclose", "/", c->tmp);
    PM_TRY(pm_sync_rename(c->tmp, c->path));
    c->tmp[0] = '\0';
    if (c->sum_out) *c->sum_out = c->sum;
    /* The index in place: the pieces of older checkpoints go (a crash
     * before this leaves them, and the older index naming them, whole). */
    if (c->index) pm_ckpt_drop_pieces(c->dir, c->pieces_id);
  }
done:
  if (attr >= 0) H5Aclose(attr);
  if (space >= 0) H5Sclose(space);
  pm_ckpt_abort(c);
  return ret;
}

void pm_ckpt_abort(pm_ckpt *c) {
  if (!c) return;
  if (c->file >= 0) H5Fclose(c->file);
  if (!c->reading && c->tmp[0]) unlink(c->tmp);
  free(c);
}
