/* pm_bench_suite: reading a bench suite file: its methods (variants of a
 * backend with overrides) and its cases (a scene, methods, resolutions),
 * every key checked and named in errors. */
#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm_backend.h"
#include "pm_bench_impl.h"
#include "pm_files.h"
#include "pm_scene.h"

/* Every key of mapping id (at path) is one of the names in keys
 * (comma-separated). */
static pm_err only_keys(const pm_sdoc *d, int id, const char *path,
                        const char *keys) {
  for (int i = 0; i < pm_sdoc_count(d, id); i++) {
    int value;
    const char *k = pm_sdoc_scalar(d, pm_sdoc_pair(d, id, i, &value));
    bool known = false;
    size_t len = k ? strlen(k) : 0;
    for (const char *p = keys; k && *p && !known;) {
      const char *e = strchr(p, ',');
      size_t n = e ? (size_t)(e - p) : strlen(p);
      known = n == len && strncmp(p, k, n) == 0;
      p += n + (e ? 1 : 0);
    }
    if (!known) {
      char at[PM_SDOC_PATH];
      snprintf(at, sizeof at, "%s%s%s", path, *path ? "." : "", k ? k : "?");
      return pm_sdoc_fail(d, at, true, "unknown key (expected one of %s)",
                          keys);
    }
  }
  return PM_SUCCESS;
}

/* The scalar at path, 1 to BENCH_NAME - 1 characters of a name (no ':',
 * '/', '=', ',' or blanks) unless free_text. */
static pm_err name_at(const pm_sdoc *d, const char *path, char *buf,
                      size_t size, const char *what) {
  const char *t = pm_sdoc_scalar(d, pm_sdoc_find(d, path, false));
  if (!t || !*t || strlen(t) >= size || strpbrk(t, ":/=, \t"))
    return pm_sdoc_expected(d, path, what);
  snprintf(buf, size, "%s", t);
  return PM_SUCCESS;
}

/* The list of scalars at path (absent: none) into items. */
static pm_err scalars_at(const pm_sdoc *d, const char *path, int max,
                         const char **items, int *n, const char *what) {
  int id = pm_sdoc_find(d, path, false);
  *n = 0;
  if (!id) return PM_SUCCESS;
  if (pm_sdoc_kind_of(d, id) != PM_SDOC_LIST)
    return pm_sdoc_expected(d, path, what);
  int count = pm_sdoc_count(d, id);
  if (count > max) return pm_sdoc_fail(d, path, false, "at most %d items", max);
  for (int i = 0; i < count; i++) {
    char at[PM_SDOC_PATH];
    snprintf(at, sizeof at, "%s.%d", path, i);
    items[i] = pm_sdoc_scalar(d, pm_sdoc_item(d, id, i));
    if (!items[i] || !*items[i]) return pm_sdoc_expected(d, at, what);
  }
  *n = count;
  return PM_SUCCESS;
}

/* An override KEY=VALUE (LABEL:KEY=VALUE when scoped), not the method. */
static pm_err check_set(const pm_sdoc *d, const char *path, const char *set,
                        bool scoped) {
  const char *eq = strchr(set, '='), *colon = strchr(set, ':');
  const char *key = scoped && colon && colon < eq ? colon + 1 : set;
  if (!eq || eq == key) return pm_sdoc_expected(d, path, "KEY=VALUE");
  if (strncmp(key, "method=", 7) == 0)
    return pm_sdoc_fail(d, path, false,
                        "the method of each run is the case's methods' "
                        "(methods.N.method), not an override");
  return PM_SUCCESS;
}

