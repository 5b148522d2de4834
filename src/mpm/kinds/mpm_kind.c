/* mpm_kind: the table of particle kinds.  A new kind is its folder under
 * kinds/ and one row here. */
#include "mpm_kind.h"

/* The kinds in the order mpm_kind_of asks them. */
static const mpm_kind *const kinds[] = {&mpm_kind_membrane, &mpm_kind_rigid,
                                        &mpm_kind_fluid, &mpm_kind_solid};

mpm_body_role mpm_body_role_of(const pm_scene_body *b) {
  if (b->shape == PM_BODY_MEMBRANE) return MPM_BODY_MEMBRANE;
  if (b->moving) return MPM_BODY_RIGID;
  return MPM_BODY_VOLUME;
}

const mpm_kind *mpm_kind_of(const pm_scene_material *sm, mpm_body_role role) {
  for (size_t i = 0; i < sizeof kinds / sizeof *kinds; i++)
    if (kinds[i]->takes(sm, role)) return kinds[i];
  return NULL;
}
