/* pm_bench: a suite of comparisons (pm_bench.h): the suite file read and
 * checked, each case run per resolution by pm_compare_run, the FE
 * referee's ladder beside, and one report. */
#include "pm_bench.h"

#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "pm_backend.h"
#include "pm_compare.h"
#include "pm_fe.h"
#include "pm_files.h"
#include "pm_scene.h"
#include "pm_scene_doc.h"

#define BENCH_NAME PM_COMPARE_NAME_MAX
#define BENCH_METHODS 16 /* variants a suite defines */
#define BENCH_CASES 64
#define BENCH_RES 8   /* resolutions of a case */
#define BENCH_SETS 32 /* overrides of a method or a case */
#define BENCH_FE_ROWS 16
#define MIB (1024.0 * 1024.0)

typedef struct {
  char label[BENCH_NAME], method[BENCH_NAME];
  int n_sets;
  const char *sets[BENCH_SETS]; /* the suite document's text */
} bench_method;

typedef struct {
  char name[BENCH_NAME];
  char scene[PM_PATH_MAX + 1];
  int n_methods;
  int method[PM_COMPARE_MAX_METHODS]; /* suite methods, or -1 - backend */
  char plain[PM_COMPARE_MAX_METHODS][BENCH_NAME]; /* a method by name */
  int n_res;
  double res[BENCH_RES]; /* discretization.mesh_size (none: the scene's) */
  int n_sets;
  const char *sets[BENCH_SETS];
} bench_case;

/* One comparison: a case at a resolution. */
typedef struct {
  int c;
  double res; /* NaN: the scene's own */
  char dir[PM_PATH_MAX + 1];
  pm_err err;
  char message[PM_COMPARE_MESSAGE_MAX]; /* when no method ran */
  int n_rows;
  pm_compare_row rows[PM_COMPARE_MAX_METHODS];
  double seconds; /* the comparison's wall time */
} bench_run;

/* The FE referee of a case: its ladder's reactions and times. */
typedef struct {
  bool have;
  char dir[PM_PATH_MAX + 1];
  int n;
  pm_fe_row rows[BENCH_FE_ROWS];
  double reaction; /* the referee's loaded reaction, N */
  double tol;      /* its relative reaction tolerance (NaN: none) */
  int axis;
} bench_fe;

typedef struct {
  pm_sdoc doc;
  char *text;
  char path[PM_PATH_MAX + 1], folder[PM_PATH_MAX + 1];
  char name[BENCH_NAME];
  int n_methods;
  bench_method m[BENCH_METHODS];
  int n_cases;
  bench_case c[BENCH_CASES];
} bench_suite;

/* ---- reading the suite ----------------------------------------------------
 */

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

static pm_err read_method(bench_suite *S, int i) {
  const pm_sdoc *d = &S->doc;
  bench_method *M = &S->m[i];
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
  for (int k = 0; k < i; k++)
    if (strcmp(S->m[k].label, M->label) == 0)
      return pm_sdoc_fail(d, p, false,
                          "label %s is defined twice (also "
                          "methods.%d)",
                          M->label, k);
  snprintf(q, sizeof q, "%s.set", p);
  return sets_at(d, q, M->sets, &M->n_sets, false);
}

static pm_err read_case(bench_suite *S, int i) {
  const pm_sdoc *d = &S->doc;
  bench_case *C = &S->c[i];
  char p[32], q[64];
  snprintf(p, sizeof p, "cases.%d", i);
  PM_CALL(mapping_at(d, p, "name,scene,methods,resolutions,set",
                     "a mapping {name, scene, methods, resolutions, set}"));
  snprintf(q, sizeof q, "%s.name", p);
  PM_CALL(name_at(d, q, C->name, sizeof C->name,
                  "a case name of up to 63 characters without ':', '/', "
                  "'=', ',' or blanks"));
  for (int k = 0; k < i; k++)
    if (strcmp(S->c[k].name, C->name) == 0)
      return pm_sdoc_fail(d, q, false,
                          "case %s is named twice (also "
                          "cases.%d)",
                          C->name, k);
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
  /* Overrides: every method, or LABEL:KEY=VALUE one of them. */
  snprintf(q, sizeof q, "%s.set", p);
  return sets_at(d, q, C->sets, &C->n_sets, true);
}

