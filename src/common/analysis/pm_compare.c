/* pm_compare: the methods' runs of one scene, their fields on one lattice
 * (moving least squares) and their errors against each other and the
 * references: the options, each method's run, and the comparison. */
#include "pm_compare.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "pm_compare_impl.h"
#include "pm_scene_mirror.h"
#include "pm_memory.h"
#include "pm_metrics.h"
#include "pm_mls.h"
#include "pm_probe.h"

#define CMP_SETS_MAX 66 /* method=M and the --set overrides */
#define CMP_FIELDS_MAX 16

/* ---- options ------------------------------------------------------------ */

/* The comma-separated method names into c->meth[].name. */
static pm_err parse_methods(const char *list, cmp_study *c) {
  char buf[PM_COMPARE_MAX_METHODS * CMP_NAME_MAX],
      *names[PM_COMPARE_MAX_METHODS];
  PM_CHECK(list && *list, PM_ERR_SCENE,
           "compare needs --methods M1,M2,... (e.g. fpm,mpm,mpm-implicit)");
  PM_CHECK(strlen(list) < sizeof buf, PM_ERR_SCENE,
           "--methods %.40s...: at most %zu characters", list, sizeof buf - 1);
  snprintf(buf, sizeof buf, "%s", list);
  c->n = pm_split_fields(buf, names, PM_COMPARE_MAX_METHODS);
  PM_CHECK(c->n <= PM_COMPARE_MAX_METHODS, PM_ERR_SCENE,
           "--methods %s: at most %d methods", list, PM_COMPARE_MAX_METHODS);
  for (int k = 0; k < c->n; k++) {
    size_t len = strlen(names[k]);
    PM_CHECK(len > 0 && len < CMP_NAME_MAX, PM_ERR_SCENE,
             "--methods %s: expected method names of 1 to %d characters "
             "separated by commas",
             list, CMP_NAME_MAX - 1);
    /* LABEL=METHOD: a variant of a method under a label of its own (its
     * folder, its rows and the scope of its --set LABEL:KEY=VALUE). */
    char *eq = strchr(names[k], '=');
    const char *method = eq ? eq + 1 : names[k];
    if (eq) *eq = 0;
    PM_CHECK(*names[k] && *method && !strpbrk(names[k], ":/ ") &&
                 !strpbrk(method, "=:/ "),
             PM_ERR_SCENE,
             "--methods %s: expected METHOD or LABEL=METHOD, labels without "
             "':', '/' or spaces, got '%s%s%s'",
             list, names[k], eq ? "=" : "", eq ? method : "");
    for (int l = 0; l < k; l++)
      PM_CHECK(strcmp(c->meth[l].name, names[k]) != 0, PM_ERR_SCENE,
               "--methods %s: %s is named twice", list, names[k]);
    memcpy(c->meth[k].name, names[k], strlen(names[k]) + 1);
    memcpy(c->meth[k].method, method, strlen(method) + 1);
  }
  return PM_SUCCESS;
}

/* The method a "METHOD:KEY=VALUE" override is for, as a length (0: every
 * method).  Keys hold no ':', values may. */
static size_t scope_of(const char *set) {
  const char *colon = strchr(set, ':'), *eq = strchr(set, '=');
  return colon && (!eq || colon < eq) ? (size_t)(colon - set) : 0;
}

/* Every scoped override names one of the methods; none sets the method. */
static pm_err check_sets(const pm_compare_options *o, const cmp_study *c) {
  PM_CHECK(o->n_sets <= CMP_SETS_MAX - 1, PM_ERR_SCENE,
           "compare: at most %d --set options", CMP_SETS_MAX - 1);
  for (int k = 0; k < o->n_sets; k++) {
    const char *set = o->sets[k];
    size_t len = scope_of(set);
    const char *key = len ? set + len + 1 : set;
    bool known = len == 0;
    for (int m = 0; m < c->n && !known; m++)
      known = strlen(c->meth[m].name) == len &&
              strncmp(c->meth[m].name, set, len) == 0;
    PM_CHECK(known, PM_ERR_SCENE,
             "--set %s: %.*s is not one of the --methods (%s)", set, (int)len,
             set, o->methods);
    PM_CHECK(strncmp(key, "method=", 7) != 0, PM_ERR_SCENE,
             "--set %s: compare sets the method of each run from --methods",
             set);
  }
  return PM_SUCCESS;
}

