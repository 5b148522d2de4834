/* pm_output_append: results.h5 and results.xdmf brought to a new frame at
 * a cost that does not grow with the number of frames.
 *
 * Each of the two files has a spare in results/, the published file it
 * replaced, one frame behind.  A frame appends what the spare lacks (one
 * or two frames: links to results.h5's /frames, grids before
 * results.xdmf's closing tags) to the spare in place, syncs it, and
 * renames it over the published file, which becomes the spare in turn
 * (it keeps a second name, ".prev", while the rename happens).  The
 * published file is only ever replaced whole by rename, so a reader or a
 * killed run meets a complete index listing frames already on disk; a
 * spare torn by a kill is never published: a resumed run deletes the
 * spares, and a spare that is not as expected (a tail that is not
 * XDMF_TAIL, a frame count that differs, a file HDF5 cannot open or that
 * a reader holds locked) is rebuilt as a copy of the published file. */
#include <errno.h>
#include <fcntl.h>
#include <hdf5.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pm_files.h"
#include "pm_h5.h"
#include "pm_output_impl.h"

/* to replaced whole by a synced copy of from. */
static pm_err copy_file(const char *from, const char *to) {
  pm_err ret = PM_SUCCESS;
  pm_afile *f = NULL;
  char buf[65536];
  size_t n;
  FILE *in = fopen(from, "rb");
  PM_CHECK(in, PM_ERR_IO, "cannot read '%s': %s", from, strerror(errno));
  PM_TRY(pm_afile_open(to, &f));
  while ((n = fread(buf, 1, sizeof buf, in)) > 0)
    PM_ENSURE(fwrite(buf, 1, n, pm_afile_stream(f)) == n, PM_ERR_IO,
              "cannot write a copy of '%s': %s", from, strerror(errno));
  PM_ENSURE(!ferror(in), PM_ERR_IO, "cannot read '%s': %s", from,
            strerror(errno));
  ret = pm_afile_commit(f);
  f = NULL;
done:
  pm_afile_abort(f);
  fclose(in);
  return ret;
}

/* The spare index, holding frames [0, from), given links to frames
 * [from, n) and the attribute frames = n, in place. */
static pm_err index_append(const pm_results *r, long from, long n) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1, frames = -1, attr = -1;
  const char *path = r->index_spare_path;
  char name[32], target[64];
  long held = -1;
  H5_OK(file = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT), "H5Fopen", "/", path);
  PM_TRY(pm_h5_read_attr(file, "frames", H5T_NATIVE_LONG, &held, "/", path));
  PM_ENSURE(held == from, PM_ERR_HDF5, "'%s' lists %ld frames, %ld expected",
            path, held, from);
  H5_OK(frames = H5Gopen2(file, "frames", H5P_DEFAULT), "H5Gopen2", "/frames",
        path);
  for (long k = from; k < n; k++) {
    snprintf(name, sizeof name, "%06ld", k);
    snprintf(target, sizeof target, RESULTS_SUBDIR "/" FRAME_FMT, k);
    H5_OK(
        H5Lcreate_external(target, "/", frames, name, H5P_DEFAULT, H5P_DEFAULT),
        "H5Lcreate_external", name, path);
  }
  H5_OK(attr = H5Aopen(file, "frames", H5P_DEFAULT), "H5Aopen", "frames", path);
  H5_OK(H5Awrite(attr, H5T_NATIVE_LONG, &n), "H5Awrite", "frames", path);
  H5_OK(H5Aclose(attr), "H5Aclose", "frames", path);
  attr = -1;
  H5_OK(H5Gclose(frames), "H5Gclose", "/frames", path);
  frames = -1;
  hid_t f = file;
  file = -1;
  H5_OK(H5Fclose(f), "H5Fclose", "/", path);
  PM_TRY(pm_sync_file(path));
done:
  pm_h5_close_quiet(&attr);
  pm_h5_close_quiet(&frames);
  pm_h5_close_quiet(&file);
  return ret;
}

/* The spare XDMF, holding frames [0, from), given r's grids of frames
 * [from, n) before its closing tags (checked to be XDMF_TAIL), in place. */
