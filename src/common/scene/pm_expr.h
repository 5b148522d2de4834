/* pm_expr: compiled expressions in x, y, z, t (libmatheval) for regions, load
 * curves and analytic reference fields. */
#ifndef PM_EXPR_H
#define PM_EXPR_H

#include <stdbool.h>

#include "pm_error.h"

typedef struct pm_expr pm_expr;

/* Compile text (e.g. "-0.4*z", "0.01*sin(2*pi*t)", "3").  Only the variables
 * x, y, z, t are allowed; constants pi and e are known.  On failure returns
 * PM_ERR_EXPR with a message quoting the text and naming the unknown
 * variable or the syntax error; *out is NULL.  A number that is not finite
 * (nan, inf, 1e999), and an expression without variables whose value is
 * not finite ("1/0", "sqrt(-1)"), fail the same way. */
pm_err pm_expr_create(const char *text, pm_expr **out);
/* Evaluate at (x, y, z, t).  Not thread-safe on one pm_expr. */
double pm_expr_eval(const pm_expr *e, double x, double y, double z, double t);
/* Whether the expression uses the variable ('x','y','z' or 't'). */
bool pm_expr_uses(const pm_expr *e, char var);
/* The source text. */
const char *pm_expr_text(const pm_expr *e);
/* Where the expression comes from, for messages at run time (e.g.
 * "cases/a.yaml:12:30: boundary.1.displacement.z"): a copy of where is
 * kept.  PM_ERR_MEMORY on failure. */
pm_err pm_expr_set_origin(pm_expr *e, const char *where);
/* That origin, or NULL when none was set. */
const char *pm_expr_origin(const pm_expr *e);

/* The end of pm_expr_fail_value's messages, by which a run's driver tells
 * a condition's value from an instability of the method. */
#define PM_EXPR_NOT_FINITE "not a finite value"

/* Fail with PM_ERR_UNSTABLE for the value v (not finite) that e gave at
 * time t for WHAT index (a point, a node) at x: "step N, t = T s: WHAT I at
 * (x, y, z): ORIGIN: "TEXT" = nan, not a finite value".  A negative step
 * is left out. */
pm_err pm_expr_fail_value(const pm_expr *e, double v, long step, double t,
                          const char *what, long index, const double x[3]);

/* Why text, a number as a scene writes it (nan, .nan, -.inf, inf, 1e999),
 * is not finite ("not a number", "infinite", "too large for a double"), or
 * NULL when text is not such a number. */
const char *pm_number_not_finite(const char *text);

/* Free; NULL is allowed. */
void pm_expr_destroy(pm_expr *e);

#endif