static pm_err read_suite(const char *path, bench_suite *S) {
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

/* ---- running --------------------------------------------------------------
 */

/* Whether case name is selected by only (NULL: every case; else a
 * comma-separated list of names, each selecting the cases whose name holds
 * it). */
static bool selected(const char *only, const char *name) {
  if (!only) return true;
  for (const char *p = only; *p;) {
    const char *e = strchr(p, ',');
    size_t n = e ? (size_t)(e - p) : strlen(p);
    for (const char *q = name; n && strlen(q) >= n; q++)
      if (strncmp(q, p, n) == 0) return true;
    p += n + (e ? 1 : 0);
  }
  return false;
}

static const char *label_of(const bench_suite *S, const bench_case *C, int k) {
  return C->method[k] >= 0 ? S->m[C->method[k]].label : C->plain[k];
}

/* The comparison's options for case C at resolution res: methods as
 * LABEL=METHOD, then the overrides (the case's for every method, the
 * resolution, the command line's; then each method's own, scoped). */
static pm_err compare_options(const bench_suite *S, const bench_case *C,
                              double res, const pm_bench_options *o,
                              char *methods, size_t size, char (*own)[512],
                              const char **sets, int *n_sets) {
  size_t used = 0;
  int n = 0;
  methods[0] = 0;
  for (int k = 0; k < C->n_methods; k++) {
    const char *label = label_of(S, C, k);
    const char *method = C->method[k] >= 0 ? S->m[C->method[k]].method : label;
    used += (size_t)snprintf(methods + used, size - used, "%s%s=%s",
                             k ? "," : "", label, method);
    PM_CHECK(used < size, PM_ERR_SCENE, "%s: case %s: too many methods",
             S->path, C->name);
  }
  for (int k = 0; k < C->n_sets; k++) sets[n++] = C->sets[k];
  if (isfinite(res)) {
    snprintf(own[0], sizeof own[0], "discretization.mesh_size=%.17g", res);
    sets[n++] = own[0];
  }
  for (int k = 0; k < o->n_sets; k++) sets[n++] = o->sets[k];
  int o_own = 1;
  for (int k = 0; k < C->n_methods; k++) {
    if (C->method[k] < 0) continue;
    const bench_method *M = &S->m[C->method[k]];
    for (int j = 0; j < M->n_sets; j++) {
      PM_CHECK(o_own < BENCH_METHODS * BENCH_SETS, PM_ERR_SCENE,
               "%s: case %s: too many overrides", S->path, C->name);
      snprintf(own[o_own], sizeof own[o_own], "%s:%s", M->label, M->sets[j]);
      sets[n++] = own[o_own++];
    }
  }
  *n_sets = n;
  return PM_SUCCESS;
}

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The NRMSE a run is judged by, and against what: the FE referee's
 * lattice, else the analytic field, else a reference run. */
static double judged(const pm_compare_row *r, const char **against) {
  if (isfinite(r->e_fe)) return *against = "FE", r->e_fe;
  if (isfinite(r->e_analytic)) return *against = "analytic", r->e_analytic;
  if (isfinite(r->e_run)) return *against = "run", r->e_run;
  *against = "";
  return NAN;
}

static void print_row(FILE *out, const pm_compare_row *r) {
  const char *against, *sep = " ";
  double e = judged(r, &against);
  fprintf(out, "    %-14s %-13s", r->name, r->status);
  if (isfinite(e)) {
    fprintf(out, "%sNRMSE %.3g (%s)", sep, e, against);
    sep = ", ";
  }
  if (isfinite(r->reaction_fe)) {
    fprintf(out, "%sreaction %+.2f%% of FE", sep, 100 * r->reaction_fe);
    sep = ", ";
  }
  if (r->ran)
    fprintf(out, "%s%.2f s, %.0f MiB", sep, r->wall_seconds,
            (double)r->memory_bytes / MIB);
  if (r->message[0]) fprintf(out, "\n      %s", r->message);
  fprintf(out, "\n");
}

static void run_one(const bench_suite *S, const pm_bench_options *o,
                    bench_run *R, FILE *out) {
  const bench_case *C = &S->c[R->c];
  char methods[PM_COMPARE_MAX_METHODS * 2 * BENCH_NAME];
  static char own[BENCH_METHODS * BENCH_SETS][512];
  const char *sets[BENCH_SETS * 2 + 64 + BENCH_METHODS * BENCH_SETS];
  int n_sets = 0;
  double t0 = now();
  R->err = compare_options(S, C, R->res, o, methods, sizeof methods, own, sets,
                           &n_sets);
  if (R->err == PM_SUCCESS) {
    pm_compare_options co = {
        .scene = C->scene,
        .methods = methods,
        .n_sets = n_sets,
        .sets = sets,
        .out_dir = R->dir,
        .quiet = o->quiet,
        .overwrite = o->overwrite,
        .rows = R->rows,
        .n_rows = &R->n_rows,
    };
    R->err = pm_compare_run(&co, NULL, NULL, 0);
  }
  R->seconds = now() - t0;
  if (R->err != PM_SUCCESS && R->n_rows == 0)
    snprintf(R->message, sizeof R->message, "%s", pm_error_message());
  pm_error_clear();
  if (!out) return;
  if (R->n_rows == 0) fprintf(out, "    failed: %s\n", R->message);
  for (int k = 0; k < R->n_rows; k++) print_row(out, &R->rows[k]);
  fflush(out);
}

/* The FE referee of case C, when its scene names one. */
static void case_fe(const bench_suite *S, const bench_case *C, bench_fe *F) {
  pm_scene *s = NULL;
  pm_fe_reference *r = NULL;
  memset(F, 0, sizeof *F);
  if (pm_scene_load(C->scene, C->n_sets, C->sets, &s) == PM_SUCCESS &&
      s->reference_fe && pm_fe_load(s->reference_fe, &r) == PM_SUCCESS) {
    F->have = true;
    snprintf(F->dir, sizeof F->dir, "%s", r->dir);
    F->axis = 0;
    for (int k = 1; k < 3; k++)
      if (fabs(r->reaction[k]) > fabs(r->reaction[F->axis])) F->axis = k;
    F->reaction = r->reaction[F->axis];
    F->tol = r->tolerance.reaction;
    F->n = r->n_rows < BENCH_FE_ROWS ? r->n_rows : BENCH_FE_ROWS;
    for (int k = 0; k < F->n; k++) F->rows[k] = r->rows[k];
  }
  pm_error_clear();
  (void)S;
  pm_fe_free(r);
  pm_scene_destroy(s);
}

/* ---- the report -----------------------------------------------------------
 */

static void res_text(char *b, size_t size, double res) {
  if (isfinite(res))
    snprintf(b, size, "%g", res);
  else
    snprintf(b, size, "scene");
}

/* Whether a run reached a state its figures are of. */
static bool reached(const pm_compare_row *r) {
  return strcmp(r->status, "converged") == 0 ||
         strcmp(r->status, "completed") == 0;
}

/* Cross-validation: for each case with an FE referee and each method run
 * at two or more resolutions, the reaction error of its finest run
 * against the change its last refinement made.  A method converging
 * toward the referee at first order or better has an error no larger than
 * that change (h halved: e_f = (e_c - e_f) / (2^q - 1) <= e_c - e_f for q
 * >= 1); an error well beyond it (more than twice) is the method's bias,
 * which its own refinement does not show. */
static void md_verdict(const bench_suite *S, const bench_run *runs, int n_runs,
                       const bench_fe *fe, FILE *m) {
  bool header = false;
  char b[4][PM_TABLE_NUMBER];
  for (int c = 0; c < S->n_cases; c++) {
    const bench_case *C = &S->c[c];
    if (!fe[c].have) continue;
    for (int k = 0; k < C->n_methods; k++) {
      const pm_compare_row *coarse = NULL, *fine = NULL;
      for (int i = 0; i < n_runs; i++) {
        if (runs[i].c != c || k >= runs[i].n_rows) continue;
        const pm_compare_row *r = &runs[i].rows[k];
        if (!reached(r) || !isfinite(r->reaction_fe)) continue;
        if (!fine || r->points > fine->points) {
          coarse = fine;
          fine = r;
        } else if (!coarse || r->points > coarse->points) {
          coarse = r;
        }
      }
      if (!coarse) continue;
      if (!header) {
        fprintf(m, "\n## Convergence toward the referee\n\n| case | "
                   "method | points | reaction error (%%) | change by the "
                   "last refinement (%%) | NRMSE | verdict |\n"
                   "|---|---|---|---|---|---|---|\n");
        header = true;
      }
      const double e = fine->reaction_fe, d = coarse->reaction_fe - e;
      const double tol = fe[c].tol;
      const char *verdict =
          isfinite(tol) && fabs(e) <= tol
              ? "agrees with FE within its tolerance"
          : fabs(e) >= fabs(e + d)
              ? "not converging toward FE: its error grew with refinement"
          : fabs(e) <= 2 * fabs(d)
              ? "converging toward FE"
              : "biased: its refinement does not show its error";
      fprintf(m, "| %s | %s | %ld -> %ld | %s | %s | %s | %s |\n", C->name,
              fine->name, coarse->points, fine->points,
              pm_table_number(b[0], 100 * e, 3),
              pm_table_number(b[1], 100 * d, 3),
              pm_table_number(b[2], fine->e_fe, 3), verdict);
    }
  }
  if (header)
    fprintf(m, "\nA method whose error at its finest run is at most twice "
               "the change its last refinement made converges toward the "
               "referee (at order 1 or better in h); one whose error shrank "
               "by less than that is biased: a denser run of it alone "
               "would agree with itself and not with FE.\n");
}

static void write_md(const bench_suite *S, const bench_run *runs, int n_runs,
                     const bench_fe *fe, double seconds, FILE *m) {
  char b[6][PM_TABLE_NUMBER], res[32];
  int n_fail = 0;
  fprintf(m,
          "# Benchmark suite: %s\n\nSuite %s: %d cases, %d comparisons, "
          "%.1f s in all.\n\n## Accuracy and cost\n\n",
          S->name, S->path, S->n_cases, n_runs, seconds);
  fprintf(m, "| case | resolution (m) | method | status | points | h (m) | "
             "steps | NRMSE | against | reaction error (FE) | wall (s) | "
             "memory (MiB) |\n|---|---|---|---|---|---|---|---|---|---|---|"
             "---|\n");
  for (int i = 0; i < n_runs; i++) {
    const bench_run *R = &runs[i];
    res_text(res, sizeof res, R->res);
    if (R->n_rows == 0) {
      fprintf(m, "| %s | %s | | failed | | | | | | | | |\n", S->c[R->c].name,
              res);
      n_fail++;
    }
    for (int k = 0; k < R->n_rows; k++) {
      const pm_compare_row *r = &R->rows[k];
      const char *against;
      double e = judged(r, &against);
      n_fail += r->message[0] != 0;
      fprintf(m, "| %s | %s | %s | %s |", S->c[R->c].name, res, r->name,
              r->status);
      if (r->ran)
        fprintf(m, " %ld | %s | %ld |", r->points,
                pm_table_number(b[0], r->h, 4), r->steps);
      else
        fprintf(m, " | | |");
      fprintf(m, " %s | %s | %s |", pm_table_number(b[1], e, 3), against,
              pm_table_number(b[2], 100 * r->reaction_fe, 3));
      if (r->ran)
        fprintf(m, " %.3g | %.1f |\n", r->wall_seconds,
                (double)r->memory_bytes / MIB);
      else
        fprintf(m, " | |\n");
    }
  }
  fprintf(m, "\nReaction error in %% of the FE referee's loaded reaction.\n");
  bool any_fe = false;
  for (int c = 0; c < S->n_cases; c++) any_fe = any_fe || fe[c].have;
  if (any_fe) {
    fprintf(m, "\n## The FE referee's ladder\n\n| case | N | nodes | h (m) | "
               "reaction (N) | reaction error (%%) | wall (s) |\n"
               "|---|---|---|---|---|---|---|\n");
    for (int c = 0; c < S->n_cases; c++) {
      const bench_fe *F = &fe[c];
      if (!F->have) continue;
      for (int k = 0; k < F->n; k++) {
        const pm_fe_row *r = &F->rows[k];
        if (!r->converged) continue;
        double err = (r->reaction[F->axis] - F->reaction) / F->reaction;
        fprintf(m, "| %s | %d | %ld | %s | %s | %s | %.3g |\n", S->c[c].name,
                r->n, r->nodes, pm_table_number(b[0], r->h, 4),
                pm_table_number(b[1], r->reaction[F->axis], 6),
                pm_table_number(b[2], 100 * err, 3), r->wall_seconds);
      }
    }
    fprintf(m, "\nErrors against the referee's finest converged level, "
               "whose own uncertainty its tolerance.csv gives; the coarser "
               "levels show what FE accuracy costs in time (CalculiX, its "
               "recorded wall time).\n");
  }
  md_verdict(S, runs, n_runs, fe, m);
  if (n_fail) {
    fprintf(m, "\n## Failures\n\n");
    for (int i = 0; i < n_runs; i++) {
      const bench_run *R = &runs[i];
      res_text(res, sizeof res, R->res);
      if (R->n_rows == 0) {
        fprintf(m, "- %s at %s: ", S->c[R->c].name, res);
        pm_md_text(m, R->message);
        fprintf(m, "\n");
      }
      for (int k = 0; k < R->n_rows; k++) {
        const pm_compare_row *r = &R->rows[k];
        if (!r->message[0]) continue;
        fprintf(m, "- %s at %s, %s (%s): ", S->c[R->c].name, res, r->name,
                r->status);
        pm_md_text(m, r->message);
        fprintf(m, "\n");
      }
    }
  }
  fprintf(m, "\n## Definitions\n\nEach case runs at each resolution "
             "(discretization.mesh_size) as one `pointmech compare` in "
             "CASE/h-RESOLUTION, whose compare.md has every figure.  NRMSE: "
             "the displacement against the FE referee's lattice when the "
             "scene has one, else against the analytic field "
             "(reference.displacement), mapped by moving least squares.  "
             "Wall time: the run's own, setup included.  Pictures: "
             "accuracy-cost.png (tools/plot-bench.py).\n");
}

static void write_csv(const bench_suite *S, const bench_run *runs, int n_runs,
                      const bench_fe *fe, FILE *f) {
  char b[12][PM_TABLE_NUMBER];
  fprintf(f, "kind,case,resolution,label,method,status,points,h,steps,"
             "nrmse,against,nrmse_analytic,nrmse_fe,reaction_error_fe,"
             "sed_error_fe,min_jacobian,wall_seconds,setup_seconds,"
             "memory_bytes,message\n");
  for (int i = 0; i < n_runs; i++) {
    const bench_run *R = &runs[i];
    const char *cname = S->c[R->c].name;
    pm_table_number(b[0], R->res, 10);
    if (R->n_rows == 0) {
      fprintf(f, "method,%s,%s,,,failed,,,,,,,,,,,,,,", cname, b[0]);
      pm_csv_text(f, R->message);
      fputc('\n', f);
    }
    for (int k = 0; k < R->n_rows; k++) {
      const pm_compare_row *r = &R->rows[k];
      const char *against;
      double e = judged(r, &against);
      fprintf(f, "method,%s,%s,%s,%s,%s,", cname, b[0], r->name, r->method,
              r->status);
      if (r->ran)
        fprintf(f, "%ld,%s,%ld", r->points, pm_table_number(b[1], r->h, 10),
                r->steps);
      else
        fprintf(f, ",,");
      fprintf(f, ",%s,%s,%s,%s,%s,%s,%s,", pm_table_number(b[2], e, 10),
              against, pm_table_number(b[3], r->e_analytic, 10),
              pm_table_number(b[4], r->e_fe, 10),
              pm_table_number(b[5], r->reaction_fe, 10),
              pm_table_number(b[6], r->sed_fe, 10),
              pm_table_number(b[7], r->min_jacobian, 10));
      if (r->ran)
        fprintf(f, "%.6g,%.6g,%zu,", r->wall_seconds, r->setup_seconds,
                r->memory_bytes);
      else
        fprintf(f, ",,,");
      pm_csv_text(f, r->message);
      fputc('\n', f);
    }
  }
  for (int c = 0; c < S->n_cases; c++) {
    const bench_fe *F = &fe[c];
    if (!F->have) continue;
    for (int k = 0; k < F->n; k++) {
      const pm_fe_row *r = &F->rows[k];
      if (!r->converged) continue;
      double err = (r->reaction[F->axis] - F->reaction) / F->reaction;
      fprintf(
          f, "fe,%s,,fe,CalculiX %s,converged,%ld,%s,%ld,,,,,%s,,,%.6g,,,\n",
          S->c[c].name, r->element, r->nodes, pm_table_number(b[0], r->h, 10),
          r->increments, pm_table_number(b[1], err, 10), r->wall_seconds);
    }
  }
}

static pm_err write_report(const char *dir, const bench_suite *S,
                           const bench_run *runs, int n_runs,
                           const bench_fe *fe, double seconds, FILE *out) {
  pm_err ret = PM_SUCCESS;
  pm_afile *md = NULL, *csv = NULL;
  char path[PM_PATH_MAX + 1], *text = NULL;
  size_t len = 0;
  FILE *mem = open_memstream(&text, &len);
  PM_ENSURE(mem, PM_ERR_MEMORY, "cannot build the bench report");
  write_md(S, runs, n_runs, fe, seconds, mem);
  fclose(mem);
  PM_TRY(pm_path_join(path, sizeof path, dir, "bench.md"));
  PM_TRY(pm_afile_open(path, &md));
  fputs(text, pm_afile_stream(md));
  PM_TRY(pm_afile_commit(md));
  md = NULL;
  PM_TRY(pm_path_join(path, sizeof path, dir, "bench.csv"));
  PM_TRY(pm_afile_open(path, &csv));
  write_csv(S, runs, n_runs, fe, pm_afile_stream(csv));
  PM_TRY(pm_afile_commit(csv));
  csv = NULL;
  if (out) fprintf(out, "report in %s/bench.{md,csv}\n", dir);
done:
  if (md) pm_afile_abort(md);
  if (csv) pm_afile_abort(csv);
  free(text);
  return ret;
}

/* ---- the suite -------------------------------------------------------- */

pm_err pm_bench_run(const pm_bench_options *o, FILE *out, char *dir,
                    size_t size) {
  pm_err ret = PM_SUCCESS, first = PM_SUCCESS;
  bench_suite *S = NULL;
  bench_run *runs = NULL;
  bench_fe *fe = NULL;
  char out_dir[PM_PATH_MAX + 1], path[PM_PATH_MAX + 1];
  int n_runs = 0, first_run = -1;
  if (dir && size) dir[0] = 0;
  PM_TRY(PM_ALLOC(S, 1, "bench suite"));
  PM_TRY(read_suite(o->suite, S));
  if (o->out_dir)
    snprintf(out_dir, sizeof out_dir, "%s", o->out_dir);
  else
    snprintf(out_dir, sizeof out_dir, "out/%s-bench", S->name);
  PM_TRY(pm_path_join(path, sizeof path, out_dir, "bench.csv"));
  PM_ENSURE(o->overwrite || access(path, F_OK) != 0, PM_ERR_IO,
            "%s already holds a bench's report: pass --overwrite to run the "
            "suite again over it, or choose another --out",
            out_dir);
  PM_TRY(pm_mkdir_p(out_dir));
  if (dir && size) snprintf(dir, size, "%s", out_dir);
  /* The runs: each selected case at each resolution. */
  int total = 0;
  for (int c = 0; c < S->n_cases; c++)
    if (selected(o->only, S->c[c].name))
      total += S->c[c].n_res ? S->c[c].n_res : 1;
  PM_ENSURE(total > 0, PM_ERR_SCENE,
            "%s: no case's name holds any of '%s' (--only)", o->suite, o->only);
  PM_TRY(PM_ALLOC(runs, (size_t)total, "bench runs"));
  PM_TRY(PM_ALLOC(fe, (size_t)S->n_cases, "bench FE ladders"));
  for (int c = 0; c < S->n_cases; c++) {
    const bench_case *C = &S->c[c];
    if (!selected(o->only, C->name)) continue;
    case_fe(S, C, &fe[c]);
    for (int j = 0; j < (C->n_res ? C->n_res : 1); j++) {
      bench_run *R = &runs[n_runs++];
      R->c = c;
      R->res = C->n_res ? C->res[j] : NAN;
      char res[32], sub[PM_PATH_MAX + 1];
      res_text(res, sizeof res, R->res);
      snprintf(sub, sizeof sub, "%s/h-%s", C->name, res);
      PM_TRY(pm_path_join(R->dir, sizeof R->dir, out_dir, sub));
    }
  }
  double t0 = now();
  for (int i = 0; i < n_runs; i++) {
    bench_run *R = &runs[i];
    const bench_case *C = &S->c[R->c];
    char res[32];
    res_text(res, sizeof res, R->res);
    if (out) {
      fprintf(out, "[%d/%d] %s at %s (%.0f s so far):", i + 1, n_runs, C->name,
              res, now() - t0);
      for (int k = 0; k < C->n_methods; k++)
        fprintf(out, " %s", label_of(S, C, k));
      fprintf(out, "\n");
      fflush(out);
    }
    run_one(S, o, R, out);
    if (R->err != PM_SUCCESS && first == PM_SUCCESS) {
      first = R->err;
      first_run = i;
    }
    if (R->err == PM_ERR_INTERRUPTED) {
      n_runs = i + 1;
      break;
    }
  }
  PM_TRY(write_report(out_dir, S, runs, n_runs, fe, now() - t0, out));
  if (first != PM_SUCCESS) {
    int n_failed = 0;
    for (int i = 0; i < n_runs; i++) n_failed += runs[i].err != PM_SUCCESS;
    ret = PM_ERROR(first,
                   "%s: %d of %d comparisons had a failure (the first: %s at "
                   "%g); the report lists each: %s/bench.md",
                   o->suite, n_failed, n_runs, S->c[runs[first_run].c].name,
                   runs[first_run].res, out_dir);
  }
done:
  if (S) {
    pm_sdoc_free(&S->doc);
    free(S->text);
  }
  free(S);
  free(runs);
  free(fe);
  return ret;
}
