/* frame_read: a dataset of one frame of a run's results read whole
 * through OUT/results.h5 (the index's links, and a frame written in
 * pieces through its virtual datasets), for the tests of the results
 * writer (test_output_pieces, ranks_output). */
#ifndef FRAME_READ_H
#define FRAME_READ_H

#include <hdf5.h>
#include <stdbool.h>
#include <stdio.h>

/* Dataset name of frame k of the results in dir into out (memory type
 * mtype); false when it cannot be read. */
static inline bool pm_test_read_frame(const char *dir, long k, const char *name,
                                      hid_t mtype, void *out) {
  char path[4096], obj[96];
  snprintf(path, sizeof path, "%s/results.h5", dir);
  snprintf(obj, sizeof obj, "/frames/%06ld/%s", k, name);
  hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  hid_t d = file >= 0 ? H5Dopen2(file, obj, H5P_DEFAULT) : -1;
  bool ok =
      d >= 0 && H5Dread(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) >= 0;
  if (d >= 0) H5Dclose(d);
  if (file >= 0) H5Fclose(file);
  return ok;
}

#endif
