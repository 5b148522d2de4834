/* pm_h5: HDF5 error messages for the readers and writers in src/common. */
#include "pm_h5.h"

#include <stdio.h>

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
