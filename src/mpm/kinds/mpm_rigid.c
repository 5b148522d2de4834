/* mpm_rigid: the kind of particles that move as prescribed (a body with
 * motion: a pipette): no stress and no state; they carry their mass, and
 * mpm_motion imposes their velocity on the nodes they touch. */
#include <stdio.h>

#include "mpm_kind.h"
#include "mpm_state.h"

static pm_err rigid_setup(mpm_group *g, const pm_scene_material *sm,
                          const mpm_options *opt) {
  (void)sm, (void)opt;
  g->params = NULL;
  g->viscosity = 0;
  return PM_SUCCESS;
}

static void rigid_seed(const mpm_group *g, mpm_group_state *gs, long k,
                       const pm_scene_body *b, double sigma[9]) {
  (void)g, (void)gs, (void)k, (void)b, (void)sigma;
}

static void rigid_describe(const mpm_group *g, char *buf, size_t size) {
  (void)g;
  snprintf(buf, size, "rigid, moves as prescribed (no stress)");
}

static void rigid_wave_speeds(const mpm_model *m, const mpm_state *s,
                              const mpm_group *g, double *cp, double *cs) {
  (void)m, (void)s;
  for (long p = g->begin; p < g->end; p++) {
    cp[p] = 0;
    if (cs) cs[p] = 0;
  }
}

static void rigid_energies(const mpm_model *m, const mpm_state *s,
                           const mpm_group *g, double *strain,
                           double *internal) {
  (void)m, (void)s, (void)g, (void)strain, (void)internal;
}

static void rigid_fields(const mpm_model *m, const mpm_state *s,
                         const mpm_group *g, double *sed, double *pressure,
                         double *energy) {
  (void)m, (void)s;
  for (long p = g->begin; p < g->end; p++) sed[p] = pressure[p] = energy[p] = 0;
}

/* A body with motion, whatever its material. */
static bool rigid_takes(const pm_scene_material *sm, mpm_body_role role) {
  (void)sm;
  return role == MPM_BODY_RIGID;
}

/* No state. */
static double rigid_doubles(const pm_scene_material *sm, bool fbar) {
  (void)sm, (void)fbar;
  return 0;
}

const mpm_kind mpm_kind_rigid = {
    .name = "rigid",
    .stage_name = NULL,
    .flags = MPM_KIND_RIGID,
    .takes = rigid_takes,
    .estimate_doubles = rigid_doubles,
    .setup = rigid_setup,
    .seed = rigid_seed,
    .stress = NULL,
    .describe = rigid_describe,
    .wave_speeds = rigid_wave_speeds,
    .energies = rigid_energies,
    .fields = rigid_fields,
};
