/* pm_api_impl: the handle behind pointmech.h, shared by the files of the
 * library's interface (pm_api.c: loading and running; pm_api_state.c: the
 * state read back); not for callers of pointmech.h. */
#ifndef PM_API_IMPL_H
#define PM_API_IMPL_H

#include <stdbool.h>

#include "pm_run.h"
#include "pointmech.h"

/* Fields a state gives at most (the shared ones and a method's own). */
#define PM_API_FIELDS 32

struct pointmech {
  char **sets; /* the overrides, "key=value", owned */
  int n_sets;
  pm_scene *s;  /* the loaded scene, or NULL */
  void *sim;    /* its simulation once run (the backend's), or NULL */
  bool running; /* inside pointmech_run: the state is the step's */
  bool ran;     /* o holds the run's outcome */
  pm_outcome o;
  pointmech_observer observer;
  void *observer_ctx;
  pm_field fields[PM_API_FIELDS]; /* the last call's, borrowed */
  int n_fields;
};

/* The library's pm_err as the interface's code (the same numbers). */
static inline pointmech_code pm_api_code(pm_err e) { return (pointmech_code)e; }

#endif
