/* pm_bench: a bench suite run: each selected case compared at each of its
 * resolutions by the methods it names, with the FE referee's ladder, then
 * the report. */
#include "pm_bench.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "pm_bench_impl.h"
#include "pm_compare.h"
#include "pm_fe.h"
#include "pm_files.h"

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

static const char *label_of(const pm_bench_suite *S, const pm_bench_case *C,
                            int k) {
  return C->method[k] >= 0 ? S->m[C->method[k]].label : C->plain[k];
}

/* The comparison's options for case C at resolution res: methods as
 * LABEL=METHOD, then the overrides (the case's for every method, the
 * resolution, the command line's; then each method's own, scoped). */
static pm_err compare_options(const pm_bench_suite *S, const pm_bench_case *C,
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
    const pm_bench_method *M = &S->m[C->method[k]];
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

static void print_row(FILE *out, const pm_compare_row *r) {
  const char *against, *sep = " ";
  double e = pm_bench_judged(r, &against);
  fprintf(out, "    %-14s %-13s", r->name, r->status);
  if (isfinite(e)) {
    fprintf(out, "%sNRMSE %.3g (%s)", sep, e, against);
    sep = ", ";
  }
  if (isfinite(r->reaction_fe)) {
    fprintf(out, "%sreaction %+.2f%% of FE", sep, 100 * r->reaction_fe);
    sep = ", ";
  }
  if (isfinite(r->tip_fe)) {
    fprintf(out, "%stip %+.2f%% of FE", sep, 100 * r->tip_fe);
    sep = ", ";
  }
  if (r->ran)
    fprintf(out, "%s%.2f s wall, %.2f s CPU, %.0f MiB", sep, r->wall_seconds,
            r->cpu_seconds, (double)r->memory_bytes / MIB);
  if (r->message[0]) fprintf(out, "\n      %s", r->message);
  fprintf(out, "\n");
}

static void run_one(const pm_bench_suite *S, const pm_bench_options *o,
                    pm_bench_comparison *R, FILE *out) {
  const pm_bench_case *C = &S->c[R->c];
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

/* The FE referee of case C, when its scene names one (with the case's
 * overrides and then the command line's, as its runs see it). */
static void case_fe(const pm_bench_options *o, const pm_bench_case *C,
                    pm_bench_fe *F) {
  pm_scene *s = NULL;
  pm_fe_reference *r = NULL;
  const char *sets[BENCH_SETS + 64];
  int n = 0;
  memset(F, 0, sizeof *F);
  for (int k = 0; k < C->n_sets; k++) sets[n++] = C->sets[k];
  for (int k = 0; k < o->n_sets && n < BENCH_SETS + 64; k++)
    sets[n++] = o->sets[k];
  if (pm_scene_load(C->scene, n, sets, &s) == PM_SUCCESS && s->reference_fe &&
      pm_fe_load(s->reference_fe, &r) == PM_SUCCESS) {
    F->have = true;
    snprintf(F->dir, sizeof F->dir, "%s", r->dir);
    F->axis = 0;
    for (int k = 1; k < 3; k++)
      if (fabs(r->reaction[k]) > fabs(r->reaction[F->axis])) F->axis = k;
    F->reaction = r->reaction[F->axis];
    F->tol = r->tolerance.reaction;
    F->tip = r->tip_face >= 0;
    if (F->tip) {
      F->reaction = r->tip_u;
      F->tol = r->tolerance.tip;
    }
    F->n = r->n_rows < BENCH_FE_ROWS ? r->n_rows : BENCH_FE_ROWS;
    for (int k = 0; k < F->n; k++) F->rows[k] = r->rows[k];
  }
  pm_error_clear();
  pm_fe_free(r);
  pm_scene_destroy(s);
}

pm_err pm_bench_run(const pm_bench_options *o, FILE *out, char *dir,
                    size_t size) {
  pm_err ret = PM_SUCCESS, first = PM_SUCCESS;
  pm_bench_suite *S = NULL;
  pm_bench_comparison *runs = NULL;
  pm_bench_fe *fe = NULL;
  char out_dir[PM_PATH_MAX + 1], path[PM_PATH_MAX + 1];
  int n_runs = 0, first_run = -1;
  if (dir && size) dir[0] = 0;
  PM_TRY(PM_ALLOC(S, 1, "bench suite"));
  PM_TRY(pm_bench_read_suite(o->suite, S));
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
    const pm_bench_case *C = &S->c[c];
    if (!selected(o->only, C->name)) continue;
    case_fe(o, C, &fe[c]);
    for (int j = 0; j < (C->n_res ? C->n_res : 1); j++) {
      pm_bench_comparison *R = &runs[n_runs++];
      R->c = c;
      R->res = C->n_res ? C->res[j] : NAN;
      char res[32], sub[PM_PATH_MAX + 1];
      pm_bench_res_text(res, sizeof res, R->res);
      snprintf(sub, sizeof sub, "%s/h-%s", C->name, res);
      PM_TRY(pm_path_join(R->dir, sizeof R->dir, out_dir, sub));
    }
  }
  double t0 = now();
  for (int i = 0; i < n_runs; i++) {
    pm_bench_comparison *R = &runs[i];
    const pm_bench_case *C = &S->c[R->c];
    char res[32];
    pm_bench_res_text(res, sizeof res, R->res);
    if (out) {
      fprintf(out, "[%d/%d] %s at %s (%.0f s so far):", i + 1, n_runs, C->name,
              res, now() - t0);
      for (int k = 0; k < C->n_methods; k++)
        fprintf(out, " %s", label_of(S, C, k));
      fprintf(out, "\n");
      fflush(out);
    }
    run_one(S, o, R, out);
    /* After a case's last resolution: its FE ladder, timed alike. */
    if (R->err != PM_ERR_INTERRUPTED &&
        (i + 1 == n_runs || runs[i + 1].c != R->c)) {
      char case_dir[PM_PATH_MAX + 1];
      PM_TRY(pm_path_join(case_dir, sizeof case_dir, out_dir, C->name));
      pm_bench_fe_ladder(C, &fe[R->c], o->fe_tool, case_dir, out);
    }
    if (R->err != PM_SUCCESS && first == PM_SUCCESS) {
      first = R->err;
      first_run = i;
    }
    if (R->err == PM_ERR_INTERRUPTED) {
      n_runs = i + 1;
      break;
    }
  }
  PM_TRY(pm_bench_write_report(out_dir, S, runs, n_runs, fe, now() - t0, out));
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
