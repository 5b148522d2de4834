/* pm_files: paths, directories and output files that appear whole or not
 * at all (written under a temporary name, synced, renamed into place). */
#include "pm_files.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/types.h>
#include <unistd.h>

/* ---- Paths ------------------------------------------------------------- */

pm_err pm_path_join(char *buf, size_t size, const char *dir, const char *name) {
  int n;
  PM_CHECK(buf && size > 0 && name, PM_ERR_ARG, "pm_path_join: NULL argument");
  if (!dir || !dir[0])
    n = snprintf(buf, size, "%s", name);
  else if (dir[strlen(dir) - 1] == '/')
    n = snprintf(buf, size, "%s%s", dir, name);
  else
    n = snprintf(buf, size, "%s/%s", dir, name);
  PM_CHECK(n >= 0 && (size_t)n < size, PM_ERR_ARG,
           "path '%s/%s' is too long (%zu bytes at most)", dir ? dir : "", name,
           size - 1);
  return PM_SUCCESS;
}

/* ---- Directories -------------------------------------------------------- */

/* mkdir one component; an existing directory is fine. */
static pm_err mkdir_one(const char *path) {
  struct stat st;
  int e;
  if (mkdir(path, 0777) == 0) return PM_SUCCESS;
  e = errno;
  if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) return PM_SUCCESS;
  PM_CHECK(e != EEXIST, PM_ERR_IO,
           "cannot create directory '%s': exists and is not a directory", path);
  return PM_ERROR(PM_ERR_IO, "cannot create directory '%s': %s", path,
                  strerror(e));
}

pm_err pm_mkdir_p(const char *dir) {
  char buf[PM_PATH_MAX + 1];
  size_t len;
  PM_CHECK(dir && dir[0], PM_ERR_ARG, "pm_mkdir_p: empty directory name");
  len = strlen(dir);
  PM_CHECK(len <= PM_PATH_MAX, PM_ERR_ARG,
           "directory name too long: '%.64s...'", dir);
  memcpy(buf, dir, len + 1);
  /* Create every prefix ending before a '/', then the whole path. */
  for (size_t i = 1; i < len; i++) {
    if (buf[i] != '/' || buf[i - 1] == '/') continue;
    buf[i] = '\0';
    PM_CALL(mkdir_one(buf));
    buf[i] = '/';
  }
  PM_CALL(mkdir_one(buf));
  return PM_SUCCESS;
}

/* fsync the directory holding path (best effort: errors are ignored, some
 * file systems refuse to sync directories). */
static void sync_parent_dir(const char *path) {
  char dir[PM_PATH_MAX + 1];
  const char *slash = strrchr(path, '/');
  size_t len;
  int fd;
  if (!slash) {
    strcpy(dir, ".");
  } else {
    len = (size_t)(slash - path);
    if (len == 0) len = 1; /* "/file" */
    if (len > PM_PATH_MAX) return;
    memcpy(dir, path, len);
    dir[len] = '\0';
  }
  fd = open(dir, O_RDONLY);
  if (fd < 0) return;
  (void)fsync(fd);
  (void)close(fd);
}

pm_err pm_rename(const char *from, const char *to) {
  PM_CHECK(from && to, PM_ERR_ARG, "pm_rename: NULL path");
  PM_CHECK(rename(from, to) == 0, PM_ERR_IO, "cannot rename '%s' to '%s': %s",
           from, to, strerror(errno));
  sync_parent_dir(to);
  return PM_SUCCESS;
}

pm_err pm_sync_file(const char *path) {
  int fd = open(path, O_RDONLY | O_CLOEXEC);
  PM_CHECK(fd >= 0, PM_ERR_IO, "cannot reopen '%s' to sync it: %s", path,
           strerror(errno));
  int rc = fsync(fd), e = errno;
  close(fd);
  PM_CHECK(rc == 0, PM_ERR_IO, "cannot sync '%s': %s", path, strerror(e));
  return PM_SUCCESS;
}

pm_err pm_sync_rename(const char *tmp, const char *path) {
  PM_CALL(pm_sync_file(tmp));
  return pm_rename(tmp, path);
}

/* ---- Atomic files ------------------------------------------------------ */

struct pm_afile {
  FILE *fp;
  char *final_path; /* both point into one allocation: paths[] */
  char *tmp_path;
  char paths[];
};

