/* pm_files: output files that appear whole or not at all (write to a
 * temporary name, rename when complete), mkdir -p, history CSV, JSON writer,
 * and the data lines of text tables read back with their line numbers. */
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

/* Join dir and name as "dir/name" into buf (size bytes).  dir NULL or ""
 * gives name alone.  Fails with PM_ERR_ARG when the result does not fit. */
pm_err pm_path_join(char *buf, size_t size, const char *dir, const char *name);

/* ---- Reading text tables ---------------------------------------------- */

/* The data lines of a text file, one at a time: blank lines and lines whose
 * first non-blank character is '#' are skipped, leading blanks and trailing
 * blanks and line ends removed.  `line` is the 1-based number of the line
 * last returned, for messages ("FILE:LINE: ..."). */
typedef struct {
  FILE *fp;
  const char *path; /* borrowed: must outlive the reader */
  char *buf;
  size_t size;
  long line;
} pm_lines;

/* Open path for reading.  Fails with PM_ERR_IO naming what ("points
 * file") and the path. */
pm_err pm_lines_open(pm_lines *r, const char *path, const char *what);

/* The next data line in *text (owned by r, valid until the next call), or
 * NULL at the end of the file.  Fails with PM_ERR_IO on a read error. */
pm_err pm_lines_next(pm_lines *r, char **text);

/* Close the file and free the buffer (a reader never opened, zeroed, is
 * accepted). */
void pm_lines_close(pm_lines *r);

/* Split s at commas in place into at most max fields (blanks around each
 * trimmed).  Returns the number of fields, or max + 1 when there are
 * more. */
int pm_split_fields(char *s, char **fields, int max);

/* A whole field as a number (surrounding blanks allowed; "nan" and "inf"
 * are numbers).  False when the field holds anything else. */
bool pm_parse_number(const char *s, double *v);

/* The whole of file path as text (NUL-terminated, *len bytes before the
 * NUL; free it).  what names the file in messages ("scene"). */
pm_err pm_read_text(const char *path, const char *what, char **text,
                    size_t *len);

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

/* Make the closed file tmp durable (fsync) and rename it to path, as
 * pm_rename.  A write the system refused (full disk, file size limit)
 * shows here at the latest.  PM_ERR_IO naming the path and the reason. */
pm_err pm_sync_rename(const char *tmp, const char *path);

/* ---- History CSV ------------------------------------------------------- */

/* DIR/history.csv, written in place row by row: what pm_history_sync has
 * made durable is a whole table up to that row. */
typedef struct pm_history pm_history;

/* keep_rows < 0: create DIR/history.csv (replacing an older one) with the
 * header line of ncols column names (names[i] borrowed for the call only;
 * names with a comma, quote or line break are quoted).  keep_rows >= 0
 * (a resumed run): the file must start with the same header; it keeps its
 * first keep_rows rows (replaced whole) and rows are appended after them.
 * *out is owned by the caller and released by pm_history_close.  Fails with
 * PM_ERR_ARG (ncols < 1, NULL name), PM_ERR_IO naming the path (and, on
 * resume, a header that differs or fewer rows than keep_rows),
 * PM_ERR_MEMORY. */
pm_err pm_history_open(const char *dir, int ncols, const char *const *names,
                       long keep_rows, pm_history **out);

/* Append one row of ncols values (printed %.10g; non-finite values appear as
 * nan/inf).  Allocation-free.  Fails with PM_ERR_IO on a write error. */
pm_err pm_history_row(pm_history *h, const double *values);

/* Flush the rows written so far to disk (fflush + fsync).  PM_ERR_IO with
 * the system's reason (full disk, file size limit). */
pm_err pm_history_sync(pm_history *h);

/* Number of columns of h. */
int pm_history_ncols(const pm_history *h);

/* Sync and close; always frees h (NULL accepted).  PM_ERR_IO on failure. */
pm_err pm_history_close(pm_history *h);

/* ---- Output folders ----------------------------------------------------- */

