/* pm_history_csv: a run's history.csv, written in place row by row and
 * synced, and cut back to a checkpoint's rows when a run resumes. */
#include "pm_history_csv.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm_files.h"

struct pm_history {
  FILE *fp;
  int ncols;
  char path[PM_PATH_MAX + 1];
};

/* Write a CSV field, quoting it when it holds a separator. */
static void csv_field(FILE *fp, const char *s) {
  if (!strpbrk(s, ",\"\r\n")) {
    fputs(s, fp);
    return;
  }
  putc('"', fp);
  for (; *s; s++) {
    if (*s == '"') putc('"', fp);
    putc(*s, fp);
  }
  putc('"', fp);
}

static void csv_header(FILE *fp, int ncols, const char *const *names) {
  for (int i = 0; i < ncols; i++) {
    if (i) putc(',', fp);
    csv_field(fp, names[i]);
  }
  putc('\n', fp);
}

/* history.csv of a resumed run: the same header, and its first keep_rows
 * rows, rewritten whole (rows after them came after the checkpoint). */
static pm_err history_truncate(const char *path, int ncols,
                               const char *const *names, long keep_rows) {
  pm_err ret = PM_SUCCESS;
  FILE *in = NULL;
  pm_afile *out = NULL;
  char *line = NULL, *header = NULL;
  size_t cap = 0, hcap = 0;
  long rows = 0;
  in = fopen(path, "r");
  PM_CHECK(in, PM_ERR_IO, "cannot open '%s' to resume it: %s", path,
           strerror(errno));
  /* The header must be the one this run writes. */
  FILE *h = open_memstream(&header, &hcap);
  PM_ENSURE(h, PM_ERR_MEMORY, "cannot build the header of '%s'", path);
  csv_header(h, ncols, names);
  fclose(h);
  PM_ENSURE(getline(&line, &cap, in) >= 0 && strcmp(line, header) == 0,
            PM_ERR_IO,
            "'%s' does not start with the columns this run writes: it "
            "belongs to another scene or program version",
            path);
  PM_TRY(pm_afile_open(path, &out));
  FILE *fp = pm_afile_stream(out);
  fputs(header, fp);
  while (rows < keep_rows && getline(&line, &cap, in) >= 0) {
    PM_ENSURE(strchr(line, '\n'), PM_ERR_IO,
              "'%s' row %ld is cut short: the checkpoint names %ld rows", path,
              rows + 1, keep_rows);
    fputs(line, fp);
    rows++;
  }
  PM_ENSURE(rows == keep_rows, PM_ERR_IO,
            "'%s' holds %ld rows, the checkpoint names %ld", path, rows,
            keep_rows);
  pm_afile *f = out;
  out = NULL;
  PM_TRY(pm_afile_commit(f));
done:
  if (in) fclose(in);
  pm_afile_abort(out);
  free(line);
  free(header);
  return ret;
}

pm_err pm_history_open(const char *dir, int ncols, const char *const *names,
                       long keep_rows, pm_history **out) {
  pm_err ret = PM_SUCCESS;
  pm_history *h = NULL;
  PM_CHECK(out, PM_ERR_ARG, "pm_history_open: NULL out");
  *out = NULL;
  PM_CHECK(ncols >= 1 && names, PM_ERR_ARG,
           "history needs at least one column name (got %d)", ncols);
  for (int i = 0; i < ncols; i++)
    PM_CHECK(names[i], PM_ERR_ARG, "history column %d has no name", i);
  PM_TRY(PM_ALLOC(h, 1, "history writer"));
  h->ncols = ncols;
  PM_TRY(pm_path_join(h->path, sizeof h->path, dir, "history.csv"));
  if (keep_rows >= 0) {
    PM_TRY(history_truncate(h->path, ncols, names, keep_rows));
    h->fp = fopen(h->path, "a");
  } else {
    /* Written in place: every row synced is a whole result. */
    h->fp = fopen(h->path, "w");
  }
  PM_ENSURE(h->fp, PM_ERR_IO, "cannot open '%s' for writing: %s", h->path,
            strerror(errno));
  if (keep_rows < 0) csv_header(h->fp, ncols, names);
  PM_TRY(pm_history_sync(h));
  *out = h;
  h = NULL;
done:
  if (h && h->fp) fclose(h->fp);
  free(h);
  return ret;
}

pm_err pm_history_row(pm_history *h, const double *values) {
  PM_CHECK(h && values, PM_ERR_ARG, "pm_history_row: NULL argument");
  for (int i = 0; i < h->ncols; i++)
    if (fprintf(h->fp, i ? ",%.10g" : "%.10g", values[i]) < 0) break;
  PM_CHECK(putc('\n', h->fp) != EOF && !ferror(h->fp), PM_ERR_IO,
           "cannot write a row of '%s': %s", h->path, strerror(errno));
  return PM_SUCCESS;
}

pm_err pm_history_sync(pm_history *h) {
  PM_CHECK(h, PM_ERR_ARG, "pm_history_sync: NULL history");
  PM_CHECK(fflush(h->fp) == 0 && !ferror(h->fp), PM_ERR_IO,
           "cannot write '%s': %s", h->path, strerror(errno));
  PM_CHECK(fsync(fileno(h->fp)) == 0, PM_ERR_IO, "cannot sync '%s': %s",
           h->path, strerror(errno));
  return PM_SUCCESS;
}

int pm_history_ncols(const pm_history *h) { return h ? h->ncols : 0; }

pm_err pm_history_close(pm_history *h) {
  pm_err ret = PM_SUCCESS;
  if (!h) return PM_SUCCESS;
  ret = pm_history_sync(h);
  if (fclose(h->fp) != 0 && ret == PM_SUCCESS)
    ret =
        PM_ERROR(PM_ERR_IO, "cannot close '%s': %s", h->path, strerror(errno));
  free(h);
  return ret;
}
