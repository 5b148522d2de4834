/* fuzz_tiff: the TIFF stack reader under a fuzzer.  An input is one TIFF
 * file: its size is read from the page headers, then the whole stack, and
 * the image is freed, so a leak is a finding. */
#include <stdint.h>

#include "fuzz_file.h"
#include "gm_image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const double d[3] = {1e-6, 1e-6, 2e-6}, o[3] = {0, 0, 0};
  const char *path = fuzz_file("stack.tif", data, size);
  long n[3];
  gm_image im = {.v = NULL};
  if (gm_image_tiff_size(path, n) == PM_SUCCESS)
    (void)gm_image_read_tiff_path(path, d, o, &im);
  gm_image_free(&im);
  pm_error_clear();
  fuzz_clear();
  return 0;
}
