/* pm_output_write: an HDF5 file of the results written whole (under a
 * temporary name, committed by rename), its room checked before it is
 * written, the system's causes of a failure named, and its datasets. */
#include <errno.h>
#include <hdf5.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include "pm_files.h"
#include "pm_h5.h"
#include "pm_output_impl.h"

/* ---- Files written whole ------------------------------------------------ */

/* path + ".tmp.<pid>" into buf. */
void pm_output_tmp_name(char *buf, size_t size, const char *path) {
  snprintf(buf, size, "%s.tmp.%ld", path, (long)getpid());
}

/* Close the HDF5 file written under tmp and commit it to path. */
pm_err pm_output_commit(hid_t *file, const char *tmp, const char *path) {
  hid_t f = *file;
  *file = -1;
  PM_CHECK(H5Fclose(f) >= 0, PM_ERR_HDF5, "H5Fclose(/) failed on '%s': %s", tmp,
           pm_h5_message());
  return pm_sync_rename(tmp, path);
}

/* An HDF5 failure that the system caused (no space, file too large, no
 * permission) is an I/O error, named with the system's reason. */
pm_err pm_output_classify(pm_err e, int saved_errno, const char *path) {
  if (e != PM_ERR_HDF5) return e;
  if (saved_errno == ENOSPC || saved_errno == EFBIG || saved_errno == EDQUOT ||
      saved_errno == EACCES || saved_errno == EROFS || saved_errno == EIO) {
    pm_error_clear();
    return PM_ERROR(PM_ERR_IO, "cannot write '%s': %s", path,
                    strerror(saved_errno));
  }
  return e;
}

/* Refuse a file of about bytes that the file size limit or the free space
 * on dir's disk cannot hold, before HDF5 meets it half-way (a file HDF5
 * cannot flush cannot be closed either). */
pm_err pm_output_check_room(const char *dir, const char *path, double bytes) {
  struct rlimit rl;
  struct statvfs vfs;
  if (getrlimit(RLIMIT_FSIZE, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY &&
      bytes > (double)rl.rlim_cur)
    return PM_ERROR(PM_ERR_IO,
                    "cannot write '%s': File too large (about %.0f bytes; "
                    "the file size limit, ulimit -f, is %.0f bytes)",
                    path, bytes, (double)rl.rlim_cur);
  if (statvfs(dir, &vfs) == 0 &&
      bytes > (double)vfs.f_bavail * (double)vfs.f_frsize)
    return PM_ERROR(PM_ERR_IO,
                    "cannot write '%s': No space left on device (about %.0f "
                    "bytes, %.0f free)",
                    path, bytes, (double)vfs.f_bavail * (double)vfs.f_frsize);
  return PM_SUCCESS;
}

/* ---- Datasets ----------------------------------------------------------- */

/* Write the dataset loc/name of rank dims (file type ftype, memory mtype). */
pm_err pm_output_dataset(hid_t loc, const char *name, int rank,
                         const hsize_t *dims, hid_t ftype, hid_t mtype,
                         const void *data, const char *path, hid_t *keep_open) {
  pm_err ret = PM_SUCCESS;
  hid_t space = -1, dset = -1;
  H5_OK(space = H5Screate_simple(rank, dims, NULL), "H5Screate_simple", name,
        path);
  H5_OK(dset = H5Dcreate2(loc, name, ftype, space, H5P_DEFAULT, H5P_DEFAULT,
                          H5P_DEFAULT),
        "H5Dcreate2", name, path);
  if (data)
    H5_OK(H5Dwrite(dset, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data),
          "H5Dwrite", name, path);
  if (keep_open) {
    *keep_open = dset;
    dset = -1;
  } else {
    H5_OK(H5Dclose(dset), "H5Dclose", name, path);
    dset = -1;
  }
done:
  pm_h5_close_quiet(&dset);
  pm_h5_close_quiet(&space);
  return ret;
}
