/* pm_h5: private helpers of the HDF5 readers and writers in src/common:
 * HDF5's own error message, and a check macro that names call and object. */
#ifndef PM_H5_H
#define PM_H5_H

#include <hdf5.h>

#include "pm_error.h"

/* The most specific message on HDF5's error stack (the stack is not
 * cleared by H5E calls, so this works right after a failed call).  Points
 * to a per-thread buffer valid until the next call. */
const char *pm_h5_message(void);

/* Close an identifier if open, ignoring errors (cleanup paths only), and
 * set it to -1. */
void pm_h5_close_quiet(hid_t *id);

/* Scalar attribute name on loc: written from value (file type ftype,
 * memory type mtype), or read into value; a variable-length UTF-8 string
 * attribute written from text (NULL as ""), or read into a malloc'd copy
 * *out.  PM_ERR_HDF5 naming the call, obj and path. */
pm_err pm_h5_write_attr(hid_t loc, const char *name, hid_t ftype, hid_t mtype,
                        const void *value, const char *path);
pm_err pm_h5_write_string_attr(hid_t loc, const char *name, const char *text,
                               const char *path);
pm_err pm_h5_read_attr(hid_t loc, const char *name, hid_t mtype, void *value,
                       const char *obj, const char *path);
pm_err pm_h5_read_string_attr(hid_t loc, const char *name, char **out,
                              const char *path);

/* Check an herr_t / hid_t result: a negative value fails with PM_ERR_HDF5
 * naming the call, the object and the file (needs `ret` and `done`). */
#define H5_OK(expr, call, obj, path)                                           \
  do {                                                                         \
    if ((expr) < 0) {                                                          \
      ret = pm_h5_fail(__FILE__, __LINE__, __func__, (call), (obj), (path));   \
      goto done;                                                               \
    }                                                                          \
  } while (0)
/* H5_OK's error: HDF5's message, and where path's folder no longer exists
 * (HDF5's own words then vary with the moment it was removed) that too. */
pm_err pm_h5_fail(const char *file, int line, const char *func,
                  const char *call, const char *obj, const char *path);

#endif
