/* pm_curve: load curves, an expression of t or a (t, factor) table from a
 * CSV file, linear between its rows. */
#include "pm_curve.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_table_read.h"

static bool ends_with(const char *s, const char *tail) {
  const size_t n = strlen(s), m = strlen(tail);
  return n >= m && strcmp(s + n - m, tail) == 0;
}

/* Append row (t, f) to c, growing its arrays by doubling (*cap rows). */
static pm_err push_row(pm_curve *c, long *cap, double t, double f) {
  if (c->n == *cap) {
    const long grown = *cap ? 2 * *cap : 16;
    double *nt = realloc(c->t, (size_t)grown * sizeof(double));
    if (nt) c->t = nt;
    double *nf = nt ? realloc(c->f, (size_t)grown * sizeof(double)) : NULL;
    if (nf) c->f = nf;
    PM_CHECK(nt && nf, PM_ERR_MEMORY, "out of memory reading %s", c->file);
    *cap = grown;
  }
  c->t[c->n] = t;
  c->f[c->n] = f;
  c->n++;
  return PM_SUCCESS;
}

/* The rows of c->file: "t, factor" per data line ('#' comments and blank
 * lines skipped), each checked as it is read. */
static pm_err read_table(pm_curve *c) {
  pm_err ret = PM_SUCCESS;
  pm_lines in = {0};
  long cap = 0;
  bool header = false;
  char *text, *fields[3];
  double t, f;
  PM_TRY(pm_lines_open(&in, c->file, "load curve"));
  for (;;) {
    PM_TRY(pm_lines_next(&in, &text));
    if (!text) break;
    const int nf = pm_split_fields(text, fields, 2);
    if (nf != 2 || !pm_parse_number(fields[0], &t) ||
        !pm_parse_number(fields[1], &f)) {
      /* a header first is allowed: it names the columns */
      if (c->n == 0 && !header && nf == 2 && !pm_parse_number(fields[0], &t)) {
        header = true;
        continue;
      }
      ret = PM_ERROR(PM_ERR_SCENE,
                     "%s:%ld: expected two numbers t, factor, got %d "
                     "field%s",
                     c->file, in.line, nf > 2 ? 3 : nf, nf == 1 ? "" : "s");
      if (nf == 2)
        ret = PM_ERROR(PM_ERR_SCENE,
                       "%s:%ld: expected two numbers t, factor, got '%s', "
                       "'%s'",
                       c->file, in.line, fields[0], fields[1]);
      goto done;
    }
    if (!isfinite(t) || !isfinite(f)) {
      ret =
          PM_ERROR(PM_ERR_SCENE, "%s:%ld: expected finite numbers, got %g, %g",
                   c->file, in.line, t, f);
      goto done;
    }
    if (c->n > 0 && !(t > c->t[c->n - 1])) {
      ret = PM_ERROR(PM_ERR_SCENE,
                     "%s:%ld: expected a time after %g (times strictly "
                     "increasing), got %g",
                     c->file, in.line, c->t[c->n - 1], t);
      goto done;
    }
    PM_TRY(push_row(c, &cap, t, f));
  }
  if (c->n == 0)
    ret = PM_ERROR(PM_ERR_SCENE, "%s: expected rows t, factor, got none",
                   c->file);
done:
  pm_lines_close(&in);
  return ret;
}

pm_err pm_curve_create(const char *text, const char *dir, pm_curve **out) {
  pm_err ret = PM_SUCCESS;
  *out = NULL;
  pm_curve *c = calloc(1, sizeof *c);
  PM_CHECK(c, PM_ERR_MEMORY, "out of memory");
  if (!ends_with(text, ".csv")) {
    PM_TRY(pm_expr_create(text, &c->expr));
  } else {
    const bool rel = dir && dir[0] && text[0] != '/';
    const size_t len = (rel ? strlen(dir) + 1 : 0) + strlen(text) + 1;
    c->file = malloc(len);
    if (!c->file) {
      ret = PM_ERROR(PM_ERR_MEMORY, "out of memory");
      goto done;
    }
    snprintf(c->file, len, "%s%s%s", rel ? dir : "", rel ? "/" : "", text);
    PM_TRY(read_table(c));
  }
  *out = c;
  c = NULL;
done:
  pm_curve_destroy(c);
  return ret;
}

double pm_curve_at(const pm_curve *c, double t) {
  if (!c) return 1.0;
  if (c->expr) return pm_expr_eval(c->expr, 0, 0, 0, t);
  if (t <= c->t[0]) return c->f[0];
  if (t >= c->t[c->n - 1]) return c->f[c->n - 1];
  long lo = 0, hi = c->n - 1; /* t[lo] < t <= t[hi] */
  while (hi - lo > 1) {
    const long mid = (lo + hi) / 2;
    if (c->t[mid] < t)
      lo = mid;
    else
      hi = mid;
  }
  const double s = (t - c->t[lo]) / (c->t[hi] - c->t[lo]);
  return c->f[lo] + s * (c->f[hi] - c->f[lo]);
}

double pm_curve_end(const pm_curve *c) {
  return c && !c->expr && c->n > 0 ? c->t[c->n - 1] : 0.0;
}

void pm_curve_destroy(pm_curve *c) {
  if (!c) return;
  pm_expr_destroy(c->expr);
  free(c->t);
  free(c->f);
  free(c->file);
  free(c);
}
