/* pm_table_read: reading text files: a whole file, or the data lines of a
 * table one at a time, split at commas into fields and numbers. */
#include "pm_table_read.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm_files.h"

pm_err pm_lines_open(pm_lines *r, const char *path, const char *what) {
  memset(r, 0, sizeof *r);
  r->path = path;
  r->fp = fopen(path, "r");
  PM_CHECK(r->fp, PM_ERR_IO, "cannot open %s '%s': %s", what, path,
           strerror(errno));
  return PM_SUCCESS;
}

pm_err pm_lines_next(pm_lines *r, char **text) {
  ssize_t len;
  *text = NULL;
  while ((len = getline(&r->buf, &r->size, r->fp)) >= 0) {
    r->line++;
    while (len > 0 && strchr(" \t\r\n", r->buf[len - 1])) r->buf[--len] = '\0';
    char *s = r->buf + strspn(r->buf, " \t");
    if (*s == '\0' || *s == '#') continue;
    *text = s;
    return PM_SUCCESS;
  }
  PM_CHECK(!ferror(r->fp), PM_ERR_IO, "read error on '%s' after line %ld",
           r->path, r->line);
  return PM_SUCCESS;
}

void pm_lines_close(pm_lines *r) {
  if (r->fp) fclose(r->fp);
  free(r->buf);
  r->fp = NULL;
  r->buf = NULL;
}

static char *trim(char *s) {
  s += strspn(s, " \t");
  size_t len = strlen(s);
  while (len > 0 && (s[len - 1] == ' ' || s[len - 1] == '\t')) s[--len] = '\0';
  return s;
}

int pm_split_fields(char *s, char **fields, int max) {
  int n = 0;
  for (;;) {
    char *comma = strchr(s, ',');
    if (comma) *comma = '\0';
    if (n == max) return max + 1;
    fields[n++] = trim(s);
    if (!comma) return n;
    s = comma + 1;
  }
}

bool pm_parse_number(const char *s, double *v) {
  char *end;
  s += strspn(s, " \t");
  *v = strtod(s, &end);
  if (end == s) return false;
  end += strspn(end, " \t");
  return *end == '\0';
}

pm_err pm_read_text(const char *path, const char *what, char **text,
                    size_t *len) {
  pm_err ret = PM_SUCCESS;
  FILE *f = fopen(path, "rb");
  char *buf = NULL;
  size_t cap = 0, n = 0;
  *text = NULL;
  *len = 0;
  PM_ENSURE(f, PM_ERR_IO, "cannot open %s %s: %s", what, path, strerror(errno));
  for (;;) {
    if (n + 4096 + 1 > cap) {
      cap = 2 * (n + 4096 + 1);
      char *grown = realloc(buf, cap);
      PM_ENSURE(grown, PM_ERR_MEMORY, "cannot read %s %s: out of memory", what,
                path);
      buf = grown;
    }
    size_t got = fread(buf + n, 1, cap - n - 1, f);
    n += got;
    if (got == 0) break;
  }
  PM_ENSURE(!ferror(f), PM_ERR_IO, "cannot read %s %s: %s", what, path,
            strerror(errno));
  buf[n] = '\0';
  *text = buf;
  *len = n;
  buf = NULL;
done:
  free(buf);
  if (f) fclose(f);
  return ret;
}
