/* mpm_kind: the table of particle kinds. */
#include "mpm_kind.h"

mpm_body_role mpm_body_role_of(const pm_scene_body *b) {
  if (b->shape == PM_BODY_MEMBRANE) return MPM_BODY_MEMBRANE;
  if (b->moving) return MPM_BODY_RIGID;
  return MPM_BODY_VOLUME;
}

const mpm_kind *mpm_kind_of(const pm_scene_material *sm, mpm_body_role role) {
  if (role == MPM_BODY_MEMBRANE) return &mpm_kind_membrane;
  if (role == MPM_BODY_RIGID) return &mpm_kind_rigid;
  return pm_material_is_fluid(&sm->mat) ? &mpm_kind_fluid : &mpm_kind_solid;
}
