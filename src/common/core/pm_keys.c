/* pm_keys: lookups and descriptions over key tables (the reader is in
 * src/common/scene). */
#include "pm_keys.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

const pm_key *pm_key_find(const pm_key *keys, const char *name) {
  for (const pm_key *k = keys; k && k->type != PM_KEY_END; k++)
    if (strcmp(k->name, name) == 0) return k;
  return NULL;
}

void pm_key_names(const pm_name *names, char *buf, size_t size) {
  size_t used = 0;
  if (size) buf[0] = '\0';
  for (const pm_name *n = names; n && n->name && used < size; n++)
    used += (size_t)snprintf(buf + used, size - used, "%s%s",
                             n == names ? "" : ", ", n->name);
}

const char *pm_key_name_of(const pm_name *names, int v) {
  for (const pm_name *n = names; n && n->name; n++)
    if (n->value == v) return n->name;
  return "?";
}

bool pm_key_in_range(const pm_key *k, double v) {
  if (isnan(v)) return false;
  if ((k->range & PM_RANGE_GE) && !(v >= k->lo)) return false;
  if ((k->range & PM_RANGE_GT) && !(v > k->lo)) return false;
  if ((k->range & PM_RANGE_LE) && !(v <= k->hi)) return false;
  if ((k->range & PM_RANGE_LT) && !(v < k->hi)) return false;
  return true;
}

/* "a number > 0", "a number in (-1, 0.5)", "an integer in [1, 64]". */
static void describe_range(const pm_key *k, const char *noun, char *buf,
                           size_t size) {
  unsigned lo = k->range & (PM_RANGE_GE | PM_RANGE_GT);
  unsigned hi = k->range & (PM_RANGE_LE | PM_RANGE_LT);
  if (lo && hi)
    snprintf(buf, size, "%s in %c%.10g, %.10g%c", noun,
             lo == PM_RANGE_GE ? '[' : '(', k->lo, k->hi,
             hi == PM_RANGE_LE ? ']' : ')');
  else if (lo)
    snprintf(buf, size, "%s %s %.10g", noun, lo == PM_RANGE_GE ? ">=" : ">",
             k->lo);
  else if (hi)
    snprintf(buf, size, "%s %s %.10g", noun, hi == PM_RANGE_LE ? "<=" : "<",
             k->hi);
  else
    snprintf(buf, size, "%s", noun);
}

void pm_key_describe(const pm_key *k, char *buf, size_t size) {
  char names[512];
  switch (k->type) {
  case PM_KEY_NUMBER: describe_range(k, "a number", buf, size); break;
  case PM_KEY_INTEGER: describe_range(k, "an integer", buf, size); break;
  case PM_KEY_BOOL: snprintf(buf, size, "true or false"); break;
  case PM_KEY_STRING: snprintf(buf, size, "a non-empty string"); break;
  case PM_KEY_ENUM:
    pm_key_names(k->names, names, sizeof names);
    snprintf(buf, size, "one of %s", names);
    break;
  case PM_KEY_FLAGS:
    pm_key_names(k->names, names, sizeof names);
    snprintf(buf, size, "a list of names from %s", names);
    break;
  case PM_KEY_EXPR:
    snprintf(buf, size, "an expression in %s",
             (k->flags & PM_KEY_NO_T)     ? "x, y, z"
             : (k->flags & PM_KEY_NO_XYZ) ? "t"
                                          : "x, y, z, t");
    break;
  case PM_KEY_COMPONENTS:
    snprintf(buf, size, "a mapping of components x, y, z");
    break;
  case PM_KEY_POINT: snprintf(buf, size, "a list of 2 or 3 numbers"); break;
  case PM_KEY_NUMBERS: {
    char each[128];
    describe_range(k, (k->flags & PM_KEY_WHOLE) ? "integers" : "numbers", each,
                   sizeof each);
    if (k->min_count == k->max_count)
      snprintf(buf, size, "a list of %d %s", k->max_count, each);
    else
      snprintf(buf, size, "a list of %d to %d %s", k->min_count, k->max_count,
               each);
    break;
  }
  case PM_KEY_MAPPING: snprintf(buf, size, "a mapping"); break;
  case PM_KEY_LIST: snprintf(buf, size, "a list of mappings"); break;
  default: snprintf(buf, size, "%s", k->what ? k->what : "a value"); break;
  }
}

void pm_key_print(FILE *out, const pm_key *keys, const char *prefix) {
  char path[256], what[512], line[768];
  for (const pm_key *k = keys; k && k->type != PM_KEY_END; k++) {
    snprintf(path, sizeof path, "%s%s", prefix, k->name);
    if (k->type == PM_KEY_MAPPING) {
      fprintf(out, "%-38s %s\n", path, k->doc ? k->doc : "");
      char sub[260];
      snprintf(sub, sizeof sub, "%s.", path);
      pm_key_print(out, k->keys, sub);
      continue;
    }
    if (k->type == PM_KEY_LIST) snprintf(path + strlen(path), 8, ".N");
    pm_key_describe(k, what, sizeof what);
    snprintf(line, sizeof line, "%s%s%s%s%s", what,
             k->unit && k->unit[0] ? ", " : "", k->unit ? k->unit : "",
             (k->flags & PM_KEY_REQUIRED)        ? "; required"
             : (k->def && strcmp(k->def, "nan")) ? "; default "
                                                 : "",
             (k->flags & PM_KEY_REQUIRED) || !k->def || !strcmp(k->def, "nan")
                 ? ""
                 : k->def);
    fprintf(out, "%-38s %s\n%-38s   %s\n", path, k->doc ? k->doc : "", "",
            line);
    if (k->type == PM_KEY_LIST) {
      char sub[264];
      snprintf(sub, sizeof sub, "%s.", path);
      pm_key_print(out, k->keys, sub);
    }
  }
}
