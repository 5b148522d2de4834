/* fuzz_checkpoint: the checkpoint reader under a fuzzer.  An input is one
 * checkpoint.h5: vetted, opened, its run items read as a resumed run reads
 * them, and its checksum checked. */
#include <stdint.h>

#include "fuzz_file.h"
#include "pm_checkpoint.h"
#include "pm_h5_vet.h"
#include "pm_run_impl.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  (void)fuzz_file("checkpoint.h5", data, size);
  pm_ckpt *ck = NULL;
  pm_run_header h = {0};
  /* As `resume` reads it: vetted in a child first (scripts/fuzz.sh turns
   * the child off, so that the fuzzer sees the reader in its process). */
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