/* How a run takes its output folder. */
typedef enum {
  PM_OUTDIR_NEW = 0,   /* refuse a folder holding another run's files */
  PM_OUTDIR_OVERWRITE, /* remove another run's files first */
  PM_OUTDIR_RESUME     /* continue the run whose files are there */
} pm_outdir_mode;

/* A folder held by this process for a run. */
typedef struct pm_outdir pm_outdir;

/* Claim dir for a run: create it (and its parents) unless resuming, check
 * that it is writable, lock it (DIR/.pointmech.lock holds the pid; the
 * lock dies with the process, so a killed run never blocks the next one),
 * remove the temporary files a killed run left (RUNFILE.tmp.PID; nothing
 * else), and apply mode to the files
 * a run writes (summary.json, history.csv, results.h5, results.xdmf,
 * checkpoint.h5, results/).  Fails with PM_ERR_IO naming the folder and the
 * reason: not writable, in use by a running pointmech (its pid), or, for
 * PM_OUTDIR_NEW, holding another run's files (and its status).  Release
 * with pm_outdir_release. */
pm_err pm_outdir_claim(const char *dir, pm_outdir_mode mode, pm_outdir **out);

/* The status member of dir/summary.json into buf ("" when there is
 * none). */
void pm_summary_status(const char *dir, char *buf, size_t size);

/* Unlock and free (NULL accepted).  A folder the claim created and
 * nothing was written to is removed. */
void pm_outdir_release(pm_outdir *d);

/* ---- JSON writer ------------------------------------------------------- */

/* Pretty-printed JSON written straight to a pm_afile.  One top-level value;
 * containers nest at most PM_JSON_MAX_DEPTH deep.  Each call takes a key:
 * the member name inside an object (required, escaped like a string), NULL
 * inside an array and at the top level.  A misuse (wrong key, too deep,
 * mismatched end, second top-level value) fails with PM_ERR_ARG; every later
 * call then fails too and the writer refuses to commit.  Write errors fail with
 * PM_ERR_IO. */
#define PM_JSON_MAX_DEPTH 16
typedef struct pm_json pm_json;

/* Start writing path (through pm_afile).  *out owned by the caller, released
 * by pm_json_close.  Failures as pm_afile_open. */
pm_err pm_json_open(const char *path, pm_json **out);
/* Open an object ({) / close the innermost object (}). */
pm_err pm_json_begin_object(pm_json *j, const char *key);
pm_err pm_json_end_object(pm_json *j);
/* Open an array ([) / close the innermost array (]). */
pm_err pm_json_begin_array(pm_json *j, const char *key);
pm_err pm_json_end_array(pm_json *j);
/* A number printed with 15 significant digits, or 17 when 15 do not read
 * back exactly; NaN and infinities are
 * written as null (JSON has no such numbers). */
pm_err pm_json_number(pm_json *j, const char *key, double value);
pm_err pm_json_integer(pm_json *j, const char *key, long long value);
/* A string (UTF-8 passed through; quote, backslash and control characters
 * escaped).  NULL is written as null. */
pm_err pm_json_string(pm_json *j, const char *key, const char *value);
pm_err pm_json_bool(pm_json *j, const char *key, bool value);
pm_err pm_json_null(pm_json *j, const char *key);

/* commit: the document must be complete (one top-level value, every
 * container closed, no earlier misuse), then the file is committed;
 * otherwise (or when commit is false) the temporary file is removed.
 * Always frees j (NULL accepted).  Fails with PM_ERR_ARG for an incomplete
 * document (file discarded) or PM_ERR_IO from the commit. */
pm_err pm_json_close(pm_json *j, bool commit);

/* The opening members of a run's summary.json, the same for every method:
 * program, version, scene (path), name, method and the --set overrides
 * (n_overrides strings). */
pm_err pm_json_run_header(pm_json *j, const char *scene_path, const char *name,
                          const char *method, int n_overrides,
                          char *const *overrides);

#endif
