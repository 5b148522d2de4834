/* mpm_grid_stages: the stages that work on the grid between the transfers
 * (gravity, absorbing faces, damping, the grid update with its conditions,
 * the USF grid velocity) and the stable time step. */
#ifndef MPM_GRID_STAGES_H
#define MPM_GRID_STAGES_H

#include "mpm_stage.h"

struct mpm_model;
struct mpm_state;

/* Nodal velocities from the momenta (null directions zero) with the
 * conditions applied, into the work's vel: the velocity USF and MUSL take
 * the stress from. */
void mpm_grid_velocity(mpm_ctx *ctx);

/* Stable step: dt_safety h over the largest of (wave speed + |v|) and the
 * viscous and artificial viscous terms (LS-DYNA form), over all particles;
 * INFINITY when nothing moves and no particle has a wave speed.  cp:
 * scratch of one double per particle. */
double mpm_stable_dt(const struct mpm_model *m, const struct mpm_state *s,
                     double *cp);

/* Stages.  time step: the stable step, cut to end at time.end.  gravity:
 * m g on the nodes (its work booked after the update, with the step's
 * mean velocity).  absorbing: viscous tractions on absorbing faces.
 * damping: mass-proportional, fixed or by dynamic relaxation.  grid
 * update: v^L = v + dt f / m with null directions and conditions, their
 * reactions and work, and the quasi-static residual.  grid velocity: see
 * mpm_grid_velocity. */
pm_err mpm_stage_time_step(mpm_ctx *ctx, const mpm_stage *self);
pm_err mpm_stage_gravity(mpm_ctx *ctx, const mpm_stage *self);
pm_err mpm_book_gravity(mpm_ctx *ctx, const mpm_stage *self);
pm_err mpm_stage_absorbing(mpm_ctx *ctx, const mpm_stage *self);
pm_err mpm_stage_damping(mpm_ctx *ctx, const mpm_stage *self);
pm_err mpm_remember_fixed(mpm_ctx *ctx, const mpm_stage *self);
pm_err mpm_stage_grid_update(mpm_ctx *ctx, const mpm_stage *self);
pm_err mpm_stage_grid_velocity(mpm_ctx *ctx, const mpm_stage *self);

#endif
