/* pm_checkpoint_impl: the checkpoint handle, shared by the whole file's
 * items (pm_checkpoint.c) and the pieces a checkpoint across ranks is
 * written in (pm_checkpoint_pieces.c); not for other callers. */
#ifndef PM_CHECKPOINT_IMPL_H
#define PM_CHECKPOINT_IMPL_H

#include <hdf5.h>
#include <stdint.h>

#include "pm_checkpoint.h"
#include "pm_files.h"

#define CKPT_FORMAT "pointmech checkpoint 1"

struct pm_ckpt {
  hid_t file;
  bool reading;
  long items;
  uint64_t sum; /* FNV-1a over names and bytes, in call order */
  /* A reader of a piece: the checksum its index names (expect_set). */
  bool expect_set;
  uint64_t expect;
  /* A writer: where finish stores the checksum (may be NULL). */
  uint64_t *sum_out;
  /* The output folder's checkpoint.h5 (not a piece): its folder, and the
   * pieces it names (-1: none), whose older ones go once it is in place. */
  bool index;
  long pieces_id;
  char dir[PM_PATH_MAX + 1];
  char path[PM_PATH_MAX + 1];
  char tmp[PM_PATH_MAX + 40];
};

#endif
