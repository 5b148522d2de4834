/* fuzz_index: the readers of a results folder under a fuzzer: what
 * `probe` and `compare` read (a frame's points and displacements through
 * the index), and what `resume` reopens.  An input is a results folder
 * (fuzz_results_folder).
 *
 * As the program reads it (the default): probe's reader in a child that
 * passes the points and displacements back, resume's files vetted by HDF5
 * in a child (about a CPU second each: fuzz_isolate) and then reopened in
 * this process.  PM_ISOLATE=0: everything in this process. */
#include <stdint.h>
#include <stdlib.h>

#include "fuzz_file.h"
#include "pm_output.h"
#include "pm_probe.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  long n_points = 0, n_frames = 0;
  fuzz_isolate(data, size);
  if (!fuzz_results_folder(data, size, &n_points, &n_frames)) return 0;
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
