/* pm_api: pointmech.h's handle, loading a scene with its overrides, and
 * running it through the program's driver (pm_run_scene_observed) with the
 * caller's observer. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_api_impl.h"
#include "pm_app.h"
#include "pm_backend.h"
#include "pm_error.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_newton.h"

/* pointmech_code is pm_err under other names: the numbers are one. */
_Static_assert(POINTMECH_ERR_MEMORY == (int)PM_ERR_MEMORY &&
                   POINTMECH_ERR_SCENE == (int)PM_ERR_SCENE &&
                   POINTMECH_ERR_UNSTABLE == (int)PM_ERR_UNSTABLE &&
                   POINTMECH_ERR_INTERRUPTED == (int)PM_ERR_INTERRUPTED &&
                   POINTMECH_ERR_INTERNAL == (int)PM_ERR_INTERNAL &&
                   POINTMECH_ERR_INTERNAL + 1 == (int)PM_ERR_COUNT,
               "pointmech_code and pm_err differ");

const char *pointmech_version(void) { return PM_VERSION; }

const char *pointmech_error_message(void) { return pm_error_message(); }

const char *pointmech_code_name(int code) {
  static char names[PM_ERR_COUNT][48];
  if (code < 0 || code >= PM_ERR_COUNT) return "POINTMECH_UNKNOWN";
  if (code == PM_SUCCESS) return "POINTMECH_OK";
  char *n = names[code];
  if (!n[0])
    snprintf(n, sizeof names[code], "POINTMECH_%s",
             pm_err_name((pm_err)code) + strlen("PM_"));
  return n;
}

/* The backends, registered once (as the program does at its start). */
static pm_err api_init(void) {
  static bool done = false;
  if (!done) {
    PM_CALL(pm_app_init());
    done = true;
  }
  return PM_SUCCESS;
}

static pm_err attach_mpi_impl(const void *comm) {
  PM_CHECK(comm, PM_ERR_ARG, "pointmech_attach_mpi: comm is NULL");
  PM_CALL(api_init());
#ifdef PM_HAVE_MPI
  int ready = 0;
  MPI_Initialized(&ready);
  PM_CHECK(ready, PM_ERR_ARG,
           "pointmech_attach_mpi: MPI is not started (MPI_Init first)");
#endif
  return pm_par_attach(*(const MPI_Comm *)comm);
}

void pointmech_finalize(void) { pm_solve_finalize(); }

static pm_err create_impl(pointmech **out) {
  PM_CHECK(out, PM_ERR_ARG, "pointmech_create: out is NULL");
  *out = NULL;
  PM_CALL(api_init());
  pointmech *p = NULL;
  PM_CALL(PM_ALLOC(p, 1, "pointmech handle"));
  *out = p;
  return PM_SUCCESS;
}

void pointmech_destroy(pointmech *p) {
  if (!p) return;
  if (p->sim) p->s->backend->destroy(p->sim);
  pm_scene_destroy(p->s);
  for (int k = 0; k < p->n_sets; k++) free(p->sets[k]);
  free(p->sets);
  free(p);
}

static pm_err set_impl(pointmech *p, const char *key_value) {
  PM_CHECK(p && key_value, PM_ERR_ARG, "pointmech_set: NULL argument");
  PM_CHECK(!p->s, PM_ERR_ARG,
           "pointmech_set %s: the scene is loaded already (overrides come "
           "before pointmech_load_file or pointmech_load_string)",
           key_value);
  PM_CHECK(strchr(key_value, '='), PM_ERR_ARG,
           "pointmech_set %s: expected KEY=VALUE", key_value);
  PM_CALL(pm_realloc((void **)&p->sets, (size_t)p->n_sets + 1, sizeof *p->sets,
                     "overrides"));
  p->sets[p->n_sets] = strdup(key_value);
  PM_CHECK(p->sets[p->n_sets], PM_ERR_MEMORY, "pointmech_set: out of memory");
  p->n_sets++;
  return PM_SUCCESS;
}

