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

/* fsync the closed file path. */
static pm_err sync_file(const char *path) {
  int fd = open(path, O_RDONLY | O_CLOEXEC);
  PM_CHECK(fd >= 0, PM_ERR_IO, "cannot reopen '%s' to sync it: %s", path,
           strerror(errno));
  int rc = fsync(fd), e = errno;
  close(fd);
  PM_CHECK(rc == 0, PM_ERR_IO, "cannot sync '%s': %s", path, strerror(e));
  return PM_SUCCESS;
}

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
  PM_TRY(sync_file(path));
done:
  pm_h5_close_quiet(&attr);
  pm_h5_close_quiet(&frames);
  pm_h5_close_quiet(&file);
  return ret;
}

/* The spare XDMF given r's grids from byte off on before its closing tags
 * (checked to be XDMF_TAIL), in place. */
static pm_err xdmf_append(const pm_results *r, size_t off) {
  pm_err ret = PM_SUCCESS;
  const char *path = r->xdmf_spare_path;
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

/* results.h5 at n frames: appended to its spare when results.h5 holds
 * n - 1, else rewritten whole. */
static pm_err publish_index(pm_results *r, long n) {
  if (r->index_published != n - 1 || n < 1) {
    PM_CALL(pm_output_index_commit(r));
    r->index_published = n;
    return PM_SUCCESS;
  }
  long from = r->index_spare;
  r->index_spare = -1; /* until the append is done */
  if (from < 0 || from > n - 1 || index_append(r, from, n) != PM_SUCCESS) {
    pm_error_clear();
    PM_CALL(copy_file(r->index_path, r->index_spare_path));
    PM_CALL(index_append(r, n - 1, n));
  }
  return rotate(r->index_path, r->index_spare_path, r->index_prev_path, n,
                &r->index_published, &r->index_spare);
}

/* results.xdmf at n frames: r's grids appended to its spare when
 * results.xdmf holds n - 1 >= 1 frames, else rewritten whole. */
static pm_err publish_xdmf(pm_results *r, long n) {
  if (r->xdmf_published != n - 1 || n < 2) {
    PM_CALL(pm_output_xdmf_commit(r));
    r->xdmf_published = n;
    return PM_SUCCESS;
  }
  long from = r->xdmf_spare;
  r->xdmf_spare = -1;
  bool known = from >= 1 && (from == r->text_from || from == n - 1);
  size_t off = from == r->text_from ? 0 : r->last_at;
  if (!known || xdmf_append(r, off) != PM_SUCCESS) {
    pm_error_clear();
    PM_CALL(copy_file(r->xdmf_path, r->xdmf_spare_path));
    PM_CALL(xdmf_append(r, r->last_at));
  }
  return rotate(r->xdmf_path, r->xdmf_spare_path, r->xdmf_prev_path, n,
                &r->xdmf_published, &r->xdmf_spare);
}

pm_err pm_output_publish(pm_results *r) {
  long n = r->n_frames;
  PM_CALL(publish_index(r, n));
  PM_CALL(publish_xdmf(r, n));
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
