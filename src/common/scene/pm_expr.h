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
 * variable or the syntax error; *out is NULL. */
pm_err pm_expr_create(const char *text, pm_expr **out);
/* Evaluate at (x, y, z, t).  Not thread-safe on one pm_expr. */
double pm_expr_eval(const pm_expr *e, double x, double y, double z, double t);
/* Whether the expression uses the variable ('x','y','z' or 't'). */
bool pm_expr_uses(const pm_expr *e, char var);
/* The source text. */
const char *pm_expr_text(const pm_expr *e);
/* Free; NULL is allowed. */
void pm_expr_destroy(pm_expr *e);

#endif
