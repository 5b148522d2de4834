/* mpm_kind: the table of particle kinds. */
#include "mpm_kind.h"

const mpm_kind *mpm_kind_of(const pm_scene_material *sm) {
  return pm_material_is_fluid(&sm->mat) ? &mpm_kind_fluid : &mpm_kind_solid;
}
