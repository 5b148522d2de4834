/* pm_table_read: reading text files: a whole file, or the data lines of a
 * table one at a time (with their line numbers), split at commas into
 * fields and numbers.  Included by pm_files.h. */
#ifndef PM_TABLE_READ_H
#define PM_TABLE_READ_H

#include <stdbool.h>
#include <stdio.h>

#include "pm_error.h"

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

#endif
