/* gm_points_load: a membrane given as bare points, read from a text file
 * (.csv, or columns separated by white space), one point a line with its
 * share of the area or length; a bad line is named by FILE:LINE:COL. */
#include "gm_curve.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* Fields of a line kept for parsing; a line with more is counted and then
 * refused (at most dim + 1 columns are meaningful). */
#define GM_POINTS_FIELDS 8

typedef struct {
  const char *path;
  int dim;
  bool csv;
  long line;  /* the line being read (from 1) */
  int cols;   /* columns of every point line; 0 before the first */
  long first; /* the line that set cols */
  long n, cap;
  double *x, *share;
} points_reader;

/* "(x, y, z[, area])": what a line holds, for messages. */
static const char *layout(int dim) {
  return dim == 3 ? "(x, y, z[, area])" : "(x, y[, length])";
}

static bool blank(char c) {
  return c == ' ' || c == '\t' || c == '\v' || c == '\f';
}

/* Splits line (a comment and the line's end already cut off) in place
 * into NUL-terminated fields, comma-separated (csv) or separated by white
 * space, each trimmed of white space; the first GM_POINTS_FIELDS starts go
 * to at (offsets into line).  Returns the number of fields, 0 for a blank
 * line. */
static int split(char *line, bool csv, size_t *at) {
  size_t i = 0;
  while (blank(line[i])) i++;
  if (!line[i]) return 0;
  int count = 0;
  for (;;) {
    while (blank(line[i])) i++;
    const size_t start = i;
    if (count < GM_POINTS_FIELDS) at[count] = start;
    count++;
    while (line[i] && (csv ? line[i] != ',' : !blank(line[i]))) i++;
    size_t end = i;
    while (end > start && blank(line[end - 1])) end--;
    const char sep = line[i];
    line[end] = '\0';
    if (!sep) break;
    i++;
    /* White space at the end of a line is no empty last field; a comma
     * there is (a CSV's missing value). */
    if (!csv) {
      while (blank(line[i])) i++;
      if (!line[i]) break;
    }
  }
  return count;
}

/* Whether s, a whole field, reads as a number (finite or not). */
static bool number(const char *s, double *v) {
  char *end;
  *v = strtod(s, &end);
  return end != s && *end == '\0';
}

/* The value of field s, column k (from 0) of the current line, starting at
 * the line's byte col (from 1), or a failure naming FILE:LINE:COL. */
static pm_err read_value(const points_reader *r, const char *s, size_t col,
                         int k, double *v) {
  PM_CHECK(s[0], PM_ERR_SCENE,
           "%s:%ld:%zu: expected a number %s, got an empty field", r->path,
           r->line, col, layout(r->dim));
  PM_CHECK(number(s, v), PM_ERR_SCENE,
           "%s:%ld:%zu: expected a number %s, got '%.60s'", r->path, r->line,
           col, layout(r->dim), s);
  const char *why = pm_number_not_finite(s);
  PM_CHECK(isfinite(*v), PM_ERR_SCENE,
           "%s:%ld:%zu: expected a finite number %s, got '%.60s' (%s)", r->path,
           r->line, col, layout(r->dim), s, why ? why : "not finite");
  PM_CHECK(k < r->dim || *v > 0.0, PM_ERR_SCENE,
           "%s:%ld:%zu: expected a positive %s, got '%.60s'", r->path, r->line,
           col, r->dim == 3 ? "area" : "length", s);
  return PM_SUCCESS;
}

/* Room for one more point. */
static pm_err grow(points_reader *r) {
  if (r->n < r->cap) return PM_SUCCESS;
  const long cap = r->cap ? 2 * r->cap : 256;
  double *x = realloc(r->x, sizeof *x * 3 * (size_t)cap);
  PM_CHECK(x, PM_ERR_MEMORY, "no memory for %ld points of '%s'", cap, r->path);
  r->x = x;
  if (r->cols > r->dim) {
    double *share = realloc(r->share, sizeof *share * (size_t)cap);
    PM_CHECK(share, PM_ERR_MEMORY, "no memory for %ld points of '%s'", cap,
             r->path);
    r->share = share;
  }
  r->cap = cap;
  return PM_SUCCESS;
}

/* One line of text (its end cut off), which may be blank, a comment, the
 * header or a point; *started tells whether a line before had any field
 * (then this one is no header) and is set when this one has. */
