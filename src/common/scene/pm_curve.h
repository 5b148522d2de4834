/* pm_curve: a load curve, the factor a condition's value is multiplied by
 * at time t: an expression of t, or a table of (t, factor) rows read from
 * a CSV file, linear between rows and held at its first and last values
 * outside them. */
#ifndef PM_CURVE_H
#define PM_CURVE_H

#include "pm_expr.h"

typedef struct pm_curve {
  pm_expr *expr; /* factor(t), or NULL for a table */
  long n;        /* table rows (0 for an expression) */
  double *t, *f; /* n each: times strictly increasing, factors */
  char *file;    /* the table's file, or NULL */
} pm_curve;

/* A curve from text: a path ending in .csv (relative to dir unless
 * absolute; dir NULL: as given) is a table, anything else an expression
 * of t alone.  A table needs at least one row of two finite numbers
 * "t, factor", times strictly increasing; anything else fails with
 * PM_ERR_SCENE naming FILE:LINE and what was expected, an expression with
 * PM_ERR_EXPR.  *out is NULL on failure. */
pm_err pm_curve_create(const char *text, const char *dir, pm_curve **out);

/* The factor at time t; 1 for a NULL curve.  Not thread-safe (an
 * expression's evaluation). */
double pm_curve_at(const pm_curve *c, double t);

/* The last time of a table (where its factor stops changing), or 0 for an
 * expression or NULL. */
double pm_curve_end(const pm_curve *c);

/* Free; NULL is allowed. */
void pm_curve_destroy(pm_curve *c);

#endif
