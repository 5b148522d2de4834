/* pm_reader: one pass over the YAML tree and the key tables: checks, values
 * and defaults. */
#include "pm_reader.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_expr.h"

/* Deeper tables than this come only from a table that contains itself. */
#define PM_READER_DEPTH 16

/* buf = path.seg (paths are for messages: a long one is cut). */
static void join(char *buf, const char *path, const char *seg) {
  if (snprintf(buf, PM_SDOC_PATH, "%s%s%s", path, path[0] ? "." : "", seg) >=
      PM_SDOC_PATH)
    buf[PM_SDOC_PATH - 1] = '\0';
}

/* Whether text is a whole decimal integer (leading zeros refused: they
 * read as octal elsewhere). */
static bool scalar_is_int(const char *text, long *out) {
  char *end;
  errno = 0;
  long v = strtol(text, &end, 10);
  const char *digits = text + (text[0] == '-' || text[0] == '+');
  if (end == text || *end || errno == ERANGE) return false;
  if (digits[0] == '0' && digits[1] != '\0') return false;
  *out = v;
  return true;
}

static bool scalar_is_number(const char *text, double *out) {
  char *end;
  double v = strtod(text, &end);
  if (end == text || *end != '\0' || !isfinite(v)) return false;
  *out = v;
  return true;
}

/* "WHERE: expected WHAT, got GOT" for a number at path, saying why when
 * GOT is a number that is not finite (nan, .inf, 1e999). */
static pm_err expected_number(pm_reader *r, const char *path,
                              const char *what) {
  char got[PM_SDOC_WHERE];
  int id = pm_sdoc_find(r->doc, path, false);
  const char *s = pm_sdoc_scalar(r->doc, id);
  const char *why = s ? pm_number_not_finite(s) : NULL;
  if (!why) return pm_reader_expected(r, path, what);
  pm_sdoc_got(r->doc, id, got, sizeof got);
  return pm_reader_fail(r, path, false,
                        "expected %s, got %s (%s; numbers must be finite)",
                        what, got, why);
}

/* "WHERE: expected <what k takes>, got GOT" at node id. */
static pm_err expected_key(pm_reader *r, const char *path, const pm_key *k) {
  char what[512];
  pm_key_describe(k, what, sizeof what);
  if (k->type == PM_KEY_NUMBER || k->type == PM_KEY_INTEGER)
    return expected_number(r, path, what);
  return pm_reader_expected(r, path, what);
}

static int name_value(const pm_name *names, const char *s, int *v) {
  for (const pm_name *n = names; n && n->name; n++)
    if (strcmp(n->name, s) == 0) {
      *v = n->value;
      return 1;
    }
  return 0;
}

pm_err pm_reader_expr(pm_reader *r, const char *path, const char *text,
                      const char *vars, pm_expr **out) {
  char msg[PM_SDOC_WHERE];
  if (pm_expr_create(text, out) != PM_SUCCESS) {
    /* Copy first: the new message is formatted into the same buffer. */
    snprintf(msg, sizeof msg, "%s", pm_error_message());
    return pm_reader_fail(r, path, false, "%s", msg);
  }
  /* Kept for messages about the values it gives during a run. */
  pm_sdoc_where(r->doc, pm_sdoc_find(r->doc, path, false), path, msg,
                sizeof msg);
  pm_err err = pm_expr_set_origin(*out, msg);
  if (err != PM_SUCCESS) {
    pm_expr_destroy(*out);
    *out = NULL;
    return err;
  }
  for (const char *v = "xyzt"; *v; v++) {
    if (strchr(vars, *v) || !pm_expr_uses(*out, *v)) continue;
    char allowed[16];
    size_t n = 0;
    for (const char *a = vars; *a && n + 4 < sizeof allowed; a++) {
      if (n) {
        allowed[n++] = ',';
        allowed[n++] = ' ';
      }
      allowed[n++] = *a;
    }
    allowed[n] = '\0';
    pm_expr_destroy(*out);
    *out = NULL;
    return pm_reader_fail(r, path, false,
                          "invalid expression \"%s\": variable %c is not "
                          "allowed here (allowed: %s)",
                          text, *v, allowed);
  }
  return PM_SUCCESS;
}

