/* fuzz_raw: the raw volume reader under a fuzzer.  An input's first four
 * bytes are what a scene gives beside the file: nx, ny, nz (0 to 255 each)
 * and the bits per voxel (the byte's low five bits: 8 and 16 are the valid
 * ones); the rest is the file. */
#include <stdint.h>

#include "fuzz_file.h"
#include "gm_image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const double d[3] = {1e-6, 1e-6, 1e-6}, o[3] = {0, 0, 0};
  if (size < 4) return 0;
  const long n[3] = {data[0], data[1], data[2]};
  const int bits = data[3] & 31;
  const char *path = fuzz_file("volume.raw", data + 4, size - 4);
  gm_image im = {.v = NULL};
  (void)gm_image_read_raw(path, n, bits, d, o, &im);
  gm_image_free(&im);
  pm_error_clear();
  fuzz_clear();
  return 0;
}
