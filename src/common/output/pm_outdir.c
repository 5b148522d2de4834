/* pm_outdir: a run's output folder: claimed (created, checked, locked)
 * for one run at a time, and its summary's status read back. */
#include "pm_outdir.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "pm_files.h"

struct pm_outdir {
  int fd;       /* the lock file, flock'ed for the run's life */
  bool created; /* the claim created the folder */
  char dir[PM_PATH_MAX + 1];
};

/* The files a run writes in its folder (results/ holds the frames). */
static const char *const run_files[] = {"summary.json",  "history.csv",
                                        "results.h5",    "results.xdmf",
                                        "checkpoint.h5", "checkpoint.pieces"};
#define N_RUN_FILES (sizeof run_files / sizeof *run_files)
#define LOCK_NAME ".pointmech.lock"

void pm_summary_status(const char *dir, char *buf, size_t size) {
  char path[PM_PATH_MAX + 1], line[512];
  buf[0] = '\0';
  if (pm_path_join(path, sizeof path, dir, "summary.json")) return;
  FILE *fp = fopen(path, "r");
  if (!fp) return;
  while (fgets(line, sizeof line, fp)) {
    char *p = strstr(line, "\"status\": \"");
    if (!p) continue;
    p += 11;
    size_t n = strcspn(p, "\"");
    snprintf(buf, size, "%.*s", (int)(n < size ? n : size - 1), p);
    break;
  }
  fclose(fp);
}

/* Remove dir/name when it exists; a folder (results/) with its files. */
static pm_err remove_entry(const char *dir, const char *name) {
  char path[PM_PATH_MAX + 1], child[PM_PATH_MAX + 1];
  struct stat st;
  PM_CALL(pm_path_join(path, sizeof path, dir, name));
  if (lstat(path, &st) != 0) return PM_SUCCESS;
  if (S_ISDIR(st.st_mode)) {
    DIR *d = opendir(path);
    PM_CHECK(d, PM_ERR_IO, "cannot read '%s': %s", path, strerror(errno));
    struct dirent *e;
    pm_err ret = PM_SUCCESS;
    while ((e = readdir(d)) && ret == PM_SUCCESS) {
      if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
      ret = pm_path_join(child, sizeof child, path, e->d_name);
      if (ret == PM_SUCCESS && unlink(child) != 0)
        ret = PM_ERROR(PM_ERR_IO, "cannot remove '%s': %s", child,
                       strerror(errno));
    }
    closedir(d);
    PM_CALL(ret);
    PM_CHECK(rmdir(path) == 0, PM_ERR_IO, "cannot remove '%s': %s", path,
             strerror(errno));
    return PM_SUCCESS;
  }
  PM_CHECK(unlink(path) == 0, PM_ERR_IO, "cannot remove '%s': %s", path,
           strerror(errno));
  return PM_SUCCESS;
}

/* Does dir hold an earlier run's files?  *which names the first. */
static bool holds_run(const char *dir, const char **which) {
  char path[PM_PATH_MAX + 1];
  struct stat st;
  for (size_t k = 0; k < N_RUN_FILES; k++)
    if (!pm_path_join(path, sizeof path, dir, run_files[k]) &&
        stat(path, &st) == 0) {
      *which = run_files[k];
      return true;
    }
  if (!pm_path_join(path, sizeof path, dir, "results") &&
      stat(path, &st) == 0) {
    *which = "results/";
    return true;
  }
  return false;
}

/* Is name a temporary file of a run: RUNFILE.tmp.PID? */
static bool run_tmp_name(const char *name) {
  for (size_t k = 0; k < N_RUN_FILES; k++) {
    size_t len = strlen(run_files[k]);
    if (strncmp(name, run_files[k], len) || strncmp(name + len, ".tmp.", 5))
      continue;
    const char *pid = name + len + 5;
    return *pid && strspn(pid, "0123456789") == strlen(pid);
  }
  return false;
}

/* Remove the temporary files (RUNFILE.tmp.PID) a killed run left in dir;
 * nothing else of the folder's is touched. */
static pm_err drop_tmp(const char *dir) {
  DIR *d = opendir(dir);
  PM_CHECK(d, PM_ERR_IO, "cannot read '%s': %s", dir, strerror(errno));
  struct dirent *e;
  char path[PM_PATH_MAX + 1];
  pm_err ret = PM_SUCCESS;
  while ((e = readdir(d)) && ret == PM_SUCCESS) {
    struct stat st;
    if (!run_tmp_name(e->d_name) ||
        pm_path_join(path, sizeof path, dir, e->d_name) != PM_SUCCESS ||
        lstat(path, &st) != 0 || !S_ISREG(st.st_mode))
      continue;
    if (unlink(path) != 0 && errno != ENOENT)
      ret =
          PM_ERROR(PM_ERR_IO, "cannot remove '%s': %s", path, strerror(errno));
  }
  closedir(d);
  return ret;
}

/* Whether fd is still the lock file at path: a run releasing a folder it
 * created and left empty unlinks the lock file (and removes the folder)
 * before it closes the file, and a claim that opened the file before the
 * unlink gets the lock of a file no longer in the folder once that close
 * comes.  A third claim would then create a new lock file and lock that
 * too: two runs in one folder. */
