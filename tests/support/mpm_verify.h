/* mpm_verify: helpers shared by the MPM verification programs (include
 * after cmocka.h). */
#ifndef MPM_VERIFY_H
#define MPM_VERIFY_H

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>

#include "mpm_backend.h"
#include "mpm_state.h"
#include "mpm_test_arrays.h"
#include "pm_app.h"
#include "pm_run.h"
#include "pm_scene.h"

/* Load a scene with overrides, or fail the test with the message (the
 * backends are registered first). */
static inline pm_scene *load_scene(const char *file, int n_sets,
                                   const char *const *sets) {
  pm_scene *s = NULL;
  if (pm_app_init() != PM_SUCCESS) fail_msg("%s", pm_error_message());
  if (pm_scene_load(file, n_sets, sets, &s) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  return s;
}

/* Positions, velocities and stresses are all finite. */
static inline bool state_finite(const mpm_model *m, const mpm_state *s) {
  for (long i = 0; i < 3 * m->n; i++)
    if (!isfinite(s->x[i]) || !isfinite(s->v[i])) return false;
  for (long i = 0; i < 9 * m->n; i++)
    if (!isfinite(s->sigma[i])) return false;
  return true;
}

/* A simulation and the outcome of its run through the run driver. */
typedef struct {
  mpm_sim *sim;
  pm_outcome out;
} verify_run;

/* The simulation of s, or fail the test. */
static inline verify_run *verify_create(const pm_scene *s) {
  verify_run *r = calloc(1, sizeof *r);
  void *sim = NULL;
  /* the scene's backend: mpm or mpm-implicit, both an mpm_sim */
  if (!r || s->backend->create(s, &sim) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  r->sim = sim;
  return r;
}

/* Run it without output: it must end with status expected and a finite
 * state. */
static inline void verify_go(verify_run *r, pm_status expected) {
  const char *name = r->sim->scene->name;
  pm_err err = pm_run_sim(r->sim->scene, r->sim, NULL, true, &r->out);
  if (err != PM_SUCCESS && r->out.fig.status != expected)
    fail_msg("%s: %s", name, pm_error_message());
  if (r->out.fig.status != expected)
    fail_msg("%s: status %s, expected %s (%s)", name,
             pm_status_name(r->out.fig.status), pm_status_name(expected),
             r->out.message);
  assert_true(state_finite(r->sim->model, r->sim->state));
}

static inline void verify_destroy(verify_run *r) {
  if (!r) return;
  r->sim->scene->backend->destroy(r->sim);
  free(r);
}

/* One line of the table: measured against expected, with the error
 * relative to `scale` (the expected value when scale is 0) and its bound.
 * NaN-safe: a NaN fails.  Returns whether the check holds. */
static inline bool row(const char *what, double measured, double expected,
                       double scale, double tol) {
  double ref = scale > 0 ? scale : fabs(expected);
  double err =
      ref > 0 ? fabs(measured - expected) / ref : fabs(measured - expected);
  bool ok = err <= tol;
  printf("  %-46s %13.6g %13.6g %10.2e %9.2e  %s\n", what, measured, expected,
         err, tol, ok ? "ok" : "FAIL");
  return ok;
}

/* The head of a table of rows. */
static inline void table_head(const char *title) {
  printf("\n%s\n  %-46s %13s %13s %10s %9s\n", title, "quantity", "measured",
         "expected", "rel. err", "bound");
}

#endif