/* The list of overrides at path (checked by check_set). */
static pm_err sets_at(const pm_sdoc *d, const char *path, const char **sets,
                      int *n, bool scoped) {
  PM_CALL(scalars_at(d, path, BENCH_SETS, sets, n,
                     scoped ? "a list of KEY=VALUE or LABEL:KEY=VALUE "
                              "overrides"
                            : "a list of KEY=VALUE overrides"));
  for (int k = 0; k < *n; k++) {
    char at[PM_SDOC_PATH + 16];
    snprintf(at, sizeof at, "%.*s.%d", PM_SDOC_PATH - 1, path, k);
    PM_CALL(check_set(d, at, sets[k], scoped));
  }
  return PM_SUCCESS;
}

/* The mapping at path, holding no key but those of keys. */
static pm_err mapping_at(const pm_sdoc *d, const char *path, const char *keys,
                         const char *what) {
  int id = pm_sdoc_find(d, path, false);
  if (pm_sdoc_kind_of(d, id) != PM_SDOC_MAPPING)
    return pm_sdoc_expected(d, path, what);
  return only_keys(d, id, path, keys);
}

/* Fails at path when name is one of the n names before it (the first at
 * first, each stride bytes after the one before), with message (its %s:
 * the name, its %d: the earlier one's index). */
static pm_err unique_name(const pm_sdoc *d, const char *path, const char *name,
                          const char *first, size_t stride, int n,
                          const char *message) {
  for (int k = 0; k < n; k++)
    if (strcmp(first + (size_t)k * stride, name) == 0)
      return pm_sdoc_fail(d, path, false, message, name, k);
  return PM_SUCCESS;
}

static pm_err read_method(pm_bench_suite *S, int i) {
  const pm_sdoc *d = &S->doc;
  pm_bench_method *M = &S->m[i];
  char p[32], q[64];
  snprintf(p, sizeof p, "methods.%d", i);
  PM_CALL(
      mapping_at(d, p, "label,method,set", "a mapping {label, method, set}"));
  snprintf(q, sizeof q, "%s.label", p);
  PM_CALL(name_at(d, q, M->label, sizeof M->label,
                  "a label of up to 63 characters without ':', '/', '=', "
                  "',' or blanks"));
  snprintf(q, sizeof q, "%s.method", p);
  PM_CALL(name_at(d, q, M->method, sizeof M->method, "a method name"));
  if (!pm_backend_find(M->method)) {
    char names[256];
    pm_backend_names(names, sizeof names);
    return pm_sdoc_fail(d, q, false, "expected one of %s, got %s", names,
                        M->method);
  }
  PM_CALL(unique_name(d, p, M->label, S->m[0].label, sizeof S->m[0], i,
                      "label %s is defined twice (also methods.%d)"));
  snprintf(q, sizeof q, "%s.set", p);
  return sets_at(d, q, M->sets, &M->n_sets, false);
}

/* The whole number at path, lo to hi, into *v. */
static pm_err count_at(const pm_sdoc *d, const char *path, int lo, int hi,
                       int *v, const char *what) {
  double x;
  const char *t = pm_sdoc_scalar(d, pm_sdoc_find(d, path, false));
  if (!t || !pm_parse_number(t, &x) || x != floor(x) || x < lo || x > hi)
    return pm_sdoc_expected(d, path, what);
  *v = (int)x;
  return PM_SUCCESS;
}

/* A case's FE ladder (at path, absent: none): {ladder: [N, ...], threads:
 * T}, the meshes CalculiX solves (tools/fe-referee.py), coarsest first. */