static bool lock_current(int fd, const char *path) {
  struct stat a, b;
  return fstat(fd, &a) == 0 && a.st_nlink > 0 && stat(path, &b) == 0 &&
         a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

/* Lock dir's lock file, writing the process id into it.  A lock file
 * unlinked while it was taken (lock_current) is let go and the claim
 * repeated; make: a folder removed meanwhile by that release is made
 * again (*remade). */
static pm_err take_lock(const char *dir, bool make, int *fd_out, bool *remade) {
  char path[PM_PATH_MAX + 1], pid[32];
  *fd_out = -1;
  PM_CALL(pm_path_join(path, sizeof path, dir, LOCK_NAME));
  int fd = -1;
  for (int attempt = 0;; attempt++) {
    fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0 && errno == ENOENT && make && attempt < 100) {
      PM_CALL(pm_mkdir_p(dir));
      *remade = true;
      continue;
    }
    PM_CHECK(fd >= 0, PM_ERR_IO, "output folder '%s' is not writable: %s", dir,
             strerror(errno));
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
      ssize_t n = pread(fd, pid, sizeof pid - 1, 0);
      pid[n > 0 ? n : 0] = '\0';
      pid[strcspn(pid, "\n")] = '\0';
      close(fd);
      return PM_ERROR(PM_ERR_IO,
                      "output folder '%s' is in use by a running pointmech "
                      "(pid %s): wait for it, stop it, or choose another "
                      "--out",
                      dir, pid[0] ? pid : "unknown");
    }
    if (lock_current(fd, path)) break;
    close(fd);
    PM_CHECK(attempt < 100, PM_ERR_IO,
             "cannot lock output folder '%s': its lock file '%s' keeps "
             "being replaced",
             dir, path);
  }
  int n = snprintf(pid, sizeof pid, "%ld\n", (long)getpid());
  if (ftruncate(fd, 0) != 0 || pwrite(fd, pid, (size_t)n, 0) != n) {
    int e = errno;
    close(fd);
    return PM_ERROR(PM_ERR_IO, "cannot write the lock file '%s': %s", path,
                    strerror(e));
  }
  *fd_out = fd;
  return PM_SUCCESS;
}

pm_err pm_outdir_claim(const char *dir, pm_outdir_mode mode, pm_outdir **out) {
  pm_err ret = PM_SUCCESS;
  pm_outdir *d = NULL;
  const char *which = NULL;
  struct stat st;
  PM_CHECK(out && dir && dir[0], PM_ERR_ARG, "pm_outdir_claim: no folder");
  PM_CHECK(strlen(dir) < sizeof d->dir - 32, PM_ERR_ARG,
           "output folder name too long: '%.64s...'", dir);
  *out = NULL;
  bool existed = stat(dir, &st) == 0;
  if (mode == PM_OUTDIR_RESUME)
    PM_CHECK(existed && S_ISDIR(st.st_mode), PM_ERR_IO,
             "cannot resume '%s': %s", dir,
             existed ? "not a folder" : "no such folder");
  else
    PM_CALL(pm_mkdir_p(dir));
  PM_CHECK(access(dir, W_OK | X_OK) == 0, PM_ERR_IO,
           "output folder '%s' is not writable: %s", dir, strerror(errno));
  PM_TRY(PM_ALLOC(d, 1, "output folder"));
  d->fd = -1;
  d->created = !existed;
  snprintf(d->dir, sizeof d->dir, "%s", dir);
  bool remade = false;
  PM_TRY(take_lock(dir, mode != PM_OUTDIR_RESUME, &d->fd, &remade));
  d->created = d->created || remade;
  if (mode == PM_OUTDIR_NEW && holds_run(dir, &which)) {
    char status[64];
    pm_summary_status(dir, status, sizeof status);
    PM_ENSURE(false, PM_ERR_IO,
              "output folder '%s' already holds the results of another run "
              "(%s%s%s%s): pass --overwrite to replace them, `pointmech "
              "resume %s` to continue that run, or choose another --out",
              dir, which, status[0] ? ", status \"" : "", status,
              status[0] ? "\"" : "", dir);
  }
  PM_TRY(drop_tmp(dir));
  if (mode == PM_OUTDIR_OVERWRITE) {
    for (size_t k = 0; k < N_RUN_FILES; k++)
      PM_TRY(remove_entry(dir, run_files[k]));
    PM_TRY(remove_entry(dir, "results"));
  }
  *out = d;
  d = NULL;
done:
  pm_outdir_release(d);
  return ret;
}

void pm_outdir_release(pm_outdir *d) {
  if (!d) return;
  /* A folder this claim created and nothing was written to goes again:
   * the lock file is unlinked while it is still locked, and a claim that
   * had opened it finds it gone once it gets the lock (lock_current) and
   * claims anew, making the folder again. */
  if (d->created && d->fd >= 0) {
    char path[PM_PATH_MAX + 1];
    DIR *dd = opendir(d->dir);
    int others = 0;
    struct dirent *e;
    while (dd && (e = readdir(dd)))
      if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") &&
          strcmp(e->d_name, LOCK_NAME))
        others++;
    if (dd) closedir(dd);
    if (dd && others == 0 &&
        pm_path_join(path, sizeof path, d->dir, LOCK_NAME) == PM_SUCCESS &&
        unlink(path) == 0)
      rmdir(d->dir);
  }
  if (d->fd >= 0) close(d->fd); /* releases the lock */
  free(d);
}