static pm_err read_line(points_reader *r, char *line, bool *started) {
  char *hash = strchr(line, '#');
  if (hash) *hash = '\0';
  size_t at[GM_POINTS_FIELDS];
  const int count = split(line, r->csv, at);
  if (count == 0) return PM_SUCCESS;
  const bool first_content = !*started;
  *started = true;
  const int kept = count < GM_POINTS_FIELDS ? count : GM_POINTS_FIELDS;
  /* A header names the columns: no field of it is a number.  A first line
   * mixing numbers and words is a point with a mistake, said as such. */
  if (first_content) {
    bool words = true;
    double v;
    for (int k = 0; k < kept && words; k++) words = !number(line + at[k], &v);
    if (words) return PM_SUCCESS;
  }
  double p[4] = {0, 0, 0, 0};
  const int values = count < r->dim + 1 ? count : r->dim + 1;
  for (int k = 0; k < values; k++)
    PM_CALL(read_value(r, line + at[k], at[k] + 1, k, p + k));
  if (r->cols == 0) {
    PM_CHECK(count == r->dim || count == r->dim + 1, PM_ERR_SCENE,
             "%s:%ld:1: expected %d or %d columns %s, got %d", r->path, r->line,
             r->dim, r->dim + 1, layout(r->dim), count);
    r->cols = count;
    r->first = r->line;
  }
  PM_CHECK(count == r->cols, PM_ERR_SCENE,
           "%s:%ld:1: expected %d columns like line %ld, got %d", r->path,
           r->line, r->cols, r->first, count);
  PM_CALL(grow(r));
  double *x = r->x + 3 * r->n;
  x[0] = p[0];
  x[1] = p[1];
  x[2] = r->dim == 3 ? p[2] : 0.0;
  if (r->cols > r->dim) r->share[r->n] = p[r->dim];
  r->n++;
  return PM_SUCCESS;
}

static bool csv_name(const char *path) {
  const char *dot = strrchr(path, '.');
  return dot && !strchr(dot, '/') && strcasecmp(dot, ".csv") == 0;
}

pm_err gm_points_load(const char *path, int dim, long *n, double **x,
                      double **share) {
  PM_CHECK(n && x && share, PM_ERR_ARG, "gm_points_load: no output");
  *n = 0;
  *x = *share = NULL;
  PM_CHECK(path && path[0], PM_ERR_ARG, "no point file name");
  PM_CHECK(dim == 2 || dim == 3, PM_ERR_ARG,
           "point dimension must be 2 or 3 (got %d) for '%s'", dim, path);
  pm_err ret = PM_SUCCESS;
  points_reader r = {.path = path, .dim = dim, .csv = csv_name(path)};
  char *line = NULL;
  size_t size = 0;
  FILE *f = fopen(path, "r");
  PM_ENSURE(f, PM_ERR_IO, "cannot open point file '%s': %s", path,
            strerror(errno));
  ssize_t len;
  bool started = false;
  errno = 0;
  while ((len = getline(&line, &size, f)) >= 0) {
    r.line++;
    /* A byte order mark some editors write before a CSV's first line. */
    char *text = line;
    if (r.line == 1 && !strncmp(text, "\xEF\xBB\xBF", 3)) text += 3;
    const size_t got = strlen(line);
    PM_ENSURE(got == (size_t)len, PM_ERR_SCENE,
              "%s:%ld:%zu: expected text, got a NUL byte (a binary file?)",
              path, r.line, got + 1);
    while (len > 0 && (line[len - 1] == '\n' || line[len - 1] == '\r'))
      line[--len] = '\0';
    PM_TRY(read_line(&r, text, &started));
    errno = 0;
  }
  PM_ENSURE(!ferror(f), PM_ERR_IO, "cannot read point file '%s': %s", path,
            strerror(errno));
  PM_ENSURE(r.n > 0, PM_ERR_SCENE,
            "%s: no points (expected lines of %d or %d numbers %s)", path, dim,
            dim + 1, layout(dim));
  *n = r.n;
  *x = r.x;
  *share = r.share;
  r.x = r.share = NULL;
done:
  if (f) fclose(f);
  free(line);
  free(r.x);
  free(r.share);
  return ret;
}