static pm_err read_fe(const pm_sdoc *d, const char *path, pm_bench_case *C) {
  char q[PM_SDOC_PATH + 16];
  C->n_fe = C->fe_threads = 0;
  if (!pm_sdoc_find(d, path, false)) return PM_SUCCESS;
  PM_CALL(mapping_at(d, path, "ladder,threads",
                     "a mapping {ladder: [N, ...], threads}"));
  const char *items[BENCH_FE_LEVELS];
  snprintf(q, sizeof q, "%s.ladder", path);
  if (!pm_sdoc_find(d, q, false))
    return pm_sdoc_expected(d, q, "a list of meshes N (elements per edge)");
  PM_CALL(scalars_at(d, q, BENCH_FE_LEVELS, items, &C->n_fe,
                     "a list of meshes N (elements per edge)"));
  if (C->n_fe < 1)
    return pm_sdoc_expected(d, q, "a list of at least one mesh N");
  for (int k = 0; k < C->n_fe; k++) {
    char at[PM_SDOC_PATH + 32];
    snprintf(at, sizeof at, "%s.%d", q, k);
    PM_CALL(count_at(d, at, 1, 64, &C->fe_ladder[k],
                     "a mesh N: a whole number of elements per edge, 1 to "
                     "64, above the one before"));
    if (k && C->fe_ladder[k] <= C->fe_ladder[k - 1])
      return pm_sdoc_expected(d, at,
                              "a mesh N above the one before (coarsest "
                              "first)");
  }
  snprintf(q, sizeof q, "%s.threads", path);
  if (pm_sdoc_find(d, q, false))
    PM_CALL(count_at(d, q, 1, 256, &C->fe_threads,
                     "a number of threads for CalculiX, 1 to 256"));
  return PM_SUCCESS;
}

static pm_err read_case(pm_bench_suite *S, int i) {
  const pm_sdoc *d = &S->doc;
  pm_bench_case *C = &S->c[i];
  char p[32], q[64];
  snprintf(p, sizeof p, "cases.%d", i);
  PM_CALL(mapping_at(d, p, "name,scene,methods,resolutions,set,fe",
                     "a mapping {name, scene, methods, resolutions, set, "
                     "fe}"));
  snprintf(q, sizeof q, "%s.name", p);
  PM_CALL(name_at(d, q, C->name, sizeof C->name,
                  "a case name of up to 63 characters without ':', '/', "
                  "'=', ',' or blanks"));
  PM_CALL(unique_name(d, q, C->name, S->c[0].name, sizeof S->c[0], i,
                      "case %s is named twice (also cases.%d)"));
  /* The scene, relative to the suite file. */
  snprintf(q, sizeof q, "%s.scene", p);
  const char *scene = pm_sdoc_scalar(d, pm_sdoc_find(d, q, false));
  if (!scene || !*scene)
    return pm_sdoc_expected(d, q, "a scene file (relative to the suite)");
  if (scene[0] == '/')
    snprintf(C->scene, sizeof C->scene, "%s", scene);
  else
    PM_CALL(pm_path_join(C->scene, sizeof C->scene, S->folder, scene));
  if (access(C->scene, R_OK) != 0)
    return pm_sdoc_fail(d, q, false, "cannot read scene %s: %s", C->scene,
                        strerror(errno));
  /* Methods: labels of the suite's methods, or methods by name. */
  const char *names[PM_COMPARE_MAX_METHODS];
  snprintf(q, sizeof q, "%s.methods", p);
  PM_CALL(scalars_at(d, q, PM_COMPARE_MAX_METHODS, names, &C->n_methods,
                     "a list of method labels"));
  if (!pm_sdoc_find(d, q, false)) {
    if (S->n_methods == 0)
      return pm_sdoc_fail(d, p, false,
                          "no methods: give the case's methods, or the "
                          "suite's (methods: [{label, method, set}])");
    if (S->n_methods > PM_COMPARE_MAX_METHODS)
      return pm_sdoc_fail(d, p, false,
                          "the suite has %d methods and a comparison at "
                          "most %d: give the case's methods",
                          S->n_methods, PM_COMPARE_MAX_METHODS);
    C->n_methods = S->n_methods;
    for (int k = 0; k < S->n_methods; k++) C->method[k] = k;
  }
  for (int k = 0; k < C->n_methods && names[0] && pm_sdoc_find(d, q, false);
       k++) {
    char at[96];
    snprintf(at, sizeof at, "%s.%d", q, k);
    C->method[k] = -1;
    for (int l = 0; l < S->n_methods; l++)
      if (strcmp(S->m[l].label, names[k]) == 0) C->method[k] = l;
    if (C->method[k] < 0) {
      if (!pm_backend_find(names[k]) || strlen(names[k]) >= BENCH_NAME)
        return pm_sdoc_fail(d, at, false,
                            "%s is neither a label of the suite's methods "
                            "nor a method",
                            names[k]);
      C->method[k] = -2;
      snprintf(C->plain[k], sizeof C->plain[k], "%s", names[k]);
    }
    for (int l = 0; l < k; l++)
      if (strcmp(names[l], names[k]) == 0)
        return pm_sdoc_fail(d, at, false, "%s is named twice", names[k]);
  }
  /* Resolutions. */
  const char *res[BENCH_RES];
  snprintf(q, sizeof q, "%s.resolutions", p);
  PM_CALL(scalars_at(d, q, BENCH_RES, res, &C->n_res,
                     "a list of cell or element sizes (m)"));
  for (int k = 0; k < C->n_res; k++) {
    char at[96];
    snprintf(at, sizeof at, "%s.%d", q, k);
    if (!pm_parse_number(res[k], &C->res[k]) || !(C->res[k] > 0) ||
        !isfinite(C->res[k]))
      return pm_sdoc_expected(d, at, "a size above 0 (m)");
  }
  snprintf(q, sizeof q, "%s.fe", p);
  PM_CALL(read_fe(d, q, C));
  /* Overrides: every method, or LABEL:KEY=VALUE one of them. */
  snprintf(q, sizeof q, "%s.set", p);
  return sets_at(d, q, C->sets, &C->n_sets, true);
}

