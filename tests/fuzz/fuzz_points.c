/* fuzz_points: the point file readers under a fuzzer.  An input is one
 * text file, read as a point cloud (a membrane's or a curve's: comma
 * separated as .csv, white-space separated otherwise; in 2-D and 3-D) and
 * as voxel centres of an image (on a 16 x 16 x 4 grid of micrometre
 * voxels). */
#include <stdint.h>
#include <stdlib.h>

#include "fuzz_file.h"
#include "gm_curve.h"
#include "gm_image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void cloud(const char *path, int dim) {
  long n = 0;
  double *x = NULL, *share = NULL;
  (void)gm_points_load(path, dim, &n, &x, &share);
  free(x);
  free(share);
  pm_error_clear();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const long n[3] = {16, 16, 4};
  const double d[3] = {1e-6, 1e-6, 1e-6}, o[3] = {0, 0, 0};
  const char *csv = fuzz_file("cloud.csv", data, size);
  cloud(csv, 2);
  cloud(csv, 3);
  const char *xyz = fuzz_file("cloud.xyz", data, size);
  cloud(xyz, 2);
  cloud(xyz, 3);
  gm_image im = {.v = NULL};
  (void)gm_image_read_points(xyz, 1e-6, n, d, o, &im);
  gm_image_free(&im);
  pm_error_clear();
  fuzz_clear();
  return 0;
}
