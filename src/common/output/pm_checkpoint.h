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

/* pm_ckpt_create and pm_ckpt_open of a file at path (a piece). */
pm_err pm_ckpt_create_at(const char *path, pm_ckpt **out);
pm_err pm_ckpt_open_at(const char *path, pm_ckpt **out);

/* Whether the file of reader c has an item name (a checkpoint's layout:
 * whole, or an index of pieces).  Reads nothing: the checksum is
 * untouched. */
bool pm_ckpt_has(const pm_ckpt *c, const char *name);

/* ---- A checkpoint in pieces (a run shared among ranks) ------------------
 *
 * Each rank writes its share's state as a piece,
 * OUT/checkpoint.pieces/ID.piece_RRRR.h5 (ID the checkpoint's step), a
 * checkpoint file of its own (items, checksum, written aside and renamed);
 * rank 0 then writes OUT/checkpoint.h5 as the index naming them: their
 * count, ID, each piece's checksum and what the backend records of it.
 * Only once the index is in place do the older checkpoint's pieces go, so
 * a crash at any point leaves a whole checkpoint, the older or the new. */

/* The folder of the pieces, made if missing (rank 0, before the ranks
 * write).  PM_ERR_IO naming it. */
pm_err pm_ckpt_pieces_folder(const char *dir);
/* The path of piece `piece` of checkpoint id under output folder dir. */
pm_err pm_ckpt_piece_path(char *buf, size_t size, const char *dir, long id,
                          int piece);
/* Start writing piece `piece` of checkpoint id; its finish stores the
 * checksum of its items into *sum (the index records it). */
pm_err pm_ckpt_create_piece(const char *dir, long id, int piece,
                            unsigned long long *sum, pm_ckpt **out);
/* Open piece `piece` of checkpoint id for reading, with vet first vetted
 * as `resume` vets the index (pm_h5_vet, in a child process); its finish
 * also refuses a checksum other than sum, the one the index names.
 * PM_ERR_IO naming the piece. */
pm_err pm_ckpt_open_piece(const char *dir, long id, int piece,
                          unsigned long long sum, bool vet, pm_ckpt **out);
/* The index writer c names the pieces of checkpoint id: once it is in
 * place (pm_ckpt_finish) the other pieces in the folder are removed. */
void pm_ckpt_set_pieces(pm_ckpt *c, long id);
/* Remove the pieces in dir's pieces folder but those of checkpoint keep
 * (-1: all); what cannot be removed stays (a later checkpoint retries). */
void pm_ckpt_drop_pieces(const char *dir, long keep);

#endif
