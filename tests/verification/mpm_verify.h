/* mpm_verify: helpers shared by the MPM verification programs (include
 * after cmocka.h). */
#ifndef MPM_VERIFY_H
#define MPM_VERIFY_H

#include <math.h>
#include <stdbool.h>

#include "mpm_model.h"
#include "pm_scene.h"

/* Load a scene with overrides, or fail the test with the message. */
static inline pm_scene *load_scene(const char *file, int n_sets,
                                   const char *const *sets) {
  pm_scene *s = NULL;
  if (pm_scene_load(file, n_sets, sets, &s) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  return s;
}

/* Positions, velocities and stresses are all finite. */
static inline bool state_finite(const mpm_sim *sim) {
  for (long i = 0; i < 3 * sim->n; i++)
    if (!isfinite(sim->x[i]) || !isfinite(sim->v[i])) return false;
  for (long i = 0; i < 9 * sim->n; i++)
    if (!isfinite(sim->sigma[i])) return false;
  return true;
}

#endif
