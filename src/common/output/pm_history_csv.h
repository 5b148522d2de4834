/* pm_history_csv: a run's history.csv, written in place row by row and
 * synced.  Included by pm_files.h. */
#ifndef PM_HISTORY_CSV_H
#define PM_HISTORY_CSV_H

#include "pm_error.h"

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

#endif
