/* fuzz_index: the readers of a results folder under a fuzzer: what
 * `probe` and `compare` read (a frame's points and displacements through
 * the index), and what `resume` reopens.  An input is the folder's files joined
 * by the separator below: results.h5 (the index), results/mesh.h5, then frames
 * 0, 1, ... (as many as follow, up to 8: the frames kept).  The mesh's point
 * count the resumed run expects is the first 4 bytes (little-endian). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_file.h"
#include "pm_output.h"
#include "pm_probe.h"

#define SEP "\n--pm-fuzz-file--\n"
#define MAX_FRAMES 8

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The next part of the input from *at (to the separator or the end). */
static size_t next_part(const uint8_t *data, size_t size, size_t *at,
                        size_t *len) {
  const size_t sep = sizeof SEP - 1, start = *at;
  for (size_t k = start; k + sep <= size; k++)
    if (memcmp(data + k, SEP, sep) == 0) {
      *len = k - start;
      *at = k + sep;
      return start;
    }
  *len = size - start;
  *at = size + 1;
  return start;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 4) return 0;
  const long n_points =
      (long)((uint32_t)data[0] | (uint32_t)data[1] << 8 |
             (uint32_t)data[2] << 16 | (uint32_t)data[3] << 24);
  size_t at = 4, len;
  long n_frames = -2; /* the index and the mesh come first */
  char name[64];
  while (at <= size && n_frames < MAX_FRAMES) {
    size_t start = next_part(data, size, &at, &len);
    if (n_frames == -2)
      snprintf(name, sizeof name, "results.h5");
    else if (n_frames == -1)
      snprintf(name, sizeof name, "results/mesh.h5");
    else
      snprintf(name, sizeof name, "results/frame_%06ld.h5", n_frames);
    (void)fuzz_file(name, data + start, len);
    n_frames++;
  }
  /* The first and the last frame, as probe reads them. */
  for (long frame = 0; frame >= -1; frame--) {
    long n = 0;
    double *x = NULL, *u = NULL;
    (void)pm_results_read(fuzz_dir(), frame, &n, &x, &u);
    free(x);
    free(u);
    pm_error_clear();
  }
  pm_results *r = NULL;
  if (pm_results_reopen(fuzz_dir(), n_points, n_frames > 0 ? n_frames : 0,
                        &r) == PM_SUCCESS)
    (void)pm_results_frames(r);
  pm_results_close(r, true);
  pm_error_clear();
  fuzz_clear();
  return 0;
}