/* Load the scene for the method labelled label (NULL: the scene as
 * given): method=METHOD, the overrides for every method, then the
 * label's own. */
static pm_err load_scene(const pm_compare_options *o, const char *label,
                         const char *method, pm_scene **s) {
  const char *sets[CMP_SETS_MAX];
  char first[CMP_NAME_MAX + 8];
  int n = 0;
  if (method) {
    snprintf(first, sizeof first, "method=%s", method);
    sets[n++] = first;
  }
  for (int pass = 0; pass < (method ? 2 : 1); pass++)
    for (int k = 0; k < o->n_sets; k++) {
      size_t len = scope_of(o->sets[k]);
      if (pass == 0 && len == 0)
        sets[n++] = o->sets[k];
      else if (pass == 1 && len == strlen(label) &&
               strncmp(o->sets[k], label, len) == 0)
        sets[n++] = o->sets[k] + len + 1;
    }
  return pm_scene_load(o->scene, n, sets, s);
}

/* ---- one method --------------------------------------------------------- */

/* Record why method M stopped: its error, a status, the message. */
static pm_err method_failed(cmp_method *M, pm_err e, const char *status,
                            const char *message) {
  M->err = e;
  if (status) snprintf(M->status, sizeof M->status, "%s", status);
  snprintf(M->message, sizeof M->message, "%s",
           message && *message ? message : pm_error_message());
  return e;
}

/* The von Mises stress of sim's points: the backend's field, or from its
 * Cauchy stress into *own; NULL when it gives neither. */
static pm_err von_mises_of(const pm_backend *be, void *sim, long n,
                           double **own, const double **vm) {
  pm_field f[CMP_FIELDS_MAX];
  int nf = be->fields(sim, PM_FIELD_STRESS, f, CMP_FIELDS_MAX);
  *vm = NULL;
  for (int k = 0; k < nf; k++)
    if (f[k].ncomp == 1 && strcmp(f[k].name, "von_mises") == 0) {
      *vm = f[k].data;
      return PM_SUCCESS;
    }
  for (int k = 0; k < nf; k++)
    if (f[k].ncomp == 9 && strcmp(f[k].name, "stress") == 0) {
      PM_CALL(PM_ALLOC(*own, n, "von Mises stress"));
      pm_stress_invariants(n, f[k].data, *own, NULL);
      *vm = *own;
      return PM_SUCCESS;
    }
  return PM_SUCCESS;
}

/* The displacement at the lattice and von Mises stress at the centre of
 * the simulation sim after its run. */
static pm_err map_method(cmp_study *c, cmp_method *M, const pm_scene *s,
                         void *sim) {
  const pm_backend *be = s->backend;
  pm_err ret = PM_SUCCESS;
  pm_points p;
  pm_mls *mls = NULL;
  double *own = NULL;
  const double *vm = NULL;
  char what[CMP_NAME_MAX + 32];
  be->points(sim, &p);
  snprintf(what, sizeof what, "the points of %s", M->name);
  PM_TRY(pm_mls_create(p.n, p.x, what, &mls));
  PM_TRY(PM_ALLOC(M->u, 3 * c->m, "displacement at the lattice"));
  M->flagged = cmp_map_lattice(c, s, mls, be->displacement(sim), M->u);
  M->mapped = true;
  PM_TRY(von_mises_of(be, sim, p.n, &own, &vm));
  if (vm) { /* (a scalar: the image's value as it is) */
    double centre[3];
    pm_scene_mirror_fold(s, c->centre, centre);
    cmp_fit_on_cloud(mls, centre, 1, vm, &M->von_mises_centre);
  }
done:
  pm_mls_free(mls);
  free(own);
  return ret;
}

