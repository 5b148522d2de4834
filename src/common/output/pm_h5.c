/* pm_h5: HDF5 error messages, closing on error paths and scalar attributes
 * for the readers and writers in src/common. */
#include "pm_h5.h"

#include "pm_files.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static herr_t h5_walk(unsigned n, const H5E_error2_t *err, void *data) {
  char *buf = data;
  if (n == 0 && err->desc)
    snprintf(buf, 512, "%s (in %s)", err->desc,
             err->func_name ? err->func_name : "?");
  return 0;
}

const char *pm_h5_message(void) {
  static _Thread_local char buf[512];
  buf[0] = '\0';
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, h5_walk, buf);
  if (!buf[0]) snprintf(buf, sizeof buf, "no HDF5 error message");
  return buf;
}

pm_err pm_h5_fail(const char *file, int line, const char *func,
                  const char *call, const char *obj, const char *path) {
  return pm_error_set(
      PM_ERR_HDF5, file, line, func, "%s(%s) failed on '%s': %s%s", call, obj,
      path, pm_h5_message(),
      path && pm_folder_gone(path) ? " (its folder no longer exists)" : "");
}

/* Close an identifier if open, ignoring errors (cleanup paths only). */
void pm_h5_close_quiet(hid_t *id) {
  if (*id < 0) return;
  switch (H5Iget_type(*id)) {
  case H5I_FILE: H5Fclose(*id); break;
  case H5I_GROUP: H5Gclose(*id); break;
  case H5I_DATASET: H5Dclose(*id); break;
  case H5I_DATASPACE: H5Sclose(*id); break;
  case H5I_DATATYPE: H5Tclose(*id); break;
  case H5I_ATTR: H5Aclose(*id); break;
  case H5I_GENPROP_LST: H5Pclose(*id); break;
  default: break;
  }
  *id = -1;
}

/* Scalar attribute name of file type ftype on loc written from value. */
pm_err pm_h5_write_attr(hid_t loc, const char *name, hid_t ftype, hid_t mtype,
                        const void *value, const char *path) {
  pm_err ret = PM_SUCCESS;
  hid_t space = -1, attr = -1;
  H5_OK(space = H5Screate(H5S_SCALAR), "H5Screate", name, path);
  H5_OK(attr = H5Acreate2(loc, name, ftype, space, H5P_DEFAULT, H5P_DEFAULT),
        "H5Acreate2", name, path);
  H5_OK(H5Awrite(attr, mtype, value), "H5Awrite", name, path);
  H5_OK(H5Aclose(attr), "H5Aclose", name, path);
  attr = -1;
done:
  pm_h5_close_quiet(&attr);
  pm_h5_close_quiet(&space);
  return ret;
}

/* Variable-length UTF-8 string attribute (no size limit: the text lives in
 * the global heap). */
pm_err pm_h5_write_string_attr(hid_t loc, const char *name, const char *text,
                               const char *path) {
  pm_err ret = PM_SUCCESS;
  hid_t type = -1;
  const char *value = text ? text : "";
  H5_OK(type = H5Tcopy(H5T_C_S1), "H5Tcopy", name, path);
  H5_OK(H5Tset_size(type, H5T_VARIABLE), "H5Tset_size", name, path);
  H5_OK(H5Tset_cset(type, H5T_CSET_UTF8), "H5Tset_cset", name, path);
  PM_TRY(pm_h5_write_attr(loc, name, type, type, &value, path));
done:
  pm_h5_close_quiet(&type);
  return ret;
}

/* Whether attribute attr (name) holds one value: H5Aread writes every
 * value it holds, and a damaged file's array would be written past the one
 * the reader has room for (its strings, for a string, left allocated). */
static pm_err one_value(hid_t attr, const char *name, const char *path) {
  hid_t space = H5Aget_space(attr);
  const hssize_t n = space >= 0 ? H5Sget_simple_extent_npoints(space) : -1;
  if (space >= 0) H5Sclose(space);
  PM_CHECK(n == 1, PM_ERR_HDF5,
           "'%s' is damaged: attribute %s holds %lld values, expected one",
           path, name, (long long)n);
  return PM_SUCCESS;
}

/* Read scalar attribute name of loc into value (memory type mtype). */
pm_err pm_h5_read_attr(hid_t loc, const char *name, hid_t mtype, void *value,
                       const char *obj, const char *path) {
  pm_err ret = PM_SUCCESS;
  hid_t attr = -1;
  H5_OK(attr = H5Aopen(loc, name, H5P_DEFAULT), "H5Aopen", obj, path);
  PM_TRY(one_value(attr, name, path));
  H5_OK(H5Aread(attr, mtype, value), "H5Aread", obj, path);
  H5_OK(H5Aclose(attr), "H5Aclose", obj, path);
  attr = -1;
done:
  pm_h5_close_quiet(&attr);
  return ret;
}

/* A variable-length string attribute as a malloc'd copy (*out). */
pm_err pm_h5_read_string_attr(hid_t loc, const char *name, char **out,
                              const char *path) {
  pm_err ret = PM_SUCCESS;
  hid_t attr = -1, type = -1;
  char *value = NULL;
  *out = NULL;
  H5_OK(attr = H5Aopen(loc, name, H5P_DEFAULT), "H5Aopen", name, path);
  /* Read in the attribute's own type (character set included). */
  H5_OK(type = H5Aget_type(attr), "H5Aget_type", name, path);
  PM_ENSURE(H5Tget_class(type) == H5T_STRING && H5Tis_variable_str(type) > 0,
            PM_ERR_HDF5, "attribute %s of '%s' is not a string", name, path);
  PM_TRY(one_value(attr, name, path));
  H5_OK(H5Aread(attr, type, &value), "H5Aread", name, path);
  *out = strdup(value ? value : "");
  PM_ENSURE(*out, PM_ERR_MEMORY, "cannot copy attribute %s of '%s'", name,
            path);
done:
  if (value) H5free_memory(value);
  pm_h5_close_quiet(&type);
  pm_h5_close_quiet(&attr);
  return ret;
}
