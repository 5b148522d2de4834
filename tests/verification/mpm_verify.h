/* mpm_verify: helpers shared by the MPM verification programs (include
 * after cmocka.h). */
#ifndef MPM_VERIFY_H
#define MPM_VERIFY_H

#include <math.h>
#include <stdbool.h>

#include "mpm_state.h"
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
static inline bool state_finite(const mpm_model *m, const mpm_state *s) {
  for (long i = 0; i < 3 * m->n; i++)
    if (!isfinite(s->x[i]) || !isfinite(s->v[i])) return false;
  for (long i = 0; i < 9 * m->n; i++)
    if (!isfinite(s->sigma[i])) return false;
  return true;
}

/* Group gi's state array called name, or fail the test. */
static inline const double *group_array(const mpm_state *s, int gi,
                                        const char *name) {
  const mpm_array *a = mpm_group_state_find(&s->group[gi], name);
  if (!a) fail_msg("group %d has no array %s", gi, name);
  return a->data;
}

#endif
