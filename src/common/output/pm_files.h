/* pm_files: paths, mkdir -p and output files that appear whole or not at
 * all (write to a temporary name, rename when complete); with the pieces
 * of the output folder it includes: history CSV (pm_history_csv.h), JSON
 * writer (pm_json.h), output folders (pm_outdir.h) and text tables read
 * back with their line numbers (pm_table_read.h). */
#ifndef PM_FILES_H
#define PM_FILES_H

#include <stdbool.h>
#include <stdio.h>

#include "pm_error.h"

/* Longest path the module accepts (bytes, without the terminating NUL). */
#define PM_PATH_MAX 4095

/* Create directory dir and its missing parents (like mkdir -p, mode 0777
 * minus umask).  An existing directory is fine.  Fails with PM_ERR_ARG for
 * an empty or too long path, PM_ERR_IO (naming the component and the system
 * message) when a component cannot be created or is not a directory. */
pm_err pm_mkdir_p(const char *dir);

/* Whether the folder path names a file in no longer exists (removed
 * during a run, say). */
bool pm_folder_gone(const char *path);

/* Join dir and name as "dir/name" into buf (size bytes).  dir NULL or ""
 * gives name alone.  Fails with PM_ERR_ARG when the result does not fit. */
pm_err pm_path_join(char *buf, size_t size, const char *dir, const char *name);

/* ---- Atomic files ------------------------------------------------------ */

/* A file being written under FINAL.tmp.<pid>; renamed to FINAL on commit. */
typedef struct pm_afile pm_afile;

/* Open final_path.tmp.<pid> for writing (truncating a stale one).  *out
 * receives a handle owned by the caller, released by exactly one of
 * pm_afile_commit or pm_afile_abort.  Fails (with *out NULL) with PM_ERR_ARG
 * for a bad path, PM_ERR_IO naming the temporary path when it cannot be
 * created (missing or unwritable directory), PM_ERR_MEMORY. */
pm_err pm_afile_open(const char *final_path, pm_afile **out);

/* The stdio stream to write to (owned by the handle: do not fclose). */
FILE *pm_afile_stream(pm_afile *f);

/* The final path the handle commits to (owned by the handle). */
const char *pm_afile_path(const pm_afile *f);

/* Finish the file: check the stream's error flag, fflush, fsync, fclose and
 * rename the temporary file to the final path (replacing an older file).
 * Always frees f (NULL is accepted).  On failure the temporary file is
 * removed, the final path is untouched, and PM_ERR_IO names the path. */
pm_err pm_afile_commit(pm_afile *f);

/* Discard the file: close and unlink the temporary file, free f (NULL is
 * accepted).  Leaves the final path untouched.  Cannot fail. */
void pm_afile_abort(pm_afile *f);

/* Rename from to to (same file system) and fsync the directory of to when
 * possible.  Fails with PM_ERR_IO naming both paths. */
pm_err pm_rename(const char *from, const char *to);

/* Make the closed file path durable (fsync).  PM_ERR_IO naming the path
 * and the reason. */
pm_err pm_sync_file(const char *path);

/* Make the closed file tmp durable (fsync) and rename it to path, as
 * pm_rename.  A write the system refused (full disk, file size limit)
 * shows here at the latest.  PM_ERR_IO naming the path and the reason. */
pm_err pm_sync_rename(const char *tmp, const char *path);

#include "pm_history_csv.h"
#include "pm_json.h"
#include "pm_outdir.h"
#include "pm_table_read.h"

#endif