static const char *expr_vars(const pm_key *k) {
  if (k->flags & PM_KEY_NO_T) return "xyz";
  if (k->flags & PM_KEY_NO_XYZ) return "t";
  return "xyzt";
}

/* A list of numbers (POINT, NUMBERS) at node id. */
static pm_err read_numbers(pm_reader *r, int id, const char *path,
                           const pm_key *k, double *v, int lo, int hi,
                           int *count) {
  char sub[PM_SDOC_PATH];
  if (pm_sdoc_kind_of(r->doc, id) != PM_SDOC_LIST)
    return expected_key(r, path, k);
  int n = pm_sdoc_count(r->doc, id);
  if (n < lo || n > hi) {
    if (k->type == PM_KEY_POINT)
      return pm_reader_fail(r, path, false,
                            "expected %d numbers (dimension %d), got %d", lo,
                            lo, n);
    return pm_reader_fail(r, path, false,
                          lo == hi ? "expected %d numbers, got %d"
                                   : "expected %d to %d numbers, got %d",
                          lo, lo == hi ? n : hi, n);
  }
  for (int i = 0; i < n; i++) {
    char idx[16];
    snprintf(idx, sizeof idx, "%d", i);
    join(sub, path, idx);
    const char *s = pm_sdoc_scalar(r->doc, pm_sdoc_item(r->doc, id, i));
    double x;
    bool ok = s && scalar_is_number(s, &x);
    if (ok && k->type == PM_KEY_NUMBERS)
      ok = pm_key_in_range(k, x) &&
           (!(k->flags & PM_KEY_WHOLE) || x == floor(x));
    if (!ok) {
      char what[256];
      if (k->type == PM_KEY_POINT) {
        snprintf(what, sizeof what, "a number");
      } else {
        pm_key item = *k;
        item.type = (k->flags & PM_KEY_WHOLE) ? PM_KEY_INTEGER : PM_KEY_NUMBER;
        pm_key_describe(&item, what, sizeof what);
      }
      return expected_number(r, sub, what);
    }
    v[i] = x;
  }
  if (count) *count = n;
  return PM_SUCCESS;
}

static pm_err read_components(pm_reader *r, int id, const char *path,
                              const pm_key *k, void *dst) {
  static const pm_key axes[] = {{.name = "x", .type = PM_KEY_EXPR},
                                {.name = "y", .type = PM_KEY_EXPR},
                                {.name = "z", .type = PM_KEY_EXPR},
                                {0}};
  pm_expr **e = dst;
  unsigned *mask = (unsigned *)((char *)dst - k->offset + k->count_offset);
  char sub[PM_SDOC_PATH];
  if (pm_sdoc_kind_of(r->doc, id) != PM_SDOC_MAPPING)
    return expected_key(r, path, k);
  for (int i = 0; i < pm_sdoc_count(r->doc, id); i++) {
    int v, key = pm_sdoc_pair(r->doc, id, i, &v);
    const char *name = pm_sdoc_scalar(r->doc, key);
    const char *hit =
        name && name[0] && !name[1] ? strchr("xyz", name[0]) : NULL;
    int c = hit ? (int)(hit - "xyz") : -1;
    join(sub, path, name ? name : "?");
    if (c < 0)
      return pm_reader_fail(r, sub, true,
                            "unknown key (expected one of x, y, z)");
    if (c >= r->dimension)
      return pm_reader_fail(r, sub, true,
                            "expected components x, y (dimension 2), got z");
    if (*mask & (1u << c)) return pm_reader_fail(r, sub, true, "duplicate key");
    pm_key one = axes[c];
    one.flags = k->flags;
    PM_CALL(pm_reader_value(r, v, sub, &one, &e[c]));
    *mask |= 1u << c;
  }
  return PM_SUCCESS;
}