/* Why a write into path failed (err: the errno seen, which a stream's
 * buffered write may have left stale): its folder gone (removed during the
 * run), a read-only or full file system, else err's text. */
/* The folder path is in, and its file system: statvfs's outcome. */
static int folder_stat(const char *path, struct statvfs *fs) {
  char dir[PM_PATH_MAX + 1];
  snprintf(dir, sizeof dir, "%s", path);
  char *slash = strrchr(dir, '/');
  if (slash) *slash = '\0';
  return statvfs(slash ? (dir[0] ? dir : "/") : ".", fs);
}

bool pm_folder_gone(const char *path) {
  struct statvfs fs;
  return folder_stat(path, &fs) != 0 && errno == ENOENT;
}

static const char *write_cause(const char *path, int err) {
  struct statvfs fs;
  if (folder_stat(path, &fs) != 0)
    return errno == ENOENT ? "its folder no longer exists" : strerror(err);
  if (fs.f_flag & ST_RDONLY) return strerror(EROFS);
  if (fs.f_bavail == 0) return strerror(ENOSPC);
  return strerror(err);
}

pm_err pm_afile_open(const char *final_path, pm_afile **out) {
  pm_err ret = PM_SUCCESS;
  pm_afile *f = NULL;
  size_t len, tmp_size;
  int n;
  PM_CHECK(out, PM_ERR_ARG, "pm_afile_open: NULL out");
  *out = NULL;
  PM_CHECK(final_path && final_path[0], PM_ERR_ARG,
           "pm_afile_open: empty path");
  len = strlen(final_path);
  PM_CHECK(len + 32 <= PM_PATH_MAX, PM_ERR_ARG, "path too long: '%.64s...'",
           final_path);
  tmp_size = len + 32;
  f = malloc(sizeof *f + len + 1 + tmp_size);
  PM_ENSURE(f, PM_ERR_MEMORY, "cannot allocate the handle for '%s'",
            final_path);
  f->fp = NULL;
  f->final_path = f->paths;
  f->tmp_path = f->paths + len + 1;
  memcpy(f->final_path, final_path, len + 1);
  n = snprintf(f->tmp_path, tmp_size, "%s.tmp.%ld", final_path, (long)getpid());
  PM_ENSURE(n > 0 && (size_t)n < tmp_size, PM_ERR_INTERNAL,
            "temporary name of '%s' truncated", final_path);
  f->fp = fopen(f->tmp_path, "w");
  PM_ENSURE(f->fp, PM_ERR_IO, "cannot open '%s' for writing: %s", f->tmp_path,
            write_cause(f->tmp_path, errno));
  *out = f;
  f = NULL;
done:
  free(f);
  return ret;
}

FILE *pm_afile_stream(pm_afile *f) { return f ? f->fp : NULL; }

const char *pm_afile_path(const pm_afile *f) {
  return f ? f->final_path : NULL;
}

pm_err pm_afile_commit(pm_afile *f) {
  pm_err ret = PM_SUCCESS;
  FILE *fp;
  if (!f) return PM_SUCCESS;
  fp = f->fp;
  PM_ENSURE(!ferror(fp), PM_ERR_IO, "cannot write '%s': %s", f->tmp_path,
            write_cause(f->tmp_path, errno));
  PM_ENSURE(fflush(fp) == 0, PM_ERR_IO, "cannot write '%s': %s", f->tmp_path,
            write_cause(f->tmp_path, errno));
  PM_ENSURE(fsync(fileno(fp)) == 0, PM_ERR_IO, "cannot sync '%s': %s",
            f->tmp_path, strerror(errno));
  f->fp = NULL; /* closed by fclose even when it fails */
  PM_ENSURE(fclose(fp) == 0, PM_ERR_IO, "cannot close '%s': %s", f->tmp_path,
            strerror(errno));
  PM_TRY(pm_rename(f->tmp_path, f->final_path));
done:
  if (ret != PM_SUCCESS) {
    if (f->fp) fclose(f->fp);
    unlink(f->tmp_path);
  }
  free(f);
  return ret;
}

void pm_afile_abort(pm_afile *f) {
  if (!f) return;
  if (f->fp) fclose(f->fp);
  unlink(f->tmp_path);
  free(f);
}
