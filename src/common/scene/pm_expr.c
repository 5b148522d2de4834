/* pm_expr: expressions in x, y, z, t compiled by libmatheval, restricted to
 * those four variables so a typo in a scene is an error, not a zero. */
#include "pm_expr.h"

#include <math.h>
#include <matheval.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct pm_expr {
  char *text;      /* as given */
  char *origin;    /* scene key and position, or NULL */
  void *evaluator; /* libmatheval handle */
  unsigned uses;   /* bit i: variable "xyzt"[i] appears */
};

static const char pm_expr_vars[] = "xyzt";

/* libmatheval leaks a node on every syntax error and echoes stray
 * characters to stdout, so a small recursive-descent check of its grammar
 * runs first and only well-formed text reaches it. */
typedef struct {
  const char *text, *p;
  const char *error; /* first problem found, NULL if none */
} expr_syntax;

static const char *const expr_functions[] = {
    "exp",   "log",   "sqrt",     "sin",   "cos",   "tan",   "cot",
    "sec",   "csc",   "asin",     "acos",  "atan",  "acot",  "asec",
    "acsc",  "sinh",  "cosh",     "tanh",  "coth",  "sech",  "csch",
    "asinh", "acosh", "atanh",    "acoth", "asech", "acsch", "abs",
    "step",  "delta", "nandelta", "erf",   NULL};
/* matheval's constants whose names start with a digit. */
static const char *const expr_digit_constants[] = {"1_pi", "2_pi", "2_sqrtpi",
                                                   NULL};

static bool is_alpha(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}
static bool is_digit(char c) { return c >= '0' && c <= '9'; }

static void syn_skip(expr_syntax *x) {
  while (*x->p == ' ' || *x->p == '\t') x->p++;
}

static bool syn_fail(expr_syntax *x, const char *what) {
  if (!x->error) x->error = what;
  return false;
}

/* Length of the word (letters, digits, _) at p that is in names, or 0. */
static size_t word_in(const char *p, const char *const *names) {
  size_t n = 0;
  while (is_alpha(p[n]) || is_digit(p[n])) n++;
  for (int i = 0; names[i]; i++)
    if (strlen(names[i]) == n && strncmp(p, names[i], n) == 0) return n;
  return 0;
}

static bool syn_sum(expr_syntax *x);

static bool syn_number(expr_syntax *x) {
  const char *p = x->p;
  size_t digits = 0;
  while (is_digit(*p)) p++, digits++;
  if (*p == '.') {
    p++;
    while (is_digit(*p)) p++, digits++;
  }
  if (!digits) return syn_fail(x, "malformed number");
  if (*p == 'e' || *p == 'E') {
    const char *q = p + 1;
    if (*q == '+' || *q == '-') q++;
    /* "2e" is 2 times the constant e to nobody; matheval rejects it. */
    if (!is_digit(*q)) return syn_fail(x, "malformed number");
    while (is_digit(*q)) q++;
    p = q;
  }
  if (!isfinite(strtod(x->p, NULL)))
    return syn_fail(x, "number too large for a double");
  x->p = p;
  return true;
}

/* primary: number | name | function '(' sum ')' | '(' sum ')' */
static bool syn_primary(expr_syntax *x) {
  syn_skip(x);
  size_t n;
  if (*x->p == '(') {
    x->p++;
    if (!syn_sum(x)) return false;
    syn_skip(x);
    if (*x->p != ')') return syn_fail(x, "expected ')'");
    x->p++;
    return true;
  }
  if ((n = word_in(x->p, expr_digit_constants)) > 0) {
    x->p += n;
    return true;
  }
  if (is_digit(*x->p) || *x->p == '.') return syn_number(x);
  if (!is_alpha(*x->p))
    return syn_fail(x, *x->p ? "expected a number, name or '('"
                             : "unexpected end");
  bool function = word_in(x->p, expr_functions) > 0;
  while (is_alpha(*x->p) || is_digit(*x->p)) x->p++;
  if (!function) return true;
  syn_skip(x);
  if (*x->p != '(') return syn_fail(x, "expected '(' after a function name");
  return syn_primary(x);
}

/* factor: '-' factor | primary ['^' factor] */
static bool syn_factor(expr_syntax *x) {
  syn_skip(x);
  if (*x->p == '-') {
    x->p++;
    return syn_factor(x);
  }
  if (!syn_primary(x)) return false;
  syn_skip(x);
  if (*x->p != '^') return true;
  x->p++;
  return syn_factor(x);
}

/* product: factor (('*' | '/') factor)* */
static bool syn_product(expr_syntax *x) {
  if (!syn_factor(x)) return false;
  for (syn_skip(x); *x->p == '*' || *x->p == '/'; syn_skip(x)) {
    x->p++;
    if (!syn_factor(x)) return false;
  }
  return true;
}

