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

/* Check an herr_t / hid_t result: a negative value fails with PM_ERR_HDF5
 * naming the call, the object and the file (needs `ret` and `done`). */
#define H5_OK(expr, call, obj, path)                                           \
  do {                                                                         \
    if ((expr) < 0) {                                                          \
      ret = pm_error_set(PM_ERR_HDF5, __FILE__, __LINE__, __func__,            \
                         "%s(%s) failed on '%s': %s", (call), (obj), (path),   \
                         pm_h5_message());                                     \
      goto done;                                                               \
    }                                                                          \
  } while (0)

#endif