static pm_err xdmf_append(const pm_results *r, long from, long n) {
  pm_err ret = PM_SUCCESS;
  const char *path = r->xdmf_spare_path;
  /* r's text holds frames [text_from, n), frame n - 1 from last_at. */
  PM_CHECK(from == r->text_from || from == n - 1, PM_ERR_INTERNAL,
           "the XDMF grids of frames %ld to %ld are not at hand", from, n - 1);
  const size_t off = from == r->text_from ? 0 : r->last_at;
  const size_t tail = sizeof XDMF_TAIL - 1, len = r->frames.len - off;
  char seen[sizeof XDMF_TAIL];
  struct stat st;
  int fd = open(path, O_RDWR | O_CLOEXEC);
  PM_CHECK(fd >= 0, PM_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
  PM_ENSURE(fstat(fd, &st) == 0, PM_ERR_IO, "cannot stat '%s': %s", path,
            strerror(errno));
  off_t at = st.st_size - (off_t)tail;
  PM_ENSURE(at > 0 && pread(fd, seen, tail, at) == (ssize_t)tail &&
                memcmp(seen, XDMF_TAIL, tail) == 0,
            PM_ERR_IO, "'%s' does not end as an XDMF of frames", path);
  PM_ENSURE(pwrite(fd, r->frames.s + off, len, at) == (ssize_t)len &&
                pwrite(fd, XDMF_TAIL, tail, at + (off_t)len) == (ssize_t)tail,
            PM_ERR_IO, "cannot write '%s': %s", path, strerror(errno));
  PM_ENSURE(fsync(fd) == 0, PM_ERR_IO, "cannot sync '%s': %s", path,
            strerror(errno));
done:
  close(fd);
  return ret;
}

/* The spare, brought to n frames, replaces published; the published file
 * becomes the spare (its count *spare_n; -1 when it could not be kept). */
static pm_err rotate(const char *published, const char *spare, const char *prev,
                     long n, long *published_n, long *spare_n) {
  long before = *published_n;
  (void)unlink(prev);
  bool kept = link(published, prev) == 0;
  pm_err ret = pm_rename(spare, published);
  if (ret != PM_SUCCESS) {
    if (kept) (void)unlink(prev);
    *spare_n = -1;
    return ret;
  }
  *published_n = n;
  *spare_n = kept && rename(prev, spare) == 0 ? before : -1;
  if (*spare_n < 0) (void)unlink(prev);
  return PM_SUCCESS;
}

/* One of the files that describe the frames, with its spare. */
typedef struct {
  const char *path, *spare, *prev;
  long *published, *spare_n; /* the frames each holds (-1: unknown) */
  long min_n;                /* fewest frames to append to */
  pm_err (*whole)(const pm_results *r);
  pm_err (*append)(const pm_results *r, long from, long n);
} described_by;

/* The file at n frames: appended to its spare when it holds n - 1 (at
 * least min_n - 1), else rewritten whole.  A spare that is not as
 * expected is first made a copy of the file. */
static pm_err publish_one(pm_results *r, long n, const described_by *d) {
  if (*d->published != n - 1 || n < d->min_n) {
    PM_CALL(d->whole(r));
    *d->published = n;
    return PM_SUCCESS;
  }
  long from = *d->spare_n;
  *d->spare_n = -1; /* until the append is done */
  if (from < 0 || from > n - 1 || d->append(r, from, n) != PM_SUCCESS) {
    pm_error_clear();
    PM_CALL(copy_file(d->path, d->spare));
    PM_CALL(d->append(r, n - 1, n));
  }
  return rotate(d->path, d->spare, d->prev, n, d->published, d->spare_n);
}

pm_err pm_output_publish(pm_results *r) {
  long n = r->n_frames;
  const described_by index = {
      .path = r->index_path,
      .spare = r->index_spare_path,
      .prev = r->index_prev_path,
      .published = &r->index_published,
      .spare_n = &r->index_spare,
      .min_n = 1,
      .whole = pm_output_index_commit,
      .append = index_append,
  };
  /* An XDMF of no frame is the bare mesh, without the frames' tail. */
  const described_by xdmf = {
      .path = r->xdmf_path,
      .spare = r->xdmf_spare_path,
      .prev = r->xdmf_prev_path,
      .published = &r->xdmf_published,
      .spare_n = &r->xdmf_spare,
      .min_n = 2,
      .whole = pm_output_xdmf_commit,
      .append = xdmf_append,
  };
  PM_CALL(publish_one(r, n, &index));
  PM_CALL(publish_one(r, n, &xdmf));
  /* Only the last grid is needed again (by the spare, one frame behind). */
  if (n >= 1 && r->text_from < n - 1) {
    size_t keep = r->frames.len - r->last_at;
    memmove(r->frames.s, r->frames.s + r->last_at, keep);
    r->frames.len = keep;
    r->last_at = 0;
    r->text_from = n - 1;
  }
  return PM_SUCCESS;
}

void pm_output_spares_unknown(pm_results *r) {
  r->index_spare = -1;
  r->xdmf_spare = -1;
}