static pm_err read_list(pm_reader *r, int id, const char *path, const pm_key *k,
                        void *dst) {
  char sub[PM_SDOC_PATH], idx[16];
  void **arr = dst;
  int *count = (int *)((char *)dst - k->offset + k->count_offset);
  if (pm_sdoc_kind_of(r->doc, id) != PM_SDOC_LIST)
    return expected_key(r, path, k);
  int n = pm_sdoc_count(r->doc, id);
  if (n < k->min_count || (k->max_count > 0 && n > k->max_count)) {
    if (k->max_count > 0)
      return pm_reader_fail(r, path, false, "expected %d to %d entries, got %d",
                            k->min_count, k->max_count, n);
    return pm_reader_fail(r, path, false, "expected at least %d entr%s, got %d",
                          k->min_count, k->min_count == 1 ? "y" : "ies", n);
  }
  if (n == 0) return PM_SUCCESS;
  char *elems = NULL;
  PM_CALL(pm_calloc((void **)&elems, (size_t)n, k->elem_size, path));
  *arr = elems;
  *count = n;
  for (int i = 0; i < n; i++) {
    snprintf(idx, sizeof idx, "%d", i);
    join(sub, path, idx);
    int item = pm_sdoc_item(r->doc, id, i);
    if (pm_sdoc_kind_of(r->doc, item) != PM_SDOC_MAPPING)
      return pm_reader_expected(r, sub, "a mapping");
    PM_CALL(pm_reader_read(r, item, sub, k->keys, elems + i * k->elem_size));
  }
  return PM_SUCCESS;
}

pm_err pm_reader_value(pm_reader *r, int id, const char *path, const pm_key *k,
                       void *dst) {
  const char *s = pm_sdoc_scalar(r->doc, id);
  char sub[PM_SDOC_PATH];
  switch (k->type) {
  case PM_KEY_NUMBER: {
    double v;
    if (!s || !scalar_is_number(s, &v) || !pm_key_in_range(k, v))
      return expected_key(r, path, k);
    *(double *)dst = v;
    return PM_SUCCESS;
  }
  case PM_KEY_INTEGER: {
    long v;
    if (!s || !scalar_is_int(s, &v) || !pm_key_in_range(k, (double)v))
      return expected_key(r, path, k);
    *(long *)dst = v;
    return PM_SUCCESS;
  }
  case PM_KEY_BOOL:
    if (!s || (strcmp(s, "true") && strcmp(s, "false")))
      return expected_key(r, path, k);
    *(bool *)dst = strcmp(s, "true") == 0;
    return PM_SUCCESS;
  case PM_KEY_STRING:
    if (!s || !s[0]) return expected_key(r, path, k);
    free(*(char **)dst);
    *(char **)dst = strdup(s);
    PM_CHECK(*(char **)dst, PM_ERR_MEMORY, "cannot copy %s", path);
    return PM_SUCCESS;
  case PM_KEY_ENUM:
    if (!s || !name_value(k->names, s, (int *)dst))
      return expected_key(r, path, k);
    return PM_SUCCESS;
  case PM_KEY_FLAGS: {
    unsigned mask = 0;
    if (pm_sdoc_kind_of(r->doc, id) != PM_SDOC_LIST)
      return expected_key(r, path, k);
    int n = pm_sdoc_count(r->doc, id);
    if (n < k->min_count)
      return pm_reader_fail(r, path, false,
                            "expected a list of at least %d name%s, got %d",
                            k->min_count, k->min_count == 1 ? "" : "s", n);
    for (int i = 0; i < n; i++) {
      char idx[16], names[512], what[560];
      int v;
      snprintf(idx, sizeof idx, "%d", i);
      join(sub, path, idx);
      const char *item = pm_sdoc_scalar(r->doc, pm_sdoc_item(r->doc, id, i));
      if (!item || !name_value(k->names, item, &v)) {
        pm_key_names(k->names, names, sizeof names);
        snprintf(what, sizeof what, "one of %s", names);
        return pm_reader_expected(r, sub, what);
      }
      mask |= (unsigned)v;
    }
    *(unsigned *)dst = mask;
    return PM_SUCCESS;
  }
  case PM_KEY_EXPR:
    if (!s || !s[0]) return expected_key(r, path, k);
    pm_expr_destroy(*(pm_expr **)dst);
    *(pm_expr **)dst = NULL;
    return pm_reader_expr(r, path, s, expr_vars(k), (pm_expr **)dst);
  case PM_KEY_COMPONENTS: return read_components(r, id, path, k, dst);
  case PM_KEY_POINT:
    return read_numbers(r, id, path, k, dst, r->dimension, r->dimension, NULL);
  case PM_KEY_NUMBERS:
    return read_numbers(r, id, path, k, dst, k->min_count, k->max_count,
                        (int *)((char *)dst - k->offset + k->count_offset));
  case PM_KEY_MAPPING:
    if (pm_sdoc_kind_of(r->doc, id) != PM_SDOC_MAPPING)
      return expected_key(r, path, k);
    return pm_reader_read(r, id, path, k->keys, dst);
  case PM_KEY_LIST: return read_list(r, id, path, k, dst);
  case PM_KEY_CUSTOM: return k->read(r, id, path, k, dst);
  default: break;
  }
  return PM_ERROR(PM_ERR_INTERNAL, "%s: key of unknown type %d", path,
                  (int)k->type);
}