pm_err pm_bench_read_suite(const char *path, pm_bench_suite *S) {
  size_t len;
  snprintf(S->path, sizeof S->path, "%s", path);
  char tmp[PM_PATH_MAX + 1];
  snprintf(tmp, sizeof tmp, "%s", path);
  snprintf(S->folder, sizeof S->folder, "%s", dirname(tmp));
  PM_CALL(pm_read_text(path, "suite", &S->text, &len));
  PM_CALL(pm_sdoc_parse(&S->doc, path, S->text, len));
  const pm_sdoc *d = &S->doc;
  int root = pm_sdoc_root(d);
  if (pm_sdoc_kind_of(d, root) != PM_SDOC_MAPPING)
    return pm_sdoc_fail(d, "", false,
                        "expected a mapping {name, methods, cases}");
  PM_CALL(only_keys(d, root, "", "name,methods,cases"));
  PM_CALL(name_at(d, "name", S->name, sizeof S->name,
                  "a suite name of up to 63 characters without ':', '/', "
                  "'=', ',' or blanks"));
  int id = pm_sdoc_find(d, "methods", false);
  if (id) {
    if (pm_sdoc_kind_of(d, id) != PM_SDOC_LIST)
      return pm_sdoc_expected(d, "methods", "a list of {label, method, set}");
    S->n_methods = pm_sdoc_count(d, id);
    if (S->n_methods > BENCH_METHODS)
      return pm_sdoc_fail(d, "methods", false, "at most %d methods",
                          BENCH_METHODS);
    for (int i = 0; i < S->n_methods; i++) PM_CALL(read_method(S, i));
  }
  id = pm_sdoc_find(d, "cases", false);
  if (pm_sdoc_kind_of(d, id) != PM_SDOC_LIST || pm_sdoc_count(d, id) < 1)
    return pm_sdoc_expected(d, "cases",
                            "a list of cases {name, scene, methods, "
                            "resolutions, set}");
  S->n_cases = pm_sdoc_count(d, id);
  if (S->n_cases > BENCH_CASES)
    return pm_sdoc_fail(d, "cases", false, "at most %d cases", BENCH_CASES);
  for (int i = 0; i < S->n_cases; i++) PM_CALL(read_case(S, i));
  return PM_SUCCESS;
}
