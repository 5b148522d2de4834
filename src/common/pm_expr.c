/* pm_expr: expressions in x, y, z, t compiled by libmatheval, restricted to
 * those four variables so a typo in a scene is an error, not a zero. */
#include "pm_expr.h"

#include <matheval.h>
#include <stdlib.h>
#include <string.h>

struct pm_expr {
  char *text;       /* as given */
  void *evaluator;  /* libmatheval handle */
  unsigned uses;    /* bit i: variable "xyzt"[i] appears */
};

static const char pm_expr_vars[] = "xyzt";

/* Characters libmatheval's grammar can use.  Anything else would reach the
 * flex scanner's default rule, which echoes it to stdout before failing. */
static bool expr_char_ok(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
         (c >= '0' && c <= '9') || strchr("_.+-*/^() \t", c) != NULL;
}

pm_err pm_expr_create(const char *text, pm_expr **out) {
  pm_err ret = PM_SUCCESS;
  pm_expr *e = NULL;
  *out = NULL;
  if (!text) return PM_ERROR(PM_ERR_EXPR, "invalid expression: no text");
  PM_TRY(PM_ALLOC(e, 1, "expression"));
  e->text = strdup(text);
  PM_ENSURE(e->text, PM_ERR_MEMORY, "cannot copy expression \"%s\"", text);
  for (const char *c = text; *c; c++)
    PM_ENSURE(expr_char_ok(*c), PM_ERR_EXPR,
              "invalid expression \"%s\": unexpected character '%c'", text,
              *c);
  PM_ENSURE(strspn(text, " \t") < strlen(text), PM_ERR_EXPR,
            "invalid expression \"%s\": empty", text);
  /* matheval takes a non-const string; give it the private copy. */
  e->evaluator = evaluator_create(e->text);
  PM_ENSURE(e->evaluator, PM_ERR_EXPR, "invalid expression \"%s\": syntax error",
            text);
  char **names = NULL;
  int count = 0;
  evaluator_get_variables(e->evaluator, &names, &count);
  for (int i = 0; i < count; i++) {
    const char *v = strchr(pm_expr_vars, names[i][0]);
    PM_ENSURE(v && names[i][0] && names[i][1] == '\0', PM_ERR_EXPR,
              "invalid expression \"%s\": unknown variable %s (allowed: x, y, "
              "z, t)",
              text, names[i]);
    e->uses |= 1u << (v - pm_expr_vars);
  }
  *out = e;
  e = NULL;
done:
  pm_expr_destroy(e);
  return ret;
}

double pm_expr_eval(const pm_expr *e, double x, double y, double z, double t) {
  static char *names[] = {"x", "y", "z", "t"};
  double values[] = {x, y, z, t};
  return evaluator_evaluate(e->evaluator, 4, names, values);
}

bool pm_expr_uses(const pm_expr *e, char var) {
  const char *v = var ? strchr(pm_expr_vars, var) : NULL;
  return e && v && (e->uses & (1u << (v - pm_expr_vars)));
}

const char *pm_expr_text(const pm_expr *e) { return e ? e->text : NULL; }

void pm_expr_destroy(pm_expr *e) {
  if (!e) return;
  if (e->evaluator) evaluator_destroy(e->evaluator);
  free(e->text);
  free(e);
}