/* Split a default's comma-separated items into v (at most max). */
static int default_items(const char *def, char items[][64], int max) {
  int n = 0;
  for (const char *p = def; *p && n < max;) {
    while (*p == ' ') p++;
    size_t len = strcspn(p, ",");
    size_t end = len;
    while (end > 0 && p[end - 1] == ' ') end--;
    snprintf(items[n++], 64, "%.*s", (int)end, p);
    p += len + (p[len] == ',');
  }
  return n;
}

/* The key's default into dst (absent key).  A default that does not parse
 * is the table's fault: PM_ERR_INTERNAL. */
static pm_err apply_default(pm_reader *r, const char *path, const pm_key *k,
                            void *dst, int depth) {
  char items[8][64];
  if (k->type == PM_KEY_MAPPING) {
    for (const pm_key *c = k->keys; c->type != PM_KEY_END; c++) {
      char sub[PM_SDOC_PATH];
      join(sub, path, c->name);
      if (depth < PM_READER_DEPTH && !(c->flags & PM_KEY_REQUIRED))
        PM_CALL(apply_default(r, sub, c, (char *)dst + c->offset, depth + 1));
    }
    return PM_SUCCESS;
  }
  if (!k->def) return PM_SUCCESS;
  bool ok = true;
  switch (k->type) {
  case PM_KEY_NUMBER: *(double *)dst = strtod(k->def, NULL); break;
  case PM_KEY_INTEGER: *(long *)dst = strtol(k->def, NULL, 10); break;
  case PM_KEY_BOOL: *(bool *)dst = strcmp(k->def, "true") == 0; break;
  case PM_KEY_STRING:
    *(char **)dst = strdup(k->def);
    ok = *(char **)dst != NULL;
    break;
  case PM_KEY_ENUM: ok = name_value(k->names, k->def, (int *)dst); break;
  case PM_KEY_FLAGS: {
    unsigned mask = 0;
    int n = default_items(k->def, items, 8), v = 0;
    for (int i = 0; i < n && ok; i++) {
      ok = name_value(k->names, items[i], &v);
      mask |= (unsigned)v;
    }
    *(unsigned *)dst = mask;
    break;
  }
  case PM_KEY_EXPR:
    ok = pm_expr_create(k->def, (pm_expr **)dst) == PM_SUCCESS;
    break;
  case PM_KEY_POINT:
  case PM_KEY_NUMBERS: {
    int n = default_items(k->def, items, 8);
    for (int i = 0; i < n && i < 8; i++)
      ((double *)dst)[i] = strtod(items[i], NULL);
    if (k->type == PM_KEY_NUMBERS)
      *(int *)((char *)dst - k->offset + k->count_offset) = n;
    break;
  }
  default: break;
  }
  PM_CHECK(ok, PM_ERR_INTERNAL, "%s: the default \"%s\" does not parse", path,
           k->def);
  return PM_SUCCESS;
}

