/* mpm_test_arrays: an MPM group's state arrays by name, for the MPM unit
 * and verification tests alike. */
#ifndef MPM_TEST_ARRAYS_H
#define MPM_TEST_ARRAYS_H

#include <stddef.h>

#include "mpm_state.h"

/* Group gi's state array called name, or NULL when the group has none. */
static inline const double *group_array(const mpm_state *s, int gi,
                                        const char *name) {
  const mpm_array *a = mpm_group_state_find(&s->group[gi], name);
  return a ? a->data : NULL;
}

#endif