static pm_err check_loadable(const pointmech *p, const void *what) {
  PM_CHECK(p && what, PM_ERR_ARG, "pointmech_load: NULL argument");
  PM_CHECK(!p->s, PM_ERR_ARG,
           "pointmech_load: a scene is loaded already (one a handle)");
  return PM_SUCCESS;
}

static pm_err load_file_impl(pointmech *p, const char *path) {
  PM_CALL(check_loadable(p, path));
  return pm_scene_load(path, p->n_sets, (const char *const *)p->sets, &p->s);
}

static pm_err load_string_impl(pointmech *p, const char *text,
                               const char *name) {
  PM_CALL(check_loadable(p, text));
  return pm_scene_load_text(text, strlen(text), name ? name : "scene.yaml",
                            p->n_sets, (const char *const *)p->sets, &p->s);
}

const char *pointmech_scene_name(const pointmech *p) {
  return p && p->s && p->s->name ? p->s->name : "";
}

const char *pointmech_method(const pointmech *p) {
  return p && p->s ? p->s->method : "";
}

/* The driver's report of a step, to the caller's observer. */
static pm_err api_step(void *ctx, const pm_step_report *r, bool frame) {
  pointmech *p = ctx;
  const pointmech_step st = {.step = r->step,
                             .time = r->t,
                             .residual = r->residual,
                             .progress = r->progress,
                             .frame = frame,
                             .last = r->last};
  const int rc = p->observer(p, &st, p->observer_ctx);
  if (rc == 0) return PM_SUCCESS;
  return PM_ERROR(PM_ERR_INTERRUPTED,
                  "stopped by the observer (it returned %d) after step %ld, "
                  "t = %.6g s",
                  rc, r->step, r->t);
}

/* Across ranks the state is gathered into rank 0's view on frame steps
 * (and where the run writes): the observer reads fields there. */
static bool api_wants(void *ctx, const pm_step_report *r, bool frame) {
  (void)ctx, (void)r;
  return frame;
}

static pm_err run_impl(pointmech *p, const char *out_dir, unsigned flags,
                       pointmech_observer observer, void *ctx) {
  PM_CHECK(p, PM_ERR_ARG, "pointmech_run: p is NULL");
  PM_CHECK(p->s, PM_ERR_ARG, "pointmech_run: no scene loaded");
  PM_CHECK(!p->ran && !p->running, PM_ERR_ARG,
           "pointmech_run: this handle has run (a handle runs once)");
  p->observer = observer;
  p->observer_ctx = ctx;
  const pm_observer also = {.ctx = p, .step = api_step, .wants = api_wants};
  const unsigned run_flags =
      (flags & POINTMECH_RUN_PROGRESS ? 0u : PM_RUN_QUIET) |
      (flags & POINTMECH_RUN_OVERWRITE ? PM_RUN_OVERWRITE : 0u);
  p->running = true;
  pm_err e = pm_run_scene_observed(p->s, out_dir, run_flags,
                                   observer ? &also : NULL, &p->sim, &p->o);
  p->running = false;
  p->ran = true;
  return e;
}

const char *pointmech_status(const pointmech *p) {
  return pm_status_name(p && p->ran ? p->o.fig.status : PM_STATUS_NOT_RUN);
}

/* The interface's functions: the codes are pm_err's numbers. */
pointmech_code pointmech_attach_mpi(const void *comm) {
  return pm_api_code(attach_mpi_impl(comm));
}

pointmech_code pointmech_create(pointmech **out) {
  return pm_api_code(create_impl(out));
}

pointmech_code pointmech_set(pointmech *p, const char *key_value) {
  return pm_api_code(set_impl(p, key_value));
}

pointmech_code pointmech_load_file(pointmech *p, const char *path) {
  return pm_api_code(load_file_impl(p, path));
}

pointmech_code pointmech_load_string(pointmech *p, const char *text,
                                     const char *name) {
  return pm_api_code(load_string_impl(p, text, name));
}

pointmech_code pointmech_run(pointmech *p, const char *out_dir, unsigned flags,
                             pointmech_observer observer, void *ctx) {
  return pm_api_code(run_impl(p, out_dir, flags, observer, ctx));
}