/* sum: product (('+' | '-') product)* */
static bool syn_sum(expr_syntax *x) {
  if (!syn_product(x)) return false;
  for (syn_skip(x); *x->p == '+' || *x->p == '-'; syn_skip(x)) {
    x->p++;
    if (!syn_product(x)) return false;
  }
  return true;
}

/* NULL when text is well formed; else what is wrong, *at its offset. */
static const char *expr_syntax_error(const char *text, size_t *at) {
  expr_syntax x = {text, text, NULL};
  syn_skip(&x);
  if (!*x.p) {
    *at = 0;
    return "empty";
  }
  if (syn_sum(&x)) {
    syn_skip(&x);
    if (*x.p) syn_fail(&x, "unexpected text");
  }
  *at = (size_t)(x.p - text);
  return x.error;
}

/* A value that is not finite as text: "nan" (whatever its sign), "inf",
 * "-inf". */
static const char *value_text(double v) {
  return isnan(v) ? "nan" : v > 0 ? "inf" : "-inf";
}

pm_err pm_expr_create(const char *text, pm_expr **out) {
  pm_err ret = PM_SUCCESS;
  pm_expr *e = NULL;
  *out = NULL;
  if (!text) return PM_ERROR(PM_ERR_EXPR, "invalid expression: no text");
  PM_TRY(PM_ALLOC(e, 1, "expression"));
  e->text = strdup(text);
  PM_ENSURE(e->text, PM_ERR_MEMORY, "cannot copy expression \"%s\"", text);
  /* "nan" and "inf" would read as unknown variables, ".nan" as a syntax
   * error: say what they are. */
  const char *not_finite = pm_number_not_finite(text);
  PM_ENSURE(!not_finite, PM_ERR_EXPR,
            "invalid expression \"%s\": %s (expected a finite value)", text,
            not_finite);
  size_t at = 0;
  const char *problem = expr_syntax_error(text, &at);
  PM_ENSURE(!problem, PM_ERR_EXPR,
            "invalid expression \"%s\": syntax error at character %zu: %s",
            text, at + 1, problem);
  /* matheval takes a non-const string; give it the private copy. */
  e->evaluator = evaluator_create(e->text);
  PM_ENSURE(e->evaluator, PM_ERR_EXPR,
            "invalid expression \"%s\": syntax error", text);
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
  /* A constant is known now: one that is not finite is an input error,
   * not a failure at some step of the run. */
  if (!e->uses) {
    double value = pm_expr_eval(e, 0, 0, 0, 0);
    PM_ENSURE(isfinite(value), PM_ERR_EXPR,
              "invalid expression \"%s\": its value is %s (expected a finite "
              "value)",
              text, value_text(value));
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

pm_err pm_expr_set_origin(pm_expr *e, const char *where) {
  char *copy = strdup(where);
  PM_CHECK(copy, PM_ERR_MEMORY, "cannot copy the origin of \"%s\"", e->text);
  free(e->origin);
  e->origin = copy;
  return PM_SUCCESS;
}

const char *pm_expr_origin(const pm_expr *e) { return e ? e->origin : NULL; }

pm_err pm_expr_fail_value(const pm_expr *e, double v, long step, double t,
                          const char *what, long index, const double x[3]) {
  char when[64] = "";
  if (step >= 0) snprintf(when, sizeof when, "step %ld, ", step);
  return PM_ERROR(PM_ERR_UNSTABLE,
                  "%st = %.6g s: %s %ld at (%g, %g, %g): %s%s\"%s\" = "
                  "%s, " PM_EXPR_NOT_FINITE,
                  when, t, what, index, x[0], x[1], x[2],
                  e->origin ? e->origin : "", e->origin ? ": " : "", e->text,
                  value_text(v));
}

const char *pm_number_not_finite(const char *text) {
  const char *p = text + (text[0] == '+' || text[0] == '-');
  /* YAML 1.2's spellings, which strtod does not read. */
  if (!strcmp(p, ".inf") || !strcmp(p, ".Inf") || !strcmp(p, ".INF"))
    return "infinite";
  if (p == text &&
      (!strcmp(p, ".nan") || !strcmp(p, ".NaN") || !strcmp(p, ".NAN")))
    return "not a number";
  char *end;
  double v = strtod(text, &end);
  if (end == text || *end || isfinite(v)) return NULL;
  if (isnan(v)) return "not a number";
  return strpbrk(text, "iI") ? "infinite" : "too large for a double";
}

void pm_expr_destroy(pm_expr *e) {
  if (!e) return;
  if (e->evaluator) evaluator_destroy(e->evaluator);
  free(e->origin);
  free(e->text);
  free(e);
}
