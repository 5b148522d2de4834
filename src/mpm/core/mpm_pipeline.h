/* mpm_pipeline: the explicit MPM step as an ordered list of stages,
 * assembled once from what the scene contains, and its execution. */
#ifndef MPM_PIPELINE_H
#define MPM_PIPELINE_H

#include "mpm_particles.h"
#include "mpm_stage.h"

/* Fixed stages (at most 12), and per group a constitutive stage and the
 * stage before it (membranes: normals). */
#define MPM_MAX_STAGES (13 + 2 * MPM_MAX_GROUPS)

typedef struct {
  mpm_stage stage[MPM_MAX_STAGES];
  int n;
  int update; /* the grid update: the after_update hooks follow it */
} mpm_pipeline;

/* Assemble m->pipeline from the model's options, groups (each kind's
 * constitutive stage) and conditions.  Called by mpm_model_create. */
void mpm_pipeline_build(struct mpm_model *m);

/* One explicit step of size state->dt: every stage in order, the
 * after_update hooks after the grid update, then the time and the step
 * count advance.  Returns the first stage's failure (PM_ERR_UNSTABLE, the
 * state left as the failing stage left it). */
pm_err mpm_step(const struct mpm_model *m, struct mpm_state *s,
                struct mpm_work *w);

#endif
