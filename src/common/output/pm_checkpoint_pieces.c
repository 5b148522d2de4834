/* pm_checkpoint_pieces: a checkpoint across ranks written in pieces, one a
 * rank, named by rank 0's index (pm_checkpoint.h). */
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm_checkpoint_impl.h"
#include "pm_h5.h"
#include "pm_h5_vet.h"

#define PIECES_FOLDER "checkpoint.pieces"
#define PIECE_FMT "%09ld.piece_%04d.h5"

bool pm_ckpt_has(const pm_ckpt *c, const char *name) {
  return c && c->file >= 0 && H5Lexists(c->file, name, H5P_DEFAULT) > 0;
}

pm_err pm_ckpt_pieces_folder(const char *dir) {
  char sub[PM_PATH_MAX + 1];
  PM_CALL(pm_path_join(sub, sizeof sub, dir, PIECES_FOLDER));
  return pm_mkdir_p(sub);
}

pm_err pm_ckpt_piece_path(char *buf, size_t size, const char *dir, long id,
                          int piece) {
  char sub[PM_PATH_MAX + 1], name[64];
  PM_CALL(pm_path_join(sub, sizeof sub, dir, PIECES_FOLDER));
  snprintf(name, sizeof name, PIECE_FMT, id, piece);
  return pm_path_join(buf, size, sub, name);
}

pm_err pm_ckpt_create_piece(const char *dir, long id, int piece,
                            unsigned long long *sum, pm_ckpt **out) {
  char path[PM_PATH_MAX + 1];
  *out = NULL;
  PM_CALL(pm_ckpt_piece_path(path, sizeof path, dir, id, piece));
  PM_CALL(pm_ckpt_create_at(path, out));
  (*out)->sum_out = (uint64_t *)sum;
  return PM_SUCCESS;
}

pm_err pm_ckpt_open_piece(const char *dir, long id, int piece,
                          unsigned long long sum, bool vet, pm_ckpt **out) {
  char path[PM_PATH_MAX + 1];
  const char *paths[1] = {path};
  *out = NULL;
  PM_CALL(pm_ckpt_piece_path(path, sizeof path, dir, id, piece));
  PM_CHECK(access(path, F_OK) == 0, PM_ERR_IO,
           "checkpoint '%s/checkpoint.h5' names piece %d, and %s is missing",
           dir, piece, path);
  if (vet)
    PM_CALL(pm_h5_vet(paths, 1, true, "a checkpoint piece of this program",
                      PM_ERR_IO));
  PM_CALL(pm_ckpt_open_at(path, out));
  (*out)->expect_set = true;
  (*out)->expect = sum;
  return PM_SUCCESS;
}

void pm_ckpt_set_pieces(pm_ckpt *c, long id) {
  if (c) c->pieces_id = id;
}

void pm_ckpt_drop_pieces(const char *dir, long keep) {
  char sub[PM_PATH_MAX + 1], path[PM_PATH_MAX + 1];
  if (pm_path_join(sub, sizeof sub, dir, PIECES_FOLDER)) {
    pm_error_clear();
    return;
  }
  DIR *d = opendir(sub);
  if (!d) return; /* no pieces */
  struct dirent *e;
  while ((e = readdir(d))) {
    long id = -1;
    int piece = -1, end = 0;
    /* Pieces of other checkpoints, and temporary ones a crash left (the
     * index goes in place once every rank's piece is). */
    if (sscanf(e->d_name, "%ld.piece_%d.h5%n", &id, &piece, &end) < 2 ||
        (id == keep && !e->d_name[end]))
      continue;
    if (pm_path_join(path, sizeof path, sub, e->d_name) == PM_SUCCESS)
      unlink(path);
    else
      pm_error_clear();
  }
  closedir(d);
}