/* The process's CPU time so far (user + system, every thread), s. */
static double cpu_now(void) {
  struct rusage u;
  if (getrusage(RUSAGE_SELF, &u) != 0) return NAN;
  return (double)(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * (double)(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

/* Load, run and map method k; its failures are its own (recorded in it
 * and returned), the others' runs go on. */
static pm_err run_method(cmp_study *c, int k, FILE *out) {
  const pm_compare_options *o = c->o;
  cmp_method *M = &c->meth[k];
  pm_scene *s = NULL;
  void *sim = NULL;
  pm_err e;
  M->von_mises_centre = M->cpu_seconds = NAN;
  snprintf(M->status, sizeof M->status, "refused");
  if (out)
    fprintf(out, "method %d/%d: %s -> %s\n", k + 1, c->n, M->name, M->dir);
  e = load_scene(o, M->name, M->method, &s);
  if (e == PM_SUCCESS) e = pm_memory_check(s);
  if (e != PM_SUCCESS) {
    method_failed(M, e, NULL, NULL);
    goto done;
  }
  M->n_bcs = s->n_bcs;
  const double cpu0 = cpu_now();
  e = s->backend->create(s, &sim);
  if (e != PM_SUCCESS) {
    method_failed(M, e, "failed", NULL);
    goto done;
  }
  unsigned flags =
      (o->quiet ? PM_RUN_QUIET : 0u) | (o->overwrite ? PM_RUN_OVERWRITE : 0u);
  e = pm_run_sim(s, sim, M->dir, flags, &M->out);
  M->cpu_seconds = cpu_now() - cpu0;
  const pm_status st = M->out.fig.status;
  snprintf(M->status, sizeof M->status, "%s", pm_status_name(st));
  if (e != PM_SUCCESS) method_failed(M, e, NULL, M->out.message);
  /* As the run reports its error: a field that went unstable or was never
   * finished is not compared. */
  if (st == PM_STATUS_COMPLETED || st == PM_STATUS_CONVERGED ||
      st == PM_STATUS_NOT_CONVERGED) {
    pm_err m = map_method(c, M, s, sim);
    if (m != PM_SUCCESS && e == PM_SUCCESS) e = method_failed(M, m, NULL, NULL);
  }
done:
  if (e != PM_SUCCESS && out) fprintf(out, "  %s: %s\n", M->status, M->message);
  if (sim) s->backend->destroy(sim);
  pm_scene_destroy(s);
  return e;
}

/* ---- the comparison ----------------------------------------------------- */

/* The references --reference and the scene name; the FE referee is loaded
 * into *fe. */
static pm_err choose_references(cmp_study *c, pm_fe_reference **fe) {
  const pm_compare_options *o = c->o;
  const pm_scene *s = c->base;
  const char *ref = o->reference;
  char fe_dir[PM_PATH_MAX + 1] = "";
  c->analytic = s->reference_mask != 0;
  if (!ref) {
    if (s->reference_fe) snprintf(fe_dir, sizeof fe_dir, "%s", s->reference_fe);
  } else if (strcmp(ref, "analytic") == 0) {
    PM_CHECK(c->analytic, PM_ERR_SCENE,
             "%s: --reference analytic: the scene has no reference field "
             "(reference.displacement)",
             o->scene);
  } else if (!pm_fe_names_reference(ref, fe_dir, sizeof fe_dir)) {
    PM_CHECK(strncmp(ref, "fe:", 3) != 0, PM_ERR_SCENE,
             "--reference %s: expected fe:DIR", ref);
    snprintf(c->run_dir, sizeof c->run_dir, "%s", ref);
  }
  if (fe_dir[0]) {
    PM_CALL(pm_fe_load(fe_dir, fe));
    c->fe = *fe;
  }
  return PM_SUCCESS;
}

/* The methods' figures for the caller. */
static void fill_rows(const cmp_study *c, pm_compare_row *rows, int *n) {
  for (int k = 0; k < c->n; k++) {
    const cmp_method *M = &c->meth[k];
    const pm_figures *g = &M->out.fig;
    pm_compare_row *r = &rows[k];
    memset(r, 0, sizeof *r);
    memcpy(r->name, M->name, sizeof r->name);
    memcpy(r->method, M->method, sizeof r->method);
    memcpy(r->status, M->status, sizeof r->status);
    memcpy(r->message, M->message, sizeof r->message);
    r->ran = g->status != PM_STATUS_NOT_RUN;
    r->points = g->points;
    r->steps = g->steps;
    r->flagged = M->mapped ? M->flagged : -1;
    r->h = r->ran ? g->h : NAN;
    /* The method's whole cost: its setup (meshing, cells, operators;
     * seeding) before the run's own wall time, as its CPU time is. */
    r->wall_seconds =
        r->ran ? g->wall_seconds +
                     (isfinite(g->setup_seconds) ? g->setup_seconds : 0)
               : NAN;
    r->setup_seconds = r->ran ? g->setup_seconds : NAN;
    r->cpu_seconds = r->ran ? M->cpu_seconds : NAN;
    r->memory_bytes = g->memory_bytes;
    r->e_analytic = M->e_analytic;
    r->e_fe = M->e_fe;
    r->e_run = M->e_run;
    r->reaction_fe = M->reaction_fe;
    r->sed_fe = M->sed_fe;
    r->tip_fe = M->tip_fe;
    r->loaded_reaction = r->ran ? M->out.loaded_reaction : NAN;
    r->min_jacobian = r->ran ? g->min_jacobian : NAN;
  }
  if (n) *n = c->n;
}

/* Which methods failed, for the error returned. */
static void failed_names(const cmp_study *c, char *buf, size_t size) {
  size_t len = 0;
  buf[0] = 0;
  for (int k = 0; k < c->n && len < size; k++)
    if (c->meth[k].err != PM_SUCCESS)
      len += (size_t)snprintf(buf + len, size - len, "%s%s %s", len ? ", " : "",
                              c->meth[k].name, c->meth[k].status);
}

pm_err pm_compare_run(const pm_compare_options *o, FILE *out, char *dir,
                      size_t size) {
  pm_err ret = PM_SUCCESS, first_fail = PM_SUCCESS;
  cmp_study *c = NULL;
  pm_scene *base = NULL;
  pm_fe_reference *fe = NULL;
  const long n_lattice = o->lattice ? o->lattice : PM_COMPARE_LATTICE;
  if (dir && size) dir[0] = 0;
  PM_ENSURE(n_lattice >= 3, PM_ERR_SCENE,
            "--lattice %ld: expected at least 3 points", o->lattice);
  PM_TRY(PM_ALLOC(c, 1, "comparison"));
  c->o = o;
  PM_TRY(parse_methods(o->methods, c));
  PM_TRY(check_sets(o, c));
  /* The scene as given sets the name, the conditions, the references and
   * the bodies' box, the same for every method. */
  PM_TRY(load_scene(o, NULL, NULL, &base));
  c->base = base;
  c->dim = base->dimension;
  if (o->out_dir)
    snprintf(c->out_dir, sizeof c->out_dir, "%s", o->out_dir);
  else
    snprintf(c->out_dir, sizeof c->out_dir, "out/%s-compare", base->name);
  if (dir && size) snprintf(dir, size, "%s", c->out_dir);
  PM_TRY(choose_references(c, &fe));
  if (c->fe)
    PM_TRY(cmp_fe_lattice(c));
  else
    PM_TRY(cmp_regular_lattice(c, n_lattice));
  if (c->run_dir[0]) PM_TRY(cmp_map_run(c));
  PM_TRY(pm_mkdir_p(c->out_dir));
  for (int k = 0; k < c->n; k++)
    PM_TRY(pm_path_join(c->meth[k].dir, sizeof c->meth[k].dir, c->out_dir,
                        c->meth[k].name));
  for (int k = 0; k < c->n; k++) {
    pm_err e = run_method(c, k, out);
    if (e != PM_SUCCESS && first_fail == PM_SUCCESS) first_fail = e;
    if (e == PM_ERR_INTERRUPTED) {
      first_fail = e;
      for (int l = k + 1; l < c->n; l++) {
        cmp_method *L = &c->meth[l];
        snprintf(L->status, sizeof L->status, "not-run");
        snprintf(L->message, sizeof L->message,
                 "not started: the comparison was interrupted");
        L->von_mises_centre = NAN;
      }
      break;
    }
  }
  PM_TRY(cmp_compute_errors(c));
  PM_TRY(cmp_write_report(c, out));
  if (o->rows) fill_rows(c, o->rows, o->n_rows);
  if (out) fprintf(out, "tables in %s/compare.{md,csv}\n", c->out_dir);
  if (first_fail != PM_SUCCESS) {
    char names[512];
    failed_names(c, names, sizeof names);
    ret = PM_ERROR(first_fail, "%s: not every method ran through: %s; see %s",
                   o->scene, names[0] ? names : "interrupted", c->out_dir);
  }
done:
  if (c) {
    for (int k = 0; k < c->n; k++) free(c->meth[k].u);
    free(c->x);
    free(c->valid);
    free(c->run_u);
  }
  free(c);
  pm_fe_free(fe);
  pm_scene_destroy(base);
  return ret;
}
