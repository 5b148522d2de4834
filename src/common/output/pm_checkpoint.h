/* pm_checkpoint: OUT/checkpoint.h5, the whole state of a run and only the
 * state, written atomically (temporary name, sync, rename) and read back
 * for `pointmech resume`.
 *
 * One function lists a state's items for both directions: in a writer each
 * call stores the item, in a reader it fills it (checking its size).  The
 * items are datasets of the root group in call order; a 64-bit checksum of
 * every name and byte, in that order, is an attribute checked when the
 * reader finishes, so a damaged or foreign file is refused with the
 * reason. */
#ifndef PM_CHECKPOINT_H
#define PM_CHECKPOINT_H

#include <stdbool.h>
#include <stddef.h>

#include "pm_error.h"

typedef struct pm_ckpt pm_ckpt;

/* Start writing dir/checkpoint.h5 (as checkpoint.h5.tmp.<pid>).  PM_ERR_IO
 * or PM_ERR_HDF5 naming the path. */
pm_err pm_ckpt_create(const char *dir, pm_ckpt **out);

/* Open dir/checkpoint.h5 for reading.  PM_ERR_IO when there is none or it
 * is not a checkpoint of this program (naming the path and why). */
pm_err pm_ckpt_open(const char *dir, pm_ckpt **out);

/* True for a reader. */
bool pm_ckpt_reading(const pm_ckpt *c);

/* The path of the checkpoint (for messages). */
const char *pm_ckpt_path(const pm_ckpt *c);

/* Items (name: letters, digits, '_', '.', unique).  Write: store n values
 * from data.  Read: the stored item must have n values of this type; fills
 * data.  A reader fails with PM_ERR_IO naming the item and the sizes. */
pm_err pm_ckpt_doubles(pm_ckpt *c, const char *name, long n, double *data);
pm_err pm_ckpt_longs(pm_ckpt *c, const char *name, long n, long *data);
pm_err pm_ckpt_ints(pm_ckpt *c, const char *name, long n, int *data);
pm_err pm_ckpt_bytes(pm_ckpt *c, const char *name, long n, unsigned char *data);
/* One value. */
pm_err pm_ckpt_double(pm_ckpt *c, const char *name, double *v);
pm_err pm_ckpt_long(pm_ckpt *c, const char *name, long *v);
/* A string: written from *text; read into a malloc'd *text (the caller
 * frees it). */
pm_err pm_ckpt_string(pm_ckpt *c, const char *name, char **text);

/* Writer: store the checksum, close, sync and rename to checkpoint.h5
 * (replacing the older one).  Reader: check that every item was read and
 * that the checksum matches (PM_ERR_IO "damaged" otherwise).  Always frees
 * c. */
pm_err pm_ckpt_finish(pm_ckpt *c);

/* Discard: a writer removes its temporary file.  Frees c (NULL
 * accepted). */
void pm_ckpt_abort(pm_ckpt *c);

#endif
