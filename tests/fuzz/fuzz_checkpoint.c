/* fuzz_checkpoint: the checkpoint reader under a fuzzer.  An input is one
 * checkpoint.h5: vetted, opened, its run items read as a resumed run reads
 * them, and its checksum checked.
 *
 * As the program reads it (the default): vetted by HDF5 in a child
 * (pm_h5_vet.h, about a CPU second each: fuzz_isolate), then read in this
 * process, so a crash, leak, sanitizer report or hang here is one of the
 * program's.  PM_ISOLATE=0: no child (the vetting's walk is then not
 * run; the reader meets whatever libhdf5 does, under coverage). */
#include <stdint.h>

#include "fuzz_file.h"
#include "pm_checkpoint.h"
#include "pm_h5_vet.h"
#include "pm_run_impl.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fuzz_isolate(data, size);
  (void)fuzz_file("checkpoint.h5", data, size);
  pm_ckpt *ck = NULL;
  pm_run_header h = {0};
  /* As `resume` reads it: vetted in a child first. */
  if (pm_ckpt_vet(fuzz_dir()) == PM_SUCCESS &&
      pm_ckpt_open(fuzz_dir(), &ck) == PM_SUCCESS) {
    pm_err e = pm_run_header_items(ck, &h);
    if (e == PM_SUCCESS) {
      (void)pm_ckpt_finish(ck);
    } else {
      pm_ckpt_abort(ck);
    }
  }
  pm_run_header_free(&h);
  pm_error_clear();
  fuzz_clear();
  return 0;
}