static void list_keys(char *buf, size_t size, int n,
                      const pm_key *const *keys) {
  size_t used = 0;
  buf[0] = '\0';
  for (int t = 0; t < n; t++)
    for (const pm_key *k = keys[t]; k->type != PM_KEY_END && used < size; k++)
      used += (size_t)snprintf(buf + used, size - used, "%s%s",
                               used ? ", " : "", k->name);
}

pm_err pm_reader_mapping(pm_reader *r, int id, const char *path, int n,
                         const pm_key *const *keys, void *const *bases,
                         const char *expected) {
  char sub[PM_SDOC_PATH], names[PM_SDOC_WHERE];
  if (id && pm_sdoc_kind_of(r->doc, id) != PM_SDOC_MAPPING)
    return pm_reader_expected(r, path, "a mapping");
  /* Every key of the scene is one of the tables'. */
  for (int i = 0; id && i < pm_sdoc_count(r->doc, id); i++) {
    int key = pm_sdoc_pair(r->doc, id, i, NULL);
    const char *name = pm_sdoc_scalar(r->doc, key);
    if (!name)
      return pm_reader_fail(r, path, false, "expected a key name, got %s",
                            pm_sdoc_kind_of(r->doc, key) == PM_SDOC_MAPPING
                                ? "a mapping"
                                : "a list");
    join(sub, path, name);
    bool known = false;
    for (int t = 0; t < n && !known; t++) known = pm_key_find(keys[t], name);
    if (!known) {
      if (!expected) list_keys(names, sizeof names, n, keys);
      return pm_reader_fail(r, sub, true, "unknown key (expected one of %s)",
                            expected ? expected : names);
    }
    for (int j = 0; j < i; j++) {
      const char *prev = pm_sdoc_scalar(r->doc, pm_sdoc_pair(r->doc, id, j, 0));
      if (prev && strcmp(prev, name) == 0)
        return pm_reader_fail(r, sub, true, "duplicate key");
    }
  }
  for (int t = 0; t < n; t++)
    for (const pm_key *k = keys[t]; k->type != PM_KEY_END; k++) {
      void *dst = (char *)bases[t] + k->offset;
      int child = id ? pm_sdoc_child(r->doc, id, k->name) : 0;
      join(sub, path, k->name);
      if (child) {
        PM_CALL(pm_reader_value(r, child, sub, k, dst));
      } else if (k->flags & PM_KEY_REQUIRED) {
        return pm_reader_fail(r, sub, false, "missing required key");
      } else {
        PM_CALL(apply_default(r, sub, k, dst, 0));
      }
    }
  return PM_SUCCESS;
}

pm_err pm_reader_read(pm_reader *r, int id, const char *path,
                      const pm_key *keys, void *base) {
  return pm_reader_mapping(r, id, path, 1, &keys, &base, NULL);
}

bool pm_reader_has(const pm_reader *r, const char *path) {
  return pm_sdoc_find(r->doc, path, false) != 0;
}

void pm_reader_release(const pm_key *keys, void *base) {
  for (const pm_key *k = keys; k && k->type != PM_KEY_END; k++) {
    char *dst = (char *)base + k->offset;
    switch (k->type) {
    case PM_KEY_STRING:
      free(*(char **)dst);
      *(char **)dst = NULL;
      break;
    case PM_KEY_EXPR:
      pm_expr_destroy(*(pm_expr **)dst);
      *(pm_expr **)dst = NULL;
      break;
    case PM_KEY_COMPONENTS:
      for (int c = 0; c < 3; c++) {
        pm_expr_destroy(((pm_expr **)dst)[c]);
        ((pm_expr **)dst)[c] = NULL;
      }
      break;
    case PM_KEY_MAPPING: pm_reader_release(k->keys, dst); break;
    case PM_KEY_CUSTOM:
      if (k->release) k->release(dst);
      break;
    case PM_KEY_LIST: {
      char *elems = *(char **)dst;
      int n = *(int *)((char *)base + k->count_offset);
      for (int i = 0; elems && i < n; i++)
        pm_reader_release(k->keys, elems + i * k->elem_size);
      free(elems);
      *(char **)dst = NULL;
      break;
    }
    default: break;
    }
  }
}
